//! Questions before an action that would lose work: the "save changes?"
//! prompt and the window's close request; and the offer to convert a
//! dropped mesh that looks made in another unit.

use eframe::egui;

use super::AnthesisApp;
use super::default_project;
use super::document::Document;
use super::files::DialogPurpose;
use super::log::Topic;

/// Something that would lose unsaved changes, waiting for the user's answer.
#[derive(Debug, Clone, PartialEq)]
pub enum Pending {
    /// A new project from the built-in flower of this name.
    New(String),
    Open(Option<std::path::PathBuf>),
    Quit,
}

impl AnthesisApp {
    /// Asks for `action`, or first whether to save unsaved changes.
    pub fn request(&mut self, action: Pending) {
        if self.doc.is_dirty() {
            self.pending = Some(action);
        } else {
            self.perform(action);
        }
    }

    /// Carries out `action` without asking.
    pub(super) fn perform(&mut self, action: Pending) {
        match action {
            Pending::New(name) => match new_project(&name) {
                Ok(project) => {
                    self.discard_recovery();
                    self.log
                        .info(format!("new project from {} (`{name}`)", project.name));
                    self.replace_document(Document::new(project, None));
                    self.log.succeeded(Topic::Project);
                }
                Err(e) => self
                    .log
                    .error_about(Topic::Project, format!("cannot start a new project: {e}")),
            },
            Pending::Open(Some(path)) => self.open_path(&path),
            Pending::Open(None) => self.ask_for_path(DialogPurpose::OpenProject),
            Pending::Quit => {
                self.may_close = true;
                self.ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            }
        }
    }

    /// "Save changes?" before an action that would lose them.
    pub(super) fn unsaved_prompt(&mut self, ctx: &egui::Context) {
        let Some(action) = self.pending.clone() else {
            return;
        };
        if self.dialogs.is_open() {
            return;
        }
        let verb = match action {
            Pending::New(_) => "starting a new project",
            Pending::Open(_) => "opening another project",
            Pending::Quit => "quitting",
        };
        let mut answer = None;
        egui::Modal::new(egui::Id::unique("unsaved changes")).show(ctx, |ui| {
            ui.heading("Unsaved changes");
            ui.label(format!(
                "Save the changes to {} before {verb}?",
                self.doc.title().trim_end_matches(" *")
            ));
            ui.horizontal(|ui| {
                if ui.button("Save").clicked() {
                    answer = Some(Answer::Save);
                }
                if ui.button("Don't save").clicked() {
                    answer = Some(Answer::Discard);
                }
                if ui.button("Cancel").clicked() {
                    answer = Some(Answer::Cancel);
                }
            });
        });
        match answer {
            Some(Answer::Save) => {
                if self.doc.path.is_some() {
                    if self.save() {
                        self.pending = None;
                        self.perform(action);
                    }
                } else {
                    // The action waits for the save-as dialog.
                    self.save_as();
                }
            }
            Some(Answer::Discard) => {
                self.pending = None;
                self.perform(action);
            }
            Some(Answer::Cancel) => self.pending = None,
            None => {}
        }
    }

    /// A close request with unsaved changes becomes the "save changes?"
    /// prompt.
    pub(super) fn handle_close_request(&mut self, ctx: &egui::Context) {
        if ctx.input(|i| i.viewport().close_requested()) && !self.may_close && self.doc.is_dirty() {
            ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
            self.pending = Some(Pending::Quit);
        }
    }
}

/// The built-in flower `name` as a new project (the lily falls back on
/// [`default_project`], which also builds it).
fn new_project(name: &str) -> anyhow::Result<anthesis_flower::Project> {
    if name == "lily" {
        return default_project();
    }
    match anthesis_garden::builtin(name) {
        Some(loaded) => Ok(loaded?),
        None => Err(anyhow::anyhow!("no built-in flower `{name}`")),
    }
}

/// A dropped mesh whose size does not fit the project (see
/// `anthesis_flower::scale::check_replacement`), waiting for the user to
/// convert it, use it as it is, or keep the old one.
#[derive(Debug, Clone)]
pub struct UnitOffer {
    pub template: usize,
    pub path: std::path::PathBuf,
    pub mesh: Box<anthesis_mesh::Mesh>,
    pub mismatch: anthesis_flower::scale::ScaleMismatch,
}

impl AnthesisApp {
    /// The offer to convert a dropped mesh made in another unit.
    pub(super) fn unit_prompt(&mut self, ctx: &egui::Context) {
        let Some(offer) = &self.unit_offer else {
            return;
        };
        let scale = anthesis_files::short_number(1.0 / offer.mismatch.factor);
        let mut answer = None;
        egui::Modal::new(egui::Id::unique("mesh in another unit")).show(ctx, |ui| {
            ui.heading("A mesh in another unit?");
            ui.label(offer.mismatch.to_string());
            ui.horizontal(|ui| {
                if ui.button(format!("Convert (scale by {scale})")).clicked() {
                    answer = Some(UnitAnswer::Convert);
                }
                if ui.button("Use as it is").clicked() {
                    answer = Some(UnitAnswer::AsItIs);
                }
                if ui.button("Keep the old mesh").clicked() {
                    answer = Some(UnitAnswer::Keep);
                }
            });
        });
        let Some(answer) = answer else {
            return;
        };
        let Some(offer) = self.unit_offer.take() else {
            return;
        };
        match answer {
            UnitAnswer::Convert => {
                let mesh = offer.mismatch.rescaled(&offer.mesh);
                self.use_mesh(offer.template, mesh, &offer.path);
            }
            UnitAnswer::AsItIs => self.use_mesh(offer.template, *offer.mesh, &offer.path),
            UnitAnswer::Keep => self
                .log
                .info(format!("kept the mesh; {} not used", offer.path.display())),
        }
    }

    /// The dropped mesh waiting for the unit question, if any.
    pub fn unit_offer(&self) -> Option<&UnitOffer> {
        self.unit_offer.as_ref()
    }
}

#[derive(Debug, Clone, Copy)]
enum UnitAnswer {
    Convert,
    AsItIs,
    Keep,
}

/// The user's answer to the prompt.
#[derive(Debug, Clone, Copy)]
enum Answer {
    Save,
    Discard,
    Cancel,
}

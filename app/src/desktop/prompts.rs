//! Questions before an action that would lose work: the "save changes?"
//! prompt and the window's close request.

use eframe::egui;

use super::AnthesisApp;
use super::default_project;
use super::document::Document;
use super::files::DialogPurpose;

/// Something that would lose unsaved changes, waiting for the user's answer.
#[derive(Debug, Clone, PartialEq)]
pub enum Pending {
    New,
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
            Pending::New => match default_project() {
                Ok(project) => {
                    self.discard_recovery();
                    self.replace_document(Document::new(project, None));
                }
                Err(e) => self.log.error(format!("cannot start a new project: {e}")),
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
            Pending::New => "starting a new project",
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

/// The user's answer to the prompt.
#[derive(Debug, Clone, Copy)]
enum Answer {
    Save,
    Discard,
    Cancel,
}

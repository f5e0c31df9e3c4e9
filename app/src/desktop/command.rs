//! Every user action as a value. Menus, keyboard shortcuts, buttons, file
//! drops and tests make a [`Command`]; [`AnthesisApp::apply`] carries it
//! out, in this one place. A change to the project is a [`ProjectEdit`],
//! applied through [`Document::edit`] so that it is one undo step and
//! restarts the simulation.
//!
//! Continuous widget state that is not the document — the camera being
//! dragged, the playhead being scrubbed, export settings — is changed by
//! its widget directly; everything that also has a menu entry, a shortcut
//! or a button goes through here, and so do the brush's settings
//! ([`Command::SetBrush`]; the shortcuts step them too).

use std::path::PathBuf;

use anthesis_flower::{Project, Resolution, Template};
use anthesis_maps::{Blend, DirectionMap, MapKey, MapKind, ScalarMap};
use anthesis_mesh::Mesh;

use super::files::DialogPurpose;
use super::log::Topic;
use super::prompts::Pending;
use super::viewport::ViewOptions;
use super::{AnthesisApp, Document};
use anthesis_maps::brush::{Brush, PaintTarget, StrokeDab, dab_keyed, dab_scalar};

/// One user action.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// Show the gallery of starting points for a new project.
    NewProject,
    /// A new project from the built-in flower of this name (asks about
    /// unsaved changes).
    NewFrom(String),
    /// Open a project: this file, or ask for one (asks about unsaved
    /// changes first).
    OpenProject(Option<PathBuf>),
    /// Save to the project's file, or ask for one.
    Save,
    /// Ask where to save, then save.
    SaveAs,
    /// Close the window (asks about unsaved changes).
    Quit,
    /// A file dropped on the window (project, mesh or map).
    DropFile(PathBuf),
    /// Show the export dialog.
    OpenExportDialog,
    /// Ask where to export.
    BrowseExportPath,
    /// Ask for an OBJ mesh to make a new template of.
    BrowseTemplateObj,
    /// Ask for a scanned petal (an OBJ without UVs) to fit.
    BrowseScan,
    /// Ask for an OBJ to use as this template's open shape (two-state).
    BrowseOpenShape(usize),
    /// A file dialog (native or the in-app browser) answered: the path
    /// chosen for `purpose`, or `None` when cancelled.
    FileChosen {
        purpose: DialogPurpose,
        path: Option<PathBuf>,
    },
    /// Export the computed keyframes with the dialog's settings.
    StartExport,
    Undo,
    Redo,
    /// Change the project, as one undo step named `label`.
    Edit {
        label: String,
        edit: ProjectEdit,
    },
    /// Select an organ (index into the project's organs).
    SelectOrgan(usize),
    /// Simulate only the selected organ (fast, no collisions) or all.
    SetSingleOrganPreview(bool),
    /// Simulate again from the bud.
    Resimulate,
    /// Stop simulating; the keyframes so far stay.
    StopSimulation,
    TogglePlay,
    /// One keyframe forwards (+1) or back (−1).
    StepKeyframe(i32),
    GoToStart,
    /// The newest keyframe, following new ones.
    GoToEnd,
    /// Frame the camera on the whole scene.
    FrameAll,
    /// What the viewport shows.
    SetView(ViewOptions),
    /// Show or hide the log panel.
    ShowLog(bool),
    /// Show or hide the undo history window.
    ShowHistory(bool),
    /// Show or hide the Help → Shortcuts window.
    ShowShortcuts(bool),
    /// Undo or redo until this many steps of the history are applied.
    GoToHistory(usize),
    /// One step larger (`true`) or smaller brush radius
    /// ([`PaintState::grow_radius`](super::paint::PaintState::grow_radius)).
    StepBrushRadius {
        larger: bool,
    },
    /// One step stronger (`true`) or weaker brush.
    StepBrushStrength {
        stronger: bool,
    },
    /// Add becomes subtract, any other mode add.
    SwapBrushAddSubtract,
    /// The brush as the paint panel's controls set it (mode, radius,
    /// strength, hardness, value, mirror); not an undo step.
    SetBrush(Brush),
}

/// A change to the project. Indices are into the project's templates and a
/// template's time keys.
#[derive(Debug, Clone, PartialEq)]
pub enum ProjectEdit {
    /// The parameters panel: a template's fields and the project's
    /// keyframe count.
    Template {
        template: usize,
        value: Box<Template>,
        keyframes: u32,
    },
    /// One brush dab on a map of a time key.
    Dabs {
        template: usize,
        key: usize,
        target: PaintTarget,
        brush: Brush,
        /// The dabs in order, each with the stroke's direction there (used
        /// by the direction map).
        dabs: Vec<StrokeDab>,
    },
    /// A time key (an existing step is left alone).
    AddKey { template: usize, key: Box<MapKey> },
    /// Remove a time key (the last one stays).
    RemoveKey { template: usize, key: usize },
    /// How maps change from one key to the next.
    Blend { template: usize, blend: Blend },
    /// Replace a template's mesh.
    Mesh { template: usize, mesh: Box<Mesh> },
    /// The resolution every template is simulated at (the parameters
    /// panel); the meshes as built stay in the project.
    Resolution(Resolution),
    /// The flower's parts (stamens, pistils, stem, receptacle), all of
    /// them: the parts section of the Flower panel.
    Parts(Vec<anthesis_flower::parts::Part>),
    /// The whole flower as the Flower panel edited it (templates, organs,
    /// arrangement, overlap order; made by `anthesis_flower::edit`).
    Flower(Box<anthesis_flower::Flower>),
    /// Replace one map of a time key.
    Map {
        template: usize,
        key: usize,
        map: Box<LoadedMap>,
    },
}

/// A map read from a file, with the map it replaces.
#[derive(Debug, Clone, PartialEq)]
pub enum LoadedMap {
    Scalar(MapKind, ScalarMap),
    Direction(DirectionMap),
    /// The template's colour map (any size: it is not simulated).
    Colour(ScalarMap),
}

impl ProjectEdit {
    /// Applies the edit; an index that does not exist changes nothing.
    pub fn apply(self, project: &mut Project) {
        let templates = &mut project.flower.templates;
        match self {
            ProjectEdit::Template {
                template,
                value,
                keyframes,
            } => {
                if let Some(t) = templates.get_mut(template) {
                    *t = *value;
                    project.settings.keyframes = keyframes;
                }
            }
            ProjectEdit::Dabs {
                template,
                key,
                target,
                brush,
                dabs,
            } => {
                if let Some(t) = templates.get_mut(template) {
                    if target == PaintTarget::Colour {
                        // The colour map: one for the template, not keyed.
                        let colouring = t.colouring_to_paint();
                        for dab in dabs {
                            dab_scalar(&mut colouring.mix, &brush, dab.centre_in_uv, 0.0);
                        }
                        return;
                    }
                    for dab in dabs {
                        dab_keyed(
                            &mut t.maps,
                            key,
                            target,
                            &brush,
                            dab.centre_in_uv,
                            dab.direction_in_uv,
                        );
                    }
                }
            }
            ProjectEdit::AddKey { template, key } => {
                if let Some(t) = templates.get_mut(template) {
                    // A key at an existing step is refused by the maps and
                    // the project stays as it was.
                    let _ = t.maps.insert(*key);
                }
            }
            ProjectEdit::RemoveKey { template, key } => {
                if let Some(t) = templates.get_mut(template) {
                    // The last key cannot go; nothing changes then.
                    let _ = t.maps.remove(key);
                }
            }
            ProjectEdit::Blend { template, blend } => {
                if let Some(t) = templates.get_mut(template) {
                    t.maps.blend = blend;
                }
            }
            ProjectEdit::Mesh { template, mesh } => {
                if let Some(t) = templates.get_mut(template) {
                    t.mesh = *mesh;
                }
            }
            ProjectEdit::Resolution(resolution) => project.settings.resolution = resolution,
            ProjectEdit::Parts(parts) => project.flower.parts = parts,
            ProjectEdit::Flower(flower) => project.flower = *flower,
            ProjectEdit::Map {
                template,
                key: _,
                map,
            } if matches!(*map, LoadedMap::Colour(_)) => {
                if let (Some(t), LoadedMap::Colour(mix)) = (templates.get_mut(template), *map) {
                    t.colouring_to_paint().mix = mix;
                }
            }
            ProjectEdit::Map { template, key, map } => {
                let Some(k) = templates
                    .get_mut(template)
                    .and_then(|t| t.maps.keys_mut().get_mut(key))
                else {
                    return;
                };
                match *map {
                    LoadedMap::Scalar(kind, map) => *k.maps.scalar_mut(kind) = map,
                    LoadedMap::Direction(map) => k.maps.direction = map,
                    LoadedMap::Colour(_) => {}
                }
            }
        }
    }
}

impl AnthesisApp {
    /// Carries out `command`.
    pub fn apply(&mut self, command: Command) {
        match command {
            Command::NewProject => self.gallery.show(&self.ctx),
            Command::NewFrom(name) => self.request(Pending::New(name)),
            Command::OpenProject(path) => self.request(Pending::Open(path)),
            Command::Save => {
                self.save();
            }
            Command::SaveAs => self.save_as(),
            Command::Quit => self.request(Pending::Quit),
            Command::DropFile(path) => self.drop_file(&path),
            Command::OpenExportDialog => self.open_export(),
            Command::BrowseExportPath => self.ask_for_path(DialogPurpose::ExportGlb),
            Command::BrowseTemplateObj => self.ask_for_path(DialogPurpose::ImportTemplateObj),
            Command::BrowseScan => self.ask_for_path(DialogPurpose::ImportScan),
            Command::BrowseOpenShape(template) => {
                self.ask_for_path(DialogPurpose::OpenShape(template));
            }
            Command::FileChosen { purpose, path } => self.file_chosen(purpose, path),
            Command::StartExport => self.start_export(),
            Command::Undo => self.undo(),
            Command::Redo => self.redo(),
            Command::Edit { label, edit } => {
                self.edit(&label, edit);
            }
            Command::SelectOrgan(organ) => self.select_organ(organ),
            Command::SetSingleOrganPreview(on) => self.set_single_organ_preview(on),
            Command::Resimulate => self.needs_run = true,
            Command::StopSimulation => {
                self.session.cancel();
                self.log.info("simulation stopped");
            }
            Command::TogglePlay => self.playback.toggle_play(self.session.shown_end()),
            Command::StepKeyframe(direction) => {
                self.playback.step(direction, self.session.shown_end());
            }
            Command::GoToStart => self.playback.go_to_start(),
            Command::GoToEnd => self.playback.go_to_end(self.session.shown_end()),
            Command::FrameAll => self.frame_all(),
            Command::SetView(view) => self.view = view,
            Command::ShowLog(on) => self.settings.show_log = on,
            Command::ShowHistory(on) => self.settings.show_history = on,
            Command::ShowShortcuts(on) => self.show_shortcuts = on,
            Command::GoToHistory(position) => {
                if !self.doc.go_to(position).is_empty() {
                    self.log.info(format!(
                        "history: {} of {} steps applied",
                        self.doc.history_position(),
                        self.doc.history_labels().count()
                    ));
                    self.after_history_change();
                }
            }
            Command::StepBrushRadius { larger: true } => self.paint.grow_radius(),
            Command::StepBrushRadius { larger: false } => self.paint.shrink_radius(),
            Command::StepBrushStrength { stronger: true } => self.paint.raise_strength(),
            Command::StepBrushStrength { stronger: false } => self.paint.lower_strength(),
            Command::SwapBrushAddSubtract => self.paint.toggle_mode(),
            Command::SetBrush(brush) => self.paint.brush = brush,
        }
    }

    /// Applies the commands the panels queued this frame, in order.
    pub(super) fn apply_queued(&mut self) {
        let queued = std::mem::take(&mut self.queued);
        if queued.is_empty() {
            return;
        }
        for command in queued {
            self.apply(command);
        }
        // The panels were drawn before the change: draw them again.
        self.ctx.request_repaint();
    }

    /// Applies `edit` as one undo step named `label` (see
    /// [`Document::edit`]); returns whether the project changed.
    pub fn edit(&mut self, label: &str, edit: ProjectEdit) -> bool {
        if let ProjectEdit::Resolution(resolution) = &edit {
            // Remeshed before the document changes: a resolution that does
            // not fit in memory or a template that cannot be remeshed is
            // refused, and the meshes shown stay.
            let mut trial = self.doc.project().clone();
            trial.settings.resolution = *resolution;
            if let Err(message) = self.resolved.prepare(&trial) {
                self.log.error_about(
                    Topic::Resolution,
                    format!("the resolution stays as it was: {message}"),
                );
                return false;
            }
            self.log.succeeded(Topic::Resolution);
        }
        if let ProjectEdit::Flower(flower) = &edit {
            // Checked as a loaded project is: a flower the panel made
            // wrongly never reaches the simulation.
            let mut trial = self.doc.project().clone();
            trial.flower = (**flower).clone();
            if let Err(error) = anthesis_flower::project::check(&trial) {
                self.log.error_about(
                    Topic::Project,
                    format!("the flower stays as it was: {error}"),
                );
                return false;
            }
        }
        let added_step = match &edit {
            ProjectEdit::AddKey { template, key } => Some((*template, key.step)),
            _ => None,
        };
        let changed = self.doc.edit(label, |project| edit.apply(project));
        if changed {
            self.needs_run = true;
            let organs = self.project().flower.organs.len();
            self.selected_organ = self.selected_organ.min(organs.saturating_sub(1));
        }
        if let Some((template, step)) = added_step
            && let Some(index) = self
                .project()
                .flower
                .templates
                .get(template)
                .and_then(|t| t.maps.keys().iter().position(|k| k.step == step))
        {
            // Paint the new key next.
            self.paint.key = index;
        }
        changed
    }

    pub fn undo(&mut self) {
        match self.doc.undo() {
            Some(label) => {
                self.log.info(format!("undid {label}"));
                self.after_history_change();
            }
            None => self.log.info("nothing to undo"),
        }
    }

    pub fn redo(&mut self) {
        match self.doc.redo() {
            Some(label) => {
                self.log.info(format!("redid {label}"));
                self.after_history_change();
            }
            None => self.log.info("nothing to redo"),
        }
    }

    fn after_history_change(&mut self) {
        let organs = self.project().flower.organs.len();
        self.selected_organ = self.selected_organ.min(organs.saturating_sub(1));
        self.needs_run = true;
    }

    pub fn select_organ(&mut self, organ: usize) {
        if organ < self.project().flower.organs.len() && organ != self.selected_organ {
            self.selected_organ = organ;
            if self.single_organ_preview {
                self.needs_run = true;
            }
        }
    }

    pub fn set_single_organ_preview(&mut self, on: bool) {
        if on != self.single_organ_preview {
            self.single_organ_preview = on;
            self.needs_run = true;
            // One organ or the whole flower: frame what is shown next.
            self.reframe();
        }
    }
}

/// Applies `edit` to `doc` as one sealed undo step (for tests and for
/// callers without an app).
pub fn edit_document(doc: &mut Document, label: &str, edit: ProjectEdit) -> bool {
    let changed = doc.edit(label, |project| edit.apply(project));
    doc.seal();
    changed
}

#[cfg(test)]
mod tests {
    use super::*;
    use anthesis_maps::GrowthMaps;
    use anthesis_maps::brush::BrushMode;
    use glam::DVec2;

    fn project() -> Project {
        anthesis_sim::fixtures::whorl(2, 4, 6, 3)
    }

    /// Every kind of edit, each of which changes the fixture project.
    fn edits(project: &Project) -> Vec<ProjectEdit> {
        let template = &project.flower.templates[0];
        let mut changed = template.clone();
        changed.dg = 0.0123;
        changed.thickness = 0.31;
        let mut mesh = template.mesh.clone();
        for p in &mut mesh.positions {
            p.x *= 1.5;
        }
        let painted_size = 16;
        vec![
            ProjectEdit::Template {
                template: 0,
                value: Box::new(changed),
                keyframes: project.settings.keyframes + 7,
            },
            ProjectEdit::Dabs {
                template: 0,
                key: 0,
                target: PaintTarget::Scalar(MapKind::Bend),
                brush: Brush {
                    mode: BrushMode::Set,
                    value: 0.1,
                    ..Brush::default()
                },
                dabs: vec![StrokeDab {
                    centre_in_uv: DVec2::new(0.3, 0.5),
                    direction_in_uv: DVec2::ZERO,
                }],
            },
            ProjectEdit::Dabs {
                template: 0,
                key: 0,
                target: PaintTarget::Direction,
                brush: Brush::default(),
                dabs: vec![StrokeDab {
                    centre_in_uv: DVec2::new(0.5, 0.5),
                    direction_in_uv: DVec2::new(0.1, 0.0),
                }],
            },
            ProjectEdit::AddKey {
                template: 0,
                key: Box::new(MapKey {
                    dg: None,
                    step: 77,
                    maps: GrowthMaps::default(),
                }),
            },
            ProjectEdit::Blend {
                template: 0,
                blend: Blend::logistic(),
            },
            ProjectEdit::Mesh {
                template: 0,
                mesh: Box::new(mesh),
            },
            ProjectEdit::Map {
                template: 0,
                key: 0,
                map: Box::new(LoadedMap::Scalar(
                    MapKind::Stretch,
                    ScalarMap::from_fn(painted_size, painted_size, |uv| uv.x as f32),
                )),
            },
            ProjectEdit::Resolution(Resolution::MeanEdge(0.5)),
            ProjectEdit::Parts(vec![crate::desktop::parts_panel::new_part(
                project, "pistil",
            )]),
            ProjectEdit::Flower(Box::new(
                project
                    .flower
                    .with_organ(project.flower.new_organ(0).expect("template 0"))
                    .expect("an organ is added"),
            )),
        ]
    }

    #[test]
    fn each_edit_changes_the_project_and_undo_gives_it_back_and_redo_again() {
        let original = project();
        for edit in edits(&original) {
            let mut doc = Document::new(original.clone(), None);
            assert!(
                edit_document(&mut doc, "edit", edit.clone()),
                "{edit:?} changed nothing"
            );
            let edited = doc.project().clone();
            assert_ne!(edited, original);
            assert!(doc.undo().is_some());
            assert_eq!(doc.project(), &original, "undo of {edit:?}");
            assert!(!doc.is_dirty());
            assert!(doc.redo().is_some());
            assert_eq!(doc.project(), &edited, "redo of {edit:?}");
        }
    }

    #[test]
    fn removing_a_key_is_undone_and_the_last_key_stays() {
        let mut doc = Document::new(project(), None);
        let add = ProjectEdit::AddKey {
            template: 0,
            key: Box::new(MapKey {
                dg: None,
                step: 45,
                maps: GrowthMaps::default(),
            }),
        };
        assert!(edit_document(&mut doc, "add key", add));
        let with_added = doc.project().clone();
        let remove = |key| ProjectEdit::RemoveKey { template: 0, key };
        let count = with_added.flower.templates[0].maps.keys().len();
        for removed in 1..count {
            assert!(edit_document(&mut doc, "remove key", remove(0)));
            assert_eq!(
                doc.project().flower.templates[0].maps.keys().len(),
                count - removed
            );
        }
        assert!(
            !edit_document(&mut doc, "remove key", remove(0)),
            "the last key cannot go"
        );
        for _ in 1..count {
            doc.undo();
        }
        assert_eq!(doc.project(), &with_added);
    }

    #[test]
    fn an_edit_of_a_template_that_does_not_exist_changes_nothing() {
        let original = project();
        let missing = original.flower.templates.len() + 3;
        let mut doc = Document::new(original.clone(), None);
        let edits = [
            ProjectEdit::Template {
                template: missing,
                value: Box::new(original.flower.templates[0].clone()),
                keyframes: 9,
            },
            ProjectEdit::Dabs {
                template: missing,
                key: 0,
                target: PaintTarget::Scalar(MapKind::Bend),
                brush: Brush::default(),
                dabs: vec![StrokeDab {
                    centre_in_uv: DVec2::splat(0.5),
                    direction_in_uv: DVec2::ZERO,
                }],
            },
            ProjectEdit::Map {
                template: 0,
                key: 5,
                map: Box::new(LoadedMap::Direction(DirectionMap::constant(DVec2::X))),
            },
        ];
        for edit in edits {
            assert!(!edit_document(&mut doc, "edit", edit));
        }
        assert_eq!(doc.project(), &original);
        assert!(!doc.is_dirty());
    }
}

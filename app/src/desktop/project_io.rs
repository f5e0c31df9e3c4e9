//! Project files: open, save, save as, dropped files, the file dialogs'
//! answers and starting an export. Errors are shown in the log and the
//! user's work stays.

use std::path::{Path, PathBuf};

use anthesis_flower::project::{
    LoadedProject, keep_backup, load_project_with_warnings, save_project,
};
use eframe::egui;

use super::AnthesisApp;
use super::command::{Command, LoadedMap, ProjectEdit};
use super::document::Document;
use super::export;
use super::files::{DialogPurpose, Polled};
use super::log::Topic;
use super::prompts::{Pending, UnitOffer};
use anthesis_maps::brush::PaintTarget;
use anthesis_sim::Selection;

impl AnthesisApp {
    /// Opens the project at `path`; on failure the current work stays and
    /// the error is shown.
    pub fn open_path(&mut self, path: &Path) {
        // A project folder opens its project file, which is then the
        // document's path (saved to, remembered).
        let resolved = anthesis_flower::project::project_file(path);
        let path = resolved.as_deref().unwrap_or(path);
        match load_project_with_warnings(path) {
            Ok(LoadedProject {
                project,
                mut warnings,
            }) => {
                warnings.extend(anthesis_flower::unit::note_if_unstated(&project));
                self.settings.remember(path);
                // The work open before was saved or thrown away (the
                // "save changes?" prompt came first).
                self.discard_recovery();
                self.replace_document(Document::new(project, Some(path.to_path_buf())));
                self.log.info(format!("opened {}", path.display()));
                self.log.succeeded(Topic::Project);
                for warning in warnings {
                    self.log.warn(warning);
                }
                // The command line refuses such a project; the window opens
                // it (the user may fix the mesh or thickness here) and says
                // why a run will likely fail.
                for mismatch in anthesis_flower::scale::check_flower(&self.project().flower) {
                    self.log
                        .warn(format!("{mismatch}: the simulation will likely fail"));
                }
            }
            Err(e) => {
                self.log
                    .error_about(Topic::Project, format!("cannot open the project: {e}"));
                if !path.exists() {
                    self.settings.forget(path);
                }
            }
        }
    }

    /// A file dropped on the window: a project (`.toml`) opens after the
    /// unsaved-changes prompt, an OBJ mesh replaces the selected organ's
    /// template mesh, a PNG replaces the map being painted. Anything that
    /// cannot be used is reported and changes nothing.
    pub fn drop_file(&mut self, path: &Path) {
        let extension = path
            .extension()
            .map(|e| e.to_string_lossy().to_lowercase())
            .unwrap_or_default();
        match extension.as_str() {
            "toml" => self.request(Pending::Open(Some(path.to_path_buf()))),
            "obj" => self.replace_mesh(path),
            "png" => self.load_map(path),
            _ => self.log.warn(format!(
                "cannot use {}: drop a project (.toml), a mesh (.obj) or a map (.png)",
                path.display()
            )),
        }
    }

    fn replace_mesh(&mut self, path: &Path) {
        let template = self.selected_template();
        match anthesis_mesh::load_obj(path) {
            Ok(mesh) => {
                let current = &self.project().flower.templates[template];
                match anthesis_flower::scale::check_replacement(current, &mesh) {
                    // Looks made in another unit: ask before using it.
                    Some(mismatch) => {
                        self.unit_offer = Some(UnitOffer {
                            template,
                            path: path.to_path_buf(),
                            mesh: Box::new(mesh),
                            mismatch,
                        });
                    }
                    None => self.use_mesh(template, mesh, path),
                }
            }
            Err(e) => self.log.error_about(
                Topic::Import,
                format!("cannot use {} as a mesh: {e}", path.display()),
            ),
        }
    }

    /// Puts `mesh` (read from `path`) in place of `template`'s mesh, as one
    /// undoable edit.
    pub(super) fn use_mesh(&mut self, template: usize, mesh: anthesis_mesh::Mesh, path: &Path) {
        let name = self.project().flower.templates[template].name.clone();
        self.edit(
            &format!("mesh of {name}"),
            ProjectEdit::Mesh {
                template,
                mesh: Box::new(mesh),
            },
        );
        self.doc.seal();
        self.log
            .info(format!("{name} now uses the mesh of {}", path.display()));
        self.log.succeeded(Topic::Import);
    }

    fn load_map(&mut self, path: &Path) {
        let template = self.selected_template();
        let (key, target) = (self.paint.key, self.paint.target);
        let size = self.project().flower.templates[template].maps.raster_size();
        let fits = |found: (u32, u32)| match size {
            Some(expected) if found != expected && found != (1, 1) => Err(format!(
                "the map is {}x{} pixels but the template's maps are {}x{}",
                found.0, found.1, expected.0, expected.1
            )),
            _ => Ok(()),
        };
        let loaded = match target {
            PaintTarget::Scalar(kind) => anthesis_maps::ScalarMap::load_png(path)
                .map_err(|e| e.to_string())
                .and_then(|map| fits(map.size()).map(|()| LoadedMap::Scalar(kind, map))),
            PaintTarget::Direction => anthesis_maps::DirectionMap::load_png(path)
                .map_err(|e| e.to_string())
                .and_then(|map| fits(map.size()).map(|()| LoadedMap::Direction(map))),
            PaintTarget::Colour => anthesis_maps::ScalarMap::load_png(path)
                .map(LoadedMap::Colour)
                .map_err(|e| e.to_string()),
        };
        match loaded {
            Ok(map) => {
                let name = self.project().flower.templates[template].name.clone();
                self.edit(
                    &format!("{} map of {name}", target.label()),
                    ProjectEdit::Map {
                        template,
                        key,
                        map: Box::new(map),
                    },
                );
                self.doc.seal();
                self.log.succeeded(Topic::Import);
                self.log.info(format!(
                    "loaded the {} map of {name} from {}",
                    target.label(),
                    path.display()
                ));
            }
            Err(e) => self.log.error_about(
                Topic::Import,
                format!("cannot use {} as a map: {e}", path.display()),
            ),
        }
    }

    pub(super) fn replace_document(&mut self, doc: Document) {
        self.doc = doc;
        self.session.forget_shown();
        self.selected_organ = 0;
        self.reframe();
        self.needs_run = true;
        self.playback.time_in_keyframes = 0.0;
        self.playback.follow = true;
    }

    fn project_folder(&self) -> Option<PathBuf> {
        self.doc
            .path
            .as_ref()
            .and_then(|p| p.parent())
            .map(Path::to_path_buf)
    }

    /// Opens the file dialog for `purpose`, starting in the project's
    /// folder; the answer arrives in a later frame.
    pub(super) fn ask_for_path(&mut self, purpose: DialogPurpose) {
        let mut folder = self.project_folder();
        let mut name = purpose.suggested_name(&self.project().name);
        // Browsing for the export's path starts from what its field says.
        let typed = Path::new(self.export.path.trim());
        if purpose == DialogPurpose::ExportGlb
            && let Some(file) = typed.file_name()
        {
            name = Some(file.to_string_lossy().into_owned());
            if let Some(parent) = typed.parent().filter(|p| p.is_dir()) {
                folder = Some(parent.to_path_buf());
            }
        }
        let wake = self.ctx.clone();
        self.dialogs
            .open(purpose, folder.as_deref(), name, move || {
                wake.request_repaint()
            });
    }

    /// Saves to the document's path, or asks for one. Returns whether the
    /// project was written.
    pub fn save(&mut self) -> bool {
        match self.doc.path.clone() {
            Some(path) => self.save_to(&path),
            None => {
                self.save_as();
                false
            }
        }
    }

    pub fn save_as(&mut self) {
        self.ask_for_path(DialogPurpose::SaveProjectAs);
    }

    /// Writes the project to `path`; errors are shown, the work stays.
    pub fn save_to(&mut self, path: &Path) -> bool {
        // The version saved before stays in backup/ beside it; failing to
        // keep it must not stop the save.
        if let Err(e) = keep_backup(path) {
            self.log.warn(format!(
                "could not keep the previous version as a backup: {e}"
            ));
        }
        match save_project(self.doc.project(), path) {
            Ok(()) => {
                self.doc.mark_saved(path.to_path_buf());
                self.discard_recovery();
                self.settings.remember(path);
                self.log.info(format!("saved {}", path.display()));
                self.log.succeeded(Topic::Project);
                true
            }
            Err(e) => {
                self.log
                    .error_about(Topic::Project, format!("cannot save: {e}"));
                false
            }
        }
    }

    /// Uses the in-app file browser from now on, as the app does by itself
    /// when no native dialog can be shown (tests).
    pub fn use_in_app_file_browser(&mut self) {
        self.dialogs = super::files::Dialogs::in_app();
    }

    /// The native dialog's answer, as a [`Command::FileChosen`]; when no
    /// native dialog can be shown, says so (the in-app browser is open
    /// instead).
    pub(super) fn handle_dialog_answers(&mut self) {
        match self.dialogs.poll() {
            None => {}
            Some(Polled::Chosen(purpose, path)) => {
                self.apply(Command::FileChosen { purpose, path })
            }
            Some(Polled::InAppInstead(why)) => self.log.warn(format!(
                "no native file dialog can be shown ({why}): using the in-app file browser"
            )),
        }
    }

    /// The in-app file browser, when open; its answer is queued as a
    /// [`Command::FileChosen`].
    pub(super) fn file_browser(&mut self, ctx: &egui::Context) {
        if let Some((purpose, path)) = self.dialogs.browser_ui(ctx) {
            self.queued.push(Command::FileChosen { purpose, path });
        }
    }

    /// `path` was chosen (or, `None`, the dialog cancelled) for `purpose`.
    pub(super) fn file_chosen(&mut self, purpose: DialogPurpose, path: Option<PathBuf>) {
        let Some(path) = path else {
            // Cancelled: a pending action waiting for "save as" is dropped.
            if purpose == DialogPurpose::SaveProjectAs {
                self.pending = None;
            }
            return;
        };
        match purpose {
            DialogPurpose::OpenProject => self.open_path(&path),
            DialogPurpose::SaveProjectAs => {
                if self.save_to(&path)
                    && let Some(action) = self.pending.take()
                {
                    self.perform(action);
                }
            }
            DialogPurpose::ExportGlb => {
                self.export.path = path.display().to_string();
            }
            DialogPurpose::ImportTemplateObj => self.import_template(&path),
            DialogPurpose::ImportScan => self.import_scan(&path),
            DialogPurpose::OpenShape(template) => self.open_shape_from_obj(template, &path),
            DialogPurpose::FitTarget => self.fit.target = path.display().to_string(),
        }
    }

    /// Makes a new template of the OBJ mesh at `path` (uniform growth maps
    /// like the simple petal) with one organ of it, as one undo step; a
    /// file that is not a valid mesh, or a mesh in another unit, is refused
    /// with the reason, in the log and the Flower panel.
    pub(super) fn import_template(&mut self, path: &Path) {
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().trim().to_string())
            .filter(|s| !s.is_empty())
            .unwrap_or_else(|| "imported".to_string());
        let result = anthesis_mesh::load_obj(path)
            .map_err(|e| e.to_string())
            .and_then(|mesh| {
                // Painting, remeshing and the simulation read the organ
                // through its UVs: a layout that breaks the convention is
                // refused now rather than at the first remesh.
                if let Err(e) = anthesis_bud::MeshSurface::new(&mesh) {
                    return Err(format!(
                        "its UV layout cannot be a template's (u across the organ, v from the \
                         base at 0 to the tip at 1, not overlapping): {e}; a mesh without \
                         usable UVs can come in through Import scanned petal…"
                    ));
                }
                Ok(mesh)
            })
            .and_then(|mesh| {
                let template = anthesis_garden::five_petal::simple_template_of_mesh(&name, mesh);
                self.project()
                    .flower
                    .with_template_and_organ(template)
                    .map_err(|e| e.to_string())
            });
        match result {
            Ok(flower) => {
                let added = flower
                    .templates
                    .last()
                    .map_or(name.clone(), |t| t.name.clone());
                self.edit(
                    &format!("import template {added}"),
                    ProjectEdit::Flower(Box::new(flower)),
                );
                self.doc.seal();
                self.flower_panel
                    .imported(self.project().flower.templates.len() - 1);
                self.log
                    .info(format!("new template {added} from {}", path.display()));
                self.log.succeeded(Topic::Import);
            }
            Err(e) => {
                let message = format!("cannot import {} as a template: {e}", path.display());
                self.flower_panel.refuse(message.clone());
                self.log.error_about(Topic::Import, message);
            }
        }
    }

    /// Reads the scanned petal at `path` and fits it, for review in the
    /// Flower panel (nothing changes until the user makes the template);
    /// a scan that cannot be read or has no single outline is refused with
    /// the reason, in the log and the Flower panel.
    pub(super) fn import_scan(&mut self, path: &Path) {
        match super::scan_panel::ScanReview::read(path, 1.0) {
            Ok((review, notes)) => {
                self.flower_panel.scan_read(review);
                // The review starts its fit when it is next drawn.
                self.ctx.request_repaint();
                self.log
                    .info(format!("scanned petal {} read", path.display()));
                for note in notes {
                    self.log.info(format!("{}: {note}", path.display()));
                }
            }
            Err(e) => {
                let message = format!("cannot import {} as a scanned petal: {e}", path.display());
                self.flower_panel.refuse(message.clone());
                self.log.error_about(Topic::Import, message);
            }
        }
    }

    /// Makes template `template` two-state with the OBJ at `path` as its
    /// open shape (one undo step), or says why the file does not fit.
    fn open_shape_from_obj(&mut self, template: usize, path: &Path) {
        let Some(current) = self.project().flower.templates.get(template).cloned() else {
            return;
        };
        let read = anthesis_files::read_regular_text(
            path,
            anthesis_mesh::obj::MAX_OBJ_BYTES,
            "an OBJ mesh",
        )
        .map_err(|e| e.to_string())
        .and_then(|text| {
            anthesis_mesh::obj::object_text(&text, None)
                .and_then(|text| anthesis_mesh::obj::parse_obj(&text))
                .map_err(|e| e.to_string())
        });
        let open = match read {
            Ok(mesh) => mesh,
            Err(e) => {
                self.log.error_about(
                    Topic::Project,
                    format!("cannot read the open shape {}: {e}", path.display()),
                );
                return;
            }
        };
        let problem = if open.positions.len() != current.mesh.positions.len() {
            Some(format!(
                "it has {} vertices but the mesh of template \"{}\" has {}",
                open.positions.len(),
                current.name,
                current.mesh.positions.len()
            ))
        } else if open.triangles != current.mesh.triangles {
            Some(format!(
                "its triangles are not those of template \"{}\" (same vertices in the same \
                 order and the same triangles are needed)",
                current.name
            ))
        } else {
            None
        };
        if let Some(problem) = problem {
            self.log.error_about(
                Topic::Project,
                format!("cannot use {} as the open shape: {problem}", path.display()),
            );
            return;
        }
        let keyframes = self.project().settings.keyframes;
        let mut value = current;
        match &mut value.two_state {
            Some(animation) => animation.open = open.positions,
            None => {
                value.two_state = Some(anthesis_flower::TwoStateAnimation::new(
                    open.positions,
                    keyframes,
                ));
            }
        }
        let label = format!("open shape of {}", value.name);
        self.edit(
            &label,
            ProjectEdit::Template {
                template,
                value: Box::new(value),
                keyframes,
            },
        );
        self.doc.seal();
        self.log.info(format!("{label} from {}", path.display()));
    }

    /// Shows the export dialog, suggesting a .glb beside the project.
    pub fn open_export(&mut self) {
        self.export.open = true;
        if self.export.path.trim().is_empty() {
            let folder = self.project_folder().unwrap_or_default();
            let name = super::files::default_file_name(&self.project().name);
            self.export.path = folder.join(name).display().to_string();
        }
    }

    /// Starts the export the dialog asks for. It never writes the proxy:
    /// the window's converged keyframes, or a run of the export's own. With
    /// one organ previewed it writes the whole flower unless the dialog
    /// asks for the organ alone: from the whole flower's keyframes kept
    /// from before the preview when they are complete and of this very
    /// project, else from a run of its own.
    pub(super) fn start_export(&mut self) {
        let wake = self.ctx.clone();
        let wake = move || wake.request_repaint();
        let previewing = self.single_organ_preview;
        let whole = previewing && self.export.whole_flower;
        let selection = if whole {
            Selection::All
        } else {
            self.selection()
        };
        if self.export.resimulate {
            self.export
                .start_resimulated(self.doc.project(), selection, wake);
            return;
        }
        // The keyframes are of the meshes at the project's resolution.
        let project = self.resolved_project();
        let organs: Vec<usize> = selection.organs(project.flower.organs.len());
        let keyframes = if whole {
            match self.session.complete_run_of(&organs, &project) {
                Some(keyframes) => keyframes,
                None => {
                    self.export.start_whole_flower(self.doc.project(), wake);
                    return;
                }
            }
        } else {
            let crossed: Vec<u32> = self.session.crossed_keyframes().collect();
            if let (Some(first), Some(last)) = (crossed.first(), crossed.last()) {
                self.log.warn(format!(
                    "the export holds {} keyframe{} where organs pass through each other \
                     ({first} to {last}; red on the timeline)",
                    crossed.len(),
                    if crossed.len() == 1 { "" } else { "s" }
                ));
            }
            self.session.keyframes().to_vec()
        };
        let tracks = export::tracks(&project, &organs, &keyframes, self.export.render_level);
        match tracks {
            Ok(tracks) => self.export.start(tracks, wake),
            Err(error) => self.export.fail(error.to_string()),
        }
    }
}

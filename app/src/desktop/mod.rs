//! The desktop window: an eframe application over the engine.
//!
//! [`AnthesisApp`] holds the state (the open [`Document`], the simulation
//! [`SimSession`], playback, view and dialogs) and small methods that change
//! it; each panel lives in its own module and only draws and reports what
//! the user asked for. No engine logic lives here: simulation, maps,
//! project files and export are the engine crates'.

pub mod brush;
pub mod document;
pub mod export;
pub mod files;
pub mod log;
pub mod paint;
pub mod params;
pub mod session;
pub mod timeline;
pub mod viewport;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anthesis_flower::Project;
use anthesis_flower::project::{load_project, save_project};
use anthesis_sim::Selection;
use anyhow::{Result, anyhow};
use eframe::egui::{self, Key, KeyboardShortcut, Modifiers};

use document::Document;
use export::ExportDialog;
use files::{DialogPurpose, Dialogs, Settings};
use log::Log;
use paint::PaintState;
use session::{DRAIN_BUDGET, SimSession};
use timeline::Playback;
use viewport::{OrbitCamera, ViewOptions, ViewportGpu};

/// The flower shown at first launch: the built-in Asiatic lily, or (should
/// this build lack it) a generated six-organ whorl.
pub fn default_project() -> Project {
    anthesis_garden::builtin_lily().unwrap_or_else(|_| {
        let mut project = anthesis_sim::fixtures::whorl(6, 14, 28, 100);
        project.name = "Default flower".to_string();
        project
    })
}

/// The key under which [`Settings`] are stored.
const SETTINGS_KEY: &str = "anthesis-settings";

/// Opens the window; returns when it is closed.
pub fn run() -> Result<()> {
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("Anthesis")
            .with_inner_size([1400.0, 900.0])
            .with_min_inner_size([800.0, 500.0]),
        renderer: eframe::Renderer::Wgpu,
        ..Default::default()
    };
    eframe::run_native(
        "Anthesis",
        options,
        Box::new(|cc| Ok(Box::new(AnthesisApp::new(cc, Startup::default())))),
    )
    .map_err(|e| anyhow!("cannot open the window: {e}"))
}

/// How the app starts.
pub struct Startup {
    /// The project to open; `None`: the last project, else the default.
    pub project: Option<(Project, Option<PathBuf>)>,
    /// Simulate with the engine's worker (`false`: keyframes are fed in by
    /// hand through [`AnthesisApp::session_mut`], for tests).
    pub live: bool,
    /// Read settings saved by an earlier launch.
    pub restore: bool,
}

impl Default for Startup {
    fn default() -> Self {
        Startup {
            project: None,
            live: true,
            restore: true,
        }
    }
}

/// Something that would lose unsaved changes, waiting for the user's answer.
#[derive(Debug, Clone, PartialEq)]
pub enum Pending {
    New,
    Open(Option<PathBuf>),
    Quit,
}

/// The application state.
pub struct AnthesisApp {
    doc: Document,
    session: SimSession,
    playback: Playback,
    camera: OrbitCamera,
    /// The camera has been framed on the flower once.
    framed: bool,
    /// The camera as the first framing left it, until the run finishes:
    /// if the user has not moved it by then, it is framed on the open
    /// flower.
    auto_camera: Option<OrbitCamera>,
    view: ViewOptions,
    settings: Settings,
    /// Index into the project's organs.
    selected_organ: usize,
    single_organ_preview: bool,
    log: Log,
    dialogs: Dialogs,
    export: ExportDialog,
    paint: PaintState,
    /// An action waiting for "save changes?".
    pending: Option<Pending>,
    /// Closing was confirmed; let the window close.
    may_close: bool,
    /// The project changed since the last run started.
    needs_run: bool,
    /// The viewport's GPU state is installed.
    has_gpu: bool,
    /// Increments whenever the scene is rebuilt.
    scene_revision: u64,
    /// The selected organ's outline, kept between frames.
    outline: viewport::Outline,
    title: String,
    ctx: egui::Context,
}

impl AnthesisApp {
    pub fn new(cc: &eframe::CreationContext<'_>, startup: Startup) -> AnthesisApp {
        let ctx = cc.egui_ctx.clone();
        let settings: Settings = if startup.restore {
            cc.storage
                .and_then(|s| eframe::get_value(s, SETTINGS_KEY))
                .unwrap_or_default()
        } else {
            Settings::default()
        };
        let mut log = Log::default();
        let has_gpu = match &cc.wgpu_render_state {
            Some(render_state) => {
                ViewportGpu::install(render_state);
                true
            }
            None => {
                log.error("no wgpu renderer: the 3D viewport is off");
                false
            }
        };
        let session = if startup.live {
            let wake = ctx.clone();
            match SimSession::with_worker(move || wake.request_repaint()) {
                Ok(session) => session,
                Err(e) => {
                    log.error(format!("cannot start the simulation thread: {e}"));
                    SimSession::recorded()
                }
            }
        } else {
            SimSession::recorded()
        };
        let (project, path) = match startup.project {
            Some(given) => given,
            None => match &settings.last_project {
                Some(path) => match load_project(path) {
                    Ok(project) => (project, Some(path.clone())),
                    Err(e) => {
                        log.warn(format!("could not reopen the last project: {e}"));
                        (default_project(), None)
                    }
                },
                None => (default_project(), None),
            },
        };
        let playback = Playback {
            looping: settings.looping,
            speed: settings.speed,
            ..Playback::default()
        };
        let mut app = AnthesisApp {
            doc: Document::new(project, path),
            session,
            playback,
            camera: settings.camera.unwrap_or_default(),
            framed: settings.camera.is_some(),
            auto_camera: None,
            view: settings.view,
            single_organ_preview: settings.single_organ_preview,
            settings,
            selected_organ: 0,
            log,
            dialogs: Dialogs::default(),
            export: ExportDialog::default(),
            paint: PaintState::default(),
            pending: None,
            may_close: false,
            needs_run: true,
            has_gpu,
            scene_revision: 0,
            outline: viewport::Outline::default(),
            title: String::new(),
            ctx,
        };
        app.log.info(format!("opened {}", app.doc.title()));
        app
    }

    pub fn document(&self) -> &Document {
        &self.doc
    }

    pub fn project(&self) -> &Project {
        self.doc.project()
    }

    pub fn session(&self) -> &SimSession {
        &self.session
    }

    /// For tests and recordings: feed events to a session without worker.
    pub fn session_mut(&mut self) -> &mut SimSession {
        &mut self.session
    }

    pub fn playback(&self) -> &Playback {
        &self.playback
    }

    pub fn playback_mut(&mut self) -> &mut Playback {
        &mut self.playback
    }

    pub fn view_options(&self) -> &ViewOptions {
        &self.view
    }

    pub fn view_options_mut(&mut self) -> &mut ViewOptions {
        &mut self.view
    }

    pub fn camera_mut(&mut self) -> &mut OrbitCamera {
        &mut self.camera
    }

    pub fn export_dialog(&self) -> &ExportDialog {
        &self.export
    }

    pub fn log(&self) -> &Log {
        &self.log
    }

    pub fn selected_organ(&self) -> usize {
        self.selected_organ
    }

    pub fn select_organ(&mut self, organ: usize) {
        if organ < self.project().flower.organs.len() && organ != self.selected_organ {
            self.selected_organ = organ;
            if self.single_organ_preview {
                self.needs_run = true;
            }
        }
    }

    /// The template of the selected organ.
    pub fn selected_template(&self) -> usize {
        self.project()
            .flower
            .organs
            .get(self.selected_organ)
            .map_or(0, |o| o.template)
    }

    pub fn paint_mut(&mut self) -> &mut PaintState {
        &mut self.paint
    }

    pub fn single_organ_preview(&self) -> bool {
        self.single_organ_preview
    }

    pub fn set_single_organ_preview(&mut self, on: bool) {
        if on != self.single_organ_preview {
            self.single_organ_preview = on;
            self.needs_run = true;
        }
    }

    pub fn pending(&self) -> Option<&Pending> {
        self.pending.as_ref()
    }

    /// Which organs the next run simulates.
    pub fn selection(&self) -> Selection {
        if self.single_organ_preview {
            Selection::Only(self.selected_organ)
        } else {
            Selection::All
        }
    }

    /// Starts simulating the project as it is now (cancelling the running
    /// job), and follows the new keyframes.
    pub fn restart_simulation(&mut self) {
        let project = Arc::new(self.doc.project().clone());
        self.session.start(project, self.selection());
        self.needs_run = false;
        if self.session.is_live() {
            self.playback.follow = true;
        }
    }

    /// Applies an edit as one undo step (see [`Document::edit`]).
    pub fn edit(&mut self, label: &str, change: impl FnOnce(&mut Project)) {
        if self.doc.edit(label, change) {
            self.needs_run = true;
        }
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

    /// Asks for `action`, or first whether to save unsaved changes.
    pub fn request(&mut self, action: Pending) {
        if self.doc.is_dirty() {
            self.pending = Some(action);
        } else {
            self.perform(action);
        }
    }

    /// Carries out `action` without asking.
    fn perform(&mut self, action: Pending) {
        match action {
            Pending::New => {
                self.replace_document(Document::new(default_project(), None));
            }
            Pending::Open(Some(path)) => self.open_path(&path),
            Pending::Open(None) => {
                let folder = self.project_folder();
                let wake = self.ctx.clone();
                self.dialogs
                    .open(DialogPurpose::OpenProject, folder.as_deref(), move || {
                        wake.request_repaint()
                    });
            }
            Pending::Quit => {
                self.may_close = true;
                self.ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            }
        }
    }

    /// Opens the project at `path`; on failure the current work stays and
    /// the error is shown.
    pub fn open_path(&mut self, path: &Path) {
        match load_project(path) {
            Ok(project) => {
                self.settings.remember(path);
                self.replace_document(Document::new(project, Some(path.to_path_buf())));
                self.log.info(format!("opened {}", path.display()));
            }
            Err(e) => {
                self.log.error(format!("cannot open the project: {e}"));
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
                let name = self.project().flower.templates[template].name.clone();
                self.edit(&format!("mesh of {name}"), |p| {
                    p.flower.templates[template].mesh = mesh;
                });
                self.doc.seal();
                self.log
                    .info(format!("{name} now uses the mesh of {}", path.display()));
            }
            Err(e) => self
                .log
                .error(format!("cannot use {} as a mesh: {e}", path.display())),
        }
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
            brush::PaintTarget::Scalar(kind) => anthesis_maps::ScalarMap::load_png(path)
                .map_err(|e| e.to_string())
                .and_then(|map| fits(map.size()).map(|()| map))
                .map(|map| {
                    Box::new(move |maps: &mut anthesis_maps::GrowthMaps| {
                        *maps.scalar_mut(kind) = map;
                    }) as Box<dyn FnOnce(&mut anthesis_maps::GrowthMaps)>
                }),
            brush::PaintTarget::Direction => anthesis_maps::DirectionMap::load_png(path)
                .map_err(|e| e.to_string())
                .and_then(|map| fits(map.size()).map(|()| map))
                .map(|map| {
                    Box::new(move |maps: &mut anthesis_maps::GrowthMaps| maps.direction = map)
                        as Box<dyn FnOnce(&mut anthesis_maps::GrowthMaps)>
                }),
        };
        match loaded {
            Ok(apply) => {
                let name = self.project().flower.templates[template].name.clone();
                self.edit(&format!("{} map of {name}", target.label()), |p| {
                    if let Some(k) = p.flower.templates[template].maps.keys_mut().get_mut(key) {
                        apply(&mut k.maps);
                    }
                });
                self.doc.seal();
                self.log.info(format!(
                    "loaded the {} map of {name} from {}",
                    target.label(),
                    path.display()
                ));
            }
            Err(e) => self
                .log
                .error(format!("cannot use {} as a map: {e}", path.display())),
        }
    }

    fn replace_document(&mut self, doc: Document) {
        self.doc = doc;
        self.selected_organ = 0;
        self.framed = false;
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
        let folder = self.project_folder();
        let wake = self.ctx.clone();
        self.dialogs
            .open(DialogPurpose::SaveProjectAs, folder.as_deref(), move || {
                wake.request_repaint()
            });
    }

    /// Writes the project to `path`; errors are shown, the work stays.
    pub fn save_to(&mut self, path: &Path) -> bool {
        match save_project(self.doc.project(), path) {
            Ok(()) => {
                self.doc.mark_saved(path.to_path_buf());
                self.settings.remember(path);
                self.log.info(format!("saved {}", path.display()));
                true
            }
            Err(e) => {
                self.log.error(format!("cannot save: {e}"));
                false
            }
        }
    }

    fn handle_dialog_answers(&mut self) {
        let Some((purpose, answer)) = self.dialogs.poll() else {
            return;
        };
        let Some(path) = answer else {
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
        }
    }

    /// Shows the export dialog, suggesting a .glb beside the project.
    pub fn open_export(&mut self) {
        self.export.open = true;
        if self.export.path.trim().is_empty() {
            let folder = self.project_folder().unwrap_or_default();
            let stem: String = self
                .project()
                .name
                .chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() || c == '-' {
                        c
                    } else {
                        '_'
                    }
                })
                .collect();
            self.export.path = folder.join(format!("{stem}.glb")).display().to_string();
        }
    }

    fn start_export(&mut self) {
        let tracks = export::tracks(
            self.doc.project(),
            self.session.organs(),
            self.session.keyframes(),
        );
        let wake = self.ctx.clone();
        self.export.start(tracks, move || wake.request_repaint());
    }

    fn drain_worker(&mut self) {
        let drained = self.session.drain(DRAIN_BUDGET);
        for failure in drained.failures {
            self.log.error(format!("the simulation stopped: {failure}"));
        }
        if let Some(end) = self.export.poll() {
            match end {
                export::ExportState::Done { path, bytes } => self.log.info(format!(
                    "exported {} ({:.1} MB)",
                    path.display(),
                    bytes as f64 / 1e6
                )),
                export::ExportState::Failed { message } => {
                    self.log.error(format!("export failed: {message}"))
                }
                _ => {}
            }
        }
    }

    /// Keyboard shortcuts, unless a text field has the keyboard.
    fn shortcuts(&mut self, ctx: &egui::Context) {
        let command = |key| KeyboardShortcut::new(Modifiers::COMMAND, key);
        let command_shift = |key| KeyboardShortcut::new(Modifiers::COMMAND | Modifiers::SHIFT, key);
        let consume = |shortcut: KeyboardShortcut| ctx.input_mut(|i| i.consume_shortcut(&shortcut));
        // Shift variants first: Ctrl+Shift+Z also matches Ctrl+Z. A text
        // field that has the keyboard keeps Ctrl+Z for itself.
        if !ctx.egui_wants_keyboard_input() {
            if consume(command_shift(Key::Z)) || consume(command(Key::Y)) {
                self.redo();
            }
            if consume(command(Key::Z)) {
                self.undo();
            }
        }
        if consume(command_shift(Key::S)) {
            self.save_as();
        }
        if consume(command(Key::S)) {
            self.save();
        }
        if consume(command(Key::O)) {
            self.request(Pending::Open(None));
        }
        if consume(command(Key::N)) {
            self.request(Pending::New);
        }
        if consume(command(Key::E)) {
            self.open_export();
        }
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        let computed = self.session.last_index();
        let pressed = |key| ctx.input_mut(|i| i.consume_key(Modifiers::NONE, key));
        if pressed(Key::Space) {
            self.playback.toggle_play(computed);
        }
        if pressed(Key::ArrowLeft) {
            self.playback.step(-1, computed);
        }
        if pressed(Key::ArrowRight) {
            self.playback.step(1, computed);
        }
        if pressed(Key::Home) {
            self.playback.go_to_start();
        }
        if pressed(Key::End) {
            self.playback.go_to_end(computed);
        }
        if pressed(Key::F) {
            self.frame_all();
        }
        if pressed(Key::W) {
            self.view.wireframe = !self.view.wireframe;
        }
        if pressed(Key::P) {
            self.set_single_organ_preview(!self.single_organ_preview);
        }
    }

    pub fn frame_all(&mut self) {
        let scene = viewport::build_scene(
            self.doc.project(),
            &self.session,
            self.playback.time_in_keyframes,
            self.view.show_others || !self.single_organ_preview,
        );
        if let Some(bounds) = viewport::scene_bounds(&scene) {
            self.camera.frame(bounds);
        }
    }

    fn menu_bar(&mut self, ui: &mut egui::Ui) {
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                if ui.button("New").clicked() {
                    self.request(Pending::New);
                }
                if ui.button("Open…  (Ctrl+O)").clicked() {
                    self.request(Pending::Open(None));
                }
                ui.menu_button("Open recent", |ui| {
                    if self.settings.recent.is_empty() {
                        ui.label("(none yet)");
                    }
                    for path in self.settings.recent.clone() {
                        if ui.button(path.display().to_string()).clicked() {
                            self.request(Pending::Open(Some(path)));
                        }
                    }
                });
                ui.separator();
                if ui.button("Save  (Ctrl+S)").clicked() {
                    self.save();
                }
                if ui.button("Save as…  (Ctrl+Shift+S)").clicked() {
                    self.save_as();
                }
                ui.separator();
                if ui.button("Export animation…  (Ctrl+E)").clicked() {
                    self.open_export();
                }
                ui.separator();
                if ui.button("Quit").clicked() {
                    self.request(Pending::Quit);
                }
            });
            ui.menu_button("Edit", |ui| {
                let undo = self.doc.undo_label().map(|l| format!("Undo {l}  (Ctrl+Z)"));
                if ui
                    .add_enabled(
                        undo.is_some(),
                        egui::Button::new(undo.unwrap_or_else(|| "Undo".into())),
                    )
                    .clicked()
                {
                    self.undo();
                }
                let redo = self
                    .doc
                    .redo_label()
                    .map(|l| format!("Redo {l}  (Ctrl+Shift+Z)"));
                if ui
                    .add_enabled(
                        redo.is_some(),
                        egui::Button::new(redo.unwrap_or_else(|| "Redo".into())),
                    )
                    .clicked()
                {
                    self.redo();
                }
            });
            ui.menu_button("View", |ui| {
                ui.checkbox(&mut self.view.wireframe, "Wireframe  (W)");
                ui.checkbox(&mut self.view.direction_arrows, "Growth direction arrows");
                ui.checkbox(
                    &mut self.view.show_others,
                    "Other organs as buds in preview",
                );
                ui.menu_button("Map overlay", |ui| {
                    ui.radio_value(&mut self.view.overlay, None, "none");
                    for kind in anthesis_maps::MapKind::ALL {
                        ui.radio_value(&mut self.view.overlay, Some(kind), kind.label());
                    }
                });
                if ui.button("Frame all  (F)").clicked() {
                    self.frame_all();
                }
                ui.checkbox(&mut self.settings.show_log, "Log panel");
            });
        });
    }

    /// The left panel: organs, preview switch and the parameters.
    fn organs_panel(&mut self, ui: &mut egui::Ui) {
        ui.heading("Organs");
        let organs: Vec<String> = self
            .project()
            .flower
            .organs
            .iter()
            .map(|o| o.name.clone())
            .collect();
        egui::ScrollArea::vertical()
            .id_salt("organ list")
            .max_height(160.0)
            .show(ui, |ui| {
                for (i, name) in organs.iter().enumerate() {
                    if ui
                        .selectable_label(i == self.selected_organ, name)
                        .on_hover_text("Select this organ (or click it in the viewport)")
                        .clicked()
                    {
                        self.select_organ(i);
                    }
                }
            });
        let mut preview = self.single_organ_preview;
        if ui
            .checkbox(&mut preview, "Single-organ preview  (P)")
            .on_hover_text(
                "Simulate only the selected organ, without collisions: much faster while \
                 painting. Off: the whole flower with collisions.",
            )
            .changed()
        {
            self.set_single_organ_preview(preview);
        }
        ui.separator();
        let template = self.selected_template();
        egui::ScrollArea::vertical()
            .id_salt("parameters")
            .show(ui, |ui| {
                if params::parameters_ui(ui, &mut self.doc, template) {
                    self.needs_run = true;
                }
            });
    }

    /// "Save changes?" before an action that would lose them.
    fn unsaved_prompt(&mut self, ctx: &egui::Context) {
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
                    answer = Some("save");
                }
                if ui.button("Don't save").clicked() {
                    answer = Some("discard");
                }
                if ui.button("Cancel").clicked() {
                    answer = Some("cancel");
                }
            });
        });
        match answer {
            Some("save") => {
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
            Some("discard") => {
                self.pending = None;
                self.perform(action);
            }
            Some(_) => self.pending = None,
            None => {}
        }
    }

    fn central(&mut self, ui: &mut egui::Ui) {
        self.log.banner_ui(ui);
        let show_others = self.view.show_others || !self.single_organ_preview;
        let scene = viewport::build_scene(
            self.doc.project(),
            &self.session,
            self.playback.time_in_keyframes,
            show_others,
        );
        if !self.framed
            && self.session.last_index().is_some()
            && let Some((lo, hi)) = viewport::scene_bounds(&scene)
        {
            // The open flower is wider than the bud: leave room.
            let centre = 0.5 * (lo + hi);
            let half = 0.5 * (hi - lo);
            let room = glam::DVec3::new(half.y.max(half.x), half.y, half.y.max(half.z)) * 1.3;
            self.camera.frame((centre - room, centre + room));
            self.framed = true;
            self.auto_camera = Some(self.camera);
        }
        if let Some(auto) = self.auto_camera
            && matches!(self.session.status(), session::RunStatus::Finished { .. })
        {
            if auto == self.camera {
                let last = f64::from(self.session.last_index().unwrap_or(0));
                let open =
                    viewport::build_scene(self.doc.project(), &self.session, last, show_others);
                let bounds = [
                    viewport::scene_bounds(&scene),
                    viewport::scene_bounds(&open),
                ]
                .into_iter()
                .flatten()
                .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)));
                if let Some(bounds) = bounds {
                    self.camera.frame(bounds);
                }
            }
            self.auto_camera = None;
        }
        let overlay = self.view.overlay.map(|kind| (kind, self.paint.key));
        let meshes = Arc::new(viewport::scene_meshes(
            self.doc.project(),
            &scene,
            Some(self.selected_organ),
            overlay,
        ));
        self.scene_revision += 1;
        if !self.has_gpu {
            ui.label("The 3D viewport needs the wgpu renderer.");
            return;
        }
        let outline = self.outline.edges_of(
            &self
                .doc
                .project()
                .flower
                .template_of(self.selected_organ)
                .mesh,
        );
        let response = viewport::viewport_ui(
            ui,
            &mut self.camera,
            self.doc.project(),
            &scene,
            meshes,
            self.scene_revision,
            &self.view,
            Some((self.selected_organ, outline)),
            Some(self.paint.key),
            self.paint.on_3d,
        );
        let template = self.selected_template();
        match response.painting {
            Some(hit) if self.project().flower.organs[hit.organ].template == template => {
                if self.paint.dab(&mut self.doc, template, hit.point_in_uv) {
                    self.needs_run = true;
                }
            }
            _ => {
                if let Some(hit) = response.clicked {
                    self.select_organ(hit.organ);
                }
            }
        }
    }

    fn update_title(&mut self, ctx: &egui::Context) {
        let title = format!("{} — Anthesis", self.doc.title());
        if title != self.title {
            ctx.send_viewport_cmd(egui::ViewportCommand::Title(title.clone()));
            self.title = title;
        }
    }

    fn handle_close_request(&mut self, ctx: &egui::Context) {
        if ctx.input(|i| i.viewport().close_requested()) && !self.may_close && self.doc.is_dirty() {
            ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
            self.pending = Some(Pending::Quit);
        }
    }
}

impl eframe::App for AnthesisApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.handle_dialog_answers();
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .filter(|p| !p.as_os_str().is_empty())
                .collect()
        });
        for path in dropped {
            self.drop_file(&path);
        }
        self.drain_worker();
        self.handle_close_request(&ctx);
        self.shortcuts(&ctx);
        if ctx.input(|i| i.pointer.any_released()) {
            self.doc.seal();
            self.paint.end_stroke();
        }

        let dt = f64::from(ctx.input(|i| i.stable_dt)).min(0.1);
        self.playback
            .advance(dt, self.session.last_index(), self.session.total());

        egui::Panel::top("menu").show(ui, |ui| self.menu_bar(ui));
        egui::Panel::bottom("timeline")
            .resizable(false)
            .show(ui, |ui| {
                let requests = timeline::timeline_ui(ui, &mut self.playback, &self.session);
                if requests.stop {
                    self.session.cancel();
                    self.log.info("simulation stopped");
                }
                if requests.resimulate {
                    self.needs_run = true;
                }
            });
        if self.settings.show_log {
            egui::Panel::bottom("log")
                .resizable(true)
                .default_size(110.0)
                .show(ui, |ui| self.log.ui(ui));
        }
        egui::Panel::left("organs")
            .resizable(true)
            .default_size(270.0)
            .show(ui, |ui| self.organs_panel(ui));
        egui::Panel::right("paint")
            .resizable(true)
            .default_size(340.0)
            .show(ui, |ui| {
                let template = self.selected_template();
                if self.paint.ui(ui, &mut self.doc, template) {
                    self.needs_run = true;
                }
            });
        egui::CentralPanel::no_frame().show(ui, |ui| self.central(ui));

        let requests = self
            .export
            .ui(&ctx, self.session.keyframes().len(), self.session.total());
        if requests.browse {
            let folder = self.project_folder();
            let wake = ctx.clone();
            self.dialogs
                .open(DialogPurpose::ExportGlb, folder.as_deref(), move || {
                    wake.request_repaint()
                });
        }
        if requests.export {
            self.start_export();
        }
        self.unsaved_prompt(&ctx);

        if self.needs_run {
            self.restart_simulation();
        }
        self.update_title(&ctx);
        if self.playback.playing {
            ctx.request_repaint();
        } else if self.session.is_running() || self.export.is_running() {
            // The worker wakes the window on every event; this keeps the
            // elapsed time moving without drawing (and taking a core from
            // the solver) at full frame rate.
            ctx.request_repaint_after(std::time::Duration::from_millis(250));
        }
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        self.settings.last_project = self.doc.path.clone();
        self.settings.view = self.view;
        self.settings.camera = Some(self.camera);
        self.settings.single_organ_preview = self.single_organ_preview;
        self.settings.looping = self.playback.looping;
        self.settings.speed = self.playback.speed;
        eframe::set_value(storage, SETTINGS_KEY, &self.settings);
    }
}

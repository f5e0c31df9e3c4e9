//! The desktop window: an eframe application over the engine.
//!
//! This module holds the app's state ([`AnthesisApp`]: the open
//! [`Document`], the simulation [`SimSession`], playback, view and dialogs)
//! and the frame loop. What the user asks for becomes a [`Command`],
//! applied in [`command`]; the rest is split by concern: project files in
//! `project_io`, the menu bar and shortcuts in `menus`, the panels in
//! `panels` (each panel's widgets in its own module: `params`, `paint`,
//! `timeline`, `export`), the "save changes?" prompt in `prompts`, camera
//! framing in `framing`. No engine logic lives here: simulation, maps,
//! project files and export are the engine crates'.

pub mod autosave;
mod background;
pub mod bud_sketch;
pub mod checked_field;
pub mod command;
mod difference;
pub mod document;
pub mod export;
pub mod files;
pub mod fit;
pub mod flower_panel;
mod framing;
mod gallery;
pub mod log;
pub mod measure_panel;
mod menus;
pub mod paint;
mod panels;
pub mod params;
pub mod parts_panel;
pub mod pde_panel;
mod project_io;
mod prompts;
pub mod rerun;
pub mod resolution;
pub mod scan_panel;
pub mod session;
pub mod settings;
pub mod shape_panel;
pub mod sketch_panel;
pub mod timeline;
pub mod two_state;
pub mod viewport;
pub mod widgets;
pub mod words;

use std::path::PathBuf;
use std::sync::Arc;

use anthesis_flower::Project;
use anthesis_flower::project::load_project_with_warnings;
use anthesis_sim::Selection;
use anyhow::{Result, anyhow};
use eframe::egui;

use anthesis_flower::project::recovery::RecoveryFolder;
use anthesis_render::OrbitCamera;
pub use command::{Command, ProjectEdit};
use document::Document;
use export::ExportDialog;
use files::Dialogs;
use log::{Log, Topic};
use paint::PaintState;
use session::{DRAIN_BUDGET, SimSession};
use settings::Settings;
use timeline::Playback;
use viewport::{ViewOptions, ViewportGpu};

/// The flower shown at first launch and by File → New: the Asiatic lily
/// embedded in the binary or, should this build lack it, the same lily
/// built by `anthesis-garden`.
pub fn default_project() -> Result<Project> {
    anthesis_garden::builtin_lily().or_else(|embedded| {
        anthesis_garden::flowers::lily().map_err(|built| {
            anyhow!("no default flower: the embedded lily: {embedded}; building it: {built}")
        })
    })
}

/// The name eframe keeps the app's data under (settings, and the
/// recovery folder beside them).
const APP_ID: &str = "Anthesis";

/// The environment variable that sets the autosave interval in seconds
/// (over the settings' `autosave_seconds`), e.g. for a crash test.
const AUTOSAVE_VARIABLE: &str = "ANTHESIS_AUTOSAVE_SECONDS";

/// How often unsaved work is saved for recovery, at most.
fn autosave_interval(settings: &Settings) -> std::time::Duration {
    let seconds = std::env::var(AUTOSAVE_VARIABLE)
        .ok()
        .and_then(|text| text.trim().parse::<u64>().ok())
        .unwrap_or(settings.autosave_seconds);
    std::time::Duration::from_secs(seconds)
}

/// How soon after the worker wakes the window it draws: not at once, since
/// egui answers `request_repaint` with two frames ("to give some things
/// time to settle") and a delayed request with one, and each frame takes
/// about 0.1 s of a core from the solver on a software renderer.
const WAKE_DELAY: std::time::Duration = std::time::Duration::from_millis(1);

/// The key under which [`Settings`] are stored.
const SETTINGS_KEY: &str = "anthesis-settings";

/// Opens the window, on `project` (and the file it came from) if given,
/// else as [`Startup::default`], with `warnings`, what loading the project
/// read past, in the log; returns when it is closed.
pub fn run(project: Option<(Project, Option<PathBuf>)>, warnings: Vec<String>) -> Result<()> {
    let options = eframe::NativeOptions {
        // eframe makes the window no larger than the largest monitor (and
        // a size restored from the last launch too); the first frame
        // maximises it where even that leaves no room for the window's
        // frame ([`too_large_for`]).
        viewport: egui::ViewportBuilder::default()
            .with_title("Anthesis")
            .with_inner_size(DEFAULT_WINDOW_SIZE)
            .with_min_inner_size([800.0, 500.0])
            .with_clamp_size_to_monitor_size(true),
        renderer: eframe::Renderer::Wgpu,
        ..Default::default()
    };
    eframe::run_native(
        APP_ID,
        options,
        Box::new(|cc| {
            let startup = Startup {
                project,
                warnings,
                ..Startup::default()
            };
            let mut app = AnthesisApp::new(cc, startup).map_err(|e| e.to_string())?;
            match eframe::storage_dir(APP_ID) {
                Some(data) => app.enable_autosave(
                    RecoveryFolder::new(data.join("recovery")),
                    autosave_interval(&app.settings),
                ),
                None => app
                    .log
                    .warn("no data folder for this user: autosave is off; save your work often"),
            }
            Ok(Box::new(app))
        }),
    )
    .map_err(|e| anyhow!("cannot open the window: {e}"))
}

/// The window's size at the first launch, in points.
pub const DEFAULT_WINDOW_SIZE: [f32; 2] = [1400.0, 900.0];

/// Room a window's frame and the desktop's panels take, at most, in
/// points.
const WINDOW_FRAME_ROOM: f32 = 60.0;

/// Whether a window of `inner` size (points) leaves no room for its frame
/// and the desktop's panels on a monitor of `monitor` size: then it is
/// maximised, which fits it to the monitor's work area.
pub fn too_large_for(inner: egui::Vec2, monitor: egui::Vec2) -> bool {
    inner.x + WINDOW_FRAME_ROOM > monitor.x || inner.y + WINDOW_FRAME_ROOM > monitor.y
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
    /// What loading `project` read past (a mesh wound inside out, loose
    /// edges), shown in the log as File → Open shows it.
    pub warnings: Vec<String>,
}

impl Default for Startup {
    fn default() -> Self {
        Startup {
            project: None,
            live: true,
            restore: true,
            warnings: Vec::new(),
        }
    }
}

pub use prompts::Pending;

/// What the left panel shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LeftTab {
    /// The selected organ's template: parameters and resolution.
    Organ,
    /// The whole flower: templates, arrangement, organs, overlap order,
    /// parts.
    Flower,
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
    fit: fit::FitDialog,
    paint: PaintState,
    /// An action waiting for "save changes?".
    pending: Option<Pending>,
    /// A dropped mesh that looks made in another unit, waiting for the
    /// user's choice.
    unit_offer: Option<prompts::UnitOffer>,
    /// Closing was confirmed; let the window close.
    may_close: bool,
    /// The project changed since the last run started.
    needs_run: bool,
    /// Restart pacing while painting.
    rerun: rerun::Rerun,
    /// The viewport's GPU state is installed.
    has_gpu: bool,
    /// The viewport's scene, rebuilt only when what it shows changes.
    scene: viewport::SceneCache,
    /// The selected organ's outline, kept between frames.
    outline: viewport::Outline,
    /// The project at its resolution, as simulated and shown.
    resolved: resolution::Resolved,
    /// Commands the panels asked for this frame, applied after drawing.
    queued: Vec<Command>,
    /// The Help → Shortcuts window is open.
    show_shortcuts: bool,
    /// Help → Getting started and About.
    help: menus::HelpWindows,
    /// The window has been checked against the monitor's size once.
    fitted_to_monitor: bool,
    /// What the left panel shows: the selected organ's parameters or the
    /// whole flower.
    left_tab: LeftTab,
    /// The Flower panel's L-system text and choices.
    flower_panel: flower_panel::FlowerPanelState,
    /// File → New: the starting points and their pictures.
    gallery: gallery::Gallery,
    /// Writes unsaved work for recovery (off until enabled).
    autosave: Option<autosave::Autosave>,
    /// Work recovered after a crash, waiting for "recover or discard?".
    recovery_offer: Option<anthesis_flower::project::recovery::Recovery>,
    title: String,
    ctx: egui::Context,
}

impl AnthesisApp {
    /// The app as `startup` asks. Fails only when there is no project to
    /// show: none given, none to reopen and no default flower.
    pub fn new(cc: &eframe::CreationContext<'_>, startup: Startup) -> Result<AnthesisApp> {
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
            // One frame per wake (see `WAKE_DELAY`).
            match SimSession::with_worker(move || wake.request_repaint_after(WAKE_DELAY)) {
                Ok(session) => session,
                Err(e) => {
                    log.error(format!("cannot start the simulation thread: {e}"));
                    SimSession::recorded()
                }
            }
        } else {
            SimSession::recorded()
        };
        for warning in startup.warnings {
            log.warn(warning);
        }
        let (project, path) = match startup.project {
            Some(given) => given,
            None => match &settings.last_project {
                Some(path) => match load_project_with_warnings(path) {
                    Ok(loaded) => {
                        let note = anthesis_flower::unit::note_if_unstated(&loaded.project);
                        for warning in loaded.warnings.into_iter().chain(note) {
                            log.warn(warning);
                        }
                        (loaded.project, Some(path.clone()))
                    }
                    Err(e) => {
                        log.warn(format!("could not reopen the last project: {e}"));
                        (default_project()?, None)
                    }
                },
                None => (default_project()?, None),
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
            fit: fit::FitDialog::default(),
            paint: PaintState::default(),
            pending: None,
            unit_offer: None,
            may_close: false,
            needs_run: true,
            rerun: rerun::Rerun::default(),
            has_gpu,
            scene: viewport::SceneCache::default(),
            outline: viewport::Outline::default(),
            resolved: resolution::Resolved::default(),
            queued: Vec::new(),
            show_shortcuts: false,
            help: menus::HelpWindows::default(),
            fitted_to_monitor: false,
            left_tab: LeftTab::Organ,
            flower_panel: flower_panel::FlowerPanelState::default(),
            gallery: gallery::Gallery::default(),
            autosave: None,
            recovery_offer: None,
            title: String::new(),
            ctx,
        };
        app.log.info(format!("opened {}", app.doc.title()));
        Ok(app)
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

    pub fn export_dialog_mut(&mut self) -> &mut ExportDialog {
        &mut self.export
    }

    pub fn fit_dialog(&self) -> &fit::FitDialog {
        &self.fit
    }

    pub fn log(&self) -> &Log {
        &self.log
    }

    /// The Flower panel's state (its L-system text, for tests).
    pub fn flower_panel(&self) -> &flower_panel::FlowerPanelState {
        &self.flower_panel
    }

    pub fn selected_organ(&self) -> usize {
        self.selected_organ
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

    /// How many times the viewport's scene has been built (for tests and
    /// measurements).
    pub fn scene_rebuilds(&self) -> u64 {
        self.scene.builds()
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
    /// job), its proxy first where it has one. The playhead stays where it
    /// is: what was shown stays shown, marked stale, until the new run's
    /// proxy or converged keyframes reach it. `clock`: the frame clock
    /// (egui's input time) the restarts are paced on.
    fn start_run(&mut self, clock: f64) {
        let selection = self.selection();
        let project = self.resolved_project();
        // A run too large for the memory would be killed by the kernel,
        // taking the window and the user's work with it.
        if let Err(e) = anthesis_sim::memory::check_run(
            &project,
            &selection,
            anthesis_sim::memory::KeyframeCost::Editable,
        ) {
            self.log.error_about(
                Topic::Simulation,
                format!("the simulation did not start: {e}"),
            );
            self.needs_run = false;
            return;
        }
        let proxy = self.resolved.proxy().cloned();
        self.session.start_with_proxy(project, proxy, selection);
        self.needs_run = false;
        self.rerun.started(clock);
    }

    /// Starts the run the project's changes want, paced while the pointer
    /// is down (see [`rerun`]).
    fn run_if_needed(&mut self, ctx: &egui::Context) {
        if !self.needs_run {
            return;
        }
        let dragging = ctx.input(|i| i.pointer.any_down());
        let clock = ctx.input(|i| i.time);
        let wait = self.rerun.wait(dragging, clock);
        if wait.is_zero() {
            self.start_run(clock);
        } else {
            ctx.request_repaint_after(wait);
        }
    }

    /// The project as simulated and shown: the document's, every template
    /// at the project's resolution (remeshed when its mesh or the
    /// resolution changed; a template that cannot be remeshed stays as
    /// built and the log says why).
    pub fn resolved_project(&mut self) -> Arc<Project> {
        if let Some(problem) = self
            .resolved
            .update(self.doc.project(), self.doc.revision())
        {
            self.log.error_about(Topic::Resolution, problem);
        }
        if let Some(warning) = anthesis_flower::remesh_cache::installed().take_warning() {
            self.log.warn(warning);
        }
        match self.resolved.project() {
            Some(project) => Arc::clone(project),
            None => Arc::new(self.doc.project().clone()),
        }
    }

    /// Logs a run's failure as an error, adding the values the user chose
    /// that it may come from.
    pub fn report_run_failure(&mut self, failure: &str) {
        // A value the user chose at the end of its range is named.
        // And the values outside the range runs settle in (a failure
        // that is not the solver's, as a petal passing through itself,
        // does not say them), not again when the failure names them.
        let project = self.doc.project();
        let mut suspects: Vec<String> = project
            .flower
            .templates
            .iter()
            .flat_map(anthesis_sim::values_out_of_range)
            .collect();
        suspects.extend(checked_field::values_at_limits(project));
        suspects.retain(|s| !s.split(" of ").next().is_some_and(|v| failure.contains(v)));
        // One line per value and template ("thickness 0.001 of petal").
        let mut seen = std::collections::HashSet::new();
        suspects.retain(|s| seen.insert(s.split(" is ").next().map(|v| v.replace('`', ""))));
        let suspects = if suspects.is_empty() {
            String::new()
        } else {
            format!(" ({})", suspects.join("; "))
        };
        self.log.error_about(
            Topic::Simulation,
            format!("the simulation stopped: {failure}{suspects}"),
        );
    }

    fn drain_worker(&mut self) {
        let drained = self.session.drain(DRAIN_BUDGET);
        if drained.finished {
            self.log.succeeded(Topic::Simulation);
        }
        for note in drained.notes {
            self.log.info(note);
        }
        for warning in drained.warnings {
            self.log.warn(warning);
        }
        for failure in drained.failures {
            self.report_run_failure(&failure);
        }
        if let Some(end) = self.export.poll() {
            match end {
                export::ExportState::Done { path, bytes } => {
                    self.log.info(format!(
                        "exported {} ({:.1} MB)",
                        path.display(),
                        bytes as f64 / 1e6
                    ));
                    self.log.succeeded(Topic::Export);
                }
                export::ExportState::Failed { message } => self
                    .log
                    .error_about(Topic::Export, format!("export failed: {message}")),
                _ => {}
            }
        }
    }

    /// Once the monitor's size is known: a window too large for it is
    /// maximised (see [`too_large_for`]).
    fn fit_to_monitor(&mut self, ctx: &egui::Context) {
        if self.fitted_to_monitor {
            return;
        }
        let (monitor, inner) = ctx.input(|i| {
            let viewport = i.viewport();
            (viewport.monitor_size, viewport.inner_rect.map(|r| r.size()))
        });
        let (Some(monitor), Some(inner)) = (monitor, inner) else {
            return;
        };
        self.fitted_to_monitor = true;
        if too_large_for(inner, monitor) {
            ctx.send_viewport_cmd(egui::ViewportCommand::Maximized(true));
        }
    }

    fn update_title(&mut self, ctx: &egui::Context) {
        let title = format!("{} — Anthesis", self.doc.title());
        if title != self.title {
            ctx.send_viewport_cmd(egui::ViewportCommand::Title(title.clone()));
            self.title = title;
        }
    }
}

impl eframe::App for AnthesisApp {
    /// One frame: input that arrives outside the panels (dialog answers,
    /// dropped files, worker events, shortcuts) first, then the panels,
    /// then the commands they queued, then a new run if the project
    /// changed.
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
            self.apply(Command::DropFile(path));
        }
        self.drain_worker();
        for notice in checked_field::take_notices(&ctx) {
            self.log.warn(notice);
        }
        self.handle_close_request(&ctx);
        for command in self.shortcut_commands(&ctx) {
            self.apply(command);
        }
        if ctx.input(|i| i.pointer.any_released()) {
            self.doc.seal();
            self.paint.end_stroke();
        }

        // The time since the last frame while playing (egui's stable_dt
        // is that when the last frame asked for the next); Playback
        // bounds it.
        let dt = f64::from(ctx.input(|i| i.stable_dt));
        self.playback
            .advance(dt, self.session.shown_end(), self.session.total());
        let viewed = (!self.playback.playing && !self.playback.follow)
            .then(|| self.playback.time_in_keyframes.max(0.0).ceil() as u32);
        self.session.set_viewed_keyframe(viewed);

        egui::Panel::top("menu").show(ui, |ui| self.menu_bar(ui));
        egui::Panel::bottom("timeline")
            .resizable(false)
            .show(ui, |ui| self.timeline_panel(ui));
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
            .show(ui, |ui| self.paint_panel(ui));
        egui::CentralPanel::no_frame().show(ui, |ui| self.viewport_panel(ui));
        self.export_window(&ctx);
        self.fit_window(&ctx);
        self.history_window(&ctx);
        self.shortcuts_window(&ctx);
        self.help_windows(&ctx);
        self.gallery_window(&ctx);
        self.file_browser(&ctx);
        self.apply_queued();
        self.unsaved_prompt(&ctx);
        self.unit_prompt(&ctx);
        self.recovery_prompt(&ctx);
        self.autosave_tick(&ctx);

        self.run_if_needed(&ctx);
        self.update_title(&ctx);
        self.fit_to_monitor(&ctx);
        if self.playback.playing {
            ctx.request_repaint();
        } else if self.session.is_running() || self.export.is_running() {
            // The worker wakes the window for the viewed keyframe and a
            // run's start and end at once, for the rest at most every half
            // second (`anthesis_sim::worker::PROGRESS_WAKE_EVERY`); this
            // keeps the elapsed time moving through a long iteration. Each
            // redraw takes about 0.1 s of a core on a software renderer,
            // from the solver.
            ctx.request_repaint_after(std::time::Duration::from_millis(1000));
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

    /// A clean exit (the user answered any "save changes?"): the recovery
    /// files are no longer needed. Unless a recovery still waits for an
    /// answer: then it stays for the next launch.
    fn on_exit(&mut self) {
        if self.recovery_offer.is_none() {
            self.discard_recovery();
        }
        if let Some(autosave) = self.autosave.as_mut() {
            autosave.finish();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_window_is_maximised_only_where_its_frame_has_no_room() {
        let default = egui::Vec2::from(DEFAULT_WINDOW_SIZE);
        assert!(!too_large_for(default, egui::vec2(1920.0, 1080.0)));
        // eframe clamps 1400×900 to a 1280×800 monitor: no room left.
        assert!(too_large_for(
            egui::vec2(1280.0, 800.0),
            egui::vec2(1280.0, 800.0)
        ));
        assert!(too_large_for(default, egui::vec2(1440.0, 900.0)));
        assert!(!too_large_for(
            egui::vec2(1200.0, 700.0),
            egui::vec2(1280.0, 800.0)
        ));
    }
}

//! Edit → "Fit growth maps to a target…": the fit of `anthesis-fit` for the
//! selected organ, on a thread named `anthesis-fit`, with its progress
//! (iteration, RMS and largest distance) and a Cancel button; the fitted
//! maps replace the organ's template's maps as one undo step when the user
//! applies them. The target is any triangulated OBJ; with "Register" ticked
//! it is first put on the organ (`anthesis_fit::register_target`), and the
//! motion found is shown before the fit goes on.

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, sync_channel};

use anthesis_fit::{Fit, FitProgress, FitSettings, Registered, Similarity, Target};
use anthesis_flower::Project;
use anthesis_mesh::obj::MAX_OBJ_BYTES;
use anthesis_render::OrganMesh;
use eframe::egui;

use super::AnthesisApp;
use super::command::{Command, ProjectEdit};

/// The registered target's colour over the organ (linear RGBA, a cyan no
/// template uses).
const TARGET_COLOUR_LINEAR: [f32; 4] = [0.05, 0.6, 0.8, 1.0];

/// Where a fit stands.
#[derive(Debug, Clone)]
pub enum FitState {
    Idle,
    Running { progress: Option<FitProgress> },
    Done { fit: Box<Fit> },
    Failed { message: String },
    Cancelled,
}

enum Message {
    Registered(Registered),
    Progress(FitProgress),
    Done(Result<Fit, anthesis_fit::FitError>),
}

/// A fit on its thread: its messages, its cancel flag, and what it fits.
struct Job {
    receiver: Receiver<Message>,
    cancel: Arc<AtomicBool>,
}

/// The dialog's fields and the running fit.
pub struct FitDialog {
    pub open: bool,
    /// The target OBJ's path, as typed.
    pub target: String,
    /// Time keys of the fitted maps.
    pub keys: u32,
    /// Put the target on the organ first (a scan in its own frame).
    pub register: bool,
    /// With the registration, a uniform scale too.
    pub register_scale: bool,
    /// The registration of the running or last fit, if it had one.
    registered: Option<Registered>,
    /// The target of the running or last fit.
    target_surface: Option<Arc<Target>>,
    /// The registered target where the registration (or the fit's
    /// refinement) put it, as the viewport draws it over the organ, and
    /// the count of its changes (the viewport's scene key).
    overlay: Option<OrganMesh>,
    overlay_revision: u64,
    /// The organ fitted (index into the project's organs) and the
    /// document revision it was started on.
    started: Option<(usize, u64)>,
    state: FitState,
    job: Option<Job>,
}

impl Default for FitDialog {
    fn default() -> Self {
        FitDialog {
            open: false,
            target: String::new(),
            keys: 1,
            register: false,
            register_scale: false,
            registered: None,
            target_surface: None,
            overlay: None,
            overlay_revision: 0,
            started: None,
            state: FitState::Idle,
            job: None,
        }
    }
}

/// What the user asked of the dialog this frame.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct FitRequests {
    pub start: bool,
    pub apply: bool,
    /// Choose the target in a file dialog.
    pub browse: bool,
}

impl FitDialog {
    pub fn state(&self) -> &FitState {
        &self.state
    }

    /// The running or last fit's registration, if it had one.
    pub fn registered(&self) -> Option<&Registered> {
        self.registered.as_ref()
    }

    /// The registered target as the viewport draws it over the organ
    /// while the dialog is open (a cyan surface, so where it passes the
    /// organ shows): a number that changes with it (0: nothing shown) and
    /// the mesh.
    pub fn target_overlay(&self) -> (u64, Option<&OrganMesh>) {
        match &self.overlay {
            Some(mesh) if self.open => (self.overlay_revision, Some(mesh)),
            _ => (0, None),
        }
    }

    /// Shows the target at `placement` over the organ (`None`: nothing).
    fn set_overlay(&mut self, placement: Option<Similarity>) {
        self.overlay_revision += 1;
        self.overlay = match (placement, &self.target_surface) {
            (Some(placement), Some(target)) => {
                let positions: Vec<_> = target
                    .surface
                    .positions
                    .iter()
                    .map(|&x| placement.apply(x))
                    .collect();
                Some(OrganMesh::from_positions(
                    &positions,
                    &target.surface.triangles,
                    TARGET_COLOUR_LINEAR,
                ))
            }
            _ => None,
        };
    }

    pub fn is_running(&self) -> bool {
        self.job.is_some()
    }

    /// Starts fitting organ `organ` of `resolved` (the project at the
    /// resolution it is simulated at) to the OBJ at `target`; `revision`
    /// is the document's, so that the result is applied only to the
    /// project it was fitted on.
    pub fn start(
        &mut self,
        resolved: Arc<Project>,
        organ: usize,
        revision: u64,
        target: &Path,
    ) -> Result<(), String> {
        if self.is_running() {
            return Err("a fit is already running".into());
        }
        let organ_def = resolved
            .flower
            .organs
            .get(organ)
            .ok_or_else(|| format!("there is no organ {organ}"))?;
        let text = anthesis_files::read_regular_text(target, MAX_OBJ_BYTES, "an OBJ mesh")
            .map_err(|e| format!("cannot read the target {}: {e}", target.display()))?;
        let mesh = &resolved.flower.template_of(organ).mesh;
        let target_surface = Arc::new(
            anthesis_fit::read_target(&text, &organ_def.name, mesh)
                .map_err(|e| format!("target {}: {e}", target.display()))?,
        );
        self.target_surface = Some(Arc::clone(&target_surface));
        let register = self.register;
        let scale = self.register && self.register_scale;
        let settings = FitSettings {
            keys: self.keys.clamp(1, resolved.settings.keyframes + 1),
            refine_placement: register,
            ..FitSettings::default()
        };
        // One message per iteration and the result: the fit's iteration
        // limit keeps them well within the bound, and progress that would
        // not fit is dropped rather than waited for.
        let (sender, receiver) = sync_channel(64);
        let cancel = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&cancel);
        std::thread::Builder::new()
            .name("anthesis-fit".into())
            .spawn(move || {
                let progress_sender = sender.clone();
                let cancelled = || flag.load(Ordering::Relaxed);
                let placement = if register {
                    match anthesis_fit::register_target(
                        &resolved,
                        organ,
                        &target_surface,
                        scale,
                        &cancelled,
                    ) {
                        Ok(registered) => {
                            let _ = sender.send(Message::Registered(registered));
                            registered.registration.placement
                        }
                        Err(error) => {
                            let _ = sender.send(Message::Done(Err(error)));
                            return;
                        }
                    }
                } else {
                    anthesis_fit::Similarity::IDENTITY
                };
                let result = anthesis_fit::fit(
                    &resolved,
                    organ,
                    &target_surface,
                    placement,
                    &settings,
                    &mut |p| {
                        let _ = progress_sender.try_send(Message::Progress(p));
                    },
                    &cancelled,
                );
                let _ = sender.send(Message::Done(result));
            })
            .map_err(|e| format!("cannot start the fit: {e}"))?;
        self.job = Some(Job { receiver, cancel });
        self.registered = None;
        self.set_overlay(None);
        self.started = Some((organ, revision));
        self.state = FitState::Running { progress: None };
        Ok(())
    }

    /// Asks the running fit to stop (it ends within one simulation step).
    pub fn cancel(&self) {
        if let Some(job) = &self.job {
            job.cancel.store(true, Ordering::Relaxed);
        }
    }

    /// Takes what the fit thread sent; true when the fit ended this call.
    pub fn poll(&mut self) -> bool {
        let Some(job) = &self.job else {
            return false;
        };
        let mut ended = None;
        let mut placed = None;
        while let Ok(message) = job.receiver.try_recv() {
            match message {
                Message::Registered(registered) => placed = Some(registered),
                Message::Progress(p) => {
                    self.state = FitState::Running { progress: Some(p) };
                }
                Message::Done(result) => ended = Some(result),
            }
        }
        if ended.is_none()
            && matches!(
                job.receiver.try_recv(),
                Err(std::sync::mpsc::TryRecvError::Disconnected)
            )
        {
            ended = Some(Err(anthesis_fit::FitError::Target(
                "the fit stopped without a result".into(),
            )));
        }
        if let Some(registered) = placed {
            self.registered = Some(registered);
            self.set_overlay(Some(registered.registration.placement));
        }
        let Some(result) = ended else {
            return false;
        };
        self.job = None;
        if let (Ok(fit), Some(_)) = (&result, &self.registered) {
            // Where the fit's refinement left the registered target.
            self.set_overlay(Some(fit.placement));
        }
        self.state = match result {
            Ok(fit) => FitState::Done { fit: Box::new(fit) },
            Err(anthesis_fit::FitError::Cancelled) => FitState::Cancelled,
            Err(error) => FitState::Failed {
                message: error.to_string(),
            },
        };
        true
    }

    /// The edit that puts the fitted maps into `project`'s template of the
    /// fitted organ, if there is a result and `project` is still at the
    /// revision the fit started on.
    pub fn apply_edit(&self, project: &Project, revision: u64) -> Result<Command, String> {
        let FitState::Done { fit } = &self.state else {
            return Err("there is no fit to apply".into());
        };
        let Some((organ, started)) = self.started else {
            return Err("there is no fit to apply".into());
        };
        if started != revision {
            return Err(
                "the project changed while the fit ran; fit again to apply maps to it".into(),
            );
        }
        let template = project
            .flower
            .organs
            .get(organ)
            .map(|o| o.template)
            .ok_or("the fitted organ is gone")?;
        let mut value = project.flower.templates[template].clone();
        value.maps = fit.maps.clone();
        Ok(Command::Edit {
            label: "fit growth maps".into(),
            edit: ProjectEdit::Template {
                template,
                value: Box::new(value),
                keyframes: project.settings.keyframes,
            },
        })
    }

    /// The dialog window; returns what was asked.
    pub fn ui(&mut self, ctx: &egui::Context, organ_name: &str) -> FitRequests {
        let mut requests = FitRequests::default();
        if !self.open {
            return requests;
        }
        let mut open = self.open;
        egui::Window::new("Fit growth maps to a target")
            .open(&mut open)
            .resizable(false)
            .show(ctx, |ui| {
                ui.label(format!(
                    "Finds the growth maps of organ {organ_name}'s template whose simulation \
                     ends on the target: an OBJ surface of any triangulation, in the \
                     project's frame and units, or anywhere with Register ticked (a scan or \
                     a model in its own frame)."
                ));
                let running = self.is_running();
                ui.add_enabled_ui(!running, |ui| {
                    egui::Grid::new("fit-grid").num_columns(2).show(ui, |ui| {
                        let label = ui.label("Target OBJ").id;
                        ui.horizontal(|ui| {
                            ui.add(
                                egui::TextEdit::singleline(&mut self.target)
                                    .hint_text("/path/to/open.obj")
                                    .desired_width(300.0),
                            )
                            .labelled_by(label);
                            // As the export's path: typed, or chosen.
                            if ui
                                .button("Browse…")
                                .on_hover_text("Choose the target OBJ in a file dialog")
                                .clicked()
                            {
                                requests.browse = true;
                            }
                        });
                        ui.end_row();
                        let label = ui.label("Time keys").id;
                        super::checked_field::checked_with(
                            ui,
                            "time keys",
                            &mut self.keys,
                            1..=5,
                            |d| d,
                        )
                        .labelled_by(label);
                        ui.end_row();
                        ui.label("");
                        ui.checkbox(&mut self.register, "Register the target on the organ first")
                            .on_hover_text(
                                "The rigid motion that best lays the target on the organ's \
                                 current shape with its base on the organ's base",
                            );
                        ui.end_row();
                        ui.label("");
                        ui.add_enabled(
                            self.register,
                            egui::Checkbox::new(&mut self.register_scale, "… and its scale"),
                        );
                        ui.end_row();
                    });
                });
                ui.horizontal(|ui| {
                    if running {
                        if ui.button("Cancel").clicked() {
                            self.cancel();
                        }
                    } else if ui
                        .add_enabled(!self.target.trim().is_empty(), egui::Button::new("Fit"))
                        .clicked()
                    {
                        requests.start = true;
                    }
                    if matches!(self.state, FitState::Done { .. })
                        && ui.button("Apply the fitted maps").clicked()
                    {
                        requests.apply = true;
                    }
                });
                if let Some(registered) = &self.registered {
                    ui.label(registered.describe());
                }
                match &self.state {
                    FitState::Idle => {}
                    FitState::Running { progress: None } => {
                        ui.label("first guess…");
                    }
                    FitState::Running { progress: Some(p) } => {
                        ui.label(format!(
                            "iteration {}: RMS {:.2} %, max {:.2} % of the organ's length \
                             ({} simulations, {:.0} s)",
                            p.iteration,
                            100.0 * p.rms,
                            100.0 * p.max,
                            p.simulations,
                            p.seconds
                        ));
                    }
                    FitState::Done { fit } => {
                        ui.label(fit.verdict());
                    }
                    FitState::Failed { message } => {
                        ui.colored_label(ui.visuals().error_fg_color, message);
                    }
                    FitState::Cancelled => {
                        ui.label("cancelled");
                    }
                }
            });
        self.open = open;
        requests
    }
}

impl AnthesisApp {
    /// The fit dialog: starts a fit, follows it, applies its maps.
    pub(super) fn fit_window(&mut self, ctx: &egui::Context) {
        if self.fit.poll() {
            match self.fit.state() {
                FitState::Done { fit } => self.log.info(fit.verdict()),
                FitState::Failed { message } => self.log.warn(format!("fit: {message}")),
                _ => {}
            }
        }
        let organ = self.selected_organ;
        let name = self
            .doc
            .project()
            .flower
            .organs
            .get(organ)
            .map_or_else(String::new, |o| o.name.clone());
        let requests = self.fit.ui(ctx, &name);
        if requests.browse {
            self.ask_for_path(super::files::DialogPurpose::FitTarget);
        }
        if requests.start {
            let resolved = self.resolved_project();
            let revision = self.doc.revision();
            let target = std::path::PathBuf::from(self.fit.target.trim());
            if let Err(message) = self.fit.start(resolved, organ, revision, &target) {
                self.fit.state = FitState::Failed { message };
            }
        }
        if requests.apply {
            match self.fit.apply_edit(self.doc.project(), self.doc.revision()) {
                Ok(command) => self.queued.push(command),
                Err(message) => self.fit.state = FitState::Failed { message },
            }
        }
        if self.fit.is_running() {
            ctx.request_repaint_after(std::time::Duration::from_millis(200));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small petal whose final shape (keyframe 8) is written as OBJ.
    fn petal_and_target(dir: &Path) -> (Arc<Project>, std::path::PathBuf) {
        let mut project = anthesis_sim::fixtures::whorl(1, 6, 10, 8);
        project.flower.templates[0].dg = 0.03;
        let maps = project.flower.templates[0].maps.clone();
        let shape = anthesis_fit::simulate_final(&project, 0, maps, &|| false).expect("simulates");
        let mut text = String::from("o petal-1\n");
        for p in &shape {
            text.push_str(&format!("v {} {} {}\n", p.x, p.y, p.z));
        }
        let path = dir.join("open.obj");
        std::fs::write(&path, text).expect("write");
        (Arc::new(project), path)
    }

    fn wait(dialog: &mut FitDialog) {
        while dialog.is_running() {
            dialog.poll();
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
    }

    #[test]
    fn a_fit_runs_reports_and_applies_as_one_edit() {
        let dir = tempfile::tempdir().expect("tempdir");
        let (project, target) = petal_and_target(dir.path());
        let mut dialog = FitDialog::default();
        dialog
            .start(Arc::clone(&project), 0, 7, &target)
            .expect("starts");
        wait(&mut dialog);
        let FitState::Done { fit } = dialog.state() else {
            panic!("{:?}", dialog.state());
        };
        assert!(fit.rms < fit.guess_rms, "{fit:?}");
        let fitted_maps = fit.maps.clone();
        // Another revision: refused.
        assert!(dialog.apply_edit(&project, 8).is_err());
        let Ok(Command::Edit { edit, .. }) = dialog.apply_edit(&project, 7) else {
            panic!("an edit");
        };
        let mut edited = (*project).clone();
        edit.apply(&mut edited);
        assert_eq!(edited.flower.templates[0].maps, fitted_maps);
    }

    #[test]
    fn a_registered_target_is_shown_over_the_organ_while_the_dialog_is_open() {
        let dir = tempfile::tempdir().expect("tempdir");
        let (project, target) = petal_and_target(dir.path());
        // The target turned about +Y and moved: in its own frame.
        let text = std::fs::read_to_string(&target).expect("read");
        let turned: String = text
            .lines()
            .map(|line| match line.strip_prefix("v ") {
                Some(rest) => {
                    let v: Vec<f64> = rest
                        .split_whitespace()
                        .map(|w| w.parse().expect("number"))
                        .collect();
                    format!("v {} {} {}\n", -v[2] + 40.0, v[1] - 5.0, v[0])
                }
                None => format!("{line}\n"),
            })
            .collect();
        let scan = dir.path().join("scan.obj");
        std::fs::write(&scan, turned).expect("write");
        let mut dialog = FitDialog {
            open: true,
            register: true,
            ..FitDialog::default()
        };
        assert_eq!(dialog.target_overlay().0, 0);
        dialog.start(project, 0, 1, &scan).expect("starts");
        wait(&mut dialog);
        assert!(
            matches!(dialog.state(), FitState::Done { .. }),
            "{:?}",
            dialog.state()
        );
        let registered = dialog.registered().expect("registered");
        // The quarter turn undone.
        let angle = registered.registration.placement.angle_deg();
        assert!((angle - 90.0).abs() < 1.0, "{angle}");
        let (revision, mesh) = dialog.target_overlay();
        assert!(revision > 0);
        let mesh = mesh.expect("shown");
        // Over the organ: near the fitted shape, not where the file has it.
        let FitState::Done { fit } = dialog.state() else {
            unreachable!()
        };
        let centre = |points: &mut dyn Iterator<Item = glam::DVec3>| {
            let all: Vec<glam::DVec3> = points.collect();
            all.iter().sum::<glam::DVec3>() / all.len() as f64
        };
        let shown = centre(
            &mut mesh
                .positions_in_world
                .iter()
                .map(|p| glam::DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))),
        );
        let organ = centre(&mut fit.shape.iter().copied());
        assert!(shown.distance(organ) < 0.05 * fit.length, "{shown} {organ}");
        // Closed: not shown.
        dialog.open = false;
        assert_eq!(dialog.target_overlay(), (0, None));
    }

    #[test]
    fn cancel_stops_the_fit() {
        let dir = tempfile::tempdir().expect("tempdir");
        let (project, target) = petal_and_target(dir.path());
        let mut dialog = FitDialog::default();
        dialog.start(project, 0, 1, &target).expect("starts");
        dialog.cancel();
        wait(&mut dialog);
        assert!(
            matches!(dialog.state(), FitState::Cancelled),
            "{:?}",
            dialog.state()
        );
    }

    #[test]
    fn a_bad_target_is_said_before_anything_runs() {
        let dir = tempfile::tempdir().expect("tempdir");
        let (project, _) = petal_and_target(dir.path());
        let bad = dir.path().join("bad.obj");
        std::fs::write(&bad, "o petal-1\nv 0 0 0\n").expect("write");
        let mut dialog = FitDialog::default();
        let error = dialog.start(project, 0, 1, &bad).expect_err("one vertex");
        assert!(error.contains("the target has 1 vertices"), "{error}");
        assert!(!dialog.is_running());
    }
}

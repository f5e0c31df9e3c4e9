//! The export dialog: a .glb, .usda, .usdc or .gif path (typed or picked with the
//! native dialog) and the options; the export runs on a thread named
//! `anthesis-export` and reports progress, then the result or the error.
//! The window itself is drawn by `export/dialog.rs`.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, sync_channel};
use std::sync::{Arc, Mutex};

use anthesis_export::{Encoding, GlbOptions, Timing, Track};
use anthesis_flower::resolution::predicted_size;
use anthesis_flower::{Project, Resolution};
use anthesis_render::{OffscreenRenderer, OrganMesh};
use anthesis_sim::batch::{self, BatchError, Format};
use anthesis_sim::crossing::OnCrossing;
use anthesis_sim::memory::{self, KeyframeCost};
use anthesis_sim::{Keyframe, Selection, SimError};
use anyhow::Context;

use crate::animation::{self, AnimationOptions, AnimationTarget};

mod dialog;

/// How the dialog asks for the animation's timing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimingMode {
    FramesPerSecond,
    Duration,
}

/// Where an export stands.
#[derive(Debug, Clone, PartialEq)]
pub enum ExportState {
    Idle,
    Running { progress: f32 },
    Done { path: PathBuf, bytes: u64 },
    Failed { message: String },
}

enum Message {
    Progress(f32),
    Done(Result<u64, String>),
}

/// The dialog's fields and the running export.
pub struct ExportDialog {
    pub open: bool,
    pub path: String,
    pub timing_mode: TimingMode,
    pub frames_per_second: f64,
    pub duration_seconds: f64,
    pub max_morph_targets: usize,
    pub normals: bool,
    pub encoding: Encoding,
    /// Levels of Loop subdivision of every organ in the export (0 = the
    /// simulated mesh; each level about four times the vertices).
    pub render_level: u32,
    /// How a .gif export looks (size, camera, turn, speed).
    pub animation: AnimationOptions,
    /// A .gif shows every `animation_step`-th keyframe (and the last).
    pub animation_step: u32,
    /// Export a run of its own at `resimulate_edge` (every template
    /// remeshed at that mean edge, the painted maps kept) instead of the
    /// keyframes the window computed: paint coarse, export fine. The
    /// window's run and the project stay as they are.
    pub resimulate: bool,
    /// With a single organ previewed: export the whole flower (its
    /// keyframes kept from before the preview when they are up to date,
    /// else a run of its own) rather than the previewed organ alone.
    pub whole_flower: bool,
    /// The mean edge of that run, in the project's lengths (0: not chosen
    /// yet; the dialog suggests half the edge the window simulates at).
    pub resimulate_edge: f64,
    /// The edge last suggested: while `resimulate_edge` is still that
    /// suggestion, it follows the window's resolution.
    suggested_edge: f64,
    state: ExportState,
    job: Option<(PathBuf, Receiver<Message>)>,
    /// Set to stop the running export's simulation.
    cancel: Arc<AtomicBool>,
    /// The keyframes of the running export's own run, if it makes one.
    running_run: Option<u32>,
    /// The Simulation row's note ([`run_note`]) and what it was made for.
    run_note: Option<(RunNoteKey, Result<String, String>)>,
}

/// What the Simulation row's note depends on: the edge's bits, the
/// simulated organs, the keyframes and each template's particles.
type RunNoteKey = (u64, Vec<usize>, u32, Vec<usize>, usize);

impl Default for ExportDialog {
    fn default() -> Self {
        let defaults = GlbOptions::default();
        ExportDialog {
            open: false,
            path: String::new(),
            timing_mode: TimingMode::FramesPerSecond,
            frames_per_second: anthesis_export::DEFAULT_FRAMES_PER_SECOND,
            duration_seconds: 4.0,
            max_morph_targets: defaults.max_morph_targets,
            normals: defaults.normals,
            encoding: defaults.encoding,
            render_level: 0,
            animation: AnimationOptions::default(),
            animation_step: 1,
            resimulate: false,
            whole_flower: true,
            resimulate_edge: 0.0,
            suggested_edge: 0.0,
            state: ExportState::Idle,
            job: None,
            cancel: Arc::new(AtomicBool::new(false)),
            running_run: None,
            run_note: None,
        }
    }
}

/// The most subdivision levels the dialog offers (the default lily at 3 is
/// about 380,000 render vertices per keyframe).
pub const MAX_DIALOG_RENDER_LEVEL: u32 = 3;

/// Renders every `step`-th keyframe of `tracks` (and the last) offscreen
/// and writes them as a looping GIF (see [`animation::write_animation`]).
fn write_gif(
    path: &Path,
    tracks: &[Track],
    options: &AnimationOptions,
    step: u32,
    progress: &mut dyn FnMut(f32),
) -> anyhow::Result<()> {
    let target = AnimationTarget::Gif(path.to_path_buf());
    animation::check_request(&target, options)?;
    let count = tracks.iter().map(|t| t.keyframes.len()).max().unwrap_or(0);
    let Some(last) = count.checked_sub(1) else {
        anyhow::bail!("there are no keyframes to render yet");
    };
    let keyframes = animation::keyframes_every(step, last as u32);
    // Each track's colour map, decoded once.
    let textures: Vec<_> = tracks.iter().map(crate::look::track_texture).collect();
    let scenes: Vec<Vec<OrganMesh>> = keyframes
        .iter()
        .map(|&k| {
            tracks
                .iter()
                .zip(&textures)
                .filter_map(|(t, texture)| {
                    // A still track (one keyframe) shows it throughout.
                    let positions = t.keyframes.get(k as usize).or(t.keyframes.last())?;
                    let mesh = OrganMesh::from_positions(positions, &t.triangles, t.base_colour);
                    Some(crate::look::with_texture(mesh, &t.uvs, texture.as_ref()))
                })
                .collect()
        })
        .collect();
    let mut renderer = OffscreenRenderer::new().context("cannot render")?;
    let frames = scenes.len();
    animation::write_animation(&mut renderer, &scenes, options, &target, &mut |done| {
        progress(done as f32 / frames as f32)
    })?;
    Ok(())
}

/// What the user asked the dialog for.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct ExportRequests {
    pub browse: bool,
    pub export: bool,
}

/// The animation tracks of the computed keyframes: one per simulated organ
/// (as render meshes of `render_level` levels of subdivision, 0 for the
/// simulated meshes) and the receptacle, as every export of a flower has
/// them ([`anthesis_export::flower_tracks`]).
pub fn tracks(
    project: &Project,
    organs: &[usize],
    keyframes: &[Arc<Keyframe>],
    render_level: u32,
) -> Result<Vec<Track>, anthesis_export::ExportError> {
    anthesis_export::flower_tracks(
        &project.flower,
        organs,
        keyframes.iter().map(|k| k.positions_in_world.as_slice()),
        render_level,
    )
}

/// The share of the progress bar an export's own run takes (the rest is
/// writing the file).
const RUN_SHARE: f32 = 0.9;

/// What the dialog writes to `target`: the format its extension names,
/// else an animated glTF.
pub fn target_format(target: &Path) -> Format {
    match Format::from_path(target) {
        Some(format) if format != Format::ObjFolder => format,
        _ => Format::Glb,
    }
}

/// Writes `tracks` to `target` in the format its name picks
/// ([`target_format`]): a USD layer for .usda, .usd (text) or .usdc
/// (binary), a rendered animation for .gif, else the animated glTF;
/// returns the file's size.
fn write_tracks(
    target: &Path,
    tracks: &[Track],
    options: &GlbOptions,
    animation: &AnimationOptions,
    animation_step: u32,
    progress: &mut dyn FnMut(f32),
) -> Result<u64, String> {
    let written = match target_format(target) {
        Format::Gif => write_gif(target, tracks, animation, animation_step, progress),
        // The export's own error names the file already.
        format => batch::write(target, format, tracks, options, progress).map_err(|e| match e {
            BatchError::Write { source, .. } => source.into(),
            e => e.into(),
        }),
    };
    written.map_err(|e| format!("{e:#}")).and_then(|()| {
        std::fs::metadata(target)
            .map(|m| m.len())
            .map_err(|e| format!("{}: {e}", target.display()))
    })
}

/// Runs `selection` of `project` at its resolution (checked against the
/// memory first, then every template remeshed) to its last keyframe and
/// returns its tracks, as render meshes of `render_level`. The error
/// finishes a sentence naming the run ("the run at mean edge E …").
fn simulate_at(
    project: &Project,
    selection: &Selection,
    render_level: u32,
    progress: &mut dyn FnMut(f32),
    cancelled: &(dyn Fn() -> bool + Sync),
) -> Result<Vec<Track>, String> {
    let resolved =
        batch::prepare(project, selection, KeyframeCost::Kept, None).map_err(|e| match e {
            BatchError::Memory(e) => format!("does not fit: {e}"),
            e => format!("cannot start: {e}"),
        })?;
    let total = resolved.settings.keyframes.max(1);
    let run = batch::simulate(
        &resolved,
        selection,
        OnCrossing::Stop,
        cancelled,
        &mut |_, keyframe| progress(keyframe.index as f32 / total as f32),
    )
    .map_err(|e| format!("cannot start: {e}"))?;
    match run.stepped.failure {
        None => {}
        Some(SimError::Cancelled) => return Err("was cancelled".to_string()),
        Some(error) => return Err(format!("stopped: {error}")),
    }
    run.tracks(&resolved, selection, render_level)
        .map_err(|e| format!("{e}"))
}

/// The particles a run of `organs` of `project` at `edge` makes in its
/// largest organ, next to `now`, the largest organ's in the window's run;
/// or why that run would not fit.
fn run_note(
    project: &Project,
    selection: &Selection,
    organs: &[usize],
    edge: f64,
    now: usize,
) -> Result<String, String> {
    let mut trial = project.clone();
    trial.settings.resolution = Resolution::MeanEdge(edge);
    memory::check_run(&trial, selection, KeyframeCost::Kept).map_err(|e| e.to_string())?;
    let templates = || {
        organs
            .iter()
            .filter(|&&i| i < project.flower.organs.len())
            .map(|&i| project.flower.template_of(i))
    };
    let largest = templates()
        .map(|t| predicted_size(&t.mesh, edge).0)
        .max()
        .unwrap_or(0);
    Ok(format!(
        "≈ {} particles in the largest organ ({} now)",
        super::params::grouped(largest as u64),
        super::params::grouped(now as u64)
    ))
}

/// A mean edge as the dialog writes it: at most four decimals.
fn edge_text(edge: f64) -> String {
    if edge >= 1e-3 {
        let text = format!("{edge:.4}");
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{edge:.2e}")
    }
}

/// The mean edge the window simulates `project` at: its resolution's, or
/// the first template's mesh as built.
fn shown_edge(project: &Project) -> f64 {
    project
        .settings
        .resolution
        .mean_edge()
        .or_else(|| {
            project
                .flower
                .templates
                .first()
                .map(|t| anthesis_bud::quality(&t.mesh).mean_edge)
        })
        .filter(|e| e.is_finite() && *e > 0.0)
        .unwrap_or(1.0)
}

impl ExportDialog {
    /// Suggests half the edge the window simulates at (about four times
    /// the particles, rounded as the Resolution control rounds) for a run
    /// of its own, until the user chooses an edge: the dialog is drawn from
    /// the first frame, and a suggestion made then, for the meshes as
    /// built, was kept after the Resolution changed.
    fn suggest_edge(&mut self, project: &Project) {
        let suggestion = super::params::round_to_3_digits(shown_edge(project) / 2.0);
        if self.resimulate_edge <= 0.0 || self.resimulate_edge == self.suggested_edge {
            self.resimulate_edge = suggestion;
        }
        self.suggested_edge = suggestion;
    }

    pub fn state(&self) -> &ExportState {
        &self.state
    }

    pub fn options(&self) -> GlbOptions {
        GlbOptions {
            timing: match self.timing_mode {
                TimingMode::FramesPerSecond => Timing::FramesPerSecond(self.frames_per_second),
                TimingMode::Duration => Timing::Duration(self.duration_seconds),
            },
            max_morph_targets: self.max_morph_targets,
            normals: self.normals,
            encoding: self.encoding,
        }
    }

    /// Shows an export that could not start (its tracks could not be
    /// built) as failed, with `message`.
    pub fn fail(&mut self, message: String) {
        self.state = ExportState::Failed { message };
    }

    /// Starts writing `tracks` to the dialog's path on a thread; `wake` is
    /// called on progress and at the end.
    pub fn start(&mut self, tracks: Vec<Track>, wake: impl Fn() + Send + Sync + 'static) {
        if self.target().is_none() {
            return;
        }
        if tracks.iter().all(|t| t.keyframes.is_empty()) {
            self.state = ExportState::Failed {
                message: "there are no keyframes to export yet".to_string(),
            };
            return;
        }
        self.spawn(0.0, move |_, _| Ok(tracks), wake);
    }

    /// Starts a run of `selection` of `project` (the document's project,
    /// meshes as built) at the dialog's mean edge on a thread, then writes
    /// it to the dialog's path; `wake` is called on progress and at the
    /// end. A run too large for the memory, an edge a template cannot be
    /// remeshed at and a run that stops are reported as the export's
    /// failure; [`ExportDialog::cancel`] stops the run.
    pub fn start_resimulated(
        &mut self,
        project: &Project,
        selection: Selection,
        wake: impl Fn() + Send + Sync + 'static,
    ) {
        let edge = self.resimulate_edge;
        let mut project = project.clone();
        project.settings.resolution = Resolution::MeanEdge(edge);
        let what = format!("the run at mean edge {}", edge_text(edge));
        self.start_run(project, selection, what, wake);
    }

    /// Starts a run of the whole of `project` (the document's project) at
    /// its own resolution on a thread, then writes it (as
    /// [`ExportDialog::start_resimulated`]): the export of the whole
    /// flower while the window previews one organ, when the window has no
    /// up-to-date keyframes of it.
    pub fn start_whole_flower(
        &mut self,
        project: &Project,
        wake: impl Fn() + Send + Sync + 'static,
    ) {
        let what = "the run of the whole flower".to_string();
        self.start_run(project.clone(), Selection::All, what, wake);
    }

    /// Runs `selection` of `project` at its resolution, then writes it;
    /// `what` names the run in errors ("… does not fit: …").
    fn start_run(
        &mut self,
        project: Project,
        selection: Selection,
        what: String,
        wake: impl Fn() + Send + Sync + 'static,
    ) {
        let render_level = self.render_level;
        let keyframes = project.settings.keyframes;
        // The run is most of the work: RUN_SHARE of the progress bar.
        self.spawn(
            RUN_SHARE,
            move |progress, cancelled| {
                simulate_at(&project, &selection, render_level, progress, cancelled)
                    .map_err(|e| format!("{what} {e}"))
            },
            wake,
        );
        if self.is_running() {
            self.running_run = Some(keyframes);
        }
    }

    /// The file to export to, or `None` (the export failed: no file named).
    fn target(&mut self) -> Option<PathBuf> {
        let path = PathBuf::from(self.path.trim());
        if path.as_os_str().is_empty() {
            self.state = ExportState::Failed {
                message: "choose a file to export to".to_string(),
            };
            return None;
        }
        Some(path)
    }

    /// Stops the running export's simulation (the file is not written).
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    /// Runs `make` (which builds the tracks, reporting its progress from 0
    /// to 1 and told whether the export was cancelled) and then writes its
    /// tracks, on a thread; `share` of the progress bar is `make`'s.
    fn spawn(
        &mut self,
        share: f32,
        make: impl FnOnce(&mut dyn FnMut(f32), &(dyn Fn() -> bool + Sync)) -> Result<Vec<Track>, String>
        + Send
        + 'static,
        wake: impl Fn() + Send + Sync + 'static,
    ) {
        let Some(path) = self.target() else {
            return;
        };
        let options = self.options();
        let animation = self.animation;
        let animation_step = self.animation_step;
        self.cancel = Arc::new(AtomicBool::new(false));
        let cancel = Arc::clone(&self.cancel);
        // Progress is dropped while the window has not taken the last few
        // (newer progress follows); the end waits for room.
        let (send, receive) = sync_channel(4);
        let target = path.clone();
        let wake = Arc::new(wake);
        let progress_wake = Arc::clone(&wake);
        let progress_send = Mutex::new(send.clone());
        let spawned = std::thread::Builder::new()
            .name("anthesis-export".into())
            .spawn(move || {
                let mut last = -1.0_f32;
                let mut progress = |p: f32| {
                    // Report in steps of 1 %.
                    if p - last >= 0.01 {
                        last = p;
                        if let Ok(send) = progress_send.lock() {
                            let _ = send.try_send(Message::Progress(p));
                        }
                        (*progress_wake)();
                    }
                };
                let cancelled = || cancel.load(Ordering::Relaxed);
                let result = make(&mut |p| progress(share * p), &cancelled).and_then(|tracks| {
                    write_tracks(
                        &target,
                        &tracks,
                        &options,
                        &animation,
                        animation_step,
                        &mut |p| progress(share + (1.0 - share) * p),
                    )
                });
                let _ = send.send(Message::Done(result));
                (*wake)();
            });
        match spawned {
            Ok(_) => {
                self.state = ExportState::Running { progress: 0.0 };
                self.job = Some((path, receive));
            }
            Err(e) => {
                self.state = ExportState::Failed {
                    message: format!("cannot start the export: {e}"),
                }
            }
        }
    }

    /// Takes the export thread's messages; returns the final state once
    /// when the export ends.
    pub fn poll(&mut self) -> Option<ExportState> {
        let (path, receive) = self.job.as_ref()?;
        let path = path.clone();
        let mut ended = None;
        while let Ok(message) = receive.try_recv() {
            match message {
                Message::Progress(progress) => {
                    self.state = ExportState::Running { progress };
                }
                Message::Done(result) => {
                    self.state = match result {
                        Ok(bytes) => ExportState::Done {
                            path: path.clone(),
                            bytes,
                        },
                        Err(message) => ExportState::Failed { message },
                    };
                    ended = Some(self.state.clone());
                }
            }
        }
        if ended.is_some() {
            self.job = None;
            self.running_run = None;
        }
        ended
    }

    pub fn is_running(&self) -> bool {
        self.job.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use anthesis_flower::resolution::resolve;
    use std::time::{Duration, Instant};

    /// Polls `dialog` until its export ends (failing after a minute).
    fn wait_for_the_end(dialog: &mut ExportDialog) -> ExportState {
        let started = Instant::now();
        loop {
            if let Some(end) = dialog.poll() {
                return end;
            }
            assert!(started.elapsed() < Duration::from_secs(60), "export hangs");
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    #[test]
    fn an_export_writes_a_glb_and_reports_done_with_its_size() {
        let project = anthesis_sim::fixtures::whorl(2, 4, 6, 2);
        let mut frames = Vec::new();
        anthesis_sim::run(&project, &anthesis_sim::Selection::All, &mut |_, k| {
            frames.push(Arc::new(k.clone()))
        })
        .expect("simulates");
        let dir = tempfile::tempdir().expect("temp dir");
        let mut dialog = ExportDialog {
            path: dir.path().join("out.glb").display().to_string(),
            ..ExportDialog::default()
        };
        dialog.start(
            tracks(&project, &[0, 1], &frames, 0).expect("tracks"),
            || {},
        );
        let end = wait_for_the_end(&mut dialog);
        let ExportState::Done { bytes, .. } = end else {
            panic!("export failed: {end:?}");
        };
        let on_disk = std::fs::read(dir.path().join("out.glb")).expect("file");
        assert_eq!(on_disk.len() as u64, bytes);
        assert_eq!(&on_disk[..4], b"glTF");
    }

    #[test]
    fn a_single_organ_run_exports_that_organ() {
        let project = anthesis_sim::fixtures::whorl(2, 4, 6, 2);
        let bud = anthesis_sim::Simulation::new(&project, &anthesis_sim::Selection::Only(1))
            .expect("sim")
            .bud();
        let tracks = tracks(&project, &[1], &[Arc::new(bud.clone())], 0).expect("tracks");
        assert_eq!(tracks.len(), 2, "the organ and the receptacle");
        let template = project.flower.template_of(1);
        assert_eq!(tracks[0].name, project.flower.organs[1].name);
        assert_eq!(tracks[0].triangles, template.mesh.triangles);
        assert_eq!(tracks[0].uvs, template.mesh.uvs);
        assert_eq!(tracks[0].base_colour, template.colour);
        assert_eq!(tracks[0].keyframes, bud.positions_in_world);
        // The receptacle, as `anthesis simulate --out` exports it too.
        let receptacle = anthesis_flower::receptacle_for(&project.flower);
        assert_eq!(tracks[1].name, "receptacle");
        assert_eq!(tracks[1].keyframes, vec![receptacle.positions]);
        assert_eq!(tracks[1].base_colour, anthesis_flower::RECEPTACLE_COLOUR);
        // Before the first keyframe there is nothing to export.
        assert!(
            super::tracks(&project, &[1], &[], 0)
                .expect("tracks")
                .is_empty()
        );
    }

    #[test]
    fn a_missing_folder_is_reported_not_panicked() {
        let project = anthesis_sim::fixtures::whorl(1, 4, 6, 1);
        let bud = anthesis_sim::Simulation::new(&project, &anthesis_sim::Selection::All)
            .expect("sim")
            .bud();
        let mut dialog = ExportDialog {
            path: "/no/such/folder/out.glb".to_string(),
            ..ExportDialog::default()
        };
        dialog.start(
            tracks(&project, &[0], &[Arc::new(bud)], 0).expect("tracks"),
            || {},
        );
        let end = wait_for_the_end(&mut dialog);
        assert!(
            matches!(&end, ExportState::Failed { message } if message.contains("/no/such/folder")),
            "{end:?}"
        );
    }

    #[test]
    fn usda_and_usdc_paths_write_usd_layers() {
        let project = anthesis_sim::fixtures::whorl(2, 4, 6, 2);
        let mut frames = Vec::new();
        anthesis_sim::run(&project, &anthesis_sim::Selection::All, &mut |_, k| {
            frames.push(Arc::new(k.clone()))
        })
        .expect("simulates");
        let dir = tempfile::tempdir().expect("temp dir");
        let usda = dir.path().join("out.usda");
        let mut dialog = ExportDialog {
            path: usda.display().to_string(),
            ..ExportDialog::default()
        };
        dialog.start(
            tracks(&project, &[0, 1], &frames, 0).expect("tracks"),
            || {},
        );
        let end = wait_for_the_end(&mut dialog);
        let ExportState::Done { bytes, .. } = end else {
            panic!("export failed: {end:?}");
        };
        // Pixar's USD reads such layers in anthesis-export's tests.
        let layer = std::fs::read_to_string(&usda).expect("layer written");
        assert_eq!(layer.len() as u64, bytes);
        assert!(layer.starts_with("#usda 1.0"));
        assert_eq!(
            layer.matches("def Mesh ").count(),
            3,
            "one mesh per organ and the receptacle"
        );
        assert!(layer.contains("endTimeCode = 2"));

        let usdc = dir.path().join("out.usdc");
        dialog.path = usdc.display().to_string();
        dialog.start(
            tracks(&project, &[0, 1], &frames, 0).expect("tracks"),
            || {},
        );
        let end = wait_for_the_end(&mut dialog);
        let ExportState::Done { bytes, .. } = end else {
            panic!("binary export failed: {end:?}");
        };
        // The binary crate form of the same layer (read back by Pixar's
        // USD in anthesis-export's and the command line's tests).
        let crate_file = std::fs::read(&usdc).expect("crate file written");
        assert_eq!(crate_file.len() as u64, bytes);
        assert!(crate_file.starts_with(b"PXR-USDC"));
    }

    #[test]
    fn a_gif_path_renders_the_opening_with_the_dialogs_options() {
        use image::AnimationDecoder;

        let project = anthesis_sim::fixtures::whorl(2, 4, 6, 4);
        let mut frames = vec![Arc::new(
            anthesis_sim::Simulation::new(&project, &anthesis_sim::Selection::All)
                .expect("sim")
                .bud(),
        )];
        anthesis_sim::run(&project, &anthesis_sim::Selection::All, &mut |_, k| {
            frames.push(Arc::new(k.clone()))
        })
        .expect("simulates");
        let dir = tempfile::tempdir().expect("temp dir");
        let gif = dir.path().join("opening.gif");
        let mut dialog = ExportDialog {
            path: gif.display().to_string(),
            animation_step: 2,
            ..ExportDialog::default()
        };
        dialog.animation.width = 80;
        dialog.animation.height = 60;
        dialog.start(
            tracks(&project, &[0, 1], &frames, 0).expect("tracks"),
            || {},
        );
        let end = wait_for_the_end(&mut dialog);
        let ExportState::Done { bytes, .. } = end else {
            panic!("export failed: {end:?}");
        };
        assert_eq!(std::fs::metadata(&gif).expect("gif").len(), bytes);
        let file = std::io::BufReader::new(std::fs::File::open(&gif).expect("open"));
        let decoded = image::codecs::gif::GifDecoder::new(file)
            .expect("a GIF")
            .into_frames()
            .collect_frames()
            .expect("frames");
        let keyframes = frames.len() as u32 - 1;
        assert_eq!(
            decoded.len(),
            animation::keyframes_every(2, keyframes).len()
        );
        assert_eq!(decoded[0].buffer().dimensions(), (80, 60));

        // Too large for a GIF: refused, nothing written.
        let wide = dir.path().join("wide.gif");
        dialog.path = wide.display().to_string();
        dialog.animation.width = 70_000;
        dialog.start(
            tracks(&project, &[0, 1], &frames, 0).expect("tracks"),
            || {},
        );
        let end = wait_for_the_end(&mut dialog);
        assert!(
            matches!(&end, ExportState::Failed { message } if message.contains("65535")),
            "{end:?}"
        );
        assert!(!wide.exists());
    }

    #[test]
    fn the_smooth_mesh_option_subdivides_the_organs_and_refuses_too_fine_levels() {
        let project = anthesis_sim::fixtures::whorl(2, 4, 6, 2);
        let mut frames = Vec::new();
        anthesis_sim::run(&project, &anthesis_sim::Selection::All, &mut |_, k| {
            frames.push(Arc::new(k.clone()))
        })
        .expect("simulates");
        let coarse = tracks(&project, &[0, 1], &frames, 0).expect("tracks");
        let smooth = tracks(&project, &[0, 1], &frames, 1).expect("tracks");
        let mesh = &project.flower.template_of(0).mesh;
        let edges = anthesis_mesh::Topology::build(mesh)
            .expect("manifold")
            .edges
            .len();
        assert_eq!(smooth[0].uvs.len(), mesh.vertex_count() + edges);
        assert_eq!(smooth[0].triangles.len(), 4 * mesh.triangle_count());
        assert_eq!(smooth[0].keyframes.len(), coarse[0].keyframes.len());
        assert_eq!(smooth[2], coarse[2], "the receptacle is exported as it is");

        // Through the dialog: a file of the render meshes, or the reason
        // when the level asks for too much.
        let dir = tempfile::tempdir().expect("temp dir");
        let mut dialog = ExportDialog {
            path: dir.path().join("smooth.glb").display().to_string(),
            render_level: 1,
            ..ExportDialog::default()
        };
        dialog.start(
            tracks(&project, &[0, 1], &frames, dialog.render_level).expect("tracks"),
            || {},
        );
        let end = wait_for_the_end(&mut dialog);
        assert!(matches!(end, ExportState::Done { .. }), "{end:?}");
        let error = tracks(&project, &[0, 1], &frames, 12).expect_err("too fine");
        dialog.fail(error.to_string());
        assert!(
            matches!(dialog.state(), ExportState::Failed { message }
                if message.contains("render subdivision level 12")
                    && message.contains("the finest that fits")),
            "{:?}",
            dialog.state()
        );
    }

    #[test]
    fn a_run_of_its_own_at_a_finer_edge_is_the_engines_run_at_that_resolution() {
        let project = anthesis_sim::fixtures::whorl(2, 4, 6, 3);
        let edge = shown_edge(&project) / 2.0;
        let mut fine = project.clone();
        fine.settings.resolution = Resolution::MeanEdge(edge);
        let mut progress = Vec::new();
        let made = simulate_at(
            &fine,
            &Selection::All,
            0,
            &mut |p| progress.push(p),
            &|| false,
        )
        .expect("runs");
        // The same as the engine's run of the project remeshed there, bit
        // for bit, with more than twice the particles of the built mesh
        // (about four times, less at this tiny mesh's rim).
        let resolved = resolve(&fine).expect("remeshes");
        let mut frames = Vec::new();
        anthesis_sim::run(&resolved, &Selection::All, &mut |_, k| {
            frames.push(Arc::new(k.clone()))
        })
        .expect("simulates");
        assert_eq!(
            made,
            tracks(&resolved, &[0, 1], &frames, 0).expect("tracks")
        );
        let built = project.flower.template_of(0).mesh.vertex_count();
        assert!(
            made[0].uvs.len() > 2 * built,
            "{} vs {built}",
            made[0].uvs.len()
        );
        assert_eq!(made[0].keyframes.len(), 4, "the bud and three keyframes");
        assert_eq!(progress.last(), Some(&1.0));

        // Through the dialog: written, the project untouched.
        let dir = tempfile::tempdir().expect("temp dir");
        let mut dialog = ExportDialog {
            path: dir.path().join("fine.glb").display().to_string(),
            resimulate: true,
            resimulate_edge: edge,
            ..ExportDialog::default()
        };
        dialog.start_resimulated(&project, Selection::All, || {});
        assert_eq!(
            dialog.running_run,
            Some(3),
            "the bar counts the run's keyframes"
        );
        let end = wait_for_the_end(&mut dialog);
        assert_eq!(dialog.running_run, None);
        let ExportState::Done { bytes, .. } = end else {
            panic!("export failed: {end:?}");
        };
        assert_eq!(
            std::fs::metadata(dir.path().join("fine.glb"))
                .expect("file")
                .len(),
            bytes
        );
        assert_eq!(project.settings.resolution, Resolution::AsBuilt);
    }

    #[test]
    fn the_suggested_edge_follows_the_resolution_until_one_is_chosen() {
        let mut project = anthesis_sim::fixtures::whorl(2, 4, 6, 3);
        let mut dialog = ExportDialog::default();
        dialog.suggest_edge(&project);
        let built = shown_edge(&project);
        assert_eq!(
            dialog.resimulate_edge,
            super::super::params::round_to_3_digits(built / 2.0)
        );
        // The window's Resolution set coarser: half of that now.
        project.settings.resolution = Resolution::MeanEdge(0.8);
        dialog.suggest_edge(&project);
        assert_eq!(dialog.resimulate_edge, 0.4);
        // An edge the user chose stays.
        dialog.resimulate_edge = 0.25;
        project.settings.resolution = Resolution::MeanEdge(2.0);
        dialog.suggest_edge(&project);
        assert_eq!(dialog.resimulate_edge, 0.25);
    }

    #[test]
    fn a_run_of_its_own_says_why_it_cannot_be_made_and_stops_when_cancelled() {
        let project = anthesis_sim::fixtures::whorl(2, 4, 6, 3);
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("fine.glb");
        // Far too fine for any memory: refused before anything is meshed.
        let mut dialog = ExportDialog {
            path: path.display().to_string(),
            resimulate: true,
            resimulate_edge: shown_edge(&project) * 1e-5,
            ..ExportDialog::default()
        };
        dialog.start_resimulated(&project, Selection::All, || {});
        let end = wait_for_the_end(&mut dialog);
        assert!(
            matches!(&end, ExportState::Failed { message }
                if message.starts_with("the run at mean edge") && message.contains("does not fit")),
            "{end:?}"
        );
        // Cancelled: the run stops and no file is written.
        let mut fine = project.clone();
        fine.settings.resolution = Resolution::MeanEdge(shown_edge(&project) / 2.0);
        let stopped = simulate_at(&fine, &Selection::All, 0, &mut |_| {}, &|| true);
        assert_eq!(stopped, Err("was cancelled".to_string()));
        dialog.resimulate_edge = shown_edge(&project) / 2.0;
        dialog.start_resimulated(&project, Selection::All, || {});
        dialog.cancel();
        let end = wait_for_the_end(&mut dialog);
        match end {
            // The run may have ended before the cancel reached it.
            ExportState::Done { .. } => assert!(path.exists()),
            ExportState::Failed { message } => {
                assert!(message.ends_with("was cancelled"), "{message}");
                assert!(!path.exists());
            }
            other => panic!("{other:?}"),
        }
    }
}

//! The simulation as the window sees it: the engine's worker (or, in tests,
//! keyframes fed in by hand), the keyframes of the current run and its
//! status. Events of superseded runs are dropped by their run id.
//!
//! Every keyframe index shows the best frame there is: the current run's
//! converged keyframe, else its proxy's (the same flower on coarser meshes,
//! computed first so an edit shows at once), else an earlier run's (stale,
//! so an edit keeps the frame the user looks at). Each frame keeps the
//! project whose meshes its positions belong to, so a proxy is drawn on the
//! proxy's meshes.
//!
//! The session also keeps the result before the last change, for the
//! viewport's before/after view and its difference overlay: the converged
//! keyframes of the last run that finished ([`Outcome`]) become "before"
//! when a run of the same organs starts on another project (an edit, an
//! undo or a redo alike: after an undo, "before" is the result with the
//! undone edit, so the view shows what the undo changed). A run superseded
//! before it finished never becomes "before": during a stroke, which starts
//! several runs, "before" stays the result from before the stroke.

use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anthesis_export::KeyframeBlend;
use anthesis_flower::Project;
use anthesis_sim::crossing::Crossings;
use anthesis_sim::worker::{Event, RunId, Worker};
use anthesis_sim::{Keyframe, KeyframeStats, Selection};
use glam::DVec3;

/// Where keyframes come from.
enum Source {
    /// The engine's simulation thread.
    Worker(Worker),
    /// Nothing runs; keyframes arrive through [`SimSession::accept`] (tests
    /// and snapshot recordings). Run ids are counted here.
    Recorded { next_run: RunId },
}

/// The state of the current run.
#[derive(Debug, Clone, PartialEq)]
pub enum RunStatus {
    /// No run asked for yet.
    Idle,
    /// Asked for, no `Started` event yet.
    Queued,
    Running,
    Finished {
        seconds: f64,
        /// The first keyframe the run computed (see `Event::Started`).
        first_computed: u32,
    },
    Failed {
        message: String,
    },
}

/// Which computation a shown frame comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameKind {
    /// The converged run, at the project's resolution.
    Converged,
    /// The proxy: the same flower on coarser meshes.
    Proxy,
}

/// What is shown at one keyframe index, as the timeline colours it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameState {
    /// The current run's converged keyframe.
    Converged,
    /// The current run's proxy keyframe (the converged one is coming).
    Proxy,
    /// An earlier run's keyframe, shown until the current run reaches it.
    Stale,
}

/// One shown keyframe: its positions and the project whose template meshes
/// they belong to.
#[derive(Clone)]
struct Frame {
    keyframe: Arc<Keyframe>,
    meshes: Arc<Project>,
    kind: FrameKind,
    run: RunId,
    /// Tells this frame from every other the session has held (counted).
    serial: u64,
}

/// The organs at a time on the timeline, as shown.
#[derive(Clone)]
pub struct ShownAt {
    /// One position list per simulated organ (in [`SimSession::organs`]
    /// order), interpolated between the keyframes around the time.
    pub positions: Vec<Vec<DVec3>>,
    /// The project whose template meshes the positions belong to (the
    /// proxy's for a proxy frame).
    pub meshes: Arc<Project>,
    pub kind: FrameKind,
    /// An earlier run's frame.
    pub stale: bool,
}

/// Every converged keyframe of one finished run, the bud first.
#[derive(Clone)]
pub struct Outcome {
    /// The organs run, indices into the project's organs.
    pub organs: Vec<usize>,
    /// The project run: its template meshes are the keyframes'.
    pub project: Arc<Project>,
    pub keyframes: Vec<Arc<Keyframe>>,
}

/// The frames shown for one selection of organs, set aside while another
/// selection is simulated (the whole flower while one organ is previewed).
struct Stash {
    organs: Vec<usize>,
    frames: Vec<Option<Frame>>,
}

/// Keyframes and status of the newest run.
pub struct SimSession {
    source: Source,
    run: RunId,
    /// What the current run simulates: indices into the project's organs, in
    /// keyframe order.
    organs: Vec<usize>,
    /// The current run's project (its converged meshes) and proxy.
    project: Option<Arc<Project>>,
    proxy: Option<Arc<Project>>,
    /// Keyframes the run will produce after the bud.
    total: u32,
    /// The current run's converged keyframes, contiguous from the bud.
    keyframes: Vec<Arc<Keyframe>>,
    /// What each keyframe index shows (see the module documentation).
    frames: Vec<Option<Frame>>,
    /// The frames of the selection simulated before this one.
    stash: Option<Stash>,
    status: RunStatus,
    started_at: Option<Instant>,
    /// What `elapsed` answers instead of the clock (`freeze_elapsed`).
    frozen_elapsed: Option<Duration>,
    /// Newton iteration inside the keyframe being computed.
    iteration: Option<(u32, u32)>,
    /// The first keyframe the current run computes (see `Event::Started`).
    first_computed: u32,
    /// Whether the current run's proxy is still being computed.
    proxy_running: bool,
    /// What crosses in the current run's converged keyframes, by keyframe
    /// (the run warns and goes on; see `Event::Crossed`).
    crossed: BTreeMap<u32, Arc<Crossings>>,
    /// The serial number of the next frame.
    next_serial: u64,
    /// The newest finished run's result for each selection of organs run
    /// lately (at most [`FINISHED_KEPT`], the newest last).
    finished: Vec<Outcome>,
    /// The result before the last change (see the module documentation).
    before: Option<Outcome>,
    /// Counts the changes of `before`.
    before_revision: u64,
}

/// How many selections' finished results the session keeps (the whole
/// flower and a previewed organ or two), for "before".
pub const FINISHED_KEPT: usize = 3;

/// Longest time one frame spends taking events from the worker.
pub const DRAIN_BUDGET: Duration = Duration::from_millis(4);

impl SimSession {
    /// A session over the engine's worker; `wake` is called from the worker
    /// thread after each event (pass the UI's repaint request).
    pub fn with_worker(wake: impl Fn() + Send + Sync + 'static) -> std::io::Result<SimSession> {
        Ok(Self::new(Source::Worker(Worker::spawn(wake)?)))
    }

    /// A session without a worker: keyframes come only through
    /// [`SimSession::accept`].
    pub fn recorded() -> SimSession {
        Self::new(Source::Recorded { next_run: 0 })
    }

    fn new(source: Source) -> SimSession {
        SimSession {
            source,
            run: 0,
            organs: Vec::new(),
            project: None,
            proxy: None,
            total: 0,
            keyframes: Vec::new(),
            frames: Vec::new(),
            stash: None,
            status: RunStatus::Idle,
            started_at: None,
            frozen_elapsed: None,
            iteration: None,
            first_computed: 1,
            proxy_running: false,
            crossed: BTreeMap::new(),
            next_serial: 0,
            finished: Vec::new(),
            before: None,
            before_revision: 0,
        }
    }

    /// Starts a new run of `project`, superseding (and cancelling) the
    /// current one. What was shown so far stays shown, as stale keyframes,
    /// until the new run's keyframes arrive (see [`SimSession::shown_end`]);
    /// unless it cannot stand for the new run (other meshes). A run of
    /// other organs (a preview switched on or off) sets the shown frames
    /// aside and brings back those of its own organs, if they were set
    /// aside before.
    pub fn start(&mut self, project: Arc<Project>, selection: Selection) -> RunId {
        self.start_with_proxy(project, None, selection)
    }

    /// [`SimSession::start`] with a proxy of `project` (coarser meshes),
    /// computed and shown first.
    pub fn start_with_proxy(
        &mut self,
        project: Arc<Project>,
        proxy: Option<Arc<Project>>,
        selection: Selection,
    ) -> RunId {
        let organs = selection.organs(project.flower.organs.len());
        // The newest finished result of these organs becomes "before" when
        // this run is of another project (see the module documentation).
        if let Some(finished) = self.finished.iter().find(|f| f.organs == organs)
            && !Arc::ptr_eq(&finished.project, &project)
            && *finished.project != *project
            && !self
                .before
                .as_ref()
                .is_some_and(|b| Arc::ptr_eq(&b.project, &finished.project))
        {
            self.before = Some(finished.clone());
            self.before_revision += 1;
        }
        if organs != self.organs {
            let frames = std::mem::take(&mut self.frames);
            let previous = self.stash.replace(Stash {
                organs: self.organs.clone(),
                frames,
            });
            if let Some(stash) = previous.filter(|s| s.organs == organs) {
                self.frames = stash.frames;
            }
        }
        // The bud (always a converged frame) tells which meshes the shown
        // frames stand for: other meshes (a resolution or a template
        // changed) cannot stand for the new run.
        let fits = |frame: &Frame| {
            frame.kind == FrameKind::Converged
                && frame.keyframe.positions_in_world.len() == organs.len()
                && organs.iter().all(|&o| {
                    o < frame.meshes.flower.organs.len()
                        && o < project.flower.organs.len()
                        && frame.meshes.flower.template_of(o).mesh
                            == project.flower.template_of(o).mesh
                })
        };
        if !self
            .frames
            .first()
            .is_some_and(|f| f.as_ref().is_some_and(fits))
        {
            self.frames.clear();
        }
        self.frames
            .truncate(project.settings.keyframes as usize + 1);
        self.keyframes.clear();
        self.organs = organs;
        self.total = project.settings.keyframes;
        self.run = match &mut self.source {
            Source::Worker(worker) => {
                worker.start_with_proxy(Arc::clone(&project), proxy.clone(), selection)
            }
            Source::Recorded { next_run } => {
                *next_run += 1;
                *next_run
            }
        };
        self.project = Some(project);
        self.proxy = proxy;
        self.status = RunStatus::Queued;
        self.started_at = Some(Instant::now());
        self.iteration = None;
        self.proxy_running = false;
        self.run
    }

    /// Tells the worker which keyframe the view waits for (`None` while
    /// playing or following the newest): it wakes the window at once for
    /// that one and paces the others, so the window's redraws leave the
    /// solver its cores.
    pub fn set_viewed_keyframe(&self, keyframe: Option<u32>) {
        if let Source::Worker(worker) = &self.source {
            worker.set_viewed_keyframe(keyframe);
        }
    }

    /// Forgets everything shown (a new or opened document: the old
    /// project's frames must not stand in for the new one's).
    pub fn forget_shown(&mut self) {
        self.keyframes.clear();
        self.frames.clear();
        self.stash = None;
        self.finished.clear();
        if self.before.take().is_some() {
            self.before_revision += 1;
        }
    }

    /// Cancels the current run, if any; the keyframes so far stay.
    pub fn cancel(&mut self) {
        if let Source::Worker(worker) = &self.source {
            worker.cancel();
        }
        if matches!(self.status, RunStatus::Queued | RunStatus::Running) {
            self.status = RunStatus::Failed {
                message: "stopped".to_string(),
            };
        }
    }

    /// Takes the worker's waiting events for at most `budget`. Returns the
    /// messages of failed runs (for the log) and whether anything changed.
    pub fn drain(&mut self, budget: Duration) -> Drained {
        let mut drained = Drained::default();
        let Source::Worker(worker) = &self.source else {
            return drained;
        };
        let started = Instant::now();
        let mut events = Vec::new();
        while started.elapsed() < budget {
            match worker.try_event() {
                Some(event) => events.push(event),
                None => break,
            }
        }
        for event in events {
            let finished = matches!(event, Event::Finished { .. });
            let accepted = self.accept_into(event, &mut drained);
            drained.changed |= accepted;
            drained.finished |= accepted && finished;
        }
        drained
    }

    /// Applies one event; events of other runs are ignored (returns false).
    /// Failure messages are appended to `failures`.
    pub fn accept(&mut self, event: Event, failures: &mut Vec<String>) -> bool {
        let mut drained = Drained::default();
        let accepted = self.accept_into(event, &mut drained);
        failures.append(&mut drained.failures);
        accepted
    }

    /// Sets what index `index` shows, growing the list as needed.
    fn show(&mut self, index: u32, frame: Frame) {
        let index = index as usize;
        if self.frames.len() <= index {
            self.frames.resize(index + 1, None);
        }
        self.frames[index] = Some(frame);
    }

    fn frame(&mut self, keyframe: Arc<Keyframe>, kind: FrameKind) -> Option<Frame> {
        let meshes = match kind {
            FrameKind::Converged => self.project.as_ref()?,
            FrameKind::Proxy => self.proxy.as_ref()?,
        };
        self.next_serial += 1;
        Some(Frame {
            keyframe,
            meshes: Arc::clone(meshes),
            kind,
            run: self.run,
            serial: self.next_serial,
        })
    }

    fn accept_into(&mut self, event: Event, drained: &mut Drained) -> bool {
        if event.run() != self.run {
            return false;
        }
        match event {
            Event::Started {
                keyframes,
                first_computed,
                proxy,
                ..
            } => {
                self.total = keyframes;
                self.first_computed = first_computed;
                self.status = RunStatus::Running;
                self.proxy_running = proxy;
                self.crossed.clear();
            }
            Event::Crossed { crossings, .. } => {
                self.crossed.insert(crossings.keyframe, crossings);
            }
            Event::Keyframe { keyframe, .. } => {
                if keyframe.index as usize == self.keyframes.len() {
                    let index = keyframe.index;
                    self.keyframes.push(Arc::clone(&keyframe));
                    if let Some(frame) = self.frame(keyframe, FrameKind::Converged) {
                        self.show(index, frame);
                    }
                }
                self.iteration = None;
            }
            Event::Proxy { keyframe, .. } => {
                let index = keyframe.index;
                if index as usize >= self.keyframes.len()
                    && let Some(frame) = self.frame(keyframe, FrameKind::Proxy)
                {
                    self.show(index, frame);
                }
                self.iteration = None;
            }
            Event::ProxyEnded { error, .. } => {
                self.proxy_running = false;
                self.iteration = None;
                if let Some(error) = error {
                    drained.notes.push(format!(
                        "the quick preview (proxy) stopped: {error}; the full-resolution run goes on"
                    ));
                }
            }
            Event::Progress { progress, .. } => {
                self.iteration = Some((progress.keyframe, progress.iteration));
            }
            Event::Finished { seconds, .. } => {
                // Every keyframe of the run is converged now; earlier runs'
                // keyframes past its end (the count was lowered) go too.
                self.frames.truncate(self.keyframes.len());
                if let Some(project) = &self.project
                    && self.keyframes.len() == self.total as usize + 1
                {
                    self.finished.retain(|f| f.organs != self.organs);
                    if self.finished.len() >= FINISHED_KEPT {
                        self.finished.remove(0);
                    }
                    self.finished.push(Outcome {
                        organs: self.organs.clone(),
                        project: Arc::clone(project),
                        keyframes: self.keyframes.clone(),
                    });
                }
                if let Some(note) = self.crossing_note() {
                    drained.warnings.push(note);
                }
                self.status = RunStatus::Finished {
                    seconds,
                    first_computed: self.first_computed,
                };
                self.iteration = None;
            }
            Event::Failed { error, .. } => {
                let message = error.to_string();
                drained.failures.push(message.clone());
                self.status = RunStatus::Failed { message };
                self.iteration = None;
                self.proxy_running = false;
                // What the run did not confirm is not shown as its result.
                self.frames.truncate(self.keyframes.len());
            }
            Event::Cancelled { .. } => {
                self.iteration = None;
                self.proxy_running = false;
            }
        }
        true
    }

    /// The current run's id (events of other runs are ignored).
    pub fn run(&self) -> RunId {
        self.run
    }

    pub fn status(&self) -> &RunStatus {
        &self.status
    }

    pub fn is_running(&self) -> bool {
        matches!(self.status, RunStatus::Queued | RunStatus::Running)
    }

    /// Whether the current run's proxy is still being computed.
    pub fn proxy_running(&self) -> bool {
        self.proxy_running
    }

    /// Project organ indices of the keyframes' position lists.
    pub fn organs(&self) -> &[usize] {
        &self.organs
    }

    /// Keyframes the run produces after the bud.
    pub fn total(&self) -> u32 {
        self.total
    }

    /// The current run's converged keyframes received, the bud first.
    pub fn keyframes(&self) -> &[Arc<Keyframe>] {
        &self.keyframes
    }

    /// Index of the newest converged keyframe received, if any.
    pub fn last_index(&self) -> Option<u32> {
        self.keyframes.last().map(|k| k.index)
    }

    /// Statistics of the computed keyframes after the bud.
    pub fn stats(&self) -> impl Iterator<Item = &KeyframeStats> {
        self.keyframes.iter().skip(1).map(|k| &k.stats)
    }

    /// `(keyframe, iteration)` being computed now.
    pub fn iteration(&self) -> Option<(u32, u32)> {
        self.iteration
    }

    /// Seconds since the run was asked for.
    pub fn elapsed(&self) -> Option<Duration> {
        self.started_at
            .map(|t| self.frozen_elapsed.unwrap_or_else(|| t.elapsed()))
    }

    /// Makes `elapsed` answer `elapsed` from now on, whatever the clock
    /// says: for pictures of the window (snapshots) that must not depend on
    /// how fast the machine drew them.
    pub fn freeze_elapsed(&mut self, elapsed: Duration) {
        self.frozen_elapsed = Some(elapsed);
    }

    /// Estimated seconds left, from the mean time per keyframe so far.
    pub fn seconds_left(&self) -> Option<f64> {
        if !self.is_running() || self.proxy_running {
            return None;
        }
        let done = self.last_index()?;
        if done == 0 {
            return None;
        }
        let computed: Vec<f64> = self
            .stats()
            .skip(self.first_computed.saturating_sub(1) as usize)
            .map(|s| s.seconds)
            .collect();
        let per_keyframe = if computed.is_empty() {
            self.stats().map(|s| s.seconds).sum::<f64>() / f64::from(done)
        } else {
            computed.iter().sum::<f64>() / computed.len() as f64
        };
        Some(per_keyframe * f64::from(self.total.saturating_sub(done)))
    }

    /// Index of the newest keyframe that can be shown: the current run's
    /// (converged or proxy) or, past it, an earlier run's (stale).
    pub fn shown_end(&self) -> Option<u32> {
        let shown = self.frames.iter().take_while(|f| f.is_some()).count();
        shown.checked_sub(1).map(|last| last as u32)
    }

    /// What keyframe index `index` shows, if anything.
    pub fn frame_state(&self, index: usize) -> Option<FrameState> {
        let frame = self.frames.get(index)?.as_ref()?;
        Some(if frame.run != self.run {
            FrameState::Stale
        } else if frame.kind == FrameKind::Proxy {
            FrameState::Proxy
        } else {
            FrameState::Converged
        })
    }

    /// What the view at `time_in_keyframes` shows: the state of the
    /// keyframe at or after it (the newest shown past the end).
    pub fn state_at(&self, time_in_keyframes: f64) -> Option<FrameState> {
        let end = self.shown_end()? as usize;
        self.frame_state((time_in_keyframes.max(0.0).ceil() as usize).min(end))
    }

    /// What crosses in the converged keyframe the view at
    /// `time_in_keyframes` shows (the one at or after it, as
    /// [`SimSession::state_at`] picks it), if anything.
    pub fn crossing_at(&self, time_in_keyframes: f64) -> Option<&Crossings> {
        if self.state_at(time_in_keyframes) != Some(FrameState::Converged) {
            return None;
        }
        let end = self.shown_end()?;
        let index = (time_in_keyframes.max(0.0).ceil() as u32).min(end);
        self.crossed.get(&index).map(Arc::as_ref)
    }

    /// The current run's converged keyframes in which organs cross.
    pub fn crossed_keyframes(&self) -> impl Iterator<Item = u32> + '_ {
        self.crossed.keys().copied()
    }

    /// One line for the log when a run's organs cross: the first crossing
    /// and how many keyframes have one.
    fn crossing_note(&self) -> Option<String> {
        let first = self.crossed.values().next()?;
        let count = self.crossed.len();
        let more = if count > 1 {
            format!(
                " (and {} later keyframe{})",
                count - 1,
                if count == 2 { "" } else { "s" }
            )
        } else {
            String::new()
        };
        Some(format!(
            "organs pass through each other: {first}{more}; the timeline marks them red. \
             Painting less growth where they meet keeps them apart"
        ))
    }

    /// Which frames the view at `time_in_keyframes` shows (the two it
    /// blends, as [`SimSession::shown_at`] picks them), as serial numbers
    /// that change whenever another frame takes their place: the scene
    /// needs building again exactly when these change.
    pub fn frames_at(&self, time_in_keyframes: f64) -> Option<(u64, u64)> {
        let count = self.shown_end()? as usize + 1;
        let blend = KeyframeBlend::at(count, time_in_keyframes)?;
        let serial = |i: usize| self.frames.get(i)?.as_ref().map(|f| f.serial);
        Some((serial(blend.below)?, serial(blend.above)?))
    }

    /// Whether the view at `time_in_keyframes` shows an earlier run's
    /// keyframe: the current run has not computed the keyframe at or after
    /// it yet.
    pub fn is_stale_at(&self, time_in_keyframes: f64) -> bool {
        self.state_at(time_in_keyframes) == Some(FrameState::Stale)
    }

    /// The organs at `time_in_keyframes`, interpolated linearly between the
    /// two keyframes around it where both are on the same meshes (else the
    /// nearer one); times past the newest shown keyframe show the newest.
    /// `None` before the bud.
    pub fn shown_at(&self, time_in_keyframes: f64) -> Option<ShownAt> {
        let count = self.shown_end()? as usize + 1;
        let blend = KeyframeBlend::at(count, time_in_keyframes)?;
        let below = self.frames.get(blend.below)?.as_ref()?;
        let above = self.frames.get(blend.above)?.as_ref()?;
        let same_meshes = below.kind == above.kind
            && below
                .keyframe
                .positions_in_world
                .iter()
                .map(Vec::len)
                .eq(above.keyframe.positions_in_world.iter().map(Vec::len));
        let (positions, frame) = if same_meshes {
            let positions = below
                .keyframe
                .positions_in_world
                .iter()
                .zip(&above.keyframe.positions_in_world)
                .map(|(a, b)| blend.positions(a, b))
                .collect();
            (positions, above)
        } else {
            let nearer = if time_in_keyframes - blend.below as f64 <= 0.5 {
                below
            } else {
                above
            };
            (nearer.keyframe.positions_in_world.clone(), nearer)
        };
        Some(ShownAt {
            positions,
            meshes: Arc::clone(&frame.meshes),
            kind: frame.kind,
            stale: frame.run != self.run,
        })
    }

    /// Every converged keyframe of a finished run of `organs` of exactly
    /// `project` (the current run's, or the frames set aside for another
    /// selection), or `None` when there is no such complete run (for an
    /// export of the whole flower while one organ is previewed).
    pub fn complete_run_of(
        &self,
        organs: &[usize],
        project: &Project,
    ) -> Option<Vec<Arc<Keyframe>>> {
        let complete = |frames: &[Option<Frame>], total: u32| {
            let first = frames.first()?.as_ref()?;
            let all: Option<Vec<Arc<Keyframe>>> = frames
                .iter()
                .map(|f| {
                    f.as_ref()
                        .filter(|f| {
                            f.kind == FrameKind::Converged
                                && f.run == first.run
                                && *f.meshes == *project
                        })
                        .map(|f| Arc::clone(&f.keyframe))
                })
                .collect();
            all.filter(|all| all.len() == total as usize + 1)
        };
        if organs == self.organs.as_slice() {
            return matches!(self.status, RunStatus::Finished { .. })
                .then(|| complete(&self.frames, self.total))
                .flatten();
        }
        let stash = self.stash.as_ref().filter(|s| s.organs == organs)?;
        complete(&stash.frames, project.settings.keyframes)
    }

    /// The result before the last change (see the module documentation),
    /// if there is one and it is of the organs run now.
    pub fn before(&self) -> Option<&Outcome> {
        self.before.as_ref().filter(|b| b.organs == self.organs)
    }

    /// Counts the changes of [`SimSession::before`]: the scene of the
    /// result before needs building again when it changes.
    pub fn before_revision(&self) -> u64 {
        self.before_revision
    }

    /// The organs of the result before the last change at
    /// `time_in_keyframes`, interpolated as [`SimSession::shown_at`] does
    /// (times past its end show its last keyframe); `None` when there is
    /// no such result (see [`SimSession::before`]).
    pub fn before_at(&self, time_in_keyframes: f64) -> Option<ShownAt> {
        let before = self.before()?;
        let blend = KeyframeBlend::at(before.keyframes.len(), time_in_keyframes)?;
        let below = before.keyframes.get(blend.below)?;
        let above = before.keyframes.get(blend.above)?;
        Some(ShownAt {
            positions: below
                .positions_in_world
                .iter()
                .zip(&above.positions_in_world)
                .map(|(a, b)| blend.positions(a, b))
                .collect(),
            meshes: Arc::clone(&before.project),
            kind: FrameKind::Converged,
            stale: false,
        })
    }

    /// Positions of every simulated organ at `time_in_keyframes` (see
    /// [`SimSession::shown_at`]).
    pub fn positions_at(&self, time_in_keyframes: f64) -> Option<Vec<Vec<DVec3>>> {
        self.shown_at(time_in_keyframes).map(|s| s.positions)
    }
}

/// What [`SimSession::drain`] took.
#[derive(Debug, Default)]
pub struct Drained {
    pub changed: bool,
    /// The current run finished.
    pub finished: bool,
    pub failures: Vec<String>,
    /// Things worth a line in the log that stop nothing (a proxy that
    /// failed).
    pub notes: Vec<String>,
    /// Things the user should look at that stop nothing (organs crossing).
    pub warnings: Vec<String>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn keyframe(index: u32, x: f64) -> Arc<Keyframe> {
        Arc::new(Keyframe {
            index,
            positions_in_world: vec![vec![DVec3::new(x, 0.0, 0.0)]],
            stats: KeyframeStats {
                index,
                energy: 1.0,
                iterations: 2,
                relative_gradient: 0.0,
                seconds: 0.5,
                pushed_particles: 0,
                contact_particles: 0,
            },
        })
    }

    /// Keyframe `index` of a run of all of `project`'s organs, every
    /// particle at x = `x`.
    fn keyframe_of(project: &Project, index: u32, x: f64) -> Arc<Keyframe> {
        let positions_in_world = (0..project.flower.organs.len())
            .map(|o| {
                let count = project.flower.template_of(o).mesh.vertex_count();
                vec![DVec3::new(x, 0.0, 0.0); count]
            })
            .collect();
        Arc::new(Keyframe {
            positions_in_world,
            ..(*keyframe(index, x)).clone()
        })
    }

    fn feed(session: &mut SimSession, project: &Project, run: RunId, xs: &[f64]) {
        for (i, &x) in xs.iter().enumerate() {
            let keyframe = keyframe_of(project, i as u32, x);
            assert!(session.accept(Event::Keyframe { run, keyframe }, &mut Vec::new()));
        }
    }

    fn x_at(session: &SimSession, time: f64) -> f64 {
        session.positions_at(time).expect("something shown")[0][0].x
    }

    #[test]
    fn a_new_run_shows_the_previous_keyframes_stale_until_its_own_arrive() {
        let project = Arc::new(anthesis_sim::fixtures::whorl(2, 4, 6, 5));
        let mut session = SimSession::recorded();
        let first = session.start(Arc::clone(&project), Selection::All);
        feed(
            &mut session,
            &project,
            first,
            &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0],
        );
        assert!(session.accept(
            Event::Finished {
                run: first,
                keyframes: 5,
                seconds: 1.0
            },
            &mut Vec::new()
        ));
        assert!(!session.is_stale_at(3.0));

        let second = session.start(Arc::clone(&project), Selection::All);
        assert_eq!(session.last_index(), None, "nothing of the new run yet");
        assert_eq!(session.shown_end(), Some(5), "the old run stays shown");
        assert!(session.is_stale_at(3.0) && session.state_at(3.0) != Some(FrameState::Converged));
        assert_eq!(x_at(&session, 3.0), 3.0);

        feed(&mut session, &project, second, &[0.0, 10.0, 20.0, 30.0]);
        assert!(!session.is_stale_at(3.0) && session.state_at(3.0) == Some(FrameState::Converged));
        assert_eq!(x_at(&session, 3.0), 30.0, "the new keyframe replaces it");
        assert!(session.is_stale_at(3.5) && session.is_stale_at(5.0));
        assert_eq!(
            x_at(&session, 3.5),
            0.5 * (30.0 + 4.0),
            "blends new and old"
        );
        assert_eq!(x_at(&session, 5.0), 5.0);

        // A third run before the second finished: the newest of each
        // keyframe stays shown.
        let third = session.start(Arc::clone(&project), Selection::All);
        assert_eq!(x_at(&session, 2.0), 20.0);
        assert_eq!(x_at(&session, 5.0), 5.0);
        feed(
            &mut session,
            &project,
            third,
            &[0.0, 1.5, 2.5, 3.5, 4.5, 5.5],
        );
        assert!(session.accept(
            Event::Finished {
                run: third,
                keyframes: 5,
                seconds: 1.0
            },
            &mut Vec::new()
        ));
        assert!(!session.is_stale_at(5.0));
        assert_eq!(x_at(&session, 5.0), 5.5);
    }

    #[test]
    fn frames_that_cannot_fit_the_new_run_are_not_shown() {
        let project = Arc::new(anthesis_sim::fixtures::whorl(2, 4, 6, 3));
        let mut session = SimSession::recorded();
        let run = session.start(Arc::clone(&project), Selection::All);
        feed(&mut session, &project, run, &[0.0, 1.0, 2.0, 3.0]);

        // Other organs (a single-organ preview): nothing to show.
        session.start(Arc::clone(&project), Selection::Only(1));
        assert_eq!(session.shown_end(), None);

        // Other meshes (a finer resolution): nothing to show.
        let run = session.start(Arc::clone(&project), Selection::All);
        feed(&mut session, &project, run, &[0.0, 1.0, 2.0, 3.0]);
        let finer = Arc::new(anthesis_sim::fixtures::whorl(2, 6, 8, 3));
        session.start(finer, Selection::All);
        assert_eq!(session.shown_end(), None);

        // A new document forgets what was shown.
        let run = session.start(Arc::clone(&project), Selection::All);
        feed(&mut session, &project, run, &[0.0, 1.0]);
        session.forget_shown();
        assert_eq!(session.shown_end(), None);
    }

    #[test]
    fn interpolates_linearly_and_drops_superseded_runs() {
        let project = Arc::new(anthesis_sim::fixtures::whorl(1, 4, 6, 4));
        let mut session = SimSession::recorded();
        let old = session.start(Arc::clone(&project), Selection::All);
        let run = session.start(project, Selection::All);
        let mut failures = Vec::new();
        assert!(!session.accept(
            Event::Keyframe {
                run: old,
                keyframe: keyframe(0, 99.0)
            },
            &mut failures
        ));
        for (i, x) in [(0, 0.0), (1, 2.0)] {
            assert!(session.accept(
                Event::Keyframe {
                    run,
                    keyframe: keyframe(i, x)
                },
                &mut failures
            ));
        }
        let at = |t| session.positions_at(t).expect("frames")[0][0].x;
        assert_eq!(at(0.25), 0.5);
        assert_eq!(at(1.0), 2.0);
        // Past the newest keyframe: the newest.
        assert_eq!(at(3.5), 2.0);
        assert_eq!(session.last_index(), Some(1));
        // Half a second per keyframe, one done, three to go.
        assert_eq!(session.seconds_left(), Some(1.5));
    }

    /// Feeds a real worker's events of `run` into `session` until the run
    /// ends; returns the failures reported.
    fn follow(worker: &Worker, session: &mut SimSession, run: RunId) -> Vec<String> {
        let mut failures = Vec::new();
        loop {
            let event = worker
                .wait_event(Duration::from_secs(60))
                .expect("the worker answers");
            let end = event.ends(run);
            session.accept(event, &mut failures);
            if end {
                return failures;
            }
        }
    }

    #[test]
    fn a_panic_in_the_worker_is_a_message_and_the_work_stays() {
        use anthesis_sim::fault::Fault;
        let project = Arc::new(anthesis_sim::fixtures::whorl(1, 6, 10, 4));
        let before = (*project).clone();
        let worker = Worker::spawn(|| {}).expect("thread");
        let mut session = SimSession::recorded();

        let run = session.start(Arc::clone(&project), Selection::All);
        let worker_run = worker.start_with_fault(
            Arc::clone(&project),
            Selection::All,
            Fault::PanicAtKeyframe(3),
        );
        assert_eq!(run, worker_run, "both count runs from 1");
        let failures = follow(&worker, &mut session, run);
        let expected = format!(
            "run {run}, keyframe 3: internal error, the simulation stopped (a bug in Anthesis; \
             please report it): forced fault at keyframe 3 (test hook)"
        );
        assert_eq!(failures.len(), 1, "one message for the log");
        assert_eq!(failures[0], expected);
        assert_eq!(*session.status(), RunStatus::Failed { message: expected });
        // The keyframes computed before the panic stay on the timeline and
        // the document the run read is as it was.
        assert_eq!(session.last_index(), Some(2));
        assert_eq!(*project, before);

        // The same worker runs the next request to the end.
        let next = session.start(Arc::clone(&project), Selection::All);
        assert_eq!(worker.start(project, Selection::All), next);
        assert!(follow(&worker, &mut session, next).is_empty());
        assert!(matches!(session.status(), RunStatus::Finished { .. }));
        assert_eq!(session.last_index(), Some(4));
    }

    #[test]
    fn a_stroke_on_the_late_key_keeps_the_frames_before_it_and_says_so() {
        let before = anthesis_sim::fixtures::whorl(2, 6, 10, 44);
        let mut after = before.clone();
        anthesis_sim::fixtures::stroke_near_tip(&mut after, 0, 1);
        let worker = Worker::spawn(|| {}).expect("thread");
        let mut session = SimSession::recorded();
        for project in [before, after] {
            let project = Arc::new(project);
            let run = session.start(Arc::clone(&project), Selection::All);
            assert_eq!(worker.start(project, Selection::All), run);
            assert!(follow(&worker, &mut session, run).is_empty());
        }
        assert_eq!(session.last_index(), Some(44));
        assert!(matches!(
            session.status(),
            RunStatus::Finished {
                first_computed: 40,
                ..
            }
        ));
        let line = crate::desktop::timeline::status_line(&session);
        assert!(
            line.starts_with("keyframes 40–44 in ")
                && line.ends_with("(39 kept: the edit cannot change them)"),
            "{line}"
        );
    }

    /// `project` with every template's mesh a coarser grid (a proxy as
    /// far as the session can tell: other meshes, same organs).
    fn proxy_of(project: &Project) -> Arc<Project> {
        let mut proxy = project.clone();
        for template in &mut proxy.flower.templates {
            template.mesh = anthesis_mesh::generate::test_petal(10.0, 4.0, 3, 4);
        }
        Arc::new(proxy)
    }

    fn proxy_keyframe(proxy: &Project, index: u32, x: f64) -> Arc<Keyframe> {
        keyframe_of(proxy, index, x)
    }

    fn started(session: &mut SimSession, run: RunId, keyframes: u32, proxy: bool) {
        assert!(session.accept(
            Event::Started {
                run,
                organs: Vec::new(),
                keyframes,
                first_computed: 1,
                proxy,
            },
            &mut Vec::new()
        ));
    }

    #[test]
    fn crossings_mark_their_converged_keyframes_and_are_told_once_when_the_run_ends() {
        use anthesis_sim::crossing::Crossed;
        let project = Arc::new(anthesis_sim::fixtures::whorl(2, 4, 6, 3));
        let mut session = SimSession::recorded();
        let run = session.start(Arc::clone(&project), Selection::All);
        started(&mut session, run, 3, false);
        feed(&mut session, &project, run, &[0.0, 1.0, 2.0, 3.0]);
        let organ = |index: usize, name: &str| Crossed::Organ {
            index,
            name: name.to_string(),
            uv: glam::DVec2::new(0.5, 0.9),
        };
        for keyframe in [2, 3] {
            let crossings = Arc::new(Crossings {
                keyframe,
                pairs: 4,
                between: vec![(organ(0, "petal-1"), organ(1, "petal-2"), 4)],
                organs: vec![0, 1],
                from_bud: false,
            });
            assert!(session.accept(Event::Crossed { run, crossings }, &mut Vec::new()));
        }
        assert_eq!(session.crossed_keyframes().collect::<Vec<_>>(), [2, 3]);
        assert!(session.crossing_at(1.0).is_none());
        assert_eq!(session.crossing_at(1.5).map(|c| c.keyframe), Some(2));
        assert_eq!(
            crate::desktop::timeline::crossing_badge(&session, 3.0).as_deref(),
            Some("CROSSING: petal-1 / petal-2")
        );
        let mut drained = Drained::default();
        let finished = Event::Finished {
            run,
            keyframes: 3,
            seconds: 0.1,
        };
        assert!(session.accept_into(finished, &mut drained));
        assert_eq!(drained.warnings.len(), 1, "{:?}", drained.warnings);
        let warning = &drained.warnings[0];
        assert!(
            warning.contains("keyframe 2: `petal-1` at uv (0.50, 0.90) passes through `petal-2`")
                && warning.contains("(and 1 later keyframe)"),
            "{warning}"
        );
        // The next run starts clean (the worker sends the kept ones again).
        let next = session.start(Arc::clone(&project), Selection::All);
        started(&mut session, next, 3, false);
        assert_eq!(session.crossed_keyframes().count(), 0);
    }

    #[test]
    fn proxy_frames_show_first_on_their_own_meshes_and_converged_ones_replace_them() {
        let project = Arc::new(anthesis_sim::fixtures::whorl(2, 4, 6, 3));
        let proxy = proxy_of(&project);
        let mut session = SimSession::recorded();
        let run = session.start_with_proxy(
            Arc::clone(&project),
            Some(Arc::clone(&proxy)),
            Selection::All,
        );
        started(&mut session, run, 3, true);
        assert!(session.proxy_running());
        feed(&mut session, &project, run, &[0.0]);
        for (i, x) in [(1, 10.0), (2, 20.0), (3, 30.0)] {
            let keyframe = proxy_keyframe(&proxy, i, x);
            assert!(session.accept(Event::Proxy { run, keyframe }, &mut Vec::new()));
        }
        assert_eq!(session.shown_end(), Some(3));
        assert_eq!(session.last_index(), Some(0), "only the bud is converged");
        assert_eq!(session.state_at(2.0), Some(FrameState::Proxy));
        let shown = session.shown_at(2.0).expect("shown");
        assert_eq!(shown.kind, FrameKind::Proxy);
        assert!(
            Arc::ptr_eq(&shown.meshes, &proxy),
            "drawn on the proxy's meshes"
        );
        assert_eq!(
            shown.positions[0].len(),
            proxy.flower.template_of(0).mesh.vertex_count()
        );
        // Between two proxy frames: blended.
        assert_eq!(
            session.shown_at(2.5).expect("shown").positions[0][0].x,
            25.0
        );
        assert!(session.accept(
            Event::ProxyEnded {
                run,
                seconds: 0.1,
                error: None
            },
            &mut Vec::new()
        ));
        assert!(!session.proxy_running());

        // The converged keyframes 1 and 2 arrive and replace the proxy's:
        // the view at 2 shows other frames (its scene is built again), the
        // view at 3 the same.
        let (at_2, at_3) = (session.frames_at(2.0), session.frames_at(3.0));
        for (i, x) in [(1, 1.0), (2, 2.0)] {
            let keyframe = keyframe_of(&project, i, x);
            assert!(session.accept(Event::Keyframe { run, keyframe }, &mut Vec::new()));
        }
        assert_eq!(session.state_at(2.0), Some(FrameState::Converged));
        assert_eq!(session.state_at(2.5), Some(FrameState::Proxy));
        assert_ne!(session.frames_at(2.0), at_2);
        assert_eq!(session.frames_at(3.0), at_3);
        let shown = session.shown_at(2.0).expect("shown");
        assert!(Arc::ptr_eq(&shown.meshes, &project));
        assert_eq!(shown.positions[0][0].x, 2.0);
        // Between a converged and a proxy frame (other meshes): the nearer.
        assert_eq!(session.shown_at(2.4).expect("shown").positions[0][0].x, 2.0);
        assert_eq!(
            session.shown_at(2.6).expect("shown").positions[0][0].x,
            30.0
        );
        assert!(
            session.state_at(3.0) != Some(FrameState::Converged)
                && session.state_at(2.0) == Some(FrameState::Converged)
        );
        assert_eq!(
            crate::desktop::timeline::stale_line(&session, 3.0).as_deref(),
            Some("proxy: coarse preview until the full-resolution run reaches 3")
        );
        assert_eq!(
            crate::desktop::timeline::viewport_badge(&session, 3.0).map(|b| b.0),
            Some("PROXY")
        );
        assert_eq!(
            crate::desktop::timeline::viewport_badge(&session, 2.0),
            None
        );
    }

    #[test]
    fn a_failed_run_does_not_show_the_proxy_frames_it_never_confirmed() {
        let project = Arc::new(anthesis_sim::fixtures::whorl(1, 4, 6, 3));
        let proxy = proxy_of(&project);
        let mut session = SimSession::recorded();
        let run = session.start_with_proxy(
            Arc::clone(&project),
            Some(Arc::clone(&proxy)),
            Selection::All,
        );
        started(&mut session, run, 3, true);
        feed(&mut session, &project, run, &[0.0, 1.0]);
        for i in 2..=3 {
            let keyframe = proxy_keyframe(&proxy, i, 9.0);
            session.accept(Event::Proxy { run, keyframe }, &mut Vec::new());
        }
        assert_eq!(session.shown_end(), Some(3));
        let mut failures = Vec::new();
        session.accept(
            Event::Failed {
                run,
                error: anthesis_sim::SimError::Cancelled,
            },
            &mut failures,
        );
        assert_eq!(failures.len(), 1);
        assert_eq!(session.shown_end(), Some(1));
    }

    #[test]
    fn a_preview_and_back_brings_the_whole_flowers_frames_back_at_once() {
        let project = Arc::new(anthesis_sim::fixtures::whorl(2, 4, 6, 3));
        let mut session = SimSession::recorded();
        let whole = session.start(Arc::clone(&project), Selection::All);
        started(&mut session, whole, 3, false);
        feed(&mut session, &project, whole, &[0.0, 1.0, 2.0, 3.0]);
        assert!(session.accept(
            Event::Finished {
                run: whole,
                keyframes: 3,
                seconds: 1.0
            },
            &mut Vec::new()
        ));
        let all = [0, 1];
        assert_eq!(
            session.complete_run_of(&all, &project).map(|k| k.len()),
            Some(4)
        );

        // The preview of organ 1: nothing of it yet; the whole flower's
        // keyframes are kept aside, complete.
        let alone = session.start(Arc::clone(&project), Selection::Only(1));
        assert_eq!(session.shown_end(), None);
        assert_eq!(
            session.complete_run_of(&all, &project).map(|k| k.len()),
            Some(4)
        );
        // Not for another project (an edit made in the preview).
        let mut edited = (*project).clone();
        edited.flower.templates[0].dg += 0.001;
        assert!(session.complete_run_of(&all, &edited).is_none());
        started(&mut session, alone, 3, false);

        // Back to the whole flower: its frames are shown at once (stale
        // until the run sends them again).
        session.start(Arc::clone(&project), Selection::All);
        assert_eq!(session.shown_end(), Some(3));
        assert!(session.is_stale_at(2.0));
        assert_eq!(x_at(&session, 2.0), 2.0);
    }
}

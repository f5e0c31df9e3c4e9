//! The simulation as the window sees it: the engine's worker (or, in tests,
//! keyframes fed in by hand), the keyframes of the current run and its
//! status. Events of superseded runs are dropped by their run id.

use std::sync::Arc;
use std::time::{Duration, Instant};

use anthesis_export::KeyframeBlend;
use anthesis_flower::Project;
use anthesis_sim::worker::{Event, RunId, Worker};
use anthesis_sim::{Keyframe, KeyframeStats, Selection};

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

/// Keyframes and status of the newest run.
pub struct SimSession {
    source: Source,
    run: RunId,
    /// What the current run simulates: indices into the project's organs, in
    /// keyframe order.
    organs: Vec<usize>,
    /// Keyframes the run will produce after the bud.
    total: u32,
    /// Keyframes received so far, contiguous from the bud (index 0).
    keyframes: Vec<Arc<Keyframe>>,
    /// Keyframes of earlier runs of the same organs and meshes, shown
    /// (marked stale) where the current run has not arrived yet, so an edit
    /// keeps the frame the user looks at until its new version is computed.
    /// Emptied when the current run finishes or the document is replaced.
    previous: Vec<Arc<Keyframe>>,
    status: RunStatus,
    started_at: Option<Instant>,
    /// Newton iteration inside the keyframe being computed.
    iteration: Option<(u32, u32)>,
    /// The first keyframe the current run computes (see `Event::Started`).
    first_computed: u32,
}

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
            total: 0,
            keyframes: Vec::new(),
            previous: Vec::new(),
            status: RunStatus::Idle,
            started_at: None,
            iteration: None,
            first_computed: 1,
        }
    }

    /// Whether a worker computes the keyframes.
    pub fn is_live(&self) -> bool {
        matches!(self.source, Source::Worker(_))
    }

    /// Starts a new run of `project`, superseding (and cancelling) the
    /// current one. What was shown so far stays shown, as stale keyframes,
    /// until the new run's keyframes arrive (see [`SimSession::shown_end`]);
    /// unless it cannot fit the new run (other organs, remeshed templates).
    pub fn start(&mut self, project: Arc<Project>, selection: Selection) -> RunId {
        let organs = selection.organs(project.flower.organs.len());
        let mut shown = std::mem::take(&mut self.keyframes);
        let fresh = shown.len();
        shown.extend(self.previous.drain(..).skip(fresh));
        shown.truncate(project.settings.keyframes as usize + 1);
        let fits = |keyframe: &Arc<Keyframe>| {
            keyframe.positions_in_world.len() == organs.len()
                && organs
                    .iter()
                    .zip(&keyframe.positions_in_world)
                    .all(|(&o, p)| p.len() == project.flower.template_of(o).mesh.vertex_count())
        };
        if organs == self.organs && shown.first().is_some_and(fits) {
            self.previous = shown;
        }
        self.organs = organs;
        self.total = project.settings.keyframes;
        self.run = match &mut self.source {
            Source::Worker(worker) => worker.start(project, selection),
            Source::Recorded { next_run } => {
                *next_run += 1;
                *next_run
            }
        };
        self.status = RunStatus::Queued;
        self.started_at = Some(Instant::now());
        self.iteration = None;
        self.run
    }

    /// Forgets everything shown (a new or opened document: the old
    /// project's frames must not stand in for the new one's).
    pub fn forget_shown(&mut self) {
        self.keyframes.clear();
        self.previous.clear();
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
            let accepted = self.accept(event, &mut drained.failures);
            drained.changed |= accepted;
            drained.finished |= accepted && finished;
        }
        drained
    }

    /// Applies one event; events of other runs are ignored (returns false).
    /// Failure messages are appended to `failures`.
    pub fn accept(&mut self, event: Event, failures: &mut Vec<String>) -> bool {
        if event.run() != self.run {
            return false;
        }
        match event {
            Event::Started {
                keyframes,
                first_computed,
                ..
            } => {
                self.total = keyframes;
                self.first_computed = first_computed;
                self.status = RunStatus::Running;
            }
            Event::Keyframe { keyframe, .. } => {
                if keyframe.index as usize == self.keyframes.len() {
                    self.keyframes.push(keyframe);
                }
                self.iteration = None;
            }
            Event::Progress { progress, .. } => {
                self.iteration = Some((progress.keyframe, progress.iteration));
            }
            Event::Finished { seconds, .. } => {
                // Every keyframe of the run is fresh now; earlier runs'
                // keyframes past its end (the count was lowered) go too.
                self.previous.clear();
                self.status = RunStatus::Finished {
                    seconds,
                    first_computed: self.first_computed,
                };
                self.iteration = None;
            }
            Event::Failed { error, .. } => {
                let message = error.to_string();
                failures.push(message.clone());
                self.status = RunStatus::Failed { message };
                self.iteration = None;
            }
            Event::Cancelled { .. } => {
                self.iteration = None;
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

    /// Project organ indices of the keyframes' position lists.
    pub fn organs(&self) -> &[usize] {
        &self.organs
    }

    /// Keyframes the run produces after the bud.
    pub fn total(&self) -> u32 {
        self.total
    }

    /// Keyframes received, the bud first.
    pub fn keyframes(&self) -> &[Arc<Keyframe>] {
        &self.keyframes
    }

    /// Index of the newest keyframe received, if any.
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
        self.started_at.map(|t| t.elapsed())
    }

    /// Estimated seconds left, from the mean time per keyframe so far.
    pub fn seconds_left(&self) -> Option<f64> {
        if !self.is_running() {
            return None;
        }
        let done = self.last_index()?;
        if done == 0 {
            return None;
        }
        let elapsed: f64 = self.stats().map(|s| s.seconds).sum();
        Some(elapsed / f64::from(done) * f64::from(self.total.saturating_sub(done)))
    }

    /// Index of the newest keyframe that can be shown: the current run's
    /// or, past it, an earlier run's (stale).
    pub fn shown_end(&self) -> Option<u32> {
        let shown = self.keyframes.len().max(self.previous.len());
        shown.checked_sub(1).map(|last| last as u32)
    }

    /// Whether the view at `time_in_keyframes` shows an earlier run's
    /// keyframe: the current run has not computed the keyframe at or after
    /// it yet.
    pub fn is_stale_at(&self, time_in_keyframes: f64) -> bool {
        let needed = time_in_keyframes.max(0.0).ceil() as usize;
        needed >= self.keyframes.len() && needed < self.previous.len()
    }

    /// Whether the current run has computed the keyframes the view at
    /// `time_in_keyframes` blends (the view is up to date).
    pub fn is_current_at(&self, time_in_keyframes: f64) -> bool {
        (time_in_keyframes.max(0.0).ceil() as usize) < self.keyframes.len()
    }

    /// Keyframe `index` as shown: the current run's, else an earlier run's.
    fn shown(&self, index: usize) -> Option<&Arc<Keyframe>> {
        self.keyframes
            .get(index)
            .or_else(|| self.previous.get(index))
    }

    /// Positions of every simulated organ at `time_in_keyframes`,
    /// interpolated linearly between the two keyframes around it (each the
    /// current run's where it has arrived, else an earlier run's); times
    /// past the newest keyframe show the newest. `None` before the bud.
    pub fn positions_at(&self, time_in_keyframes: f64) -> Option<Vec<Vec<glam::DVec3>>> {
        let count = self.shown_end()? as usize + 1;
        let blend = KeyframeBlend::at(count, time_in_keyframes)?;
        let (below, above) = (self.shown(blend.below)?, self.shown(blend.above)?);
        Some(
            below
                .positions_in_world
                .iter()
                .zip(&above.positions_in_world)
                .map(|(a, b)| blend.positions(a, b))
                .collect(),
        )
    }
}

/// What [`SimSession::drain`] took.
#[derive(Debug, Default)]
pub struct Drained {
    pub changed: bool,
    /// The current run finished.
    pub finished: bool,
    pub failures: Vec<String>,
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
        assert!(session.is_stale_at(3.0) && !session.is_current_at(3.0));
        assert_eq!(x_at(&session, 3.0), 3.0);

        feed(&mut session, &project, second, &[0.0, 10.0, 20.0, 30.0]);
        assert!(!session.is_stale_at(3.0) && session.is_current_at(3.0));
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
}

//! The simulation worker: one named thread that runs jobs from immutable
//! project snapshots and streams their keyframes back.
//!
//! Every job has a run id. Starting a job cancels the one running (at its
//! next iteration boundary); events carry the run id so the receiver can drop
//! events of superseded runs. The worker wakes its owner through a plain
//! callback (a UI passes something like `ctx.request_repaint`), never through
//! UI types. Dropping the handle cancels the job and joins the thread.
//!
//! A panic inside a job (a bug) ends that job with a `Failed` event naming
//! the run; the thread lives on and serves the next run. Jobs read an
//! immutable snapshot, so the owner's document is untouched by it.
//!
//! A run may bring a *proxy*: the same flower with coarser meshes
//! ([`Worker::start_with_proxy`]). The job then first computes the proxy
//! from the first keyframe the edit changes to the end (`Proxy` events),
//! and then the converged keyframes (`Keyframe` events), which replace the
//! proxy's one by one where they arrive. When the owner views a keyframe
//! before the end ([`Worker::set_viewed_keyframe`]), the proxy and then
//! the converged run go to it first, and both go on to the end after. The worker keeps the last few
//! runs' simulations, one per selection and kind ([`Lane`]), so an edit of
//! either, or a switch back to a selection run before, goes on from the
//! first keyframe it changes.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, Sender, channel};
use std::sync::{Arc, Condvar, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::Instant;

use anthesis_flower::Project;

use crate::crossing::{Crossings, OnCrossing};
#[cfg(any(test, feature = "fault-hook"))]
use crate::fault::Fault;
use crate::{IterationProgress, Keyframe, Selection, SimError, Simulation, panic_message};

/// Identifies one job; later jobs have larger ids.
pub type RunId = u64;

/// What a run reports, in order: `Started`, then `Keyframe`s (the bud first)
/// with `Progress` between them, then exactly one of `Finished`, `Failed` or
/// `Cancelled`.
#[derive(Debug, Clone)]
pub enum Event {
    /// The run has set up its simulation and starts computing.
    Started {
        /// The run.
        run: RunId,
        /// Names of the simulated organs, in the order keyframes hold them.
        organs: Vec<String>,
        /// How many keyframes the run computes after the bud.
        keyframes: u32,
        /// The first keyframe this run computes; those before it are the
        /// last run's, which the edit could not change, and are sent again
        /// at once (1 when the run starts from the bud).
        first_computed: u32,
        /// Whether a proxy pass comes before the converged keyframes.
        proxy: bool,
    },
    /// One keyframe, reused or newly computed, in increasing order.
    Keyframe {
        /// The run.
        run: RunId,
        /// The keyframe (shared: the worker keeps it to resume a later run).
        keyframe: Arc<Keyframe>,
    },
    /// One keyframe of the run's proxy (see [`Worker::start_with_proxy`]),
    /// computed before the converged keyframes of the same index; its
    /// positions belong to the proxy project's meshes. Proxy keyframes
    /// come in increasing order from `Started::first_computed` on.
    Proxy {
        /// The run.
        run: RunId,
        /// The proxy keyframe.
        keyframe: Arc<Keyframe>,
    },
    /// Organs cross in a converged keyframe (see [`crate::crossing`]). The
    /// worker's converged runs warn and go on, so a window keeps the whole
    /// opening and says where it is wrong; the event follows the keyframe's
    /// own, and is sent again for reused keyframes after `Started`. Proxy
    /// runs do not look (their converged run does).
    Crossed {
        /// The run.
        run: RunId,
        /// What crosses, where.
        crossings: Arc<Crossings>,
    },
    /// The proxy pass is over: every proxy keyframe was sent, or the proxy
    /// stopped (`error`: a coarse mesh may fail where the converged one does
    /// not). The converged keyframes follow either way.
    ProxyEnded {
        /// The run.
        run: RunId,
        /// Wall time of the proxy pass, in seconds.
        seconds: f64,
        /// Why the proxy stopped early, if it did.
        error: Option<SimError>,
    },
    /// One Newton iteration of the keyframe being computed.
    Progress {
        /// The run.
        run: RunId,
        /// Where the iteration stands.
        progress: IterationProgress,
    },
    /// Every keyframe has been sent.
    Finished {
        /// The run.
        run: RunId,
        /// How many keyframes the run holds after the bud.
        keyframes: u32,
        /// Wall time of the run, in seconds, from its start to its end.
        seconds: f64,
    },
    /// The run stopped on an error; the keyframes sent before stay valid.
    Failed {
        /// The run.
        run: RunId,
        /// Why it stopped (names the keyframe and organ).
        error: SimError,
    },
    /// The run was stopped because a newer run or a cancel replaced it.
    Cancelled {
        /// The run.
        run: RunId,
    },
}

impl Event {
    /// The run this event belongs to.
    pub fn run(&self) -> RunId {
        match self {
            Event::Started { run, .. }
            | Event::Keyframe { run, .. }
            | Event::Proxy { run, .. }
            | Event::Crossed { run, .. }
            | Event::ProxyEnded { run, .. }
            | Event::Progress { run, .. }
            | Event::Finished { run, .. }
            | Event::Failed { run, .. }
            | Event::Cancelled { run } => *run,
        }
    }

    /// Whether this is the last event of run `run` (it finished, failed or
    /// was cancelled).
    pub fn ends(&self, run: RunId) -> bool {
        self.run() == run
            && matches!(
                self,
                Event::Finished { .. } | Event::Failed { .. } | Event::Cancelled { .. }
            )
    }
}

/// A run asked for and not yet started.
struct RunRequest {
    run: RunId,
    project: Arc<Project>,
    /// The same flower with coarser meshes, computed first.
    proxy: Option<Arc<Project>>,
    selection: Selection,
    #[cfg(any(test, feature = "fault-hook"))]
    fault: Option<Fault>,
}

/// What waits for the worker thread: at most one run, the newest (a newer
/// request replaces an older one that has not started: latest wins, and
/// the newest is never dropped), and whether to shut down.
#[derive(Default)]
struct Inbox {
    next_run: Option<RunRequest>,
    shutdown: bool,
}

/// The worker's command queue: a one-slot inbox and the condition variable
/// the thread waits on.
#[derive(Default)]
struct Mailbox {
    inbox: Mutex<Inbox>,
    posted: Condvar,
}

impl Mailbox {
    /// Changes the inbox and wakes the thread. A poisoned lock (a panic
    /// while holding it) still holds a consistent inbox: every change is
    /// one assignment.
    fn post(&self, change: impl FnOnce(&mut Inbox)) {
        let mut inbox = self.inbox.lock().unwrap_or_else(PoisonError::into_inner);
        change(&mut inbox);
        self.posted.notify_one();
    }

    /// Waits for the next run; `None` once shutdown is asked for.
    fn next(&self) -> Option<RunRequest> {
        let mut inbox = self.inbox.lock().unwrap_or_else(PoisonError::into_inner);
        loop {
            if inbox.shutdown {
                return None;
            }
            if let Some(request) = inbox.next_run.take() {
                return Some(request);
            }
            inbox = self
                .posted
                .wait(inbox)
                .unwrap_or_else(PoisonError::into_inner);
        }
    }
}

type Wake = Box<dyn Fn() + Send + Sync>;

/// Shortest time between two wakes for `Progress` events alone. A wake
/// is a redraw, about a tenth of a second of a core on a software
/// renderer: woken every 100 ms (and for other keyframes every 250 ms) the
/// window's drawing took as much CPU as the solver on two cores, and an
/// early-key stroke's rerun reached the screen 27 % later than at 500 ms
/// (measured from the screen's pixels, `app/tests/xvfb-edit-latency.sh`).
pub const PROGRESS_WAKE_EVERY: std::time::Duration = std::time::Duration::from_millis(500);

/// Shortest time between two wakes for keyframes other than the one the
/// owner views (see [`Worker::set_viewed_keyframe`]); paced as
/// [`PROGRESS_WAKE_EVERY`] for the same reason.
pub const OTHER_KEYFRAME_WAKE_EVERY: std::time::Duration = std::time::Duration::from_millis(500);

/// How long after a run with a proxy starts only the viewed keyframe and
/// the run's start and end wake the owner: the proxy's latency budget for
/// an early-key stroke (issue 34). Each other wake is a redraw, about a
/// tenth of a second of a core on a software renderer, taken from the
/// proxy; a proxy that takes longer gets the usual pacing after it.
pub const PROXY_QUIET_FOR: std::time::Duration = std::time::Duration::from_millis(600);

/// What an event is, as far as waking the owner goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Wakes {
    /// A Newton iteration.
    Progress,
    /// A keyframe (converged or proxy) of this index.
    Keyframe(u32),
    /// A run with a proxy pass started.
    ProxyRunStarted,
    /// A run started, its proxy ended, or it ended.
    Lifecycle,
}

impl Wakes {
    fn of(event: &Event) -> Wakes {
        match event {
            Event::Progress { .. } => Wakes::Progress,
            Event::Keyframe { keyframe, .. } | Event::Proxy { keyframe, .. } => {
                Wakes::Keyframe(keyframe.index)
            }
            Event::Crossed { crossings, .. } => Wakes::Keyframe(crossings.keyframe),
            Event::Started { proxy: true, .. } => Wakes::ProxyRunStarted,
            _ => Wakes::Lifecycle,
        }
    }
}

/// Whether an event wakes the owner. A run's start and end, and the
/// keyframe the owner views, wake it at once; other keyframes when
/// [`OTHER_KEYFRAME_WAKE_EVERY`] has passed since the last wake (at once
/// when the owner views none in particular); progress when
/// [`PROGRESS_WAKE_EVERY`] has. For [`PROXY_QUIET_FOR`] after a run with a
/// proxy starts, or until its proxy ends, neither other keyframes nor
/// progress wake it. A window redraws on each wake, and on a software
/// renderer that takes a core from the solver.
#[derive(Debug, Default)]
struct WakeGate {
    last_wake: Option<Instant>,
    /// When the quiet of a run with a proxy began, while it lasts.
    quiet_since: Option<Instant>,
}

impl WakeGate {
    fn wakes(&mut self, event: Wakes, viewed: Option<u32>, now: Instant) -> bool {
        let quiet = self
            .quiet_since
            .is_some_and(|at| now.saturating_duration_since(at) < PROXY_QUIET_FOR);
        let since = |every| {
            !quiet
                && self
                    .last_wake
                    .is_none_or(|at| now.saturating_duration_since(at) >= every)
        };
        let wakes = match event {
            Wakes::ProxyRunStarted => {
                self.quiet_since = Some(now);
                true
            }
            Wakes::Lifecycle => {
                self.quiet_since = None;
                true
            }
            Wakes::Keyframe(index) => match viewed {
                None => !quiet,
                Some(viewed) => index == viewed || since(OTHER_KEYFRAME_WAKE_EVERY),
            },
            Wakes::Progress => since(PROGRESS_WAKE_EVERY),
        };
        if wakes {
            self.last_wake = Some(now);
        }
        wakes
    }
}

/// "No keyframe viewed in particular" in [`Worker::set_viewed_keyframe`]'s
/// atomic.
const NOTHING_VIEWED: u64 = u64::MAX;

/// Handle to the worker thread.
pub struct Worker {
    mailbox: Arc<Mailbox>,
    /// The keyframe the owner views ([`NOTHING_VIEWED`]: none in particular).
    viewed: Arc<AtomicU64>,
    events: Receiver<Event>,
    /// The newest run requested; a job whose id differs is stale and stops.
    current: Arc<AtomicU64>,
    thread: Option<JoinHandle<()>>,
}

impl Worker {
    /// Spawns the thread `anthesis-sim`. `wake` is called after each event.
    pub fn spawn(wake: impl Fn() + Send + Sync + 'static) -> std::io::Result<Worker> {
        let mailbox = Arc::new(Mailbox::default());
        let inbox = Arc::clone(&mailbox);
        // Unbounded on purpose: every event of the current run matters (the
        // keyframes are the result) and the owner drains them each frame;
        // a bound would stall the simulation on a busy UI.
        #[allow(
            clippy::disallowed_methods,
            reason = "every event of the current run is kept; see above"
        )]
        let (event_tx, events) = channel();
        let current = Arc::new(AtomicU64::new(0));
        let shared = Arc::clone(&current);
        let wake: Wake = Box::new(wake);
        let viewed = Arc::new(AtomicU64::new(NOTHING_VIEWED));
        let owner_views = Arc::clone(&viewed);
        let thread = std::thread::Builder::new()
            .name("anthesis-sim".into())
            .spawn(move || serve(&inbox, event_tx, shared, wake, &owner_views))?;
        Ok(Worker {
            mailbox,
            viewed,
            events,
            current,
            thread: Some(thread),
        })
    }

    /// Tells the worker which keyframe the owner views (`None`: none in
    /// particular, e.g. while playing or following the newest): that
    /// keyframe wakes the owner at once, others at most every
    /// [`OTHER_KEYFRAME_WAKE_EVERY`]. Cheap; call it every frame.
    pub fn set_viewed_keyframe(&self, keyframe: Option<u32>) {
        let value = keyframe.map_or(NOTHING_VIEWED, u64::from);
        self.viewed.store(value, Ordering::Relaxed);
    }

    /// Starts simulating `project`, cancelling whatever runs now. Returns the
    /// new run's id. Never blocks on the simulation.
    pub fn start(&self, project: Arc<Project>, selection: Selection) -> RunId {
        self.start_with_proxy(project, None, selection)
    }

    /// [`Worker::start`] with a proxy: `proxy` is the same project with
    /// coarser meshes (the same organs, maps and settings), simulated
    /// first from the first keyframe the edit changes, so that something
    /// is on screen fast; `project`'s own keyframes follow. `None` runs
    /// `project` alone.
    pub fn start_with_proxy(
        &self,
        project: Arc<Project>,
        proxy: Option<Arc<Project>>,
        selection: Selection,
    ) -> RunId {
        self.post_run(|run| RunRequest {
            run,
            project,
            proxy,
            selection,
            #[cfg(any(test, feature = "fault-hook"))]
            fault: None,
        })
    }

    /// [`Worker::start`] with a forced fault (tests only).
    #[cfg(any(test, feature = "fault-hook"))]
    pub fn start_with_fault(
        &self,
        project: Arc<Project>,
        selection: Selection,
        fault: Fault,
    ) -> RunId {
        self.post_run(|run| RunRequest {
            run,
            project,
            proxy: None,
            selection,
            fault: Some(fault),
        })
    }

    fn post_run(&self, request: impl FnOnce(RunId) -> RunRequest) -> RunId {
        let run = self.current.fetch_add(1, Ordering::SeqCst) + 1;
        let request = request(run);
        self.mailbox.post(|inbox| inbox.next_run = Some(request));
        run
    }

    /// Cancels the running job, if any.
    pub fn cancel(&self) {
        self.current.fetch_add(1, Ordering::SeqCst);
    }

    /// The next event, if one is waiting.
    pub fn try_event(&self) -> Option<Event> {
        self.events.try_recv().ok()
    }

    /// Waits up to `timeout` for the next event.
    pub fn wait_event(&self, timeout: std::time::Duration) -> Option<Event> {
        self.events.recv_timeout(timeout).ok()
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        self.cancel();
        self.mailbox.post(|inbox| inbox.shutdown = true);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

fn serve(
    mailbox: &Mailbox,
    events: Sender<Event>,
    current: Arc<AtomicU64>,
    wake: Wake,
    viewed: &AtomicU64,
) {
    let mut gate = WakeGate::default();
    let send = Mutex::new(move |event: Event| {
        let wakes = Wakes::of(&event);
        let _ = events.send(event);
        if gate.wakes(wakes, viewed_now(viewed), Instant::now()) {
            wake();
        }
    });
    // A panic while sending (in `wake`) poisons the lock; the sender is
    // still whole, so later events still go out.
    let emit = |event: Event| {
        let mut send = send.lock().unwrap_or_else(PoisonError::into_inner);
        send(event);
    };
    // The last runs' simulations, so that an edit goes on from the first
    // keyframe it changes. A job takes out the ones it uses: a job that
    // panics outside the simulation's own guard leaves them behind.
    let mut kept = Kept::default();
    while let Some(request) = mailbox.next() {
        let run = request.run;
        if current.load(Ordering::SeqCst) != run {
            // Cancelled before it started.
            continue;
        }
        // Unwind safety: the job owns the simulations it took and reads
        // immutable projects; nothing it leaves half done outlives it.
        let job = catch_unwind(AssertUnwindSafe(|| {
            run_job(&request, viewed_now(viewed), &mut kept, &current, &emit)
        }));
        if let Err(payload) = job {
            emit(Event::Failed {
                run,
                error: SimError::Panicked {
                    run: Some(run),
                    keyframe: None,
                    message: panic_message(payload.as_ref()),
                },
            });
        }
    }
}

/// The keyframe the owner views now, if one in particular.
fn viewed_now(viewed: &AtomicU64) -> Option<u32> {
    let viewed = viewed.load(Ordering::Relaxed);
    (viewed != NOTHING_VIEWED).then_some(viewed as u32)
}

/// Which kept simulation a run goes on from: the organs it simulates, and
/// whether it is a proxy (coarse meshes) or the converged run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Lane {
    /// The organs simulated.
    pub selection: Selection,
    /// Whether the lane simulates a proxy.
    pub proxy: bool,
}

/// What the worker keeps of a finished or cancelled run: the project and
/// lane it ran, its simulation (with checkpoints) and the keyframes it
/// computed.
struct LastRun {
    project: Arc<Project>,
    lane: Lane,
    sim: Simulation,
    keyframes: Vec<Arc<Keyframe>>,
}

/// The most simulations kept: the converged run and the proxy of the
/// selection being edited, and the converged run of one other (the whole
/// flower while a single organ is previewed), so that leaving the preview
/// computes nothing that did not change.
const KEPT_RUNS: usize = 3;

/// The kept simulations, the most recently used first.
#[derive(Default)]
struct Kept {
    runs: Vec<LastRun>,
}

impl Kept {
    /// Takes out the simulation of `lane`, if one is kept.
    fn take(&mut self, lane: &Lane) -> Option<LastRun> {
        let at = self.runs.iter().position(|r| r.lane == *lane)?;
        Some(self.runs.remove(at))
    }

    /// Keeps `last` as the most recently used, forgetting the least
    /// recently used beyond [`KEPT_RUNS`].
    fn put(&mut self, last: LastRun) {
        self.runs.retain(|r| r.lane != last.lane);
        self.runs.insert(0, last);
        self.runs.truncate(KEPT_RUNS);
    }
}

/// The simulation of `project` in `lane`: the kept one, edited, when there
/// is one (keeping the keyframes the edit cannot change), else a new one.
/// Returns it with the keyframes kept.
fn simulation_for(
    project: &Arc<Project>,
    lane: &Lane,
    last: Option<LastRun>,
) -> Result<(Simulation, Vec<Arc<Keyframe>>), SimError> {
    if let Some(mut last) = last {
        let first = last.sim.edit(&last.project, project)?;
        // Starting over may start from another bud (a new mesh).
        last.keyframes
            .truncate(if first == 1 { 0 } else { first as usize });
        return Ok((last.sim, last.keyframes));
    }
    let mut sim = Simulation::new(project, &lane.selection)?;
    sim.keep_checkpoints();
    sim.on_crossing(if lane.proxy {
        // The converged run that follows checks for crossings.
        OnCrossing::Skip
    } else {
        OnCrossing::Warn
    });
    Ok((sim, Vec::new()))
}

/// How a run of steps ended.
enum Steps {
    /// Every keyframe is computed.
    Finished,
    /// A newer run or a cancel replaced this one.
    Cancelled,
    /// A step failed.
    Failed(SimError),
}

/// Steps `sim` to its last keyframe, handing each new keyframe to `keyframe`.
fn step_to_end(
    sim: &mut Simulation,
    keyframes: &mut Vec<Arc<Keyframe>>,
    run: RunId,
    stale: &(dyn Fn() -> bool + Sync),
    emit: &dyn Fn(Event),
    keyframe: &dyn Fn(Arc<Keyframe>) -> Event,
) -> Steps {
    step_until(sim, keyframes, u32::MAX, run, stale, emit, keyframe)
}

/// [`step_to_end`], stopping once keyframe `last` is computed.
fn step_until(
    sim: &mut Simulation,
    keyframes: &mut Vec<Arc<Keyframe>>,
    last: u32,
    run: RunId,
    stale: &(dyn Fn() -> bool + Sync),
    emit: &dyn Fn(Event),
    keyframe: &dyn Fn(Arc<Keyframe>) -> Event,
) -> Steps {
    while !sim.finished() && keyframes.last().is_none_or(|k| k.index < last) {
        let result = sim.step(stale, &mut |progress| {
            emit(Event::Progress { run, progress })
        });
        match result {
            Ok(made) => {
                let made = Arc::new(made);
                let index = made.index;
                keyframes.push(Arc::clone(&made));
                emit(keyframe(made));
                if let Some(crossings) = sim.crossings().last().filter(|c| c.keyframe == index) {
                    emit(Event::Crossed {
                        run,
                        crossings: Arc::new(crossings.clone()),
                    });
                }
            }
            Err(SimError::Cancelled) => return Steps::Cancelled,
            Err(SimError::Panicked {
                keyframe, message, ..
            }) => {
                return Steps::Failed(SimError::Panicked {
                    run: Some(run),
                    keyframe,
                    message,
                });
            }
            Err(error) => return Steps::Failed(error),
        }
    }
    Steps::Finished
}

/// The proxy pass of a run: `proxy` simulated in its lane, every keyframe
/// from the run's first computed one on sent as a `Proxy` event, then
/// `ProxyEnded`.
struct ProxyPass {
    run: RunId,
    project: Arc<Project>,
    lane: Lane,
    sim: Simulation,
    keyframes: Vec<Arc<Keyframe>>,
    started: Instant,
    /// Whether `ProxyEnded` was sent (the proxy finished or failed).
    ended: bool,
}

impl ProxyPass {
    /// The proxy of run `run` set up in `lane` (the kept simulation,
    /// edited, if there is one), the kept proxy keyframes from `first` on
    /// sent at once; `None` (and `ProxyEnded` with the error) when it
    /// cannot be set up.
    fn start(
        run: RunId,
        proxy: &Arc<Project>,
        lane: Lane,
        first: u32,
        kept: &mut Kept,
        emit: &dyn Fn(Event),
    ) -> Option<ProxyPass> {
        let started = Instant::now();
        let (sim, mut keyframes) = match simulation_for(proxy, &lane, kept.take(&lane)) {
            Ok(made) => made,
            Err(error) => {
                emit(Event::ProxyEnded {
                    run,
                    seconds: started.elapsed().as_secs_f64(),
                    error: Some(error),
                });
                return None;
            }
        };
        if keyframes.is_empty() {
            keyframes.push(Arc::new(sim.bud()));
        }
        // Kept proxy keyframes the converged run has not kept: at once.
        for keyframe in keyframes.iter().skip(first as usize) {
            emit(Event::Proxy {
                run,
                keyframe: Arc::clone(keyframe),
            });
        }
        Some(ProxyPass {
            run,
            project: Arc::clone(proxy),
            lane,
            sim,
            keyframes,
            started,
            ended: false,
        })
    }

    /// Computes the proxy's keyframes up to `last` (to its end for
    /// `u32::MAX`), sending `ProxyEnded` when it ends or fails. Returns
    /// false when the run was cancelled meanwhile.
    fn step_until(
        &mut self,
        last: u32,
        stale: &(dyn Fn() -> bool + Sync),
        emit: &dyn Fn(Event),
    ) -> bool {
        let run = self.run;
        let steps = step_until(
            &mut self.sim,
            &mut self.keyframes,
            last,
            run,
            stale,
            emit,
            &|keyframe| Event::Proxy { run, keyframe },
        );
        let ended = |error| Event::ProxyEnded {
            run,
            seconds: self.started.elapsed().as_secs_f64(),
            error,
        };
        match steps {
            Steps::Finished if self.sim.finished() => emit(ended(None)),
            Steps::Finished => return true,
            Steps::Cancelled => return false,
            // The converged run goes on without the rest of the proxy.
            Steps::Failed(error) => emit(ended(Some(error))),
        }
        self.ended = true;
        true
    }

    /// Keeps the proxy's simulation for the next run.
    fn keep(self, kept: &mut Kept) {
        kept.put(LastRun {
            project: self.project,
            lane: self.lane,
            sim: self.sim,
            keyframes: self.keyframes,
        });
    }
}

/// Runs one job: the proxy first when the request has one, then the
/// converged run. With a keyframe `viewed` past the first one the edit
/// changes, the proxy and then the converged run stop there first, and go
/// on to the end after: the converged keyframe the owner looks at comes
/// before the proxy's later ones (on the lily's late-key stroke, 0.44 s
/// after the start instead of 0.59 s). The simulations used go back into
/// `kept`.
fn run_job(
    request: &RunRequest,
    viewed: Option<u32>,
    kept: &mut Kept,
    current: &AtomicU64,
    emit: &dyn Fn(Event),
) {
    let run = request.run;
    let started = Instant::now();
    let stale = || current.load(Ordering::SeqCst) != run;
    #[cfg(any(test, feature = "fault-hook"))]
    if request.fault == Some(Fault::PanicBeforeStart) {
        panic!("forced fault before run {run} started (test hook)");
    }
    let lane = Lane {
        selection: request.selection.clone(),
        proxy: false,
    };
    let last = kept.take(&lane);
    #[cfg(any(test, feature = "fault-hook"))]
    let last = last.filter(|_| request.fault.is_none());
    let (mut sim, mut keyframes) = match simulation_for(&request.project, &lane, last) {
        Ok(made) => made,
        Err(error) => {
            emit(Event::Failed { run, error });
            return;
        }
    };
    #[cfg(any(test, feature = "fault-hook"))]
    if request.fault.is_some() {
        sim.inject(request.fault);
    }
    let first_computed = keyframes.len().max(1) as u32;
    let proxy = request.proxy.as_ref().filter(|_| !sim.finished());
    emit(Event::Started {
        run,
        organs: sim.organs().iter().map(|s| s.to_string()).collect(),
        keyframes: sim.keyframe_count(),
        first_computed,
        proxy: proxy.is_some(),
    });
    if keyframes.is_empty() {
        keyframes.push(Arc::new(sim.bud()));
    }
    // The keyframes the edit left as they were, at once, and what crosses
    // in them.
    for keyframe in &keyframes {
        emit(Event::Keyframe {
            run,
            keyframe: Arc::clone(keyframe),
        });
    }
    for crossings in sim.crossings() {
        emit(Event::Crossed {
            run,
            crossings: Arc::new(crossings.clone()),
        });
    }
    let mut pass = proxy.and_then(|proxy| {
        let lane = Lane {
            selection: request.selection.clone(),
            proxy: true,
        };
        ProxyPass::start(run, proxy, lane, first_computed, kept, emit)
    });
    let steps = converged_after_proxy(
        &mut sim,
        &mut keyframes,
        pass.as_mut(),
        viewed.filter(|&v| v >= first_computed),
        run,
        &stale,
        emit,
    );
    match steps {
        Steps::Finished => emit(Event::Finished {
            run,
            keyframes: sim.keyframe_count(),
            seconds: started.elapsed().as_secs_f64(),
        }),
        Steps::Cancelled => emit(Event::Cancelled { run }),
        Steps::Failed(error) => emit(Event::Failed { run, error }),
    }
    if let Some(pass) = pass {
        pass.keep(kept);
    }
    kept.put(LastRun {
        project: Arc::clone(&request.project),
        lane,
        sim,
        keyframes,
    });
}

/// The converged keyframes of a run after its proxy `pass` (if any): with
/// a keyframe `viewed` before the end, the proxy and then the converged
/// run to it first, then the rest of the proxy and of the converged run.
/// `Cancelled` when the run was cancelled during the proxy too.
fn converged_after_proxy(
    sim: &mut Simulation,
    keyframes: &mut Vec<Arc<Keyframe>>,
    mut pass: Option<&mut ProxyPass>,
    viewed: Option<u32>,
    run: RunId,
    stale: &(dyn Fn() -> bool + Sync),
    emit: &dyn Fn(Event),
) -> Steps {
    let converged = |keyframe| Event::Keyframe { run, keyframe };
    let ahead = viewed.filter(|&v| v < sim.keyframe_count());
    if let (Some(last), Some(p)) = (ahead, pass.as_deref_mut()) {
        if !p.step_until(last, stale, emit) {
            return Steps::Cancelled;
        }
        let steps = step_until(sim, keyframes, last, run, stale, emit, &converged);
        if !matches!(steps, Steps::Finished) {
            return steps;
        }
    }
    if let Some(p) = pass
        && !p.ended
        && !p.step_until(u32::MAX, stale, emit)
    {
        return Steps::Cancelled;
    }
    step_to_end(sim, keyframes, run, stale, emit, &converged)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::whorl;
    use std::sync::atomic::AtomicUsize;
    use std::time::Duration;

    fn collect_until_end(worker: &Worker, run: RunId) -> Vec<Event> {
        let mut seen = Vec::new();
        loop {
            let event = worker
                .wait_event(Duration::from_secs(60))
                .expect("the worker answers");
            let end = event.ends(run);
            seen.push(event);
            if end {
                return seen;
            }
        }
    }

    #[test]
    fn a_run_streams_every_keyframe_in_order_and_wakes_the_owner() {
        let wakes = Arc::new(AtomicUsize::new(0));
        let counter = Arc::clone(&wakes);
        let worker = Worker::spawn(move || {
            counter.fetch_add(1, Ordering::SeqCst);
        })
        .expect("thread");
        let project = Arc::new(whorl(1, 6, 10, 5));
        let run = worker.start(project, Selection::All);
        let events = collect_until_end(&worker, run);
        let indices: Vec<u32> = events
            .iter()
            .filter_map(|e| match e {
                Event::Keyframe { keyframe, .. } => Some(keyframe.index),
                _ => None,
            })
            .collect();
        assert_eq!(indices, vec![0, 1, 2, 3, 4, 5]);
        assert!(matches!(
            events.first(),
            Some(Event::Started { keyframes: 5, .. })
        ));
        assert!(matches!(
            events.last(),
            Some(Event::Finished { keyframes: 5, .. })
        ));
        // Every event but progress wakes the owner; progress alone at most
        // every PROGRESS_WAKE_EVERY. The wake follows each send, so the
        // last one may still be on its way when the last event arrives.
        let progress = events
            .iter()
            .filter(|e| matches!(e, Event::Progress { .. }))
            .count();
        assert!(progress > 0, "the run reports its iterations");
        let others = events.len() - progress;
        let deadline = Instant::now() + Duration::from_secs(10);
        while wakes.load(Ordering::SeqCst) < others + 1 && Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(1));
        }
        let woken = wakes.load(Ordering::SeqCst);
        assert!(
            woken >= others && woken <= events.len(),
            "{woken} wakes for {others} events and {progress} iterations"
        );
    }

    #[test]
    fn the_viewed_keyframe_wakes_the_owner_at_once_and_the_rest_are_paced() {
        let mut gate = WakeGate::default();
        let t0 = Instant::now();
        let at = |ms| t0 + Duration::from_millis(ms);
        let progress = PROGRESS_WAKE_EVERY.as_millis() as u64;
        let other = OTHER_KEYFRAME_WAKE_EVERY.as_millis() as u64;
        // Progress: at most every PROGRESS_WAKE_EVERY.
        assert!(gate.wakes(Wakes::Progress, None, at(0)), "the first wakes");
        assert!(!gate.wakes(Wakes::Progress, None, at(30)));
        assert!(!gate.wakes(Wakes::Progress, None, at(progress - 1)));
        assert!(
            gate.wakes(Wakes::Lifecycle, None, at(progress - 1)),
            "a start or end always wakes"
        );
        assert!(
            !gate.wakes(Wakes::Progress, None, at(progress + 50)),
            "counted from the last wake"
        );
        let t = 2 * progress - 1;
        assert!(gate.wakes(Wakes::Progress, None, at(t)));
        // Keyframes: every one when nothing in particular is viewed.
        assert!(gate.wakes(Wakes::Keyframe(3), None, at(t + 1)));
        assert!(gate.wakes(Wakes::Keyframe(4), None, at(t + 2)));
        // The viewed one at once; others OTHER_KEYFRAME_WAKE_EVERY apart.
        assert!(!gate.wakes(Wakes::Keyframe(5), Some(54), at(t + 100)));
        assert!(gate.wakes(Wakes::Keyframe(54), Some(54), at(t + 101)));
        assert!(!gate.wakes(Wakes::Keyframe(55), Some(54), at(t + 100 + other)));
        assert!(gate.wakes(Wakes::Keyframe(56), Some(54), at(t + 101 + other)));
    }

    #[test]
    fn a_run_with_a_proxy_is_quiet_but_for_the_viewed_keyframe_until_its_proxy_ends() {
        let mut gate = WakeGate::default();
        let t0 = Instant::now();
        let at = |ms| t0 + Duration::from_millis(ms);
        let quiet = PROXY_QUIET_FOR.as_millis() as u64;
        assert!(gate.wakes(Wakes::ProxyRunStarted, Some(100), at(0)));
        assert!(!gate.wakes(Wakes::Progress, Some(100), at(150)));
        assert!(!gate.wakes(Wakes::Keyframe(40), Some(100), at(300)));
        assert!(!gate.wakes(Wakes::Keyframe(41), None, at(301)));
        assert!(gate.wakes(Wakes::Keyframe(100), Some(100), at(400)));
        assert!(!gate.wakes(Wakes::Progress, Some(100), at(quiet - 1)));
        // A slow proxy gets the usual pacing once the quiet is over.
        let paced = quiet.max(400 + PROGRESS_WAKE_EVERY.as_millis() as u64);
        assert!(gate.wakes(Wakes::Progress, Some(100), at(paced + 1)));
        // The proxy's end ends the quiet at once.
        assert!(gate.wakes(Wakes::ProxyRunStarted, Some(100), at(2000)));
        assert!(!gate.wakes(Wakes::Keyframe(3), Some(100), at(2300)));
        assert!(gate.wakes(Wakes::Lifecycle, Some(100), at(2310)));
        let other = OTHER_KEYFRAME_WAKE_EVERY.as_millis() as u64;
        assert!(gate.wakes(Wakes::Keyframe(4), Some(100), at(2310 + other)));
    }

    #[test]
    fn the_worker_paces_wakes_by_the_keyframe_viewed() {
        let wakes = Arc::new(AtomicUsize::new(0));
        let counter = Arc::clone(&wakes);
        let worker = Worker::spawn(move || {
            counter.fetch_add(1, Ordering::SeqCst);
        })
        .expect("thread");
        worker.set_viewed_keyframe(Some(40));
        let run = worker.start(Arc::new(whorl(1, 4, 6, 40)), Selection::All);
        let events = collect_until_end(&worker, run);
        let keyframes = keyframes_of(&events).len();
        // The start, the end, keyframe 40, and the others at most every
        // OTHER_KEYFRAME_WAKE_EVERY (the small run takes well under a
        // second).
        let deadline = Instant::now() + Duration::from_secs(10);
        while wakes.load(Ordering::SeqCst) < 3 && Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(1));
        }
        let woken = wakes.load(Ordering::SeqCst);
        assert!(woken >= 3, "{woken}");
        assert!(woken < keyframes, "{woken} wakes for {keyframes} keyframes");
    }

    /// The keyframes of `events`, in the order they came.
    fn keyframes_of(events: &[Event]) -> Vec<Arc<Keyframe>> {
        events
            .iter()
            .filter_map(|e| match e {
                Event::Keyframe { keyframe, .. } => Some(Arc::clone(keyframe)),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn an_edit_resends_the_keyframes_it_cannot_change_and_computes_the_rest() {
        let worker = Worker::spawn(|| {}).expect("thread");
        let before = whorl(2, 6, 10, 44);
        let first = worker.start(Arc::new(before.clone()), Selection::All);
        let old = keyframes_of(&collect_until_end(&worker, first));
        let mut after = before.clone();
        crate::fixtures::stroke_near_tip(&mut after, 0, 1);
        let second = worker.start(Arc::new(after.clone()), Selection::All);
        let events = collect_until_end(&worker, second);
        let new = keyframes_of(&events);
        let indices: Vec<u32> = new.iter().map(|k| k.index).collect();
        assert_eq!(indices, (0..=44).collect::<Vec<_>>());
        // Keyframes before 40 (where the stroked step-50 key is first
        // read) are the same ones, sent before any work.
        assert!((0..40).all(|i| Arc::ptr_eq(&new[i], &old[i])));
        assert!((40..=44).all(|i| !Arc::ptr_eq(&new[i], &old[i])));
        let first_progress = events.iter().find_map(|e| match e {
            Event::Progress { progress, .. } => Some(progress.keyframe),
            _ => None,
        });
        assert_eq!(first_progress, Some(40));
        assert!(matches!(
            events.first(),
            Some(Event::Started {
                first_computed: 40,
                ..
            })
        ));
        // And they are what a run of the edited project gives.
        let mut fresh = Vec::new();
        crate::run(&after, &Selection::All, &mut |_, k| fresh.push(k.clone()))
            .expect("the edited project runs");
        for (k, f) in new.iter().zip(&fresh) {
            assert_eq!(
                k.positions_in_world, f.positions_in_world,
                "keyframe {}",
                k.index
            );
        }
        // Another selection starts over.
        let one = worker.start(Arc::new(after), Selection::Only(0));
        let alone = keyframes_of(&collect_until_end(&worker, one));
        assert_eq!(alone.len(), 45);
        assert!(!Arc::ptr_eq(&alone[0], &new[0]));
    }

    #[test]
    fn a_new_run_cancels_the_running_one() {
        let worker = Worker::spawn(|| {}).expect("thread");
        let long = worker.start(Arc::new(whorl(1, 14, 28, 100_000)), Selection::All);
        // Wait until the long run is really computing.
        loop {
            if let Some(Event::Keyframe { keyframe, .. }) =
                worker.wait_event(Duration::from_secs(60))
                && keyframe.index >= 1
            {
                break;
            }
        }
        let short = worker.start(Arc::new(whorl(1, 6, 10, 3)), Selection::All);
        let events = collect_until_end(&worker, short);
        assert!(
            events
                .iter()
                .any(|e| matches!(e, Event::Cancelled { run } if *run == long)),
            "the long run must report its cancellation"
        );
        assert!(matches!(events.last(), Some(Event::Finished { run, .. }) if *run == short));
    }

    #[test]
    fn a_burst_of_starts_while_busy_runs_the_newest() {
        let worker = Worker::spawn(|| {}).expect("thread");
        worker.start(Arc::new(whorl(1, 14, 28, 100_000)), Selection::All);
        // Wait until the long run is really computing, then ask for many
        // more runs than any queue would hold before it notices.
        loop {
            if let Some(Event::Keyframe { keyframe, .. }) =
                worker.wait_event(Duration::from_secs(60))
                && keyframe.index >= 1
            {
                break;
            }
        }
        let project = Arc::new(whorl(1, 6, 10, 2));
        let mut newest = 0;
        for _ in 0..100 {
            newest = worker.start(Arc::clone(&project), Selection::All);
        }
        let events = collect_until_end(&worker, newest);
        assert!(
            matches!(events.last(), Some(Event::Finished { run, .. }) if *run == newest),
            "the newest run must finish: {:?}",
            events.last()
        );
        // The runs in between were replaced before they started.
        let started: Vec<RunId> = events
            .iter()
            .filter_map(|e| match e {
                Event::Started { run, .. } => Some(*run),
                _ => None,
            })
            .collect();
        assert_eq!(started, [newest]);
    }

    #[test]
    fn a_bad_project_fails_with_a_typed_error_and_the_worker_goes_on() {
        let worker = Worker::spawn(|| {}).expect("thread");
        let mut bad = whorl(1, 6, 10, 3);
        bad.flower.templates[0].thickness = 0.0;
        let run = worker.start(Arc::new(bad), Selection::All);
        let events = collect_until_end(&worker, run);
        assert!(matches!(
            events.last(),
            Some(Event::Failed {
                error: SimError::BadTemplate { .. },
                ..
            })
        ));
        let good = worker.start(Arc::new(whorl(1, 6, 10, 2)), Selection::All);
        let events = collect_until_end(&worker, good);
        assert!(matches!(events.last(), Some(Event::Finished { .. })));
    }

    /// The keyframe indices a run delivered.
    fn keyframe_indices(events: &[Event]) -> Vec<u32> {
        events
            .iter()
            .filter_map(|e| match e {
                Event::Keyframe { keyframe, .. } => Some(keyframe.index),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn a_panic_in_a_step_fails_that_run_by_name_and_the_worker_serves_the_next() {
        let worker = Worker::spawn(|| {}).expect("thread");
        let project = Arc::new(whorl(2, 6, 10, 5));
        let run = worker.start_with_fault(
            Arc::clone(&project),
            Selection::All,
            Fault::PanicAtKeyframe(3),
        );
        let events = collect_until_end(&worker, run);
        // The keyframes before the panic arrived; the panic is the run's end.
        assert_eq!(keyframe_indices(&events), [0, 1, 2]);
        let Some(Event::Failed { run: failed, error }) = events.last() else {
            panic!("the run must fail: {:?}", events.last());
        };
        assert_eq!(*failed, run);
        assert_eq!(
            *error,
            SimError::Panicked {
                run: Some(run),
                keyframe: Some(3),
                message: "forced fault at keyframe 3 (test hook)".to_string(),
            }
        );
        let message = error.to_string();
        assert!(
            message.starts_with(&format!("run {run}, keyframe 3: internal error")),
            "{message}"
        );

        // The same thread runs the same project to the end afterwards: the
        // project snapshot was not touched by the failed run.
        let next = worker.start(Arc::clone(&project), Selection::All);
        let events = collect_until_end(&worker, next);
        assert_eq!(keyframe_indices(&events), [0, 1, 2, 3, 4, 5]);
        assert!(matches!(
            events.last(),
            Some(Event::Finished { keyframes: 5, .. })
        ));
        assert_eq!(*project, whorl(2, 6, 10, 5));
    }

    #[test]
    fn a_panic_outside_the_steps_is_caught_too() {
        let worker = Worker::spawn(|| {}).expect("thread");
        let project = Arc::new(whorl(1, 6, 10, 2));
        let run = worker.start_with_fault(
            Arc::clone(&project),
            Selection::All,
            Fault::PanicBeforeStart,
        );
        let events = collect_until_end(&worker, run);
        assert_eq!(events.len(), 1, "{events:?}");
        let Some(Event::Failed { error, .. }) = events.last() else {
            panic!("the run must fail: {events:?}");
        };
        assert!(
            error.to_string().starts_with(&format!(
                "run {run}, before its first keyframe: internal error"
            )),
            "{error}"
        );
        let next = worker.start(project, Selection::All);
        let events = collect_until_end(&worker, next);
        assert!(matches!(
            events.last(),
            Some(Event::Finished { keyframes: 2, .. })
        ));
    }

    #[test]
    fn a_panicking_wake_callback_does_not_silence_the_worker() {
        let calls = Arc::new(AtomicUsize::new(0));
        let counter = Arc::clone(&calls);
        let worker = Worker::spawn(move || {
            if counter.fetch_add(1, Ordering::SeqCst) == 0 {
                panic!("the owner's wake callback failed");
            }
        })
        .expect("thread");
        let project = Arc::new(whorl(1, 6, 10, 2));
        let first = worker.start(Arc::clone(&project), Selection::All);
        let events = collect_until_end(&worker, first);
        assert!(
            matches!(
                events.last(),
                Some(Event::Failed {
                    error: SimError::Panicked { .. },
                    ..
                })
            ),
            "{events:?}"
        );
        let next = worker.start(project, Selection::All);
        let events = collect_until_end(&worker, next);
        assert!(
            matches!(events.last(), Some(Event::Finished { .. })),
            "{events:?}"
        );
    }

    #[test]
    fn dropping_the_handle_stops_a_long_run() {
        let worker = Worker::spawn(|| {}).expect("thread");
        worker.start(Arc::new(whorl(1, 14, 28, 100_000)), Selection::All);
        std::thread::sleep(Duration::from_millis(50));
        let started = Instant::now();
        drop(worker);
        assert!(
            started.elapsed() < Duration::from_secs(10),
            "drop must not wait for 100 000 keyframes"
        );
    }

    /// The proxy keyframes of `events`, in the order they came.
    fn proxies_of(events: &[Event]) -> Vec<Arc<Keyframe>> {
        events
            .iter()
            .filter_map(|e| match e {
                Event::Proxy { keyframe, .. } => Some(Arc::clone(keyframe)),
                _ => None,
            })
            .collect()
    }

    /// Each organ's particle count in `keyframe`.
    fn counts(keyframe: &Keyframe) -> Vec<usize> {
        keyframe.positions_in_world.iter().map(Vec::len).collect()
    }

    #[test]
    fn a_proxy_comes_first_and_the_converged_keyframes_are_those_of_a_run_without_it() {
        let fine = Arc::new(whorl(2, 6, 10, 6));
        let coarse = Arc::new(whorl(2, 4, 6, 6));
        let plain = Worker::spawn(|| {}).expect("thread");
        let run = plain.start(Arc::clone(&fine), Selection::All);
        let expected = keyframes_of(&collect_until_end(&plain, run));

        let worker = Worker::spawn(|| {}).expect("thread");
        let run =
            worker.start_with_proxy(Arc::clone(&fine), Some(Arc::clone(&coarse)), Selection::All);
        let events = collect_until_end(&worker, run);
        assert!(matches!(
            events.first(),
            Some(Event::Started {
                proxy: true,
                first_computed: 1,
                ..
            })
        ));
        // The bud (converged), the proxy's keyframes 1-6, the end of the
        // proxy, then the converged keyframes 1-6.
        assert_eq!(
            order_from(&events, 0),
            "k0 p1 p2 p3 p4 p5 p6 end k1 k2 k3 k4 k5 k6"
        );
        let coarse_counts: Vec<usize> = (0..2)
            .map(|o| coarse.flower.template_of(o).mesh.vertex_count())
            .collect();
        for proxy in proxies_of(&events) {
            assert_eq!(counts(&proxy), coarse_counts, "proxy on the coarse meshes");
        }
        let got = keyframes_of(&events);
        assert_eq!(got.len(), expected.len());
        for (a, b) in got.iter().zip(&expected) {
            assert_eq!(a.bits(), b.bits(), "keyframe {}", a.index);
        }
    }

    /// A small whorl of 44 keyframes, and the same with a stroke on its
    /// step-40 key (which changes keyframes from 40 on).
    fn late_key_edit() -> (Project, Project) {
        let before = whorl(2, 6, 10, 44);
        let mut after = before.clone();
        crate::fixtures::stroke_near_tip(&mut after, 0, 1);
        (before, after)
    }

    /// The proxy of a [`late_key_edit`] project: coarser meshes, its maps.
    fn coarse_of(fine: &Project) -> Arc<Project> {
        let mut coarse = whorl(2, 4, 6, 44);
        coarse.flower.templates[0].maps = fine.flower.templates[0].maps.clone();
        Arc::new(coarse)
    }

    #[test]
    fn an_edit_with_a_proxy_keeps_the_unchanged_keyframes_and_redoes_the_proxy_from_the_first_change()
     {
        let (before, after) = late_key_edit();
        let worker = Worker::spawn(|| {}).expect("thread");
        let mut last = Vec::new();
        for project in [before, after] {
            let proxy = coarse_of(&project);
            let run = worker.start_with_proxy(Arc::new(project), Some(proxy), Selection::All);
            last = collect_until_end(&worker, run);
        }
        let Some(Event::Started { first_computed, .. }) = last.first() else {
            panic!("the run starts");
        };
        assert_eq!(*first_computed, 40, "the stroke is on the step-40 key");
        let proxies: Vec<u32> = proxies_of(&last).iter().map(|k| k.index).collect();
        assert_eq!(proxies, (40..=44).collect::<Vec<_>>());
        let converged: Vec<u32> = keyframes_of(&last).iter().map(|k| k.index).collect();
        assert_eq!(converged, (0..=44).collect::<Vec<_>>());
        // The kept keyframes come before the proxy, the new ones after it.
        let first_proxy = last
            .iter()
            .position(|e| matches!(e, Event::Proxy { .. }))
            .expect("a proxy");
        let kept = last[..first_proxy]
            .iter()
            .filter(|e| matches!(e, Event::Keyframe { .. }))
            .count();
        assert_eq!(kept, 40);
    }

    /// The order of `events`' keyframes (`kN` converged, `pN` proxy) and
    /// the proxy's end, from keyframe `from` on.
    fn order_from(events: &[Event], from: u32) -> String {
        events
            .iter()
            .filter_map(|e| match e {
                Event::Keyframe { keyframe, .. } if keyframe.index >= from => {
                    Some(format!("k{}", keyframe.index))
                }
                Event::Proxy { keyframe, .. } => Some(format!("p{}", keyframe.index)),
                Event::ProxyEnded { error: None, .. } => Some("end".to_string()),
                Event::ProxyEnded { error: Some(e), .. } => Some(format!("failed: {e}")),
                _ => None,
            })
            .collect::<Vec<_>>()
            .join(" ")
    }

    #[test]
    fn the_viewed_keyframe_comes_converged_before_the_rest_of_the_proxy() {
        let (before, after) = late_key_edit();
        let plain = Worker::spawn(|| {}).expect("thread");
        let run = plain.start(Arc::new(after.clone()), Selection::All);
        let expected = keyframes_of(&collect_until_end(&plain, run));

        let worker = Worker::spawn(|| {}).expect("thread");
        worker.set_viewed_keyframe(Some(3));
        let run = worker.start_with_proxy(
            Arc::new(before.clone()),
            Some(coarse_of(&before)),
            Selection::All,
        );
        let first = collect_until_end(&worker, run);
        assert!(
            order_from(&first, 0).starts_with("k0 p1 p2 p3 k1 k2 k3 p4 p5 "),
            "{}",
            order_from(&first, 0)
        );
        // An edit from keyframe 40 viewed at 42: the proxy to 42, the
        // converged run to 42, the proxy's rest, the converged rest.
        worker.set_viewed_keyframe(Some(42));
        let run = worker.start_with_proxy(
            Arc::new(after.clone()),
            Some(coarse_of(&after)),
            Selection::All,
        );
        let last = collect_until_end(&worker, run);
        assert_eq!(
            order_from(&last, 40),
            "p40 p41 p42 k40 k41 k42 p43 p44 end k43 k44"
        );
        // The same converged keyframes as a run without a proxy.
        let got = keyframes_of(&last);
        assert_eq!(got.len(), expected.len());
        for (a, b) in got.iter().zip(&expected) {
            assert_eq!(a.bits(), b.bits(), "keyframe {}", a.index);
        }
        // The last keyframe viewed: the proxy runs to the end first.
        worker.set_viewed_keyframe(Some(44));
        let run = worker.start_with_proxy(
            Arc::new(before.clone()),
            Some(coarse_of(&before)),
            Selection::All,
        );
        assert_eq!(
            order_from(&collect_until_end(&worker, run), 40),
            "p40 p41 p42 p43 p44 end k40 k41 k42 k43 k44"
        );
    }

    #[test]
    fn going_back_to_a_selection_run_before_computes_nothing_that_did_not_change() {
        let project = Arc::new(whorl(2, 6, 10, 5));
        let worker = Worker::spawn(|| {}).expect("thread");
        let run = worker.start(Arc::clone(&project), Selection::All);
        let whole = keyframes_of(&collect_until_end(&worker, run));
        let run = worker.start(Arc::clone(&project), Selection::Only(1));
        let alone = collect_until_end(&worker, run);
        assert!(matches!(alone.last(), Some(Event::Finished { .. })));
        let run = worker.start(Arc::clone(&project), Selection::All);
        let back = collect_until_end(&worker, run);
        assert!(matches!(
            back.first(),
            Some(Event::Started {
                first_computed: 6,
                ..
            })
        ));
        assert!(
            !back.iter().any(|e| matches!(e, Event::Progress { .. })),
            "nothing computed"
        );
        let again = keyframes_of(&back);
        assert_eq!(again.len(), whole.len());
        assert!(again.iter().zip(&whole).all(|(a, b)| Arc::ptr_eq(a, b)));
    }

    #[test]
    fn a_proxy_that_fails_says_so_and_the_converged_run_goes_on() {
        let fine = Arc::new(whorl(1, 6, 10, 3));
        // A proxy the simulation refuses: no organs to simulate for
        // organ 0 of a one-organ selection.
        let mut broken = whorl(1, 4, 6, 3);
        broken.flower.organs.clear();
        let worker = Worker::spawn(|| {}).expect("thread");
        let run = worker.start_with_proxy(fine, Some(Arc::new(broken)), Selection::Only(0));
        let events = collect_until_end(&worker, run);
        assert!(
            events
                .iter()
                .any(|e| matches!(e, Event::ProxyEnded { error: Some(_), .. }))
        );
        assert!(matches!(events.last(), Some(Event::Finished { .. })));
        assert_eq!(keyframes_of(&events).len(), 4);
    }
}

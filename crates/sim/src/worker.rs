//! The simulation worker: one named thread that runs jobs from immutable
//! project snapshots and streams their keyframes back.
//!
//! Every job has a run id. Starting a job cancels the one running (at its
//! next iteration boundary); events carry the run id so the receiver can drop
//! events of superseded runs. The worker wakes its owner through a plain
//! callback (a UI passes something like `ctx.request_repaint`), never through
//! UI types. Dropping the handle cancels the job and joins the thread.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, Sender, SyncSender, channel, sync_channel};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Instant;

use anthesis_flower::Project;

use crate::{IterationProgress, Keyframe, Selection, SimError, Simulation};

/// Identifies one job; later jobs have larger ids.
pub type RunId = u64;

/// What a run reports, in order: `Started`, then `Keyframe`s (the bud first)
/// with `Progress` between them, then exactly one of `Finished`, `Failed` or
/// `Cancelled`.
#[derive(Debug, Clone)]
pub enum Event {
    Started {
        run: RunId,
        organs: Vec<String>,
        keyframes: u32,
    },
    Keyframe {
        run: RunId,
        keyframe: Arc<Keyframe>,
    },
    Progress {
        run: RunId,
        progress: IterationProgress,
    },
    Finished {
        run: RunId,
        keyframes: u32,
        seconds: f64,
    },
    Failed {
        run: RunId,
        error: SimError,
    },
    Cancelled {
        run: RunId,
    },
}

impl Event {
    pub fn run(&self) -> RunId {
        match self {
            Event::Started { run, .. }
            | Event::Keyframe { run, .. }
            | Event::Progress { run, .. }
            | Event::Finished { run, .. }
            | Event::Failed { run, .. }
            | Event::Cancelled { run } => *run,
        }
    }
}

enum Command {
    Run {
        run: RunId,
        project: Arc<Project>,
        selection: Selection,
    },
    Shutdown,
}

type Wake = Box<dyn Fn() + Send + Sync>;

/// Handle to the worker thread.
pub struct Worker {
    commands: SyncSender<Command>,
    events: Receiver<Event>,
    /// The newest run requested; a job whose id differs is stale and stops.
    current: Arc<AtomicU64>,
    thread: Option<JoinHandle<()>>,
}

/// Commands waiting at most; older `Run` commands are skipped anyway.
const COMMAND_CAPACITY: usize = 16;

impl Worker {
    /// Spawns the thread `anthesis-sim`. `wake` is called after each event.
    pub fn spawn(wake: impl Fn() + Send + Sync + 'static) -> std::io::Result<Worker> {
        let (commands, command_rx) = sync_channel(COMMAND_CAPACITY);
        let (event_tx, events) = channel();
        let current = Arc::new(AtomicU64::new(0));
        let shared = Arc::clone(&current);
        let wake: Wake = Box::new(wake);
        let thread = std::thread::Builder::new()
            .name("anthesis-sim".into())
            .spawn(move || serve(command_rx, event_tx, shared, wake))?;
        Ok(Worker {
            commands,
            events,
            current,
            thread: Some(thread),
        })
    }

    /// Starts simulating `project`, cancelling whatever runs now. Returns the
    /// new run's id. Never blocks on the simulation.
    pub fn start(&self, project: Arc<Project>, selection: Selection) -> RunId {
        let run = self.current.fetch_add(1, Ordering::SeqCst) + 1;
        // The channel only fills if the thread is gone; then nothing runs.
        let _ = self.commands.try_send(Command::Run {
            run,
            project,
            selection,
        });
        run
    }

    /// Cancels the running job, if any.
    pub fn cancel(&self) {
        self.current.fetch_add(1, Ordering::SeqCst);
    }

    /// The id of the newest run asked for.
    pub fn current_run(&self) -> RunId {
        self.current.load(Ordering::SeqCst)
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
        let _ = self.commands.try_send(Command::Shutdown);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

fn serve(commands: Receiver<Command>, events: Sender<Event>, current: Arc<AtomicU64>, wake: Wake) {
    let send = Mutex::new(move |event: Event| {
        let _ = events.send(event);
        wake();
    });
    let emit = |event: Event| {
        if let Ok(send) = send.lock() {
            send(event);
        }
    };
    while let Ok(command) = commands.recv() {
        match command {
            Command::Shutdown => return,
            Command::Run {
                run,
                project,
                selection,
            } => {
                if current.load(Ordering::SeqCst) != run {
                    // Superseded before it started.
                    continue;
                }
                run_job(run, &project, &selection, &current, &emit);
            }
        }
    }
}

fn run_job(
    run: RunId,
    project: &Project,
    selection: &Selection,
    current: &AtomicU64,
    emit: &dyn Fn(Event),
) {
    let started = Instant::now();
    let stale = || current.load(Ordering::SeqCst) != run;
    let mut sim = match Simulation::new(project, selection) {
        Ok(sim) => sim,
        Err(error) => {
            emit(Event::Failed { run, error });
            return;
        }
    };
    emit(Event::Started {
        run,
        organs: sim.organs().iter().map(|s| s.to_string()).collect(),
        keyframes: sim.keyframe_count(),
    });
    emit(Event::Keyframe {
        run,
        keyframe: Arc::new(sim.bud()),
    });
    while !sim.finished() {
        let result = sim.step(&stale, &mut |progress| {
            emit(Event::Progress { run, progress })
        });
        match result {
            Ok(keyframe) => emit(Event::Keyframe {
                run,
                keyframe: Arc::new(keyframe),
            }),
            Err(SimError::Cancelled) => {
                emit(Event::Cancelled { run });
                return;
            }
            Err(error) => {
                emit(Event::Failed { run, error });
                return;
            }
        }
    }
    emit(Event::Finished {
        run,
        keyframes: sim.keyframe_count(),
        seconds: started.elapsed().as_secs_f64(),
    });
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
            let end = event.run() == run
                && matches!(
                    event,
                    Event::Finished { .. } | Event::Failed { .. } | Event::Cancelled { .. }
                );
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
        // The wake follows each send, so the last one may still be on its
        // way when the last event arrives.
        let deadline = Instant::now() + Duration::from_secs(10);
        while wakes.load(Ordering::SeqCst) < events.len() && Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(1));
        }
        assert_eq!(wakes.load(Ordering::SeqCst), events.len());
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
}

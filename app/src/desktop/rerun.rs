//! When an edit starts a new run, and how long its result takes to reach
//! the screen.
//!
//! While the pointer is down (a brush stroke, a dragged value) every frame
//! may change the project; starting a run on each would spend the solver's
//! time on cancelled runs. So a run starts at most every
//! [`RESTART_EVERY_WHILE_DRAGGING`] while the pointer is down, and at once
//! when it is released. The time from that release (or from a single edit)
//! to the viewed keyframe of the new run on screen is what a user waits
//! for; it is logged per edit.

use std::time::{Duration, Instant};

use anthesis_sim::worker::RunId;

use super::session::SimSession;

/// Shortest time between two runs started while the pointer is down.
pub const RESTART_EVERY_WHILE_DRAGGING: Duration = Duration::from_millis(100);

/// Restart pacing and the edit latency being measured.
#[derive(Debug, Default)]
pub struct Rerun {
    /// When the last run started, on the frame clock (egui's input time in
    /// seconds: wall time in the window, the stepped time of a test
    /// harness, so the pacing does not depend on how fast frames are
    /// drawn).
    last_start: Option<f64>,
    /// The run that will show the last finished edit, and when that edit
    /// finished.
    waiting: Option<(RunId, Instant)>,
    /// The last run started while the pointer was down: when no edit came
    /// after it, it is the one that shows the edit at release.
    started_while_dragging: Option<RunId>,
}

impl Rerun {
    /// How long a wanted run must still wait at frame-clock time `clock`:
    /// zero when the pointer is up (`dragging` false) or the last run
    /// started long enough ago.
    pub fn wait(&self, dragging: bool, clock: f64) -> Duration {
        match self.last_start {
            Some(last) if dragging => {
                let since = Duration::try_from_secs_f64(clock - last).unwrap_or(Duration::ZERO);
                RESTART_EVERY_WHILE_DRAGGING.saturating_sub(since)
            }
            _ => Duration::ZERO,
        }
    }

    /// Notes that `run` started at `now` (frame-clock time `clock`).
    /// `finished_edit`: it is the run of an edit the user has finished
    /// (pointer up) over a result already on screen, so its latency is
    /// measured. `dragging`: the pointer is down.
    pub fn started(
        &mut self,
        run: RunId,
        finished_edit: bool,
        dragging: bool,
        now: Instant,
        clock: f64,
    ) {
        self.last_start = Some(clock);
        self.started_while_dragging = dragging.then_some(run);
        if finished_edit {
            self.waiting = Some((run, now));
        } else if self.waiting.is_some_and(|(waiting, _)| waiting != run) {
            // A later run supersedes the one measured; the edit it showed
            // is measured again when that run is released.
            self.waiting = None;
        }
    }

    /// The pointer was released at `now`. When the last run started during
    /// the drag already holds every edit (`needs_run` false: nothing
    /// changed since), that run shows the finished edit; otherwise the run
    /// started now will (see [`Rerun::started`]).
    pub fn released(&mut self, needs_run: bool, now: Instant) {
        if let Some(run) = self.started_while_dragging.take()
            && !needs_run
        {
            self.waiting = Some((run, now));
        }
    }

    /// Called each frame with what the viewport shows: the time from the
    /// finished edit to now, once (when the viewed keyframe of its run is
    /// on screen).
    pub fn shown(
        &mut self,
        session: &SimSession,
        time_in_keyframes: f64,
        now: Instant,
    ) -> Option<Duration> {
        let (run, since) = self.waiting?;
        if run != session.run() {
            self.waiting = None;
            return None;
        }
        if !session.is_current_at(time_in_keyframes) {
            return None;
        }
        self.waiting = None;
        Some(now.saturating_duration_since(since))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_wait_only_while_dragging_and_only_after_a_recent_start() {
        let mut rerun = Rerun::default();
        assert_eq!(rerun.wait(true, 2.0), Duration::ZERO, "the first dab runs");
        rerun.started(1, false, true, Instant::now(), 2.0);
        let wait = rerun.wait(true, 2.03);
        assert!(
            (wait.as_secs_f64() - 0.07).abs() < 1e-9,
            "{wait:?} after 30 ms"
        );
        assert_eq!(rerun.wait(false, 2.03), Duration::ZERO, "release runs");
        assert_eq!(rerun.wait(true, 2.25), Duration::ZERO);
        // A clock that went back (a new harness) waits at most the pace.
        assert!(rerun.wait(true, 1.0) <= RESTART_EVERY_WHILE_DRAGGING);
    }
}

#[cfg(test)]
mod release_tests {
    use std::sync::Arc;

    use anthesis_sim::Selection;

    use super::*;

    #[test]
    fn a_release_after_the_last_paced_run_measures_that_run() {
        // Slow frames: every dab of a stroke started a run, the last one
        // holds the whole stroke, and nothing is left to run at release.
        let project = Arc::new(anthesis_sim::fixtures::whorl(1, 4, 6, 3));
        let mut session = SimSession::recorded();
        let mut rerun = Rerun::default();
        let t0 = Instant::now();
        for dab in 0..3 {
            let run = session.start(Arc::clone(&project), Selection::All);
            let at = t0 + Duration::from_millis(150 * dab);
            rerun.started(run, false, true, at, 0.15 * dab as f64);
        }
        let released_at = t0 + Duration::from_millis(400);
        rerun.released(false, released_at);
        assert_eq!(rerun.waiting, Some((session.run(), released_at)));

        // With an edit left to run, the run started at release is measured.
        let run = session.start(Arc::clone(&project), Selection::All);
        rerun.started(run, false, true, released_at, 0.4);
        rerun.released(true, released_at);
        let next = session.start(project, Selection::All);
        rerun.started(next, true, false, released_at, 0.4);
        assert_eq!(rerun.waiting, Some((next, released_at)));
    }
}

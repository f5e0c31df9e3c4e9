//! When an edit starts a new run.
//!
//! While the pointer is down (a brush stroke, a dragged value) every frame
//! may change the project; starting a run on each would spend the solver's
//! time on cancelled runs. So a run starts at most every
//! [`RESTART_EVERY_WHILE_DRAGGING`] while the pointer is down, and at once
//! when it is released. How long a user then waits for the result is
//! measured where the user sees it, from the screen's pixels
//! (`app/tests/xvfb-edit-latency.sh`), not here: a frame built is not yet
//! a frame on screen.

use std::time::Duration;

/// Shortest time between two runs started while the pointer is down.
pub const RESTART_EVERY_WHILE_DRAGGING: Duration = Duration::from_millis(100);

/// Restart pacing.
#[derive(Debug, Default)]
pub struct Rerun {
    /// When the last run started, on the frame clock (egui's input time in
    /// seconds: wall time in the window, the stepped time of a test
    /// harness, so the pacing does not depend on how fast frames are
    /// drawn).
    last_start: Option<f64>,
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

    /// Notes that a run started at frame-clock time `clock`.
    pub fn started(&mut self, clock: f64) {
        self.last_start = Some(clock);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_wait_only_while_dragging_and_only_after_a_recent_start() {
        let mut rerun = Rerun::default();
        assert_eq!(rerun.wait(true, 2.0), Duration::ZERO, "the first dab runs");
        rerun.started(2.0);
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

//! Phase 1: growth. Every organ grows its triangles for the keyframe
//! (regional growth, paper §4) and is carried by its joint; the parts move
//! to the keyframe's pose.

use rayon::prelude::*;

use crate::Simulation;
#[cfg(any(test, feature = "fault-hook"))]
use crate::fault;

impl Simulation {
    /// Grows every organ for keyframe `step` (each on its own thread) and
    /// moves the parts there.
    pub(crate) fn grow(&mut self, step: u32) {
        #[cfg(any(test, feature = "fault-hook"))]
        let fault = self.fault;
        self.organs.par_iter_mut().enumerate().for_each(|(_i, o)| {
            #[cfg(any(test, feature = "fault-hook"))]
            if _i == 0 && fault == Some(fault::Fault::PanicAtKeyframe(step)) {
                panic!("forced fault at keyframe {step} (test hook)");
            }
            // Growth attaches the organ too (see `OrganSim::predict`).
            o.grow(step);
        });
        for obstacle in &mut self.obstacles {
            obstacle.move_to(step);
        }
    }
}

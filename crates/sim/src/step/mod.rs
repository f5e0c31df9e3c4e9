//! One keyframe of [`Simulation::step`], in phases, one file each (the way
//! rapier's physics pipeline splits a step):
//!
//! 1. [`grow`]: every organ grows its triangles for the keyframe (regional
//!    growth) and is carried by its joint; the parts move to their pose.
//! 2. [`search`]: the contact search where the organs are, and
//!    [`settle`]'s start on those contacts (particles grown onto the wrong
//!    side of a neighbour meet it half way).
//! 3. [`settle`]: each organ minimises its energy against the contacts held
//!    fixed (Newton, on its own thread), then is attached again; while
//!    some particle lies deeper than [`RESETTLE_DEPTH`] on the wrong side,
//!    the search runs again and the organs settle again (at most
//!    [`MAX_CONTACT_ROUNDS`] rounds).
//! 4. [`push_back`]: the paper's push-back of what is left on the wrong
//!    side, one overlap side at a time.
//! 5. [`guard`]: the checks that end a keyframe: no energy blow-up, and no
//!    triangle crossing another or its own (see [`crate::crossing`]).
//! 6. [`record`]: the keyframe and its statistics (contacts, pushes), and
//!    the checkpoint an edit resumes from.

mod grow;
mod guard;
mod push_back;
mod record;
mod rim;
pub(crate) mod search;
mod settle;

use std::time::Instant;

use crate::collide::{Violated, max_violation};
use crate::{IterationProgress, Keyframe, SimError, Simulation};
use search::unknown_geometry;

/// How many times per keyframe the organs settle, at most: once against the
/// contacts found after growth, then again against contacts found where
/// they settled (see `Simulation::step`).
const MAX_CONTACT_ROUNDS: u32 = 4;
/// Organs settle again while some particle lies deeper than this, in mean
/// edges of its organ, on the wrong side of a neighbour: the final push-back
/// then moves particles by about this at most (unless the rounds ran out),
/// too little to show as a dent.
const RESETTLE_DEPTH: f64 = 0.01;

impl Simulation {
    /// One keyframe, its phases in order (see the module's list).
    pub(crate) fn step_unguarded(
        &mut self,
        cancel: &(dyn Fn() -> bool + Sync),
        progress: &mut dyn FnMut(IterationProgress),
    ) -> Result<Keyframe, SimError> {
        let started = Instant::now();
        let step = self.next_step;
        self.grow(step);
        let mut iterations = 0;
        let mut gradient;
        // Contacts are found right after growth and held while the organs
        // relax: rebuilt every iteration from organs that all move at once,
        // they made neighbours bounce off each other instead of settling.
        let mut found = self.search(&mut unknown_geometry(self.organs.len()));
        let mut contacts = self.contacts(&found, Violated::MoveHalf, true);
        self.start_on(&contacts);
        let mut geometry;
        let mut round = 1;
        let mut pressed = Vec::new();
        // The contacts where the organs end the keyframe, when a search
        // already found them (for the statistics).
        let mut contacts_now = None;
        let pushed = loop {
            let (done, last) =
                self.settle_round(step, &contacts, &found, iterations, cancel, progress)?;
            iterations += done;
            gradient = last;
            for organ in &mut self.organs {
                organ.attach(step);
            }
            // Every organ moved.
            geometry = unknown_geometry(self.organs.len());
            if self.overlaps.is_empty()
                && self.free.is_empty()
                && self.obstacles.is_empty()
                && !self.self_contact()
            {
                break 0;
            }
            pressed = self.count_pressed(&found, &contacts);
            // Each organ kept off where its neighbours were when the
            // contacts were found, but the neighbours moved too: where
            // organs press on each other they now overlap. Pushed back from
            // there, particles jumped and left spikes; instead, while some
            // particle lies deep on the wrong side, the organs settle again
            // against contacts found where they are now.
            let next = self.search_with(&mut geometry, true);
            let fresh = self.contacts(&next, Violated::MoveHalf, true);
            let deepest = self
                .organs
                .iter()
                .zip(&fresh)
                .map(|(o, c)| max_violation(&o.positions, c) / o.mean_edge)
                .fold(0.0, f64::max);
            if deepest == 0.0 {
                // Nothing violated: these are the contacts the statistics
                // look for (moving a violated contact half way is the only
                // difference to `Violated::MoveAll`), and nothing moves
                // before they are counted.
                contacts_now = Some(self.neighbours_only(&next, fresh));
                break 0;
            }
            if deepest <= RESETTLE_DEPTH || round == MAX_CONTACT_ROUNDS {
                // The paper's push-back: nobody ends on the wrong side.
                let (pushed, after) = self.push_back(&mut geometry, next);
                contacts_now = after;
                break pushed;
            }
            contacts = fresh;
            found = next;
            round += 1;
        };
        let energy = self.check_energies(step, &found)?;
        self.check_crossings(step)?;
        Ok(self.record(
            step,
            started,
            energy,
            (iterations, gradient),
            pushed,
            &pressed,
            contacts_now,
            &mut geometry,
        ))
    }
}

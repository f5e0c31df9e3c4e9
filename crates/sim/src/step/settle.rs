//! Phases 2 and 3: the organs start the keyframe on the contacts found
//! after growth, then each settles on its own thread (Newton against the
//! contacts held fixed); what a failed or cancelled round reports.

use anthesis_physics::Contact;
use rayon::prelude::*;

use super::search::Found;
use crate::collide::start_on_contacts;
use crate::organ::{Settle, Settled};
use crate::{IterationProgress, SimError, Simulation};

/// A keyframe's contact search finds particles that rest on a neighbour a
/// hair off their contact's side or past it (the penalty's give, about
/// 1e-7 mean edges, and the start's extrapolation, 1e-6 on the lily):
/// those less than this short of it (in mean edges of their organ) start
/// the keyframe [`START_INSIDE`] past it (see `start_on_contacts`).
const START_REACH: f64 = 1e-4;
/// How far past its contact a particle on it starts a keyframe, in mean
/// edges of its organ: enough that rounding cannot leave it outside.
const START_INSIDE: f64 = 1e-6;

impl Simulation {
    /// Growth and the joint schedule may have carried particles onto the
    /// wrong side. Newton's method started there sees deep, stiff
    /// penalties and its first steps crumpled organs (a tip folded until
    /// a triangle collapsed); put them on their side first, each pair of
    /// particles meeting in the middle, and let the organs relax around
    /// the dents. They, and the particles resting on a neighbour, start
    /// a hair inside their contact, so Newton's first step holds it (see
    /// `start_on_contacts`).
    pub(crate) fn start_on(&mut self, contacts: &[Vec<Contact>]) {
        for (organ, c) in self.organs.iter_mut().zip(contacts) {
            let edge = organ.mean_edge;
            start_on_contacts(
                &mut organ.positions,
                c,
                START_REACH * edge,
                START_INSIDE * edge,
            );
        }
    }

    /// One contact round of keyframe `step`: every organ settles against
    /// `contacts` (found in `found`), `iterations` having been taken in
    /// the keyframe's earlier rounds. Reports the progress of each
    /// lockstep iteration and returns the iterations this round adds and
    /// the last relative gradient, or why the keyframe stops.
    pub(crate) fn settle_round(
        &mut self,
        step: u32,
        contacts: &[Vec<Contact>],
        found: &Found,
        iterations: u32,
        cancel: &(dyn Fn() -> bool + Sync),
        progress: &mut dyn FnMut(IterationProgress),
    ) -> Result<(u32, f64), SimError> {
        let solver = self.settings.solver;
        // Within a round the contacts are fixed, so each organ settles
        // on its own: its iterations read nothing of the others. Each
        // runs to convergence on its own thread instead of all moving in
        // lockstep, where the organ that needed the most iterations kept
        // the other core idle. The keyframes, counts and progress are
        // those of the lockstep loop (an organ that had converged only
        // repeated its converged report there).
        let settled: Vec<Settled> = self
            .organs
            .par_iter_mut()
            .zip(contacts.par_iter())
            .map(|(o, c)| o.settle(step, c, &solver, cancel))
            .collect();
        // The first failure in lockstep order: the earliest iteration,
        // then the first organ.
        let failure = settled
            .iter()
            .enumerate()
            .filter_map(|(i, s)| match &s.outcome {
                Settle::Failed(error) => Some((s.gradients.len(), i, error)),
                _ => None,
            })
            .min_by_key(|&(at, i, _)| (at, i));
        let not_converged = settled
            .iter()
            .any(|s| matches!(s.outcome, Settle::NotConverged));
        // Lockstep iterations that reported progress in this round.
        let reported = match failure {
            Some((at, _, _)) => at,
            None if not_converged => solver.max_iterations as usize,
            None => settled.iter().map(|s| s.gradients.len()).max().unwrap_or(0),
        };
        // An organ that stopped earlier repeats its last gradient.
        let gradient_at = |i: usize| {
            settled
                .iter()
                .filter_map(|s| s.gradients.get(i).or(s.gradients.last()))
                .fold(0.0f64, |a, &b| a.max(b))
        };
        // Cancelled: the iterations every organ had done are reported.
        let cancelled = settled
            .iter()
            .filter(|s| matches!(s.outcome, Settle::Cancelled))
            .map(|s| s.gradients.len())
            .min();
        let reported = cancelled.map_or(reported, |done| done.min(reported));
        for i in 0..reported {
            progress(IterationProgress {
                keyframe: step,
                iteration: iterations + i as u32,
                relative_gradient: gradient_at(i),
            });
        }
        if cancelled.is_some() {
            return Err(SimError::Cancelled);
        }
        if let Some((_, organ, error)) = failure {
            return Err(SimError::Diverged {
                keyframe: step,
                organ: self.organs[organ].name.clone(),
                error: error.clone(),
                held_against: self.held_against(found, organ),
                values: self.values_out_of_range(organ),
            });
        }
        if not_converged {
            let (organ, relative_gradient) = self.worst_organ(contacts);
            return Err(SimError::NotConverged {
                keyframe: step,
                organ: self.organs[organ].name.clone(),
                iterations: iterations + solver.max_iterations,
                relative_gradient,
                held_against: self.held_against(found, organ),
                values: self.values_out_of_range(organ),
            });
        }
        Ok((
            reported.saturating_sub(1) as u32,
            gradient_at(reported.saturating_sub(1)),
        ))
    }

    /// The organ furthest from converging against `contacts`, and its
    /// relative gradient.
    pub(crate) fn worst_organ(&mut self, contacts: &[Vec<Contact>]) -> (usize, f64) {
        let mut worst = (0, -1.0);
        for (i, (organ, c)) in self.organs.iter_mut().zip(contacts).enumerate() {
            let g = organ.relative_gradient(c);
            if g > worst.1 {
                worst = (i, g);
            }
        }
        worst
    }

    /// The organs, in the flower's order, and "the parts" that held
    /// `organ` off them in the search `found` (the names a stopped run
    /// gives, see [`crate::held_against_note`]).
    pub(crate) fn held_against(&self, found: &Found, organ: usize) -> Vec<String> {
        let mut others: Vec<usize> = self
            .sides()
            .filter(|&(key, moving, _, _)| moving == organ && !found.sides[key].is_empty())
            .map(|(_, _, other, _)| other)
            .chain(
                self.free
                    .iter()
                    .zip(&found.free)
                    .filter(|((moving, _), list)| *moving == organ && !list.is_empty())
                    .map(|(&(_, other), _)| other),
            )
            .collect();
        others.sort_unstable();
        others.dedup();
        let mut names: Vec<String> = others
            .into_iter()
            .map(|o| format!("`{}`", self.organs[o].name))
            .collect();
        if !found.parts[organ].is_empty() {
            names.push("the parts".to_string());
        }
        if !found.selves[organ].is_empty() {
            names.push("itself".to_string());
        }
        names
    }
}

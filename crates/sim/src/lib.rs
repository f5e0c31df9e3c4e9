//! The keyframe simulation loop (paper §3): for each of N steps, grow every
//! organ's triangles (regional growth), then minimise the energy, attaching
//! each organ to the receptacle by shape matching and keeping organs on
//! their side of each other after every iteration. Each step gives one
//! keyframe.
//!
//! [`Simulation`]'s doc lists a step's phases, each in its own file under
//! `step/`.
//!
//! Organs are solved in parallel (rayon) but each organ's arithmetic is
//! sequential and collisions read a snapshot, so results are bit-identical
//! whatever the thread count.

#![warn(missing_docs)]

pub mod batch;
pub mod collide;
pub mod crossing;
mod error;
#[cfg(any(test, feature = "fault-hook"))]
pub mod fault;
#[cfg(any(test, feature = "fixtures"))]
pub mod fixtures;
mod keyframe;
pub mod measure;
pub mod memory;
mod obstacle;
mod organ;
pub mod resume;
mod step;
pub mod worker;

use std::panic::{AssertUnwindSafe, catch_unwind};

use anthesis_flower::Project;
use anthesis_mesh::crossing::CrossingSearch;
use rayon::prelude::*;

use crate::crossing::{Crossings, OnCrossing};
use crate::obstacle::ObstacleSim;
use crate::organ::{OrganSim, OrganState};
use crate::resume::{Edit, edit_between};
use crate::step::search::free_pairs;

pub use crate::error::{
    SimError, held_against_note, panic_message, values_note, values_out_of_range,
};
pub use crate::keyframe::{Keyframe, KeyframeStats, Selection};

/// Progress inside a keyframe, reported after every iteration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IterationProgress {
    /// The keyframe being computed.
    pub keyframe: u32,
    /// Which Newton iteration of the keyframe this is, from 0, counted
    /// over all contact rounds.
    pub iteration: u32,
    /// The largest relative gradient over the organs at the start of this
    /// iteration; the keyframe converges below the relative tolerance.
    pub relative_gradient: f64,
}

/// The state of every organ at the end of one keyframe, and what the
/// blow-up check compares the next keyframe with.
struct Checkpoint {
    organs: Vec<OrganState>,
    previous_energy: Vec<f64>,
}

/// A running simulation of a project (or of one organ of it).
///
/// Each [`Simulation::step`] computes one keyframe in these phases, one
/// file each under `step/` (the way rapier's pipeline splits a step):
/// 1. **grow** (`step/grow.rs`): every organ grows its triangles (regional
///    growth) and is carried by its joint; the parts move to their pose;
/// 2. **search** (`step/search.rs`): contacts where the organs are, against
///    the neighbours (overlap sides, free pairs), the parts and the organ
///    itself; the organs start on them (`step/settle.rs`);
/// 3. **settle** (`step/settle.rs`): each organ minimises its energy against
///    the contacts held fixed, on its own thread, and is attached again;
///    searched and settled again while some particle lies deep on the wrong
///    side;
/// 4. **push back** (`step/push_back.rs`): what is left on the wrong side is
///    moved out, one overlap side at a time;
/// 5. **guard** (`step/guard.rs`): no energy blow-up, no crossing triangles;
/// 6. **record** (`step/record.rs`): the keyframe, its statistics and the
///    checkpoint an edit resumes from.
pub struct Simulation {
    organs: Vec<OrganSim>,
    /// The simulated organs, and their indices in the project.
    selection: Selection,
    chosen: Vec<usize>,
    /// When kept (see [`Simulation::keep_checkpoints`]), entry `k` is the
    /// state at the end of keyframe `k` (0: the bud), for every keyframe
    /// computed so far.
    checkpoints: Option<Vec<Checkpoint>>,
    /// Overlaps between simulated organs, as indices into `organs`.
    overlaps: Vec<(usize, usize)>,
    /// Every (moving, other) pair of growing organ and organ with no
    /// overlap rule between them, each keeping the side it was on.
    free: Vec<(usize, usize)>,
    /// The parts every organ is kept out of.
    obstacles: Vec<ObstacleSim>,
    settings: anthesis_flower::SimulationSettings,
    next_step: u32,
    /// Energy per organ at the previous keyframe, to spot blow-ups.
    previous_energy: Vec<f64>,
    /// The keyframe whose step panicked: the organs may be half updated,
    /// so no further step runs.
    panicked_at: Option<u32>,
    /// What a step does when its keyframe has crossing triangles.
    on_crossing: OnCrossing,
    /// The crossing search's buffers, kept between keyframes.
    crossing_search: CrossingSearch,
    /// What [`OnCrossing::Warn`] let through, per keyframe in order.
    crossings: Vec<Crossings>,
    /// Whether contacts between organs push both (see
    /// [`Simulation::two_sided_contact`]).
    two_sided: bool,
    /// Particles held off their own organ by a self-contact while the
    /// organs settled, summed over the keyframes computed.
    self_pressed: u64,
    /// Test only: the push-back checks each piece of the rim contacts it
    /// keeps against one made again where the organs are.
    #[cfg(test)]
    check_rim_pieces: bool,
    /// Test only: the rim pieces the push-back kept.
    #[cfg(test)]
    kept_rim_pieces: usize,
    /// Per organ, its template's values outside the range the solver is
    /// made for, named when a run stops at it (see
    /// [`error::values_out_of_range`]).
    out_of_range: Vec<Vec<String>>,
    #[cfg(any(test, feature = "fault-hook"))]
    fault: Option<fault::Fault>,
}

/// Per organ of `chosen`, its template's values outside the range the
/// solver is made for.
fn out_of_range(project: &Project, chosen: &[usize]) -> Vec<Vec<String>> {
    chosen
        .iter()
        .map(|&i| error::values_out_of_range(project.flower.template_of(i)))
        .collect()
}

impl Simulation {
    /// The values of organ `organ`'s template outside the range the
    /// solver is made for, for a failure at it.
    pub(crate) fn values_out_of_range(&self, organ: usize) -> Vec<String> {
        self.out_of_range.get(organ).cloned().unwrap_or_default()
    }

    /// Sets up a run of `project` (all organs or one, per `selection`) at
    /// the bud: validates every template and builds its solver. Fails with
    /// [`SimError::BadMesh`], [`SimError::BadTemplate`] or
    /// [`SimError::NoSuchOrgan`].
    pub fn new(project: &Project, selection: &Selection) -> Result<Simulation, SimError> {
        let flower = &project.flower;
        if let Selection::Only(i) = selection
            && *i >= flower.organs.len()
        {
            return Err(SimError::NoSuchOrgan(*i));
        }
        let chosen = selection.organs(flower.organs.len());
        // Each organ on its own thread (its fill-reducing order and
        // symbolic factorisation: 0.2 s for the whole lily at 4k particles
        // per organ on one core); the first failure in organ order is the
        // one reported, whatever the threads.
        let organs = chosen
            .par_iter()
            .map(|&i| OrganSim::new(&flower.organs[i], flower.template_of(i), &project.settings))
            .collect::<Vec<_>>()
            .into_iter()
            .collect::<Result<Vec<_>, _>>()?;
        let overlaps = flower
            .overlaps
            .iter()
            .filter_map(|o| {
                let inner = chosen.iter().position(|&c| c == o.inner)?;
                let outer = chosen.iter().position(|&c| c == o.outer)?;
                Some((inner, outer))
            })
            .collect::<Vec<_>>();
        let previous_energy = vec![0.0; organs.len()];
        let out_of_range = out_of_range(project, &chosen);
        let free = free_pairs(&organs, &overlaps);
        let obstacles = anthesis_flower::parts::obstacles(flower)
            .into_iter()
            .map(ObstacleSim::new)
            .collect();
        Ok(Simulation {
            organs,
            selection: selection.clone(),
            chosen,
            checkpoints: None,
            overlaps,
            free,
            obstacles,
            settings: project.settings,
            next_step: 1,
            previous_energy,
            panicked_at: None,
            on_crossing: OnCrossing::Stop,
            crossing_search: CrossingSearch::new(),
            crossings: Vec::new(),
            two_sided: false,
            self_pressed: 0,
            #[cfg(test)]
            check_rim_pieces: false,
            #[cfg(test)]
            kept_rim_pieces: 0,
            out_of_range,
            #[cfg(all(feature = "fault-hook", not(test)))]
            fault: fault::Fault::from_env(),
            #[cfg(test)]
            fault: None,
        })
    }

    /// Keeps the state at the end of every keyframe from now on, so that
    /// [`Simulation::edit`] can go on from the first keyframe an edit
    /// changes instead of from the bud. Costs, per keyframe and organ, the
    /// positions and two numbers per edge (see
    /// [`Simulation::checkpoint_bytes`]); a batch run that is never edited
    /// does without.
    pub fn keep_checkpoints(&mut self) {
        if self.checkpoints.is_none() && self.next_step == 1 {
            let bud = self.checkpoint();
            self.checkpoints = Some(vec![bud]);
        }
    }

    /// Memory the kept checkpoints hold, in bytes.
    pub fn checkpoint_bytes(&self) -> usize {
        self.checkpoints
            .iter()
            .flatten()
            .map(|c| c.organs.iter().map(OrganState::bytes).sum::<usize>())
            .sum()
    }

    pub(crate) fn checkpoint(&mut self) -> Checkpoint {
        Checkpoint {
            organs: self.organs.iter_mut().map(OrganSim::save).collect(),
            previous_energy: self.previous_energy.clone(),
        }
    }

    /// Makes this simulation run `after` instead of `before` (the project
    /// it was made from or last edited to), keeping every computed keyframe
    /// the edit cannot change (see [`resume`]). Returns the first keyframe
    /// the next [`Simulation::step`] computes: keyframes before it are those
    /// computed already and still valid; 1 means the run starts over (when
    /// the edit reaches the bud, or no checkpoints were kept).
    ///
    /// The keyframes computed from there are the same, bit for bit, as a
    /// run of `after` from the bud.
    pub fn edit(&mut self, before: &Project, after: &Project) -> Result<u32, SimError> {
        let edit = if self.panicked_at.is_some() {
            Edit::Everything
        } else {
            edit_between(before, after, &self.chosen)
        };
        let first = match edit {
            Edit::Nothing => self.next_step,
            Edit::From(step) => step.min(self.next_step),
            Edit::Everything => 1,
        };
        let rewound = first > 1 && self.rewind(first);
        if !rewound {
            let keep = self.checkpoints.is_some();
            let selection = self.selection.clone();
            let (on_crossing, two_sided) = (self.on_crossing, self.two_sided);
            *self = Simulation::new(after, &selection)?;
            self.on_crossing = on_crossing;
            self.two_sided = two_sided;
            if keep {
                self.keep_checkpoints();
            }
            return Ok(1);
        }
        self.out_of_range = out_of_range(after, &self.chosen);
        for (organ, &index) in self.organs.iter_mut().zip(&self.chosen) {
            organ.take_maps(
                before.flower.template_of(index),
                after.flower.template_of(index),
            );
        }
        // A part's schedule may differ from a later step on (`resume`):
        // the parts take the edited ones, as a run of `after` from the bud
        // has them (their shapes and places are the same, or the run
        // started over above).
        let pieces = anthesis_flower::parts::obstacles(&after.flower);
        for (obstacle, piece) in self.obstacles.iter_mut().zip(pieces) {
            obstacle.take(piece);
        }
        self.settings.keyframes = after.settings.keyframes;
        Ok(self.next_step)
    }

    /// Puts every organ back at the end of keyframe `step - 1`, if that
    /// state was kept, so the next step computes keyframe `step`.
    pub(crate) fn rewind(&mut self, step: u32) -> bool {
        let Some(checkpoints) = &mut self.checkpoints else {
            return false;
        };
        let Some(state) = checkpoints.get(step as usize - 1) else {
            return false;
        };
        for (organ, saved) in self.organs.iter_mut().zip(&state.organs) {
            organ.restore(saved);
        }
        self.previous_energy.clone_from(&state.previous_energy);
        checkpoints.truncate(step as usize);
        self.next_step = step;
        self.crossings.retain(|c| c.keyframe < step);
        true
    }

    /// Forces `fault` on this simulation (tests only).
    #[cfg(any(test, feature = "fault-hook"))]
    pub fn inject(&mut self, fault: Option<fault::Fault>) {
        self.fault = fault;
    }

    /// What a step does when its keyframe has crossing triangles (see
    /// [`crossing`]): stop ([`OnCrossing::Stop`], the default) or go on
    /// and keep what it found ([`Simulation::crossings`]).
    pub fn on_crossing(&mut self, choice: OnCrossing) {
        self.on_crossing = choice;
    }

    /// Two-sided contact (issue 35): with `on`, a contact between organs
    /// acts on both, equal and opposite: a particle pressed between 0.015
    /// and 0.5 mean edges into a neighbour pushes the neighbour's triangle
    /// under it back (its corners, by their barycentric weights), and the
    /// two meet half way, so a petal pressing a neighbour moves it. Off by
    /// default: with it the whole lily takes 9 % more Newton iterations and
    /// the apple a quarter more, and an apparently harmless change of the
    /// depth threshold made the apple's sepal rims cross its petals
    /// (README, "Two-sided contact").
    pub fn two_sided_contact(&mut self, on: bool) {
        self.two_sided = on;
    }

    /// How many particles a self-contact held off their own organ while
    /// the organs settled, summed over the keyframes computed (a particle
    /// counts once per keyframe and contact round).
    pub fn self_contact_count(&self) -> u64 {
        self.self_pressed
    }

    /// The crossings [`OnCrossing::Warn`] let through, one per keyframe
    /// that had any, in keyframe order.
    pub fn crossings(&self) -> &[Crossings] {
        &self.crossings
    }

    /// Names of the simulated organs, in keyframe order.
    pub fn organs(&self) -> Vec<&str> {
        self.organs.iter().map(|o| o.name.as_str()).collect()
    }

    /// Triangles of simulated organ `i`.
    pub fn triangles(&self, i: usize) -> &[[u32; 3]] {
        &self.organs[i].mesh.triangles
    }

    /// UVs of simulated organ `i`.
    pub fn uvs(&self, i: usize) -> &[glam::DVec2] {
        &self.organs[i].mesh.uvs
    }

    /// Display colour of simulated organ `i`.
    pub fn colour(&self, i: usize) -> [f32; 4] {
        self.organs[i].colour
    }

    /// Numeric Hessian factorisations done so far, over all organs (the
    /// dominant cost of a run; see the benchmark notes in the README).
    pub fn factorisations(&self) -> u64 {
        self.organs.iter().map(|o| o.factorisations()).sum()
    }

    /// How many keyframes the run computes after the bud (the project's
    /// setting).
    pub fn keyframe_count(&self) -> u32 {
        self.settings.keyframes
    }

    /// Keyframe 0: the bud, placed on the receptacle.
    pub fn bud(&self) -> Keyframe {
        Keyframe {
            index: 0,
            positions_in_world: self.organs.iter().map(|o| o.initial.clone()).collect(),
            stats: KeyframeStats {
                index: 0,
                energy: 0.0,
                iterations: 0,
                relative_gradient: 0.0,
                seconds: 0.0,
                pushed_particles: 0,
                contact_particles: 0,
            },
        }
    }

    /// Whether all keyframes have been computed.
    pub fn finished(&self) -> bool {
        self.next_step > self.settings.keyframes
    }

    /// Computes the next keyframe. `cancel` is polled between iterations;
    /// when it returns true the step stops with [`SimError::Cancelled`] and
    /// the simulation must not be stepped again.
    ///
    /// A panic inside the step (a bug) is caught and returned as
    /// [`SimError::Panicked`] naming the keyframe; the keyframes returned
    /// before stay good, and every later call returns the same error.
    pub fn step(
        &mut self,
        cancel: &(dyn Fn() -> bool + Sync),
        progress: &mut dyn FnMut(IterationProgress),
    ) -> Result<Keyframe, SimError> {
        let step = self.next_step;
        let panicked = |keyframe: u32, message: String| SimError::Panicked {
            run: None,
            keyframe: Some(keyframe),
            message,
        };
        if let Some(keyframe) = self.panicked_at {
            return Err(panicked(
                keyframe,
                "an earlier step failed; the simulation cannot go on".to_string(),
            ));
        }
        // Unwind safety: after a panic the organs may be half updated;
        // `panicked_at` stops every later step from reading them.
        match catch_unwind(AssertUnwindSafe(|| self.step_unguarded(cancel, progress))) {
            Ok(result) => result,
            Err(payload) => {
                self.panicked_at = Some(step);
                Err(panicked(step, panic_message(payload.as_ref())))
            }
        }
    }
}

/// Runs a whole project to the end, calling `on_keyframe` for the bud and
/// each computed keyframe. Convenience for the command line and tests.
pub fn run(
    project: &Project,
    selection: &Selection,
    on_keyframe: &mut dyn FnMut(&Simulation, &Keyframe),
) -> Result<Simulation, SimError> {
    let mut sim = Simulation::new(project, selection)?;
    let bud = sim.bud();
    on_keyframe(&sim, &bud);
    while !sim.finished() {
        let keyframe = sim.step(&|| false, &mut |_| {})?;
        on_keyframe(&sim, &keyframe);
    }
    Ok(sim)
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_note_on_what_held_an_organ_lists_its_neighbours_in_words() {
        let names = |n: &[&str]| n.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        assert_eq!(held_against_note(&[]), "");
        assert!(
            held_against_note(&names(&["`sepal-1`"]))
                .starts_with("; it was against `sepal-1` there: ")
        );
        assert!(
            held_against_note(&names(&["`petal-1`", "`petal-3`", "the parts"]))
                .starts_with("; it was against `petal-1`, `petal-3` and the parts there: ")
        );
    }

    use super::*;
    use crate::fault::Fault;
    use crate::fixtures::whorl;

    #[test]
    fn a_panicking_step_is_an_error_naming_its_keyframe_and_the_run_stops_there() {
        let project = whorl(2, 6, 10, 4);
        let mut sim = Simulation::new(&project, &Selection::All).expect("valid");
        sim.inject(Some(Fault::PanicAtKeyframe(2)));
        let first = sim
            .step(&|| false, &mut |_| {})
            .expect("keyframe 1 is fine");
        assert_eq!(first.index, 1);
        let error = sim
            .step(&|| false, &mut |_| {})
            .expect_err("keyframe 2 panics");
        assert!(
            matches!(
                &error,
                SimError::Panicked { run: None, keyframe: Some(2), message }
                    if message == "forced fault at keyframe 2 (test hook)"
            ),
            "{error:?}"
        );
        assert!(error.to_string().starts_with("keyframe 2: internal error"));
        // The organs may be half grown: no later step runs on them.
        let again = sim.step(&|| false, &mut |_| {}).expect_err("still stopped");
        assert!(
            matches!(
                again,
                SimError::Panicked {
                    keyframe: Some(2),
                    ..
                }
            ),
            "{again:?}"
        );
    }
}

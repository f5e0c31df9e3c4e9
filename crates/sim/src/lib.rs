//! The keyframe simulation loop (paper §3): for each of N steps, grow every
//! organ's triangles (regional growth), then minimise the energy, attaching
//! each organ to the receptacle by shape matching and keeping organs on
//! their side of each other after every iteration. Each step gives one
//! keyframe.
//!
//! Organs are solved in parallel (rayon) but each organ's arithmetic is
//! sequential and collisions read a snapshot, so results are bit-identical
//! whatever the thread count.

#![warn(missing_docs)]

pub mod batch;
pub mod collide;
pub mod crossing;
#[cfg(any(test, feature = "fault-hook"))]
pub mod fault;
pub mod fixtures;
pub mod memory;
mod obstacle;
mod organ;
pub mod resume;
pub mod worker;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::time::Instant;

use anthesis_flower::Project;
use anthesis_mesh::MeshError;
use anthesis_mesh::crossing::{Body, CrossingSearch};
use anthesis_physics::solver::same_position_bits;
use anthesis_physics::{Contact, SolverError};
use glam::DVec3;
use rayon::prelude::*;

use crate::collide::{
    Surface, Tracker, Violated, contacts_against, contacts_of, kept_side_contacts, max_violation,
    move_half, push_back, self_contacts, start_on_contacts,
};
use crate::crossing::{Crossed, Crossings, OnCrossing};
use crate::obstacle::ObstacleSim;
use crate::organ::{OrganSim, OrganState, Settle, Settled};
use crate::resume::{Edit, edit_between};

/// Which organs to simulate.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Selection {
    /// The whole flower, with collisions.
    All,
    /// One organ on its own (fast preview), by index into the project's organs.
    Only(usize),
}

impl Selection {
    /// The chosen organs of a flower of `organ_count` organs, as indices in
    /// the order a run's keyframes hold them (not checked against the count).
    pub fn organs(&self, organ_count: usize) -> Vec<usize> {
        match self {
            Selection::All => (0..organ_count).collect(),
            Selection::Only(i) => vec![*i],
        }
    }
}

/// Statistics of one keyframe.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct KeyframeStats {
    /// The keyframe's number (0 is the bud).
    pub index: u32,
    /// Total elastic energy of the simulated organs after minimisation.
    pub energy: f64,
    /// Newton iterations taken (the largest over organs).
    pub iterations: u32,
    /// Largest relative gradient over organs at convergence: the largest
    /// force on a particle over a typical edge's force at 100 % strain (see
    /// `SolverSettings::relative_tolerance`).
    pub relative_gradient: f64,
    /// Wall time for this keyframe.
    pub seconds: f64,
    /// Particles the final push-back moved.
    pub pushed_particles: u32,
    /// Particles touching a neighbouring organ when the keyframe ends:
    /// held off it by a contact force when the organs settled, or within
    /// the collision offset of its surface or pressed into it after.
    pub contact_particles: u32,
}

/// One keyframe: world positions of every simulated organ.
#[derive(Debug, Clone, PartialEq)]
pub struct Keyframe {
    /// The keyframe's number: 0 is the bud, `k` the state after `k` steps.
    pub index: u32,
    /// One position list per simulated organ, in the order of
    /// [`Simulation::organs`], in the world frame.
    pub positions_in_world: Vec<Vec<DVec3>>,
    /// How the keyframe's solve went (energy, iterations, time, contacts).
    pub stats: KeyframeStats,
}

impl Keyframe {
    /// Every bit of the keyframe but its wall time: its number, each
    /// organ's particle count and positions, and its statistics. Two runs
    /// made the same keyframe when these are equal (the rerun and
    /// determinism checks compare them).
    pub fn bits(&self) -> Vec<u64> {
        let s = &self.stats;
        let mut out = vec![
            u64::from(self.index),
            u64::from(s.index),
            s.energy.to_bits(),
            u64::from(s.iterations),
            s.relative_gradient.to_bits(),
            u64::from(s.pushed_particles),
            u64::from(s.contact_particles),
        ];
        for organ in &self.positions_in_world {
            out.push(organ.len() as u64);
            out.extend(organ.iter().flat_map(|p| p.to_array().map(f64::to_bits)));
        }
        out
    }
}

/// Why a run stopped early. Each names the keyframe and organ involved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// A template's mesh fails validation, so the run does not start.
    #[error("template `{template}` has a bad mesh: {error}")]
    BadMesh {
        /// The template's name.
        template: String,
        /// What is wrong with its mesh.
        error: MeshError,
    },
    /// A template's parameters are out of range (e.g. a thickness of 0),
    /// or its solver could not be set up; the run does not start.
    #[error("template `{template}`: {message}")]
    BadTemplate {
        /// The template's name.
        template: String,
        /// Which value is wrong, or why the solver could not be set up.
        message: String,
    },
    /// A single organ was asked to be simulated by an index the project
    /// does not have.
    #[error("organ index {0} does not exist")]
    NoSuchOrgan(usize),
    /// The energy minimisation of one organ failed (see [`SolverError`]).
    #[error(
        "keyframe {keyframe}, organ `{organ}`: the solver diverged: {error}{}",
        held_against_note(held_against)
    )]
    Diverged {
        /// The keyframe being computed.
        keyframe: u32,
        /// The organ's name.
        organ: String,
        /// How the solver failed.
        error: SolverError,
        /// What the organ was held off in that keyframe (see
        /// [`held_against_note`]).
        held_against: Vec<String>,
    },
    /// An organ's energy became non-finite or rose more than a
    /// million-fold from the previous keyframe: growth too strong for the
    /// mesh or its stiffness.
    #[error(
        "keyframe {keyframe}, organ `{organ}`: the energy blew up to {energy:.3e} (from {previous:.3e}){}",
        held_against_note(held_against)
    )]
    EnergyBlowUp {
        /// The keyframe being computed.
        keyframe: u32,
        /// The organ's name.
        organ: String,
        /// Its elastic energy at this keyframe.
        energy: f64,
        /// Its elastic energy at the previous keyframe.
        previous: f64,
        /// What the organ was held off in that keyframe (see
        /// [`held_against_note`]).
        held_against: Vec<String>,
    },
    /// The organs did not settle within the solver's iteration limit
    /// (`max_iterations` per contact round); a higher limit or a looser
    /// tolerance may help.
    #[error(
        "keyframe {keyframe}, organ `{organ}`: not converged after {iterations} iterations (relative gradient {relative_gradient:.3e}){}",
        held_against_note(held_against)
    )]
    NotConverged {
        /// The keyframe being computed.
        keyframe: u32,
        /// The organ furthest from converging.
        organ: String,
        /// The Newton iterations taken in the keyframe, over all contact
        /// rounds.
        iterations: u32,
        /// That organ's relative gradient when the limit was reached (see
        /// [`KeyframeStats::relative_gradient`]).
        relative_gradient: f64,
        /// What the organ was held off in that keyframe (see
        /// [`held_against_note`]).
        held_against: Vec<String>,
    },
    /// Triangles of the keyframe cross: an organ passes through another,
    /// a part or itself (see [`crossing`]). The organs are left where that
    /// keyframe put them; the keyframes before it stay good.
    #[error("{0}; the keyframes before it are kept")]
    Crossed(Box<Crossings>),
    /// A bug: the simulation panicked. Caught so the worker and the
    /// command line survive it and keep what was computed before.
    #[error("{}", describe_panic(*.run, *.keyframe, .message))]
    Panicked {
        /// The worker's run, when the worker caught it.
        run: Option<u64>,
        /// The keyframe being computed, if the panic came from a step.
        keyframe: Option<u32>,
        /// The panic's message.
        message: String,
    },
    /// The caller asked the step to stop (a newer run replaced it); not a
    /// failure, and the keyframes before are kept.
    #[error("cancelled")]
    Cancelled,
}

/// What a run that stopped at an organ adds about what held it: a
/// painter whose petal curls around a sepal, or is pressed onto a stamen,
/// should learn which neighbours to look at. The contacts keep each organ
/// on its side of the others (the overlap order) and outside the parts; an
/// organ grown around another, or caught between neighbours and a part,
/// cannot be, and the solver then stops there.
pub fn held_against_note(held_against: &[String]) -> String {
    const CAUGHT: &str = ": organs grown around or caught between each other can stop a run";
    match held_against {
        [] => String::new(),
        [one] => format!("; it was against {one} there{CAUGHT}"),
        [init @ .., last] => format!(
            "; it was against {} and {last} there{CAUGHT}",
            init.join(", ")
        ),
    }
}

fn describe_panic(run: Option<u64>, keyframe: Option<u32>, message: &str) -> String {
    let place = match (run, keyframe) {
        (Some(run), Some(keyframe)) => format!("run {run}, keyframe {keyframe}"),
        (Some(run), None) => format!("run {run}, before its first keyframe"),
        (None, Some(keyframe)) => format!("keyframe {keyframe}"),
        (None, None) => "the simulation".to_string(),
    };
    format!(
        "{place}: internal error, the simulation stopped (a bug in Anthesis; please report it): {message}"
    )
}

/// The text of a caught panic's payload (`panic!` gives a `&str` or a
/// `String`).
pub fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(text) = payload.downcast_ref::<&str>() {
        (*text).to_string()
    } else if let Some(text) = payload.downcast_ref::<String>() {
        text.clone()
    } else {
        "a panic without a message".to_string()
    }
}

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

/// How many times per keyframe the organs settle, at most: once against the
/// contacts found after growth, then again against contacts found where
/// they settled (see `Simulation::step`).
const MAX_CONTACT_ROUNDS: u32 = 4;
/// Organs settle again while some particle lies deeper than this, in mean
/// edges of its organ, on the wrong side of a neighbour: the final push-back
/// then moves particles by about this at most (unless the rounds ran out),
/// too little to show as a dent.
const RESETTLE_DEPTH: f64 = 0.01;

/// A keyframe's contact search finds particles that rest on a neighbour a
/// hair off their contact's side or past it (the penalty's give, about
/// 1e-7 mean edges, and the start's extrapolation, 1e-6 on the lily):
/// those less than this short of it (in mean edges of their organ) start
/// the keyframe [`START_INSIDE`] past it (see `start_on_contacts`).
const START_REACH: f64 = 1e-4;
/// How far past its contact a particle on it starts a keyframe, in mean
/// edges of its organ: enough that rounding cannot leave it outside.
const START_INSIDE: f64 = 1e-6;

/// Passes of the final push-back at most.
const PUSH_BACK_PASSES: u32 = 3;

/// The state of every organ at the end of one keyframe, and what the
/// blow-up check compares the next keyframe with.
struct Checkpoint {
    organs: Vec<OrganState>,
    previous_energy: Vec<f64>,
}

/// A running simulation of a project (or of one organ of it).
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
    /// Particles held off their own organ by a self-contact while the
    /// organs settled, summed over the keyframes computed.
    self_pressed: u64,
    #[cfg(any(test, feature = "fault-hook"))]
    fault: Option<fault::Fault>,
}

impl Simulation {
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
            self_pressed: 0,
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

    fn checkpoint(&mut self) -> Checkpoint {
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
            let on_crossing = self.on_crossing;
            *self = Simulation::new(after, &selection)?;
            self.on_crossing = on_crossing;
            if keep {
                self.keep_checkpoints();
            }
            return Ok(1);
        }
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
    fn rewind(&mut self, step: u32) -> bool {
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

    /// Where the triangles of the organs where they are now cross each
    /// other, themselves or the parts at step `step`'s pose, if anywhere.
    fn find_crossings(&mut self, step: u32) -> Option<Crossings> {
        for obstacle in &mut self.obstacles {
            obstacle.move_to(step);
        }
        let organs = self.organs.len();
        let bodies: Vec<Body<'_>> = self
            .organs
            .iter()
            .map(|o| Body {
                positions: &o.positions,
                triangles: &o.mesh.triangles,
            })
            .chain(self.obstacles.iter().map(|o| {
                let s = o.surface();
                Body {
                    positions: s.positions,
                    triangles: s.triangles,
                }
            }))
            .collect();
        // Twice the organs' largest mean edge: a cell holds a triangle and
        // its neighbours.
        let cell = 2.0 * self.organs.iter().map(|o| o.mean_edge).fold(0.0, f64::max);
        // Parts against parts are not tested: they overlap by design.
        let found = self
            .crossing_search
            .find(&bodies, cell, &|i, j| i.min(j) < organs);
        if found.is_empty() {
            return None;
        }
        let side = |body: u32, triangle: u32, at: [f64; 3]| {
            let body = body as usize;
            match self.organs.get(body) {
                Some(o) => {
                    let corners = o.mesh.triangles[triangle as usize];
                    let uv = (0..3)
                        .map(|k| o.mesh.uvs[corners[k] as usize] * at[k])
                        .sum::<glam::DVec2>();
                    Crossed::Organ {
                        index: body,
                        name: o.name.clone(),
                        uv,
                    }
                }
                None => Crossed::Part {
                    name: self.obstacles[body - organs].name().to_string(),
                },
            }
        };
        let mut between: Vec<((u32, u32), Crossed, Crossed, usize)> = Vec::new();
        for c in &found {
            let key = (c.a.body, c.b.body);
            match between.iter_mut().find(|(k, ..)| *k == key) {
                Some((_, _, _, n)) => *n += 1,
                None => between.push((
                    key,
                    side(c.a.body, c.a.triangle, c.at_a),
                    side(c.b.body, c.b.triangle, c.at_b),
                    1,
                )),
            }
        }
        let mut crossing_organs: Vec<usize> = found
            .iter()
            .flat_map(|c| [c.a.body as usize, c.b.body as usize])
            .filter(|&b| b < organs)
            .collect();
        crossing_organs.sort_unstable();
        crossing_organs.dedup();
        Some(Crossings {
            keyframe: step,
            pairs: found.len(),
            between: between.into_iter().map(|(_, a, b, n)| (a, b, n)).collect(),
            organs: crossing_organs,
        })
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
    pub fn color(&self, i: usize) -> [f32; 4] {
        self.organs[i].color
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

    fn step_unguarded(
        &mut self,
        cancel: &(dyn Fn() -> bool + Sync),
        progress: &mut dyn FnMut(IterationProgress),
    ) -> Result<Keyframe, SimError> {
        let started = Instant::now();
        let step = self.next_step;
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
        let solver = self.settings.solver;
        let mut iterations = 0;
        let mut gradient;
        // Contacts are found right after growth and held while the organs
        // relax: rebuilt every iteration from organs that all move at once,
        // they made neighbours bounce off each other instead of settling.
        let mut found = self.search(&mut unknown_geometry(self.organs.len()));
        let mut contacts = self.contacts(&found, Violated::MoveHalf, true);
        // Growth and the joint schedule may have carried particles onto the
        // wrong side. Newton's method started there sees deep, stiff
        // penalties and its first steps crumpled organs (a tip folded until
        // a triangle collapsed); put them on their side first, each pair of
        // particles meeting in the middle, and let the organs relax around
        // the dents. They, and the particles resting on a neighbour, start
        // a hair inside their contact, so Newton's first step holds it (see
        // `start_on_contacts`).
        for (organ, c) in self.organs.iter_mut().zip(&contacts) {
            let edge = organ.mean_edge;
            start_on_contacts(
                &mut organ.positions,
                c,
                START_REACH * edge,
                START_INSIDE * edge,
            );
        }
        let mut geometry;
        let mut round = 1;
        let mut pressed = Vec::new();
        // The contacts where the organs end the keyframe, when a search
        // already found them (for the statistics).
        let mut contacts_now = None;
        let pushed = loop {
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
                    held_against: self.held_against(&found, organ),
                });
            }
            if not_converged {
                iterations += solver.max_iterations;
                let (organ, relative_gradient) = self.worst_organ(&contacts);
                return Err(SimError::NotConverged {
                    keyframe: step,
                    organ: self.organs[organ].name.clone(),
                    iterations,
                    relative_gradient,
                    held_against: self.held_against(&found, organ),
                });
            }
            iterations += reported.saturating_sub(1) as u32;
            gradient = gradient_at(reported.saturating_sub(1));
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
            // The contacts held, less the self-contacts (appended last).
            let neighbours = self.neighbour_contacts(&found);
            let held: Vec<Vec<Contact>> = contacts
                .iter()
                .zip(&neighbours)
                .map(|(c, &n)| c[..n].to_vec())
                .collect();
            pressed = self.pressed(&held);
            self.self_pressed += self
                .pressed(&found.selves)
                .iter()
                .flatten()
                .filter(|&&p| p)
                .count() as u64;
            // Each organ kept off where its neighbours were when the
            // contacts were found, but the neighbours moved too: where
            // organs press on each other they now overlap. Pushed back from
            // there, particles jumped and left spikes; instead, while some
            // particle lies deep on the wrong side, the organs settle again
            // against contacts found where they are now.
            let next = self.search(&mut geometry);
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
                let neighbours = self.neighbour_contacts(&next);
                contacts_now = Some(
                    fresh
                        .into_iter()
                        .zip(neighbours)
                        .map(|(mut c, n)| {
                            c.truncate(n);
                            c
                        })
                        .collect(),
                );
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

        let mut energy = 0.0;
        let energies: Vec<f64> = self.organs.par_iter().map(OrganSim::energy).collect();
        for (i, (organ, &e)) in self.organs.iter().zip(&energies).enumerate() {
            if !e.is_finite()
                || (self.previous_energy[i] > 0.0
                    && e > 1e6 * self.previous_energy[i].max(organ.energy_floor()))
            {
                return Err(SimError::EnergyBlowUp {
                    keyframe: step,
                    organ: organ.name.clone(),
                    energy: e,
                    previous: self.previous_energy[i],
                    held_against: self.held_against(&found, i),
                });
            }
            self.previous_energy[i] = e;
            energy += e;
        }
        // No silent crossing (see `crossing`).
        if let Some(crossings) = self.find_crossings(step) {
            match self.on_crossing {
                OnCrossing::Stop => return Err(SimError::Crossed(Box::new(crossings))),
                OnCrossing::Warn => self.crossings.push(crossings),
            }
        }
        self.next_step += 1;
        if self.checkpoints.is_some() {
            let state = self.checkpoint();
            self.checkpoints.get_or_insert_default().push(state);
        }
        Ok(Keyframe {
            index: step,
            positions_in_world: self.organs.iter().map(|o| o.positions.clone()).collect(),
            stats: KeyframeStats {
                index: step,
                energy,
                iterations,
                relative_gradient: gradient,
                seconds: started.elapsed().as_secs_f64(),
                pushed_particles: pushed as u32,
                contact_particles: self.particles_in_contact(&pressed, contacts_now, &mut geometry),
            },
        })
    }

    /// Per organ, which particles the organs lean on a neighbour with: a
    /// contact of `contacts` (those held while they settled) is violated,
    /// so its force holds them off.
    fn pressed(&self, contacts: &[Vec<Contact>]) -> Vec<Vec<bool>> {
        self.organs
            .iter()
            .zip(contacts)
            .map(|(o, c)| {
                let mut held = vec![false; o.positions.len()];
                for contact in c {
                    let p = contact.particle as usize;
                    held[p] |= contact.violation(o.positions[p]) > 0.0;
                }
                held
            })
            .collect()
    }

    /// How many particles touch a neighbouring organ: `pressed` (held off
    /// it by a contact force while the organs settled), or their contact
    /// is violated or short of it by less than the collision offset now (a
    /// particle with several neighbours counts once). `contacts` are those
    /// of the organs where they are, when known.
    fn particles_in_contact(
        &self,
        pressed: &[Vec<bool>],
        contacts: Option<Vec<Vec<Contact>>>,
        geometry: &mut [Option<Geometry>],
    ) -> u32 {
        let offset = self.settings.collision_offset;
        contacts
            .unwrap_or_else(|| self.contacts(&self.search(geometry), Violated::MoveAll, false))
            .iter()
            .zip(&self.organs)
            .enumerate()
            .map(|(i, (contacts, organ))| {
                let mut touching = pressed
                    .get(i)
                    .cloned()
                    .unwrap_or_else(|| vec![false; organ.positions.len()]);
                for c in contacts {
                    let p = c.particle as usize;
                    touching[p] |= c.violation(organ.positions[p]) > -offset;
                }
                touching.iter().filter(|&&t| t).count() as u32
            })
            .sum()
    }

    /// Every overlap side's contacts and every organ's against the parts,
    /// from the current positions (`geometry`: what is known of the organs
    /// there, completed here), each to be put all the way
    /// ([`Violated::MoveAll`]; [`Simulation::contacts`] gives each organ's
    /// list, moved half way where both organs give way).
    fn search(&self, geometry: &mut [Option<Geometry>]) -> Found {
        let mut parts = vec![Vec::new(); self.organs.len()];
        self.obstacle_contacts(&mut parts, &vec![true; self.organs.len()]);
        self.drop_base_contacts(&mut parts);
        let mut sides = vec![Vec::new(); 2 * self.overlaps.len()];
        geometry
            .par_iter_mut()
            .zip(&self.organs)
            .for_each(|(known, organ)| {
                known.get_or_insert_with(|| Geometry::of(organ));
            });
        let geometry: Vec<&Geometry> = geometry.iter().flatten().collect();
        let selves = self.self_contacts(&geometry);
        let free = self
            .free
            .par_iter()
            .map(|&(moving, other)| self.free_contacts_of(moving, other, geometry[other]))
            .collect();
        if self.overlaps.is_empty() {
            return Found {
                parts,
                sides,
                selves,
                free,
            };
        }
        // A kinematic organ (two-state) gets no contacts.
        let keys: Vec<(usize, usize, usize, f64)> = self
            .sides()
            .filter(|&(_, moving, _, _)| !self.organs[moving].is_kinematic())
            .collect();
        // Each side's contacts on its own thread.
        let found: Vec<Vec<Contact>> = keys
            .par_iter()
            .map(|&(_, moving, other, side)| {
                self.contacts_between(moving, other, side, geometry[other])
            })
            .collect();
        for (&(key, ..), list) in keys.iter().zip(found) {
            sides[key] = list;
        }
        Found {
            parts,
            sides,
            selves,
            free,
        }
    }

    /// Organ `moving`'s contacts against organ `other` (a free pair;
    /// `known`: the other's geometry where it is), each keeping the side it
    /// was on when the last keyframe ended, to be put all the way.
    fn free_contacts_of(&self, moving: usize, other: usize, known: &Geometry) -> Vec<Contact> {
        let (m, o) = (&self.organs[moving], &self.organs[other]);
        let mut list = Vec::new();
        let (Some(previous_moving), Some(previous_other)) = (
            m.previous(),
            o.previous()
                .or_else(|| o.is_kinematic().then_some(o.positions.as_slice())),
        ) else {
            return list;
        };
        let previous_normals = anthesis_mesh::vertex_normals(previous_other, &o.mesh.triangles);
        let then = Surface {
            positions: previous_other,
            ..o.surface(&previous_normals)
        };
        kept_side_contacts(
            &m.surface(&[]),
            &o.surface(&known.normals),
            &known.tracker,
            previous_moving,
            &then,
            &m.is_base,
            self.settings.collision_offset,
            Violated::MoveAll,
            &mut list,
        );
        list
    }

    /// How many of each organ's contacts of `found` are against the parts
    /// and its neighbours: [`Simulation::contacts`] appends the
    /// self-contacts after them.
    fn neighbour_contacts(&self, found: &Found) -> Vec<usize> {
        let mut counts: Vec<usize> = found.parts.iter().map(Vec::len).collect();
        for (key, moving, _, _) in self.sides() {
            counts[moving] += found.sides[key].len();
        }
        for (&(moving, _), list) in self.free.iter().zip(&found.free) {
            counts[moving] += list.len();
        }
        counts
    }

    /// Whether any organ can touch itself (a growing organ: a kinematic
    /// one gets no contacts).
    fn self_contact(&self) -> bool {
        self.organs.iter().any(|o| !o.is_kinematic())
    }

    /// Each organ's self-contacts where it is (`geometry`: each organ's),
    /// each to be put all the way, base particles left out (see
    /// `collide::self_contacts`).
    fn self_contacts(&self, geometry: &[&Geometry]) -> Vec<Vec<Contact>> {
        (0..self.organs.len())
            .into_par_iter()
            .map(|i| self.self_contacts_of(i, geometry[i]))
            .collect()
    }

    /// Organ `i`'s self-contacts where it is (`known`: its geometry).
    fn self_contacts_of(&self, i: usize, known: &Geometry) -> Vec<Contact> {
        let organ = &self.organs[i];
        let mut list = Vec::new();
        let Some(previous) = organ.previous().filter(|_| !organ.is_kinematic()) else {
            return list;
        };
        let locality = organ.locality();
        let cells = known.tracker.cell_bounds(locality.uv);
        let previous_normals = anthesis_mesh::vertex_normals(previous, &organ.mesh.triangles);
        let then = Surface {
            positions: previous,
            ..organ.surface(&previous_normals)
        };
        self_contacts(
            &organ.surface(&known.normals),
            &known.tracker,
            &cells,
            &locality,
            &then,
            &organ.is_base,
            self.settings.collision_offset,
            Violated::MoveAll,
            &mut list,
        );
        list
    }

    /// Each organ's contacts of `found`: against the parts, then each side
    /// in order, then (with `selves`) against itself. With
    /// [`Violated::MoveHalf`] a violated contact against an organ that
    /// gives way moves half way (a kinematic organ, two-state, never gives
    /// way, so the organ against it moves all the way, as against a part);
    /// so does a self-contact (the other side of the fold is held off this
    /// one too). The statistics count contacts without `selves` (particles
    /// touching a neighbour).
    fn contacts(&self, found: &Found, violated: Violated, selves: bool) -> Vec<Vec<Contact>> {
        let mut contacts = found.parts.clone();
        for (key, moving, other, _) in self.sides() {
            let half = violated == Violated::MoveHalf && !self.organs[other].is_kinematic();
            let positions = &self.organs[moving].positions;
            contacts[moving].extend(found.sides[key].iter().map(|&c| {
                if half {
                    move_half(c, positions[c.particle as usize])
                } else {
                    c
                }
            }));
        }
        for (&(moving, other), list) in self.free.iter().zip(&found.free) {
            let half = violated == Violated::MoveHalf && !self.organs[other].is_kinematic();
            let positions = &self.organs[moving].positions;
            contacts[moving].extend(list.iter().map(|&c| {
                if half {
                    move_half(c, positions[c.particle as usize])
                } else {
                    c
                }
            }));
        }
        if selves {
            for ((list, own), organ) in contacts.iter_mut().zip(&found.selves).zip(&self.organs) {
                list.extend(own.iter().map(|&c| match violated {
                    Violated::MoveHalf => move_half(c, organ.positions[c.particle as usize]),
                    Violated::MoveAll => c,
                }));
            }
        }
        contacts
    }

    /// Base particles sit on the receptacle, where organs meet by design;
    /// attachment, not collision, decides where they go.
    fn drop_base_contacts(&self, contacts: &mut [Vec<Contact>]) {
        for (organ, list) in self.organs.iter().zip(contacts) {
            list.retain(|c| !organ.is_base[c.particle as usize]);
        }
    }

    /// Contacts keeping the particles of every organ `wanted` outside the
    /// parts, each to be put all the way out (a part does not move aside).
    fn obstacle_contacts(&self, contacts: &mut [Vec<Contact>], wanted: &[bool]) {
        let offset = self.settings.collision_offset;
        let obstacles = &self.obstacles;
        if obstacles.is_empty() {
            return;
        }
        self.organs
            .par_iter()
            .zip(contacts)
            .zip(wanted)
            .for_each(|((organ, list), &wanted)| {
                if organ.is_kinematic() || !wanted {
                    return;
                }
                for obstacle in obstacles {
                    let near = organ
                        .positions
                        .iter()
                        .copied()
                        .enumerate()
                        .filter(|&(_, p)| obstacle.reaches(p));
                    contacts_of(
                        near,
                        &organ.surface(&[]),
                        &obstacle.surface(),
                        obstacle.tracker(),
                        1.0,
                        offset,
                        Violated::MoveAll,
                        list,
                    );
                }
            });
    }

    /// The paper's push-back: nobody ends on the wrong side. Organs are
    /// pushed one overlap side at a time, each against where the other is
    /// now (pushed both at once, two particles on the wrong side of each
    /// other would swap places and stay wrong). Returns how many particles
    /// moved, and, unless the passes ran out, every organ's contacts where
    /// it now is (as `Violated::MoveAll` finds them: its last searches are
    /// those). `geometry` is what is known of the organs where they are, and
    /// is kept up to date; `found` is the search made where they are, which
    /// a side (or an organ against the parts) pushes with until one of its
    /// organs is pushed.
    fn push_back(
        &mut self,
        geometry: &mut [Option<Geometry>],
        found: Found,
    ) -> (usize, Option<Vec<Vec<Contact>>>) {
        let mut moved: Vec<Vec<bool>> = self
            .organs
            .iter()
            .map(|o| vec![false; o.positions.len()])
            .collect();
        // How often each organ has been pushed. A search that pushed
        // nothing finds the same again until one of its organs is pushed,
        // so it is not made again before (against the parts: per organ; of
        // an overlap side: per side).
        let mut pushes = vec![0u32; self.organs.len()];
        let mut parts_clear: Vec<Option<u32>> = vec![None; self.organs.len()];
        let mut side_clear: Vec<Option<(u32, u32)>> = vec![None; 2 * self.overlaps.len()];
        // The last search against the parts, per organ, and per side; at
        // first those of `found`, made before anything was pushed.
        let Found {
            parts: mut parts_found,
            sides: mut side_found,
            selves: mut self_found,
            free: mut free_found,
        } = found;
        let mut free_clear: Vec<Option<(u32, u32)>> = vec![None; self.free.len()];
        let mut self_clear: Vec<Option<u32>> = vec![None; self.organs.len()];
        let mut parts_given = vec![true; self.organs.len()];
        // Where each side's moving organ was when its last list was found,
        // and how often the other organ had been pushed then.
        let sides: Vec<(usize, usize, usize, f64)> = self.sides().collect();
        let mut side_at: Vec<(Vec<DVec3>, u32)> = sides
            .iter()
            .map(|&(_, moving, _, _)| (self.organs[moving].positions.clone(), 0))
            .collect();
        let mut settled = false;
        // A pushed particle turns its neighbours' normals a little, which
        // can leave a particle of the other organ just short of its side:
        // pass again while that happens.
        for _ in 0..PUSH_BACK_PASSES {
            let mut pushed_in_pass = 0;
            let mut outside = vec![Vec::new(); self.organs.len()];
            let wanted: Vec<bool> = parts_clear
                .iter()
                .zip(&pushes)
                .map(|(clear, &n)| *clear != Some(n))
                .collect();
            // Nothing has been pushed before the first pass's parts.
            let search: Vec<bool> = (0..wanted.len())
                .map(|i| wanted[i] && !parts_given[i])
                .collect();
            self.obstacle_contacts(&mut outside, &search);
            self.drop_base_contacts(&mut outside);
            for (i, (organ, searched)) in self.organs.iter_mut().zip(outside).enumerate() {
                if !wanted[i] {
                    continue;
                }
                let list = if parts_given[i] {
                    parts_given[i] = false;
                    std::mem::take(&mut parts_found[i])
                } else {
                    searched
                };
                let pushed = push_back(&mut organ.positions, &list, &mut moved[i]);
                if pushed > 0 {
                    pushes[i] += 1;
                    geometry[i] = None;
                } else {
                    parts_clear[i] = Some(pushes[i]);
                }
                parts_found[i] = list;
                pushed_in_pass += pushed;
            }
            for &(key, moving, other, side) in &sides {
                if self.organs[moving].is_kinematic()
                    || side_clear[key] == Some((pushes[moving], pushes[other]))
                {
                    continue;
                }
                // While the other organ stays where it was, only the
                // moving organ's particles that moved since its last
                // list can find other contacts.
                let (before, other_pushes) = &side_at[key];
                let list = std::mem::take(&mut side_found[key]);
                let contacts = if *other_pushes == pushes[other] {
                    let changed = self.changed_since(moving, before);
                    if changed.is_empty() {
                        list
                    } else {
                        let known = geometry[other]
                            .get_or_insert_with(|| Geometry::of(&self.organs[other]));
                        self.update_contacts(moving, other, side, known, list, &changed)
                    }
                } else {
                    let known =
                        geometry[other].get_or_insert_with(|| Geometry::of(&self.organs[other]));
                    self.contacts_between(moving, other, side, known)
                };
                side_at[key] = (self.organs[moving].positions.clone(), pushes[other]);
                let pushed = push_back(
                    &mut self.organs[moving].positions,
                    &contacts,
                    &mut moved[moving],
                );
                if pushed > 0 {
                    pushes[moving] += 1;
                    geometry[moving] = None;
                } else {
                    side_clear[key] = Some((pushes[moving], pushes[other]));
                }
                side_found[key] = contacts;
                pushed_in_pass += pushed;
            }
            // Each free pair: the search made before the push-back while
            // neither organ was pushed, else where they are.
            for (key, &(moving, other)) in self.free.iter().enumerate() {
                if free_clear[key] == Some((pushes[moving], pushes[other])) {
                    continue;
                }
                let given = std::mem::take(&mut free_found[key]);
                let list = if pushes[moving] == 0 && pushes[other] == 0 && free_clear[key].is_none()
                {
                    given
                } else {
                    let known =
                        geometry[other].get_or_insert_with(|| Geometry::of(&self.organs[other]));
                    self.free_contacts_of(moving, other, known)
                };
                let pushed = push_back(
                    &mut self.organs[moving].positions,
                    &list,
                    &mut moved[moving],
                );
                if pushed > 0 {
                    pushes[moving] += 1;
                    geometry[moving] = None;
                } else {
                    free_clear[key] = Some((pushes[moving], pushes[other]));
                }
                free_found[key] = list;
                pushed_in_pass += pushed;
            }
            // Each organ against itself: the search made before the
            // push-back while nothing has pushed it, else where it is.
            for i in 0..self.organs.len() {
                if self.organs[i].is_kinematic() || self_clear[i] == Some(pushes[i]) {
                    continue;
                }
                let given = std::mem::take(&mut self_found[i]);
                let list = if pushes[i] == 0 && self_clear[i].is_none() {
                    given
                } else {
                    let known = geometry[i].get_or_insert_with(|| Geometry::of(&self.organs[i]));
                    self.self_contacts_of(i, known)
                };
                let pushed = push_back(&mut self.organs[i].positions, &list, &mut moved[i]);
                if pushed > 0 {
                    pushes[i] += 1;
                    geometry[i] = None;
                } else {
                    self_clear[i] = Some(pushes[i]);
                }
                pushed_in_pass += pushed;
            }
            if pushed_in_pass == 0 {
                settled = true;
                break;
            }
        }
        let pushed = moved.iter().flatten().filter(|&&m| m).count();
        // Every search of the last pass, or the earlier one it skipped,
        // was made where the organs are now, and found nothing to push.
        let found = settled.then(|| {
            let mut contacts = parts_found;
            for (key, moving, _, _) in self.sides() {
                contacts[moving].extend_from_slice(&side_found[key]);
            }
            for (&(moving, _), list) in self.free.iter().zip(&free_found) {
                contacts[moving].extend_from_slice(list);
            }
            contacts
        });
        (pushed, found)
    }

    /// Contacts of organ `moving` against organ `other` (`known`: its
    /// normals and tracker where it is) from the current positions, each
    /// moving particle to be put all the way on its side (`side` as in
    /// [`contacts_against`]).
    fn contacts_between(
        &self,
        moving: usize,
        other: usize,
        side: f64,
        known: &Geometry,
    ) -> Vec<Contact> {
        let (m, o) = (&self.organs[moving], &self.organs[other]);
        let other_surface = o.surface(&known.normals);
        let moving_surface = m.surface(&[]);
        let mut contacts = Vec::new();
        contacts_against(
            &moving_surface,
            &other_surface,
            &known.tracker,
            side,
            self.settings.collision_offset,
            Violated::MoveAll,
            &mut contacts,
        );
        contacts.retain(|c| !m.is_base[c.particle as usize]);
        contacts
    }

    /// Which particles of organ `moving` are no longer where `before`
    /// has them (bit for bit).
    fn changed_since(&self, moving: usize, before: &[DVec3]) -> Vec<usize> {
        let now = &self.organs[moving].positions;
        (0..now.len())
            .filter(|&p| !same_position_bits(now[p], before[p]))
            .collect()
    }

    /// `list`, the contacts of organ `moving` against organ `other` found
    /// where `other` is now, brought to where `moving`'s particles are now:
    /// the particles `changed` (ascending) and those sharing an edge with
    /// one are searched again, the others' contacts kept. The same as
    /// [`Simulation::contacts_between`] (each particle's contact depends
    /// only on where it, the particles it shares an edge with and the other
    /// organ are), in the same order (by particle, at most one each).
    fn update_contacts(
        &self,
        moving: usize,
        other: usize,
        side: f64,
        known: &Geometry,
        list: Vec<Contact>,
        changed: &[usize],
    ) -> Vec<Contact> {
        let (m, o) = (&self.organs[moving], &self.organs[other]);
        let own = m.surface(&[]);
        let mut is_changed = vec![false; m.positions.len()];
        for &p in changed {
            for &t in own.rings.around(p as u32) {
                for k in own.triangles[t as usize] {
                    is_changed[k as usize] = true;
                }
            }
        }
        let mut fresh = Vec::new();
        contacts_of(
            (0..m.positions.len())
                .filter(|&p| is_changed[p])
                .map(|p| (p, m.positions[p])),
            &own,
            &o.surface(&known.normals),
            &known.tracker,
            side,
            self.settings.collision_offset,
            Violated::MoveAll,
            &mut fresh,
        );
        fresh.retain(|c| !m.is_base[c.particle as usize]);
        let mut merged = Vec::with_capacity(list.len() + fresh.len());
        let mut fresh = fresh.into_iter().peekable();
        for c in list {
            while let Some(f) = fresh.next_if(|f| f.particle < c.particle) {
                merged.push(f);
            }
            if !is_changed[c.particle as usize] {
                merged.push(c);
            }
        }
        merged.extend(fresh);
        merged
    }

    fn worst_organ(&mut self, contacts: &[Vec<Contact>]) -> (usize, f64) {
        let mut worst = (0, -1.0);
        for (i, (organ, c)) in self.organs.iter_mut().zip(contacts).enumerate() {
            let g = organ.relative_gradient(c);
            if g > worst.1 {
                worst = (i, g);
            }
        }
        worst
    }

    /// Every overlap side in order: its key in [`Found::sides`], the organ
    /// whose particles it holds, the other organ, and which side of the
    /// other they stay on (+1 its inner side). Inner particles stay on the
    /// outer organ's inner side (key `2 * overlap`), outer particles on the
    /// inner organ's outer side (`2 * overlap + 1`).
    fn sides(&self) -> impl Iterator<Item = (usize, usize, usize, f64)> + '_ {
        self.overlaps
            .iter()
            .enumerate()
            .flat_map(|(index, &(inner, outer))| {
                [
                    (2 * index, inner, outer, 1.0),
                    (2 * index + 1, outer, inner, -1.0),
                ]
            })
    }

    /// The organs, in the flower's order, and "the parts" that held
    /// `organ` off them in the search `found` (the names a stopped run
    /// gives, see [`held_against_note`]).
    fn held_against(&self, found: &Found, organ: usize) -> Vec<String> {
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

/// A contact search where the organs are (see `Simulation::search`): each
/// organ's contacts against the parts and each overlap side's (`2 * overlap`
/// for the inner organ's particles, `2 * overlap + 1` for the outer's), each
/// to be put all the way, base particles left out.
struct Found {
    parts: Vec<Vec<Contact>>,
    sides: Vec<Vec<Contact>>,
    /// Each organ's contacts against itself.
    selves: Vec<Vec<Contact>>,
    /// Each free pair's contacts (`Simulation::free`, same order).
    free: Vec<Vec<Contact>>,
}

/// One organ's unit normals and nearest-particle lookup where it is:
/// every collision search needs them, and an organ that has not moved
/// since keeps them.
struct Geometry {
    normals: Vec<DVec3>,
    tracker: Tracker,
}

impl Geometry {
    fn of(organ: &OrganSim) -> Geometry {
        Geometry {
            normals: anthesis_mesh::vertex_normals(&organ.positions, &organ.mesh.triangles),
            tracker: Tracker::new(&organ.positions, 2.0 * organ.mean_edge),
        }
    }
}

/// Every (moving, other) pair of organs with no overlap rule between them
/// (either way), the moving one growing (a kinematic organ gets no
/// contacts): issue 35's organs of one whorl, which keep the side of each
/// other they were on.
fn free_pairs(organs: &[OrganSim], overlaps: &[(usize, usize)]) -> Vec<(usize, usize)> {
    let ruled = |a: usize, b: usize| {
        overlaps
            .iter()
            .any(|&(i, o)| (i, o) == (a, b) || (i, o) == (b, a))
    };
    let mut pairs = Vec::new();
    for a in 0..organs.len() {
        for b in 0..organs.len() {
            if a != b && !ruled(a, b) && !organs[a].is_kinematic() {
                pairs.push((a, b));
            }
        }
    }
    pairs
}

/// Nothing known yet of `organs` organs' geometry.
fn unknown_geometry(organs: usize) -> Vec<Option<Geometry>> {
    (0..organs).map(|_| None).collect()
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

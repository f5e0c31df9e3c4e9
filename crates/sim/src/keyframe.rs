//! What a run gives: which organs, and per keyframe their positions and
//! statistics.

use glam::DVec3;

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

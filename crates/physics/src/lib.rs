//! The physics of one organ, after Ijiri et al. 2008: regional growth (§4)
//! sets rest lengths and rest dihedral angles; energy minimisation (§5)
//! finds the shape that honours them; shape matching (§5.3) attaches the
//! organ to the receptacle.

#![warn(missing_docs)]

pub mod elastic;
pub mod growth;
pub mod hinge;
pub mod membrane;
pub mod model;
pub mod pattern;
pub mod shape_match;
pub mod solver;
#[cfg(test)]
mod test_rng;

pub use elastic::{Contact, Elastic};
pub use growth::{BendBase, BendRule, GrowthModel, GrowthRates, LengthBase, RegionalGrowth};
pub use model::Model;

pub use solver::{NewtonSolver, SolverError, SolverSettings, StepReport};

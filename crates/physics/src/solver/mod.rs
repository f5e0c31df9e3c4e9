//! Newton's method with a backtracking line search and a sparse Cholesky
//! factorisation whose symbolic analysis (fill-reducing ordering, elimination
//! tree) is done once per mesh and reused for every factorisation. The
//! Hessian is handed to the factorisation already in that order (see
//! [`Ordered`]), so no factorisation permutes it again.
//!
//! The factor is kept in single precision: it factorises in about 60 % of
//! the time of a double-precision one and takes half the memory. Each
//! Newton direction is then solved by conjugate gradients on the
//! double-precision matrix that was factorised, preconditioned with the
//! factor, until its residual lies far below the convergence tolerance
//! (one to three iterations), so Newton goes as with the exact solve.
//!
//! The paper takes implicit-Euler steps `(I/h + H) dx = -grad E` with CG; a
//! Newton step is the limit `h -> infinity`, regularised just enough to be
//! positive definite (the energy does not see rigid motions, so `H` alone is
//! singular). With the line search every accepted step lowers the energy.
//!
//! One Newton iteration ([`NewtonSolver::step`]) goes through these
//! phases, one file each:
//! 1. `newton`: evaluate the energy and gradient (or take those the last
//!    line search kept) and test for convergence;
//! 2. `factor`: assemble the Hessian with the violated contacts' penalties
//!    and factorise it, when the keyframe's factor no longer serves;
//! 3. `cg`: the Newton direction, by conjugate gradients preconditioned with
//!    the factor (in `ordered`'s fill-reducing order);
//! 4. `line_search`: the first fraction from the contacts the step would
//!    cross, then backtracking until the energy falls enough.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};
use glam::DVec3;

use crate::elastic::{Contact, Elastic};
use crate::pattern::BlockPattern;

mod cg;
mod factor;
mod line_search;
mod newton;
mod ordered;

use factor::apply_inverse;
use line_search::first_fraction;
use ordered::Ordered;

/// When a keyframe counts as solved, and how hard to try.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverSettings {
    /// Converged when the largest force on any particle, `max_i |dE/dx_i|`,
    /// is below this fraction of [`Elastic::force_scale`] (the force of a
    /// typical edge at 100 % strain). The default `1e-5` means residual
    /// forces worth a strain of one in a hundred thousand. A keyframe also
    /// needs the Newton step its remaining forces ask for to move no
    /// particle more than 1e-4 of the organ's size; together they leave the
    /// shapes about as close to a run at `1e-8` as a run at `1e-6` (README,
    /// "Accuracy").
    pub relative_tolerance: f64,
    /// Newton iterations allowed per keyframe before the run fails.
    pub max_iterations: u32,
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings {
            relative_tolerance: 1e-5,
            max_iterations: 50,
        }
    }
}

/// What one call of [`NewtonSolver::step`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepReport {
    /// Energy at entry.
    pub energy_before: f64,
    /// Energy after the step (equal to `energy_before` when converged).
    pub energy_after: f64,
    /// `max_i |dE/dx_i| / force_scale` at entry.
    pub relative_gradient: f64,
    /// The entry state already met the tolerance; no step was taken.
    pub converged: bool,
    /// Fraction of the Newton step that was accepted.
    pub step_fraction: f64,
}

/// Why a solve stopped without an answer; the simulation reports it for the
/// organ and keyframe where it happened and keeps the keyframes before.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum SolverError {
    /// A position or the energy became NaN or infinite (growth or
    /// stiffness values far too large for the mesh).
    #[error("a particle position or the energy became NaN or infinite")]
    NonFinite,
    /// The Hessian stayed not positive definite after twelve rounds of
    /// growing diagonal regularisation.
    #[error("the Hessian could not be factorised even with regularisation {regularisation:.3e}")]
    Factorisation {
        /// The last regularisation tried, added to the Hessian's diagonal.
        regularisation: f64,
    },
    /// The Newton direction does not point downhill, or no fraction of the
    /// step lowers the energy (even with a fresh factorisation), before the
    /// tolerance was met.
    #[error(
        "no step along the Newton direction lowers the energy (relative gradient {relative_gradient:.3e})"
    )]
    NoDescent {
        /// `max_i |dE/dx_i| / force_scale` where the search stopped (see
        /// [`StepReport::relative_gradient`]).
        relative_gradient: f64,
    },
    /// The symbolic analysis of the sparsity pattern failed (faer's
    /// message); a bug or an out-of-memory rather than bad input.
    #[error("sparse analysis failed: {0}")]
    Analysis(String),
}

/// Solver state for one mesh: pattern, ordering, symbolic factorisation and buffers,
/// all reused across iterations and keyframes; the numeric factor is reused
/// only within a keyframe (see [`NewtonSolver::begin_keyframe`]).
pub struct NewtonSolver {
    pattern: BlockPattern,
    ordered: Ordered,
    /// Analysis of the matrix in `ordered`'s order (no permutation of its
    /// own).
    symbolic: SymbolicCholesky<usize>,
    hessian: Vec<f64>,
    /// `hessian`'s values as `ordered` lays them out.
    ordered_hessian: Vec<f64>,
    /// `ordered_hessian` in single precision, as factorised.
    single_hessian: Vec<f32>,
    /// A right-hand side in `ordered`'s order, in single precision.
    single_rhs: Vec<f32>,
    /// The Cholesky factor of `single_hessian`.
    factor: Vec<f32>,
    memory: MemBuffer,
    cg: Cg,
    direction: Vec<f64>,
    gradient: Vec<DVec3>,
    trial: Vec<DVec3>,
    factor_valid: bool,
    /// The elastic energy evaluated at the positions kept in `trial`, and
    /// what else is kept from that evaluation, for the step that starts
    /// there: by [`NewtonSolver::evaluate_start`] at a keyframe's start, or
    /// by the line search at the trial it accepted.
    start: Option<(f64, Kept)>,
    /// Whether the last keyframe's first step started where
    /// [`NewtonSolver::evaluate_start`] evaluated.
    started_there: bool,
    /// Whether `hessian` holds the elastic part of the Hessian at the
    /// positions of this step (assembled with its gradient).
    hessian_here: bool,
    /// The elastic energy (without contacts and anchors) at the positions
    /// where the last step found the keyframe converged, kept in
    /// `converged`; `None` after a step that did not converge.
    converged_elastic_energy: Option<f64>,
    converged: Vec<DVec3>,
    /// The contacts whose penalty the factorised Hessian holds (those that
    /// were violated where it was assembled), in `contacts` order.
    held: Vec<Contact>,
    last_step_cut: bool,
    previous_gradient: Option<f64>,
    factorisations: u64,
}

/// What an evaluation kept for the next step holds besides the elastic
/// energy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kept {
    /// Nothing: a keyframe's start evaluated for its energy alone.
    Energy,
    /// A keyframe's start with its elastic gradient in `gradient` and the
    /// Hessian's elastic part in `hessian`.
    GradientAndHessian,
    /// The trial the line search accepted, with its elastic gradient in
    /// `gradient` (the gradient the next step would compute there).
    Gradient,
}

/// A predicted energy decrease below this fraction of the energy is lost in
/// rounding (the energy sums thousands of terms).
const STATIONARY: f64 = 1e-13;

/// Refactorise when an iteration reduced the relative gradient by less than
/// this factor.
const REFACTOR_RATIO: f64 = 0.1;

/// A direction is refined until the residual force it leaves on every
/// particle is at most this fraction of the convergence tolerance: far
/// enough below it that the inexact solve costs no Newton iteration.
/// Measured against 0.01 (issue-11-cg notes): a twentieth of the tolerance
/// keeps every Newton iteration and factorisation count (4k petal 158 and
/// 105, 4k whole lily 1104 -> 1105 and 741, the bending-strip tests 90, 120
/// and 90) for 18 % fewer conjugate-gradient iterations (4k petal 424 ->
/// 349, 4k whole lily 2981 -> 2486), each a triangular solve pair and a
/// mat-vec (~2 ms at 4k particles). Looser targets, a constant (0.07 to
/// 0.5) or one relative to the gradient (Eisenstat-Walker `eta |g|`,
/// `eta` 1e-4 to 1e-2, or `gamma |g|^2`), saved up to twice that on the
/// lily but added an iteration to a strip test, whose keyframes sit at
/// exactly their budget of three.
const CG_TOLERANCE: f64 = 0.05;

/// A keyframe converges only when, besides meeting the force tolerance, the
/// Newton step its remaining forces still ask for moves no particle more
/// than this fraction of the organ's size ([`Elastic::size`]). Small forces
/// alone leave a soft mode far from its equilibrium: a petal sliding along
/// the neighbours that press it in a tight bud. At the tolerance 1e-5
/// without this condition Pinocchio's whole flower ended 3.2e-3 of a petal
/// from a run at 1e-8 (1e-6: 1.8e-4), with it 1.8e-4. It is about 5e-3 of
/// an edge at the default resolution; 5e-5 cost the 4k whole lily 5 % more
/// factorisations (725 against 691), 1e-2 of an edge sent Pinocchio's tight
/// bud to another shape (notes of issue 11, 2026-11-27).
const REMAINING_STEP: f64 = 1e-4;

/// Conjugate-gradient iterations allowed per direction; with the factor of
/// the same matrix one to three suffice on the lily, up to about ten in
/// the bending-strip tests.
const MAX_CG: usize = 20;

/// Buffers of the conjugate-gradient refinement, in `Ordered`'s order.
struct Cg {
    solution: Vec<f64>,
    residual: Vec<f64>,
    preconditioned: Vec<f64>,
    search: Vec<f64>,
    product: Vec<f64>,
}

impl std::fmt::Debug for NewtonSolver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NewtonSolver")
            .field("dimension", &self.pattern.dimension())
            .field("hessian_nonzeros", &self.pattern.nonzeros())
            .field("factor_nonzeros", &self.factor.len())
            .finish()
    }
}

impl NewtonSolver {
    /// Analyses the sparsity of `elastic` over `particles` particles.
    pub fn new(particles: usize, elastic: &Elastic) -> Result<NewtonSolver, SolverError> {
        let pattern = elastic.pattern(particles);
        let n = pattern.dimension();
        let analyse = |structure, ordering| {
            factorize_symbolic_cholesky(
                structure,
                Side::Upper,
                ordering,
                // Particles couple in dense 3x3 blocks, so the factor is made
                // of small dense column groups: the supernodal kernels
                // measured several times faster here than the simplicial
                // ones faer picks by default for a matrix this size.
                CholeskySymbolicParams {
                    supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                    ..Default::default()
                },
            )
            .map_err(|e| SolverError::Analysis(format!("{e:?}")))
        };
        // faer's approximate minimum degree ordering, computed once; the
        // factorisations then see the matrix in that order.
        let amd = analyse(
            SymbolicSparseColMatRef::new_checked(n, n, pattern.col_ptr(), None, pattern.row_idx()),
            SymmetricOrdering::Amd,
        )?;
        let order = match amd.perm() {
            Some(perm) => perm.arrays().0.to_vec(),
            None => (0..n).collect(),
        };
        let ordered = Ordered::new(&pattern, order);
        let (upper_col_ptr, upper_row_idx) = ordered.upper_structure();
        let symbolic = analyse(
            SymbolicSparseColMatRef::new_checked(n, n, &upper_col_ptr, None, &upper_row_idx),
            SymmetricOrdering::Identity,
        )?;
        let scratch = symbolic
            .factorize_numeric_llt_scratch::<f32>(Par::Seq, Default::default())
            .or(symbolic.solve_in_place_scratch::<f32>(1, Par::Seq));
        Ok(NewtonSolver {
            ordered_hessian: vec![0.0; pattern.nonzeros()],
            single_hessian: vec![0.0; pattern.nonzeros()],
            single_rhs: vec![0.0; n],
            cg: Cg {
                solution: vec![0.0; n],
                residual: vec![0.0; n],
                preconditioned: vec![0.0; n],
                search: vec![0.0; n],
                product: vec![0.0; n],
            },
            ordered,
            hessian: vec![0.0; pattern.nonzeros()],
            factor: vec![0.0; symbolic.len_val()],
            memory: MemBuffer::new(scratch),
            direction: vec![0.0; n],
            gradient: vec![DVec3::ZERO; particles],
            trial: vec![DVec3::ZERO; particles],
            factor_valid: false,
            start: None,
            started_there: true,
            hessian_here: false,
            converged_elastic_energy: None,
            converged: vec![DVec3::ZERO; particles],
            held: Vec::new(),
            last_step_cut: false,
            previous_gradient: None,
            factorisations: 0,
            symbolic,
            pattern,
        })
    }

    /// Call when a new keyframe starts (the rest state changed): the
    /// convergence history and the factor of the last keyframe no longer
    /// apply. A factor kept across keyframes saved factorisations on paper,
    /// but its stale directions made Newton converge linearly: measured on
    /// the default lily (`anthesis simulate`, 100 keyframes), one petal took
    /// 267 iterations and 116 factorisations with it and 115 and 103
    /// without; the whole flower 446 and 1098 against 255 and 929. As the
    /// preconditioner of conjugate gradients on the current Hessian it did
    /// not pay either: a factor one keyframe old already needs about seven
    /// iterations (each a triangular solve and a mat-vec, a sixth of a
    /// factorisation at 4k particles) to reach the tolerance (4k petal:
    /// 67 factorisations and 606 iterations, 5.8 s CPU, against 105
    /// factorisations, 4.9 s). With nothing kept, a keyframe's work depends
    /// only on the organ's state at its start, so a run can resume from any
    /// keyframe bit for bit.
    pub fn begin_keyframe(&mut self) {
        self.start = None;
        self.converged_elastic_energy = None;
        self.previous_gradient = None;
        self.factor_valid = false;
        self.last_step_cut = false;
    }

    /// The elastic energy (without contacts and anchors) at `positions`,
    /// if the last [`NewtonSolver::step`] found the keyframe converged at
    /// exactly these positions (same bits) and evaluated it there.
    pub fn converged_elastic_energy(&self, positions: &[DVec3]) -> Option<f64> {
        self.converged_elastic_energy
            .filter(|_| same_bits(&self.converged, positions))
    }

    /// How many numeric factorisations this solver has done.
    pub fn factorisations(&self) -> u64 {
        self.factorisations
    }

    /// The relative gradient `max_i |dE/dx_i| / force_scale` at `positions`.
    pub fn relative_gradient(
        &mut self,
        elastic: &Elastic,
        contacts: &[Contact],
        positions: &[DVec3],
    ) -> f64 {
        self.start = None;
        elastic.gradient(positions, contacts, &mut self.gradient);
        max_norm(&self.gradient) / elastic.force_scale()
    }

    /// The elastic energy at `positions` without contacts and anchors
    /// ([`Elastic::elastic_energy`]), for a keyframe's start. Its gradient
    /// is kept with it: the next [`NewtonSolver::step`], if it starts at
    /// exactly these positions (same bits) with `elastic` unchanged but
    /// for its anchors, only adds the penalties instead of evaluating
    /// energy and gradient again. Where the contacts move the start
    /// (`start_on_contacts` in the simulation) the step must evaluate
    /// anyway; the gradient is computed here only if the last keyframe's
    /// first step did start here, so such a run of keyframes pays for it
    /// once. Either way the energy has the same bits. With the gradient,
    /// the elastic part of the Hessian is assembled in the same pass (the
    /// first step of a keyframe factorises: the solver keeps no factor
    /// across keyframes).
    pub fn evaluate_start(&mut self, elastic: &Elastic, positions: &[DVec3]) -> f64 {
        let energy = if self.started_there {
            elastic.elastic_energy_gradient_and_hessian(
                positions,
                &mut self.gradient,
                &self.pattern,
                &mut self.hessian,
            )
        } else {
            elastic.elastic_energy(positions)
        };
        self.trial.copy_from_slice(positions);
        let kept = if self.started_there {
            Kept::GradientAndHessian
        } else {
            Kept::Energy
        };
        self.start = Some((energy, kept));
        energy
    }
}

/// Whether `a` and `b` hold the same positions, bit for bit (a value
/// computed at `a` may then be reused at `b`).
pub fn same_bits(a: &[DVec3], b: &[DVec3]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(p, q)| same_position_bits(*p, *q))
}

/// Whether `p` and `q` are the same position, bit for bit.
pub fn same_position_bits(p: DVec3, q: DVec3) -> bool {
    p.to_array().map(f64::to_bits) == q.to_array().map(f64::to_bits)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn max_norm(g: &[DVec3]) -> f64 {
    g.iter().map(|v| v.length()).fold(0.0, f64::max)
}

#[cfg(test)]
mod tests;

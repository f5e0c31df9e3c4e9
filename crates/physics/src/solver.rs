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

    /// One Newton iteration from `positions`: if the gradient already meets
    /// the tolerance nothing moves; otherwise solves `(H + mu I) dx = -g` and
    /// takes the largest fraction of `dx` (1, 1/2, 1/4, …) that lowers the
    /// energy enough (Armijo). The line search evaluates each trial's
    /// elastic gradient with its energy and keeps the accepted one's: the
    /// next step, if it starts there (same bits; the rest state changes
    /// only between keyframes), only adds its contacts and anchors,
    /// so the check that usually ends a keyframe evaluates nothing. On the
    /// lily no trial was rejected at tolerance 1e-5, so no gradient is
    /// evaluated for nothing.
    pub fn step(
        &mut self,
        elastic: &Elastic,
        contacts: &[Contact],
        positions: &mut [DVec3],
        settings: &SolverSettings,
    ) -> Result<StepReport, SolverError> {
        let start = self.start.take();
        let here = start.is_some() && same_bits(&self.trial, positions);
        if matches!(start, Some((_, Kept::Energy | Kept::GradientAndHessian))) {
            self.started_there = here;
        }
        self.hessian_here = here && matches!(start, Some((_, Kept::GradientAndHessian)));
        self.converged_elastic_energy = None;
        // `energy_and_gradient` in its two parts, the elastic one kept.
        let elastic_energy = match start {
            Some((energy, Kept::GradientAndHessian | Kept::Gradient)) if here => energy,
            // This step factorises (unless the keyframe has converged
            // already): the Hessian's elastic part in the same pass.
            _ if !self.factor_valid => {
                self.hessian_here = true;
                elastic.elastic_energy_gradient_and_hessian(
                    positions,
                    &mut self.gradient,
                    &self.pattern,
                    &mut self.hessian,
                )
            }
            _ => elastic.elastic_energy_and_gradient(positions, &mut self.gradient),
        };
        let energy_before =
            elastic.add_penalties(positions, contacts, elastic_energy, &mut self.gradient);
        if !energy_before.is_finite() {
            return Err(SolverError::NonFinite);
        }
        let relative_gradient = max_norm(&self.gradient) / elastic.force_scale();
        if !relative_gradient.is_finite() {
            return Err(SolverError::NonFinite);
        }
        if relative_gradient <= settings.relative_tolerance && self.remaining_step_small(elastic) {
            self.converged_elastic_energy = Some(elastic_energy);
            self.converged.copy_from_slice(positions);
            return Ok(StepReport {
                energy_before,
                energy_after: energy_before,
                relative_gradient,
                converged: true,
                step_fraction: 0.0,
            });
        }
        // Modified Newton: keep the keyframe's last factorisation while it
        // works. The Hessian changes little between iterations, so an old
        // factor still gives a good descent direction; refactorise when there
        // is none (a new keyframe), when the
        // last step was cut by the line search, when the gradient fell by
        // less than REFACTOR_RATIO since the previous iteration, or when
        // the contacts violated now are not those the factor holds. A
        // contact's penalty is a thousand times stiffer than an edge, so a
        // factor that holds a contact the last step left (or misses one it
        // entered) all but pins that particle (or lets it run through):
        // on the default lily every such step (40 in the late-key stroke's
        // rerun) left the gradient where it was, and the next iteration
        // refactorised anyway.
        let slow = self
            .previous_gradient
            .is_some_and(|previous| relative_gradient > REFACTOR_RATIO * previous);
        if !self.factor_valid || slow || self.last_step_cut || !self.holds(contacts, positions) {
            self.factorize(elastic, contacts, positions)?;
        }
        self.previous_gradient = Some(relative_gradient);
        // A scalar residual of at most t / sqrt(3) keeps a particle's at t.
        let target =
            CG_TOLERANCE * settings.relative_tolerance * elastic.force_scale() / 3f64.sqrt();
        self.solve(target)?;

        let slope: f64 = self
            .gradient
            .iter()
            .enumerate()
            .map(|(i, g)| g.dot(DVec3::from_slice(&self.direction[3 * i..3 * i + 3])))
            .sum();
        if slope >= 0.0 {
            return Err(SolverError::NoDescent { relative_gradient });
        }
        if -slope <= STATIONARY * energy_before.abs() {
            // The best possible decrease is below what the energy can
            // resolve in floating point: this is a minimum to machine
            // precision, even if the gradient is above the tolerance.
            self.converged_elastic_energy = Some(elastic_energy);
            self.converged.copy_from_slice(positions);
            return Ok(StepReport {
                energy_before,
                energy_after: energy_before,
                relative_gradient,
                converged: true,
                step_fraction: 0.0,
            });
        }
        const ARMIJO: f64 = 1e-4;
        let mut fraction = first_fraction(
            elastic.contact_stiffness,
            contacts,
            positions,
            &self.direction,
            slope,
        );
        for _ in 0..40 {
            for (i, (t, x)) in self.trial.iter_mut().zip(positions.iter()).enumerate() {
                *t = *x + DVec3::from_slice(&self.direction[3 * i..3 * i + 3]) * fraction;
            }
            // `Elastic::energy` in its two parts, with the elastic gradient
            // the next step takes if this trial is accepted (`gradient` is
            // not needed any more in this step).
            let trial_elastic =
                elastic.elastic_energy_and_gradient(&self.trial, &mut self.gradient);
            let energy = if trial_elastic == f64::INFINITY {
                trial_elastic
            } else {
                elastic.add_penalty_energy(&self.trial, contacts, trial_elastic)
            };
            if energy.is_finite() && energy <= energy_before + ARMIJO * fraction * slope {
                self.last_step_cut = fraction < 1.0;
                positions.copy_from_slice(&self.trial);
                self.start = Some((trial_elastic, Kept::Gradient));
                return Ok(StepReport {
                    energy_before,
                    energy_after: energy,
                    relative_gradient,
                    converged: false,
                    step_fraction: fraction,
                });
            }
            fraction *= 0.5;
        }
        if self.factor_valid && !self.last_step_cut {
            // An old factor may point badly; try once more with a fresh one.
            self.last_step_cut = true;
            return self.step(elastic, contacts, positions, settings);
        }
        Err(SolverError::NoDescent { relative_gradient })
    }

    /// Whether the Newton step the gradient in `self.gradient` still asks
    /// for, estimated with this keyframe's factor (one solve, no conjugate
    /// gradients), moves no particle more than [`REMAINING_STEP`] of the
    /// organ's size. Without a factor (a keyframe whose start already met
    /// the force tolerance) there is nothing to estimate with.
    fn remaining_step_small(&mut self, elastic: &Elastic) -> bool {
        if !self.factor_valid {
            return true;
        }
        let limit = REMAINING_STEP * elastic.size();
        self.ordered.negated(&self.gradient, &mut self.cg.residual);
        apply_inverse(
            &self.symbolic,
            &self.factor,
            &mut self.memory,
            &mut self.single_rhs,
            &self.cg.residual,
            &mut self.cg.preconditioned,
        );
        self.ordered
            .scatter(&self.cg.preconditioned, &mut self.direction);
        self.direction
            .chunks_exact(3)
            .all(|d| d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= limit * limit)
    }

    /// Fills `self.direction` with the regularised Newton direction for the
    /// gradient in `self.gradient`.
    /// Assembles the Hessian at `positions` and factorises it (regularised
    /// just enough to be positive definite).
    fn factorize(
        &mut self,
        elastic: &Elastic,
        contacts: &[Contact],
        positions: &[DVec3],
    ) -> Result<(), SolverError> {
        self.factor_valid = false;
        self.held.clear();
        self.held.extend(violated(contacts, positions));
        if std::mem::take(&mut self.hessian_here) {
            elastic.add_penalty_hessian(positions, &self.held, &self.pattern, &mut self.hessian);
        } else {
            elastic.hessian(positions, &self.held, &self.pattern, &mut self.hessian);
        }
        let n = self.pattern.dimension();
        let mean_diagonal = self.pattern.diagonal(&self.hessian).sum::<f64>() / n as f64;
        if !mean_diagonal.is_finite() {
            return Err(SolverError::NonFinite);
        }
        // Just enough to remove the rigid-motion null space. The factor,
        // only a preconditioner of that system, gets ten times more while
        // single precision finds the matrix not positive definite (the
        // rigid motions are barely held at `mu`; the strip tests needed
        // 10 `mu` about every other factorisation).
        let mu = 1e-8 * mean_diagonal.max(f64::MIN_POSITIVE);
        self.pattern.add_to_diagonal(&mut self.hessian, mu);
        self.ordered.gather(
            &self.hessian,
            &mut self.ordered_hessian,
            &mut self.single_hessian,
        );
        let mut extra: f64 = 0.0;
        for _ in 0..12 {
            if extra > 0.0 {
                for (single, &double) in self.single_hessian.iter_mut().zip(&self.ordered_hessian) {
                    *single = double as f32;
                }
                let col_ptr = self.ordered.structure.col_ptr();
                for col in 0..n {
                    // The diagonal entry comes first in each lower column.
                    self.single_hessian[col_ptr[col]] += extra as f32;
                }
            }
            let matrix =
                SparseColMatRef::new(self.ordered.structure.as_ref(), &self.single_hessian[..]);
            let factored = self.symbolic.factorize_numeric_llt(
                &mut self.factor,
                matrix,
                Side::Lower,
                LltRegularization::default(),
                Par::Seq,
                MemStack::new(&mut self.memory),
                Default::default(),
            );
            if factored.is_ok() {
                self.factor_valid = true;
                self.factorisations += 1;
                return Ok(());
            }
            extra = 10.0 * extra.max(mu);
        }
        Err(SolverError::Factorisation {
            regularisation: extra,
        })
    }

    /// Whether the factorised Hessian holds the penalty of exactly the
    /// contacts violated at `positions`.
    fn holds(&self, contacts: &[Contact], positions: &[DVec3]) -> bool {
        violated(contacts, positions).eq(self.held.iter())
    }

    /// Fills `self.direction` with `-K^-1 g` for the factorised matrix `K`
    /// (the regularised Hessian of this or an earlier iteration of the
    /// keyframe): conjugate gradients on `K` in double precision,
    /// preconditioned with its single-precision factor, until no scalar of
    /// the residual exceeds `target`.
    fn solve(&mut self, target: f64) -> Result<(), SolverError> {
        let Cg {
            solution: x,
            residual: r,
            preconditioned: z,
            search: p,
            product: q,
        } = &mut self.cg;
        self.ordered.negated(&self.gradient, r);
        let mut precondition = |r: &[f64], z: &mut [f64]| {
            apply_inverse(
                &self.symbolic,
                &self.factor,
                &mut self.memory,
                &mut self.single_rhs,
                r,
                z,
            )
        };
        x.fill(0.0);
        precondition(r, z);
        p.copy_from_slice(z);
        let mut rz = dot(r, z);
        for iteration in 0..MAX_CG {
            self.ordered.multiply(&self.ordered_hessian, p, q);
            let curvature = dot(p, q);
            if curvature.is_nan() || curvature <= 0.0 {
                // Not positive definite in double precision where the
                // (more regularised) single-precision factor was: keep what
                // CG has, or the factor's own direction.
                if iteration == 0 {
                    x.copy_from_slice(z);
                }
                break;
            }
            let alpha = rz / curvature;
            for i in 0..x.len() {
                x[i] += alpha * p[i];
                r[i] -= alpha * q[i];
            }
            if r.iter().all(|v| v.abs() <= target) {
                break;
            }
            precondition(r, z);
            let rz_next = dot(r, z);
            let beta = rz_next / rz;
            rz = rz_next;
            for i in 0..p.len() {
                p[i] = z[i] + beta * p[i];
            }
        }
        self.ordered.scatter(x, &mut self.direction);
        if self.direction.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(SolverError::NonFinite)
        }
    }
}

/// `z = K^-1 r` for the single-precision factor `factor` of `symbolic`,
/// with `single` as the single-precision right-hand side.
fn apply_inverse(
    symbolic: &SymbolicCholesky<usize>,
    factor: &[f32],
    memory: &mut MemBuffer,
    single: &mut [f32],
    r: &[f64],
    z: &mut [f64],
) {
    for (s, &v) in single.iter_mut().zip(r) {
        *s = v as f32;
    }
    let n = single.len();
    LltRef::new(symbolic, factor).solve_in_place_with_conj(
        Conj::No,
        MatMut::from_column_major_slice_mut(single, n, 1),
        Par::Seq,
        MemStack::new(memory),
    );
    for (v, &s) in z.iter_mut().zip(single.iter()) {
        *v = f64::from(s);
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

/// The Hessian's sparsity in a fill-reducing order, as the lower triangle
/// in compressed columns (the layout faer's supernodal factorisation works
/// in), with where each entry comes from in the [`BlockPattern`]'s values.
/// Handing faer the matrix already ordered saves it permuting (and
/// transposing) the matrix at every factorisation, for one gather: a
/// factorisation of a lily petal's Hessian took 4 % less time at 4k
/// particles and 9 % less at 1k (best of 30); the factor is the same, bit
/// for bit, as when faer permutes.
struct Ordered {
    /// `order[new] = old`: the scalar unknown at each new position.
    order: Vec<usize>,
    /// The lower triangle's structure, checked once here (faer checks a
    /// structure when it is made, which was 0.5 % of a 4k run when every
    /// factorisation made its own).
    structure: SymbolicSparseColMat<usize>,
    /// For each stored entry, its index in the pattern's values.
    source: Vec<usize>,
}

impl Ordered {
    fn new(pattern: &BlockPattern, order: Vec<usize>) -> Ordered {
        let n = pattern.dimension();
        let mut new_of_old = vec![0; n];
        for (new, &old) in order.iter().enumerate() {
            new_of_old[old] = new;
        }
        // (row, source) of each entry, per new column.
        let mut columns: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n];
        for col in 0..n {
            for idx in pattern.col_ptr()[col]..pattern.col_ptr()[col + 1] {
                let (a, b) = (new_of_old[pattern.row_idx()[idx]], new_of_old[col]);
                columns[a.min(b)].push((a.max(b), idx));
            }
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::with_capacity(pattern.nonzeros());
        let mut source = Vec::with_capacity(pattern.nonzeros());
        col_ptr.push(0);
        for column in &mut columns {
            column.sort_unstable();
            for &(row, idx) in column.iter() {
                row_idx.push(row);
                source.push(idx);
            }
            col_ptr.push(row_idx.len());
        }
        // Every particle has its diagonal block, so each lower column
        // starts with its diagonal entry (factorize and multiply use that).
        debug_assert!((0..n).all(|col| row_idx[col_ptr[col]] == col));
        Ordered {
            structure: SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx),
            order,
            source,
        }
    }

    /// The upper triangle's structure (the symbolic analysis reads the
    /// upper triangle).
    fn upper_structure(&self) -> (Vec<usize>, Vec<usize>) {
        let n = self.order.len();
        let (col_ptr, row_idx) = (self.structure.col_ptr(), self.structure.row_idx());
        let mut counts = vec![0; n + 1];
        for &row in row_idx {
            counts[row + 1] += 1;
        }
        for i in 0..n {
            counts[i + 1] += counts[i];
        }
        let upper_col_ptr = counts.clone();
        let mut upper_row_idx = vec![0; row_idx.len()];
        for col in 0..n {
            for &row in &row_idx[col_ptr[col]..col_ptr[col + 1]] {
                upper_row_idx[counts[row]] = col;
                counts[row] += 1;
            }
        }
        (upper_col_ptr, upper_row_idx)
    }

    /// `y = A x` for the symmetric matrix whose lower triangle, in this
    /// layout, is `values`.
    fn multiply(&self, values: &[f64], x: &[f64], y: &mut [f64]) {
        let (col_ptr, row_idx) = (self.structure.col_ptr(), self.structure.row_idx());
        y.fill(0.0);
        for (col, &x_col) in x.iter().enumerate() {
            // The diagonal entry comes first in each lower column.
            let (diagonal, below) = (col_ptr[col], col_ptr[col] + 1..col_ptr[col + 1]);
            y[col] += values[diagonal] * x_col;
            let mut column_sum = 0.0;
            for (&row, &value) in row_idx[below.clone()].iter().zip(&values[below]) {
                y[row] += value * x_col;
                column_sum += value * x[row];
            }
            y[col] += column_sum;
        }
    }

    /// `-gradient` (per particle) as a vector in this order.
    fn negated(&self, gradient: &[DVec3], ordered: &mut [f64]) {
        for (v, &old) in ordered.iter_mut().zip(&self.order) {
            *v = -gradient[old / 3][old % 3];
        }
    }

    /// A vector in this order back in the particles' order (three
    /// components per particle).
    fn scatter(&self, ordered: &[f64], out: &mut [f64]) {
        for (&v, &old) in ordered.iter().zip(&self.order) {
            out[old] = v;
        }
    }

    /// Lays the pattern's `values` out in this order, in `ordered` and in
    /// single precision in `single`.
    fn gather(&self, values: &[f64], ordered: &mut [f64], single: &mut [f32]) {
        for ((v, s), &idx) in ordered.iter_mut().zip(single).zip(&self.source) {
            *v = values[idx];
            *s = *v as f32;
        }
    }
}

/// The fraction of the Newton step `direction` the line search tries first:
/// the minimum over `(0, 1]` of the step's quadratic model with the
/// contacts it would cross added. The penalty is one-sided, so the Hessian
/// at `positions` does not see a contact until it is violated; a full step
/// ran particles deep into contacts and halving cut it to a sliver, for
/// several iterations, until a contact was violated (measured on the
/// default lily: keyframes with touching petals took 7 to 11 iterations
/// with step fractions of 0.01 to 0.03). Along the step the model is
/// `slope t + ½ (−slope) t²` (for `d = −K⁻¹g`, `dᵀKd = −slope`) plus, for
/// each contact not violated now, `½ k max(0, v + t w)²`; it is convex,
/// so its minimum is where its derivative crosses zero (found by
/// bisection; `k` is the contact stiffness). The energy still decides: the line search checks this
/// fraction and halves from it.
fn first_fraction(
    k: f64,
    contacts: &[Contact],
    positions: &[DVec3],
    direction: &[f64],
    slope: f64,
) -> f64 {
    // (violation now, its rate along the step) of contacts the full step
    // would cross.
    let crossed: Vec<(f64, f64)> = contacts
        .iter()
        .filter_map(|c| {
            let p = c.particle as usize;
            let step = DVec3::from_slice(&direction[3 * p..3 * p + 3]);
            let now = c.violation(positions[p]);
            let rate = -c.normal.dot(step);
            (now <= 0.0 && now + rate > 0.0).then_some((now, rate))
        })
        .collect();
    let derivative = |t: f64| {
        slope * (1.0 - t)
            + crossed
                .iter()
                .map(|&(v, w)| k * (v + t * w).max(0.0) * w)
                .sum::<f64>()
    };
    if crossed.is_empty() || derivative(1.0) <= 0.0 {
        return 1.0;
    }
    let (mut low, mut high) = (0.0, 1.0);
    for _ in 0..50 {
        let mid = 0.5 * (low + high);
        if derivative(mid) <= 0.0 {
            low = mid;
        } else {
            high = mid;
        }
    }
    high
}

/// The contacts of `contacts` violated at `positions` (those whose penalty
/// acts, and so is in the Hessian), in order.
fn violated<'a>(
    contacts: &'a [Contact],
    positions: &'a [DVec3],
) -> impl Iterator<Item = &'a Contact> {
    contacts
        .iter()
        .filter(|c| c.violation(positions[c.particle as usize]) > 0.0)
}

fn max_norm(g: &[DVec3]) -> f64 {
    g.iter().map(|v| v.length()).fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use anthesis_mesh::Topology;
    use anthesis_mesh::generate::test_petal;

    /// A test petal's particles and its elastic model at rest there.
    fn petal_at_rest() -> (Vec<DVec3>, Elastic) {
        let mesh = test_petal(30.0, 12.0, 9, 17);
        let topology = Topology::build(&mesh).expect("manifold");
        let elastic = Elastic::at_rest(&mesh.positions, &topology);
        (mesh.positions, elastic)
    }

    /// A petal's Hessian away from rest (springs and hinges both bent),
    /// factorised, and a gradient.
    fn factorised_petal() -> (NewtonSolver, Elastic) {
        let (positions, elastic) = petal_at_rest();
        let moved: Vec<DVec3> = positions
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let t = i as f64;
                *p + DVec3::new((1.3 * t).sin(), (0.7 * t).cos(), (2.1 * t).sin()) * 0.3
            })
            .collect();
        let mut solver = NewtonSolver::new(moved.len(), &elastic).expect("analysis");
        solver
            .factorize(&elastic, &[], &moved)
            .expect("positive definite");
        for (i, g) in solver.gradient.iter_mut().enumerate() {
            let t = i as f64;
            *g = DVec3::new(t.sin(), (3.0 * t).cos(), 1.0 - 0.01 * t);
        }
        (solver, elastic)
    }

    #[test]
    fn the_matrix_handed_over_in_order_factorises_as_when_faer_orders_it() {
        let (solver, _) = factorised_petal();
        // faer permuting the same (single-precision) matrix into its AMD
        // order itself.
        let pattern = &solver.pattern;
        let n = pattern.dimension();
        let structure =
            SymbolicSparseColMatRef::new_checked(n, n, pattern.col_ptr(), None, pattern.row_idx());
        let symbolic = factorize_symbolic_cholesky(
            structure,
            Side::Upper,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            },
        )
        .expect("analysis");
        assert_eq!(symbolic.len_val(), solver.factor.len(), "the same fill");
        let mut memory = MemBuffer::new(
            symbolic.factorize_numeric_llt_scratch::<f32>(Par::Seq, Default::default()),
        );
        let values: Vec<f32> = solver.hessian.iter().map(|&v| v as f32).collect();
        let mut factor = vec![0.0f32; symbolic.len_val()];
        symbolic
            .factorize_numeric_llt(
                &mut factor,
                SparseColMatRef::new(structure, &values[..]),
                Side::Upper,
                LltRegularization::default(),
                Par::Seq,
                MemStack::new(&mut memory),
                Default::default(),
            )
            .expect("positive definite");
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&solver.factor), bits(&factor));
    }

    #[test]
    fn a_fresh_direction_solves_the_newton_system_to_the_target() {
        let (mut solver, _) = factorised_petal();
        let n = solver.pattern.dimension();
        let residual = |solver: &NewtonSolver| -> f64 {
            let mut product = vec![0.0; n];
            solver
                .pattern
                .multiply(&solver.hessian, &solver.direction, &mut product);
            (0..n)
                .map(|i| (product[i] + solver.gradient[i / 3][i % 3]).abs())
                .fold(0.0, f64::max)
        };
        // One iteration (the single-precision factor's own direction,
        // scaled) leaves a residual far above a millionth of the gradient ...
        solver.solve(f64::INFINITY).expect("finite");
        let unrefined = residual(&solver);
        let target = 1e-6;
        assert!(unrefined > 10.0 * target, "{unrefined:e}");
        // ... which refinement brings below it, (H + mu I) d = -g.
        solver.solve(target).expect("finite");
        let refined = residual(&solver);
        assert!(refined <= target, "{refined:e} (unrefined {unrefined:e})");
    }

    /// A contact holding particle 0 above the plane y = 0 (offset 0).
    fn floor() -> Contact {
        Contact {
            particle: 0,
            point: DVec3::ZERO,
            normal: DVec3::Y,
            offset: 0.0,
        }
    }

    #[test]
    fn the_factor_holds_the_contacts_violated_where_it_was_made() {
        let (mut positions, mut elastic) = petal_at_rest();
        elastic.contact_stiffness = 1000.0;
        // A plane through particle 0 with particle 0 a hair on its wrong
        // side, and one through particle 1 with particle 1 on its side.
        let plane = |p: u32, offset: f64| Contact {
            particle: p,
            point: positions[p as usize],
            normal: DVec3::Z,
            offset,
        };
        let contacts = [plane(0, 1e-3), plane(1, -1e-3)];
        let mut solver = NewtonSolver::new(positions.len(), &elastic).expect("analysis");
        solver
            .factorize(&elastic, &contacts, &positions)
            .expect("positive definite");
        assert_eq!(solver.held, vec![contacts[0]], "the violated one only");
        assert!(solver.holds(&contacts, &positions));
        // Each particle moving within its side keeps the factor ...
        positions[0].z -= 1e-4;
        positions[1].z += 1e-4;
        assert!(solver.holds(&contacts, &positions));
        // ... particle 0 leaving its contact makes it stale ...
        positions[0].z += 2e-3;
        assert!(!solver.holds(&contacts, &positions));
        // ... and so does particle 1 entering its own.
        positions[0].z -= 2e-3;
        positions[1].z -= 3e-3;
        assert!(!solver.holds(&contacts, &positions));
    }

    #[test]
    fn a_keyframe_converges_only_once_the_remaining_step_is_small() {
        // A petal at rest held by weak anchors (a thousandth of an edge's
        // stiffness) at targets half an edge along x: moving the whole
        // petal costs only the anchors, a soft mode. Off its targets by
        // d, every particle feels a force of 1e-3 F d / edge, below the
        // force tolerance (1e-5 F) for any d under a hundredth of an edge,
        // while the step back is d for every particle.
        let (bud, mut elastic) = petal_at_rest();
        let force = elastic.force_scale();
        let edge = elastic.rest_lengths.iter().sum::<f64>() / elastic.rest_lengths.len() as f64;
        elastic.anchor_stiffness = 1e-3 * force / edge;
        let targets: Vec<DVec3> = bud.iter().map(|p| *p + DVec3::X * 0.5 * edge).collect();
        elastic.anchors = targets
            .iter()
            .enumerate()
            .map(|(i, t)| (i as u32, *t))
            .collect();
        let settings = SolverSettings::default();
        let mut solver = NewtonSolver::new(bud.len(), &elastic).expect("analysis");
        solver.begin_keyframe();
        let mut positions = bud.clone();
        let first = solver
            .step(&elastic, &[], &mut positions, &settings)
            .expect("a step");
        assert!(!first.converged, "half an edge off its targets it moves");
        // 0.6 % of an edge short of the targets: within the force
        // tolerance, more than REMAINING_STEP of the petal's size from them.
        let short = 6e-3 * edge;
        assert!(short > 1.5 * REMAINING_STEP * elastic.size());
        for (p, t) in positions.iter_mut().zip(&targets) {
            *p = *t - DVec3::X * short;
        }
        let off = solver
            .step(&elastic, &[], &mut positions, &settings)
            .expect("a step");
        assert!(
            off.relative_gradient < settings.relative_tolerance,
            "{}: the forces alone would call this converged",
            off.relative_gradient
        );
        assert!(!off.converged, "0.6 % of an edge off its targets");
        let last = solver
            .step(&elastic, &[], &mut positions, &settings)
            .expect("a step");
        assert!(last.converged);
        let left = positions
            .iter()
            .zip(&targets)
            .map(|(p, t)| p.distance(*t))
            .fold(0.0, f64::max);
        assert!(
            left <= REMAINING_STEP * elastic.size(),
            "{left} from the targets, {short} before the last step"
        );
    }

    #[test]
    fn a_step_refactorises_when_the_last_one_left_a_contact() {
        // A petal held at rest by weak springs on every particle (anchors),
        // one of them pulled a tenth of an edge away, and its tip particle a hair
        // inside a contact that a twentieth of that pull draws it off.
        // The first step (fresh factor, contact held) brings the largest
        // force down twentyfold but barely moves the tip, which leaves the
        // contact: modified Newton would keep that factor (the gradient
        // fell more than tenfold), whose stiff penalty pins the tip, for a
        // step that leaves its force as it is.
        let (bud, mut elastic) = petal_at_rest();
        elastic.contact_stiffness = 1000.0;
        elastic.anchor_stiffness = 1.0;
        let by_y = |a: &usize, b: &usize| bud[*a].y.total_cmp(&bud[*b].y);
        let tip = (0..bud.len()).max_by(by_y).expect("particles");
        let base = (0..bud.len()).min_by(by_y).expect("particles");
        let mut positions = bud.clone();
        for (i, p) in positions.iter().enumerate() {
            let pull = match i {
                _ if i == tip => DVec3::Z * 0.01,
                _ if i == base => DVec3::X * 0.2,
                _ => DVec3::ZERO,
            };
            elastic.anchors.push((i as u32, *p + pull));
        }
        let contacts = [Contact {
            particle: tip as u32,
            point: positions[tip],
            normal: DVec3::Z,
            offset: 1e-6,
        }];
        assert!(contacts[0].violation(positions[tip]) > 0.0);
        let settings = SolverSettings::default();
        let mut solver = NewtonSolver::new(positions.len(), &elastic).expect("analysis");
        solver.begin_keyframe();
        let first = solver
            .step(&elastic, &contacts, &mut positions, &settings)
            .expect("a step");
        assert!(contacts[0].violation(positions[tip]) < 0.0, "the tip left");
        let second = solver
            .step(&elastic, &contacts, &mut positions, &settings)
            .expect("a step");
        assert!(
            second.relative_gradient < 0.1 * first.relative_gradient,
            "{} after {}: a fall that keeps an unchanged factor",
            second.relative_gradient,
            first.relative_gradient
        );
        assert_eq!(solver.factorisations(), 2, "a fresh factor without it");
        let third = solver
            .step(&elastic, &contacts, &mut positions, &settings)
            .expect("a step");
        assert!(
            third.relative_gradient < 0.1 * second.relative_gradient,
            "{} after {}: the tip moved",
            third.relative_gradient,
            second.relative_gradient
        );
    }

    #[test]
    fn a_step_from_an_evaluated_start_is_the_step_that_evaluates_it() {
        // A bent petal with its base anchored and a contact violated: steps
        // from a start evaluated by `evaluate_start` (the elastic energy,
        // gradient and Hessian kept, the penalties added by the step and
        // its factorisation) give the bits of plain steps, also
        // when the positions moved in between (the start is not used) and
        // in the keyframe after that (no gradient kept). So do the steps
        // after the first, which start at the trial the line search
        // accepted with its gradient kept, also when the contacts change
        // in between (the penalties are added by the step) or the
        // positions move (the gradient is evaluated afresh). The plain
        // solver forgets every kept evaluation before each step.
        let (bud, mut elastic) = petal_at_rest();
        elastic.contact_stiffness = 1000.0;
        elastic.anchor_stiffness = 100.0;
        elastic.anchors = (0..9).map(|i| (i, bud[i as usize])).collect();
        let bent: Vec<DVec3> = bud
            .iter()
            .map(|p| *p + DVec3::Z * (0.002 * p.y * p.y))
            .collect();
        let tip = bent.len() - 1;
        let contacts = [Contact {
            particle: tip as u32,
            point: bent[tip] + DVec3::Z * 0.01,
            normal: DVec3::Z,
            offset: 0.0,
        }];
        let settings = SolverSettings::default();
        let bits = |x: &[DVec3]| {
            x.iter()
                .map(|p| p.to_array().map(f64::to_bits))
                .collect::<Vec<_>>()
        };
        let mut plain = NewtonSolver::new(bud.len(), &elastic).expect("analysis");
        let mut started = NewtonSolver::new(bud.len(), &elastic).expect("analysis");
        // Keyframes starting where the start was evaluated, one starting
        // elsewhere, then two more (the first without a kept gradient).
        let mut from_trials = 0;
        for (keyframe, moved) in [(0, false), (1, false), (2, true), (3, false), (4, false)] {
            let mut start = bent.clone();
            start[tip].z -= 0.001 * keyframe as f64;
            let (mut x, mut y) = (start.clone(), start.clone());
            plain.begin_keyframe();
            started.begin_keyframe();
            let energy = started.evaluate_start(&elastic, &y);
            assert_eq!(energy.to_bits(), elastic.elastic_energy(&y).to_bits());
            let kept = started.start.map(|(_, kept)| kept);
            let expected = if keyframe == 3 {
                Kept::Energy
            } else {
                Kept::GradientAndHessian
            };
            assert_eq!(kept, Some(expected), "keyframe {keyframe}: gradient kept");
            if moved {
                x[3].x += 1e-3;
                y[3].x += 1e-3;
            }
            for i in 0..4 {
                // The contact released in the second step.
                let contacts = if i == 1 { &contacts[..0] } else { &contacts };
                if keyframe == 4 && i == 2 {
                    x[5].y += 1e-4;
                    y[5].y += 1e-4;
                }
                if i > 0 && matches!(started.start, Some((_, Kept::Gradient))) {
                    from_trials += 1;
                }
                plain.start = None;
                let a = plain.step(&elastic, contacts, &mut x, &settings);
                let b = started.step(&elastic, contacts, &mut y, &settings);
                assert_eq!(a, b, "keyframe {keyframe} step {i}");
                assert_eq!(bits(&x), bits(&y), "keyframe {keyframe} step {i}");
            }
            assert_eq!(started.started_there, !moved, "keyframe {keyframe}");
            assert_eq!(started.factorisations(), plain.factorisations());
        }
        assert!(
            from_trials >= 5,
            "{from_trials} steps from an accepted trial"
        );
    }

    #[test]
    fn the_first_fraction_is_the_minimum_of_the_model_with_the_crossed_contact() {
        // The particle at height a moves by -b along y (b > a): the full
        // step crosses the floor by b - a. Model derivative:
        // slope (1 - t) + k (t b - a) b = 0  =>  t = (-slope + k a b) / (k b² - slope).
        let (a, b, k, slope) = (0.2, 1.0, 50.0, -3.0);
        let positions = [DVec3::new(0.0, a, 0.0)];
        let direction = [0.0, -b, 0.0];
        let t = first_fraction(k, &[floor()], &positions, &direction, slope);
        let expected = (-slope + k * a * b) / (k * b * b - slope);
        assert!((t - expected).abs() < 1e-12, "{t} against {expected}");
        assert!(
            t > a / b && t < 1.0,
            "just past the floor, short of the full step"
        );
    }

    #[test]
    fn a_step_that_crosses_no_contact_or_a_violated_one_starts_whole() {
        let k = 50.0;
        // Stays above the floor.
        let t = first_fraction(k, &[floor()], &[DVec3::Y], &[0.0, -0.5, 0.0], -1.0);
        assert_eq!(t, 1.0);
        // Already below it: the Hessian holds that contact already.
        let t = first_fraction(k, &[floor()], &[-DVec3::Y], &[0.0, -0.5, 0.0], -1.0);
        assert_eq!(t, 1.0);
        // No contacts.
        assert_eq!(
            first_fraction(k, &[], &[DVec3::Y], &[0.0, -5.0, 0.0], -1.0),
            1.0
        );
    }
}

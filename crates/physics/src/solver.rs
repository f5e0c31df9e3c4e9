//! Newton's method with a backtracking line search and a sparse Cholesky
//! factorisation whose symbolic analysis (fill-reducing ordering, elimination
//! tree) is done once per mesh and reused for every factorisation. The
//! Hessian is handed to the factorisation already in that order (see
//! [`Ordered`]), so no factorisation permutes it again.
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
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};
use glam::DVec3;

use crate::elastic::{Contact, Elastic};
use crate::pattern::BlockPattern;

/// When a keyframe counts as solved, and how hard to try.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverSettings {
    /// Converged when the largest force on any particle, `max_i |dE/dx_i|`,
    /// is below this fraction of [`Elastic::force_scale`] (the force of a
    /// typical edge at 100 % strain). `1e-6` means residual forces worth a
    /// strain of one in a million.
    pub relative_tolerance: f64,
    /// Newton iterations allowed per keyframe before the run fails.
    pub max_iterations: u32,
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings {
            relative_tolerance: 1e-6,
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
    /// A right-hand side in `ordered`'s order.
    ordered_rhs: Vec<f64>,
    factor: Vec<f64>,
    memory: MemBuffer,
    direction: Vec<f64>,
    gradient: Vec<DVec3>,
    trial: Vec<DVec3>,
    factor_valid: bool,
    last_step_cut: bool,
    previous_gradient: Option<f64>,
    factorisations: u64,
}

/// A predicted energy decrease below this fraction of the energy is lost in
/// rounding (the energy sums thousands of terms).
const STATIONARY: f64 = 1e-13;

/// Refactorise when an iteration reduced the relative gradient by less than
/// this factor.
const REFACTOR_RATIO: f64 = 0.1;

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
            .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
            .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        Ok(NewtonSolver {
            ordered_hessian: vec![0.0; pattern.nonzeros()],
            ordered_rhs: vec![0.0; n],
            ordered,
            hessian: vec![0.0; pattern.nonzeros()],
            factor: vec![0.0; symbolic.len_val()],
            memory: MemBuffer::new(scratch),
            direction: vec![0.0; n],
            gradient: vec![DVec3::ZERO; particles],
            trial: vec![DVec3::ZERO; particles],
            factor_valid: false,
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
    /// without; the whole flower 446 and 1098 against 255 and 929. With
    /// nothing kept, a keyframe's work depends only on the organ's state at
    /// its start, so a run can resume from any keyframe bit for bit.
    pub fn begin_keyframe(&mut self) {
        self.previous_gradient = None;
        self.factor_valid = false;
        self.last_step_cut = false;
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
        elastic.gradient(positions, contacts, &mut self.gradient);
        max_norm(&self.gradient) / elastic.force_scale()
    }

    /// One Newton iteration from `positions`: if the gradient already meets
    /// the tolerance nothing moves; otherwise solves `(H + mu I) dx = -g` and
    /// takes the largest fraction of `dx` (1, 1/2, 1/4, …) that lowers the
    /// energy enough (Armijo).
    pub fn step(
        &mut self,
        elastic: &Elastic,
        contacts: &[Contact],
        positions: &mut [DVec3],
        settings: &SolverSettings,
    ) -> Result<StepReport, SolverError> {
        let energy_before = elastic.energy_and_gradient(positions, contacts, &mut self.gradient);
        if !energy_before.is_finite() {
            return Err(SolverError::NonFinite);
        }
        let relative_gradient = max_norm(&self.gradient) / elastic.force_scale();
        if !relative_gradient.is_finite() {
            return Err(SolverError::NonFinite);
        }
        if relative_gradient <= settings.relative_tolerance {
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
        // last step was cut by the line search, or when the gradient fell by
        // less than REFACTOR_RATIO since the previous iteration.
        let slow = self
            .previous_gradient
            .is_some_and(|previous| relative_gradient > REFACTOR_RATIO * previous);
        if !self.factor_valid || slow || self.last_step_cut {
            self.factorize(elastic, contacts, positions)?;
        }
        self.previous_gradient = Some(relative_gradient);
        self.solve_with_factor()?;

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
            let energy = elastic.energy(&self.trial, contacts);
            if energy.is_finite() && energy <= energy_before + ARMIJO * fraction * slope {
                self.last_step_cut = fraction < 1.0;
                positions.copy_from_slice(&self.trial);
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
        elastic.hessian(positions, contacts, &self.pattern, &mut self.hessian);
        let n = self.pattern.dimension();
        let mean_diagonal = self.pattern.diagonal(&self.hessian).sum::<f64>() / n as f64;
        if !mean_diagonal.is_finite() {
            return Err(SolverError::NonFinite);
        }
        // Just enough to remove the rigid-motion null space; raised tenfold
        // while the factorisation finds the matrix not positive definite.
        let mut mu = 1e-8 * mean_diagonal.max(f64::MIN_POSITIVE);
        let mut added = 0.0;
        for _ in 0..12 {
            self.pattern.add_to_diagonal(&mut self.hessian, mu - added);
            added = mu;
            self.ordered
                .gather(&self.hessian, &mut self.ordered_hessian);
            let matrix = SparseColMatRef::new(
                SymbolicSparseColMatRef::new_checked(
                    n,
                    n,
                    &self.ordered.col_ptr,
                    None,
                    &self.ordered.row_idx,
                ),
                &self.ordered_hessian,
            );
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
            mu *= 10.0;
        }
        Err(SolverError::Factorisation { regularisation: mu })
    }

    /// Fills `self.direction` with `-K^-1 g` for the factorised matrix `K`.
    fn solve_with_factor(&mut self) -> Result<(), SolverError> {
        let n = self.pattern.dimension();
        for (x, &old) in self.ordered_rhs.iter_mut().zip(&self.ordered.order) {
            *x = -self.gradient[old / 3][old % 3];
        }
        let llt = LltRef::new(&self.symbolic, &self.factor);
        let rhs = MatMut::from_column_major_slice_mut(&mut self.ordered_rhs, n, 1);
        llt.solve_in_place_with_conj(Conj::No, rhs, Par::Seq, MemStack::new(&mut self.memory));
        for (&x, &old) in self.ordered_rhs.iter().zip(&self.ordered.order) {
            self.direction[old] = x;
        }
        if self.direction.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(SolverError::NonFinite)
        }
    }
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
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
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
        Ordered {
            order,
            col_ptr,
            row_idx,
            source,
        }
    }

    /// The upper triangle's structure (the symbolic analysis reads the
    /// upper triangle).
    fn upper_structure(&self) -> (Vec<usize>, Vec<usize>) {
        let n = self.order.len();
        let mut counts = vec![0; n + 1];
        for &row in &self.row_idx {
            counts[row + 1] += 1;
        }
        for i in 0..n {
            counts[i + 1] += counts[i];
        }
        let col_ptr = counts.clone();
        let mut row_idx = vec![0; self.row_idx.len()];
        for col in 0..n {
            for &row in &self.row_idx[self.col_ptr[col]..self.col_ptr[col + 1]] {
                row_idx[counts[row]] = col;
                counts[row] += 1;
            }
        }
        (col_ptr, row_idx)
    }

    /// Lays the pattern's `values` out in this order.
    fn gather(&self, values: &[f64], ordered: &mut [f64]) {
        for (v, &idx) in ordered.iter_mut().zip(&self.source) {
            *v = values[idx];
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

fn max_norm(g: &[DVec3]) -> f64 {
    g.iter().map(|v| v.length()).fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use anthesis_mesh::Topology;
    use anthesis_mesh::generate::test_petal;

    #[test]
    fn the_matrix_handed_over_in_order_gives_faers_own_solution_bit_for_bit() {
        // A petal's Hessian away from rest (springs and hinges both bent).
        let mesh = test_petal(30.0, 12.0, 9, 17);
        let topology = Topology::build(&mesh).expect("manifold");
        let elastic = Elastic::at_rest(&mesh.positions, &topology);
        let moved: Vec<DVec3> = mesh
            .positions
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
        solver.solve_with_factor().expect("finite");

        // faer permuting the same matrix (the regularised Hessian the
        // solver factorised) into its AMD order itself.
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
            symbolic
                .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
                .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq)),
        );
        let mut factor = vec![0.0; symbolic.len_val()];
        symbolic
            .factorize_numeric_llt(
                &mut factor,
                SparseColMatRef::new(structure, &solver.hessian),
                Side::Upper,
                LltRegularization::default(),
                Par::Seq,
                MemStack::new(&mut memory),
                Default::default(),
            )
            .expect("positive definite");
        let mut x: Vec<f64> = solver
            .gradient
            .iter()
            .flat_map(|g| (-*g).to_array())
            .collect();
        LltRef::new(&symbolic, &factor).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut x, n, 1),
            Par::Seq,
            MemStack::new(&mut memory),
        );
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&solver.direction), bits(&x));
        // And it is the solution, (H + mu I) x = -g, to what the
        // conditioning allows (mu is 1e-8 of the mean diagonal).
        let mut product = vec![0.0; n];
        pattern.multiply(&solver.hessian, &x, &mut product);
        let scale = product.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (i, p) in product.iter().enumerate() {
            let g = solver.gradient[i / 3][i % 3];
            assert!((p + g).abs() <= 1e-6 * scale, "row {i}: {p} against {}", -g);
        }
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

//! The Hessian assembled with the violated contacts' penalties and
//! factorised in single precision, and solves with that factor.

use super::*;

impl NewtonSolver {
    /// Assembles the Hessian at `positions` and factorises it (regularised
    /// just enough to be positive definite).
    pub(super) fn factorize(
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
    pub(super) fn holds(&self, contacts: &[Contact], positions: &[DVec3]) -> bool {
        violated(contacts, positions).eq(self.held.iter())
    }
}

/// `z = K^-1 r` for the single-precision factor `factor` of `symbolic`,
/// with `single` as the single-precision right-hand side.
pub(super) fn apply_inverse(
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

/// The contacts of `contacts` violated at `positions` (those whose penalty
/// acts, and so is in the Hessian), in order.
pub(super) fn violated<'a>(
    contacts: &'a [Contact],
    positions: &'a [DVec3],
) -> impl Iterator<Item = &'a Contact> {
    contacts
        .iter()
        .filter(|c| c.violation(positions[c.particle as usize]) > 0.0)
}

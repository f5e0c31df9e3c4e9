//! The Newton direction by conjugate gradients, preconditioned with the
//! keyframe's factor.

use super::*;

impl NewtonSolver {
    /// Fills `self.direction` with `-K^-1 g` for the factorised matrix `K`
    /// (the regularised Hessian of this or an earlier iteration of the
    /// keyframe): conjugate gradients on `K` in double precision,
    /// preconditioned with its single-precision factor, until no scalar of
    /// the residual exceeds `target`.
    pub(super) fn solve(&mut self, target: f64) -> Result<(), SolverError> {
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

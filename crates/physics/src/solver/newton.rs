//! One Newton iteration: evaluate, test for convergence, factorise if
//! needed, solve for the direction, search along it.

use super::*;

impl NewtonSolver {
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
        let elastic_energy = self.evaluate(elastic, positions);
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
            return Ok(self.converged_at(
                positions,
                elastic_energy,
                energy_before,
                relative_gradient,
            ));
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
            return Ok(self.converged_at(
                positions,
                elastic_energy,
                energy_before,
                relative_gradient,
            ));
        }
        if let Some(report) = self.line_search(
            elastic,
            contacts,
            positions,
            energy_before,
            slope,
            relative_gradient,
        ) {
            return Ok(report);
        }
        if self.factor_valid && !self.last_step_cut {
            // An old factor may point badly; try once more with a fresh one.
            self.last_step_cut = true;
            return self.step(elastic, contacts, positions, settings);
        }
        Err(SolverError::NoDescent { relative_gradient })
    }

    /// The elastic energy at `positions`, with its gradient in
    /// `self.gradient`: taken from the evaluation kept for this step when
    /// it starts where that was made (same bits), else computed (with the
    /// Hessian's elastic part when this step will factorise).
    fn evaluate(&mut self, elastic: &Elastic, positions: &[DVec3]) -> f64 {
        let start = self.start.take();
        let here = start.is_some() && same_bits(&self.trial, positions);
        if matches!(start, Some((_, Kept::Energy | Kept::GradientAndHessian))) {
            self.started_there = here;
        }
        self.hessian_here = here && matches!(start, Some((_, Kept::GradientAndHessian)));
        self.converged_elastic_energy = None;
        // `energy_and_gradient` in its two parts, the elastic one kept.
        match start {
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
        }
    }

    /// Reports the keyframe converged at `positions` (nothing moves), and
    /// keeps the elastic energy there.
    fn converged_at(
        &mut self,
        positions: &[DVec3],
        elastic_energy: f64,
        energy_before: f64,
        relative_gradient: f64,
    ) -> StepReport {
        self.converged_elastic_energy = Some(elastic_energy);
        self.converged.copy_from_slice(positions);
        StepReport {
            energy_before,
            energy_after: energy_before,
            relative_gradient,
            converged: true,
            step_fraction: 0.0,
        }
    }

    /// Backtracking along `self.direction` from the first fraction the
    /// contacts allow (see [`first_fraction`]), halving until the energy
    /// falls enough (Armijo); moves `positions` to the accepted trial and
    /// keeps its elastic gradient for the next step. `None` when no
    /// fraction of 40 halvings lowers the energy.
    fn line_search(
        &mut self,
        elastic: &Elastic,
        contacts: &[Contact],
        positions: &mut [DVec3],
        energy_before: f64,
        slope: f64,
        relative_gradient: f64,
    ) -> Option<StepReport> {
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
                return Some(StepReport {
                    energy_before,
                    energy_after: energy,
                    relative_gradient,
                    converged: false,
                    step_fraction: fraction,
                });
            }
            fraction *= 0.5;
        }
        None
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
}

//! Where along the Newton direction the step lands.

use super::*;

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
pub(super) fn first_fraction(
    k: f64,
    contacts: &[Contact],
    positions: &[DVec3],
    direction: &[f64],
    slope: f64,
) -> f64 {
    // (violation now, its rate along the step, its share of the
    // stiffness) of contacts the full step would cross.
    let crossed: Vec<(f64, f64, f64)> = contacts
        .iter()
        .filter_map(|c| {
            let p = c.particle as usize;
            let step = DVec3::from_slice(&direction[3 * p..3 * p + 3]);
            let now = c.violation(positions[p]);
            let rate = -c.normal.dot(step);
            (now <= 0.0 && now + rate > 0.0).then_some((now, rate, c.weight))
        })
        .collect();
    let derivative = |t: f64| {
        slope * (1.0 - t)
            + crossed
                .iter()
                .map(|&(v, w, share)| (k * share) * (v + t * w).max(0.0) * w)
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

//! Two ready-made bud organs in the organ template frame (base at the
//! origin, growing along +Y, inner side facing −Z, the bud closing towards
//! −Z). Rough shapes, meant to be tuned.
//!
//! Both run `u` along −X, so that `dS/du × dS/dv` already points to the inner
//! side and a painted map looks unmirrored when viewed from the inner side.

use glam::DVec3;

use crate::surface::{BezierCurve, BezierPatch, PdeSweep};

/// A lily (Lilium) petal of a closed bud, about 40 long and 12 wide, as a PDE
/// sweep (Chaudhry et al. §IV, the cubic generator). Narrow base
/// (2 wide), widest a little below the middle, pointed tip bent in towards
/// the flower axis, cupped across. Meshed at edge 1.3 it has on the order of
/// the paper's 388 vertices.
pub fn lily_petal_surface() -> PdeSweep {
    // Profiles along the petal as cubic Bézier control values (base to tip):
    // height, half width, midrib depth (+Z is outwards) and cupping (how far
    // the margins curl inwards, towards −Z, below the midrib).
    let height = [0.0, 15.0, 32.0, 47.0];
    let half_width = [1.0, 10.0, 9.0, 0.0];
    let midrib_z = [0.0, 5.0, 3.0, -3.0];
    let cupping = [0.1, 3.0, 3.0, 0.0];
    pde_petal(height, half_width, midrib_z, cupping)
}

/// An Eustoma (lisianthus) petal of a closed bud, about 38 long, as a
/// bicubic Bézier patch (Qin and Chen 2006 §4): narrow claw at the
/// base, obovate blade widest near two thirds of its length, a broad rounded
/// top (the patch's `v = 1` edge), cupped across and bent in at the top.
/// Meshed at edge 2.0 it has on the order of the paper's 261 vertices.
pub fn eustoma_petal_surface() -> BezierPatch {
    // Per row (base to top): height, half width, midrib depth, cupping.
    let height = [0.0, 12.0, 26.0, 34.0];
    let half_width = [1.2, 7.0, 17.5, 12.5];
    let midrib_z = [0.0, 4.0, 3.0, -3.0];
    let cupping = [0.1, 2.5, 5.0, 3.0];
    // Across each row: x as a fraction of the half width (u runs along −X),
    // cupping profile (the middle two columns at 4/3 give a peak of 1 at
    // u = 0.5) and the extra height that rounds the top edge.
    let across_x = [1.0, 1.0 / 3.0, -1.0 / 3.0, -1.0];
    let across_cup = [0.0, 4.0 / 3.0, 4.0 / 3.0, 0.0];
    let top_round = [0.0, 7.0, 7.0, 0.0];
    let mut control = [[DVec3::ZERO; 4]; 4];
    for (j, row) in control.iter_mut().enumerate() {
        for (i, c) in row.iter_mut().enumerate() {
            let lift = if j == 3 { top_round[i] } else { 0.0 };
            *c = DVec3::new(
                half_width[j] * across_x[i],
                height[j] + lift,
                midrib_z[j] - cupping[j] + cupping[j] * across_cup[i],
            );
        }
    }
    BezierPatch::new(control)
}

/// A symmetric PDE-sweep petal from Bézier control values of its profiles
/// along `v`. The margins are at `x = ±half_width`, `z = midrib_z − cupping`;
/// the across-tangents `(−2·half_width, 0, ±4·cupping)` make the generator
/// (a cubic Hermite curve) a parabola across with the midrib `cupping` above
/// the margins. Because the sweep is linear in its boundary data, the
/// profiles can be combined control point by control point.
pub(crate) fn pde_petal(
    height: [f64; 4],
    half_width: [f64; 4],
    midrib_z: [f64; 4],
    cupping: [f64; 4],
) -> PdeSweep {
    let margin = |side: f64| {
        BezierCurve::new(std::array::from_fn(|k| {
            DVec3::new(side * half_width[k], height[k], midrib_z[k] - cupping[k])
        }))
    };
    let tangent = |rise: f64| {
        BezierCurve::new(std::array::from_fn(|k| {
            DVec3::new(-2.0 * half_width[k], 0.0, rise * 4.0 * cupping[k])
        }))
    };
    PdeSweep::new(margin(1.0), margin(-1.0), tangent(1.0), tangent(-1.0), 0.0)
}

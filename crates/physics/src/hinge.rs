//! The signed dihedral angle of a hinge and its gradient.
//!
//! A hinge `[i, j, k, l]` is an interior edge `i -> j` with `k` opposite in
//! the left triangle `(i, j, k)` and `l` opposite in the right triangle
//! `(j, i, l)`. Both triangles wind counter-clockwise around the normal that
//! points to the inner side. The angle is the rotation from the left normal
//! to the right normal about the edge direction: positive when the surface
//! bends away from its inner side (the inner side is convex, `l` lies on the
//! outer side of the left triangle's plane), zero when flat.

use glam::DVec3;

/// Signed dihedral angle of the hinge at positions `[xi, xj, xk, xl]`,
/// in radians, in `(-pi, pi]`.
#[inline(always)]
pub fn dihedral_angle(x: [DVec3; 4]) -> f64 {
    let [xi, xj, xk, xl] = x;
    let e = xj - xi;
    let n1 = e.cross(xk - xi);
    let n2 = (xi - xj).cross(xl - xj);
    let sin_part = n1.cross(n2).dot(e) / e.length();
    let cos_part = n1.dot(n2);
    sin_part.atan2(cos_part)
}

/// Whether either triangle of the hinge has (nearly) collapsed: its height
/// over the edge is below one millionth of the edge length.
pub fn hinge_is_degenerate(x: [DVec3; 4]) -> bool {
    let [xi, xj, xk, xl] = x;
    let e = xj - xi;
    let limit = 1e-12 * e.length_squared() * e.length_squared();
    e.cross(xk - xi).length_squared() <= limit
        || e.cross(xl - xi).length_squared() <= limit
        || e.length_squared() == 0.0
}

/// Gradient of [`dihedral_angle`] with respect to `[xi, xj, xk, xl]`.
///
/// Moving an opposite vertex towards its triangle's inner side flattens an
/// outward bend: its gradient is `-normal / height`; the edge vertices take the balancing share given by
/// where `k` and `l` project onto the edge, so the gradient is invariant to
/// translation and rotation.
#[inline(always)]
pub fn dihedral_gradient(x: [DVec3; 4]) -> [DVec3; 4] {
    let [xi, xj, xk, xl] = x;
    let e = xj - xi;
    let e_len_sq = e.length_squared();
    let e_len = e_len_sq.sqrt();
    let n1 = e.cross(xk - xi);
    let n2 = (xi - xj).cross(xl - xj);
    let gk = -n1 * (e_len / n1.length_squared());
    let gl = -n2 * (e_len / n2.length_squared());
    let alpha_k = (xk - xi).dot(e) / e_len_sq;
    let alpha_l = (xl - xi).dot(e) / e_len_sq;
    let gi = -(1.0 - alpha_k) * gk - (1.0 - alpha_l) * gl;
    let gj = -alpha_k * gk - alpha_l * gl;
    [gi, gj, gk, gl]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::TestRng;

    fn hinge(angle: f64) -> [DVec3; 4] {
        // Edge along +X, left triangle in the XY plane (normal +Z), right
        // triangle rotated about the edge by `angle` towards -Z.
        let l = DVec3::new(0.4, -angle.cos(), -angle.sin());
        [
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.6, 1.0, 0.0),
            l,
        ]
    }

    #[test]
    fn flat_hinge_is_zero_and_bending_outwards_is_positive() {
        assert!(dihedral_angle(hinge(0.0)).abs() < 1e-15);
        for a in [0.1, 0.7, 1.5, 2.5, -0.3, -2.0] {
            let got = dihedral_angle(hinge(a));
            assert!((got - a).abs() < 1e-12, "angle {a}: got {got}");
        }
    }

    #[test]
    fn gradient_matches_central_differences() {
        let mut rng = TestRng(7);
        let mut rand = || rng.centred();
        for a in [0.0, 0.4, -1.1, 2.0] {
            let mut x = hinge(a);
            for p in &mut x {
                *p += DVec3::new(rand(), rand(), rand()) * 0.2;
            }
            let g = dihedral_gradient(x);
            let h = 1e-6;
            for v in 0..4 {
                for c in 0..3 {
                    let mut xp = x;
                    let mut xm = x;
                    xp[v][c] += h;
                    xm[v][c] -= h;
                    let fd = (dihedral_angle(xp) - dihedral_angle(xm)) / (2.0 * h);
                    assert!(
                        (fd - g[v][c]).abs() < 1e-7,
                        "vertex {v} axis {c}: fd {fd} analytic {}",
                        g[v][c]
                    );
                }
            }
        }
    }
}

//! Parametric organ surfaces: bicubic Bézier patches
//! (Qin and Chen 2006 §4) and PDE sweep surfaces
//! (Chaudhry et al. §IV).
//!
//! Every surface maps the unit square of parameters to the organ template
//! frame. Parameter `u` runs across the organ (the midrib is at `u = 0.5` when
//! the surface is symmetric), `v` from the base (`0`) to the tip (`1`). These
//! parameters become the mesh UVs unchanged.

use glam::{DVec2, DVec3};

/// A parametric surface over `uv` in `[0, 1]^2` (`u` across, `v` base to tip).
pub trait Surface {
    /// The point at parameters `point_in_uv`, in the organ template frame.
    fn point(&self, point_in_uv: DVec2) -> DVec3;

    /// The UV a mesh vertex at parameters `point_in_uv` gets: the
    /// parameters themselves for a bud surface; a template mesh seen as a
    /// surface ([`crate::MeshSurface`]) maps them to its own UV layout. The
    /// remesher keeps triangles counter-clockwise in both.
    fn layout_uv(&self, point_in_uv: DVec2) -> DVec2 {
        point_in_uv
    }
}

/// Any closure `Fn(DVec2) -> DVec3` is a surface.
impl<F: Fn(DVec2) -> DVec3> Surface for F {
    fn point(&self, point_in_uv: DVec2) -> DVec3 {
        self(point_in_uv)
    }
}

/// The four cubic Bernstein polynomials at `t`.
pub fn bernstein3(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t]
}

/// A cubic Bézier curve; used for the boundary curves and boundary tangents
/// of a [`PdeSweep`] (tangent curves hold vectors, not points, in the same
/// type).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BezierCurve {
    /// The four control points, in curve order.
    pub control: [DVec3; 4],
}

impl BezierCurve {
    /// The curve of these control points.
    pub fn new(control: [DVec3; 4]) -> Self {
        BezierCurve { control }
    }

    /// A curve that is the same value everywhere.
    pub fn constant(value: DVec3) -> Self {
        BezierCurve {
            control: [value; 4],
        }
    }

    /// The curve at parameter `t` in `[0, 1]`.
    pub fn at(&self, t: f64) -> DVec3 {
        let b = bernstein3(t);
        (0..4).map(|i| b[i] * self.control[i]).sum()
    }
}

/// A bicubic Bézier patch, seed eq. 4.2:
/// `S(u, v) = sum_i sum_j B_i(u) B_j(v) P_ij` (the seed's `w` is our `v`).
///
/// `control[j][i]` is the control point in row `j` (along `v`, base row
/// first) and column `i` (along `u`). The four corners are interpolated:
/// `control[0][0]` is the point at `uv = (0, 0)`, `control[3][3]` at `(1, 1)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BezierPatch {
    /// The control points, `control[j][i]` (see above).
    pub control: [[DVec3; 4]; 4],
}

impl BezierPatch {
    /// The patch of these control points.
    pub fn new(control: [[DVec3; 4]; 4]) -> Self {
        BezierPatch { control }
    }
}

impl Surface for BezierPatch {
    fn point(&self, point_in_uv: DVec2) -> DVec3 {
        let bu = bernstein3(point_in_uv.x);
        let bv = bernstein3(point_in_uv.y);
        let mut p = DVec3::ZERO;
        for (j, row) in self.control.iter().enumerate() {
            for (i, control) in row.iter().enumerate() {
                p += bu[i] * bv[j] * *control;
            }
        }
        p
    }
}

/// The largest `k_s / k_b` a [`PdeSweep`] uses (`γ = 10`). The generator is
/// then already straight but for boundary layers a tenth of the width wide;
/// beyond it the 2x2 boundary system loses accuracy to cancellation.
pub const MAX_STRETCH_TO_BEND: f64 = 100.0;

/// A PDE sweep surface (Chaudhry et al. §IV): a generator curve,
/// the solution of the fourth-order ODE (seed eq. 5)
/// `k_b d'''' - k_s d'' = 0` in `u`, swept along two boundary curves
/// (the seed's "trajectories") that it meets with prescribed tangents:
///
/// ```text
/// S(0, v) = C0(v),  dS/du(0, v) = T0(v)
/// S(1, v) = C1(v),  dS/du(1, v) = T1(v)        (seed eq. 6)
/// ```
///
/// **Mapping to the organ's UVs.** As in the seed, the boundary curves are at
/// `u = 0` and `u = 1`, so they are the organ's two *margins* (left and right
/// edges), each running from the base (`v = 0`) to the tip (`v = 1`); the
/// generator runs across the organ and its middle (`u = 0.5`) is the midrib.
/// `T0`, `T1` are the across-derivatives at the margins: they set the width
/// direction and the cupping (a tangent tilted towards the outer side makes
/// the margins curl to the inner side). A pointed tip is made by letting the
/// two margins meet (`C0(1) = C1(1)`) with zero tangents there.
///
/// **The closed form.** With `k_s = 0` (seed solution 1) the generator is
/// the cubic Hermite interpolant
///
/// ```text
/// S(u, v) = (1 - 3u² + 2u³) C0 + u(1 - u)² T0 + u²(3 - 2u) C1 + u²(u - 1) T1
/// ```
///
/// The seed's printed eq. 11/12 lost its minus signs in transcription (its
/// `(1 + u² + 2u³) C1(v)` gives `4 C1 - 3 C2 + ...` at `u = 1`, not `C2`); the
/// form above is the unique cubic that satisfies eq. 6, which the tests check.
///
/// With `stretch_to_bend = k_s / k_b > 0` (seed solution 2, eq. 8) the
/// generator is built from `1, u, cosh(γu), sinh(γu)` with `γ = sqrt(k_s/k_b)`;
/// larger values pull the generator taut towards the straight chord between
/// the margins, with the curvature confined near the margins. `0` reproduces
/// the cubic exactly. (Solution 3, `k_s/k_b < 0`, is not offered: its
/// boundary problem is singular at some parameter values.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PdeSweep {
    /// Margin at `u = 0` (base to tip).
    pub curve0: BezierCurve,
    /// Margin at `u = 1` (base to tip).
    pub curve1: BezierCurve,
    /// `dS/du` along `curve0`.
    pub tangent0: BezierCurve,
    /// `dS/du` along `curve1`.
    pub tangent1: BezierCurve,
    /// The seed's `k_s / k_b` (`γ²`), in `[0, MAX_STRETCH_TO_BEND]`.
    stretch_to_bend: f64,
    /// Coefficients `(a2, a3)` of `phi2`, `phi3` in the generator for a unit
    /// value of each of the four boundary data `C0, T0, C1, T1`.
    blend: [[f64; 2]; 4],
}

impl PdeSweep {
    /// A sweep between margins `curve0` (`u = 0`) and `curve1` (`u = 1`) with
    /// across-tangents `tangent0`, `tangent1`. `stretch_to_bend` is the seed's
    /// `k_s / k_b`; negative or non-finite values are treated as 0 (the
    /// cubic of seed solution 1), values above [`MAX_STRETCH_TO_BEND`] are
    /// clamped to it.
    pub fn new(
        curve0: BezierCurve,
        curve1: BezierCurve,
        tangent0: BezierCurve,
        tangent1: BezierCurve,
        stretch_to_bend: f64,
    ) -> Self {
        let lambda = if stretch_to_bend.is_finite() && stretch_to_bend > 0.0 {
            stretch_to_bend.min(MAX_STRETCH_TO_BEND)
        } else {
            0.0
        };
        // d(u) = a0 + a1 u + a2 phi2(u) + a3 phi3(u), with phi2, phi3 and their
        // first derivatives zero at u = 0, so a0 = C0 and a1 = T0. The
        // conditions at u = 1 give the 2x2 system
        //   [phi2(1)  phi3(1)] [a2]   [C1 - C0 - T0]
        //   [phi2'(1) phi2(1)] [a3] = [T1 - T0     ]
        // (phi3' = phi2). Its determinant is 1/12 at lambda = 0 and grows with
        // lambda, so it is never singular.
        let [p2, p3, dp2] = generator_basis(lambda, 1.0);
        let det = p2 * p2 - dp2 * p3;
        let solve = |r0: f64, r1: f64| [(p2 * r0 - p3 * r1) / det, (p2 * r1 - dp2 * r0) / det];
        // Right-hand sides for unit C0, T0, C1, T1.
        let blend = [
            solve(-1.0, 0.0),
            solve(-1.0, -1.0),
            solve(1.0, 0.0),
            solve(0.0, 1.0),
        ];
        PdeSweep {
            curve0,
            curve1,
            tangent0,
            tangent1,
            stretch_to_bend: lambda,
            blend,
        }
    }

    /// The seed's `k_s / k_b` in use.
    pub fn stretch_to_bend(&self) -> f64 {
        self.stretch_to_bend
    }

    /// The weights of `C0, T0, C1, T1` at `u`: `S(u, v) = sum w_k X_k(v)`.
    pub fn weights(&self, u: f64) -> [f64; 4] {
        let [p2, p3, _] = generator_basis(self.stretch_to_bend, u);
        let own = [1.0, u, 0.0, 0.0];
        let mut w = [0.0; 4];
        for k in 0..4 {
            w[k] = own[k] + self.blend[k][0] * p2 + self.blend[k][1] * p3;
        }
        w
    }
}

impl Surface for PdeSweep {
    fn point(&self, point_in_uv: DVec2) -> DVec3 {
        let v = point_in_uv.y;
        let w = self.weights(point_in_uv.x);
        w[0] * self.curve0.at(v)
            + w[1] * self.tangent0.at(v)
            + w[2] * self.curve1.at(v)
            + w[3] * self.tangent1.at(v)
    }
}

/// `[phi2(u), phi3(u), phi2'(u)]` for the generator basis with
/// `lambda = γ²`: `phi2 = (cosh(γu) - 1)/γ²`, `phi3 = (sinh(γu) - γu)/γ³`,
/// which tend to `u²/2`, `u³/6` as `γ -> 0`; `phi3' = phi2` and
/// `phi2' = sinh(γu)/γ`.
fn generator_basis(lambda: f64, u: f64) -> [f64; 3] {
    if lambda * u * u < 1.0 {
        generator_basis_series(lambda, u)
    } else {
        generator_basis_closed(lambda, u)
    }
}

/// [`generator_basis`] by its power series (exact to rounding where the
/// closed form would cancel): `phi2 = sum_k λ^k u^(2k+2)/(2k+2)!`,
/// `phi3 = sum_k λ^k u^(2k+3)/(2k+3)!`, `phi2' = sum_k λ^k u^(2k+1)/(2k+1)!`.
/// Meant for `λu² < 1`, where 12 terms are far more than enough.
fn generator_basis_series(lambda: f64, u: f64) -> [f64; 3] {
    let x = lambda * u * u;
    let (mut p2, mut p3, mut dp2) = (0.0, 0.0, 0.0);
    let (mut t2, mut t3, mut td) = (u * u / 2.0, u * u * u / 6.0, u);
    for k in 0..12 {
        p2 += t2;
        p3 += t3;
        dp2 += td;
        let k = k as f64;
        t2 *= x / ((2.0 * k + 3.0) * (2.0 * k + 4.0));
        t3 *= x / ((2.0 * k + 4.0) * (2.0 * k + 5.0));
        td *= x / ((2.0 * k + 2.0) * (2.0 * k + 3.0));
    }
    [p2, p3, dp2]
}

/// [`generator_basis`] in closed form (for `λ > 0`).
fn generator_basis_closed(lambda: f64, u: f64) -> [f64; 3] {
    let g = lambda.sqrt();
    let gu = g * u;
    [
        (gu.cosh() - 1.0) / lambda,
        (gu.sinh() - gu) / (lambda * g),
        gu.sinh() / g,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn approx(a: DVec3, b: DVec3, tolerance: f64) -> bool {
        (a - b).length() <= tolerance * (1.0 + b.length())
    }

    /// A non-planar patch with distinct control points.
    fn wavy_patch() -> BezierPatch {
        BezierPatch::new(std::array::from_fn(|j| {
            std::array::from_fn(|i| {
                let (x, y) = (i as f64, j as f64);
                DVec3::new(
                    x * 2.0 - y * 0.3,
                    y * 3.0 + x * 0.5,
                    (x * 1.7 + y * 2.3).sin(),
                )
            })
        }))
    }

    /// Independent evaluation: de Casteljau along u in every row, then
    /// along v.
    fn de_casteljau(patch: &BezierPatch, uv: DVec2) -> DVec3 {
        fn curve(mut p: [DVec3; 4], t: f64) -> DVec3 {
            for level in 1..4 {
                for i in 0..4 - level {
                    p[i] = p[i].lerp(p[i + 1], t);
                }
            }
            p[0]
        }
        let rows = patch.control.map(|row| curve(row, uv.x));
        curve(rows, uv.y)
    }

    #[test]
    fn bernstein_polynomials_sum_to_one() {
        for k in 0..=10 {
            let b = bernstein3(k as f64 / 10.0);
            assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        }
        assert_eq!(bernstein3(0.0), [1.0, 0.0, 0.0, 0.0]);
        assert_eq!(bernstein3(0.5), [0.125, 0.375, 0.375, 0.125]);
    }

    #[test]
    fn bezier_patch_interpolates_its_corners() {
        let p = wavy_patch();
        let c = p.control;
        assert!(approx(p.point(DVec2::new(0.0, 0.0)), c[0][0], 1e-15));
        assert!(approx(p.point(DVec2::new(1.0, 0.0)), c[0][3], 1e-15));
        assert!(approx(p.point(DVec2::new(0.0, 1.0)), c[3][0], 1e-15));
        assert!(approx(p.point(DVec2::new(1.0, 1.0)), c[3][3], 1e-15));
    }

    #[test]
    fn bezier_patch_matches_de_casteljau() {
        let p = wavy_patch();
        // The centre by hand: weights (1,3,3,1) x (1,3,3,1) / 64.
        let w = [1.0, 3.0, 3.0, 1.0];
        let mut centre = DVec3::ZERO;
        for j in 0..4 {
            for i in 0..4 {
                centre += w[i] * w[j] / 64.0 * p.control[j][i];
            }
        }
        assert!(approx(p.point(DVec2::splat(0.5)), centre, 1e-14));
        for uv in [
            DVec2::new(0.5, 0.0),
            DVec2::new(0.0, 0.5),
            DVec2::new(0.5, 1.0),
            DVec2::new(0.25, 0.75),
            DVec2::new(0.9, 0.1),
            DVec2::new(0.33, 0.61),
        ] {
            assert!(approx(p.point(uv), de_casteljau(&p, uv), 1e-14), "at {uv}");
        }
    }

    #[test]
    fn bezier_patch_matches_the_seeds_matrix_form() {
        // Seed eq. 4.3: S(u, w) = U M B M^T W^T with U = [u^3 u^2 u 1].
        // Our control[j][i] is the seed's P_ij with i along u, j along w = v.
        let m = [
            [-1.0, 3.0, -3.0, 1.0],
            [3.0, -6.0, 3.0, 0.0],
            [-3.0, 3.0, 0.0, 0.0],
            [1.0, 0.0, 0.0, 0.0],
        ];
        let p = wavy_patch();
        let uv = DVec2::new(0.37, 0.82);
        let powers = |t: f64| [t * t * t, t * t, t, 1.0];
        let (pu, pw) = (powers(uv.x), powers(uv.y));
        // (U M)_i and (W M)_j.
        let um: [f64; 4] = std::array::from_fn(|i| (0..4).map(|k| pu[k] * m[k][i]).sum());
        let wm: [f64; 4] = std::array::from_fn(|j| (0..4).map(|k| pw[k] * m[k][j]).sum());
        let mut s = DVec3::ZERO;
        for i in 0..4 {
            for j in 0..4 {
                s += um[i] * wm[j] * p.control[j][i];
            }
        }
        assert!(approx(p.point(uv), s, 1e-14));
    }

    #[test]
    fn planar_bezier_patch_reproduces_the_bilinear_surface() {
        // Control points on the bilinear surface through four coplanar
        // corners (an irregular quadrilateral), taken at thirds: the patch
        // is that bilinear surface (linear precision of Bernstein polynomials).
        let corners = [
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(4.0, 0.5, 1.0),
            DVec3::new(-1.0, 6.0, 1.0),
            DVec3::new(5.0, 7.0, 1.0),
        ];
        let bilinear = |uv: DVec2| {
            let bottom = corners[0].lerp(corners[1], uv.x);
            let top = corners[2].lerp(corners[3], uv.x);
            bottom.lerp(top, uv.y)
        };
        let p = BezierPatch::new(std::array::from_fn(|j| {
            std::array::from_fn(|i| bilinear(DVec2::new(i as f64 / 3.0, j as f64 / 3.0)))
        }));
        for k in 0..=20 {
            let uv = DVec2::new((k as f64 * 0.37).fract(), k as f64 / 20.0);
            assert!(approx(p.point(uv), bilinear(uv), 1e-14), "at {uv}");
            assert!((p.point(uv).z - 1.0).abs() < 1e-14);
        }
    }

    fn sample_sweep(stretch_to_bend: f64) -> PdeSweep {
        PdeSweep::new(
            BezierCurve::new([
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(5.0, 10.0, 2.0),
                DVec3::new(4.0, 20.0, 1.0),
                DVec3::new(0.5, 30.0, -3.0),
            ]),
            BezierCurve::new([
                DVec3::new(-1.0, 0.0, 0.2),
                DVec3::new(-6.0, 11.0, 1.0),
                DVec3::new(-3.0, 19.0, 2.0),
                DVec3::new(-0.5, 31.0, -2.0),
            ]),
            BezierCurve::new([
                DVec3::new(-2.0, 0.0, 0.5),
                DVec3::new(-9.0, 1.0, 6.0),
                DVec3::new(-8.0, -1.0, 5.0),
                DVec3::new(-1.0, 0.0, 0.3),
            ]),
            BezierCurve::new([
                DVec3::new(-2.0, 0.3, -0.5),
                DVec3::new(-10.0, 0.0, -4.0),
                DVec3::new(-7.0, 1.0, -6.0),
                DVec3::new(-1.0, 0.0, -0.2),
            ]),
            stretch_to_bend,
        )
    }

    #[test]
    fn pde_sweep_meets_its_boundary_curves_and_tangents() {
        // Seed eq. 6, checked with finite differences of the surface itself.
        for lambda in [0.0, 0.3, 4.0, 30.0, MAX_STRETCH_TO_BEND] {
            let s = sample_sweep(lambda);
            for k in 0..=8 {
                let v = k as f64 / 8.0;
                let at = |u: f64| s.point(DVec2::new(u, v));
                assert!(approx(at(0.0), s.curve0.at(v), 1e-12), "C0, λ {lambda}");
                assert!(approx(at(1.0), s.curve1.at(v), 1e-12), "C1, λ {lambda}");
                // Second-order one-sided differences.
                let h = 1e-5;
                let d0 = (-3.0 * at(0.0) + 4.0 * at(h) - at(2.0 * h)) / (2.0 * h);
                let d1 = (3.0 * at(1.0) - 4.0 * at(1.0 - h) + at(1.0 - 2.0 * h)) / (2.0 * h);
                assert!(approx(d0, s.tangent0.at(v), 1e-6), "T0 {d0} λ {lambda}");
                assert!(approx(d1, s.tangent1.at(v), 1e-6), "T1 {d1} λ {lambda}");
            }
        }
    }

    #[test]
    fn cubic_pde_sweep_is_the_hermite_form() {
        let s = sample_sweep(0.0);
        for (u, v) in [(0.3, 0.2), (0.5, 0.5), (0.85, 0.9)] {
            let h0 = 1.0 - 3.0 * u * u + 2.0 * u * u * u;
            let h1 = u * (1.0 - u) * (1.0 - u);
            let h2 = u * u * (3.0 - 2.0 * u);
            let h3 = u * u * (u - 1.0);
            let expected = h0 * s.curve0.at(v)
                + h1 * s.tangent0.at(v)
                + h2 * s.curve1.at(v)
                + h3 * s.tangent1.at(v);
            assert!(approx(s.point(DVec2::new(u, v)), expected, 1e-13));
        }
    }

    #[test]
    fn pde_sweep_generator_solves_the_seeds_ode() {
        // Seed eq. 5: k_b d'''' - k_s d'' = 0, i.e. d'''' = λ d'' along u.
        for lambda in [0.0, 2.0, 9.0] {
            let s = sample_sweep(lambda);
            let at = |u: f64| s.point(DVec2::new(u, 0.4));
            let h = 0.01;
            for u in [0.2, 0.5, 0.75] {
                let d2 = (at(u - h) - 2.0 * at(u) + at(u + h)) / (h * h);
                let d4 = (at(u - 2.0 * h) - 4.0 * at(u - h) + 6.0 * at(u) - 4.0 * at(u + h)
                    + at(u + 2.0 * h))
                    / (h * h * h * h);
                let residual = (d4 - lambda * d2).length();
                assert!(
                    residual < 1e-3 * (1.0 + lambda * d2.length()),
                    "λ {lambda} u {u}: residual {residual}"
                );
            }
        }
    }

    #[test]
    fn generator_series_and_closed_form_agree_where_they_meet() {
        for lambda in [0.5f64, 1.0, 3.0, 40.0] {
            for x in [0.6, 1.0, 1.8] {
                let u = (x / lambda).sqrt();
                let a = generator_basis_series(lambda, u);
                let b = generator_basis_closed(lambda, u);
                for k in 0..3 {
                    assert!(
                        (a[k] - b[k]).abs() < 1e-12 * (1.0 + b[k].abs()),
                        "{a:?} {b:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn sweep_reproduces_constants_and_straight_lines() {
        // With C0 = C1 = p and zero tangents the generator is constant; with
        // C1 = C0 + t and both tangents t it is the straight line.
        for lambda in [0.0, 5.0] {
            let p = DVec3::new(1.0, 2.0, 3.0);
            let t = DVec3::new(-4.0, 0.5, 1.0);
            let flat = PdeSweep::new(
                BezierCurve::constant(p),
                BezierCurve::constant(p),
                BezierCurve::constant(DVec3::ZERO),
                BezierCurve::constant(DVec3::ZERO),
                lambda,
            );
            let line = PdeSweep::new(
                BezierCurve::constant(p),
                BezierCurve::constant(p + t),
                BezierCurve::constant(t),
                BezierCurve::constant(t),
                lambda,
            );
            for u in [0.1, 0.45, 0.8] {
                let uv = DVec2::new(u, 0.3);
                assert!(approx(flat.point(uv), p, 1e-13));
                assert!(approx(line.point(uv), p + u * t, 1e-13));
            }
        }
    }

    #[test]
    fn stretch_to_bend_is_clamped_to_the_offered_range() {
        assert_eq!(sample_sweep(-3.0).stretch_to_bend(), 0.0);
        assert_eq!(sample_sweep(f64::NAN).stretch_to_bend(), 0.0);
        assert_eq!(sample_sweep(1e9).stretch_to_bend(), MAX_STRETCH_TO_BEND);
        let s = sample_sweep(1e9);
        assert!(s.point(DVec2::new(0.5, 0.5)).is_finite());
    }
}

//! Regional growth (paper §4): each triangle, copied as it is now, grows on
//! its own; the grown copies give the new rest lengths and rest angles.
//!
//! For a triangle `T` with growth direction `D` (the UV direction pushed
//! through the triangle's UV→3D map) and the in-plane `W = n x D`, `T'`
//! scales `T` about its barycentre by the e-rate along `D` and the w-rate
//! along `W`; each edge's new rest length is the mean of its triangles'
//! grown lengths (eq. 3).
//!
//! Rest angles come from the difference between the inner and the base
//! growth, by one of two rules ([`BendRule`]):
//!
//! - [`BendRule::Curvature`] (the default). The petal is a bilayer: an
//!   inner surface `thickness` from the base one. A material line across
//!   which the inner side grows by `λ_in` and the base by `λ` bends by
//!   `Δκ = (λ_in − λ) / thickness` (per unit of its current length), and a
//!   bend it already has is carried along by the inner growth (its angle
//!   times `λ_in`: a bilayer of constant thickness grown evenly keeps its
//!   curvature, so the angle over the lengthened line grows). Per triangle
//!   the target curvature increment is the tensor
//!   `ΔK = (e_in − e)/t · D⊗D + (w_in − w)/t · W⊗W`; each hinge's increment
//!   is the dihedral angle of its two triangles, unfolded flat and lifted
//!   onto the height field `−½ pᵀ ΔK p` (the mean of its triangles' `ΔK`).
//!   That is exact for the discrete surface: a mesh whose hinges all have
//!   these angles lies on the surface of curvature `ΔK` (for isotropic
//!   growth the angle is `Δκ` times the distance between the two
//!   triangles' circumcentres, the exact angle between inscribed
//!   triangles of a sphere; for growth along `D` only, a cylinder bent
//!   along `D` and straight across it). Nothing is offset, so nothing can
//!   turn inside out at any edge length.
//! - [`BendRule::InnerTriangle`], the paper's rule (eq. 4), kept for
//!   comparison: the inner triangle `T_in` offsets each edge of `T`
//!   outwards in its plane by `s = thickness * tan(theta0 / 2)`, intersects
//!   the offset lines and lifts the corners by `thickness` along the inner
//!   normal; `T_in'` grows with the inner rates; `s'` is the in-plane
//!   distance from the grown base edge to the midpoint of the grown inner
//!   edge, and the new rest angle of an edge is the sum over its triangles
//!   of `atan(s' / thickness)`. Measured (see ARCHITECTURE.md): it realises
//!   3/4 of an anisotropic bend along the growth direction and leaks 1/4
//!   across it, is off by tens of percent on irregular triangles, and turns
//!   the inner triangle inside out when edges are shorter than the
//!   thickness.
//!
//! `theta0`, the angle the growth starts from, is the hinge's current
//! dihedral angle or its current rest angle ([`BendBase`]).
//!
//! The triangle that grows is, for its rest lengths, the triangle as it is
//! now (the paper's rule, [`LengthBase::Shape`]: length the shape could not
//! take is forgotten at each step) or its rest triangle
//! ([`LengthBase::Rest`]: the flat triangle of its three rest lengths, so
//! the rest state is the bud's grown by the cumulative growth and excess
//! length the shape could not take is kept, as ripples need).

use anthesis_mesh::Topology;

use crate::hinge::dihedral_angle;
use glam::{DVec2, DVec3};

/// Growth rates of one triangle for one step (`1 + dg * map value`, so 1
/// means no growth) and its growth direction in UV.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrowthRates {
    /// Stretch factor of the base (outer) layer along the growth direction.
    pub e: f64,
    /// Stretch factor of the base layer across the growth direction.
    pub w: f64,
    /// Stretch factor of the inner layer along the growth direction.
    pub e_in: f64,
    /// Stretch factor of the inner layer across the growth direction.
    pub w_in: f64,
    /// The growth direction as a vector in the triangle's UV layout (any
    /// length; `(0, 1)` is along `v`, base to tip).
    pub direction_in_uv: DVec2,
}

/// How the inner/base growth difference becomes rest angles (see the
/// module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BendRule {
    /// Target curvature per triangle, turned exactly into hinge angles.
    #[default]
    Curvature,
    /// The paper's imaginary inner triangle (§4.2, eq. 4).
    InnerTriangle,
}

/// The angle a hinge's growth starts from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BendBase {
    /// The hinge's dihedral angle as it is now: like the rest lengths, which
    /// grow from the current triangles, bending that the shape could not
    /// take is forgotten at each step (the tissue yields).
    #[default]
    Dihedral,
    /// The hinge's rest angle: unreached bending accumulates from step to
    /// step (the tissue remembers its target).
    RestAngle,
}

/// The triangle whose growth gives the new rest lengths.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LengthBase {
    /// The triangle as it is now (the paper, §4): growth the shape could
    /// not take is forgotten at each step (the tissue yields).
    #[default]
    Shape,
    /// The rest triangle (the flat triangle of its current rest lengths):
    /// the rest state accumulates the growth, so after steps of rates
    /// `g1, g2, …` a rest length is the bud's times their product whatever
    /// shape the sheet took (the tissue keeps its target metric).
    Rest,
}

/// The regional-growth parameters of one organ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrowthModel {
    /// Distance of the inner surface from the base surface (> 0).
    pub thickness: f64,
    /// How the difference between inner and base growth becomes rest
    /// angles.
    pub bend_rule: BendRule,
    /// Which angle a hinge's growth starts from.
    pub bend_base: BendBase,
    /// Which triangle grows into the new rest lengths.
    pub length_base: LengthBase,
}

impl GrowthModel {
    /// The default rules at `thickness`.
    pub fn new(thickness: f64) -> GrowthModel {
        GrowthModel {
            thickness,
            bend_rule: BendRule::default(),
            bend_base: BendBase::default(),
            length_base: LengthBase::default(),
        }
    }
}

/// The largest half-angle used to offset an edge for the inner triangle;
/// beyond it `tan` explodes (a fold of nearly 180° between two triangles).
const MAX_HALF_ANGLE: f64 = 1.4;

/// What the curvature rule needs of one triangle: its unit normal (inner
/// side) and growth direction, its curvature increment along and across the
/// growth direction, and the inner rates that carry existing bends.
#[derive(Debug, Clone, Copy, Default)]
struct TriangleBend {
    normal: DVec3,
    along: DVec3,
    kappa_along: f64,
    kappa_across: f64,
    e_in: f64,
    w_in: f64,
}

/// Reusable buffers for [`RegionalGrowth::grow`].
#[derive(Debug, Default, Clone)]
pub struct RegionalGrowth {
    length_sum: Vec<f64>,
    length_count: Vec<u8>,
    angle_sum: Vec<f64>,
    angle_from: Vec<f64>,
    bends: Vec<TriangleBend>,
}

impl RegionalGrowth {
    /// Computes new rest lengths and rest angles from the current shape.
    ///
    /// `rest_lengths` and `rest_angles` (one per edge) are replaced. `rates`
    /// has one entry per triangle.
    #[allow(clippy::too_many_arguments)]
    pub fn grow(
        &mut self,
        positions: &[DVec3],
        uvs: &[DVec2],
        triangles: &[[u32; 3]],
        topology: &Topology,
        rates: &[GrowthRates],
        model: &GrowthModel,
        rest_lengths: &mut [f64],
        rest_angles: &mut [f64],
    ) {
        let edges = topology.edges.len();
        self.length_sum.clear();
        self.length_sum.resize(edges, 0.0);
        self.length_count.clear();
        self.length_count.resize(edges, 0);
        match model.bend_rule {
            BendRule::Curvature => {
                self.bends.clear();
                for (t, tri) in triangles.iter().enumerate() {
                    let x = corners(positions, *tri);
                    let rates = &rates[t];
                    let frame = TriangleFrame::new(x, corners(uvs, *tri), rates.direction_in_uv);
                    let lengths = match model.length_base {
                        LengthBase::Shape => frame.grown_lengths(x, rates.e, rates.w),
                        LengthBase::Rest => grown_rest_lengths(
                            topology.triangle_edges[t].map(|e| rest_lengths[e as usize]),
                            corners(uvs, *tri),
                            rates,
                        ),
                    };
                    self.add_lengths(topology.triangle_edges[t], lengths);
                    self.bends.push(TriangleBend {
                        normal: frame.normal,
                        along: frame.along,
                        kappa_along: (rates.e_in - rates.e) / model.thickness,
                        kappa_across: (rates.w_in - rates.w) / model.thickness,
                        e_in: rates.e_in,
                        w_in: rates.w_in,
                    });
                }
                for (e, edge) in topology.edges.iter().enumerate() {
                    rest_lengths[e] = self.mean_length(e);
                    rest_angles[e] = match (edge.hinge(), edge.right) {
                        (Some(stencil), Some(right)) => curvature_hinge_angle(
                            corners(positions, stencil),
                            [
                                &self.bends[edge.left.triangle as usize],
                                &self.bends[right.triangle as usize],
                            ],
                            match model.bend_base {
                                BendBase::Dihedral => None,
                                BendBase::RestAngle => Some(rest_angles[e]),
                            },
                        ),
                        _ => 0.0,
                    };
                }
            }
            BendRule::InnerTriangle => {
                self.angle_sum.clear();
                self.angle_sum.resize(edges, 0.0);
                self.angle_from.clear();
                self.angle_from
                    .extend(topology.edges.iter().enumerate().map(|(e, edge)| {
                        match (edge.hinge(), model.bend_base) {
                            (None, _) => 0.0,
                            (Some(h), BendBase::Dihedral) => dihedral_angle(corners(positions, h)),
                            (Some(_), BendBase::RestAngle) => rest_angles[e],
                        }
                    }));
                for (t, tri) in triangles.iter().enumerate() {
                    let edge_ids = topology.triangle_edges[t];
                    let theta0 = edge_ids.map(|e| self.angle_from[e as usize]);
                    let grown = grow_triangle(
                        corners(positions, *tri),
                        corners(uvs, *tri),
                        &rates[t],
                        model.thickness,
                        theta0,
                    );
                    let lengths = match model.length_base {
                        LengthBase::Shape => grown.lengths,
                        LengthBase::Rest => grown_rest_lengths(
                            edge_ids.map(|e| rest_lengths[e as usize]),
                            corners(uvs, *tri),
                            &rates[t],
                        ),
                    };
                    self.add_lengths(edge_ids, lengths);
                    for k in 0..3 {
                        self.angle_sum[edge_ids[k] as usize] += grown.half_angles[k];
                    }
                }
                for (e, edge) in topology.edges.iter().enumerate() {
                    rest_lengths[e] = self.mean_length(e);
                    rest_angles[e] = match edge.right {
                        Some(_) => self.angle_sum[e],
                        None => 0.0,
                    };
                }
            }
        }
    }

    /// Adds one triangle's grown lengths of its sides `edge_ids`.
    fn add_lengths(&mut self, edge_ids: [u32; 3], lengths: [f64; 3]) {
        for k in 0..3 {
            let e = edge_ids[k] as usize;
            self.length_sum[e] += lengths[k];
            self.length_count[e] += 1;
        }
    }

    /// Edge `e`'s new rest length: the mean of its triangles' grown lengths.
    fn mean_length(&self, e: usize) -> f64 {
        self.length_sum[e] / f64::from(self.length_count[e].max(1))
    }
}

/// The grown lengths of the sides `(t0,t1)`, `(t1,t2)`, `(t2,t0)` of the
/// rest triangle whose sides are `rest` (in that order; the flat triangle
/// of those lengths): scaled by `e` along the growth direction (mapped
/// through the rest triangle's UV→rest Jacobian) and `w` across it. The
/// layout is the triangle up to a reflection, which maps the growth
/// direction with it and so changes no length. Lengths that no longer make a triangle
/// (each edge's rest length is the mean of its two triangles', so they
/// can drift apart) give a flat one.
fn grown_rest_lengths(rest: [f64; 3], uv: [DVec2; 3], rates: &GrowthRates) -> [f64; 3] {
    let [a, b, c] = rest;
    // Corner 2 at distance c from corner 0 and b from corner 1 (at (a, 0)).
    let along = if a > 0.0 {
        (a * a + c * c - b * b) / (2.0 * a)
    } else {
        0.0
    };
    let height = (c * c - along * along).max(0.0).sqrt();
    let x = [
        DVec3::ZERO,
        DVec3::new(a, 0.0, 0.0),
        DVec3::new(along, height, 0.0),
    ];
    TriangleFrame::new(x, uv, rates.direction_in_uv).grown_lengths(x, rates.e, rates.w)
}

/// `values` at `indices`.
#[inline]
fn corners<T: Copy, const N: usize>(values: &[T], indices: [u32; N]) -> [T; N] {
    std::array::from_fn(|k| values[indices[k] as usize])
}

/// A triangle's growth frame: unit normal (inner side), growth direction
/// and the in-plane direction across it.
struct TriangleFrame {
    normal: DVec3,
    along: DVec3,
    across: DVec3,
}

impl TriangleFrame {
    fn new(x: [DVec3; 3], uv: [DVec2; 3], direction_in_uv: DVec2) -> TriangleFrame {
        let normal = (x[1] - x[0]).cross(x[2] - x[0]).normalize_or_zero();
        let along = growth_direction(x, uv, direction_in_uv, normal);
        TriangleFrame {
            normal,
            along,
            across: normal.cross(along),
        }
    }

    /// `points` scaled about their barycentre by `e` along the growth
    /// direction and `w` across it.
    fn scale(&self, points: [DVec3; 3], e: f64, w: f64) -> [DVec3; 3] {
        let centre = (points[0] + points[1] + points[2]) / 3.0;
        points.map(|p| {
            let d = p - centre;
            centre
                + self.along * (e * d.dot(self.along))
                + self.across * (w * d.dot(self.across))
                + self.normal * d.dot(self.normal)
        })
    }

    /// Lengths of the sides `(x0,x1)`, `(x1,x2)`, `(x2,x0)` of the triangle
    /// scaled by `e` along the growth direction and `w` across it: each side
    /// lies in the triangle's plane, so its grown vector has the components
    /// `e (v·D)` and `w (v·W)` (the same lengths as [`TriangleFrame::scale`]
    /// gives, without moving the corners).
    fn grown_lengths(&self, x: [DVec3; 3], e: f64, w: f64) -> [f64; 3] {
        let grown = |v: DVec3| DVec2::new(e * v.dot(self.along), w * v.dot(self.across)).length();
        [grown(x[1] - x[0]), grown(x[2] - x[1]), grown(x[0] - x[2])]
    }
}

/// The new rest angle of the hinge `[xi, xj, xk, xl]` under the curvature
/// rule: the angle it grows from (`rest_angle`, or its dihedral angle when
/// `None`) carried by the inner growth across the edge, plus the dihedral
/// angle the hinge takes on the height field of the mean of its triangles'
/// curvature increments (see the module documentation).
///
/// Everything is in the hinge unfolded flat: the edge along `+x` from `xi`,
/// the left triangle on `+y`, the right one on `−y`, each triangle's plane
/// spanned by the edge and its own in-plane `y`. On the height field
/// `h(p) = −½ pᵀ K p` the edge's ends lie at the same height, so each lifted
/// triangle rises (or falls) only away from the edge, by `h(k) − h(i)` over
/// the height `y_k` of its opposite corner, and the angle between the two
/// lifted planes is `atan2(h_k y_l − h_l y_k, −y_k y_l − h_k h_l)` (the
/// angle between their normals `(0, −h_k, y_k)` and `(0, h_l, −y_l)`, both
/// scaled by the edge length).
///
/// Always inlined: called with its four corners copied to the stack, the
/// regional growth step took 0.36 instead of 0.26 ms on the kernels
/// example's 1k petal.
#[inline(always)]
fn curvature_hinge_angle(x: [DVec3; 4], sides: [&TriangleBend; 2], rest_angle: Option<f64>) -> f64 {
    let [xi, xj, xk, xl] = x;
    let [left, right] = sides;
    let edge = xj - xi;
    let length = edge.length();
    if length == 0.0 {
        // A collapsed edge has no angle; it keeps the one it grows from, or none.
        return rest_angle.unwrap_or(0.0);
    }
    let along_edge = edge / length;
    // Each triangle's in-plane direction away from the edge towards its own
    // side: the left triangle lies on +y, the right one, unfolded, on −y.
    let y_left = left.normal.cross(along_edge);
    let y_right = right.normal.cross(along_edge);
    // The dihedral angle from the two normals: its sine is the right normal
    // against the left triangle's y, its cosine their dot product.
    let angle_from = rest_angle
        .unwrap_or_else(|| (-right.normal.dot(y_left)).atan2(left.normal.dot(right.normal)));
    // Each side's growth direction in the unfolded frame; the direction
    // across it is its perpendicular, so its curvature tensor is
    // `κ_D d dᵀ + κ_W d⊥ d⊥ᵀ`.
    let d_left = DVec2::new(left.along.dot(along_edge), left.along.dot(y_left));
    let d_right = DVec2::new(right.along.dot(along_edge), right.along.dot(y_right));
    let tensor = |b: &TriangleBend, d: DVec2| {
        [
            b.kappa_along * d.x * d.x + b.kappa_across * d.y * d.y,
            (b.kappa_along - b.kappa_across) * d.x * d.y,
            b.kappa_along * d.y * d.y + b.kappa_across * d.x * d.x,
        ]
    };
    let (kl, kr) = (tensor(left, d_left), tensor(right, d_right));
    let k = [
        0.5 * (kl[0] + kr[0]),
        0.5 * (kl[1] + kr[1]),
        0.5 * (kl[2] + kr[2]),
    ];
    // The opposite corners: distance along the edge from xi, height over it.
    let (a_k, y_k) = ((xk - xi).dot(along_edge), (xk - xi).dot(y_left));
    let (a_l, y_l) = ((xl - xi).dot(along_edge), (xl - xi).dot(y_right));
    // h(p) − h(xi) at a corner: with p.x = a − length/2 from the edge's
    // midpoint, p.x² − length²/4 = a (a − length).
    let rise = |a: f64, y: f64| {
        -0.5 * (k[0] * a * (a - length) + k[1] * (2.0 * a - length) * y + k[2] * y * y)
    };
    let (h_k, h_l) = (rise(a_k, y_k), rise(a_l, y_l));
    let increment = (h_k * y_l - h_l * y_k).atan2(-y_k * y_l - h_k * h_l);
    // The inner growth across the edge (perpendicular to it, in each
    // triangle's plane: `d.y` along the growth direction, `d.x` across it)
    // carries the bend the hinge already has.
    let carry = |b: &TriangleBend, d: DVec2| DVec2::new(b.e_in * d.y, b.w_in * d.x).length();
    let carried = 0.5 * (carry(left, d_left) + carry(right, d_right));
    angle_from * carried + increment
}

/// What one grown triangle contributes to its edges `(t0,t1)`, `(t1,t2)`,
/// `(t2,t0)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrownTriangle {
    /// The grown rest length of each edge, in the units of the positions.
    pub lengths: [f64; 3],
    /// `atan(s' / thickness)` per edge: this triangle's share of the edge's
    /// new rest angle.
    pub half_angles: [f64; 3],
}

/// Grows one triangle (positions `x`, UVs `uv`) with `rates`, given the
/// current rest angles of its three edges.
pub fn grow_triangle(
    x: [DVec3; 3],
    uv: [DVec2; 3],
    rates: &GrowthRates,
    thickness: f64,
    theta0: [f64; 3],
) -> GrownTriangle {
    let frame = TriangleFrame::new(x, uv, rates.direction_in_uv);
    let normal = frame.normal;
    let grown = frame.scale(x, rates.e, rates.w);
    let lengths = [0, 1, 2].map(|k| (grown[(k + 1) % 3] - grown[k]).length());

    // Inner triangle: offset each edge line outwards by s, intersect, lift.
    let offsets =
        theta0.map(|a| thickness * (0.5 * a).clamp(-MAX_HALF_ANGLE, MAX_HALF_ANGLE).tan());
    let outward = [0, 1, 2].map(|k| (x[(k + 1) % 3] - x[k]).cross(normal).normalize_or_zero());
    let inner = [0, 1, 2].map(|m| {
        // Corner m lies on edge m (m -> m+1) and edge m-1 (m-1 -> m).
        let (a, b) = (m, (m + 2) % 3);
        let c = outward[a].dot(outward[b]);
        let det = (1.0 - c * c).max(1e-12);
        let alpha = (offsets[a] - c * offsets[b]) / det;
        let beta = (offsets[b] - c * offsets[a]) / det;
        x[m] + outward[a] * alpha + outward[b] * beta + normal * thickness
    });
    let inner_grown = frame.scale(inner, rates.e_in, rates.w_in);

    let half_angles = [0, 1, 2].map(|k| {
        let (a, b) = (grown[k], grown[(k + 1) % 3]);
        let edge_normal = (b - a).cross(normal).normalize_or_zero();
        let midpoint = 0.5 * (inner_grown[k] + inner_grown[(k + 1) % 3]);
        let s_grown = (midpoint - a).dot(edge_normal);
        (s_grown / thickness).atan()
    });
    GrownTriangle {
        lengths,
        half_angles,
    }
}

/// The unit 3D growth direction of a triangle: the UV direction mapped
/// through the triangle's UV→3D Jacobian. A zero direction falls back to
/// +v (base to tip); a degenerate UV triangle to its first edge.
pub fn growth_direction(
    x: [DVec3; 3],
    uv: [DVec2; 3],
    direction_in_uv: DVec2,
    normal: DVec3,
) -> DVec3 {
    let du1 = uv[1] - uv[0];
    let du2 = uv[2] - uv[0];
    let det = du1.perp_dot(du2);
    let e1 = x[1] - x[0];
    let e2 = x[2] - x[0];
    let d = if direction_in_uv.length_squared() > 1e-12 {
        direction_in_uv
    } else {
        DVec2::Y
    };
    if det.abs() > 1e-300 {
        // Solve [du1 du2] (a, b) = d, then D = a e1 + b e2.
        let a = d.perp_dot(du2) / det;
        let b = du1.perp_dot(d) / det;
        let world = e1 * a + e2 * b;
        let in_plane = world - normal * world.dot(normal);
        if in_plane.length_squared() > 0.0 {
            return in_plane.normalize();
        }
    }
    e1.normalize_or_zero()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::TestRng;

    fn right_triangle() -> ([DVec3; 3], [DVec2; 3]) {
        (
            [
                DVec3::ZERO,
                DVec3::new(2.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
            ],
            [DVec2::ZERO, DVec2::new(1.0, 0.0), DVec2::new(0.0, 1.0)],
        )
    }

    fn rates(e: f64, w: f64, e_in: f64, w_in: f64, d: DVec2) -> GrowthRates {
        GrowthRates {
            e,
            w,
            e_in,
            w_in,
            direction_in_uv: d,
        }
    }

    #[test]
    fn direction_goes_through_the_uv_jacobian() {
        let (x, uv) = right_triangle();
        // u is stretched twice in 3D, so UV (1,1) points along (2,1) in 3D.
        let d = growth_direction(x, uv, DVec2::new(1.0, 1.0), DVec3::Z);
        assert!((d - DVec3::new(2.0, 1.0, 0.0).normalize()).length() < 1e-12);
        // A zero direction falls back to +v.
        let d = growth_direction(x, uv, DVec2::ZERO, DVec3::Z);
        assert!((d - DVec3::Y).length() < 1e-12);
    }

    #[test]
    fn growth_along_u_scales_only_u_lengths() {
        let (x, uv) = right_triangle();
        let g = grow_triangle(x, uv, &rates(1.5, 1.0, 1.0, 1.0, DVec2::X), 0.1, [0.0; 3]);
        assert!(
            (g.lengths[0] - 3.0).abs() < 1e-12,
            "edge along u grows 1.5x"
        );
        assert!(
            (g.lengths[2] - 1.0).abs() < 1e-12,
            "edge along v keeps its length"
        );
        assert!((g.lengths[1] - (9.0f64 + 1.0).sqrt()).abs() < 1e-12);
    }

    #[test]
    fn no_growth_keeps_rest_angles() {
        let (x, uv) = right_triangle();
        let theta0 = [0.3, -0.2, 0.1];
        let g = grow_triangle(x, uv, &rates(1.0, 1.0, 1.0, 1.0, DVec2::Y), 0.2, theta0);
        for k in 0..3 {
            assert!(
                (g.half_angles[k] - 0.5 * theta0[k]).abs() < 1e-12,
                "edge {k}: {} vs {}",
                g.half_angles[k],
                0.5 * theta0[k]
            );
        }
    }

    /// The circumcentre of a triangle in 3D.
    fn circumcentre(a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
        let (ab, ac) = (b - a, c - a);
        let n = ab.cross(ac);
        a + (n.cross(ab) * ac.length_squared() + ac.cross(n) * ab.length_squared())
            / (2.0 * n.length_squared())
    }

    #[test]
    fn isotropic_inner_growth_gives_the_exact_angles_of_a_sphere_on_irregular_triangles() {
        // Triangles inscribed in a sphere of curvature kappa meet at the
        // angle between their normals, which pass through their
        // circumcentres: kappa times the circumcentres' distance (to first
        // order). The paper's rule uses the barycentres instead and is off by
        // tens of percent on such triangles.
        let mut mesh = anthesis_mesh::generate::flat_sheet(4.0, 5.0, 6, 7);
        let mut rng = TestRng(3);
        for (p, uv) in mesh.positions.iter_mut().zip(&mut mesh.uvs) {
            let (a, b) = (rng.centred(), rng.centred());
            *p += DVec3::new(a, b, 0.0) * 0.4;
            *uv = DVec2::new(p.x / 4.0, p.y / 5.0);
        }
        let topology = Topology::build(&mesh).expect("manifold");
        let (thickness, excess) = (0.2, 1e-4);
        let kappa = excess / thickness;
        let per_triangle =
            vec![rates(1.0, 1.0, 1.0 + excess, 1.0 + excess, DVec2::Y); mesh.triangles.len()];
        let mut lengths = vec![0.0; topology.edges.len()];
        let mut angles = vec![0.0; topology.edges.len()];
        let mut worst_paper: f64 = 0.0;
        for rule in [BendRule::Curvature, BendRule::InnerTriangle] {
            let model = GrowthModel {
                bend_rule: rule,
                ..GrowthModel::new(thickness)
            };
            RegionalGrowth::default().grow(
                &mesh.positions,
                &mesh.uvs,
                &mesh.triangles,
                &topology,
                &per_triangle,
                &model,
                &mut lengths,
                &mut angles,
            );
            for (e, edge) in topology.edges.iter().enumerate() {
                let (Some([i, j, k, l]), Some(right)) = (edge.hinge(), edge.right) else {
                    continue;
                };
                let x = |v: u32| mesh.positions[v as usize];
                let c_left = circumcentre(x(i), x(j), x(k));
                let c_right = circumcentre(x(j), x(i), x(l));
                let across = DVec3::Z.cross(x(j) - x(i)).normalize();
                let exact = kappa * (c_left - c_right).dot(across);
                let error = (angles[e] - exact).abs() / exact.abs().max(kappa * 0.1);
                match rule {
                    BendRule::Curvature => assert!(
                        error < 1e-3,
                        "edge {e} (triangles {} {}): {} vs exact {exact}",
                        edge.left.triangle,
                        right.triangle,
                        angles[e]
                    ),
                    BendRule::InnerTriangle => worst_paper = worst_paper.max(error),
                }
            }
        }
        assert!(
            worst_paper > 0.1,
            "the paper's rule is off by {worst_paper} at most here"
        );
    }

    #[test]
    fn grown_lengths_are_those_of_the_scaled_triangle() {
        let mut rng = TestRng(5);
        let mut rand = || rng.centred();
        for _ in 0..100 {
            let x = [0; 3].map(|_| DVec3::new(rand(), rand(), rand()));
            let uv = [0; 3].map(|_| DVec2::new(rand(), rand()));
            let frame = TriangleFrame::new(x, uv, DVec2::new(rand(), rand()));
            let (e, w) = (1.0 + rand(), 1.0 + rand());
            let scaled = frame.scale(x, e, w);
            let lengths = frame.grown_lengths(x, e, w);
            for k in 0..3 {
                let expected = (scaled[(k + 1) % 3] - scaled[k]).length();
                assert!(
                    (lengths[k] - expected).abs() < 1e-12 * expected,
                    "side {k}: {} vs {expected}",
                    lengths[k]
                );
            }
        }
    }

    /// The curvature rule's hinge angle as first written: the hinge
    /// unfolded flat about the edge's midpoint, each corner lifted onto the
    /// height field, and the dihedral angle of the lifted hinge measured
    /// like any other (`dihedral_angle`); `curvature_hinge_angle` is its
    /// closed form.
    fn lifted_hinge_angle(x: [DVec3; 4], sides: [&TriangleBend; 2], angle_from: f64) -> f64 {
        let [xi, xj, xk, xl] = x;
        let edge = xj - xi;
        let along_edge = edge / edge.length();
        let n_left = edge.cross(xk - xi).normalize();
        let n_right = (xi - xj).cross(xl - xj).normalize();
        let y_left = n_left.cross(along_edge);
        let y_right = n_right.cross(along_edge);
        let mid = 0.5 * (xi + xj);
        let flat = |p: DVec3, y: DVec3| DVec2::new((p - mid).dot(along_edge), (p - mid).dot(y));
        let points = [
            flat(xi, y_left),
            flat(xj, y_left),
            flat(xk, y_left),
            flat(xl, y_right),
        ];
        let tensor = |b: &TriangleBend, y: DVec3| {
            let across = b.normal.cross(b.along);
            let d = DVec2::new(b.along.dot(along_edge), b.along.dot(y));
            let w = DVec2::new(across.dot(along_edge), across.dot(y));
            [
                b.kappa_along * d.x * d.x + b.kappa_across * w.x * w.x,
                b.kappa_along * d.x * d.y + b.kappa_across * w.x * w.y,
                b.kappa_along * d.y * d.y + b.kappa_across * w.y * w.y,
            ]
        };
        let (kl, kr) = (tensor(sides[0], y_left), tensor(sides[1], y_right));
        let k = [0, 1, 2].map(|c| 0.5 * (kl[c] + kr[c]));
        let increment = dihedral_angle(points.map(|p| {
            p.extend(-0.5 * (k[0] * p.x * p.x + 2.0 * k[1] * p.x * p.y + k[2] * p.y * p.y))
        }));
        let carry = |b: &TriangleBend, y: DVec3| {
            let across = b.normal.cross(b.along);
            DVec2::new(b.e_in * y.dot(b.along), b.w_in * y.dot(across)).length()
        };
        let carried = 0.5 * (carry(sides[0], y_left) + carry(sides[1], y_right));
        angle_from * carried + increment
    }

    #[test]
    fn hinge_angle_closed_form_matches_the_lifted_hinge() {
        let mut rng = TestRng(11);
        let mut rand = || rng.centred();
        let mut checked = 0;
        for case in 0..400 {
            // A hinge bent by up to ±2.5 rad, corners jittered, the edge
            // anywhere along x.
            let bend = 5.0 * rand();
            let x = [
                DVec3::new(rand(), rand(), rand()) * 0.3,
                DVec3::new(1.0 + rand(), rand(), rand()) * 0.3 + DVec3::X,
                DVec3::new(0.5 + rand(), 1.0, 0.3 * rand()),
                DVec3::new(0.5 + rand(), -bend.cos(), -bend.sin()),
            ];
            let side =
                |n: DVec3, r: DVec3, scale: f64, rand: &mut dyn FnMut() -> f64| TriangleBend {
                    normal: n,
                    along: (r - n * r.dot(n)).normalize(),
                    kappa_along: scale * rand(),
                    kappa_across: scale * rand(),
                    e_in: 1.0 + 0.2 * rand(),
                    w_in: 1.0 + 0.2 * rand(),
                };
            let [xi, xj, xk, xl] = x;
            let n_left = (xj - xi).cross(xk - xi).normalize();
            let n_right = (xi - xj).cross(xl - xj).normalize();
            // Small curvatures like growth's and large ones, where the
            // lifted hinge is far from flat.
            let scale = if case % 2 == 0 { 0.05 } else { 3.0 };
            let r1 = DVec3::new(rand(), rand(), rand());
            let left = side(n_left, r1, scale, &mut rand);
            let r2 = DVec3::new(rand(), rand(), rand());
            let right = side(n_right, r2, scale, &mut rand);
            let sides = [&left, &right];
            let dihedral = dihedral_angle(x);
            for (from, rest) in [(dihedral, None), (0.4, Some(0.4))] {
                let closed = curvature_hinge_angle(x, sides, rest);
                let lifted = lifted_hinge_angle(x, sides, from);
                assert!(
                    (closed - lifted).abs() < 1e-12 * (1.0 + lifted.abs()),
                    "case {case}: closed form {closed}, lifted hinge {lifted}"
                );
                checked += 1;
            }
        }
        assert_eq!(checked, 800);
    }

    #[test]
    fn rest_lengths_accumulate_the_growth_while_shape_lengths_forget_it() {
        // A sheet held in its bud shape (the solver never moves it) and
        // grown n steps by e along D and w across: growing from the rest
        // triangles gives each edge the bud edge scaled by e^n along D and
        // w^n across; growing from the shape gives the bud scaled once.
        let mut mesh = anthesis_mesh::generate::flat_sheet(3.0, 4.0, 5, 6);
        let mut rng = TestRng(7);
        for (p, uv) in mesh.positions.iter_mut().zip(&mut mesh.uvs) {
            *p += DVec3::new(rng.centred(), rng.centred(), 0.0) * 0.2;
            // UVs follow the positions, so D is one direction in every
            // triangle and the scaled triangles fit together.
            *uv = DVec2::new(p.x / 3.0 + 0.5, p.y / 4.0);
        }
        let topology = Topology::build(&mesh).expect("manifold");
        let direction = DVec2::new(0.4, 1.0);
        let (e, w, steps) = (1.05, 0.98, 12);
        let per_triangle = vec![rates(e, w, e, w, direction); mesh.triangles.len()];
        let scaled = |e: f64, w: f64| -> Vec<f64> {
            // Each edge's expected length: the mean over its triangles of
            // that triangle scaled by (e, w) in its own growth frame.
            let mut sum = vec![0.0; topology.edges.len()];
            let mut count = vec![0.0; topology.edges.len()];
            for (t, tri) in mesh.triangles.iter().enumerate() {
                let x = corners(&mesh.positions, *tri);
                let frame = TriangleFrame::new(x, corners(&mesh.uvs, *tri), direction);
                let lengths = frame.grown_lengths(x, e, w);
                for k in 0..3 {
                    let edge = topology.triangle_edges[t][k] as usize;
                    sum[edge] += lengths[k];
                    count[edge] += 1.0;
                }
            }
            sum.iter().zip(&count).map(|(s, c)| s / c).collect()
        };
        for (base, expected) in [
            (LengthBase::Rest, scaled(e.powi(steps), w.powi(steps))),
            (LengthBase::Shape, scaled(e, w)),
        ] {
            let model = GrowthModel {
                length_base: base,
                ..GrowthModel::new(0.2)
            };
            let mut lengths: Vec<f64> = topology
                .edges
                .iter()
                .map(|edge| {
                    let [a, b] = edge.vertices.map(|v| v as usize);
                    mesh.positions[a].distance(mesh.positions[b])
                })
                .collect();
            let mut angles = vec![0.0; topology.edges.len()];
            let mut growth = RegionalGrowth::default();
            for _ in 0..steps {
                growth.grow(
                    &mesh.positions,
                    &mesh.uvs,
                    &mesh.triangles,
                    &topology,
                    &per_triangle,
                    &model,
                    &mut lengths,
                    &mut angles,
                );
            }
            for (edge, (got, want)) in lengths.iter().zip(&expected).enumerate() {
                assert!(
                    (got - want).abs() < 1e-9 * want,
                    "{base:?}, edge {edge}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn a_collapsed_edge_keeps_the_angle_it_grows_from() {
        let side = TriangleBend {
            normal: DVec3::Z,
            along: DVec3::Y,
            kappa_along: 0.1,
            kappa_across: 0.1,
            e_in: 1.1,
            w_in: 1.1,
        };
        let x = [DVec3::X, DVec3::X, DVec3::Y, -DVec3::Y];
        assert_eq!(curvature_hinge_angle(x, [&side, &side], Some(0.3)), 0.3);
        assert_eq!(curvature_hinge_angle(x, [&side, &side], None), 0.0);
    }

    #[test]
    fn faster_inner_growth_bends_outwards() {
        let (x, uv) = right_triangle();
        let g = grow_triangle(x, uv, &rates(1.0, 1.0, 1.1, 1.1, DVec2::Y), 0.2, [0.0; 3]);
        assert!(
            g.half_angles.iter().all(|&a| a > 0.0),
            "{:?}",
            g.half_angles
        );
        let g = grow_triangle(x, uv, &rates(1.1, 1.1, 1.0, 1.0, DVec2::Y), 0.2, [0.0; 3]);
        assert!(
            g.half_angles.iter().all(|&a| a < 0.0),
            "{:?}",
            g.half_angles
        );
    }
}

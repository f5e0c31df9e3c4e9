//! Regional growth (paper §4): each triangle, copied as it is now, grows on
//! its own; the grown copies give the new rest lengths and rest angles.
//!
//! For a triangle `T` with growth direction `D` (the UV direction pushed
//! through the triangle's UV→3D map) and the in-plane `W = n x D`:
//! - `T'` scales `T` about its barycentre by the e-rate along `D` and the
//!   w-rate along `W`; each edge's new rest length is the mean of its
//!   triangles' grown lengths (eq. 3);
//! - the inner triangle `T_in` offsets each edge of `T` outwards in its plane
//!   by `s = thickness * tan(theta0 / 2)`, where `theta0` is that edge's
//!   dihedral angle *as it is now* (like the lengths, which grow from the
//!   current triangle; the paper's "current rest angle" would let targets
//!   the shape cannot reach pile up step after step until a triangle folds), intersects the offset lines and lifts the corners by
//!   `thickness` along the inner normal; `T_in'` grows with the inner rates;
//!   `s'` is the in-plane distance from the grown base edge to the midpoint of
//!   the grown inner edge, and the new rest angle of an edge is the sum over
//!   its triangles of `atan(s' / thickness)` (eq. 4).

use anthesis_mesh::Topology;

use crate::hinge::dihedral_angle;
use glam::{DVec2, DVec3};

/// Growth rates of one triangle for one step (`1 + dg * map value`, so 1
/// means no growth) and its growth direction in UV.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrowthRates {
    pub e: f64,
    pub w: f64,
    pub e_in: f64,
    pub w_in: f64,
    pub direction_in_uv: DVec2,
}

/// The largest half-angle used to offset an edge for the inner triangle;
/// beyond it `tan` explodes (a fold of nearly 180° between two triangles).
const MAX_HALF_ANGLE: f64 = 1.4;

/// Reusable buffers for [`RegionalGrowth::grow`].
#[derive(Debug, Default, Clone)]
pub struct RegionalGrowth {
    length_sum: Vec<f64>,
    length_count: Vec<u8>,
    angle_sum: Vec<f64>,
    angle_now: Vec<f64>,
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
        thickness: f64,
        rest_lengths: &mut [f64],
        rest_angles: &mut [f64],
    ) {
        let edges = topology.edges.len();
        self.length_sum.clear();
        self.length_sum.resize(edges, 0.0);
        self.length_count.clear();
        self.length_count.resize(edges, 0);
        self.angle_sum.clear();
        self.angle_sum.resize(edges, 0.0);
        self.angle_now.clear();
        self.angle_now.extend(topology.edges.iter().map(|e| {
            e.hinge()
                .map_or(0.0, |h| dihedral_angle(h.map(|p| positions[p as usize])))
        }));

        for (t, tri) in triangles.iter().enumerate() {
            let x = tri.map(|i| positions[i as usize]);
            let uv = tri.map(|i| uvs[i as usize]);
            let edge_ids = topology.triangle_edges[t];
            let theta0 = edge_ids.map(|e| self.angle_now[e as usize]);
            let grown = grow_triangle(x, uv, &rates[t], thickness, theta0);
            for k in 0..3 {
                let e = edge_ids[k] as usize;
                self.length_sum[e] += grown.lengths[k];
                self.length_count[e] += 1;
                self.angle_sum[e] += grown.half_angles[k];
            }
        }
        for e in 0..edges {
            rest_lengths[e] = self.length_sum[e] / f64::from(self.length_count[e].max(1));
            rest_angles[e] = if topology.edges[e].is_boundary() {
                0.0
            } else {
                self.angle_sum[e]
            };
        }
    }
}

/// What one grown triangle contributes to its edges `(t0,t1)`, `(t1,t2)`,
/// `(t2,t0)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrownTriangle {
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
    let normal = (x[1] - x[0]).cross(x[2] - x[0]).normalize_or_zero();
    let along = growth_direction(x, uv, rates.direction_in_uv, normal);
    let across = normal.cross(along);
    let scale = |points: [DVec3; 3], e: f64, w: f64| {
        let centre = (points[0] + points[1] + points[2]) / 3.0;
        points.map(|p| {
            let d = p - centre;
            centre
                + along * (e * d.dot(along))
                + across * (w * d.dot(across))
                + normal * d.dot(normal)
        })
    };

    let grown = scale(x, rates.e, rates.w);
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
    let inner_grown = scale(inner, rates.e_in, rates.w_in);

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

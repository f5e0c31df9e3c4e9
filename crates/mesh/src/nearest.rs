//! Nearest points on a triangle surface: what collisions between organs
//! and the geometric checks of their results measure against.

use glam::DVec3;

/// The point of triangle `abc` nearest `p` and its barycentric weights
/// (the standard region test over the triangle's corners, edges and face;
/// small enough to write here rather than pull in a geometry crate).
#[inline]
pub fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> (DVec3, [f64; 3]) {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + ab * v, [1.0 - v, v, 0.0]);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + ac * w, [1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * w, [0.0, 1.0 - w, w]);
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    (a + ab * v + ac * w, [1.0 - v - w, v, w])
}

/// Whether the point of triangle `corners` (vertex indices) with
/// barycentric `weights` lies on the mesh's rim: on an edge or corner of
/// the triangle every corner of which it leans on is a `rim` (boundary)
/// vertex. A point inside the triangle, or on an edge with an interior
/// corner, is not (an edge between two rim vertices across the mesh is
/// taken as rim: meshes here do not have them).
#[inline]
pub fn on_rim(corners: [u32; 3], weights: [f64; 3], rim: &[bool]) -> bool {
    weights.iter().any(|&w| w <= 0.0)
        && (0..3).all(|k| weights[k] <= 0.0 || rim[corners[k] as usize])
}

/// The triangles around each vertex (indices into `triangles`, ascending).
pub fn triangles_around(triangles: &[[u32; 3]], vertex_count: usize) -> Vec<Vec<u32>> {
    let mut around = vec![Vec::new(); vertex_count];
    for (t, tri) in triangles.iter().enumerate() {
        for &v in tri {
            around[v as usize].push(t as u32);
        }
    }
    around
}

/// The triangles around each vertex of a mesh, and the ring of triangles
/// just beyond them: what the nearest point on a surface is looked for
/// among, near the nearest vertex. Both depend only on the triangles, so
/// an organ builds them once; looking the outer ring up in every contact
/// search (collecting, sorting and deduplicating the triangles around the
/// corners) was a tenth of that search's time.
#[derive(Debug, Clone, Default)]
pub struct TriangleRings {
    /// Vertex `v`'s triangles are `triangles[start[v]..beyond[v]]`, the
    /// ring beyond them `triangles[beyond[v]..start[v + 1]]`.
    start: Vec<u32>,
    beyond: Vec<u32>,
    triangles: Vec<u32>,
}

impl TriangleRings {
    /// The rings of `triangles` over `vertex_count` vertices.
    pub fn new(triangles: &[[u32; 3]], vertex_count: usize) -> TriangleRings {
        let around = triangles_around(triangles, vertex_count);
        let mut rings = TriangleRings {
            start: Vec::with_capacity(vertex_count + 1),
            beyond: Vec::with_capacity(vertex_count),
            triangles: Vec::new(),
        };
        let mut ring = Vec::new();
        for own in &around {
            rings.start.push(rings.triangles.len() as u32);
            rings.triangles.extend_from_slice(own);
            rings.beyond.push(rings.triangles.len() as u32);
            ring.clear();
            ring.extend(
                own.iter()
                    .flat_map(|&t| triangles[t as usize])
                    .flat_map(|v| around[v as usize].iter().copied())
                    .filter(|t| own.binary_search(t).is_err()),
            );
            ring.sort_unstable();
            ring.dedup();
            rings.triangles.extend_from_slice(&ring);
        }
        rings.start.push(rings.triangles.len() as u32);
        rings
    }

    /// The triangles around vertex `v` (ascending).
    #[inline]
    pub fn around(&self, v: u32) -> &[u32] {
        let v = v as usize;
        &self.triangles[self.start[v] as usize..self.beyond[v] as usize]
    }

    /// The triangles around the corners of `v`'s triangles that are not
    /// around `v` itself (ascending): the next ring out.
    #[inline]
    pub fn beyond(&self, v: u32) -> &[u32] {
        let v = v as usize;
        &self.triangles[self.beyond[v] as usize..self.start[v + 1] as usize]
    }
}

/// A point of the curved surface that Phong tessellation puts through a
/// triangle from its corners' unit normals: the flat point with
/// barycentric `weights`, moved half way towards the blend (same weights)
/// of its projections onto the corners' tangent planes. The projections
/// alone overshoot a sphere by about as much as the flat triangle sags
/// (both are r·θ²/2 to leading order), so the half-way blend (Phong's
/// shape factor 1/2) cancels the leading error: on a mesh sampled from a
/// smooth surface it lies far closer to that surface than the flat
/// triangle (checked on a sphere in the tests), and it still passes
/// through the corners. Collisions use it so that when organs meet does
/// not depend on how coarse their meshes are.
#[inline]
pub fn phong_point(corners: [DVec3; 3], normals: [DVec3; 3], weights: [f64; 3]) -> DVec3 {
    let flat: DVec3 = (0..3).map(|k| corners[k] * weights[k]).sum();
    let projected: DVec3 = (0..3)
        .map(|k| weights[k] * (flat - normals[k] * (flat - corners[k]).dot(normals[k])))
        .sum();
    0.5 * (flat + projected)
}

/// The winding number of a closed triangle surface around `x`: 1 inside
/// a surface wound around its outward normals, 0 outside (−1 inside one
/// wound inwards), from the solid angle of each triangle (Van Oosterom and
/// Strackee's formula). The geometric inside test of the collision checks.
pub fn winding_number(x: DVec3, positions: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    let mut total = 0.0;
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize] - x);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let numerator = a.dot(b.cross(c));
        let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        total += 2.0 * numerator.atan2(denominator);
    }
    total / (4.0 * std::f64::consts::PI)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_closest_point_is_no_farther_than_any_point_of_the_triangle() {
        let (a, b, c) = (
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.1, 0.0),
            DVec3::new(0.3, 1.5, 0.4),
        );
        for k in 0..200 {
            let t = k as f64 * 0.731;
            let p = DVec3::new(3.0 * t.sin(), 2.5 * (1.3 * t).cos(), (0.7 * t).sin());
            let (q, w) = closest_point_on_triangle(p, a, b, c);
            assert!(w.iter().all(|&x| (-1e-12..=1.0 + 1e-12).contains(&x)));
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            assert!(q.distance(a * w[0] + b * w[1] + c * w[2]) < 1e-12);
            for i in 0..=20 {
                for j in 0..=(20 - i) {
                    let (u, v) = (i as f64 / 20.0, j as f64 / 20.0);
                    let s = a * (1.0 - u - v) + b * u + c * v;
                    assert!(p.distance(q) <= p.distance(s) + 1e-12, "{p} {q} {s}");
                }
            }
        }
    }

    #[test]
    fn a_point_is_on_the_rim_only_on_an_edge_or_corner_of_rim_vertices() {
        // Vertices 0 and 1 on the rim, 2 inside.
        let rim = [true, true, false];
        assert!(on_rim([0, 1, 2], [0.3, 0.7, 0.0], &rim));
        assert!(on_rim([0, 1, 2], [1.0, 0.0, 0.0], &rim));
        assert!(!on_rim([0, 1, 2], [0.3, 0.0, 0.7], &rim));
        assert!(!on_rim([0, 1, 2], [0.2, 0.3, 0.5], &rim));
        assert!(!on_rim([0, 1, 2], [0.0, 0.0, 1.0], &rim));
    }

    #[test]
    fn triangles_around_lists_each_triangle_at_its_three_corners() {
        let around = triangles_around(&[[0, 1, 2], [2, 1, 3]], 5);
        assert_eq!(
            around,
            vec![vec![0], vec![0, 1], vec![0, 1], vec![1], vec![]]
        );
    }

    #[test]
    fn the_ring_beyond_a_vertex_holds_the_triangles_around_its_neighbours_only() {
        // A strip of four triangles over vertices 0..6:
        // 0-2-4
        // |/|/|
        // 1-3-5
        let triangles = [[0, 1, 2], [2, 1, 3], [2, 3, 4], [4, 3, 5]];
        let rings = TriangleRings::new(&triangles, 7);
        assert_eq!(rings.around(0), &[0]);
        assert_eq!(rings.beyond(0), &[1, 2]);
        assert_eq!(rings.around(2), &[0, 1, 2]);
        assert_eq!(rings.beyond(2), &[3]);
        assert_eq!(rings.around(5), &[3]);
        assert_eq!(rings.beyond(5), &[1, 2]);
        assert!(rings.around(6).is_empty() && rings.beyond(6).is_empty());
    }

    #[test]
    fn phong_points_lie_much_closer_to_a_sphere_than_flat_ones() {
        // A triangle of a unit sphere with exact normals: the flat
        // triangle sags inside the sphere, Phong's surface far less.
        let r = 1.0;
        for h in [0.4, 0.2, 0.1] {
            let corners = [
                DVec3::new(0.0, 0.0, r),
                DVec3::new(h, 0.0, r).normalize() * r,
                DVec3::new(0.0, h, r).normalize() * r,
            ];
            let normals = corners.map(|c| c / r);
            for w in [
                [1.0 / 3.0; 3],
                [0.5, 0.5, 0.0],
                [0.2, 0.1, 0.7],
                [0.0, 0.3, 0.7],
            ] {
                let flat: DVec3 = (0..3).map(|k| corners[k] * w[k]).sum();
                let flat_error = (flat.length() - r).abs();
                let phong_error = (phong_point(corners, normals, w).length() - r).abs();
                assert!(
                    phong_error < 0.1 * flat_error,
                    "h {h} at {w:?}: {phong_error} vs {flat_error}"
                );
            }
            // Through the corners, with their normals.
            for k in 0..3 {
                let mut at = [0.0; 3];
                at[k] = 1.0;
                assert!(phong_point(corners, normals, at).distance(corners[k]) < 1e-15);
            }
        }
    }

    #[test]
    fn the_winding_number_of_a_cube_is_one_inside_and_zero_outside() {
        // A unit cube wound around its outward normals.
        let positions: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let triangles: Vec<[u32; 3]> = quads
            .iter()
            .flat_map(|[a, b, c, d]| [[*a, *b, *c], [*a, *c, *d]])
            .collect();
        let inside = winding_number(DVec3::splat(0.3), &positions, &triangles);
        let outside = winding_number(DVec3::new(1.4, 0.5, 0.5), &positions, &triangles);
        assert!((inside - 1.0).abs() < 1e-12, "{inside}");
        assert!(outside.abs() < 1e-12, "{outside}");
        let flipped: Vec<[u32; 3]> = triangles.iter().map(|[a, b, c]| [*a, *c, *b]).collect();
        assert!((winding_number(DVec3::splat(0.5), &positions, &flipped) + 1.0).abs() < 1e-12);
    }
}

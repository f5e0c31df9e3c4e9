//! Mesh quality measures and a self-intersection check.

use std::collections::HashMap;

use anthesis_mesh::Mesh;
use glam::{DVec3, IVec3};

/// Shape statistics of a triangle mesh (3D, angles in degrees).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshQuality {
    /// The smallest interior angle of any triangle.
    pub min_angle_deg: f64,
    /// The triangle that has it.
    pub min_angle_triangle: usize,
    /// The largest interior angle of any triangle.
    pub max_angle_deg: f64,
    /// Mean length of the distinct edges.
    pub mean_edge: f64,
    /// Standard deviation of the edge lengths divided by their mean.
    pub edge_spread: f64,
    /// Fraction of triangles whose angles are all within 15° of 60°.
    pub near_equilateral: f64,
    /// Number of vertices.
    pub vertices: usize,
    /// Number of triangles.
    pub triangles: usize,
    /// Number of distinct edges.
    pub edges: usize,
}

/// Measures `mesh`. Degenerate triangles count with the angles they have
/// (a zero-length side gives a 0° angle); an empty mesh gives zeros.
pub fn quality(mesh: &Mesh) -> MeshQuality {
    let mut min_angle = f64::INFINITY;
    let mut min_angle_triangle = 0;
    let mut max_angle: f64 = 0.0;
    let mut near = 0usize;
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(3 * mesh.triangles.len());
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let p = mesh.triangle_positions(t);
        let angles = (0..3).map(|k| {
            let (a, b, c) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
            (b - a).angle_between(c - a).to_degrees()
        });
        let (lo, hi) = angles.fold((f64::INFINITY, 0.0f64), |(lo, hi), a| {
            (lo.min(a), hi.max(a))
        });
        if lo < min_angle {
            min_angle = lo;
            min_angle_triangle = t;
        }
        max_angle = max_angle.max(hi);
        if lo >= 45.0 && hi <= 75.0 {
            near += 1;
        }
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            edges.push((a.min(b), a.max(b)));
        }
    }
    // Sorted, so the sums (and the result) do not depend on any hashing.
    edges.sort_unstable();
    edges.dedup();
    let lengths: Vec<f64> = edges
        .iter()
        .map(|&(a, b)| mesh.positions[a as usize].distance(mesh.positions[b as usize]))
        .collect();
    let count = lengths.len().max(1) as f64;
    let mean = lengths.iter().sum::<f64>() / count;
    let variance = lengths.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / count;
    MeshQuality {
        min_angle_deg: if mesh.triangles.is_empty() {
            0.0
        } else {
            min_angle
        },
        min_angle_triangle,
        max_angle_deg: max_angle,
        mean_edge: mean,
        edge_spread: if mean > 0.0 {
            variance.sqrt() / mean
        } else {
            0.0
        },
        near_equilateral: near as f64 / mesh.triangles.len().max(1) as f64,
        vertices: mesh.positions.len(),
        triangles: mesh.triangles.len(),
        edges: edges.len(),
    }
}

/// The first pair of triangles that share no vertex and cross each other
/// (an edge of one passes through the interior of the other), if any.
/// Triangles are bucketed in a uniform grid of about twice the mean edge
/// length, so the cost grows linearly with the mesh size.
pub fn find_self_intersection(mesh: &Mesh) -> Option<[usize; 2]> {
    self_intersections(mesh).first().copied()
}

/// Every pair of triangles that share no vertex and cross each other, each
/// as `[lower, higher]` index, in increasing order (see
/// [`find_self_intersection`]).
pub fn self_intersections(mesh: &Mesh) -> Vec<[usize; 2]> {
    let mean_edge = quality(mesh).mean_edge;
    if mesh.triangles.is_empty() || mean_edge.is_nan() || mean_edge <= 0.0 {
        return Vec::new();
    }
    let cell = 2.0 * mean_edge;
    let cell_of = |p: DVec3| (p / cell).floor().as_ivec3();
    let mut grid: HashMap<IVec3, Vec<usize>> = HashMap::new();
    for t in 0..mesh.triangles.len() {
        let p = mesh.triangle_positions(t);
        let lo = cell_of(p[0].min(p[1]).min(p[2]));
        let hi = cell_of(p[0].max(p[1]).max(p[2]));
        for x in lo.x..=hi.x {
            for y in lo.y..=hi.y {
                for z in lo.z..=hi.z {
                    grid.entry(IVec3::new(x, y, z)).or_default().push(t);
                }
            }
        }
    }
    let mut pairs = Vec::new();
    for list in grid.values() {
        for (n, &s) in list.iter().enumerate() {
            for &t in &list[n + 1..] {
                let (ts, tt) = (mesh.triangles[s], mesh.triangles[t]);
                if ts.iter().any(|v| tt.contains(v)) {
                    continue;
                }
                let (ps, pt) = (mesh.triangle_positions(s), mesh.triangle_positions(t));
                if triangles_cross(&ps, &pt) {
                    pairs.push([s.min(t), s.max(t)]);
                }
            }
        }
    }
    // Deterministic: a pair in several cells is listed once, in order.
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}

/// How far two crossing triangles `[s, t]` of `mesh` reach through each
/// other: for each, how far the fewer of its corners lie beyond the
/// other's plane; the smaller of the two. Two surfaces that touch and cut
/// each other by a sliver give a small value, one passing through the
/// other a large one (its triangles crossing the other's through their
/// middles). Zero for triangles that do not cross (or a degenerate one).
pub fn crossing_depth(mesh: &Mesh, [s, t]: [usize; 2]) -> f64 {
    let through = |a: usize, b: usize| {
        let [p, q, r] = mesh.triangle_positions(b);
        let Some(normal) = (q - p).cross(r - p).try_normalize() else {
            return 0.0;
        };
        let side = mesh.triangle_positions(a).map(|c| (c - p).dot(normal));
        let above = side.iter().fold(0.0, |m: f64, d| m.max(*d));
        let below = side.iter().fold(0.0, |m: f64, d| m.max(-*d));
        above.min(below)
    };
    through(s, t).min(through(t, s))
}

/// Whether two triangles cross: an edge of either passes through the other.
fn triangles_cross(a: &[DVec3; 3], b: &[DVec3; 3]) -> bool {
    (0..3).any(|k| segment_hits_triangle(a[k], a[(k + 1) % 3], b))
        || (0..3).any(|k| segment_hits_triangle(b[k], b[(k + 1) % 3], a))
}

/// Möller–Trumbore test of the segment `p -> q` against a triangle's
/// interior (touching at the very edges is not a hit).
fn segment_hits_triangle(p: DVec3, q: DVec3, tri: &[DVec3; 3]) -> bool {
    const EPS: f64 = 1e-9;
    let d = q - p;
    let e1 = tri[1] - tri[0];
    let e2 = tri[2] - tri[0];
    let h = d.cross(e2);
    let det = e1.dot(h);
    let scale = d.length() * e1.length() * e2.length();
    if det.abs() <= EPS * scale {
        return false; // parallel
    }
    let s = p - tri[0];
    let b1 = s.dot(h) / det;
    let qv = s.cross(e1);
    let b2 = d.dot(qv) / det;
    let t = e2.dot(qv) / det;
    b1 > EPS && b2 > EPS && b1 + b2 < 1.0 - EPS && t > EPS && t < 1.0 - EPS
}

#[cfg(test)]
mod tests {
    use super::*;
    use anthesis_mesh::generate::flat_sheet;

    #[test]
    fn regular_grid_quality_is_exact() {
        // 1 x 1 cells split along one diagonal each: angles 45/45/90.
        let m = flat_sheet(3.0, 2.0, 4, 3);
        let q = quality(&m);
        assert_eq!(q.vertices, 12);
        assert_eq!(q.triangles, 12);
        assert_eq!(q.edges, 12 + 12 - 1);
        assert!((q.min_angle_deg - 45.0).abs() < 1e-9);
        assert!((q.max_angle_deg - 90.0).abs() < 1e-9);
        assert_eq!(q.near_equilateral, 0.0);
        // 17 unit edges and 6 diagonals of sqrt(2).
        let mean = (17.0 + 6.0 * 2f64.sqrt()) / 23.0;
        assert!((q.mean_edge - mean).abs() < 1e-12);
    }

    #[test]
    fn a_sliver_is_shallow_and_a_pass_through_is_deep() {
        // A unit triangle in the XY plane and one standing across it in the
        // plane y = 0.3: pushed down through it by `reach`, it crosses it by
        // `reach`, and is crossed by it 0.3 from the flat one's nearer side.
        let crossing = |reach: f64| {
            let mesh = Mesh {
                positions: vec![
                    DVec3::new(0.0, 0.0, 0.0),
                    DVec3::new(1.0, 0.0, 0.0),
                    DVec3::new(0.0, 1.0, 0.0),
                    DVec3::new(0.1, 0.3, -reach),
                    DVec3::new(0.5, 0.3, -reach),
                    DVec3::new(0.3, 0.3, 1.0),
                ],
                uvs: vec![glam::DVec2::ZERO; 6],
                triangles: vec![[0, 1, 2], [3, 4, 5]],
            };
            assert_eq!(self_intersections(&mesh), vec![[0, 1]]);
            crossing_depth(&mesh, [0, 1])
        };
        assert!((crossing(0.02) - 0.02).abs() < 1e-12);
        assert!((crossing(0.4) - 0.3).abs() < 1e-12);
        // Lifted clear of the flat one, it does not cross: depth 0.
        let apart = Mesh {
            positions: vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(0.1, 0.3, 0.1),
                DVec3::new(0.5, 0.3, 0.1),
                DVec3::new(0.3, 0.3, 1.0),
            ],
            uvs: vec![glam::DVec2::ZERO; 6],
            triangles: vec![[0, 1, 2], [3, 4, 5]],
        };
        assert!(self_intersections(&apart).is_empty());
        assert_eq!(crossing_depth(&apart, [0, 1]), 0.0);
    }

    #[test]
    fn crossing_sheets_are_found_and_a_flat_sheet_is_clean() {
        let m = flat_sheet(4.0, 4.0, 5, 5);
        assert_eq!(find_self_intersection(&m), None);
        // Add a second sheet piercing the first, standing in the XZ plane.
        let mut both = m.clone();
        let offset = both.positions.len() as u32;
        let other = anthesis_mesh::generate::parametric_grid(3, 3, |uv| {
            DVec3::new(uv.x * 2.0 - 1.3, 1.7, uv.y * 2.0 - 1.1)
        });
        both.positions.extend(other.positions);
        both.uvs.extend(other.uvs);
        both.triangles
            .extend(other.triangles.iter().map(|t| t.map(|i| i + offset)));
        assert!(find_self_intersection(&both).is_some());
        // Every crossing pair once, in order, each one triangle of each sheet.
        let first_sheet = m.triangles.len();
        let pairs = self_intersections(&both);
        assert!(pairs.len() >= 2, "{pairs:?}");
        assert_eq!(pairs.first().copied(), find_self_intersection(&both));
        assert!(pairs.windows(2).all(|w| w[0] < w[1]));
        assert!(
            pairs
                .iter()
                .all(|&[a, b]| a < first_sheet && b >= first_sheet)
        );
    }
}

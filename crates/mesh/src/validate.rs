//! Mesh validation: everything the physics and the UV-based growth maps
//! rely on, checked once at import with an error that names the offending
//! element.

use crate::error::Space;
use crate::{Mesh, MeshError, Topology};

/// A triangle counts as degenerate if its area is at most this times the
/// squared mean edge length (of the same space), which makes the test
/// independent of the mesh's scale.
pub const DEGENERATE_AREA_RATIO: f64 = 1e-12;

/// The largest size of a position coordinate or a UV component. Far beyond
/// any organ in any unit (a 5 cm petal is 50,000 in micrometres); values
/// past it come from a broken exporter or a hand edit, and squared (areas,
/// energies) they would lose all precision.
pub const MAX_COORDINATE: f64 = 1e6;

/// Checks that `mesh` is a single, manifold, consistently oriented triangle
/// surface with one finite UV per vertex and no degenerate triangle, in 3D
/// or in UV, and no flipped UV triangle. Returns its edge topology.
///
/// The checks run in this order and the first failure is returned: empty
/// mesh, index out of range, repeated vertex in a triangle, UV count,
/// non-finite position, non-finite UV, position or UV beyond
/// [`MAX_COORDINATE`], unused vertex, zero area in 3D, zero
/// area in UV, non-manifold edge and inconsistent orientation (from
/// [`Topology::build`]), non-manifold vertex, flipped UV triangle, more than
/// one connected piece.
pub fn validate(mesh: &Mesh) -> Result<Topology, MeshError> {
    validate_with(mesh, true)
}

/// [`validate`] for a shape whose UVs do not matter yet (a scanned petal
/// before it is fitted and given UVs by convention): the same checks of the
/// triangles, positions and topology, none of the UVs (they must still be
/// one per vertex, e.g. all zero).
pub fn validate_shape(mesh: &Mesh) -> Result<Topology, MeshError> {
    validate_with(mesh, false)
}

fn validate_with(mesh: &Mesh, check_uvs: bool) -> Result<Topology, MeshError> {
    if mesh.triangles.is_empty() {
        return Err(MeshError::Empty);
    }
    let vertex_count = mesh.positions.len();
    check_indices(mesh)?;
    for (triangle, &[a, b, c]) in mesh.triangles.iter().enumerate() {
        if a == b || a == c {
            return Err(MeshError::RepeatedVertex {
                triangle,
                vertex: a,
            });
        }
        if b == c {
            return Err(MeshError::RepeatedVertex {
                triangle,
                vertex: b,
            });
        }
    }
    if mesh.uvs.len() != vertex_count {
        return Err(MeshError::UvCountMismatch {
            vertices: vertex_count,
            uvs: mesh.uvs.len(),
        });
    }
    if let Some(vertex) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(MeshError::NonFinitePosition { vertex });
    }
    if let Some(vertex) = mesh.uvs.iter().position(|uv| check_uvs && !uv.is_finite()) {
        return Err(MeshError::NonFiniteUv { vertex });
    }
    let too_large = |values: &[f64]| values.iter().copied().find(|v| v.abs() > MAX_COORDINATE);
    for (vertex, p) in mesh.positions.iter().enumerate() {
        if let Some(value) = too_large(&p.to_array()) {
            return Err(MeshError::CoordinateOutOfRange { vertex, value });
        }
    }
    for (vertex, uv) in mesh.uvs.iter().enumerate().filter(|_| check_uvs) {
        if let Some(value) = too_large(&uv.to_array()) {
            return Err(MeshError::UvOutOfRange { vertex, value });
        }
    }
    let mut used = vec![false; vertex_count];
    for &i in mesh.triangles.iter().flatten() {
        used[i as usize] = true;
    }
    if let Some(vertex) = used.iter().position(|&u| !u) {
        return Err(MeshError::UnusedVertex { vertex });
    }

    check_areas(mesh, Space::World)?;
    if check_uvs {
        check_areas(mesh, Space::Uv)?;
    }

    let topology = Topology::build(mesh)?;

    check_vertex_fans(mesh, &topology)?;
    if check_uvs {
        check_uv_orientation(mesh)?;
    }

    let pieces = count_pieces(mesh.triangles.len(), &topology);
    if pieces > 1 {
        return Err(MeshError::MultiplePieces { pieces });
    }
    Ok(topology)
}

/// Twice the signed area of triangle `t` in UV (positive when the corners
/// run counter-clockwise in UV).
fn doubled_signed_uv_area(mesh: &Mesh, t: usize) -> f64 {
    let [a, b, c] = mesh.triangle_uvs(t);
    (b - a).perp_dot(c - a)
}

/// Fails on the first triangle whose area in `space` is at most
/// [`DEGENERATE_AREA_RATIO`] times the squared mean edge length in `space`.
fn check_areas(mesh: &Mesh, space: Space) -> Result<(), MeshError> {
    let side_lengths = |t: usize| -> [f64; 3] {
        match space {
            Space::World => {
                let [a, b, c] = mesh.triangle_positions(t);
                [a.distance(b), b.distance(c), c.distance(a)]
            }
            Space::Uv => {
                let [a, b, c] = mesh.triangle_uvs(t);
                [a.distance(b), b.distance(c), c.distance(a)]
            }
        }
    };
    let area = |t: usize| -> f64 {
        match space {
            Space::World => mesh.triangle_area(t),
            Space::Uv => 0.5 * doubled_signed_uv_area(mesh, t).abs(),
        }
    };
    let triangle_count = mesh.triangles.len();
    let total_length: f64 = (0..triangle_count)
        .map(|t| side_lengths(t).iter().sum::<f64>())
        .sum();
    let mean_edge_length = total_length / (3 * triangle_count) as f64;
    let threshold = DEGENERATE_AREA_RATIO * mean_edge_length * mean_edge_length;
    for triangle in 0..triangle_count {
        let area = area(triangle);
        if area <= threshold {
            return Err(MeshError::DegenerateTriangle {
                triangle,
                space,
                area,
            });
        }
    }
    Ok(())
}

/// The triangles around each vertex must form a single fan: walking from
/// triangle to triangle across edges that contain the vertex must reach
/// all of them. Two fans that only touch at a vertex (a "bow tie") fail.
fn check_vertex_fans(mesh: &Mesh, topology: &Topology) -> Result<(), MeshError> {
    let vertex_count = mesh.positions.len();
    let mut triangles_at: Vec<Vec<u32>> = vec![Vec::new(); vertex_count];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for &v in tri {
            triangles_at[v as usize].push(t as u32);
        }
    }
    // For each vertex, the pairs of its triangles that share an edge
    // containing it.
    let mut links_at: Vec<Vec<[u32; 2]>> = vec![Vec::new(); vertex_count];
    for edge in &topology.edges {
        if let Some(right) = edge.right {
            let link = [edge.left.triangle, right.triangle];
            for v in edge.vertices {
                links_at[v as usize].push(link);
            }
        }
    }
    for vertex in 0..vertex_count {
        let triangles = &triangles_at[vertex];
        let links = &links_at[vertex];
        let mut reached: Vec<u32> = Vec::with_capacity(triangles.len());
        let mut fans = 0;
        for &start in triangles {
            if reached.contains(&start) {
                continue;
            }
            fans += 1;
            reached.push(start);
            let mut stack = vec![start];
            while let Some(t) = stack.pop() {
                for &[a, b] in links {
                    let next = if a == t {
                        b
                    } else if b == t {
                        a
                    } else {
                        continue;
                    };
                    if !reached.contains(&next) {
                        reached.push(next);
                        stack.push(next);
                    }
                }
            }
        }
        if fans > 1 {
            return Err(MeshError::NonManifoldVertex {
                vertex: vertex as u32,
                fans,
            });
        }
    }
    Ok(())
}

/// All triangles must wind the same way in UV as the majority does
/// (counter-clockwise wins a tie, as generated meshes use it).
fn check_uv_orientation(mesh: &Mesh) -> Result<(), MeshError> {
    let positive: Vec<bool> = (0..mesh.triangles.len())
        .map(|t| doubled_signed_uv_area(mesh, t) > 0.0)
        .collect();
    let positive_count = positive.iter().filter(|&&p| p).count();
    let majority_positive = 2 * positive_count >= positive.len();
    match positive.iter().position(|&p| p != majority_positive) {
        Some(triangle) => Err(MeshError::FlippedUv { triangle }),
        None => Ok(()),
    }
}

/// Number of edge-connected pieces, by union-find over triangles.
fn count_pieces(triangle_count: usize, topology: &Topology) -> usize {
    fn root(parent: &mut [usize], mut t: usize) -> usize {
        while parent[t] != t {
            parent[t] = parent[parent[t]];
            t = parent[t];
        }
        t
    }
    let mut parent: Vec<usize> = (0..triangle_count).collect();
    for edge in &topology.edges {
        if let Some(right) = edge.right {
            let a = root(&mut parent, edge.left.triangle as usize);
            let b = root(&mut parent, right.triangle as usize);
            parent[a] = b;
        }
    }
    (0..triangle_count)
        .filter(|&t| root(&mut parent, t) == t)
        .count()
}

/// Fails with [`MeshError::IndexOutOfRange`] on the first triangle corner
/// that names no vertex of `mesh`.
pub(crate) fn check_indices(mesh: &Mesh) -> Result<(), MeshError> {
    let vertex_count = mesh.positions.len();
    for (triangle, tri) in mesh.triangles.iter().enumerate() {
        if let Some(&index) = tri.iter().find(|&&i| i as usize >= vertex_count) {
            return Err(MeshError::IndexOutOfRange {
                triangle,
                index,
                vertex_count,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate;
    use crate::generate::unit_square;
    use glam::{DVec2, DVec3};

    #[test]
    fn generated_petal_is_valid() {
        let petal = generate::test_petal(10.0, 4.0, 9, 17);
        let topology = validate(&petal).expect("valid petal");
        assert_eq!(topology.triangle_edges.len(), petal.triangle_count());
        // A disc: V - E + F = 1.
        let euler = petal.vertex_count() as i64 - topology.edges.len() as i64
            + petal.triangle_count() as i64;
        assert_eq!(euler, 1);
    }

    #[test]
    fn small_and_large_scales_are_valid() {
        for scale in [1e-6, 1e6] {
            let sheet = generate::flat_sheet(scale, scale, 4, 4);
            assert!(validate(&sheet).is_ok(), "scale {scale}");
        }
    }

    #[test]
    fn empty_mesh() {
        assert_eq!(validate(&Mesh::default()), Err(MeshError::Empty));
    }

    #[test]
    fn index_out_of_range() {
        let mut m = unit_square();
        m.triangles[1] = [0, 2, 7];
        assert_eq!(
            validate(&m),
            Err(MeshError::IndexOutOfRange {
                triangle: 1,
                index: 7,
                vertex_count: 4
            })
        );
    }

    #[test]
    fn repeated_vertex() {
        let mut m = unit_square();
        m.triangles[1] = [0, 3, 3];
        assert_eq!(
            validate(&m),
            Err(MeshError::RepeatedVertex {
                triangle: 1,
                vertex: 3
            })
        );
    }

    #[test]
    fn uv_count_mismatch() {
        let mut m = unit_square();
        m.uvs.pop();
        assert_eq!(
            validate(&m),
            Err(MeshError::UvCountMismatch {
                vertices: 4,
                uvs: 3
            })
        );
    }

    #[test]
    fn non_finite_position() {
        let mut m = unit_square();
        m.positions[2].y = f64::NAN;
        assert_eq!(
            validate(&m),
            Err(MeshError::NonFinitePosition { vertex: 2 })
        );
        let mut m = unit_square();
        m.positions[3].z = f64::NEG_INFINITY;
        assert_eq!(
            validate(&m),
            Err(MeshError::NonFinitePosition { vertex: 3 })
        );
    }

    #[test]
    fn coordinates_beyond_the_limit_are_out_of_range() {
        let mut m = unit_square();
        m.positions[2].x = 1e30;
        assert_eq!(
            validate(&m),
            Err(MeshError::CoordinateOutOfRange {
                vertex: 2,
                value: 1e30
            })
        );
        let mut m = unit_square();
        m.positions[1].z = -MAX_COORDINATE;
        assert!(validate(&m).is_ok(), "the limit itself is allowed");
        let mut m = unit_square();
        m.uvs[3].y = -2e6;
        assert_eq!(
            validate(&m),
            Err(MeshError::UvOutOfRange {
                vertex: 3,
                value: -2e6
            })
        );
        assert_eq!(
            validate(&m).expect_err("out of range").to_string(),
            "vertex 3 has a UV component of -2e6, out of range: UVs must lie within ±1e6"
        );
    }

    #[test]
    fn non_finite_uv() {
        let mut m = unit_square();
        m.uvs[1].x = f64::INFINITY;
        assert_eq!(validate(&m), Err(MeshError::NonFiniteUv { vertex: 1 }));
    }

    #[test]
    fn unused_vertex() {
        let mut m = unit_square();
        m.positions.insert(1, DVec3::new(5.0, 5.0, 5.0));
        m.uvs.insert(1, DVec2::new(0.5, 0.5));
        for tri in &mut m.triangles {
            for i in tri {
                if *i >= 1 {
                    *i += 1;
                }
            }
        }
        assert_eq!(validate(&m), Err(MeshError::UnusedVertex { vertex: 1 }));
    }

    #[test]
    fn zero_area_triangle_in_3d() {
        let mut m = unit_square();
        // Corner 3 on the diagonal 0-2: triangle 1 collapses to a segment in
        // 3D while its UVs stay a proper triangle.
        m.positions[3] = DVec3::new(2.0, 2.0, 0.0);
        match validate(&m) {
            Err(MeshError::DegenerateTriangle {
                triangle: 1,
                space: Space::World,
                area,
            }) => assert!(area.abs() < 1e-15, "{area}"),
            other => panic!("expected a degenerate 3D triangle, got {other:?}"),
        }
    }

    #[test]
    fn sliver_triangle_in_3d_is_degenerate_at_any_scale() {
        // The square shrunk to 1e-8 is valid; pushing corner 3 out to the
        // diagonal's extension, 1e-22 (1e-14 of the mesh size) off it, makes
        // triangle 1 a sliver.
        let mut m = unit_square();
        for p in &mut m.positions {
            *p *= 1e-8;
        }
        assert!(validate(&m).is_ok());
        m.positions[3] = DVec3::new(2e-8, 2e-8 + 1e-22, 0.0);
        match validate(&m) {
            Err(MeshError::DegenerateTriangle {
                triangle: 1,
                space: Space::World,
                area,
            }) => assert!(area > 0.0 && area < 1e-29, "{area}"),
            other => panic!("expected a degenerate 3D triangle, got {other:?}"),
        }
    }

    #[test]
    fn zero_area_triangle_in_uv() {
        let mut m = unit_square();
        m.uvs[3] = DVec2::new(0.5, 0.5);
        match validate(&m) {
            Err(MeshError::DegenerateTriangle {
                triangle: 1,
                space: Space::Uv,
                area,
            }) => assert!(area.abs() < 1e-15, "{area}"),
            other => panic!("expected a degenerate UV triangle, got {other:?}"),
        }
    }

    #[test]
    fn non_manifold_edge() {
        let mut m = unit_square();
        m.positions.push(DVec3::new(0.5, 0.5, 1.0));
        m.uvs.push(DVec2::new(0.2, 0.8));
        m.triangles.push([2, 0, 4]);
        assert_eq!(
            validate(&m),
            Err(MeshError::NonManifoldEdge {
                a: 0,
                b: 2,
                faces: 3
            })
        );
    }

    #[test]
    fn inconsistent_orientation() {
        let mut m = unit_square();
        m.triangles[1] = [0, 3, 2];
        assert_eq!(
            validate(&m),
            Err(MeshError::InconsistentOrientation {
                a: 2,
                b: 0,
                first: 0,
                second: 1
            })
        );
    }

    #[test]
    fn non_manifold_vertex_in_a_connected_mesh() {
        // A 5x5 grid with the two cells diagonally across the centre vertex
        // 12 removed: the cells left around 12 touch only at 12, but the
        // mesh is still one piece.
        let mut m = generate::flat_sheet(4.0, 4.0, 5, 5);
        let removed = [[6, 7, 12], [6, 12, 11], [12, 13, 18], [12, 18, 17]];
        let before = m.triangles.len();
        m.triangles.retain(|t| !removed.contains(t));
        assert_eq!(m.triangles.len(), before - 4);
        assert_eq!(
            validate(&m),
            Err(MeshError::NonManifoldVertex {
                vertex: 12,
                fans: 2
            })
        );
    }

    #[test]
    fn bow_tie_is_a_non_manifold_vertex() {
        let m = Mesh {
            positions: vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(-1.0, 0.0, 0.0),
                DVec3::new(-1.0, -1.0, 0.0),
            ],
            uvs: vec![
                DVec2::new(0.5, 0.5),
                DVec2::new(1.0, 0.5),
                DVec2::new(1.0, 1.0),
                DVec2::new(0.0, 0.5),
                DVec2::new(0.0, 0.0),
            ],
            triangles: vec![[0, 1, 2], [0, 3, 4]],
        };
        assert_eq!(
            validate(&m),
            Err(MeshError::NonManifoldVertex { vertex: 0, fans: 2 })
        );
    }

    #[test]
    fn flipped_uv_triangle() {
        // 3x3 sheet: triangles [0,1,4] and [0,4,3] share corner 0. Moving
        // the UV of 0 to (0.3, 0.6) turns [0,4,3] (triangle 1) clockwise in
        // UV and leaves the other seven counter-clockwise.
        let mut m = generate::flat_sheet(1.0, 1.0, 3, 3);
        assert_eq!(&m.triangles[..2], &[[0, 1, 4], [0, 4, 3]]);
        m.uvs[0] = DVec2::new(0.3, 0.6);
        assert_eq!(validate(&m), Err(MeshError::FlippedUv { triangle: 1 }));
    }

    #[test]
    fn mirrored_uv_layout_is_not_flipped() {
        // Every triangle clockwise in UV: the majority decides, so this is
        // a consistent (mirrored) layout.
        let mut m = generate::flat_sheet(1.0, 1.0, 3, 3);
        for uv in &mut m.uvs {
            uv.x = 1.0 - uv.x;
        }
        assert!(validate(&m).is_ok());
    }

    #[test]
    fn two_pieces() {
        let mut m = unit_square();
        let second = unit_square();
        m.positions.extend(
            second
                .positions
                .iter()
                .map(|p| *p + DVec3::new(3.0, 0.0, 0.0)),
        );
        m.uvs.extend(second.uvs.iter().map(|uv| *uv * 0.5));
        m.triangles
            .extend(second.triangles.iter().map(|t| t.map(|i| i + 4)));
        assert_eq!(validate(&m), Err(MeshError::MultiplePieces { pieces: 2 }));
    }
}

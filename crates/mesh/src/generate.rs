//! Simple generated meshes: a triangulated parametric patch. Used by tests,
//! benchmarks and as the base of the bud builders.

use glam::{DVec2, DVec3};

use crate::Mesh;

/// Triangulates the parametric surface `surface(uv)` over the unit square
/// with `columns x rows` vertices (both at least 2). UVs are the parameters.
///
/// Triangles wind counter-clockwise in UV, so their normals point along
/// `d surface/du x d surface/dv`. Diagonals alternate direction in a
/// checkerboard so the mesh has no preferred shear direction.
pub fn parametric_grid(columns: usize, rows: usize, surface: impl Fn(DVec2) -> DVec3) -> Mesh {
    assert!(
        columns >= 2 && rows >= 2,
        "a grid needs at least 2x2 vertices"
    );
    let mut positions = Vec::with_capacity(columns * rows);
    let mut uvs = Vec::with_capacity(columns * rows);
    for j in 0..rows {
        for i in 0..columns {
            let uv = DVec2::new(
                i as f64 / (columns - 1) as f64,
                j as f64 / (rows - 1) as f64,
            );
            uvs.push(uv);
            positions.push(surface(uv));
        }
    }
    let index = |i: usize, j: usize| (j * columns + i) as u32;
    let mut triangles = Vec::with_capacity(2 * (columns - 1) * (rows - 1));
    for j in 0..rows - 1 {
        for i in 0..columns - 1 {
            let (a, b, c, d) = (
                index(i, j),
                index(i + 1, j),
                index(i + 1, j + 1),
                index(i, j + 1),
            );
            if (i + j) % 2 == 0 {
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            } else {
                triangles.push([a, b, d]);
                triangles.push([b, c, d]);
            }
        }
    }
    Mesh {
        positions,
        uvs,
        triangles,
    }
}

/// A flat rectangular sheet `width x height` in the XY plane (normal +Z),
/// `u` along X and `v` along Y, with the given vertex counts.
pub fn flat_sheet(width: f64, height: f64, columns: usize, rows: usize) -> Mesh {
    parametric_grid(columns, rows, |uv| {
        DVec3::new((uv.x - 0.5) * width, uv.y * height, 0.0)
    })
}

/// `positions` each moved by a fixed pseudo-random offset of up to
/// `amplitude / 2` per axis, the same for the same `seed`: an irregular but
/// reproducible state for benchmarks and examples.
pub fn jittered(positions: &[DVec3], amplitude: f64, seed: u64) -> Vec<DVec3> {
    let mut state = seed;
    let mut random = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    };
    positions
        .iter()
        .map(|p| *p + DVec3::new(random(), random(), random()) * amplitude)
        .collect()
}

/// A petal-like test surface in the organ's template frame: base at the
/// origin, growing along +Y, cupped around -Z (the inner side faces -Z,
/// towards a flower axis placed behind the organ), width tapering to the
/// tip. About `length / columns` mean edge length.
///
/// UVs follow the Anthesis convention (u across, midrib at 0.5; v base to
/// tip); the grid runs `u` along -X so that the winding normal points to the
/// inner side (-Z).
pub fn test_petal(length: f64, width: f64, columns: usize, rows: usize) -> Mesh {
    parametric_grid(columns, rows, |uv| {
        let half_width =
            0.5 * width * (0.25 + 0.75 * (std::f64::consts::PI * uv.y).sin().powf(0.7));
        let x = -(uv.x - 0.5) * 2.0 * half_width;
        let y = uv.y * length;
        // Cupped across (inner side concave: the edges curl towards the axis at
        // -Z) and slightly incurved along.
        let z = -0.35 * x * x / width.max(1e-9) - 0.08 * length * (uv.y * uv.y);
        DVec3::new(x, y, z)
    })
}

/// The unit square in the XY plane as two triangles, `[0, 1, 2]` and
/// `[0, 2, 3]`, corners counter-clockwise from the origin, UV = XY: the
/// smallest mesh with an interior edge, for tests.
#[cfg(test)]
pub(crate) fn unit_square() -> Mesh {
    Mesh {
        positions: vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ],
        uvs: vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.0, 1.0),
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Topology;

    #[test]
    fn grid_counts_match_euler() {
        let m = flat_sheet(2.0, 3.0, 5, 7);
        assert_eq!(m.vertex_count(), 35);
        assert_eq!(m.triangle_count(), 2 * 4 * 6);
        let topo = Topology::build(&m).expect("grid is manifold");
        // V - E + F = 1 for a disc.
        assert_eq!(35 - topo.edges.len() as i64 + 48, 1);
        assert!((m.area() - 6.0).abs() < 1e-12);
    }

    #[test]
    fn flat_sheet_normals_point_plus_z() {
        let m = flat_sheet(1.0, 1.0, 3, 3);
        for n in m.vertex_normals() {
            assert!((n - DVec3::Z).length() < 1e-12);
        }
    }

    #[test]
    fn test_petal_normals_face_minus_z() {
        let m = test_petal(10.0, 4.0, 14, 28);
        let mean: DVec3 = m.vertex_normals().iter().sum();
        assert!(mean.z < 0.0, "inner side must face -Z, got {mean}");
    }
}

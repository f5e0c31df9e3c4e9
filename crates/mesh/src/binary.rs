//! A mesh as bytes, bit for bit: what a cache keeps of a derived mesh (a
//! remeshed template) so that reading it back gives the same `f64`s, not
//! a decimal rounding of them as OBJ text would.
//!
//! Layout, little-endian: [`MAGIC`], [`VERSION`] (u32), the vertex count
//! and the triangle count (u64 each), the positions (three `f64` bit
//! patterns per vertex), the UVs (two per vertex), the triangles (three
//! `u32` per triangle). Reading checks the magic, the version, that the
//! length is exactly what the counts say and that every index names a
//! vertex; it does not validate the mesh's geometry (what was written was
//! a mesh already checked).

use glam::{DVec2, DVec3};
use thiserror::Error;

use crate::Mesh;

/// The first bytes of a mesh in this layout.
pub const MAGIC: [u8; 4] = *b"AMSH";

/// The layout's version; bump it when the layout changes.
pub const VERSION: u32 = 1;

/// Magic, version, vertex count, triangle count.
const HEADER_LEN: usize = 4 + 4 + 8 + 8;

/// Why bytes are not a mesh in this layout.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum BinaryMeshError {
    /// The bytes do not start with [`MAGIC`] (not a mesh, or cut short
    /// before the header's end).
    #[error("not a binary mesh (no header)")]
    NotAMesh,
    /// A mesh of another layout version.
    #[error("a binary mesh of version {found}, this build reads version {VERSION}")]
    Version {
        /// The version the bytes say.
        found: u32,
    },
    /// The length does not match the counts in the header (cut short, or
    /// with bytes after the mesh).
    #[error(
        "a binary mesh of {vertices} vertices and {triangles} triangles needs {expected} bytes, got {found}"
    )]
    Length {
        /// Vertex count from the header.
        vertices: u64,
        /// Triangle count from the header.
        triangles: u64,
        /// The length the counts need (`u64::MAX` when they overflow).
        expected: u64,
        /// The length given.
        found: u64,
    },
    /// A triangle names a vertex the mesh does not have.
    #[error("triangle {triangle} names vertex {index} of {vertices}")]
    Index {
        /// Which triangle.
        triangle: usize,
        /// The index it holds.
        index: u32,
        /// How many vertices there are.
        vertices: usize,
    },
}

/// `mesh` as bytes (see the module documentation).
pub fn mesh_to_bytes(mesh: &Mesh) -> Vec<u8> {
    let vertices = mesh.positions.len();
    let triangles = mesh.triangles.len();
    let mut bytes = Vec::with_capacity(HEADER_LEN + vertices * 40 + triangles * 12);
    bytes.extend_from_slice(&MAGIC);
    bytes.extend_from_slice(&VERSION.to_le_bytes());
    bytes.extend_from_slice(&(vertices as u64).to_le_bytes());
    bytes.extend_from_slice(&(triangles as u64).to_le_bytes());
    let mut float = |value: f64| bytes.extend_from_slice(&value.to_bits().to_le_bytes());
    for p in &mesh.positions {
        float(p.x);
        float(p.y);
        float(p.z);
    }
    for uv in &mesh.uvs {
        float(uv.x);
        float(uv.y);
    }
    for triangle in &mesh.triangles {
        for index in triangle {
            bytes.extend_from_slice(&index.to_le_bytes());
        }
    }
    bytes
}

/// The mesh in `bytes`, exactly as [`mesh_to_bytes`] was given it.
pub fn mesh_from_bytes(bytes: &[u8]) -> Result<Mesh, BinaryMeshError> {
    let (header, body) = bytes
        .split_at_checked(HEADER_LEN)
        .ok_or(BinaryMeshError::NotAMesh)?;
    if header[..4] != MAGIC {
        return Err(BinaryMeshError::NotAMesh);
    }
    let word = |at: usize| u64::from_le_bytes(std::array::from_fn(|i| header[at + i]));
    let found = u32::from_le_bytes(std::array::from_fn(|i| header[4 + i]));
    if found != VERSION {
        return Err(BinaryMeshError::Version { found });
    }
    let (vertices, triangles) = (word(8), word(16));
    let expected = vertices
        .checked_mul(40)
        .zip(triangles.checked_mul(12))
        .and_then(|(a, b)| a.checked_add(b))
        .unwrap_or(u64::MAX);
    if expected != body.len() as u64 {
        return Err(BinaryMeshError::Length {
            vertices,
            triangles,
            expected: expected.saturating_add(HEADER_LEN as u64),
            found: bytes.len() as u64,
        });
    }
    // The counts fit in memory: the body holds them.
    let (vertices, triangles) = (vertices as usize, triangles as usize);
    let float =
        |at: usize| f64::from_bits(u64::from_le_bytes(std::array::from_fn(|i| body[at + i])));
    let positions = (0..vertices)
        .map(|v| DVec3::new(float(24 * v), float(24 * v + 8), float(24 * v + 16)))
        .collect();
    let uv_start = 24 * vertices;
    let uvs = (0..vertices)
        .map(|v| DVec2::new(float(uv_start + 16 * v), float(uv_start + 16 * v + 8)))
        .collect();
    let triangle_start = 40 * vertices;
    let index = |at: usize| u32::from_le_bytes(std::array::from_fn(|i| body[at + i]));
    let mut list = Vec::with_capacity(triangles);
    for t in 0..triangles {
        let triangle: [u32; 3] = std::array::from_fn(|k| index(triangle_start + 12 * t + 4 * k));
        if let Some(&bad) = triangle.iter().find(|&&i| i as usize >= vertices) {
            return Err(BinaryMeshError::Index {
                triangle: t,
                index: bad,
                vertices,
            });
        }
        list.push(triangle);
    }
    Ok(Mesh {
        positions,
        uvs,
        triangles: list,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::test_petal;

    /// Bit patterns of every float, to compare meshes bit for bit (NaN
    /// and -0.0 included).
    fn bits(mesh: &Mesh) -> (Vec<u64>, Vec<[u32; 3]>) {
        let floats = mesh
            .positions
            .iter()
            .flat_map(|p| p.to_array())
            .chain(mesh.uvs.iter().flat_map(|uv| uv.to_array()))
            .map(f64::to_bits)
            .collect();
        (floats, mesh.triangles.clone())
    }

    #[test]
    fn a_mesh_comes_back_bit_for_bit() {
        let mut mesh = test_petal(10.0, 5.0, 9, 17);
        // Values decimal text would round or lose.
        mesh.positions[0].x = 0.1 + 0.2;
        mesh.positions[1].y = -0.0;
        mesh.positions[2].z = f64::MIN_POSITIVE / 3.0;
        mesh.uvs[3].x = 1.0f64.next_down();
        let back = mesh_from_bytes(&mesh_to_bytes(&mesh)).expect("reads");
        assert_eq!(bits(&back), bits(&mesh));
        assert_eq!(back, mesh);
        let empty = Mesh::default();
        assert_eq!(mesh_from_bytes(&mesh_to_bytes(&empty)), Ok(empty));
    }

    #[test]
    fn damaged_bytes_are_refused_and_never_panic() {
        let mesh = test_petal(4.0, 2.0, 3, 4);
        let good = mesh_to_bytes(&mesh);
        for cut in 0..good.len() {
            assert!(mesh_from_bytes(&good[..cut]).is_err(), "cut at {cut}");
        }
        let mut longer = good.clone();
        longer.push(0);
        assert!(matches!(
            mesh_from_bytes(&longer),
            Err(BinaryMeshError::Length { .. })
        ));
        let mut version = good.clone();
        version[4] = 9;
        assert_eq!(
            mesh_from_bytes(&version),
            Err(BinaryMeshError::Version { found: 9 })
        );
        let mut magic = good.clone();
        magic[0] = b'X';
        assert_eq!(mesh_from_bytes(&magic), Err(BinaryMeshError::NotAMesh));
        // Counts that overflow any length.
        let mut huge = good.clone();
        huge[8..16].copy_from_slice(&u64::MAX.to_le_bytes());
        assert!(matches!(
            mesh_from_bytes(&huge),
            Err(BinaryMeshError::Length {
                expected: u64::MAX,
                ..
            })
        ));
        // An index past the vertices.
        let mut index = good.clone();
        let at = good.len() - 4;
        index[at..].copy_from_slice(&(mesh.vertex_count() as u32).to_le_bytes());
        assert!(matches!(
            mesh_from_bytes(&index),
            Err(BinaryMeshError::Index { .. })
        ));
    }
}

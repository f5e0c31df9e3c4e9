//! Triangle meshes with one UV layout, their edge topology, OBJ import,
//! validation and Loop subdivision (render meshes finer than the simulated
//! ones, [`Subdivision`]).
//!
//! Conventions used across Anthesis:
//! - positions are `f64` (`glam::DVec3`); UVs are `glam::DVec2`;
//! - triangles wind counter-clockwise around the normal that points to the
//!   organ's *inner* (adaxial) side, the side facing the flower axis;
//! - UV `u` runs across the organ (midrib at `u = 0.5`), `v` from the base
//!   (`0`) to the tip (`1`).

#![warn(missing_docs)]

pub mod binary;
pub mod crossing;
mod error;
pub mod generate;
pub mod nearest;
pub mod obj;
pub mod ray;
pub mod subdivide;
mod topology;
pub mod validate;

pub use error::{MeshError, Space};
pub use obj::{
    ObjFile, ObjWarning, load_obj, load_obj_file, load_obj_shape, obj_string, parse_obj,
    parse_obj_file, parse_obj_shape, parse_obj_unvalidated, write_obj,
};
pub use subdivide::Subdivision;
pub use topology::{Edge, EdgeSide, Topology};
pub use validate::{validate, validate_shape};

use glam::{DVec2, DVec3};

/// A triangle mesh with one UV per vertex.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    /// Vertex positions, in the space and units of whoever holds the mesh
    /// (an organ template's frame in the project's units, for templates).
    pub positions: Vec<DVec3>,
    /// One UV per vertex, same index as `positions`: `u` across the organ,
    /// `v` from base (0) to tip (1).
    pub uvs: Vec<DVec2>,
    /// Vertex indices of each triangle, counter-clockwise around the normal
    /// of the organ's inner side.
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// How many vertices (positions, and UVs) the mesh has.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// How many triangles the mesh has.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The three corner positions of triangle `t`.
    pub fn triangle_positions(&self, t: usize) -> [DVec3; 3] {
        self.triangles[t].map(|i| self.positions[i as usize])
    }

    /// The three corner UVs of triangle `t`.
    pub fn triangle_uvs(&self, t: usize) -> [DVec2; 3] {
        self.triangles[t].map(|i| self.uvs[i as usize])
    }

    /// Area of triangle `t` in 3D.
    pub fn triangle_area(&self, t: usize) -> f64 {
        let [a, b, c] = self.triangle_positions(t);
        0.5 * (b - a).cross(c - a).length()
    }

    /// Total surface area in 3D.
    pub fn area(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| self.triangle_area(t))
            .sum()
    }

    /// Area-weighted vertex normals (unit length, pointing to the inner side).
    pub fn vertex_normals(&self) -> Vec<DVec3> {
        vertex_normals(&self.positions, &self.triangles)
    }
}

/// Area-weighted vertex normals of `positions` for the given triangles.
/// Vertices that belong to no triangle get a zero normal.
pub fn vertex_normals(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let mut normals = vec![DVec3::ZERO; positions.len()];
    for tri in triangles {
        let [a, b, c] = tri.map(|i| positions[i as usize]);
        let n = (b - a).cross(c - a);
        for &i in tri {
            normals[i as usize] += n;
        }
    }
    for n in &mut normals {
        *n = n.normalize_or_zero();
    }
    normals
}

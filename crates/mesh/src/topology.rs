use std::collections::HashMap;

use crate::{Mesh, MeshError};

/// One side of an edge: the triangle on that side and its corner opposite
/// the edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EdgeSide {
    /// The triangle's index in the mesh.
    pub triangle: u32,
    /// The vertex index of the triangle's corner that is not on the edge.
    pub opposite: u32,
}

/// An edge and its (one or two) adjacent triangles.
///
/// `vertices` are ordered as they appear in the winding of `left`
/// (`left` contains the directed edge `vertices[0] -> vertices[1]`); `right`,
/// if present, contains `vertices[1] -> vertices[0]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Edge {
    /// The edge's two vertex indices, in the winding of `left`.
    pub vertices: [u32; 2],
    /// The triangle that runs `vertices[0] -> vertices[1]`.
    pub left: EdgeSide,
    /// The triangle that runs `vertices[1] -> vertices[0]`; `None` on the
    /// mesh's outline.
    pub right: Option<EdgeSide>,
}

impl Edge {
    /// Whether the edge has a triangle on one side only (it lies on the
    /// outline of the surface).
    pub fn is_boundary(&self) -> bool {
        self.right.is_none()
    }

    /// The hinge stencil `[i, j, k, l]` of an interior edge: the edge
    /// `i -> j`, `k` opposite in the left triangle, `l` opposite in the right.
    pub fn hinge(&self) -> Option<[u32; 4]> {
        self.right.map(|r| {
            [
                self.vertices[0],
                self.vertices[1],
                self.left.opposite,
                r.opposite,
            ]
        })
    }
}

/// Edge topology of a manifold, consistently oriented triangle mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct Topology {
    /// Every edge of the mesh once, interior and boundary.
    pub edges: Vec<Edge>,
    /// For each triangle, the edge index of its sides `(t0,t1)`, `(t1,t2)`,
    /// `(t2,t0)`.
    pub triangle_edges: Vec<[u32; 3]>,
}

impl Topology {
    /// Builds the edge list. Fails on an edge with more than two triangles or
    /// two triangles that traverse a shared edge in the same direction
    /// (inconsistent orientation).
    pub fn build(mesh: &Mesh) -> Result<Topology, MeshError> {
        Topology::from_triangles(&mesh.triangles)
    }

    /// [`Topology::build`] from the triangles alone.
    pub fn from_triangles(triangles: &[[u32; 3]]) -> Result<Topology, MeshError> {
        let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
        let mut edges: Vec<Edge> = Vec::new();
        let mut index_of: HashMap<(u32, u32), u32> = HashMap::new();
        let mut triangle_edges = Vec::with_capacity(triangles.len());
        let mut faces_on_edge: HashMap<(u32, u32), usize> = HashMap::new();
        for (t, tri) in triangles.iter().enumerate() {
            let mut te = [0u32; 3];
            for k in 0..3 {
                let (a, b, c) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
                let key = (a.min(b), a.max(b));
                let count = faces_on_edge.entry(key).or_insert(0);
                *count += 1;
                if *count > 2 {
                    return Err(MeshError::NonManifoldEdge {
                        a: key.0,
                        b: key.1,
                        faces: *count,
                    });
                }
                if let Some(&first) = directed.get(&(a, b)) {
                    return Err(MeshError::InconsistentOrientation {
                        a,
                        b,
                        first,
                        second: t,
                    });
                }
                directed.insert((a, b), t);
                let side = EdgeSide {
                    triangle: t as u32,
                    opposite: c,
                };
                te[k] = match index_of.get(&key) {
                    Some(&e) => {
                        edges[e as usize].right = Some(side);
                        e
                    }
                    None => {
                        let e = edges.len() as u32;
                        edges.push(Edge {
                            vertices: [a, b],
                            left: side,
                            right: None,
                        });
                        index_of.insert(key, e);
                        e
                    }
                };
            }
            triangle_edges.push(te);
        }
        Ok(Topology {
            edges,
            triangle_edges,
        })
    }

    /// How many edges have a triangle on both sides (the hinges).
    pub fn interior_edge_count(&self) -> usize {
        self.edges.iter().filter(|e| !e.is_boundary()).count()
    }

    /// How many edges lie on the outline of the surface.
    pub fn boundary_edge_count(&self) -> usize {
        self.edges.iter().filter(|e| e.is_boundary()).count()
    }

    /// The edges of one triangle only (the outline of the surface), as
    /// vertex pairs in the winding of their triangle.
    pub fn boundary_edges(&self) -> impl Iterator<Item = [u32; 2]> + '_ {
        self.edges
            .iter()
            .filter(|e| e.is_boundary())
            .map(|e| e.vertices)
    }

    /// For each vertex, its neighbours along edges (sorted, deduplicated).
    pub fn vertex_neighbours(&self, vertex_count: usize) -> Vec<Vec<u32>> {
        let mut nb = vec![Vec::new(); vertex_count];
        for e in &self.edges {
            let [a, b] = e.vertices;
            nb[a as usize].push(b);
            nb[b as usize].push(a);
        }
        for n in &mut nb {
            n.sort_unstable();
            n.dedup();
        }
        nb
    }

    /// Whether each vertex lies on the boundary.
    pub fn boundary_vertices(&self, vertex_count: usize) -> Vec<bool> {
        let mut on = vec![false; vertex_count];
        for e in self.edges.iter().filter(|e| e.is_boundary()) {
            on[e.vertices[0] as usize] = true;
            on[e.vertices[1] as usize] = true;
        }
        on
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::unit_square;
    use glam::{DVec2, DVec3};

    #[test]
    fn quad_has_one_interior_edge_with_its_hinge() {
        let topo = Topology::build(&unit_square()).expect("valid quad");
        assert_eq!(topo.edges.len(), 5);
        assert_eq!(topo.interior_edge_count(), 1);
        assert_eq!(topo.boundary_edge_count(), 4);
        let interior = topo.edges.iter().find(|e| !e.is_boundary()).expect("one");
        // Left triangle 0 walks 2 -> 0, right triangle 1 walks 0 -> 2.
        assert_eq!(interior.hinge(), Some([2, 0, 1, 3]));
        assert_eq!(topo.triangle_edges[0][2], topo.triangle_edges[1][0]);
        // The outline: the four sides, each in its triangle's winding.
        let mut outline: Vec<[u32; 2]> = topo.boundary_edges().collect();
        outline.sort_unstable();
        assert_eq!(outline.len(), 4);
        assert!(!outline.contains(&[0, 2]) && !outline.contains(&[2, 0]));
        for [a, b] in outline {
            assert!(
                unit_square()
                    .triangles
                    .iter()
                    .any(|t| (0..3).any(|i| [t[i], t[(i + 1) % 3]] == [a, b])),
                "{a} -> {b} is not a side of a triangle"
            );
        }
    }

    #[test]
    fn edge_shared_by_three_triangles_is_non_manifold() {
        let mut m = unit_square();
        m.positions.push(DVec3::new(0.5, 0.5, 1.0));
        m.uvs.push(DVec2::new(0.5, 0.5));
        m.triangles.push([2, 0, 4]);
        let err = Topology::build(&m).expect_err("three faces on 0-2");
        assert_eq!(
            err,
            MeshError::NonManifoldEdge {
                a: 0,
                b: 2,
                faces: 3
            }
        );
    }

    #[test]
    fn flipped_neighbour_is_inconsistent_orientation() {
        let mut m = unit_square();
        m.triangles[1] = [0, 3, 2];
        let err = Topology::build(&m).expect_err("flipped");
        assert!(matches!(
            err,
            MeshError::InconsistentOrientation { a: 2, b: 0, .. }
                | MeshError::InconsistentOrientation { a: 0, b: 2, .. }
        ));
    }
}

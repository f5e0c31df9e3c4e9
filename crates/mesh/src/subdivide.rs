//! Loop subdivision (Loop 1987, with the boundary rules of Hoppe et al.
//! 1994) as a fixed linear map from a coarse mesh's vertices to the
//! vertices of a finer render mesh.
//!
//! The map depends only on the triangles and on which rim vertices are
//! corners, never on where the vertices are later, so it is built once per
//! organ ([`Subdivision::new`]) and applied to every keyframe as a sparse
//! matrix–vector product ([`Subdivision::apply`]). Each level splits every
//! triangle into four (a new vertex on every edge) and moves the old
//! vertices:
//!
//! - an interior vertex of valence `n` becomes `(1 − nβ) v + β Σ neighbours`
//!   with Loop's `β = (5/8 − (3/8 + cos(2π/n)/4)²) / n` (1/16 at valence 6);
//! - an interior edge `a–b` between the triangles `a b c` and `b a d` gets
//!   the vertex `3/8 (a + b) + 1/8 (c + d)`;
//! - the rim (the mesh boundary: a petal's open edge) is a crease: a rim
//!   vertex becomes `3/4 v + 1/8 (p + q)` from its two rim neighbours and a
//!   rim edge gets its midpoint, so the rim is the cubic B-spline of the rim
//!   vertices and never depends on the interior (two meshes that share a rim
//!   keep sharing it);
//! - a corner (a rim vertex whose two rim edges meet at less than
//!   [`CORNER_ANGLE`] in the mesh given to [`Subdivision::new`], such as a
//!   pointed petal tip or the corners of a petal's base) stays where it is.
//!
//! The vertices of a level keep their indices in the next one (coarse vertex
//! `i` is render vertex `i`), followed by one vertex per edge. UVs are
//! interpolated linearly (an edge's vertex gets the midpoint of its ends'
//! UVs, old vertices keep theirs), so every render vertex lies in the UV
//! triangle of the coarse triangle it came from and the painted maps, which
//! live in UV space, land exactly where they did on the coarse mesh. Each
//! new triangle keeps its parent's winding, so normals keep facing the
//! inner side.

use std::f64::consts::TAU;

use glam::{DVec2, DVec3};

use crate::{Mesh, MeshError, Topology};

/// A rim vertex whose two rim edges meet at less than this angle (radians,
/// 120°) is a corner and keeps its position. A smooth rim meshed with at
/// least a dozen vertices around a half turn stays well above it; a pointed
/// tip or the square corner of a petal's base falls below.
pub const CORNER_ANGLE: f64 = TAU / 3.0;

/// The most vertices a subdivided mesh may have (about 0.8 GB of stencils
/// and positions at level 2); beyond it [`Subdivision::new`] refuses with
/// [`MeshError::SubdivisionTooLarge`].
pub const MAX_SUBDIVIDED_VERTICES: u64 = 4_000_000;

/// The vertex and triangle counts after `level` levels of subdivision of a
/// mesh with the given counts (each level: `V + E` vertices, `2E + 3F`
/// edges, `4F` triangles). Saturates instead of overflowing.
pub fn subdivided_counts(vertices: u64, edges: u64, triangles: u64, level: u32) -> (u64, u64) {
    let (mut v, mut e, mut f) = (vertices, edges, triangles);
    for _ in 0..level {
        v = v.saturating_add(e);
        e = e.saturating_mul(2).saturating_add(f.saturating_mul(3));
        f = f.saturating_mul(4);
    }
    (v, f)
}

/// Loop's vertex weight for an interior vertex of valence `n`.
pub fn loop_beta(n: usize) -> f64 {
    let n = n as f64;
    let c = 0.375 + 0.25 * (TAU / n).cos();
    (0.625 - c * c) / n
}

/// A fixed linear map from a coarse mesh's vertex positions to the
/// positions of its Loop subdivision at some level, with the subdivided
/// mesh's triangles and UVs. See the module documentation for the rules.
#[derive(Debug, Clone, PartialEq)]
pub struct Subdivision {
    level: u32,
    coarse_vertex_count: usize,
    /// Render vertex `r` is `Σ weights[i] · coarse[columns[i]]` over
    /// `i` in `row_starts[r]..row_starts[r + 1]`.
    row_starts: Vec<usize>,
    columns: Vec<u32>,
    weights: Vec<f64>,
    triangles: Vec<[u32; 3]>,
    uvs: Vec<DVec2>,
}

/// One render vertex as weights of coarse vertices.
type Stencil = Vec<(u32, f64)>;

impl Subdivision {
    /// The map of `level` levels of Loop subdivision of `mesh` (level 0 is
    /// the identity). The positions of `mesh` only decide which rim
    /// vertices are corners; its triangles and UVs are subdivided.
    ///
    /// Fails on a mesh that is not a manifold, consistently oriented
    /// surface with one UV per vertex (the errors of [`Topology::build`],
    /// [`MeshError::NonManifoldVertex`] for a vertex where two pieces of rim
    /// meet), and with [`MeshError::SubdivisionTooLarge`] before building
    /// anything when the result would have more than
    /// [`MAX_SUBDIVIDED_VERTICES`].
    pub fn new(mesh: &Mesh, level: u32) -> Result<Subdivision, MeshError> {
        let vertex_count = mesh.positions.len();
        crate::validate::check_indices(mesh)?;
        if mesh.uvs.len() != vertex_count {
            return Err(MeshError::UvCountMismatch {
                vertices: vertex_count,
                uvs: mesh.uvs.len(),
            });
        }
        let topology = Topology::from_triangles(&mesh.triangles)?;
        let (vertices, _) = subdivided_counts(
            vertex_count as u64,
            topology.edges.len() as u64,
            mesh.triangles.len() as u64,
            level,
        );
        if vertices > MAX_SUBDIVIDED_VERTICES {
            return Err(MeshError::SubdivisionTooLarge {
                level,
                vertices,
                limit: MAX_SUBDIVIDED_VERTICES,
            });
        }
        let rims = rim_neighbours(&topology, vertex_count)?;
        let mut corners: Vec<bool> = rims
            .iter()
            .enumerate()
            .map(|(v, rim)| match rim[..] {
                [p, q] => {
                    let at = mesh.positions[v];
                    let angle = (mesh.positions[p as usize] - at)
                        .angle_between(mesh.positions[q as usize] - at);
                    angle < CORNER_ANGLE
                }
                _ => false,
            })
            .collect();

        let mut stencils: Vec<Stencil> = (0..vertex_count as u32).map(|v| vec![(v, 1.0)]).collect();
        let mut triangles = mesh.triangles.clone();
        let mut uvs = mesh.uvs.clone();
        let mut topology = Some(topology);
        let mut scratch = Accumulator::new(vertex_count);
        for _ in 0..level {
            let topo = match topology.take() {
                Some(topo) => topo,
                None => Topology::from_triangles(&triangles)?,
            };
            let step = loop_step(&triangles, &topo, &corners)?;
            stencils = step
                .rows
                .iter()
                .map(|row| scratch.combine(row, &stencils))
                .collect();
            let midpoints: Vec<DVec2> = topo
                .edges
                .iter()
                .map(|e| 0.5 * (uvs[e.vertices[0] as usize] + uvs[e.vertices[1] as usize]))
                .collect();
            uvs.extend(midpoints);
            triangles = step.triangles;
            corners.resize(stencils.len(), false);
        }

        let mut row_starts = Vec::with_capacity(stencils.len() + 1);
        let entries = stencils.iter().map(Vec::len).sum();
        let mut columns = Vec::with_capacity(entries);
        let mut weights = Vec::with_capacity(entries);
        row_starts.push(0);
        for stencil in &stencils {
            for &(column, weight) in stencil {
                columns.push(column);
                weights.push(weight);
            }
            row_starts.push(columns.len());
        }
        Ok(Subdivision {
            level,
            coarse_vertex_count: vertex_count,
            row_starts,
            columns,
            weights,
            triangles,
            uvs,
        })
    }

    /// The number of levels.
    pub fn level(&self) -> u32 {
        self.level
    }

    /// How many vertices the positions given to [`Subdivision::apply`] have.
    pub fn coarse_vertex_count(&self) -> usize {
        self.coarse_vertex_count
    }

    /// How many vertices the subdivided mesh has.
    pub fn vertex_count(&self) -> usize {
        self.row_starts.len() - 1
    }

    /// The subdivided mesh's triangles (four per triangle per level, wound
    /// as their parents).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The subdivided mesh's UVs (linear interpolation of the coarse ones).
    pub fn uvs(&self) -> &[DVec2] {
        &self.uvs
    }

    /// Render vertex `vertex` as `(coarse vertex, weight)` pairs; the
    /// weights sum to 1.
    pub fn stencil(&self, vertex: usize) -> impl Iterator<Item = (u32, f64)> + '_ {
        let range = self.row_starts[vertex]..self.row_starts[vertex + 1];
        self.columns[range.clone()]
            .iter()
            .copied()
            .zip(self.weights[range].iter().copied())
    }

    /// The render positions of the coarse positions `coarse`.
    ///
    /// # Panics
    /// If `coarse` does not hold [`Subdivision::coarse_vertex_count`]
    /// positions.
    pub fn apply(&self, coarse: &[DVec3]) -> Vec<DVec3> {
        assert_eq!(
            coarse.len(),
            self.coarse_vertex_count,
            "the subdivision was built for another vertex count"
        );
        self.row_starts
            .windows(2)
            .map(|range| {
                let range = range[0]..range[1];
                self.columns[range.clone()]
                    .iter()
                    .zip(&self.weights[range])
                    .fold(DVec3::ZERO, |sum, (&c, &w)| sum + w * coarse[c as usize])
            })
            .collect()
    }

    /// The subdivided mesh at the coarse positions `coarse` (see
    /// [`Subdivision::apply`]).
    pub fn mesh(&self, coarse: &[DVec3]) -> Mesh {
        Mesh {
            positions: self.apply(coarse),
            uvs: self.uvs.clone(),
            triangles: self.triangles.clone(),
        }
    }
}

/// Each vertex's neighbours along rim edges: none inside, two on the rim.
/// A vertex where more rim meets is where two fans of triangles touch.
fn rim_neighbours(topology: &Topology, vertex_count: usize) -> Result<Vec<Vec<u32>>, MeshError> {
    let mut rims = vec![Vec::new(); vertex_count];
    for [a, b] in topology.boundary_edges() {
        rims[a as usize].push(b);
        rims[b as usize].push(a);
    }
    match rims.iter().position(|rim| rim.len() > 2) {
        Some(vertex) => Err(MeshError::NonManifoldVertex {
            vertex: vertex as u32,
            fans: rims[vertex].len() / 2,
        }),
        None => Ok(rims),
    }
}

/// One level: each new vertex as weights of the current ones, and the new
/// triangles.
struct Step {
    rows: Vec<Stencil>,
    triangles: Vec<[u32; 3]>,
}

fn loop_step(
    triangles: &[[u32; 3]],
    topology: &Topology,
    corners: &[bool],
) -> Result<Step, MeshError> {
    let vertex_count = corners.len();
    let rims = rim_neighbours(topology, vertex_count)?;
    let neighbours = topology.vertex_neighbours(vertex_count);
    let mut rows: Vec<Stencil> = Vec::with_capacity(vertex_count + topology.edges.len());
    for v in 0..vertex_count {
        let me = v as u32;
        let row = if corners[v] || neighbours[v].is_empty() {
            vec![(me, 1.0)]
        } else if let [p, q] = rims[v][..] {
            vec![(me, 0.75), (p, 0.125), (q, 0.125)]
        } else {
            let ring = &neighbours[v];
            let beta = loop_beta(ring.len());
            let mut row = Vec::with_capacity(ring.len() + 1);
            row.push((me, 1.0 - ring.len() as f64 * beta));
            row.extend(ring.iter().map(|&n| (n, beta)));
            row
        };
        rows.push(row);
    }
    for edge in &topology.edges {
        let [a, b] = edge.vertices;
        rows.push(match edge.right {
            None => vec![(a, 0.5), (b, 0.5)],
            Some(right) => vec![
                (a, 0.375),
                (b, 0.375),
                (edge.left.opposite, 0.125),
                (right.opposite, 0.125),
            ],
        });
    }
    let edge_vertex = |e: u32| vertex_count as u32 + e;
    let mut fine = Vec::with_capacity(4 * triangles.len());
    for (&[a, b, c], &[ab, bc, ca]) in triangles.iter().zip(&topology.triangle_edges) {
        let (ab, bc, ca) = (edge_vertex(ab), edge_vertex(bc), edge_vertex(ca));
        fine.push([a, ab, ca]);
        fine.push([ab, b, bc]);
        fine.push([ca, bc, c]);
        fine.push([ab, bc, ca]);
    }
    Ok(Step {
        rows,
        triangles: fine,
    })
}

/// Sums weighted stencils into one, with a dense scratch row over the
/// coarse vertices.
struct Accumulator {
    sums: Vec<f64>,
    touched: Vec<u32>,
}

impl Accumulator {
    fn new(coarse_vertex_count: usize) -> Accumulator {
        Accumulator {
            sums: vec![0.0; coarse_vertex_count],
            touched: Vec::new(),
        }
    }

    /// `Σ w · stencils[k]` over the `(k, w)` of `row`, by coarse vertex.
    fn combine(&mut self, row: &[(u32, f64)], stencils: &[Stencil]) -> Stencil {
        for &(k, w) in row {
            for &(column, weight) in &stencils[k as usize] {
                let sum = &mut self.sums[column as usize];
                if *sum == 0.0 {
                    self.touched.push(column);
                }
                *sum += w * weight;
            }
        }
        self.touched.sort_unstable();
        self.touched.dedup();
        let stencil = self
            .touched
            .iter()
            .map(|&column| (column, std::mem::take(&mut self.sums[column as usize])))
            .collect();
        self.touched.clear();
        stencil
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::{flat_sheet, test_petal};

    /// A fan of `n` triangles around vertex 0 at the origin, its rim a
    /// regular `n`-gon of radius 1 in the XY plane (wound around +Z).
    fn fan(n: u32) -> Mesh {
        let mut mesh = Mesh {
            positions: vec![DVec3::ZERO],
            uvs: vec![DVec2::splat(0.5)],
            triangles: Vec::new(),
        };
        for k in 0..n {
            let angle = TAU * f64::from(k) / f64::from(n);
            let (s, c) = angle.sin_cos();
            mesh.positions.push(DVec3::new(c, s, 0.0));
            mesh.uvs.push(DVec2::new(0.5 + 0.5 * c, 0.5 + 0.5 * s));
            mesh.triangles.push([0, 1 + k, 1 + (k + 1) % n]);
        }
        mesh
    }

    /// The regular octahedron with vertices on the unit sphere, wound
    /// around the outward normal.
    fn octahedron() -> Mesh {
        let positions = vec![
            DVec3::X,
            DVec3::NEG_X,
            DVec3::Y,
            DVec3::NEG_Y,
            DVec3::Z,
            DVec3::NEG_Z,
        ];
        let mut triangles = Vec::new();
        for (x, sx) in [(0, 1.0), (1, -1.0)] {
            for (y, sy) in [(2, 1.0), (3, -1.0)] {
                for (z, sz) in [(4, 1.0), (5, -1.0)] {
                    triangles.push(if sx * sy * sz > 0.0 {
                        [x, y, z]
                    } else {
                        [x, z, y]
                    });
                }
            }
        }
        Mesh {
            uvs: vec![DVec2::ZERO; positions.len()],
            positions,
            triangles,
        }
    }

    fn stencil_of(sub: &Subdivision, vertex: usize) -> Vec<(u32, f64)> {
        let mut stencil: Vec<(u32, f64)> = sub.stencil(vertex).collect();
        stencil.sort_by_key(|&(c, _)| c);
        stencil
    }

    fn assert_stencil(sub: &Subdivision, vertex: usize, expected: &[(u32, f64)]) {
        let mut expected = expected.to_vec();
        expected.sort_by_key(|&(c, _)| c);
        let got = stencil_of(sub, vertex);
        assert_eq!(got.len(), expected.len(), "vertex {vertex}: {got:?}");
        for ((c, w), (ec, ew)) in got.iter().zip(&expected) {
            assert_eq!(c, ec, "vertex {vertex}: {got:?}");
            assert!((w - ew).abs() < 1e-15, "vertex {vertex}: {got:?}");
        }
    }

    /// The render vertex on the edge `a`–`b` of level 1 (by its UV, the
    /// midpoint of theirs).
    fn edge_vertex(sub: &Subdivision, mesh: &Mesh, a: usize, b: usize) -> usize {
        let uv = 0.5 * (mesh.uvs[a] + mesh.uvs[b]);
        (mesh.vertex_count()..sub.vertex_count())
            .find(|&v| (sub.uvs()[v] - uv).length() < 1e-12)
            .expect("the edge has a vertex")
    }

    #[test]
    fn loops_weights_on_a_regular_vertex_and_its_edges() {
        assert_eq!(loop_beta(6), 1.0 / 16.0);
        assert!((loop_beta(3) - 3.0 / 16.0).abs() < 1e-15);
        let mesh = fan(6);
        let sub = Subdivision::new(&mesh, 1).expect("subdivides");
        // The centre: 1 - 6β = 5/8 and β = 1/16 for each neighbour.
        let mut centre = vec![(0, 0.625)];
        centre.extend((1..=6).map(|k| (k, 1.0 / 16.0)));
        assert_stencil(&sub, 0, &centre);
        // A spoke 0–2 between the triangles 0 1 2 and 0 2 3: 3/8 its ends,
        // 1/8 the opposite corners.
        let spoke = edge_vertex(&sub, &mesh, 0, 2);
        assert_stencil(
            &sub,
            spoke,
            &[(0, 0.375), (2, 0.375), (1, 0.125), (3, 0.125)],
        );
    }

    #[test]
    fn the_rim_is_a_crease_of_its_own_vertices() {
        // A 12-gon: the rim turns 30° at each vertex, no corner.
        let mesh = fan(12);
        let sub = Subdivision::new(&mesh, 1).expect("subdivides");
        assert_stencil(&sub, 1, &[(1, 0.75), (2, 0.125), (12, 0.125)]);
        let rim_edge = edge_vertex(&sub, &mesh, 1, 2);
        assert_stencil(&sub, rim_edge, &[(1, 0.5), (2, 0.5)]);

        // Moving interior vertices leaves every rim vertex where it was, at
        // every level: the rim depends on the rim alone.
        let petal = test_petal(10.0, 4.0, 9, 17);
        let sub = Subdivision::new(&petal, 3).expect("subdivides");
        let rim = Topology::from_triangles(sub.triangles())
            .expect("manifold")
            .boundary_vertices(sub.vertex_count());
        let coarse_rim = Topology::build(&petal)
            .expect("manifold")
            .boundary_vertices(petal.vertex_count());
        let mut moved = petal.positions.clone();
        for (p, on_rim) in moved.iter_mut().zip(&coarse_rim) {
            if !on_rim {
                *p += DVec3::new(0.3, -0.7, 1.1);
            }
        }
        let (before, after) = (sub.apply(&petal.positions), sub.apply(&moved));
        let mut rim_count = 0;
        for v in (0..sub.vertex_count()).filter(|&v| rim[v]) {
            assert_eq!(before[v], after[v], "rim vertex {v} moved");
            rim_count += 1;
        }
        assert_eq!(
            rim_count,
            8 * 2 * (8 + 16),
            "the rim has 8 times as many edges"
        );
        assert!(before != after, "the interior did move");
    }

    #[test]
    fn corners_stay_where_they_are() {
        // A square's rim turns 90° at each corner.
        let mesh = fan(4);
        let sub = Subdivision::new(&mesh, 2).expect("subdivides");
        for corner in 1..=4 {
            assert_stencil(&sub, corner, &[(corner as u32, 1.0)]);
        }
        // A rectangle's four corners stay put, the vertices along its sides
        // do not.
        let mut sheet = flat_sheet(4.0, 3.0, 7, 6);
        for p in &mut sheet.positions {
            p.z = 0.1 * p.x * p.x + 0.1 * p.y * p.y;
        }
        let sub = Subdivision::new(&sheet, 2).expect("subdivides");
        let fine = sub.apply(&sheet.positions);
        for corner in [0, 6, 7 * 5, 7 * 6 - 1] {
            assert_eq!(fine[corner], sheet.positions[corner], "corner {corner}");
        }
        assert_ne!(fine[7], sheet.positions[7], "a side vertex is smoothed");
    }

    #[test]
    fn counts_are_v_plus_e_and_four_f_per_level() {
        let mesh = test_petal(10.0, 4.0, 9, 17);
        let topology = Topology::build(&mesh).expect("manifold");
        let (v, e, f) = (
            mesh.vertex_count(),
            topology.edges.len(),
            mesh.triangle_count(),
        );
        let one = Subdivision::new(&mesh, 1).expect("subdivides");
        assert_eq!(one.vertex_count(), v + e);
        assert_eq!(one.triangles().len(), 4 * f);
        assert_eq!(one.uvs().len(), v + e);
        for level in 0..4 {
            let sub = Subdivision::new(&mesh, level).expect("subdivides");
            let (cv, cf) = subdivided_counts(v as u64, e as u64, f as u64, level);
            assert_eq!(sub.vertex_count() as u64, cv, "level {level}");
            assert_eq!(sub.triangles().len() as u64, cf, "level {level}");
        }
        // About 400 particles make about 6,000 render vertices at level 2.
        let (fine, _) = subdivided_counts(400, 1130, 730, 2);
        assert_eq!(fine, 400 + 1130 + 2 * 1130 + 3 * 730);
        // Level 0 is the mesh itself.
        let zero = Subdivision::new(&mesh, 0).expect("identity");
        assert_eq!(zero.mesh(&mesh.positions), mesh);
    }

    #[test]
    fn a_plane_stays_a_plane_and_affine_maps_commute() {
        // A sheet in a tilted plane, its vertices shaken within the plane.
        let mut sheet = flat_sheet(4.0, 3.0, 7, 6);
        let (e1, e2) = (
            DVec3::new(1.0, 0.2, -0.5).normalize(),
            DVec3::new(0.1, 1.0, 0.4).normalize(),
        );
        let normal = e1.cross(e2).normalize();
        for (i, p) in sheet.positions.iter_mut().enumerate() {
            let shake = 0.1 * ((i * 7919 % 13) as f64 / 13.0 - 0.5);
            *p = (p.x + shake) * e1 + (p.y - shake) * e2 + 2.0 * normal;
        }
        let sub = Subdivision::new(&sheet, 3).expect("subdivides");
        for p in sub.apply(&sheet.positions) {
            assert!((p.dot(normal) - 2.0).abs() < 1e-12, "{p} left the plane");
        }

        // Subdividing an affinely mapped mesh = mapping the subdivided one.
        let petal = test_petal(10.0, 4.0, 9, 17);
        let sub = Subdivision::new(&petal, 2).expect("subdivides");
        let linear = glam::DMat3::from_cols(
            DVec3::new(1.2, 0.3, -0.1),
            DVec3::new(-0.4, 0.9, 0.2),
            DVec3::new(0.5, 0.1, 1.7),
        );
        let shift = DVec3::new(3.0, -1.0, 0.5);
        let map = |p: DVec3| linear * p + shift;
        let mapped: Vec<DVec3> = petal.positions.iter().map(|&p| map(p)).collect();
        for (a, b) in sub.apply(&mapped).iter().zip(sub.apply(&petal.positions)) {
            assert!((*a - map(b)).length() < 1e-12, "{a} against {}", map(b));
        }
        for v in 0..sub.vertex_count() {
            let sum: f64 = sub.stencil(v).map(|(_, w)| w).sum();
            assert!(
                (sum - 1.0).abs() < 1e-14,
                "vertex {v}: weights sum to {sum}"
            );
        }
    }

    #[test]
    fn a_closed_mesh_gets_smoother() {
        let mesh = octahedron();
        // How far the surface (its vertices and triangle centres) is from
        // one sphere, and the largest angle between neighbouring triangles.
        let roughness = |level: u32| {
            let sub = Subdivision::new(&mesh, level).expect("subdivides");
            let fine = sub.mesh(&mesh.positions);
            let centres = fine
                .triangles
                .iter()
                .map(|t| t.iter().map(|&i| fine.positions[i as usize]).sum::<DVec3>() / 3.0);
            let (lo, hi) = fine
                .positions
                .iter()
                .copied()
                .chain(centres)
                .map(DVec3::length)
                .fold((f64::MAX, 0.0_f64), |(lo, hi), r| (lo.min(r), hi.max(r)));
            let normals: Vec<DVec3> = (0..fine.triangle_count())
                .map(|t| {
                    let [a, b, c] = fine.triangle_positions(t);
                    (b - a).cross(c - a).normalize()
                })
                .collect();
            let topology = Topology::build(&fine).expect("closed");
            let kink = topology
                .edges
                .iter()
                .filter_map(|e| {
                    let right = e.right?;
                    Some(
                        normals[e.left.triangle as usize]
                            .angle_between(normals[right.triangle as usize]),
                    )
                })
                .fold(0.0_f64, f64::max);
            ((hi - lo) / hi, kink)
        };
        let (spread, kink) = roughness(0);
        assert!((spread - (1.0 - 1.0 / 3.0_f64.sqrt())).abs() < 1e-12);
        assert!((kink - (1.0_f64 / 3.0).acos()).abs() < 1e-12, "{kink}");
        let mut last_kink = kink;
        for level in 1..=4 {
            let (spread, kink) = roughness(level);
            // The kinks between triangles shrink by at least 30 % per level
            // (measured: 0.55, 0.66, 0.53, 0.51; the surface tends to a
            // smooth limit) ...
            assert!(
                kink < 0.7 * last_kink,
                "level {level}: {kink} after {last_kink}"
            );
            last_kink = kink;
            // ... which is round to within a few percent (Loop's limit of
            // an octahedron is not a sphere: its valence-4 vertices stay a
            // little flatter).
            if level >= 2 {
                assert!(spread < 0.1, "level {level}: spread {spread}");
            }
        }
    }

    #[test]
    fn windings_and_the_uv_layout_are_kept() {
        let petal = test_petal(10.0, 4.0, 9, 17);
        let sub = Subdivision::new(&petal, 1).expect("subdivides");
        let fine = sub.mesh(&petal.positions);
        // Every child faces the way its parent does (children come four by
        // four in their parent's order).
        for (t, children) in fine.triangles.chunks(4).enumerate() {
            let [a, b, c] = petal.triangle_positions(t);
            let parent = (b - a).cross(c - a);
            for tri in children {
                let [a, b, c] = tri.map(|i| fine.positions[i as usize]);
                assert!((b - a).cross(c - a).dot(parent) > 0.0, "triangle {t}");
            }
        }
        // The fine mesh is a valid organ: one piece, no UV flipped, and its
        // UV layout covers exactly the coarse one.
        let two = Subdivision::new(&petal, 2).expect("subdivides");
        let fine = two.mesh(&petal.positions);
        crate::validate(&fine).expect("a valid mesh");
        let uv_area = |m: &Mesh| -> f64 {
            (0..m.triangle_count())
                .map(|t| {
                    let [a, b, c] = m.triangle_uvs(t);
                    0.5 * (b - a).perp_dot(c - a)
                })
                .sum()
        };
        assert!((uv_area(&fine) - uv_area(&petal)).abs() < 1e-12);
        let edge = edge_vertex(&sub, &petal, 0, 1);
        assert_eq!(sub.uvs()[edge], 0.5 * (petal.uvs[0] + petal.uvs[1]));
    }

    #[test]
    fn bad_meshes_and_levels_are_refused() {
        // Two triangles touching at one vertex: a bow tie.
        let bow_tie = Mesh {
            positions: vec![
                DVec3::ZERO,
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(-1.0, 0.0, 0.0),
                DVec3::new(-1.0, -1.0, 0.0),
            ],
            uvs: vec![DVec2::ZERO; 5],
            triangles: vec![[0, 1, 2], [0, 3, 4]],
        };
        assert_eq!(
            Subdivision::new(&bow_tie, 1),
            Err(MeshError::NonManifoldVertex { vertex: 0, fans: 2 })
        );
        let mut three_on_an_edge = fan(6);
        three_on_an_edge.positions.push(DVec3::Z);
        three_on_an_edge.uvs.push(DVec2::ZERO);
        three_on_an_edge.triangles.push([0, 1, 7]);
        assert!(matches!(
            Subdivision::new(&three_on_an_edge, 1),
            Err(MeshError::NonManifoldEdge { .. })
        ));
        let mut short_uvs = fan(6);
        short_uvs.uvs.pop();
        assert!(matches!(
            Subdivision::new(&short_uvs, 1),
            Err(MeshError::UvCountMismatch { .. })
        ));
        // Too fine: refused with the count, before any memory is taken.
        let petal = test_petal(10.0, 4.0, 9, 17);
        let error = Subdivision::new(&petal, 12).expect_err("too fine");
        let MeshError::SubdivisionTooLarge {
            level: 12,
            vertices,
            limit,
        } = error
        else {
            panic!("{error:?}");
        };
        assert!(vertices > limit);
        assert!(error.to_string().contains(&vertices.to_string()));
    }
}

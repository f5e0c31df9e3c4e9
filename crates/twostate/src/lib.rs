#![warn(missing_docs)]
//! Two-state blossom (the floral blossom paper §4): an organ
//! animated from its bud shape to its open shape without a growth
//! simulation.
//!
//! From the two shapes (same vertices, triangles and UVs) every triangle
//! ("cell": the paper's cells are patches of a B-spline control net; an
//! Anthesis organ is a triangle mesh, so a cell is one triangle) gets its
//! growth property ellipse in each state and from them the primary growth
//! direction (a quaternion), the adaxial and the abaxial variation
//! ([`cells`]). An in-between shape at time `t` takes each cell's ratios
//! along the growth function G(t; g, T) of eq. (4) and its direction along
//! a spherical linear interpolation timed by a velocity curve ([`timing`]),
//! and rebuilds the positions from those per-cell transforms by one sparse
//! least-squares solve ([`TwoState::shape_at`]): the edges of every
//! triangle as close as possible (area-weighted) to the transformed bud
//! edges, with the base particles held where the organ is attached.
//!
//! The matrix of that solve is the same at every `t` (an edge Laplacian of
//! the bud), so it is factorised once (sparse Cholesky, faer) and each
//! in-between shape costs three triangular solves.

pub mod cells;
pub mod timing;

use std::collections::HashMap;

use anthesis_mesh::Mesh;
use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};
use glam::{DMat3, DVec3};
use thiserror::Error;

pub use cells::{CellGrowth, Ellipse, cell_growth};
pub use timing::{GrowthFunction, VelocityCurve};

/// Why two shapes cannot be animated one into the other.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TwoStateError {
    /// The open shape is not the bud's mesh moved: another vertex count.
    #[error(
        "the open shape has {open} vertices but the bud has {bud}: the two states must be the same mesh (same vertices in the same order)"
    )]
    DifferentVertexCount {
        /// Vertices of the bud.
        bud: usize,
        /// Vertices of the open shape.
        open: usize,
    },
    /// A coordinate is not a finite number.
    #[error("vertex {vertex} of the {state} is not a finite point")]
    NotFinite {
        /// 0-based vertex index.
        vertex: usize,
        /// "bud" or "open state".
        state: &'static str,
    },
    /// A triangle's UVs enclose no area, so its ellipse has no axes.
    #[error("triangle {triangle} has UVs that enclose no area, so its growth ellipse has no axes")]
    FlatUvs {
        /// 0-based triangle index.
        triangle: usize,
    },
    /// A triangle has collapsed to a line or a point in one state.
    #[error("triangle {triangle} of the {state} has no area")]
    FlatTriangle {
        /// 0-based triangle index.
        triangle: usize,
        /// "bud" or "open state".
        state: &'static str,
    },
    /// The open shape's triangles are not the bud's.
    #[error(
        "triangle {triangle} of the open shape is not the bud's: the two states must have the same triangles in the same order"
    )]
    DifferentTriangles {
        /// 0-based index of the first triangle that differs (or the
        /// shorter list's length when the counts differ).
        triangle: usize,
    },
    /// No base particle was given, so nothing holds the organ in place.
    #[error("the organ has no base particles, so nothing attaches it while it opens")]
    NoBase,
    /// A base particle index is not a vertex of the mesh.
    #[error("base particle {index} is not a vertex of the mesh ({vertices} vertices)")]
    BaseOutOfRange {
        /// The index given.
        index: u32,
        /// Vertices of the mesh.
        vertices: usize,
    },
    /// Some part of the mesh is not connected to a base particle, so its
    /// place is undetermined.
    #[error(
        "part of the mesh is not connected to the base, so where it goes is undetermined ({0})"
    )]
    Unattached(String),
}

/// An organ between two states, ready to give its shape at any time.
#[derive(Debug)]
pub struct TwoState {
    bud: Mesh,
    open: Vec<DVec3>,
    cells: Vec<CellGrowth>,
    /// Whether each vertex is a base particle (held, not solved for).
    held: Vec<bool>,
    /// Index among the solved (free) vertices, per vertex.
    free_index: Vec<Option<usize>>,
    /// Cholesky factor of the free block of the edge Laplacian.
    factor: faer::sparse::linalg::solvers::Llt<usize, f64>,
    /// Area weight of every (triangle, edge) term: the bud triangle's area.
    weights: Vec<f64>,
    /// The growth function (ratios) and the velocity curve (directions).
    pub growth: GrowthFunction,
    /// The timing of the directions' spherical interpolation.
    pub velocity: VelocityCurve,
}

/// The three edges of a triangle as (from, to) corner numbers.
const EDGES: [(usize, usize); 3] = [(0, 1), (1, 2), (2, 0)];

impl TwoState {
    /// Extracts the growth variations between `bud` (its positions, UVs and
    /// triangles) and `open` (the same vertices moved), holding the
    /// particles in `base` (e.g. the template's base region) at positions
    /// interpolated between their two states.
    pub fn new(bud: &Mesh, open: &[DVec3], base: &[u32]) -> Result<TwoState, TwoStateError> {
        let n = bud.positions.len();
        if open.len() != n {
            return Err(TwoStateError::DifferentVertexCount {
                bud: n,
                open: open.len(),
            });
        }
        for (state, positions) in [("bud", &bud.positions[..]), ("open state", open)] {
            if let Some(vertex) = positions.iter().position(|p| !p.is_finite()) {
                return Err(TwoStateError::NotFinite { vertex, state });
            }
        }
        if base.is_empty() {
            return Err(TwoStateError::NoBase);
        }
        let mut held = vec![false; n];
        for &index in base {
            *held
                .get_mut(index as usize)
                .ok_or(TwoStateError::BaseOutOfRange { index, vertices: n })? = true;
        }
        let cells = cell_growth(bud, open)?;
        let mut free_index = vec![None; n];
        let mut free = 0;
        for (i, slot) in free_index.iter_mut().enumerate() {
            if !held[i] {
                *slot = Some(free);
                free += 1;
            }
        }
        let weights: Vec<f64> = (0..bud.triangles.len())
            .map(|t| bud.triangle_area(t))
            .collect();
        // The free block of Σ w ‖x_j − x_i‖² (an edge Laplacian).
        let mut entries: HashMap<(usize, usize), f64> = HashMap::new();
        for (t, tri) in bud.triangles.iter().enumerate() {
            for (a, b) in EDGES {
                let (i, j) = (tri[a] as usize, tri[b] as usize);
                let w = weights[t];
                for (p, q, s) in [(i, i, w), (j, j, w), (i, j, -w), (j, i, -w)] {
                    if let (Some(fp), Some(fq)) = (free_index[p], free_index[q]) {
                        *entries.entry((fp, fq)).or_insert(0.0) += s;
                    }
                }
            }
        }
        let triplets: Vec<Triplet<usize, usize, f64>> = entries
            .into_iter()
            .map(|((r, c), v)| Triplet::new(r, c, v))
            .collect();
        let matrix = SparseColMat::<usize, f64>::try_new_from_triplets(free, free, &triplets)
            .map_err(|e| TwoStateError::Unattached(format!("{e:?}")))?;
        let factor = matrix
            .sp_cholesky(Side::Lower)
            .map_err(|e| TwoStateError::Unattached(format!("{e:?}")))?;
        Ok(TwoState {
            bud: bud.clone(),
            open: open.to_vec(),
            cells,
            held,
            free_index,
            factor,
            weights,
            growth: GrowthFunction::default(),
            velocity: VelocityCurve::default(),
        })
    }

    /// [`TwoState::new`] for two meshes read from files: the open mesh must
    /// have the bud's triangles (its UVs are not used: the bud's are).
    pub fn from_meshes(bud: &Mesh, open: &Mesh, base: &[u32]) -> Result<TwoState, TwoStateError> {
        if open.positions.len() == bud.positions.len() {
            let differs = (0..bud.triangles.len().max(open.triangles.len()))
                .find(|&t| bud.triangles.get(t) != open.triangles.get(t));
            if let Some(triangle) = differs {
                return Err(TwoStateError::DifferentTriangles { triangle });
            }
        }
        TwoState::new(bud, &open.positions, base)
    }

    /// The growth variations of every cell (triangle), in triangle order.
    pub fn cells(&self) -> &[CellGrowth] {
        &self.cells
    }

    /// The shape at time `t` (in the growth function's time unit, `0` the
    /// bud and `growth.duration` the end of the opening).
    pub fn shape_at(&self, t: f64) -> Vec<DVec3> {
        let turn = self.velocity.fraction(&self.growth, t);
        let growth = self.growth.fraction(t);
        let transforms: Vec<DMat3> = self
            .cells
            .iter()
            .map(|c| c.transform(turn, growth))
            .collect();
        // Base particles follow the velocity curve from bud to open.
        let held_at = |i: usize| self.bud.positions[i].lerp(self.open[i], turn);
        let free = self.factor_size();
        let mut rhs = Mat::<f64>::zeros(free, 3);
        for (t, tri) in self.bud.triangles.iter().enumerate() {
            let w = self.weights[t];
            for (a, b) in EDGES {
                let (i, j) = (tri[a] as usize, tri[b] as usize);
                // Target edge x_j − x_i = F (X_j − X_i).
                let target = transforms[t] * (self.bud.positions[j] - self.bud.positions[i]);
                let mut add = |p: usize, v: DVec3| {
                    if let Some(fp) = self.free_index[p] {
                        for k in 0..3 {
                            rhs[(fp, k)] += v[k];
                        }
                    }
                };
                add(j, target * w);
                add(i, -target * w);
                // Held ends move to the right-hand side.
                if self.held[i] && !self.held[j] {
                    add(j, held_at(i) * w);
                }
                if self.held[j] && !self.held[i] {
                    add(i, held_at(j) * w);
                }
            }
        }
        let solved = self.factor.solve(&rhs);
        (0..self.bud.positions.len())
            .map(|i| match self.free_index[i] {
                Some(f) => DVec3::new(solved[(f, 0)], solved[(f, 1)], solved[(f, 2)]),
                None => held_at(i),
            })
            .collect()
    }

    fn factor_size(&self) -> usize {
        self.free_index.iter().filter(|f| f.is_some()).count()
    }
}

#[cfg(test)]
mod tests;

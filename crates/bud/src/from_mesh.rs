//! Remeshing an existing template mesh at another edge length, keeping its
//! UV layout (painted maps are rasters over the UVs, so they stay valid).
//!
//! The mesh is turned into a [`Surface`] and handed to the same remesher
//! that meshes bud surfaces (one rule for both): a parameter point
//! `(s, t)` in the unit square is the mesh's UV point
//!
//! ```text
//! v = v_min + t (v_max - v_min),   u = u_left(v) + s (u_right(v) - u_left(v))
//! ```
//!
//! where `[u_left(v), u_right(v)]` is the span of the UV outline at `v`;
//! the 3D point is the old surface there (the UV triangle holding it,
//! barycentric interpolation). So the new margins run along the old
//! outline, the base row along the old base, a pointed tip (or base) stays
//! the old tip's point, and every new vertex lies on the old surface with
//! the UV it had there. This needs what the UV convention already says
//! (ARCHITECTURE.md: `u` across, `v` from base to tip): every line of
//! constant `v` crosses the UV outline once, and the UV layout does not
//! overlap itself; anything else is refused with a [`BudError`] saying so.

use anthesis_mesh::{Mesh, Topology};
use glam::{DVec2, DVec3};

use crate::remesh::{self, SurfaceKind};
use crate::{Bud, BudError, RemeshOptions, Surface};

/// Lines of constant `v` at which the outline is checked (crossings, area).
const CHECK_LINES: usize = 1024;
/// Buckets along `v` that index the outline's edges.
const OUTLINE_BUCKETS: usize = 256;
/// How much more UV area the triangles may cover than the outline holds
/// before the layout counts as overlapping (the outline's area is
/// integrated numerically).
const OVERLAP_TOLERANCE: f64 = 0.01;

/// A template mesh seen as a parametric surface over the unit square (see
/// the module documentation).
#[derive(Debug)]
pub struct MeshSurface<'a> {
    mesh: &'a Mesh,
    v_min: f64,
    v_max: f64,
    /// The UV outline's edges, and for each bucket along `v` the edges
    /// whose `v` range meets it.
    outline: Vec<[DVec2; 2]>,
    outline_buckets: Vec<Vec<u32>>,
    /// Triangles by UV grid cell (those whose UV bounding box meets it).
    grid: UvGrid,
    /// Whether the mesh's triangles wind clockwise in UV.
    clockwise_in_uv: bool,
}

#[derive(Debug)]
struct UvGrid {
    origin: DVec2,
    cell: DVec2,
    columns: usize,
    rows: usize,
    /// Triangle indices of cell `c` are `items[offsets[c]..offsets[c + 1]]`.
    offsets: Vec<usize>,
    items: Vec<u32>,
}

impl<'a> MeshSurface<'a> {
    /// Reads `mesh`'s UV layout; refuses an invalid mesh, a layout with no
    /// extent, one that a line of constant `v` crosses more than once, and
    /// one that overlaps or folds over itself.
    pub fn new(mesh: &'a Mesh) -> Result<Self, BudError> {
        let topology = anthesis_mesh::validate(mesh)?;
        let (lo, hi) = mesh.uvs.iter().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), uv| (lo.min(*uv), hi.max(*uv)),
        );
        let extent = hi - lo;
        if !(extent.x > 0.0 && extent.y > 0.0 && extent.is_finite()) {
            return Err(BudError::NoUvArea);
        }
        let outline = outline_edges(mesh, &topology);
        let (v_min, v_max) = (lo.y, hi.y);
        let bucket_of = |v: f64| {
            (((v - v_min) / (v_max - v_min) * OUTLINE_BUCKETS as f64) as usize)
                .min(OUTLINE_BUCKETS - 1)
        };
        let mut outline_buckets = vec![Vec::new(); OUTLINE_BUCKETS];
        for (i, [a, b]) in outline.iter().enumerate() {
            for bucket in &mut outline_buckets[bucket_of(a.y.min(b.y))..=bucket_of(a.y.max(b.y))] {
                bucket.push(i as u32);
            }
        }
        let mut signed_area = 0.0;
        let mut covered_area = 0.0;
        for t in 0..mesh.triangle_count() {
            let area = uv_signed_area(mesh.triangle_uvs(t));
            signed_area += area;
            covered_area += area.abs();
        }
        let surface = MeshSurface {
            mesh,
            v_min,
            v_max,
            outline,
            outline_buckets,
            grid: UvGrid::new(mesh, lo, extent),
            clockwise_in_uv: signed_area < 0.0,
        };
        // Every line of constant v crosses the outline exactly twice (half-
        // open rule: a vertex on the line counts on one side).
        let mut outline_area = 0.0;
        for k in 0..CHECK_LINES {
            let v = v_min + (k as f64 + 0.5) / CHECK_LINES as f64 * (v_max - v_min);
            let crossings = surface
                .outline
                .iter()
                .filter(|[a, b]| (a.y <= v) != (b.y <= v))
                .count();
            if crossings != 2 {
                return Err(BudError::UvNotMonotone { v, crossings });
            }
            let (left, right) = surface.span(v);
            outline_area += (right - left) * (v_max - v_min) / CHECK_LINES as f64;
        }
        let folded = signed_area.abs() < (1.0 - OVERLAP_TOLERANCE) * covered_area;
        if folded || covered_area > (1.0 + OVERLAP_TOLERANCE) * outline_area {
            return Err(BudError::UvOverlap {
                covered_area,
                outline_area,
            });
        }
        Ok(surface)
    }

    /// The mesh UV of parameter point `st` (see the module documentation).
    pub fn uv_at(&self, st: DVec2) -> DVec2 {
        let v = self.v_min + st.y.clamp(0.0, 1.0) * (self.v_max - self.v_min);
        let (left, right) = self.span(v);
        DVec2::new(left + st.x.clamp(0.0, 1.0) * (right - left), v)
    }

    /// The point of the old surface at mesh UV `uv` (on the nearest triangle
    /// if `uv` is just outside the outline).
    pub fn point_at_uv(&self, uv: DVec2) -> DVec3 {
        match self.grid.locate(self.mesh, uv) {
            Some((t, weights)) => {
                let [a, b, c] = self.mesh.triangle_positions(t);
                weights[0] * a + weights[1] * b + weights[2] * c
            }
            None => DVec3::NAN,
        }
    }

    /// `[u_left, u_right]` of the outline at `v` (the smallest and largest
    /// `u` where the line of constant `v` meets it).
    fn span(&self, v: f64) -> (f64, f64) {
        let bucket = (((v - self.v_min) / (self.v_max - self.v_min) * OUTLINE_BUCKETS as f64)
            as usize)
            .min(OUTLINE_BUCKETS - 1);
        let mut left = f64::INFINITY;
        let mut right = f64::NEG_INFINITY;
        for &i in &self.outline_buckets[bucket] {
            let [a, b] = self.outline[i as usize];
            let (lo, hi) = (a.y.min(b.y), a.y.max(b.y));
            if v < lo || v > hi {
                continue;
            }
            let us = if hi - lo <= 1e-15 * (self.v_max - self.v_min) {
                // Along the line: both ends.
                [a.x, b.x]
            } else {
                let u = a.x + (b.x - a.x) * ((v - a.y) / (b.y - a.y));
                [u, u]
            };
            for u in us {
                left = left.min(u);
                right = right.max(u);
            }
        }
        if left > right {
            (f64::NAN, f64::NAN)
        } else {
            (left, right)
        }
    }
}

impl Surface for MeshSurface<'_> {
    fn point(&self, point_in_uv: DVec2) -> DVec3 {
        self.point_at_uv(self.uv_at(point_in_uv))
    }

    fn layout_uv(&self, point_in_uv: DVec2) -> DVec2 {
        self.uv_at(point_in_uv)
    }
}

/// Remeshes `mesh` at `options.target_edge` with the bud remesher, keeping
/// its UV layout (see the module documentation): the new mesh's vertices lie
/// on the old surface, each with the old surface's UV at that point; its
/// triangles wind around the same side as the old ones (the same sense in
/// UV). `options.inner_side` is not used: the old winding decides.
pub fn remesh_mesh(mesh: &Mesh, options: &RemeshOptions) -> Result<Bud, BudError> {
    let surface = MeshSurface::new(mesh)?;
    let mut remeshed = remesh::remesh(&surface, options, SurfaceKind::TemplateMesh)?;
    // The remesher winds counter-clockwise in its parameters, which is
    // counter-clockwise in UV (s grows with u, t with v).
    if surface.clockwise_in_uv {
        for t in &mut remeshed.triangles {
            t.swap(1, 2);
        }
    }
    crate::checked(remeshed, options)
}

fn uv_signed_area([a, b, c]: [DVec2; 3]) -> f64 {
    0.5 * (b - a).perp_dot(c - a)
}

/// The boundary edges of `mesh` in UV.
fn outline_edges(mesh: &Mesh, topology: &Topology) -> Vec<[DVec2; 2]> {
    topology
        .boundary_edges()
        .map(|e| e.map(|i| mesh.uvs[i as usize]))
        .collect()
}

impl UvGrid {
    fn new(mesh: &Mesh, origin: DVec2, extent: DVec2) -> UvGrid {
        let side = ((mesh.triangle_count() as f64).sqrt().ceil() as usize).clamp(1, 1024);
        let (columns, rows) = (side, side);
        let cell = extent / DVec2::new(columns as f64, rows as f64);
        let mut grid = UvGrid {
            origin,
            cell,
            columns,
            rows,
            offsets: vec![0; columns * rows + 1],
            items: Vec::new(),
        };
        let ranges: Vec<_> = (0..mesh.triangle_count())
            .map(|t| {
                let [a, b, c] = mesh.triangle_uvs(t);
                let (lo, hi) = grid.cell_of(a.min(b).min(c));
                let (lo2, hi2) = grid.cell_of(a.max(b).max(c));
                (lo..=lo2, hi..=hi2)
            })
            .collect();
        for (xs, ys) in &ranges {
            for y in ys.clone() {
                for x in xs.clone() {
                    grid.offsets[y * columns + x + 1] += 1;
                }
            }
        }
        for i in 0..columns * rows {
            grid.offsets[i + 1] += grid.offsets[i];
        }
        let mut fill = grid.offsets.clone();
        grid.items = vec![0; grid.offsets[columns * rows]];
        for (t, (xs, ys)) in ranges.into_iter().enumerate() {
            for y in ys {
                for x in xs.clone() {
                    let c = y * columns + x;
                    grid.items[fill[c]] = t as u32;
                    fill[c] += 1;
                }
            }
        }
        grid
    }

    /// The cell holding `uv` (clamped into the grid), as (column, row).
    fn cell_of(&self, uv: DVec2) -> (usize, usize) {
        let at = (uv - self.origin) / self.cell;
        let column = (at.x.max(0.0) as usize).min(self.columns - 1);
        let row = (at.y.max(0.0) as usize).min(self.rows - 1);
        (column, row)
    }

    /// The triangle holding `uv` and its barycentric weights; if none holds
    /// it (a point on the outline, just outside by rounding), the nearest
    /// by barycentric distance, weights clamped to the triangle.
    fn locate(&self, mesh: &Mesh, uv: DVec2) -> Option<(usize, [f64; 3])> {
        if !uv.is_finite() {
            return None;
        }
        let (cx, cy) = self.cell_of(uv);
        let mut best: Option<(f64, usize, [f64; 3])> = None;
        for ring in 0..self.columns.max(self.rows) {
            for y in cy.saturating_sub(ring)..=(cy + ring).min(self.rows - 1) {
                for x in cx.saturating_sub(ring)..=(cx + ring).min(self.columns - 1) {
                    if x.abs_diff(cx) != ring && y.abs_diff(cy) != ring {
                        continue;
                    }
                    let c = y * self.columns + x;
                    for &t in &self.items[self.offsets[c]..self.offsets[c + 1]] {
                        let Some(weights) = barycentric(mesh.triangle_uvs(t as usize), uv) else {
                            continue;
                        };
                        let score = weights[0].min(weights[1]).min(weights[2]);
                        if score >= -1e-12 {
                            return Some((t as usize, weights));
                        }
                        if best.is_none_or(|(s, _, _)| score > s) {
                            best = Some((score, t as usize, weights));
                        }
                    }
                }
            }
            if best.is_some() && ring >= 1 {
                break;
            }
        }
        best.map(|(_, t, weights)| {
            let clamped = weights.map(|w| w.max(0.0));
            let sum: f64 = clamped.iter().sum();
            (t, clamped.map(|w| w / sum))
        })
    }
}

/// Barycentric weights of `p` in the UV triangle; `None` if it has no area.
fn barycentric([a, b, c]: [DVec2; 3], p: DVec2) -> Option<[f64; 3]> {
    let area = (b - a).perp_dot(c - a);
    let scale = (b - a).length_squared().max((c - a).length_squared());
    if area.abs() <= 1e-14 * scale || scale == 0.0 {
        return None;
    }
    let wb = (p - a).perp_dot(c - a) / area;
    let wc = (b - a).perp_dot(p - a) / area;
    Some([1.0 - wb - wc, wb, wc])
}

//! Remeshing a parametric surface into a near-isotropic triangle mesh.
//!
//! 1. **Layout.** Rows of points at constant `v`, `target · √3/2` apart in 3D
//!    (the height of an equilateral triangle; lengths along `v` are the mean
//!    of five lines of constant `u`). Each row gets `round(width / target)`
//!    segments of equal 3D arc length, odd rows shifted by half a segment: a
//!    hexagonal lattice. The base row (`v = 0`) and the top row (`v = 1`) run
//!    from margin to margin; a top narrower than half the target becomes a
//!    single tip vertex. The margins (`u = 0`, `u = 1`) get their own points,
//!    spaced `target` apart along them, so the boundary is evenly sampled
//!    whatever the rows do; inner-row points too close to a margin point are
//!    left out.
//! 2. **Strips.** Consecutive rows are stitched into triangle strips, and each
//!    margin is stitched to the row ends beside it, always adding the triangle
//!    whose new diagonal is shorter.
//! 3. **Improvement.** Rounds of edge flips that raise the smaller of the two
//!    triangles' smallest angles, each followed by one Gauss–Seidel sweep of
//!    tangential smoothing: a vertex moves towards the area-weighted mean of
//!    the circumcentres of its triangles (the optimal-Delaunay update, which
//!    evens out angles), a boundary vertex halfway between that and the
//!    midpoint of its two boundary neighbours. The 3D move is pulled back to
//!    the parameter domain through the surface's Jacobian (one Gauss–Newton
//!    step); margin vertices slide along `v`, base and top vertices along
//!    `u`, corners and the tip stay, and a move that would fold a triangle in
//!    the parameter domain is shortened or skipped.
//!
//! The mesh winds counter-clockwise in UV (around `dS/du × dS/dv`). Its UVs
//! are the parameters, or where the surface maps them
//! ([`crate::Surface::layout_uv`]; triangles are kept counter-clockwise
//! there too).

mod improve;
mod layout;
mod strips;

use anthesis_mesh::Mesh;
use glam::{DVec2, DVec3};

use crate::{BudError, RemeshOptions, Surface};

/// Samples used to measure lengths along `v`.
const SAMPLES_ALONG_V: usize = 256;
/// Minimum samples used to measure a row's width.
const SAMPLES_ACROSS: usize = 64;
/// Inner-row points closer than this (times the target edge) to a margin
/// vertex or the tip are left out.
const NEAR_BOUNDARY: f64 = 0.55;
/// A width below this fraction of the organ's size counts as zero.
const ZERO_WIDTH: f64 = 1e-6;

/// How a vertex may move during smoothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Pin {
    Free,
    /// On the base (`v = 0`) or a blunt tip (`v = 1`): slides along `u`.
    SlideU,
    /// On a margin (`u = 0` or `u = 1`): slides along `v`.
    SlideV,
    Fixed,
}

/// Vertex indices of the rows and margins (see [`Work::lay_out`]).
struct Layout {
    rows: Vec<Vec<u32>>,
    margins: [Vec<u32>; 2],
}

struct Work<'a> {
    surface: &'a dyn Surface,
    uvs: Vec<DVec2>,
    positions: Vec<DVec3>,
    pins: Vec<Pin>,
    triangles: Vec<[u32; 3]>,
    /// The two neighbours of each boundary vertex along the boundary.
    boundary_neighbours: Vec<Vec<u32>>,
}

/// What is remeshed.
///
/// A bud surface may end in a pointed tip only (its base attaches to the
/// receptacle). A template mesh remeshed through its UVs
/// ([`crate::remesh_mesh`]) may also have a pointed base (e.g. a
/// disc-shaped UV layout), and, being piecewise flat with the kinks of its
/// old triangles, its smoothing keeps a move only if it does not make the
/// smallest angle around the vertex worse (below 20°): on the shipped
/// Eustoma petal, unguarded smoothing pushed a vertex next to the blunt
/// tip's edge (a 6.4° triangle). Bud surfaces keep the unguarded rule, so
/// the committed buds are built as before.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum SurfaceKind {
    Bud,
    TemplateMesh,
}

pub(crate) fn remesh(
    surface: &dyn Surface,
    options: &RemeshOptions,
    kind: SurfaceKind,
) -> Result<Mesh, BudError> {
    let h = options.target_edge;
    if !(h.is_finite() && h > 0.0) {
        return Err(BudError::InvalidTargetEdge(h));
    }
    let mut work = Work {
        surface,
        uvs: Vec::new(),
        positions: Vec::new(),
        pins: Vec::new(),
        triangles: Vec::new(),
        boundary_neighbours: Vec::new(),
    };
    let layout = work.lay_out(options, kind)?;
    work.triangulate(&layout);
    for _ in 0..options.smoothing_iterations {
        for _ in 0..4 {
            if work.flip_pass() == 0 {
                break;
            }
        }
        work.smooth_pass(kind == SurfaceKind::TemplateMesh);
    }
    for _ in 0..8 {
        if work.flip_pass() == 0 {
            break;
        }
    }
    Ok(Mesh {
        positions: work.positions,
        uvs: work.uvs.iter().map(|&p| surface.layout_uv(p)).collect(),
        triangles: work.triangles,
    })
}

/// Evaluates the surface, refusing non-finite points.
fn point(surface: &dyn Surface, uv: DVec2) -> Result<DVec3, BudError> {
    let p = surface.point(uv);
    if p.is_finite() {
        Ok(p)
    } else {
        Err(BudError::NonFinitePoint { u: uv.x, v: uv.y })
    }
}

/// Cumulative 3D arc length of `n + 1` samples along the polyline
/// `t -> at(t)`, `t` in `[0, 1]`.
fn cumulative_length(
    n: usize,
    mut at: impl FnMut(f64) -> Result<DVec3, BudError>,
) -> Result<Vec<f64>, BudError> {
    let mut lengths = Vec::with_capacity(n + 1);
    let mut previous = at(0.0)?;
    let mut total = 0.0;
    lengths.push(0.0);
    for k in 1..=n {
        let p = at(k as f64 / n as f64)?;
        total += (p - previous).length();
        lengths.push(total);
        previous = p;
    }
    Ok(lengths)
}

/// The parameter `t` in `[0, 1]` at which the cumulative length (sampled
/// uniformly in `t`) reaches `target`.
fn invert_length(cumulative: &[f64], target: f64) -> f64 {
    let n = cumulative.len() - 1;
    let k = cumulative.partition_point(|&l| l < target).clamp(1, n);
    let (l0, l1) = (cumulative[k - 1], cumulative[k]);
    let f = if l1 > l0 {
        ((target - l0) / (l1 - l0)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (k - 1) as f64 / n as f64 + f / n as f64
}

impl Work<'_> {
    fn add_vertex(&mut self, uv: DVec2, pin: Pin) -> Result<u32, BudError> {
        let p = point(self.surface, uv)?;
        self.uvs.push(uv);
        self.positions.push(p);
        self.pins.push(pin);
        Ok((self.uvs.len() - 1) as u32)
    }
}

//! Scanned petals (issue 14 item 6; Chaudhry et al. §III.C–§IV:
//! reconstructed polygon models turned into curve-defined PDE surfaces).
//!
//! A petal mesh of any triangulation and without UVs (a photogrammetry or
//! CAD export) becomes a [`PdeSweep`] in the organ template frame:
//!
//! 1. **Outline** ([`ScanOutline::of`]): the mesh must be one manifold
//!    piece with exactly one boundary loop (a closed scan, or one with
//!    holes, is refused naming the loops).
//! 2. **Corners** ([`ScanOutline::detect_corners`]): the base span, the
//!    two margins and the tip on that loop. The tip is the outline point
//!    farthest from the scan's (area-weighted) centroid; the base is the
//!    outline point farthest the other way along that axis, and its two
//!    corners are the sharpest turns of the outline (turning angle over a
//!    window of 3 % of the perimeter) within a fifth of the perimeter on
//!    either side of it. The tip is one point when the outline turns by at
//!    least 90° there; otherwise it is the span between the sharpest turns
//!    on either side of it (a rounded or cut top). The user may change all
//!    of them ([`ScanCorners`]).
//! 3. **Parameters** : the scan is mapped onto the parameter domain by a
//!    harmonic map (cotangent weights, clamped positive so the map cannot
//!    fold) with the outline's spans mapped by arc length onto the domain's
//!    sides: base to `v = 0`, margins to `u = 0` and `u = 1`, the tip span
//!    to `v = 1` (a pointed tip: the domain is a triangle whose apex is the
//!    tip, read as the square with its top side collapsed).
//! 4. **Fit** : a [`PdeSweep`] is linear in the control points of its
//!    margins and across-tangents for a fixed `k_s/k_b`, so they are solved
//!    by area-weighted least squares (a pointed tip shares one tip control
//!    point between the margins, with zero tangents there, so the fitted
//!    petal comes to a point as the remesher expects); then each scan point
//!    is projected to its closest parameters on the fitted surface (outline
//!    points along their own side) and the fit is solved again, for a few
//!    rounds. A few `k_s/k_b` values are tried and the best kept.
//! 5. **Errors** ([`ScanFit`]): RMS (area-weighted) and maximum distance
//!    scan→surface at the scan's vertices, and surface→scan sampled on a
//!    41×41 grid of parameters against the scan's triangles, each also as a
//!    fraction of the petal's length (base to tip along the fitted surface,
//!    through the middle of each row: [`middle_length`]).
//! 6. **Placement** : base (`S(0.5, 0)`) at the origin, the base→tip chord
//!    along +Y, the inner side to −Z. The inner side is by default the side
//!    the scan is concave to (the side its outline lies on, seen from the
//!    surface's mean point, along the mean normal); `flip_inner_side` takes
//!    the other. `u` is made to run along −X (like the shipped petals), so
//!    `dS/du × dS/dv` points to the inner side.
//!
//! The result is meshed like any bud surface ([`crate::build_organ`]), with
//! UVs by convention.

use anthesis_mesh::{Mesh, MeshError, Topology};
use glam::{DMat3, DVec2, DVec3};
use thiserror::Error;

use crate::surface::{BezierCurve, PdeSweep, Surface, bernstein3};

/// Why a scan cannot become a petal.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ScanError {
    /// The mesh is not one valid manifold surface.
    #[error("the scan is not one manifold surface: {0}")]
    Mesh(#[from] MeshError),
    /// No boundary at all.
    #[error("the scan is a closed surface (it has no outline): a petal needs one open outline")]
    Closed,
    /// More than one boundary loop: holes.
    #[error(
        "the scan has {loops} boundary loops: a petal has one outline, so it has {holes} hole(s) (the largest other loop has {hole_vertices} vertices, near ({near})); fill the holes in the modelling tool first"
    )]
    Holes {
        /// Boundary loops found.
        loops: usize,
        /// Loops besides the outline.
        holes: usize,
        /// Vertices of the largest loop besides the outline.
        hole_vertices: usize,
        /// A point on it, in the scan's coordinates.
        near: DVec3,
    },
    /// The outline is too coarse.
    #[error(
        "the scan's outline has only {0} vertices; at least 8 are needed to tell its base, margins and tip apart"
    )]
    TooFewOutlineVertices(usize),
    /// Corners that do not make a base, two margins and a tip.
    #[error("the base and tip do not split the outline into base, margins and tip: {0}")]
    BadCorners(String),
    /// The fit failed numerically.
    #[error("the fit failed: {0}")]
    Fit(String),
}

/// The scan's outline: its one boundary loop.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanOutline {
    /// Mesh vertices around the loop, in the direction of the triangles'
    /// winding.
    pub vertices: Vec<u32>,
    /// Arc length from `vertices[0]` to each vertex.
    pub arc: Vec<f64>,
    /// The loop's length.
    pub perimeter: f64,
}

/// Where the base and the tip are on the outline, as positions in
/// [`ScanOutline::vertices`], in loop order: the base runs from
/// `base[0]` to `base[1]`, one margin from `base[1]` to `tip[0]`, the tip
/// from `tip[0]` to `tip[1]` (one point when they are equal), the other
/// margin from `tip[1]` back to `base[0]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ScanCorners {
    /// The base's two corners.
    pub base: [usize; 2],
    /// The tip's two ends (equal for a pointed tip).
    pub tip: [usize; 2],
}

impl ScanCorners {
    /// Whether the tip is one point.
    pub fn pointed(&self) -> bool {
        self.tip[0] == self.tip[1]
    }
}

/// How to fit a scan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanFitOptions {
    /// The seed's `k_s / k_b`; `None` tries a few (0, 2, 10) and keeps the
    /// best.
    pub stretch_to_bend: Option<f64>,
    /// The most rounds of parameter correction after the first fit (they
    /// stop when a round lowers the mean squared distance by less than
    /// 0.5 %).
    pub rounds: usize,
    /// Take the side the scan is convex to as the inner one.
    pub flip_inner_side: bool,
}

impl Default for ScanFitOptions {
    fn default() -> Self {
        ScanFitOptions {
            stretch_to_bend: None,
            rounds: 60,
            flip_inner_side: false,
        }
    }
}

/// A fitted scan.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanFit {
    /// The fitted surface, in the organ template frame.
    pub sweep: PdeSweep,
    /// The petal's length along the surface, base to tip: the arc length
    /// of the curve through the middle of each of its rows
    /// ([`middle_length`]).
    pub length: f64,
    /// Scan→surface at the scan's vertices: RMS (area-weighted) and
    /// maximum distance, in the scan's units.
    pub scan_to_surface: [f64; 2],
    /// Surface→scan, sampled: RMS and maximum distance.
    pub surface_to_scan: [f64; 2],
    /// The rigid motion from the scan's coordinates to the template frame:
    /// `template = rotation * (scan - origin)`.
    pub rotation: DMat3,
    /// The scan's point that became the template frame's origin (the base).
    pub origin: DVec3,
    /// The corners used.
    pub corners: ScanCorners,
}

impl ScanFit {
    /// Scan→surface RMS and maximum as fractions of the length.
    pub fn relative_scan_to_surface(&self) -> [f64; 2] {
        self.scan_to_surface.map(|d| d / self.length)
    }

    /// Surface→scan RMS and maximum as fractions of the length.
    pub fn relative_surface_to_scan(&self) -> [f64; 2] {
        self.surface_to_scan.map(|d| d / self.length)
    }

    /// A scan point in the template frame.
    pub fn to_template(&self, scan_point: DVec3) -> DVec3 {
        self.rotation * (scan_point - self.origin)
    }

    /// One line for a report, errors in % of the length.
    pub fn summary(&self) -> String {
        let [rms, max] = self.relative_scan_to_surface();
        let [back_rms, back_max] = self.relative_surface_to_scan();
        format!(
            "length {:.3}; scan→surface RMS {:.2} % max {:.2} %; surface→scan RMS {:.2} % max {:.2} % (k_s/k_b {})",
            self.length,
            100.0 * rms,
            100.0 * max,
            100.0 * back_rms,
            100.0 * back_max,
            self.sweep.stretch_to_bend()
        )
    }
}

impl ScanOutline {
    /// The one boundary loop of `mesh` (checked as a shape first:
    /// [`anthesis_mesh::validate_shape`]).
    pub fn of(mesh: &Mesh) -> Result<ScanOutline, ScanError> {
        let topology = anthesis_mesh::validate_shape(mesh)?;
        outline(mesh, &topology)
    }

    /// The mesh vertex at loop position `k` (taken modulo the loop).
    pub fn vertex(&self, k: usize) -> u32 {
        self.vertices[k % self.vertices.len()]
    }

    /// The arc length along the loop from position `from` forwards to `to`.
    pub fn span(&self, from: usize, to: usize) -> f64 {
        let d = self.arc[to % self.len()] - self.arc[from % self.len()];
        if d < 0.0 { d + self.perimeter } else { d }
    }

    /// Vertices around the loop.
    pub fn len(&self) -> usize {
        self.vertices.len()
    }

    /// Whether the loop is empty (never, for an outline that was found).
    pub fn is_empty(&self) -> bool {
        self.vertices.is_empty()
    }

    /// The turning angle (radians) of the outline at each loop position,
    /// over a window of `window` arc length on either side.
    pub fn turning(&self, mesh: &Mesh, window: f64) -> Vec<f64> {
        let n = self.len();
        (0..n)
            .map(|k| {
                let here = self.point(mesh, self.arc[k]);
                let before = self.point(mesh, self.arc[k] - window);
                let after = self.point(mesh, self.arc[k] + window);
                let (a, b) = (here - before, after - here);
                if a.length_squared() == 0.0 || b.length_squared() == 0.0 {
                    0.0
                } else {
                    a.angle_between(b)
                }
            })
            .collect()
    }

    /// The point at arc length `s` (taken modulo the perimeter).
    pub fn point(&self, mesh: &Mesh, s: f64) -> DVec3 {
        let s = s.rem_euclid(self.perimeter);
        let n = self.len();
        // The last position with arc <= s.
        let k = self.arc.partition_point(|&a| a <= s).saturating_sub(1);
        let a = mesh.positions[self.vertices[k] as usize];
        let b = mesh.positions[self.vertices[(k + 1) % n] as usize];
        let length = self.span(k, k + 1);
        if length <= 0.0 {
            return a;
        }
        a.lerp(b, ((s - self.arc[k]) / length).clamp(0.0, 1.0))
    }

    /// The base and tip found automatically (see the module notes).
    pub fn detect_corners(&self, mesh: &Mesh) -> ScanCorners {
        let n = self.len();
        let mean_edge = self.perimeter / n as f64;
        let window = (0.015 * self.perimeter).max(1.5 * mean_edge);
        let turn = self.turning(mesh, window);
        let centroid = area_centroid(mesh);
        let position = |k: usize| mesh.positions[self.vertex(k) as usize];
        let tip = (0..n)
            .max_by(|&a, &b| {
                position(a)
                    .distance_squared(centroid)
                    .total_cmp(&position(b).distance_squared(centroid))
            })
            .unwrap_or(0);
        let axis = (position(tip) - centroid).normalize_or_zero();
        let base = (0..n)
            .min_by(|&a, &b| {
                (position(a) - centroid)
                    .dot(axis)
                    .total_cmp(&(position(b) - centroid).dot(axis))
            })
            .unwrap_or(0);
        // Loop distance (either way round) between two positions.
        let apart = |a: usize, b: usize| self.span(a, b).min(self.span(b, a));
        // The sharpest turn within `reach` of `center`, away from `not`.
        let sharpest = |center: usize, reach: f64, not: Option<usize>| {
            (0..n)
                .filter(|&k| apart(k, center) <= reach)
                .filter(|&k| not.is_none_or(|x| apart(k, x) > 1.5 * window))
                .max_by(|&a, &b| turn[a].total_cmp(&turn[b]))
        };
        // Two positions in loop order (the short way round from the first).
        let ordered = |a: usize, b: usize| {
            if self.span(a, b) <= self.span(b, a) {
                [a, b]
            } else {
                [b, a]
            }
        };
        let reach = 0.2 * self.perimeter;
        // The two sharpest turns near an end, and whether the end is one
        // sharp point (a turn of 90° or more, the next sharpest under half
        // of it).
        let end = |center: usize| {
            let first = sharpest(center, reach, None).unwrap_or(center);
            let second = sharpest(center, reach, Some(first)).unwrap_or((first + 1) % n);
            let pointed =
                turn[first] >= std::f64::consts::FRAC_PI_2 && turn[second] < 0.5 * turn[first];
            (first, ordered(first, second), pointed, center)
        };
        let (far, near) = (end(tip), end(base));
        // A pointed end is the tip; otherwise the base is the end whose
        // corners are closer together (a claw, not a rounded top).
        let far_is_tip = match (far.2, near.2) {
            (true, false) => true,
            (false, true) => false,
            (false, false) => self.span(far.1[0], far.1[1]) >= self.span(near.1[0], near.1[1]),
            (true, true) => true,
        };
        let (tip_end, base_end) = if far_is_tip { (far, near) } else { (near, far) };
        let base_corners = base_end.1;
        // A tip that is a span: its ends are the sharpest turns on either
        // side of the end's middle (a rounded top turns most at its
        // corners, but its middle may turn too), away from the base.
        let side = |forwards: bool| {
            let center = tip_end.3;
            (0..n)
                .filter(|&k| {
                    let along = if forwards {
                        self.span(center, k)
                    } else {
                        self.span(k, center)
                    };
                    along > window && along <= reach && apart(k, base_end.3) > reach
                })
                .max_by(|&a, &b| turn[a].total_cmp(&turn[b]))
        };
        let tip_ends = if tip_end.2 {
            [tip_end.0, tip_end.0]
        } else {
            match (side(false), side(true)) {
                (Some(before), Some(after)) => [before, after],
                _ => tip_end.1,
            }
        };
        ScanCorners {
            base: base_corners,
            tip: tip_ends,
        }
    }

    /// Checks that `corners` split the loop into base, margin, tip, margin
    /// with each margin at least two edges long.
    pub fn check(&self, corners: &ScanCorners) -> Result<(), ScanError> {
        let n = self.len();
        let [b0, b1] = corners.base;
        let [t0, t1] = corners.tip;
        if [b0, b1, t0, t1].iter().any(|&k| k >= n) {
            return Err(ScanError::BadCorners(format!(
                "a corner is past the outline's {n} vertices"
            )));
        }
        if b0 == b1 {
            return Err(ScanError::BadCorners(
                "the base's two corners are the same point: the base needs a width".into(),
            ));
        }
        // Steps along the loop from b0.
        let steps = |k: usize| (k + n - b0) % n;
        let (sb1, st0, st1) = (steps(b1), steps(t0), steps(t1));
        if !(sb1 < st0 && st0 <= st1 && st1 < n) || st1 == 0 {
            return Err(ScanError::BadCorners(
                "going round the outline from the base the order must be base, one margin, tip, the other margin".into(),
            ));
        }
        if st0 - sb1 < 2 || n - st1 < 2 {
            return Err(ScanError::BadCorners(
                "a margin has fewer than two edges: move the tip or the base away from it".into(),
            ));
        }
        Ok(())
    }
}

/// The area-weighted centroid of a mesh.
fn area_centroid(mesh: &Mesh) -> DVec3 {
    let mut sum = DVec3::ZERO;
    let mut area = 0.0;
    for t in 0..mesh.triangles.len() {
        let a = mesh.triangle_area(t);
        sum += a * mesh.triangle_positions(t).iter().sum::<DVec3>() / 3.0;
        area += a;
    }
    if area > 0.0 { sum / area } else { DVec3::ZERO }
}

/// The boundary loops of a checked mesh; the one outline or why not.
fn outline(mesh: &Mesh, topology: &Topology) -> Result<ScanOutline, ScanError> {
    let vertex_count = mesh.positions.len();
    // A manifold mesh (checked) has at most one outgoing boundary edge per
    // vertex.
    let mut next = vec![u32::MAX; vertex_count];
    for [a, b] in topology.boundary_edges() {
        next[a as usize] = b;
    }
    let mut seen = vec![false; vertex_count];
    let mut loops: Vec<Vec<u32>> = Vec::new();
    for start in 0..vertex_count {
        if next[start] == u32::MAX || seen[start] {
            continue;
        }
        let mut cycle = Vec::new();
        let mut v = start as u32;
        while !seen[v as usize] {
            seen[v as usize] = true;
            cycle.push(v);
            v = next[v as usize];
            if v == u32::MAX {
                break;
            }
        }
        loops.push(cycle);
    }
    if loops.is_empty() {
        return Err(ScanError::Closed);
    }
    let length = |cycle: &[u32]| -> f64 {
        (0..cycle.len())
            .map(|k| {
                mesh.positions[cycle[k] as usize]
                    .distance(mesh.positions[cycle[(k + 1) % cycle.len()] as usize])
            })
            .sum()
    };
    loops.sort_by(|a, b| length(b).total_cmp(&length(a)));
    if loops.len() > 1 {
        let hole = &loops[1];
        return Err(ScanError::Holes {
            loops: loops.len(),
            holes: loops.len() - 1,
            hole_vertices: hole.len(),
            near: mesh.positions[hole[0] as usize],
        });
    }
    let vertices = loops.swap_remove(0);
    if vertices.len() < 8 {
        return Err(ScanError::TooFewOutlineVertices(vertices.len()));
    }
    let mut arc = Vec::with_capacity(vertices.len());
    let mut s = 0.0;
    for k in 0..vertices.len() {
        arc.push(s);
        s += mesh.positions[vertices[k] as usize]
            .distance(mesh.positions[vertices[(k + 1) % vertices.len()] as usize]);
    }
    Ok(ScanOutline {
        vertices,
        arc,
        perimeter: s,
    })
}

/// Where each scan vertex is in the parameters, and which of them are
/// held on a side of the square while projecting.
struct Parameters {
    uv: Vec<DVec2>,
    /// `Some(u)` / `Some(v)`: the parameter held (outline points).
    held_u: Vec<Option<f64>>,
    held_v: Vec<Option<f64>>,
}

/// The harmonic map of the scan onto the parameter domain (see the module
/// notes): the outline placed on the domain's sides
/// ([`outline_on_domain`]), the inner vertices where the cotangent
/// weights ([`cotangent_weights`]) balance them ([`harmonic_interior`]),
/// then read as square parameters ([`square_parameters`]).
fn parameterise(
    mesh: &Mesh,
    outline: &ScanOutline,
    corners: &ScanCorners,
) -> Result<Parameters, ScanError> {
    let pointed = corners.pointed();
    let Boundary {
        mut domain,
        fixed,
        held_u,
        held_v,
    } = outline_on_domain(mesh.positions.len(), outline, corners);
    let neighbours = cotangent_weights(mesh);
    harmonic_interior(&neighbours, &fixed, &mut domain)?;
    let uv = square_parameters(&domain, pointed);
    Ok(Parameters { uv, held_u, held_v })
}

/// The outline's vertices on the parameter domain, and which parameters
/// they hold.
struct Boundary {
    /// Each vertex's point in the domain (the outline's placed, the rest
    /// zero).
    domain: Vec<DVec2>,
    /// Whether the vertex is on the outline (fixed in the harmonic map).
    fixed: Vec<bool>,
    held_u: Vec<Option<f64>>,
    held_v: Vec<Option<f64>>,
}

/// The outline of `n` vertices placed on the domain: base (0,0)-(1,0);
/// top (1,1)-(0,1), or the apex (0.5, 1); each span by arc length.
fn outline_on_domain(n: usize, outline: &ScanOutline, corners: &ScanCorners) -> Boundary {
    let loop_len = outline.len();
    let pointed = corners.pointed();
    // The domain: base (0,0)-(1,0); top (1,1)-(0,1), or the apex (0.5, 1).
    let [b0, b1] = corners.base;
    let [t0, t1] = corners.tip;
    let top_right = if pointed {
        DVec2::new(0.5, 1.0)
    } else {
        DVec2::new(1.0, 1.0)
    };
    let top_left = if pointed {
        DVec2::new(0.5, 1.0)
    } else {
        DVec2::new(0.0, 1.0)
    };
    let mut domain = vec![DVec2::ZERO; n];
    let mut fixed = vec![false; n];
    let mut held_u = vec![None; n];
    let mut held_v = vec![None; n];
    // Walk one span of the loop from `from` to `to`, placing its vertices
    // by arc length from `a` to `b`.
    let mut walk = |from: usize,
                    to: usize,
                    a: DVec2,
                    b: DVec2,
                    hold: &dyn Fn(f64) -> (Option<f64>, Option<f64>)| {
        let total = outline.span(from, to);
        let steps = (to + loop_len - from) % loop_len;
        for step in 0..steps {
            let k = (from + step) % loop_len;
            let t = if total > 0.0 {
                outline.span(from, k) / total
            } else {
                0.0
            };
            let v = outline.vertex(k) as usize;
            domain[v] = a.lerp(b, t);
            fixed[v] = true;
            // The span's first vertex is a corner: held where it is.
            let (hu, hv) = if step == 0 {
                (Some(a.x), Some(a.y))
            } else {
                hold(t)
            };
            held_u[v] = hu;
            held_v[v] = hv;
        }
    };
    // The base and the tip span keep their arc-length parameters (free,
    // their few points let the base row's parameters drift); margin points
    // slide along their side.
    walk(b0, b1, DVec2::ZERO, DVec2::X, &|t| (Some(t), Some(0.0)));
    walk(b1, t0, DVec2::X, top_right, &|_| (Some(1.0), None));
    if !pointed {
        walk(t0, t1, top_right, top_left, &|t| (Some(1.0 - t), Some(1.0)));
    }
    walk(t1, b0, top_left, DVec2::ZERO, &|_| (Some(0.0), None));
    if pointed {
        let tip = outline.vertex(t0) as usize;
        held_u[tip] = Some(0.5);
        held_v[tip] = Some(1.0);
    }
    Boundary {
        domain,
        fixed,
        held_u,
        held_v,
    }
}

/// Cotangent weights per vertex, clamped positive (a positive-weight
/// harmonic map onto a convex domain cannot fold).
fn cotangent_weights(mesh: &Mesh) -> Vec<Vec<(usize, f64)>> {
    let n = mesh.positions.len();
    let mut neighbours: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
    let mut add = |i: usize, j: usize, w: f64| {
        if let Some(entry) = neighbours[i].iter_mut().find(|(k, _)| *k == j) {
            entry.1 += w;
        } else {
            neighbours[i].push((j, w));
        }
    };
    for t in &mesh.triangles {
        for k in 0..3 {
            let (i, j, o) = (
                t[k] as usize,
                t[(k + 1) % 3] as usize,
                t[(k + 2) % 3] as usize,
            );
            let (a, b) = (
                mesh.positions[i] - mesh.positions[o],
                mesh.positions[j] - mesh.positions[o],
            );
            let cross = a.cross(b).length();
            let cot = if cross > 0.0 { a.dot(b) / cross } else { 0.0 };
            add(i, j, 0.5 * cot);
            add(j, i, 0.5 * cot);
        }
    }
    for list in &mut neighbours {
        let mean = list.iter().map(|(_, w)| w.abs()).sum::<f64>() / list.len().max(1) as f64;
        for entry in list.iter_mut() {
            entry.1 = entry.1.max(1e-3 * mean.max(1e-12));
        }
    }
    neighbours
}

/// The free (not `fixed`) vertices of `domain` placed where the weights
/// `neighbours` balance them: Jacobi-preconditioned conjugate gradients,
/// both coordinates at once, from the mean of the outline.
fn harmonic_interior(
    neighbours: &[Vec<(usize, f64)>],
    fixed: &[bool],
    domain: &mut [DVec2],
) -> Result<(), ScanError> {
    let n = domain.len();
    // Conjugate gradients on the free vertices, both coordinates at once.
    let free: Vec<usize> = (0..n).filter(|&v| !fixed[v]).collect();
    let mut index = vec![usize::MAX; n];
    for (k, &v) in free.iter().enumerate() {
        index[v] = k;
    }
    let diagonal: Vec<f64> = free
        .iter()
        .map(|&v| neighbours[v].iter().map(|(_, w)| w).sum())
        .collect();
    let apply = |x: &[DVec2], out: &mut [DVec2]| {
        for (k, &v) in free.iter().enumerate() {
            let mut s = diagonal[k] * x[k];
            for &(j, w) in &neighbours[v] {
                if index[j] != usize::MAX {
                    s -= w * x[index[j]];
                }
            }
            out[k] = s;
        }
    };
    let rhs: Vec<DVec2> = free
        .iter()
        .map(|&v| {
            neighbours[v]
                .iter()
                .filter(|(j, _)| fixed[*j])
                .map(|&(j, w)| w * domain[j])
                .sum()
        })
        .collect();
    let m = free.len();
    if m == 0 {
        return Ok(());
    }
    // Start from the mean of the outline.
    let start = (0..n)
        .filter(|&v| fixed[v])
        .map(|v| domain[v])
        .sum::<DVec2>()
        / (n - m).max(1) as f64;
    let mut x = vec![start; m];
    let mut ax = vec![DVec2::ZERO; m];
    apply(&x, &mut ax);
    let mut r: Vec<DVec2> = (0..m).map(|k| rhs[k] - ax[k]).collect();
    let mut z: Vec<DVec2> = (0..m).map(|k| r[k] / diagonal[k]).collect();
    let mut p = z.clone();
    let dot = |a: &[DVec2], b: &[DVec2]| -> DVec2 { a.iter().zip(b).map(|(a, b)| *a * *b).sum() };
    let mut rz = dot(&r, &z);
    let norm0 = dot(&rhs, &rhs).max_element().sqrt().max(1e-300);
    let mut ap = vec![DVec2::ZERO; m];
    for _ in 0..(4 * m + 100) {
        apply(&p, &mut ap);
        let pap = dot(&p, &ap);
        let alpha = DVec2::new(
            if pap.x > 0.0 { rz.x / pap.x } else { 0.0 },
            if pap.y > 0.0 { rz.y / pap.y } else { 0.0 },
        );
        for k in 0..m {
            x[k] += alpha * p[k];
            r[k] -= alpha * ap[k];
        }
        if dot(&r, &r).max_element().sqrt() <= 1e-12 * norm0 {
            break;
        }
        for k in 0..m {
            z[k] = r[k] / diagonal[k];
        }
        let rz_new = dot(&r, &z);
        let beta = DVec2::new(
            if rz.x > 0.0 { rz_new.x / rz.x } else { 0.0 },
            if rz.y > 0.0 { rz_new.y / rz.y } else { 0.0 },
        );
        rz = rz_new;
        for k in 0..m {
            p[k] = z[k] + beta * p[k];
        }
    }
    if x.iter().any(|p| !p.is_finite()) {
        return Err(ScanError::Fit(
            "the harmonic map of the scan onto the unit square is not finite".into(),
        ));
    }
    for (k, &v) in free.iter().enumerate() {
        domain[v] = x[k];
    }
    Ok(())
}

/// The domain points as square parameters (a triangle's rows widen to
/// the square's).
fn square_parameters(domain: &[DVec2], pointed: bool) -> Vec<DVec2> {
    domain
        .iter()
        .map(|d| {
            let width = if pointed { 1.0 - d.y } else { 1.0 };
            let u = if width > 1e-9 {
                0.5 + (d.x - 0.5) / width
            } else {
                0.5
            };
            DVec2::new(u.clamp(0.0, 1.0), d.y.clamp(0.0, 1.0))
        })
        .collect()
}

/// The fitted unknowns: which of the 16 control values (curve `k` of
/// C0, T0, C1, T1, control point `m`) each unknown is.
fn unknown_slots(pointed: bool) -> Vec<Vec<(usize, usize)>> {
    let mut unknowns = Vec::new();
    for k in 0..4 {
        for m in 0..4 {
            if pointed && m == 3 {
                // C0(1) = C1(1) shared, T0(1) = T1(1) = 0.
                if k == 0 {
                    unknowns.push(vec![(0, 3), (2, 3)]);
                }
                continue;
            }
            unknowns.push(vec![(k, m)]);
        }
    }
    unknowns
}

/// The sweep of the fitted unknowns `x` (one point per unknown).
fn sweep_of(x: &[DVec3], slots: &[Vec<(usize, usize)>], stretch_to_bend: f64) -> PdeSweep {
    let mut control = [[DVec3::ZERO; 4]; 4];
    for (value, slot) in x.iter().zip(slots) {
        for &(k, m) in slot {
            control[k][m] = *value;
        }
    }
    PdeSweep::new(
        BezierCurve::new(control[0]),
        BezierCurve::new(control[2]),
        BezierCurve::new(control[1]),
        BezierCurve::new(control[3]),
        stretch_to_bend,
    )
}

/// The area-weighted least-squares sweep through `points` at `uv`.
fn solve(
    points: &[DVec3],
    uv: &[DVec2],
    weight: &[f64],
    slots: &[Vec<(usize, usize)>],
    stretch_to_bend: f64,
) -> Result<PdeSweep, ScanError> {
    let size = slots.len();
    // The weights of C0, T0, C1, T1 in u come from a sweep with this k_s/k_b.
    let shape = PdeSweep::new(
        BezierCurve::constant(DVec3::ZERO),
        BezierCurve::constant(DVec3::ZERO),
        BezierCurve::constant(DVec3::ZERO),
        BezierCurve::constant(DVec3::ZERO),
        stretch_to_bend,
    );
    let mut normal = vec![0.0; size * size];
    let mut rhs = vec![DVec3::ZERO; size];
    let mut row = vec![0.0; size];
    for ((p, q), w) in points.iter().zip(uv).zip(weight) {
        let wu = shape.weights(q.x);
        let bv = bernstein3(q.y);
        for (r, slot) in row.iter_mut().zip(slots) {
            *r = slot.iter().map(|&(k, m)| wu[k] * bv[m]).sum();
        }
        for a in 0..size {
            if row[a] == 0.0 {
                continue;
            }
            rhs[a] += w * row[a] * *p;
            for b in 0..size {
                normal[a * size + b] += w * row[a] * row[b];
            }
        }
    }
    // A tiny ridge keeps a control value the data hardly sees finite.
    let trace: f64 = (0..size).map(|a| normal[a * size + a]).sum();
    for a in 0..size {
        normal[a * size + a] += 1e-10 * trace / size as f64;
    }
    let x = cholesky_solve(&mut normal, size, &rhs)
        .ok_or_else(|| ScanError::Fit("the least-squares system is singular".into()))?;
    Ok(sweep_of(&x, slots, stretch_to_bend))
}

/// Solves the symmetric positive definite `a x = b` (a is overwritten).
fn cholesky_solve(a: &mut [f64], n: usize, b: &[DVec3]) -> Option<Vec<DVec3>> {
    for j in 0..n {
        let mut d = a[j * n + j];
        for k in 0..j {
            d -= a[j * n + k] * a[j * n + k];
        }
        if d <= 0.0 || !d.is_finite() {
            return None;
        }
        let d = d.sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut s = a[i * n + j];
            for k in 0..j {
                s -= a[i * n + k] * a[j * n + k];
            }
            a[i * n + j] = s / d;
        }
    }
    let mut y = b.to_vec();
    for i in 0..n {
        for k in 0..i {
            y[i] = y[i] - a[i * n + k] * y[k];
        }
        y[i] /= a[i * n + i];
    }
    for i in (0..n).rev() {
        for k in i + 1..n {
            y[i] = y[i] - a[k * n + i] * y[k];
        }
        y[i] /= a[i * n + i];
    }
    Some(y)
}

/// The closest parameters to `p` on `surface` from `start` (Gauss–Newton
/// with finite-difference derivatives, held parameters kept).
fn project(
    surface: &PdeSweep,
    p: DVec3,
    start: DVec2,
    held_u: Option<f64>,
    held_v: Option<f64>,
) -> DVec2 {
    let mut q = start;
    if let Some(u) = held_u {
        q.x = u;
    }
    if let Some(v) = held_v {
        q.y = v;
    }
    if held_u.is_some() && held_v.is_some() {
        return q;
    }
    let h = 1e-5;
    for _ in 0..6 {
        let s = surface.point(q);
        let r = s - p;
        let du = (surface.point(DVec2::new(q.x + h, q.y))
            - surface.point(DVec2::new(q.x - h, q.y)))
            / (2.0 * h);
        let dv = (surface.point(DVec2::new(q.x, q.y + h))
            - surface.point(DVec2::new(q.x, q.y - h)))
            / (2.0 * h);
        let step = match (held_u.is_some(), held_v.is_some()) {
            (true, _) => {
                let a = dv.length_squared();
                if a <= 0.0 {
                    break;
                }
                DVec2::new(0.0, -r.dot(dv) / a)
            }
            (_, true) => {
                let a = du.length_squared();
                if a <= 0.0 {
                    break;
                }
                DVec2::new(-r.dot(du) / a, 0.0)
            }
            _ => {
                let (a, b, c) = (du.dot(du), du.dot(dv), dv.dot(dv));
                let det = a * c - b * b;
                if det <= 1e-300 {
                    break;
                }
                let (gu, gv) = (r.dot(du), r.dot(dv));
                DVec2::new(-(c * gu - b * gv) / det, -(a * gv - b * gu) / det)
            }
        };
        // At most a quarter of the square per step.
        let step = step.clamp(DVec2::splat(-0.25), DVec2::splat(0.25));
        let next = (q + step).clamp(DVec2::ZERO, DVec2::ONE);
        if surface.point(next).distance_squared(p) > r.length_squared() {
            break;
        }
        let moved = (next - q).length();
        q = next;
        if moved < 1e-10 {
            break;
        }
    }
    q
}

/// Each vertex's share of the area (a third of its triangles').
fn vertex_areas(mesh: &Mesh) -> Vec<f64> {
    let mut area = vec![0.0; mesh.positions.len()];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let a = mesh.triangle_area(t) / 3.0;
        for &v in tri {
            area[v as usize] += a;
        }
    }
    area
}

/// Fits `mesh` (a scanned petal: any triangulation, UVs ignored) with the
/// base and tip at `corners` (or found by [`ScanOutline::detect_corners`]);
/// see the module notes.
pub fn fit_scan(
    mesh: &Mesh,
    corners: Option<ScanCorners>,
    options: &ScanFitOptions,
) -> Result<ScanFit, ScanError> {
    let outline = ScanOutline::of(mesh)?;
    let corners = corners.unwrap_or_else(|| outline.detect_corners(mesh));
    outline.check(&corners)?;
    let start = parameterise(mesh, &outline, &corners)?;
    let weight = vertex_areas(mesh);
    let (sweep, uv) = least_squares(mesh, &start, &weight, corners.pointed(), options)?;
    let scan_to_surface = scan_to_surface(mesh, &sweep, &uv, &weight);
    let surface_to_scan = surface_to_scan(&sweep, mesh);
    let (rotation, base) = template_frame(&sweep, options.flip_inner_side)?;
    let placed = in_template_frame(&sweep, rotation, base);
    let length = middle_length(&placed);
    Ok(ScanFit {
        sweep: placed,
        length,
        scan_to_surface,
        surface_to_scan,
        rotation,
        origin: base,
        corners,
    })
}

/// The sweep fitted to the scan's vertices weighted by area from the
/// harmonic parameters `start`: for each stretch-to-bend ratio tried two
/// rounds of solving and projecting the points to their closest
/// parameters, then the best goes on for the rounds left. Returns the
/// sweep and each vertex's parameters.
fn least_squares(
    mesh: &Mesh,
    start: &Parameters,
    weight: &[f64],
    pointed: bool,
    options: &ScanFitOptions,
) -> Result<(PdeSweep, Vec<DVec2>), ScanError> {
    let slots = unknown_slots(pointed);
    let tried: Vec<f64> = match options.stretch_to_bend {
        Some(lambda) => vec![lambda],
        None => vec![0.0, 2.0, 10.0],
    };
    let total: f64 = weight.iter().sum::<f64>().max(1e-300);
    let cost = |sweep: &PdeSweep, uv: &[DVec2]| {
        mesh.positions
            .iter()
            .zip(uv)
            .zip(weight)
            .map(|((p, q), w)| w * sweep.point(*q).distance_squared(*p))
            .sum::<f64>()
            / total
    };
    // Rounds of projecting the scan's points to their closest parameters
    // and solving again, until a round lowers the cost by less than 0.5 %
    // (or `rounds` were made).
    let improve = |mut sweep: PdeSweep, mut uv: Vec<DVec2>, rounds: usize, lambda: f64| {
        let mut last = f64::INFINITY;
        for _ in 0..rounds {
            for (k, p) in mesh.positions.iter().enumerate() {
                uv[k] = project(&sweep, *p, uv[k], start.held_u[k], start.held_v[k]);
            }
            let now = cost(&sweep, &uv);
            if now > last * 0.995 {
                break;
            }
            last = now;
            sweep = solve(&mesh.positions, &uv, weight, &slots, lambda)?;
        }
        Ok::<_, ScanError>((sweep, uv))
    };
    // Each k_s/k_b gets two rounds; the best goes on.
    let screening = options.rounds.min(2);
    let mut best: Option<(f64, f64, PdeSweep, Vec<DVec2>)> = None;
    for lambda in tried {
        let first = solve(&mesh.positions, &start.uv, weight, &slots, lambda)?;
        let (sweep, uv) = improve(first, start.uv.clone(), screening, lambda)?;
        let c = cost(&sweep, &uv);
        if c.is_finite() && best.as_ref().is_none_or(|(b, ..)| c < *b) {
            best = Some((c, lambda, sweep, uv));
        }
    }
    let Some((_, lambda, sweep, uv)) = best else {
        return Err(ScanError::Fit("no finite fit".into()));
    };
    improve(sweep, uv, options.rounds - screening, lambda)
}

/// The scan's distances to the fitted sweep, RMS (weighted by `weight`)
/// and largest, each vertex at its own closest parameters from `uv`
/// (outline points not held to their side: the true distance).
fn scan_to_surface(mesh: &Mesh, sweep: &PdeSweep, uv: &[DVec2], weight: &[f64]) -> [f64; 2] {
    let total: f64 = weight.iter().sum::<f64>().max(1e-300);
    let (mut sum, mut max) = (0.0, 0.0f64);
    for ((p, q), w) in mesh.positions.iter().zip(uv).zip(weight) {
        let free = project(sweep, *p, *q, None, None);
        let d = sweep.point(free).distance(*p);
        sum += w * d * d;
        max = max.max(d);
    }
    let rms = (sum / total).sqrt();
    [rms, max]
}

/// The template frame of a fitted sweep: the rotation into it and its
/// origin (the base's middle). Y runs from base to tip, Z away from the
/// inner side, which is the concave side (the outline lies on the concave
/// side of a cupped petal) unless `flip_inner_side`.
fn template_frame(sweep: &PdeSweep, flip_inner_side: bool) -> Result<(DMat3, DVec3), ScanError> {
    let base = sweep.point(DVec2::new(0.5, 0.0));
    let tip = sweep.point(DVec2::new(0.5, 1.0));
    let y = (tip - base).normalize_or_zero();
    if y == DVec3::ZERO {
        return Err(ScanError::Fit(
            "the fitted base and tip are the same point".into(),
        ));
    }
    let (mut normal, mut surface_mean, mut rim_mean) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
    let samples = 24;
    for j in 0..=samples {
        for i in 0..=samples {
            let q = DVec2::new(i as f64, j as f64) / samples as f64;
            let h = 1e-5;
            let du = sweep.point(DVec2::new((q.x + h).min(1.0), q.y))
                - sweep.point(DVec2::new((q.x - h).max(0.0), q.y));
            let dv = sweep.point(DVec2::new(q.x, (q.y + h).min(1.0)))
                - sweep.point(DVec2::new(q.x, (q.y - h).max(0.0)));
            normal += du.cross(dv);
            surface_mean += sweep.point(q);
        }
        let t = j as f64 / samples as f64;
        rim_mean += sweep.curve0.at(t) + sweep.curve1.at(t);
    }
    surface_mean /= ((samples + 1) * (samples + 1)) as f64;
    rim_mean /= (2 * (samples + 1)) as f64;
    let mut n = (normal - normal.dot(y) * y).normalize_or_zero();
    if n == DVec3::ZERO {
        n = y.any_orthonormal_vector();
    }
    // The outline lies on the concave side of a cupped petal.
    let concave = if (rim_mean - surface_mean).dot(n) < 0.0 {
        -n
    } else {
        n
    };
    let inner = if flip_inner_side { -concave } else { concave };
    let z = -inner;
    let x = y.cross(z);
    let rotation = DMat3::from_cols(x, y, z).transpose();
    Ok((rotation, base))
}

/// The sweep put in the template frame (`rotation` about `base`), u along
/// −X like the shipped petals.
fn in_template_frame(sweep: &PdeSweep, rotation: DMat3, base: DVec3) -> PdeSweep {
    let place = |c: &BezierCurve| BezierCurve::new(c.control.map(|p| rotation * (p - base)));
    let turn = |c: &BezierCurve| BezierCurve::new(c.control.map(|t| rotation * t));
    let mut placed = PdeSweep::new(
        place(&sweep.curve0),
        place(&sweep.curve1),
        turn(&sweep.tangent0),
        turn(&sweep.tangent1),
        sweep.stretch_to_bend(),
    );
    // u along −X, like the shipped petals (then dS/du × dS/dv points to
    // the inner side, −Z).
    let h = 1e-4;
    let across = placed.point(DVec2::new(0.5 + h, 0.5)) - placed.point(DVec2::new(0.5 - h, 0.5));
    if across.x > 0.0 {
        placed = reversed_across(&placed);
    }
    placed
}

/// The same surface with `u` running the other way: `S'(u, v) = S(1 − u, v)`.
pub fn reversed_across(sweep: &PdeSweep) -> PdeSweep {
    let negated = |c: &BezierCurve| BezierCurve::new(c.control.map(|t| -t));
    PdeSweep::new(
        sweep.curve1,
        sweep.curve0,
        negated(&sweep.tangent1),
        negated(&sweep.tangent0),
        sweep.stretch_to_bend(),
    )
}

/// The arc length of `u = 0.5` from the base to the tip.
pub fn midrib_length(surface: &dyn Surface) -> f64 {
    let steps = 200;
    (0..steps)
        .map(|k| {
            let a = surface.point(DVec2::new(0.5, k as f64 / steps as f64));
            let b = surface.point(DVec2::new(0.5, (k + 1) as f64 / steps as f64));
            a.distance(b)
        })
        .sum()
}

/// The petal's length along the surface, whatever its parameters: the
/// arc length of the curve through the middle (by arc length across) of
/// each line of constant `v`, from the base to the tip.
pub fn middle_length(surface: &dyn Surface) -> f64 {
    let (rows, across) = (200, 64);
    let middle = |v: f64| {
        let points: Vec<DVec3> = (0..=across)
            .map(|i| surface.point(DVec2::new(i as f64 / across as f64, v)))
            .collect();
        let lengths: Vec<f64> = points.windows(2).map(|w| w[0].distance(w[1])).collect();
        let half = lengths.iter().sum::<f64>() / 2.0;
        let mut walked = 0.0;
        for (k, l) in lengths.iter().enumerate() {
            if walked + l >= half && *l > 0.0 {
                return points[k].lerp(points[k + 1], (half - walked) / l);
            }
            walked += l;
        }
        points[across / 2]
    };
    let mut previous = middle(0.0);
    let mut length = 0.0;
    for j in 1..=rows {
        let next = middle(j as f64 / rows as f64);
        length += previous.distance(next);
        previous = next;
    }
    length
}

/// RMS and maximum distance from a 41×41 grid of the surface's parameters
/// to the nearest scan triangle.
fn surface_to_scan(surface: &PdeSweep, mesh: &Mesh) -> [f64; 2] {
    let samples = 40;
    let grid = TriangleGrid::new(mesh);
    let (mut sum, mut max, mut count) = (0.0, 0.0f64, 0usize);
    for j in 0..=samples {
        for i in 0..=samples {
            let p = surface.point(DVec2::new(i as f64, j as f64) / samples as f64);
            let d = grid.distance(mesh, p);
            sum += d * d;
            max = max.max(d);
            count += 1;
        }
    }
    [(sum / count as f64).sqrt(), max]
}

/// The scan's triangles bucketed by the cells of a uniform grid their
/// bounding boxes touch, for nearest-triangle queries.
struct TriangleGrid {
    low: DVec3,
    cell: f64,
    size: [i64; 3],
    cells: std::collections::HashMap<[i64; 3], Vec<u32>>,
}

impl TriangleGrid {
    fn new(mesh: &Mesh) -> TriangleGrid {
        let (mut low, mut high) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for p in &mesh.positions {
            low = low.min(*p);
            high = high.max(*p);
        }
        let edges: f64 = (0..mesh.triangles.len())
            .map(|t| {
                let [a, b, c] = mesh.triangle_positions(t);
                a.distance(b) + b.distance(c) + c.distance(a)
            })
            .sum();
        let mean_edge = edges / (3 * mesh.triangles.len().max(1)) as f64;
        let extent = (high - low).max_element().max(1e-12);
        let cell = (2.0 * mean_edge).max(extent / 256.0).max(1e-12);
        let index = |p: DVec3| ((p - low) / cell).floor().as_i64vec3().to_array();
        let mut cells: std::collections::HashMap<[i64; 3], Vec<u32>> =
            std::collections::HashMap::new();
        for t in 0..mesh.triangles.len() {
            let corners = mesh.triangle_positions(t);
            let a = index(
                corners
                    .iter()
                    .fold(DVec3::splat(f64::INFINITY), |m, p| m.min(*p)),
            );
            let b = index(
                corners
                    .iter()
                    .fold(DVec3::splat(f64::NEG_INFINITY), |m, p| m.max(*p)),
            );
            for x in a[0]..=b[0] {
                for y in a[1]..=b[1] {
                    for z in a[2]..=b[2] {
                        cells.entry([x, y, z]).or_default().push(t as u32);
                    }
                }
            }
        }
        let size = index(high).map(|i| i + 1);
        TriangleGrid {
            low,
            cell,
            size,
            cells,
        }
    }

    /// The distance from `p` to the nearest triangle: cubes of cells
    /// around `p`'s cell, growing until no farther cell can hold a nearer
    /// triangle.
    fn distance(&self, mesh: &Mesh, p: DVec3) -> f64 {
        let q = (p - self.low) / self.cell;
        let centre = q.floor().as_i64vec3().to_array();
        let mut best = f64::INFINITY;
        // A cube this large covers the whole grid.
        let reach = (0..3)
            .map(|k| centre[k].abs().max((centre[k] - self.size[k]).abs()))
            .max()
            .unwrap_or(0)
            + 1;
        for r in 0..=reach {
            for x in centre[0] - r..=centre[0] + r {
                for y in centre[1] - r..=centre[1] + r {
                    for z in centre[2] - r..=centre[2] + r {
                        let on_shell = (x - centre[0]).abs() == r
                            || (y - centre[1]).abs() == r
                            || (z - centre[2]).abs() == r;
                        if !on_shell {
                            continue;
                        }
                        let Some(triangles) = self.cells.get(&[x, y, z]) else {
                            continue;
                        };
                        for &t in triangles {
                            let [a, b, c] = mesh.triangle_positions(t as usize);
                            let (n, _) =
                                anthesis_mesh::nearest::closest_point_on_triangle(p, a, b, c);
                            best = best.min(n.distance(p));
                        }
                    }
                }
            }
            // Cells outside this cube are at least this far from p.
            let inside = (0..3)
                .map(|k| {
                    let lower = q[k] - (centre[k] - r) as f64;
                    let upper = (centre[k] + r + 1) as f64 - q[k];
                    lower.min(upper)
                })
                .fold(f64::INFINITY, f64::min)
                * self.cell;
            if best <= inside {
                break;
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_triangle_grid_finds_the_nearest_triangle_as_trying_every_one_does() {
        let mesh = anthesis_mesh::generate::test_petal(10.0, 4.0, 7, 15);
        let grid = TriangleGrid::new(&mesh);
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..300 {
            // Points in and well outside the petal's box.
            let p = DVec3::new(next() * 16.0 - 8.0, next() * 20.0 - 5.0, next() * 8.0 - 4.0);
            let brute = (0..mesh.triangles.len())
                .map(|t| {
                    let [a, b, c] = mesh.triangle_positions(t);
                    anthesis_mesh::nearest::closest_point_on_triangle(p, a, b, c)
                        .0
                        .distance(p)
                })
                .fold(f64::INFINITY, f64::min);
            assert!((grid.distance(&mesh, p) - brute).abs() < 1e-12, "{p}");
        }
    }
}

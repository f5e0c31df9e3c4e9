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
//! The mesh winds counter-clockwise in UV (around `dS/du × dS/dv`).

use std::collections::HashSet;

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

/// The directed edges leaving each vertex, with their triangles: a compact
/// adjacency rebuilt before each pass.
struct Adjacency {
    /// Directed edges `a -> b` of triangle `t`, as `(b, t)`, grouped by `a`.
    items: Vec<(u32, u32)>,
    offsets: Vec<usize>,
}

impl Adjacency {
    fn new(vertex_count: usize, triangles: &[[u32; 3]]) -> Self {
        let mut offsets = vec![0; vertex_count + 1];
        for &a in triangles.iter().flatten() {
            offsets[a as usize + 1] += 1;
        }
        for i in 0..vertex_count {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets.clone();
        let mut items = vec![(0, 0); offsets[vertex_count]];
        for (t, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                let a = tri[k] as usize;
                items[fill[a]] = (tri[(k + 1) % 3], t as u32);
                fill[a] += 1;
            }
        }
        Adjacency { items, offsets }
    }

    /// `(b, t)` for the edges `a -> b` leaving `a`; their triangles `t` are
    /// exactly the triangles around `a`.
    fn leaving(&self, a: u32) -> &[(u32, u32)] {
        &self.items[self.offsets[a as usize]..self.offsets[a as usize + 1]]
    }

    /// The triangle that has the directed edge `a -> b`.
    fn triangle_of(&self, a: u32, b: u32) -> Option<usize> {
        self.leaving(a)
            .iter()
            .find(|&&(x, _)| x == b)
            .map(|&(_, t)| t as usize)
    }

    fn has_edge(&self, a: u32, b: u32) -> bool {
        self.triangle_of(a, b).is_some() || self.triangle_of(b, a).is_some()
    }
}

pub(crate) fn remesh(surface: &dyn Surface, options: &RemeshOptions) -> Result<Mesh, BudError> {
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
    let layout = work.lay_out(options)?;
    work.triangulate(&layout);
    for _ in 0..options.smoothing_iterations {
        for _ in 0..4 {
            if work.flip_pass() == 0 {
                break;
            }
        }
        work.smooth_pass();
    }
    for _ in 0..8 {
        if work.flip_pass() == 0 {
            break;
        }
    }
    Ok(Mesh {
        positions: work.positions,
        uvs: work.uvs,
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

    /// Step 1: places the vertices. Returns the rows (each in increasing
    /// `u`): the full base row first, then the interior points of each inner
    /// row (rows without any are left out), then the full top row or the
    /// single tip vertex; and the two margins (`u = 0` and `u = 1`, each from
    /// its base corner to its top corner or the tip).
    fn lay_out(&mut self, options: &RemeshOptions) -> Result<Layout, BudError> {
        let h = options.target_edge;
        let surface = self.surface;
        // Length along v: the mean of five lines of constant u.
        let lines = [0.0, 0.25, 0.5, 0.75, 1.0];
        let line_lengths = lines
            .iter()
            .map(|&u| cumulative_length(SAMPLES_ALONG_V, |v| point(surface, DVec2::new(u, v))))
            .collect::<Result<Vec<_>, _>>()?;
        let along_v: Vec<f64> = (0..=SAMPLES_ALONG_V)
            .map(|k| line_lengths.iter().map(|c| c[k]).sum::<f64>() / lines.len() as f64)
            .collect();
        let length = along_v[SAMPLES_ALONG_V];
        let row_width =
            |v: f64, n: usize| cumulative_length(n, |u| point(surface, DVec2::new(u, v)));
        // Widths and area on a coarse grid: zero-width check and size estimate.
        let widths: Vec<f64> = (0..=SAMPLES_ALONG_V)
            .map(|k| {
                let v = k as f64 / SAMPLES_ALONG_V as f64;
                row_width(v, SAMPLES_ACROSS).map(|c| c[SAMPLES_ACROSS])
            })
            .collect::<Result<_, _>>()?;
        let widest = widths.iter().copied().fold(0.0, f64::max);
        let area: f64 = (1..=SAMPLES_ALONG_V)
            .map(|k| 0.5 * (widths[k] + widths[k - 1]) * (along_v[k] - along_v[k - 1]))
            .sum();
        let size = length.max(widest);
        if length <= ZERO_WIDTH * size {
            return Err(BudError::ZeroLength);
        }
        // Everything but the last sample (the tip) must have a width.
        if let Some(k) = widths[..SAMPLES_ALONG_V]
            .iter()
            .position(|&w| w <= ZERO_WIDTH * size)
        {
            return Err(BudError::ZeroWidth {
                v: k as f64 / SAMPLES_ALONG_V as f64,
            });
        }
        let spacing = h * 3f64.sqrt() / 2.0;
        let gaps = (length / spacing).round() as usize;
        if gaps < 2 {
            return Err(BudError::TooFewRows {
                target_edge: h,
                length,
                rows: gaps + 1,
            });
        }
        // An equilateral lattice has one vertex per sqrt(3)/2 h^2 of area.
        let estimated = (area / (spacing * h)).round() as usize + 2 * gaps;
        if estimated > options.max_vertices {
            return Err(BudError::TooManyVertices {
                target_edge: h,
                area,
                estimated,
                limit: options.max_vertices,
            });
        }

        // Candidate points per row, as (uv, pin).
        let mut rows: Vec<Vec<(DVec2, Pin)>> = Vec::with_capacity(gaps + 1);
        for j in 0..=gaps {
            let (v, boundary) = match j {
                0 => (0.0, true),
                _ if j == gaps => (1.0, true),
                _ => (
                    invert_length(&along_v, j as f64 * length / gaps as f64),
                    false,
                ),
            };
            let coarse = row_width(v, SAMPLES_ACROSS)?;
            if j == gaps && coarse[SAMPLES_ACROSS] < 0.5 * h {
                // A pointed (or nearly pointed) tip: one vertex.
                rows.push(vec![(DVec2::new(0.5, 1.0), Pin::Fixed)]);
                continue;
            }
            let segments = ((coarse[SAMPLES_ACROSS] / h).round() as usize).max(1);
            let samples = SAMPLES_ACROSS.max(8 * segments + 16);
            let cumulative = if samples == SAMPLES_ACROSS {
                coarse
            } else {
                row_width(v, samples)?
            };
            let width = cumulative[samples];
            // Arc-length fractions: boundary rows from corner to corner,
            // inner rows without their ends (the margins have their own
            // vertices), odd inner rows staggered by half a segment.
            let fractions: Vec<f64> = if boundary {
                (0..=segments).map(|k| k as f64 / segments as f64).collect()
            } else if j % 2 == 1 {
                (0..segments)
                    .map(|k| (k as f64 + 0.5) / segments as f64)
                    .collect()
            } else {
                (1..segments).map(|k| k as f64 / segments as f64).collect()
            };
            let row = fractions
                .iter()
                .enumerate()
                .map(|(k, f)| {
                    let corner = boundary && (k == 0 || k == segments);
                    let u = match (corner, k) {
                        (true, 0) => 0.0,
                        (true, _) => 1.0,
                        _ => invert_length(&cumulative, f * width),
                    };
                    let pin = match (boundary, corner) {
                        (true, true) => Pin::Fixed,
                        (true, false) => Pin::SlideU,
                        _ => Pin::Free,
                    };
                    (DVec2::new(u, v), pin)
                })
                .collect();
            rows.push(row);
        }

        // Margins: points spaced evenly in 3D along u = 0 and u = 1, between
        // the corners (or the tip) of the boundary rows.
        let mut margin_points = [Vec::new(), Vec::new()];
        for (side, points) in margin_points.iter_mut().enumerate() {
            let cumulative = &line_lengths[if side == 0 { 0 } else { lines.len() - 1 }];
            let total = cumulative[SAMPLES_ALONG_V];
            let segments = ((total / h).round() as usize).max(2);
            for k in 1..segments {
                let v = invert_length(cumulative, k as f64 * total / segments as f64);
                let uv = DVec2::new(side as f64, v);
                points.push((uv, point(surface, uv)?));
            }
        }
        let tip = point(surface, DVec2::new(0.5, 1.0))?;

        // Inner-row points too close to a margin point or the tip are left
        // out (only the two outermost points of a row on each side can be).
        let too_close = |p: DVec3| {
            margin_points
                .iter()
                .flatten()
                .map(|(_, m)| m)
                .chain(std::iter::once(&tip))
                .any(|m| m.distance(p) < NEAR_BOUNDARY * h)
        };
        let last = rows.len() - 1;
        for row in &mut rows[1..last] {
            let n = row.len();
            let mut keep = Vec::with_capacity(n);
            for (k, &(uv, pin)) in row.iter().enumerate() {
                let outer = k < 2 || k + 2 >= n;
                if !(outer && too_close(point(surface, uv)?)) {
                    keep.push((uv, pin));
                }
            }
            *row = keep;
        }
        rows.retain(|r| !r.is_empty());

        // Create the vertices.
        let mut row_indices = Vec::with_capacity(rows.len());
        for row in &rows {
            let mut indices = Vec::with_capacity(row.len());
            for &(uv, pin) in row {
                indices.push(self.add_vertex(uv, pin)?);
            }
            row_indices.push(indices);
        }
        let rows = row_indices;
        let base = &rows[0];
        let top = &rows[rows.len() - 1];
        let mut margins = [Vec::new(), Vec::new()];
        for (side, margin) in margins.iter_mut().enumerate() {
            margin.push(if side == 0 {
                base[0]
            } else {
                base[base.len() - 1]
            });
            for &(uv, _) in &margin_points[side] {
                margin.push(self.add_vertex(uv, Pin::SlideV)?);
            }
            margin.push(if side == 0 {
                top[0]
            } else {
                top[top.len() - 1]
            });
        }
        Ok(Layout { rows, margins })
    }

    /// Step 2: triangulates the layout: strips between consecutive rows and
    /// between each margin and the row ends next to it.
    fn triangulate(&mut self, layout: &Layout) {
        for pair in layout.rows.windows(2) {
            // Rows run along +u, the next row is above (+v): on the left.
            self.zip(&pair[0], &pair[1], false);
        }
        let firsts: Vec<u32> = layout.rows.iter().map(|r| r[0]).collect();
        let lasts: Vec<u32> = layout.rows.iter().map(|r| r[r.len() - 1]).collect();
        // Margins run along +v; the row ends are on the right of u = 0 and on
        // the left of u = 1.
        self.zip(&layout.margins[0], &firsts, true);
        self.zip(&layout.margins[1], &lasts, false);
        // The boundary: base row, margins, top row.
        let mut neighbours = vec![Vec::new(); self.uvs.len()];
        let top = &layout.rows[layout.rows.len() - 1];
        for line in [&layout.rows[0], top, &layout.margins[0], &layout.margins[1]] {
            for pair in line.windows(2) {
                neighbours[pair[0] as usize].push(pair[1]);
                neighbours[pair[1] as usize].push(pair[0]);
            }
        }
        self.boundary_neighbours = neighbours;
    }

    /// Triangulates the strip between two polylines that run side by side in
    /// the same direction, always adding the triangle whose new diagonal is
    /// shorter. Triangles that would repeat a vertex (where the polylines
    /// share an end) are left out. The triangles are `(a, a, b)` and
    /// `(a, b, b)` in the polylines' direction, which is counter-clockwise in
    /// UV when `b` lies to the left of `a`; `b_on_right` reverses them.
    fn zip(&mut self, a: &[u32], b: &[u32], b_on_right: bool) {
        let (mut i, mut k) = (0, 0);
        while i + 1 < a.len() || k + 1 < b.len() {
            let p = |v: u32| self.positions[v as usize];
            let advance_a = if i + 1 == a.len() {
                false
            } else if k + 1 == b.len() {
                true
            } else {
                p(a[i + 1]).distance(p(b[k])) <= p(a[i]).distance(p(b[k + 1]))
            };
            let mut tri = if advance_a {
                i += 1;
                [a[i - 1], a[i], b[k]]
            } else {
                k += 1;
                [a[i], b[k], b[k - 1]]
            };
            if tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0] {
                continue;
            }
            if b_on_right {
                tri.swap(1, 2);
            }
            self.triangles.push(tri);
        }
    }

    /// Signed area of a triangle in UV (positive when counter-clockwise).
    fn uv_area(&self, t: [u32; 3]) -> f64 {
        let [a, b, c] = t.map(|i| self.uvs[i as usize]);
        0.5 * (b - a).perp_dot(c - a)
    }

    /// Whether a triangle is acceptable: counter-clockwise in UV and with a
    /// 3D area that is not negligible.
    fn is_valid(&self, t: [u32; 3]) -> bool {
        let [a, b, c] = t.map(|i| self.positions[i as usize]);
        let area = 0.5 * (b - a).cross(c - a).length();
        let longest = (b - a)
            .length_squared()
            .max((c - b).length_squared())
            .max((a - c).length_squared());
        self.uv_area(t) > 1e-12 && area > 1e-9 * longest
    }

    /// The cosine of the smallest interior angle of a triangle in 3D (the
    /// largest of the three cosines; no `acos` needed to compare angles).
    fn min_angle_cos(&self, t: [u32; 3]) -> f64 {
        let p = t.map(|i| self.positions[i as usize]);
        (0..3)
            .map(|k| {
                let (a, b, c) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
                let (e, f) = (b - a, c - a);
                e.dot(f) / (e.length_squared() * f.length_squared()).sqrt()
            })
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// One pass of edge flips over the interior edges: an edge is flipped
    /// when that raises the smallest angle of its two triangles (in the plane
    /// this is the Delaunay flip). Returns the number of flips.
    fn flip_pass(&mut self) -> usize {
        let adjacency = Adjacency::new(self.uvs.len(), &self.triangles);
        // A triangle changed in this pass is not looked at again until the
        // next pass (the adjacency is stale there); edges made in this pass
        // are remembered so that no edge is made twice.
        let mut touched = vec![false; self.triangles.len()];
        let mut made: HashSet<(u32, u32)> = HashSet::new();
        let mut flips = 0;
        for t1 in 0..self.triangles.len() {
            for k in 0..3 {
                if touched[t1] {
                    break;
                }
                // t1 = (a, b, c) and t2 = (b, a, d) become (a, d, c), (d, b, c).
                let tri = self.triangles[t1];
                let (a, b, c) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
                let Some(t2) = adjacency.triangle_of(b, a) else {
                    continue;
                };
                if touched[t2] || a > b {
                    continue;
                }
                let other = self.triangles[t2];
                let Some(d) = other.iter().copied().find(|&x| x != a && x != b) else {
                    continue;
                };
                if adjacency.has_edge(c, d) || made.contains(&(c.min(d), c.max(d))) {
                    continue;
                }
                let (n1, n2) = ([a, d, c], [d, b, c]);
                if !self.is_valid(n1) || !self.is_valid(n2) {
                    continue;
                }
                let before = self.min_angle_cos(tri).max(self.min_angle_cos(other));
                let after = self.min_angle_cos(n1).max(self.min_angle_cos(n2));
                if after < before - 1e-9 {
                    self.triangles[t1] = n1;
                    self.triangles[t2] = n2;
                    touched[t1] = true;
                    touched[t2] = true;
                    made.insert((c.min(d), c.max(d)));
                    flips += 1;
                }
            }
        }
        flips
    }

    /// The surface's partial derivatives at `uv` (central differences,
    /// one-sided at the domain's edges).
    fn jacobian(&self, uv: DVec2) -> (DVec3, DVec3) {
        const STEP: f64 = 1e-6;
        let derivative = |axis: DVec2, x: f64| {
            let lo = (x - STEP).max(0.0);
            let hi = (x + STEP).min(1.0);
            let at = |s: f64| self.surface.point(uv + axis * (s - x));
            (at(hi) - at(lo)) / (hi - lo)
        };
        (derivative(DVec2::X, uv.x), derivative(DVec2::Y, uv.y))
    }

    /// The area-weighted mean of the circumcentres of `triangles` (the
    /// optimal-Delaunay position of the vertex they surround).
    fn circumcentre_mean(&self, triangles: &[usize]) -> Option<DVec3> {
        let mut sum = DVec3::ZERO;
        let mut weight = 0.0;
        for &t in triangles {
            let [a, b, c] = self.triangles[t].map(|v| self.positions[v as usize]);
            let (ab, ac) = (b - a, c - a);
            let n = ab.cross(ac);
            let nn = n.length_squared();
            if nn == 0.0 {
                continue;
            }
            let centre = a
                + (ac.length_squared() * n.cross(ab) + ab.length_squared() * ac.cross(n))
                    / (2.0 * nn);
            let area = 0.5 * nn.sqrt();
            sum += area * centre;
            weight += area;
        }
        (weight > 0.0).then(|| sum / weight)
    }

    /// One Gauss–Seidel sweep of tangential smoothing.
    fn smooth_pass(&mut self) {
        let n = self.uvs.len();
        let adjacency = Adjacency::new(n, &self.triangles);
        let mut around = Vec::new();
        for i in 0..n {
            let pin = self.pins[i];
            if pin == Pin::Fixed {
                continue;
            }
            around.clear();
            around.extend(adjacency.leaving(i as u32).iter().map(|&(_, t)| t as usize));
            let Some(centre) = self.circumcentre_mean(&around) else {
                continue;
            };
            let target = match (pin, self.boundary_neighbours[i].as_slice()) {
                (Pin::Free, _) => centre,
                (_, &[a, b]) => {
                    let midpoint = 0.5 * (self.positions[a as usize] + self.positions[b as usize]);
                    0.5 * (centre + midpoint)
                }
                _ => continue,
            };
            let uv = self.uvs[i];
            let residual = target - self.positions[i];
            let (su, sv) = self.jacobian(uv);
            let step = match pin {
                Pin::SlideU if su.length_squared() > 0.0 => {
                    DVec2::new(su.dot(residual) / su.length_squared(), 0.0)
                }
                Pin::SlideV if sv.length_squared() > 0.0 => {
                    DVec2::new(0.0, sv.dot(residual) / sv.length_squared())
                }
                Pin::Free => {
                    // Normal equations of the Gauss–Newton step.
                    let (a, b, c) = (su.dot(su), su.dot(sv), sv.dot(sv));
                    let det = a * c - b * b;
                    if det <= 1e-12 * (a + c) * (a + c) {
                        continue;
                    }
                    let (ru, rv) = (su.dot(residual), sv.dot(residual));
                    DVec2::new((c * ru - b * rv) / det, (a * rv - b * ru) / det)
                }
                _ => continue,
            };
            if !step.is_finite() {
                continue;
            }
            // Take the step, or half of it, ... as long as no triangle folds.
            let (old_uv, old_position) = (uv, self.positions[i]);
            let mut scale = 1.0;
            for _ in 0..4 {
                let new_uv = (old_uv + step * scale).clamp(DVec2::ZERO, DVec2::ONE);
                let p = self.surface.point(new_uv);
                if p.is_finite() {
                    self.uvs[i] = new_uv;
                    self.positions[i] = p;
                    if around.iter().all(|&t| self.is_valid(self.triangles[t])) {
                        break;
                    }
                }
                self.uvs[i] = old_uv;
                self.positions[i] = old_position;
                scale *= 0.5;
            }
        }
    }
}

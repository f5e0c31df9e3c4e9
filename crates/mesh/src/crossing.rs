//! Where triangle meshes cross each other or themselves: every pair of
//! triangles (of different meshes, or of one mesh sharing no corner) where
//! an edge of one passes through the interior of the other.
//!
//! Triangles are hashed into a uniform grid over their bounding boxes
//! (Teschner et al., "Optimized Spatial Hashing for Collision Detection of
//! Deformable Objects", 2003): a table as long as the entries, filled by a
//! counting sort, so a search costs time linear in the triangles and
//! allocates nothing once its buffers have grown. A pair is tested only in
//! the one cell holding the low corner of the intersection of their boxes,
//! so it is tested once however many cells the two share, and only when the
//! boxes overlap; within a bucket the entries are swept along x (sorted by
//! their boxes' low x), so pairs apart along x are not visited. The test
//! itself: each triangle's corners against the
//! other's plane (all on one side: no crossing), then each edge of either
//! against the other's interior (Möller & Trumbore 1997), touching at the
//! very edges not counted.
//!
//! Written here rather than taken from a collision crate: the search must
//! skip the triangles of one mesh that share a corner (a sheet's
//! neighbours always touch), tell which meshes may cross at all, and give
//! where in both triangles each crossing is (for its UV); the grid over
//! glam's `DVec3` is a few dozen lines.

use glam::{DVec3, IVec3};
use rayon::prelude::*;

/// One triangle mesh taking part in a search: positions and triangles
/// (indices into the positions).
#[derive(Debug, Clone, Copy)]
pub struct Body<'a> {
    /// Vertex positions.
    pub positions: &'a [DVec3],
    /// Vertex indices of each triangle.
    pub triangles: &'a [[u32; 3]],
}

/// One triangle of one body: indices into the bodies searched and into
/// that body's triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct TriangleOf {
    /// The body.
    pub body: u32,
    /// The triangle in it.
    pub triangle: u32,
}

/// Two triangles that cross, and where: a point on the edge of one that
/// passes through the other, as barycentric weights of each triangle's
/// corners.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    /// The first triangle (the lower of the two).
    pub a: TriangleOf,
    /// The second.
    pub b: TriangleOf,
    /// The point in `a`'s corners.
    pub at_a: [f64; 3],
    /// The same point in `b`'s corners.
    pub at_b: [f64; 3],
}

/// At most this many grid entries per triangle (on average): a cell too
/// small for the triangles is doubled until they fit, which bounds a
/// search's memory and time whatever the meshes.
const MAX_CELLS_PER_TRIANGLE: usize = 8;

/// A crossing search's buffers, kept between searches (one per keyframe in
/// a run) so that a search allocates nothing once they have grown.
#[derive(Debug, Default, Clone)]
pub struct CrossingSearch {
    /// Per triangle (all bodies in order): its bounding box.
    boxes: Vec<(DVec3, DVec3)>,
    /// Per triangle: its body.
    owner: Vec<u32>,
    /// Where each body's triangles start in `boxes`.
    first: Vec<usize>,
    /// Per bucket of the hash table, where its entries start (one more
    /// than the buckets).
    starts: Vec<u32>,
    /// The entries, by bucket: a triangle and the cell it covers.
    entries: Vec<(u32, IVec3)>,
    /// Per bucket, where its next entry goes while filling.
    next: Vec<u32>,
    /// Per triangle: its corners, its vertices and its range of cells.
    corners: Vec<[DVec3; 3]>,
    vertices: Vec<[u32; 3]>,
    ranges: Vec<(IVec3, IVec3)>,
    /// Per pair of bodies, whether they may cross.
    tested: Vec<bool>,
}

impl CrossingSearch {
    /// A search with empty buffers.
    pub fn new() -> CrossingSearch {
        CrossingSearch::default()
    }

    /// Every crossing among `bodies`, sorted by `(a, b)`. `tested(i, j)`
    /// (with `i <= j`) says whether bodies `i` and `j` may cross at all
    /// (`i == j`: whether body `i` may cross itself, triangles sharing a
    /// corner never counting). `cell` is the grid's cell size, best about
    /// twice the mean edge of the triangles (it is grown where the boxes
    /// would cover too many cells). Triangles with a non-finite corner are
    /// left out.
    pub fn find(
        &mut self,
        bodies: &[Body<'_>],
        cell: f64,
        tested: &dyn Fn(usize, usize) -> bool,
    ) -> Vec<Crossing> {
        // Which bodies may cross, looked up per pair.
        let count = bodies.len();
        self.tested.clear();
        self.tested.extend(
            (0..count * count)
                .map(|k| tested((k / count).min(k % count), (k / count).max(k % count))),
        );
        self.gather(bodies);
        self.prune(count);
        let entries = self.cover(cell);
        let buckets = self.fill(entries);
        // The buckets in chunks on rayon's threads (sorted after, so the
        // answer does not depend on them), each with its own copy of a
        // bucket's entries to sweep.
        let this = &*self;
        let chunk = buckets.div_ceil(64).max(1024);
        let mut found: Vec<Crossing> = (0..buckets)
            .step_by(chunk)
            .collect::<Vec<_>>()
            .into_par_iter()
            .flat_map_iter(|first| {
                let mut out = Vec::new();
                let mut sweep = Vec::new();
                for k in first..(first + chunk).min(buckets) {
                    this.pairs_in(k, bodies.len(), &mut sweep, &mut out);
                }
                out
            })
            .collect();
        found.sort_unstable_by_key(|c| (c.a, c.b));
        found
    }

    /// Every triangle of `bodies` in order: its bounding box (NaN for a
    /// triangle with a non-finite corner), body, corners and vertices.
    fn gather(&mut self, bodies: &[Body<'_>]) {
        self.boxes.clear();
        self.owner.clear();
        self.first.clear();
        self.corners.clear();
        self.vertices.clear();
        for (b, body) in bodies.iter().enumerate() {
            self.first.push(self.boxes.len());
            for t in body.triangles {
                let corners = t.map(|v| body.positions[v as usize]);
                let [p, q, r] = corners;
                // `min` and `max` pass NaN over: a broken corner is
                // marked so that the triangle is left out.
                let broken = !(p.is_finite() && q.is_finite() && r.is_finite());
                let (lo, hi) = if broken {
                    (DVec3::NAN, DVec3::NAN)
                } else {
                    (p.min(q).min(r), p.max(q).max(r))
                };
                self.boxes.push((lo, hi));
                self.owner.push(b as u32);
                self.corners.push(corners);
                self.vertices.push(*t);
            }
        }
    }

    /// The broad phase by bodies: a triangle of a body not tested against
    /// itself (a part) can only cross a triangle of a body whose bounding
    /// box its own box overlaps, so one that overlaps none of the boxes of
    /// the bodies it is tested with is left out of the grid (as a broken
    /// triangle is). The parts' many small triangles (anthers, filaments,
    /// the stem) mostly lie away from the organs, and every one of them
    /// cost its grid cells and a test against each triangle sharing one.
    fn prune(&mut self, count: usize) {
        let mut extent = vec![(DVec3::INFINITY, DVec3::NEG_INFINITY); count];
        for (&(lo, hi), &b) in self.boxes.iter().zip(&self.owner) {
            if lo.is_finite() && hi.is_finite() {
                let e = &mut extent[b as usize];
                *e = (e.0.min(lo), e.1.max(hi));
            }
        }
        for (bx, &b) in self.boxes.iter_mut().zip(&self.owner) {
            let b = b as usize;
            if self.tested[b * count + b] {
                continue;
            }
            let (lo, hi) = *bx;
            let reaches = (0..count).any(|c| {
                c != b
                    && self.tested[b * count + c]
                    && !(lo.cmpgt(extent[c].1).any() || extent[c].0.cmpgt(hi).any())
            });
            if !reaches {
                *bx = (DVec3::NAN, DVec3::NAN);
            }
        }
    }

    /// Each triangle's range of cells of size `cell` or larger: the cell
    /// grows until the boxes cover few enough of them (a box too large for
    /// `i32` cells counts as too many). Returns how many cells they cover.
    fn cover(&mut self, cell: f64) -> usize {
        let n = self.boxes.len();
        let mut cell = if cell.is_finite() && cell > 0.0 {
            cell
        } else {
            1.0
        };
        let limit = f64::from(i32::MAX / 2);
        loop {
            self.ranges.clear();
            let mut total = 0usize;
            let mut fits = true;
            for &(lo, hi) in &self.boxes {
                if !(lo.is_finite() && hi.is_finite()) {
                    // Left out: an empty range.
                    self.ranges.push((IVec3::ONE, IVec3::ZERO));
                    continue;
                }
                let (a, b) = ((lo / cell).floor(), (hi / cell).floor());
                if a.abs().max_element() >= limit || b.abs().max_element() >= limit {
                    fits = false;
                    break;
                }
                let (a, b) = (a.as_ivec3(), b.as_ivec3());
                let d = (b - a + IVec3::ONE).as_i64vec3();
                total = total.saturating_add((d.x * d.y * d.z) as usize);
                if total > MAX_CELLS_PER_TRIANGLE * n.max(1) {
                    fits = false;
                    break;
                }
                self.ranges.push((a, b));
            }
            if fits {
                return total;
            }
            cell *= 2.0;
        }
    }

    /// The hash table of the `entries` cells the ranges cover: a power of
    /// two of buckets, at least the entries, filled by a counting sort.
    /// Returns the buckets.
    fn fill(&mut self, entries: usize) -> usize {
        let buckets = entries.max(1).next_power_of_two();
        let mask = buckets as u64 - 1;
        // Counting sort of the entries by bucket.
        self.starts.clear();
        self.starts.resize(buckets + 1, 0);
        for &range in &self.ranges {
            for c in cells(range) {
                self.starts[bucket(c, mask) + 1] += 1;
            }
        }
        for i in 0..buckets {
            self.starts[i + 1] += self.starts[i];
        }
        self.entries.clear();
        self.entries.resize(entries, (0, IVec3::ZERO));
        self.next.clear();
        self.next.extend_from_slice(&self.starts[..buckets]);
        for (t, &range) in self.ranges.iter().enumerate() {
            for c in cells(range) {
                let slot = &mut self.next[bucket(c, mask)];
                self.entries[*slot as usize] = (t as u32, c);
                *slot += 1;
            }
        }
        buckets
    }

    /// The crossings among the entries of bucket `k` (of a search over
    /// `count` bodies), each pair in the one cell where its boxes' overlap
    /// starts. The bucket's entries are copied into `sweep` with their
    /// boxes (one look-up per entry, not per pair) and sorted by the box's
    /// low x, so a triangle meets only the entries whose boxes start before
    /// its own ends along x (sweep and prune within the bucket, Baraff
    /// 1992).
    fn pairs_in(&self, k: usize, count: usize, sweep: &mut Vec<Swept>, out: &mut Vec<Crossing>) {
        let list = &self.entries[self.starts[k] as usize..self.starts[k + 1] as usize];
        if list.len() < 2 {
            return;
        }
        sweep.clear();
        sweep.extend(list.iter().map(|&(t, cell)| {
            let (lo, hi) = self.boxes[t as usize];
            let low = self.ranges[t as usize].0;
            Swept {
                lo,
                hi,
                cell,
                starts: u8::from(low.x == cell.x)
                    | u8::from(low.y == cell.y) << 1
                    | u8::from(low.z == cell.z) << 2,
                triangle: t,
            }
        }));
        sweep.sort_unstable_by(|a, b| a.lo.x.total_cmp(&b.lo.x));
        for (i, s) in sweep.iter().enumerate() {
            for t in &sweep[i + 1..] {
                // Past the box along x: no later entry overlaps it.
                if t.lo.x > s.hi.x {
                    break;
                }
                // Another cell in the same bucket, not the pair's one cell
                // (where the boxes' overlap starts, the larger of their
                // lowest cells: along each axis one of them starts here), or
                // boxes apart along y or z.
                if s.starts | t.starts != 0b111
                    || t.cell != s.cell
                    || s.lo.y > t.hi.y
                    || t.lo.y > s.hi.y
                    || s.lo.z > t.hi.z
                    || t.lo.z > s.hi.z
                {
                    continue;
                }
                let (s, t) = (
                    s.triangle.min(t.triangle) as usize,
                    s.triangle.max(t.triangle) as usize,
                );
                let (bs, bt) = (self.owner[s] as usize, self.owner[t] as usize);
                if !self.tested[bs * count + bt] {
                    continue;
                }
                let (vs, vt) = (self.vertices[s], self.vertices[t]);
                if bs == bt && vs.iter().any(|v| vt.contains(v)) {
                    continue;
                }
                if let Some((at_a, at_b)) = triangles_cross(&self.corners[s], &self.corners[t]) {
                    out.push(Crossing {
                        a: TriangleOf {
                            body: bs as u32,
                            triangle: (s - self.first[bs]) as u32,
                        },
                        b: TriangleOf {
                            body: bt as u32,
                            triangle: (t - self.first[bt]) as u32,
                        },
                        at_a,
                        at_b,
                    });
                }
            }
        }
    }
}

/// A bucket's entry as the sweep sees it: the triangle's box, the cell,
/// along which axes the box starts in that cell (bits x, y, z) and the
/// triangle.
#[derive(Debug, Clone, Copy)]
struct Swept {
    lo: DVec3,
    hi: DVec3,
    cell: IVec3,
    starts: u8,
    triangle: u32,
}

/// The bucket of cell `c` in a table of `mask + 1` buckets.
fn bucket(c: IVec3, mask: u64) -> usize {
    let h = (c.x as u32 as u64).wrapping_mul(73_856_093)
        ^ (c.y as u32 as u64).wrapping_mul(19_349_663)
        ^ (c.z as u32 as u64).wrapping_mul(83_492_791);
    // Mix the high bits down, so that the mask sees them.
    ((h ^ (h >> 17)).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 32 & mask) as usize
}

/// The cells of the range `(a, b)` (inclusive), x slowest.
fn cells((a, b): (IVec3, IVec3)) -> impl Iterator<Item = IVec3> {
    (a.x..=b.x).flat_map(move |x| {
        (a.y..=b.y).flat_map(move |y| (a.z..=b.z).map(move |z| IVec3::new(x, y, z)))
    })
}

/// Whether triangles `a` and `b` cross (an edge of either passes through
/// the other's interior), and if so where: the point, as barycentric
/// weights of `a`'s corners and of `b`'s.
pub fn triangles_cross(a: &[DVec3; 3], b: &[DVec3; 3]) -> Option<([f64; 3], [f64; 3])> {
    // Möller's interval test first (most pairs the grid hands over are
    // neighbours of one smooth sheet, which it rejects cheaply); the edges
    // are then tested for where they cross.
    let (na, nb) = (
        (a[1] - a[0]).cross(a[2] - a[0]),
        (b[1] - b[0]).cross(b[2] - b[0]),
    );
    let da = a.map(|p| (p - b[0]).dot(nb));
    let db = b.map(|p| (p - a[0]).dot(na));
    let one_side = |d: &[f64; 3]| d.iter().all(|&x| x > 0.0) || d.iter().all(|&x| x < 0.0);
    if one_side(&da) || one_side(&db) {
        return None;
    }
    let line = na.cross(nb);
    if let (Some(ia), Some(ib)) = (interval(a, &da, line), interval(b, &db, line))
        && (ia.1 < ib.0 || ib.1 < ia.0)
    {
        return None;
    }
    edges_cross(a, b)
}

/// Where an edge of `a` or `b` passes through the other's interior, the
/// first found (see [`triangles_cross`]).
fn edges_cross(a: &[DVec3; 3], b: &[DVec3; 3]) -> Option<([f64; 3], [f64; 3])> {
    for k in 0..3 {
        let (i, j) = (k, (k + 1) % 3);
        if let Some((t, inside)) = segment_through_triangle(a[i], a[j], b) {
            let mut on_edge = [0.0; 3];
            on_edge[i] = 1.0 - t;
            on_edge[j] = t;
            return Some((on_edge, inside));
        }
    }
    for k in 0..3 {
        let (i, j) = (k, (k + 1) % 3);
        if let Some((t, inside)) = segment_through_triangle(b[i], b[j], a) {
            let mut on_edge = [0.0; 3];
            on_edge[i] = 1.0 - t;
            on_edge[j] = t;
            return Some((inside, on_edge));
        }
    }
    None
}

/// Where a triangle with corners `t`, at signed distances `d` from the
/// other's plane (not all on one side), meets that plane, as an interval
/// along `line` (the planes' common direction): `None` where a corner lies
/// in the plane (the edge tests decide).
fn interval(t: &[DVec3; 3], d: &[f64; 3], line: DVec3) -> Option<(f64, f64)> {
    if d.contains(&0.0) {
        return None;
    }
    // The corner alone on its side.
    let alone = (0..3).find(|&i| {
        (d[i] > 0.0) != (d[(i + 1) % 3] > 0.0) && (d[i] > 0.0) != (d[(i + 2) % 3] > 0.0)
    })?;
    let p = t.map(|c| c.dot(line));
    let at = |j: usize| p[j] + (p[alone] - p[j]) * d[j] / (d[j] - d[alone]);
    let (x, y) = (at((alone + 1) % 3), at((alone + 2) % 3));
    Some((x.min(y), x.max(y)))
}

/// Where the segment `p -> q` passes through the interior of `tri`
/// (Möller–Trumbore; touching at the very edges, or lying in its plane, is
/// not a crossing): the fraction along the segment and the barycentric
/// weights of the triangle's corners.
pub fn segment_through_triangle(p: DVec3, q: DVec3, tri: &[DVec3; 3]) -> Option<(f64, [f64; 3])> {
    const EPS: f64 = 1e-9;
    let d = q - p;
    let e1 = tri[1] - tri[0];
    let e2 = tri[2] - tri[0];
    let h = d.cross(e2);
    let det = e1.dot(h);
    let scale = d.length() * e1.length() * e2.length();
    if det.abs() <= EPS * scale {
        return None;
    }
    let s = p - tri[0];
    let b1 = s.dot(h) / det;
    let qv = s.cross(e1);
    let b2 = d.dot(qv) / det;
    let t = e2.dot(qv) / det;
    (b1 > EPS && b2 > EPS && b1 + b2 < 1.0 - EPS && t > EPS && t < 1.0 - EPS)
        .then_some((t, [1.0 - b1 - b2, b1, b2]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::flat_sheet;

    fn body(mesh: &crate::Mesh) -> Body<'_> {
        Body {
            positions: &mesh.positions,
            triangles: &mesh.triangles,
        }
    }

    /// Every crossing by testing every pair of triangles.
    fn brute_force(bodies: &[Body<'_>], tested: &dyn Fn(usize, usize) -> bool) -> Vec<Crossing> {
        let mut found = Vec::new();
        let all: Vec<TriangleOf> = bodies
            .iter()
            .enumerate()
            .flat_map(|(b, body)| {
                (0..body.triangles.len()).map(move |t| TriangleOf {
                    body: b as u32,
                    triangle: t as u32,
                })
            })
            .collect();
        for (i, &a) in all.iter().enumerate() {
            for &b in &all[i + 1..] {
                if !tested(a.body as usize, b.body as usize) {
                    continue;
                }
                let (ta, tb) = (
                    bodies[a.body as usize].triangles[a.triangle as usize],
                    bodies[b.body as usize].triangles[b.triangle as usize],
                );
                if a.body == b.body && ta.iter().any(|v| tb.contains(v)) {
                    continue;
                }
                let pa = ta.map(|v| bodies[a.body as usize].positions[v as usize]);
                let pb = tb.map(|v| bodies[b.body as usize].positions[v as usize]);
                if let Some((at_a, at_b)) = triangles_cross(&pa, &pb) {
                    found.push(Crossing { a, b, at_a, at_b });
                }
            }
        }
        found
    }

    /// A sheet rolled about the x axis through `turns` turns, its radius
    /// growing by `pitch` per turn (a clean spiral) and wobbling by
    /// `wobble` at 1.25 waves per turn, which makes a turn pass through the
    /// one before it.
    fn rolled(turns: f64, pitch: f64, wobble: f64) -> crate::Mesh {
        let mut mesh = flat_sheet(4.0, 1.0, 9, 60);
        for p in &mut mesh.positions {
            let angle = p.y * turns * std::f64::consts::TAU;
            let radius = 1.0 + pitch * p.y * turns + wobble * (1.25 * angle).sin();
            *p = DVec3::new(p.x, radius * angle.cos(), radius * angle.sin());
        }
        mesh
    }

    #[test]
    fn the_grid_finds_what_testing_every_pair_finds() {
        let sheet = flat_sheet(2.0, 2.0, 8, 8);
        let mut tilted = sheet.clone();
        for p in &mut tilted.positions {
            *p = DVec3::new(p.x + 0.37, p.z + 0.41, p.y - 1.03);
        }
        let roll = rolled(1.6, 0.0, 0.1);
        // A body not tested against itself (as a part) partly beside the
        // others, which the broad phase leaves partly out.
        let mut beside = roll.clone();
        for p in &mut beside.positions {
            p.x += 1.7;
        }
        let bodies = [body(&sheet), body(&tilted), body(&roll), body(&beside)];
        for cell in [0.1, 0.5, 3.0] {
            let tested = |i: usize, j: usize| (i != 1 || j != 1) && (i != 3 || j != 3);
            let mut grid = CrossingSearch::find(&mut CrossingSearch::new(), &bodies, cell, &tested);
            let mut all = brute_force(&bodies, &tested);
            assert!(all.len() > 10, "{}", all.len());
            let key = |c: &Crossing| (c.a, c.b);
            grid.sort_by_key(key);
            all.sort_by_key(key);
            assert_eq!(grid, all, "cell {cell}");
        }
    }

    #[test]
    fn a_sheet_rolled_through_itself_crosses_and_one_rolled_outwards_does_not() {
        let mut search = CrossingSearch::new();
        let all = |_: usize, _: usize| true;
        let through = rolled(1.5, 0.0, 0.1);
        let found = search.find(&[body(&through)], 0.2, &all);
        assert!(!found.is_empty());
        // Each crossing is where it says, in both triangles.
        for c in &found {
            let at = |t: TriangleOf, w: [f64; 3]| {
                let tri = through.triangles[t.triangle as usize];
                (0..3)
                    .map(|k| through.positions[tri[k] as usize] * w[k])
                    .sum::<DVec3>()
            };
            assert!(at(c.a, c.at_a).distance(at(c.b, c.at_b)) < 1e-9);
            assert!(c.a < c.b && c.a.body == 0 && c.b.body == 0);
        }
        let apart = rolled(1.5, 0.3, 0.0);
        assert_eq!(search.find(&[body(&apart)], 0.2, &all), Vec::new());
        // Not looked at when the body may not cross itself.
        assert_eq!(
            search.find(&[body(&through)], 0.2, &|_, _| false),
            Vec::new()
        );
    }

    #[test]
    fn the_interval_test_rejects_no_pair_whose_edges_cross() {
        // Random triangles in a small box: the quick rejections must agree
        // with testing every edge, crossing or not.
        let mut state = 7u64;
        let mut random = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut point = || DVec3::new(random(), random(), random());
        let mut crossing = 0;
        for _ in 0..20_000 {
            let a = [point(), point(), point()];
            let b = [point(), point(), point()];
            let quick = triangles_cross(&a, &b);
            assert_eq!(quick, edges_cross(&a, &b), "{a:?} {b:?}");
            crossing += usize::from(quick.is_some());
        }
        assert!(crossing > 1000, "{crossing}");
    }

    #[test]
    fn touching_at_an_edge_or_lying_apart_is_not_a_crossing() {
        let a = [DVec3::ZERO, DVec3::X, DVec3::Y];
        // Standing on a's edge, and hanging just above a.
        let on_edge = [
            DVec3::new(0.2, 0.0, 0.0),
            DVec3::new(0.6, 0.0, 0.0),
            DVec3::new(0.4, 0.0, 1.0),
        ];
        assert_eq!(triangles_cross(&a, &on_edge), None);
        let above = a.map(|p| p + DVec3::new(0.1, 0.1, 1e-6));
        assert_eq!(triangles_cross(&a, &above), None);
        // Pushed through a's middle.
        let through = [
            DVec3::new(0.2, 0.2, -0.5),
            DVec3::new(0.3, 0.2, 0.5),
            DVec3::new(0.2, 0.6, 0.5),
        ];
        let (at_a, at_b) = triangles_cross(&a, &through).expect("crosses");
        let point = |tri: &[DVec3; 3], w: [f64; 3]| tri[0] * w[0] + tri[1] * w[1] + tri[2] * w[2];
        assert!(point(&a, at_a).distance(point(&through, at_b)) < 1e-12);
        assert!(point(&a, at_a).z.abs() < 1e-12);
    }

    #[test]
    fn a_huge_or_broken_triangle_does_not_blow_the_grid_up() {
        let sheet = flat_sheet(2.0, 2.0, 6, 6);
        let huge = [
            DVec3::new(-1e12, 0.5, -1e12),
            DVec3::new(1e12, 0.5, -1e12),
            DVec3::new(0.0, 0.5, 1e12),
        ];
        let broken = [DVec3::NAN, DVec3::ONE, DVec3::ZERO];
        let tri = [[0u32, 1, 2]];
        let bodies = [
            body(&sheet),
            Body {
                positions: &huge,
                triangles: &tri,
            },
            Body {
                positions: &broken,
                triangles: &tri,
            },
        ];
        let mut search = CrossingSearch::new();
        let found = search.find(&bodies, 1e-3, &|_, _| true);
        // The huge triangle cuts the sheet (the plane y = 0.5 across it);
        // the broken one is left out.
        assert!(
            found.iter().all(|c| c.a.body == 0 && c.b.body == 1),
            "{found:?}"
        );
        assert!(!found.is_empty());
        assert!(search.entries.len() <= MAX_CELLS_PER_TRIANGLE * 3 * sheet.triangles.len());
    }
}

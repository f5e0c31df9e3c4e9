//! Collisions between organs (paper §5.3): each particle tracks its nearest
//! particle on the organs it overlaps; the floral arrangement says on which
//! side of that organ it belongs. The side is taken at the nearest point of
//! the organ's smooth surface (on the triangles around the tracked
//! particle, curved by Phong tessellation), not on the tangent plane of the
//! tracked particle: that plane strays from a curved organ by about
//! κ·h²/2 at an edge h away, enough in a tightly wrapped bud to decide
//! which keyframe two petals meet in, so the flower's shape depended on its
//! mesh. What is shown, though, are the flat triangles, which lie a few per
//! cent of an edge off that surface where an organ curves: a contact holds
//! the particle off whichever lies farther out, and farther still where the
//! neighbour's surface bulges under the particle's own edges, so that the
//! flat triangles of touching organs do not cut each other either.
//!
//! During minimisation a violated side becomes a stiff one-sided penalty
//! (`anthesis_physics::Contact`), so Newton's method sees the contact and
//! converges; after convergence the paper's push-back moves every particle
//! still short of its side onto it, `offset` past the neighbour.

use anthesis_mesh::nearest::{TriangleRings, closest_point_on_triangle, on_rim, phong_point};
use anthesis_physics::Contact;
use glam::{DVec2, DVec3};

mod rim;
pub use rim::{
    RimSide, SelfNear, closest_between_segments, rim_contacts_of_pairs, rim_edges, rim_pairs,
};

/// One organ's current geometry as collisions see it.
pub struct Surface<'a> {
    /// The organ's particle positions, in the world frame.
    pub positions: &'a [DVec3],
    /// Unit normals pointing to the organ's inner side.
    pub normals: &'a [DVec3],
    /// The organ's triangles, as indices into `positions`.
    pub triangles: &'a [[u32; 3]],
    /// The triangles around each particle, and the ring beyond them.
    pub rings: &'a TriangleRings,
    /// Whether each particle is on the organ's rim (its boundary).
    pub rim: &'a [bool],
    /// Mean edge length, which sets the search radius.
    pub mean_edge: f64,
}

/// Nearest-particle lookup on one organ through a uniform grid over the
/// organ's bounding box (cells stored compactly, particles in index order
/// within a cell, so answers never depend on memory layout).
pub struct Tracker {
    /// Search radius: only particles this close count.
    radius: f64,
    cell: f64,
    origin: DVec3,
    /// The far corner of the particles' bounding box (`origin` is the
    /// near one).
    top: DVec3,
    dims: [i64; 3],
    /// `cell_start[c]..cell_start[c + 1]` indexes `items` for cell `c`.
    cell_start: Vec<u32>,
    items: Vec<u32>,
    /// Whether a cell or one of its 26 neighbours holds a particle: most
    /// particles of a neighbouring organ are nowhere near this one, and
    /// their queries end with one look-up.
    near: Vec<bool>,
}

/// Grids with more cells than this use coarser cells (same answers, more
/// candidates per query).
const MAX_CELLS: i64 = 1 << 20;

impl Tracker {
    /// A lookup over `positions` (one organ's particles) that answers
    /// queries within `radius` (world lengths).
    pub fn new(positions: &[DVec3], radius: f64) -> Tracker {
        let (lo, hi) = positions.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        let (lo, hi) = if positions.is_empty() {
            (DVec3::ZERO, DVec3::ZERO)
        } else {
            (lo, hi)
        };
        let mut cell = radius.max(1e-9);
        let dims = loop {
            let d = ((hi - lo) / cell).floor();
            let dims = [d.x as i64 + 1, d.y as i64 + 1, d.z as i64 + 1];
            if dims[0] * dims[1] * dims[2] <= MAX_CELLS {
                break dims;
            }
            cell *= 2.0;
        };
        let mut tracker = Tracker {
            radius,
            cell,
            origin: lo,
            top: hi,
            dims,
            cell_start: Vec::new(),
            items: Vec::new(),
            near: Vec::new(),
        };
        // Counting sort of particles by cell.
        let cells = (dims[0] * dims[1] * dims[2]) as usize;
        let mut counts = vec![0u32; cells + 1];
        let cell_ids: Vec<usize> = positions
            .iter()
            .map(|p| tracker.flat(tracker.cell_of(*p)).unwrap_or(0))
            .collect();
        for &c in &cell_ids {
            counts[c + 1] += 1;
        }
        for c in 0..cells {
            counts[c + 1] += counts[c];
        }
        let mut next = counts.clone();
        let mut items = vec![0u32; positions.len()];
        for (i, &c) in cell_ids.iter().enumerate() {
            items[next[c] as usize] = i as u32;
            next[c] += 1;
        }
        let mut near = vec![false; cells];
        for c in 0..cells {
            if counts[c + 1] == counts[c] {
                continue;
            }
            let c = c as i64;
            let (x, y, z) = (
                c % dims[0],
                (c / dims[0]) % dims[1],
                c / (dims[0] * dims[1]),
            );
            for dz in -1..=1 {
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        if let Some(n) = tracker.flat([x + dx, y + dy, z + dz]) {
                            near[n] = true;
                        }
                    }
                }
            }
        }
        tracker.cell_start = counts;
        tracker.items = items;
        tracker.near = near;
        tracker
    }

    /// Whether the box `lo..=hi` comes within `margin` of the particles'
    /// bounding box (allowing for rounding: never `false` where a particle
    /// is within `margin` of the box). Most of a neighbouring organ is
    /// nowhere near this one; this answers for it without a cell look-up.
    pub fn box_within(&self, lo: DVec3, hi: DVec3, margin: f64) -> bool {
        let margin = margin * (1.0 + 1e-9) + 1e-12;
        !(hi.cmplt(self.origin - margin).any() || lo.cmpgt(self.top + margin).any())
    }

    fn cell_of(&self, p: DVec3) -> [i64; 3] {
        let c = (p - self.origin) / self.cell;
        [floor_to_i64(c.x), floor_to_i64(c.y), floor_to_i64(c.z)]
    }

    fn flat(&self, c: [i64; 3]) -> Option<usize> {
        let inside = (0..3).all(|k| c[k] >= 0 && c[k] < self.dims[k]);
        inside.then(|| ((c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]) as usize)
    }

    /// Per cell of the grid, the bounds of `values` (one per particle
    /// the tracker was made over) of the particles in it (empty cells:
    /// inverted bounds).
    pub fn cell_bounds(&self, values: &[DVec2]) -> Vec<(DVec2, DVec2)> {
        let cells = self.cell_start.len().saturating_sub(1);
        (0..cells)
            .map(|c| {
                let range = self.cell_start[c] as usize..self.cell_start[c + 1] as usize;
                self.items[range].iter().fold(
                    (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
                    |(lo, hi), &i| (lo.min(values[i as usize]), hi.max(values[i as usize])),
                )
            })
            .collect()
    }

    /// For every particle the tracker was made over (at `positions`), the
    /// nearest particle within the search radius that is not in its
    /// neighbourhood (`locality`), ties to the lower index. Cell by cell:
    /// the particles of a cell share their 27 neighbouring cells, which are
    /// listed once for them, less those whose every particle is in the
    /// neighbourhood of every particle of the cell (the farthest corners of
    /// the two cells' bounds of the scaled UVs, `cells` from
    /// [`Tracker::cell_bounds`], within `locality.local`); each particle
    /// then skips the cells wholly in its own neighbourhood. The same
    /// answers as one query per particle walking its 27 cells, in a third
    /// of the time on the whole lily (most of a query went into the walk).
    pub fn nearest_beyond_each(
        &self,
        positions: &[DVec3],
        cells: &[(DVec2, DVec2)],
        locality: &Locality,
    ) -> Vec<Option<u32>> {
        let mut found = vec![None; positions.len()];
        let local2 = locality.local * locality.local;
        let radius2 = self.radius * self.radius;
        let mut around: Vec<usize> = Vec::with_capacity(27);
        let [nx, ny, _] = self.dims;
        for c in 0..self.cell_start.len().saturating_sub(1) {
            let own = self.cell_start[c] as usize..self.cell_start[c + 1] as usize;
            if own.is_empty() {
                continue;
            }
            let at = c as i64;
            let (cx, cy, cz) = (at % nx, (at / nx) % ny, at / (nx * ny));
            let (lo, hi) = cells[c];
            around.clear();
            for dz in -1..=1 {
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let Some(n) = self.flat([cx + dx, cy + dy, cz + dz]) else {
                            continue;
                        };
                        if self.cell_start[n] == self.cell_start[n + 1] {
                            continue;
                        }
                        let (nlo, nhi) = cells[n];
                        let far = (nhi - lo).abs().max((hi - nlo).abs());
                        if far.length_squared() >= local2 {
                            around.push(n);
                        }
                    }
                }
            }
            for &of in &self.items[own] {
                let (x, centre) = (positions[of as usize], locality.uv[of as usize]);
                let mut best: Option<(f64, u32)> = None;
                for &n in &around {
                    let (nlo, nhi) = cells[n];
                    let far = (centre - nlo).abs().max((nhi - centre).abs());
                    if far.length_squared() < local2 {
                        continue;
                    }
                    let range = self.cell_start[n] as usize..self.cell_start[n + 1] as usize;
                    for &i in &self.items[range] {
                        let d = (positions[i as usize] - x).length_squared();
                        if d > radius2 || locality.near(of as usize, i as usize) {
                            continue;
                        }
                        if best.is_none_or(|(bd, bi)| d < bd || (d == bd && i < bi)) {
                            best = Some((d, i));
                        }
                    }
                }
                found[of as usize] = best.map(|(_, i)| i);
            }
        }
        found
    }

    /// The nearest particle within the search radius of `x` (ties go to
    /// the lower index).
    pub fn nearest(&self, x: DVec3, positions: &[DVec3]) -> Option<u32> {
        if !self.box_within(x, x, self.radius) {
            return None;
        }
        let [cx, cy, cz] = self.cell_of(x);
        if let Some(c) = self.flat([cx, cy, cz])
            && !self.near[c]
        {
            return None;
        }
        let mut best: Option<(f64, u32)> = None;
        // The three cells of a row along x are stored one after the other.
        let (first, last) = ((cx - 1).max(0), (cx + 1).min(self.dims[0] - 1));
        if first > last {
            return None;
        }
        for dz in -1..=1 {
            for dy in -1..=1 {
                let (Some(a), Some(b)) = (
                    self.flat([first, cy + dy, cz + dz]),
                    self.flat([last, cy + dy, cz + dz]),
                ) else {
                    continue;
                };
                let range = self.cell_start[a] as usize..self.cell_start[b + 1] as usize;
                for &i in &self.items[range] {
                    let d = (positions[i as usize] - x).length_squared();
                    let better = match best {
                        None => true,
                        Some((bd, bi)) => d < bd || (d == bd && i < bi),
                    };
                    if better {
                        best = Some((d, i));
                    }
                }
            }
        }
        best.filter(|(d, _)| *d <= self.radius * self.radius)
            .map(|(_, i)| i)
    }
}

/// `v.floor() as i64`, without the call into the C library's `floor`
/// that `f64::floor` compiles to for the baseline x86-64 target (no
/// SSE4.1 rounding instruction): the cell look-ups of the contact searches
/// spent 2 % of a whole lily's run there. The same integer for every
/// `f64`, NaN (0) and infinities (saturated) included.
fn floor_to_i64(v: f64) -> i64 {
    let t = v as i64;
    if (t as f64) > v {
        t.saturating_sub(1)
    } else {
        t
    }
}

/// How a contact that is already violated is placed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Violated {
    /// The particle must move all the way to its side of the tracking
    /// point (the final push-back).
    MoveAll,
    /// The particle must move half the way: the other organ's particle
    /// tracks this one and moves the other half, so the two meet in the
    /// middle. Held each against the other's current place, both would move
    /// the full way and swap sides.
    MoveHalf,
}

/// Contacts for the particles of `moving` against `other`: `side` is +1 if
/// `moving` belongs on `other`'s inner side (it lies inside), -1 if on its
/// outer side. Only particles within reach of `other` (two of its mean edges
/// from its nearest particle) and over it get a contact: the point nearest
/// them on the triangles around that particle, lifted onto the Phong
/// surface, with the normal blended from the corners', moved out along it
/// to the flat triangle or by the surface's bulge under the particle's
/// edges where either lies farther out. A particle whose
/// nearest point is on `other`'s rim is over it only if it lies within the
/// collision `offset` of the rim sideways; farther it is beside the organ,
/// where nothing holds it (a fixed fraction of the mean edge instead made
/// how far past a margin a petal was held depend on the mesh).
pub fn contacts_against(
    moving: &Surface,
    other: &Surface,
    tracker: &Tracker,
    side: f64,
    offset: f64,
    violated: Violated,
    out: &mut Vec<Contact>,
) {
    contacts_of(
        moving.positions.iter().copied().enumerate(),
        moving,
        other,
        tracker,
        side,
        offset,
        violated,
        out,
    );
}

/// [`contacts_against`] for the particles `particles` (index, position) of
/// `moving` only: those farther than the tracker's reach from `other` get
/// no contact anyway, so leaving them out changes nothing. A particle's
/// contact depends on where it, the particles it shares an edge with
/// (`moving`'s triangles around it) and `other` are.
#[allow(clippy::too_many_arguments)]
pub fn contacts_of(
    particles: impl Iterator<Item = (usize, DVec3)>,
    moving: &Surface,
    other: &Surface,
    tracker: &Tracker,
    side: f64,
    offset: f64,
    violated: Violated,
    out: &mut Vec<Contact>,
) {
    for (i, x) in particles {
        let Some(q) = tracker.nearest(x, other.positions) else {
            continue;
        };
        let Some(nearest) = nearest_on_surface(x, other, q) else {
            continue;
        };
        if let Some(contact) = contact_at(moving, i, x, &nearest, side, offset, offset, violated) {
            out.push(contact);
        }
    }
}

/// The contact holding particle `i` of `moving`, at `x`, on side `side` of
/// the surface point `nearest` (see [`contacts_against`]), or `None` where
/// the point is on the rim and the particle more than `beside_rim` beside
/// it.
#[allow(clippy::too_many_arguments)]
fn contact_at(
    moving: &Surface,
    i: usize,
    x: DVec3,
    nearest: &Nearest,
    side: f64,
    offset: f64,
    beside_rim: f64,
    violated: Violated,
) -> Option<Contact> {
    let normal = nearest.normal * side;
    if nearest.on_rim {
        let d = x - nearest.point;
        let beside = (d - normal * d.dot(normal)).length();
        if beside > beside_rim {
            return None;
        }
    }
    // Held off the smooth surface, and off the flat triangle where it
    // lies farther out (on the concave side of a curved neighbour):
    // otherwise the particle could sit past the triangle drawn there.
    // On the convex side the smooth surface bulges out between the
    // points under the particle and its neighbours, so their straight
    // edge, held at its ends, dips towards it in the middle (and
    // through the flat triangles there, where they fold outwards):
    // held off farther by that bulge.
    let flat = (nearest.flat - nearest.point).dot(normal);
    let bulge = bulge_under_edges(moving, i, nearest, normal);
    let contact = Contact {
        particle: i as u32,
        point: nearest.point + normal * flat.max(bulge).max(0.0),
        normal,
        offset,
        weight: 1.0,
    };
    Some(match violated {
        Violated::MoveAll => contact,
        Violated::MoveHalf => move_half(contact, x),
    })
}

/// How far beside its own margin, in mean edges, a particle is still held
/// off a fold of its organ (against another organ: the collision offset).
const SELF_RIM_REACH: f64 = 0.5;

/// Where an organ is far from itself along its surface: its particles'
/// UVs scaled to lengths of its bud (see `OrganSim::locality`), and the
/// distance in those below which two particles are neighbours (their
/// nearness is the surface's own, not a fold of it onto itself).
pub struct Locality<'a> {
    /// Per particle, its UV scaled by the bud's lengths along `u` and `v`.
    pub uv: &'a [DVec2],
    /// Particles nearer than this in `uv` are each other's neighbourhood.
    pub local: f64,
}

impl Locality<'_> {
    fn near(&self, a: usize, b: usize) -> bool {
        self.uv[a].distance_squared(self.uv[b]) < self.local * self.local
    }
}

/// Self-contact (issue 35): contacts keeping each particle of `surface`
/// (not `skip`ped) off the organ's own surface beyond its neighbourhood
/// (`locality`), on the side it was on at the end of the last keyframe
/// (`previous`: the organ's surface then, with its normals, which the
/// crossing check found clean). `beyond` is each particle's nearest
/// particle beyond the neighbourhood ([`Tracker::nearest_beyond_each`]);
/// the contact is then as against another organ ([`contacts_against`]).
///
/// The side a particle was on is known where it lay over the surface
/// then (`side_then`). A particle that lay beside it (beside the fold's
/// margin, or where the fold has since slid along under it) takes the side
/// the fold's particle nearest it now was on against it then, turned
/// through their normals (two sheets over each other: the one is on the
/// other's side where the other is on its), and else the side most of its
/// neighbours near the fold with a known side have. Measured on the lily
/// petal rolled into a scroll (`petal-e-in-x2` in the stress example): the
/// blade's particles just beside the rolled tip's margin at keyframe 26
/// kept, against the tip, the sign of a distance of 0.03 to 0.3 mean edges
/// off its plane and 0.9 to 1.1 sideways of its rim, opposite to their
/// neighbours' under the tip, and were held through it once the tip slid
/// over them.
#[allow(clippy::too_many_arguments)]
pub fn self_contacts(
    surface: &Surface,
    beyond: &[Option<u32>],
    locality: &Locality,
    previous: &Surface,
    skip: &[bool],
    offset: f64,
    violated: Violated,
    out: &mut Vec<Contact>,
) {
    // Two turns of a roll lie rim on rim: a particle just beside the
    // other turn's margin is held too, or its edges to the held particles
    // beside it pass through that margin.
    let beside_rim = SELF_RIM_REACH * surface.mean_edge;
    // Each particle near a fold: its nearest point, its side, and whether
    // that side is known (else the side measured then, whatever it was).
    let mut near: Vec<(usize, Nearest, f64, bool)> = Vec::new();
    let mut index = vec![u32::MAX; surface.positions.len()];
    for (i, &x) in surface.positions.iter().enumerate() {
        if skip[i] {
            continue;
        }
        let Some(q) = beyond[i] else {
            continue;
        };
        let Some(nearest) = nearest_on_surface(x, surface, q) else {
            continue;
        };
        // The nearest point may lie on a triangle that reaches back into
        // the neighbourhood (past the rim of a fold): not a self-contact.
        if nearest
            .triangle
            .iter()
            .any(|&k| locality.near(i, k as usize))
        {
            continue;
        }
        // Where the particle was against the organ's surface near the same
        // particle when the last keyframe ended (the plane of the triangle
        // nearest now, taken then, can lie on the wrong side of a fold that
        // particle was beside); else where that particle was against this
        // one's surface.
        let (was, known) = side_then(previous.positions[i], previous, q, beside_rim)
            .filter(|&(_, known)| known)
            .or_else(|| {
                let (other, known) = side_then(
                    previous.positions[q as usize],
                    previous,
                    i as u32,
                    beside_rim,
                )?;
                let facing = previous.normals[i].dot(previous.normals[q as usize]);
                (known && other != 0.0 && facing != 0.0)
                    .then_some((-other.signum() * facing.signum(), true))
            })
            .or_else(|| side_then(previous.positions[i], previous, q, beside_rim))
            .unwrap_or((0.0, false));
        let side = if was != 0.0 {
            was.signum()
        } else {
            (x - nearest.point).dot(nearest.normal).signum()
        };
        index[i] = near.len() as u32;
        near.push((i, nearest, side, known));
    }
    for (i, nearest, side, known) in &near {
        let side = if *known {
            *side
        } else {
            let mut vote = 0.0;
            for &t in surface.rings.around(*i as u32) {
                for k in surface.triangles[t as usize] {
                    let n = index[k as usize];
                    if k as usize != *i && n != u32::MAX && near[n as usize].3 {
                        vote += near[n as usize].2;
                    }
                }
            }
            if vote != 0.0 { vote.signum() } else { *side }
        };
        let x = surface.positions[*i];
        if let Some(contact) =
            contact_at(surface, *i, x, nearest, side, offset, beside_rim, violated)
        {
            out.push(contact);
        }
    }
}

/// Where position `x` was against `surface` near particle `q`: its signed
/// distance along the surface's normal at the nearest point, and whether
/// that says on which side it was: it lay over the surface (no more
/// than `beside` sideways of that point, or less sideways than off it),
/// not beside its rim or the triangles looked at. `None` where `q` has no
/// surface.
fn side_then(x: DVec3, surface: &Surface, q: u32, beside: f64) -> Option<(f64, bool)> {
    let then = nearest_on_surface(x, surface, q)?;
    let d = x - then.point;
    let along = d.dot(then.normal);
    let sideways = (d - then.normal * along).length();
    Some((along, sideways <= beside.max(along.abs())))
}

/// Contacts of the particles of `moving` (not `skip`ped) against `other`,
/// an organ it has no overlap rule with (two organs of one whorl, issue
/// 35): each on the side of `other` it was on when the last keyframe ended
/// (`previous_moving`: its positions then; `previous_other`: the other's
/// surface then, near the same nearest particle), else as
/// [`contacts_against`].
#[allow(clippy::too_many_arguments)]
pub fn kept_side_contacts(
    moving: &Surface,
    other: &Surface,
    tracker: &Tracker,
    previous_moving: &[DVec3],
    previous_other: &Surface,
    skip: &[bool],
    offset: f64,
    violated: Violated,
    out: &mut Vec<Contact>,
) {
    for (i, &x) in moving.positions.iter().enumerate() {
        if skip[i] {
            continue;
        }
        let Some(q) = tracker.nearest(x, other.positions) else {
            continue;
        };
        let Some(nearest) = nearest_on_surface(x, other, q) else {
            continue;
        };
        let was = nearest_on_surface(previous_moving[i], previous_other, q).map_or(0.0, |then| {
            (previous_moving[i] - then.point).dot(then.normal)
        });
        let side = if was != 0.0 {
            was.signum()
        } else {
            (x - nearest.point).dot(nearest.normal).signum()
        };
        if let Some(contact) = contact_at(moving, i, x, &nearest, side, offset, offset, violated) {
            out.push(contact);
        }
    }
}

/// The plane of a triangle, for the barycentric weights of points
/// projected onto it (outside the triangle too).
struct PlaneFrame {
    origin: DVec3,
    u: DVec3,
    v: DVec3,
    uu: f64,
    uv: f64,
    vv: f64,
    denominator: f64,
}

impl PlaneFrame {
    /// `None` for a degenerate triangle.
    fn new(corners: [DVec3; 3]) -> Option<PlaneFrame> {
        let (u, v) = (corners[1] - corners[0], corners[2] - corners[0]);
        let (uu, uv, vv) = (u.dot(u), u.dot(v), v.dot(v));
        let denominator = uu * vv - uv * uv;
        (denominator > 1e-12 * uu * vv).then_some(PlaneFrame {
            origin: corners[0],
            u,
            v,
            uu,
            uv,
            vv,
            denominator,
        })
    }

    /// The barycentric weights of the projection of `p`.
    fn weights(&self, p: DVec3) -> [f64; 3] {
        let d = p - self.origin;
        let (du, dv) = (d.dot(self.u), d.dot(self.v));
        let b = (self.vv * du - self.uv * dv) / self.denominator;
        let c = (self.uu * dv - self.uv * du) / self.denominator;
        [1.0 - b - c, b, c]
    }
}

/// How far the other organ's smooth surface bulges along `direction`
/// under the middles of `moving`'s edges from particle `i`, beyond the
/// straight line between the points under their ends, at most (0 if it
/// sags everywhere). The surface there is the Phong patch of the triangle
/// nearest the particle continued past its edges (quadratic in the
/// barycentric weights): its offset from the flat plane is measured under
/// each end and the middle, so the flat part, linear, drops out.
fn bulge_under_edges(moving: &Surface, i: usize, nearest: &Nearest, direction: DVec3) -> f64 {
    let (corners, normals) = (nearest.corners, nearest.normals);
    let Some(plane) = PlaneFrame::new(corners) else {
        return 0.0;
    };
    let off_plane = |p: DVec3| {
        let weights = plane.weights(p);
        let flat: DVec3 = (0..3).map(|k| corners[k] * weights[k]).sum();
        (phong_point(corners, normals, weights) - flat).dot(direction)
    };
    let x = moving.positions[i];
    let at_x = off_plane(x);
    let mut most: f64 = 0.0;
    // Each neighbour is a corner of two of the ring's triangles (one at a
    // rim): its edge is measured once (a repeat could only give the same
    // value again).
    let mut seen = [u32::MAX; 16];
    let mut count = 0;
    for &t in moving.rings.around(i as u32) {
        for k in moving.triangles[t as usize] {
            if k as usize == i || seen[..count].contains(&k) {
                continue;
            }
            if count < seen.len() {
                seen[count] = k;
                count += 1;
            }
            let y = moving.positions[k as usize];
            most = most.max(off_plane(0.5 * (x + y)) - 0.5 * (at_x + off_plane(y)));
        }
    }
    most
}

/// `contact` for a particle at `x` that the other organ's particle meets
/// half way ([`Violated::MoveHalf`]): moved half way to the particle if it
/// is violated.
pub fn move_half(mut contact: Contact, x: DVec3) -> Contact {
    let violation = contact.violation(x);
    if violation > 0.0 {
        contact.point -= contact.normal * (0.5 * violation);
    }
    contact
}

/// Where on the other organ a violated contact presses (issue 35, two-sided
/// contact): the contact's index in its list, the corners of the
/// neighbour's triangle under the particle and the point's barycentric
/// weights there. The neighbour feels the reaction there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Held {
    /// The contact's index in the list it was found in.
    pub contact: u32,
    /// The other organ's particles at the triangle's corners.
    pub corners: [u32; 3],
    /// The contact point's barycentric weights on that triangle.
    pub weights: [f64; 3],
}

/// Where each contact of `contacts` (of particles at `positions`, against
/// `other`, whose nearest-particle lookup is `tracker`) that is violated
/// presses on `other`: the same triangle the contact search found (it
/// looks the same way).
pub fn held_where(
    contacts: &[Contact],
    positions: &[DVec3],
    other: &Surface,
    tracker: &Tracker,
) -> Vec<Held> {
    contacts
        .iter()
        .enumerate()
        .filter_map(|(n, c)| {
            let x = positions[c.particle as usize];
            if c.violation(x) <= 0.0 {
                return None;
            }
            let q = tracker.nearest(x, other.positions)?;
            let nearest = nearest_on_surface(x, other, q)?;
            Some(Held {
                contact: n as u32,
                corners: nearest.triangle,
                weights: nearest.weights,
            })
        })
        .collect()
}

/// The reaction of `contact` (found all the way, [`Violated::MoveAll`],
/// for a particle at `x`) on the other organ, where `held` says it presses:
/// one contact per corner of the triangle, of the contact's stiffness times
/// the corner's weight, holding the corner (at `corners_at`, the other
/// organ's positions) off the particle along the opposite normal. Each is
/// violated by half the contact's violation, as the contact moved half way
/// is ([`move_half`]): the two organs meet in the middle, and the forces
/// on the corners sum to the force on the particle, opposite.
pub fn reactions(
    contact: &Contact,
    held: &Held,
    x: DVec3,
    corners_at: &[DVec3],
    out: &mut Vec<Contact>,
) {
    let half = 0.5 * contact.violation(x);
    if half <= 0.0 {
        return;
    }
    for (&corner, &weight) in held.corners.iter().zip(&held.weights) {
        if weight <= 0.0 {
            continue;
        }
        out.push(Contact {
            particle: corner,
            point: corners_at[corner as usize] + contact.normal * (contact.offset - half),
            normal: -contact.normal,
            offset: contact.offset,
            weight: contact.weight * weight,
        });
    }
}

/// `list`, reactions on one organ (at `positions`), as one contact per
/// particle (ascending): where several contacts press a particle (a
/// corner shared by the triangles under several of the presser's
/// particles), one holds it with their summed stiffness along their
/// summed force, violated so that it pushes as hard as they did together
/// where the particle is. Held by several one-sided planes a little apart,
/// a corner left some and met others as it moved, and each change of
/// which held it cost Newton an iteration (with reactions from 0.01 mean
/// edges deep, the whole lily took 270 iterations with them apart and 167
/// merged, Maite Lady 448 and 426).
pub fn merge_reactions(mut list: Vec<Contact>, positions: &[DVec3]) -> Vec<Contact> {
    list.sort_by_key(|c| c.particle);
    let mut merged: Vec<Contact> = Vec::new();
    for group in list.chunk_by(|a, b| a.particle == b.particle) {
        let x = positions[group[0].particle as usize];
        let (force, weight) = group.iter().fold((DVec3::ZERO, 0.0), |(f, w), c| {
            (f + c.normal * (c.weight * c.violation(x)), w + c.weight)
        });
        let length = force.length();
        if length <= 0.0 || weight <= 0.0 {
            continue;
        }
        let normal = force / length;
        let offset = group[0].offset;
        merged.push(Contact {
            particle: group[0].particle,
            point: x - normal * (offset - length / weight),
            normal,
            offset,
            weight,
        });
    }
    merged
}

/// The point of an organ's surface nearest a particle.
struct Nearest {
    /// On the Phong surface.
    point: DVec3,
    /// On the flat triangle.
    flat: DVec3,
    /// The triangle's corners and their unit normals.
    corners: [DVec3; 3],
    normals: [DVec3; 3],
    /// Unit normal towards the organ's inner side.
    normal: DVec3,
    on_rim: bool,
    /// The triangle's particles.
    triangle: [u32; 3],
    /// The point's barycentric weights on the flat triangle.
    weights: [f64; 3],
}

/// The point of `surface` nearest `x` among the triangles near particle
/// `q` (the normal blended from the corners' normals with the point's
/// barycentric weights). `None` when `q` has no triangles or a zero normal.
fn nearest_on_surface(x: DVec3, surface: &Surface, q: u32) -> Option<Nearest> {
    // The nearest point on triangle `t`, kept if it is nearer than the best
    // so far (on a tie the lower triangle index wins, so the answer does not
    // depend on the order the triangles are looked at in).
    let consider = |best: &mut Option<(f64, u32, [f64; 3])>, t: u32| {
        let [a, b, c] = surface.triangles[t as usize].map(|k| surface.positions[k as usize]);
        let (flat, weights) = closest_point_on_triangle(x, a, b, c);
        let d2 = flat.distance_squared(x);
        if best.is_none_or(|(bd, bt, _)| d2 < bd || (d2 == bd && t < bt)) {
            *best = Some((d2, t, weights));
        }
    };
    let mut best = None;
    for &t in surface.rings.around(q) {
        consider(&mut best, t);
    }
    // Inside a triangle around `q` it is the nearest point near `q`. On
    // an edge or corner it may lie on the next ring (the nearest particle's
    // own triangles can miss the nearest point where the mesh is
    // stretched, and a particle by a margin then looked beside it): look
    // at the triangles around their corners too.
    if best.is_some_and(|(_, _, w)| w.iter().any(|&w| w <= 0.0)) {
        for &t in surface.rings.beyond(q) {
            consider(&mut best, t);
        }
    }
    let (_, t, weights) = best?;
    let tri = surface.triangles[t as usize];
    let corners = tri.map(|k| surface.positions[k as usize]);
    let normals = tri.map(|k| surface.normals[k as usize]);
    let normal = (0..3)
        .map(|k| normals[k] * weights[k])
        .sum::<DVec3>()
        .try_normalize()?;
    Some(Nearest {
        point: phong_point(corners, normals, weights),
        flat: (0..3).map(|k| corners[k] * weights[k]).sum(),
        corners,
        normals,
        normal,
        on_rim: on_rim(tri, weights, surface.rim),
        triangle: tri,
        weights,
    })
}

/// Places each particle of `contacts` that lies past its contact's plane
/// (on the wrong side), or less than `reach` short of it, `inside` past it,
/// to start a Newton minimisation from there. The contact penalty is
/// one-sided, so the Hessian holds a contact's stiffness only while it is
/// violated. A particle that rests on a neighbour ends a keyframe within a
/// hair of its contact, and the next keyframe's extrapolated start puts it
/// a hair off it as often as not: there the first Newton step, blind to
/// the contact, ran it into the neighbour, the line search cut the step to
/// almost nothing, and the next iteration took the step again with the
/// contact held, after a second factorisation (on the lily, one wasted
/// iteration per petal in nearly every keyframe where petals rest on the
/// sepals). Started just past it, the first step holds it; a particle
/// that was about to leave its contact does so in the next step. A
/// particle deep past its contact is put near its plane, as the paper's
/// push-back would, so the first steps do not see deep, stiff penalties.
/// Contacts of one particle are applied in order.
pub fn start_on_contacts(positions: &mut [DVec3], contacts: &[Contact], reach: f64, inside: f64) {
    for c in contacts {
        let x = &mut positions[c.particle as usize];
        let violation = c.violation(*x);
        if violation > -reach {
            *x += c.normal * (violation - inside);
        }
    }
}

/// The largest violation over `contacts` (0 when none is violated).
pub fn max_violation(positions: &[DVec3], contacts: &[Contact]) -> f64 {
    contacts
        .iter()
        .map(|c| c.violation(positions[c.particle as usize]))
        .fold(0.0, f64::max)
}

/// The paper's push-back: moves each particle that is short of its side
/// onto it, and marks it in `moved`. Returns how many particles this call
/// moved (a particle pushed by several contacts counts once). If a particle
/// has several contacts, they are applied in order.
pub fn push_back(positions: &mut [DVec3], contacts: &[Contact], moved: &mut [bool]) -> usize {
    let mut count = 0;
    let mut last_counted = None;
    for c in contacts {
        let x = &mut positions[c.particle as usize];
        let violation = c.violation(*x);
        if violation > 0.0 {
            *x += c.normal * violation;
            moved[c.particle as usize] = true;
            // Contacts of one particle are adjacent (built particle by
            // particle), so counting changes of particle counts each once.
            if last_counted != Some(c.particle) {
                count += 1;
                last_counted = Some(c.particle);
            }
        }
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cell_floor_is_the_floor_of_every_kind_of_number() {
        let mut values = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            -1.0 - 1e-16,
            1.0 - 1e-16,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            9.3e18,
            -9.3e18,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
        ];
        values.extend((-2000..2000).map(|k| f64::from(k) * 0.0137));
        for v in values {
            assert_eq!(floor_to_i64(v), v.floor() as i64, "{v}");
        }
    }

    #[test]
    fn nearest_matches_brute_force() {
        let points: Vec<DVec3> = (0..200)
            .map(|i| {
                let t = i as f64 * 0.37;
                DVec3::new(t.sin() * 3.0, (t * 1.3).cos() * 2.0, (t * 0.7).sin())
            })
            .collect();
        let tracker = Tracker::new(&points, 0.8);
        for k in 0..50 {
            let x = DVec3::new(
                (k as f64 * 0.21).cos() * 3.0,
                (k as f64 * 0.5).sin() * 2.0,
                0.1,
            );
            let brute = (0..points.len())
                .min_by(|&a, &b| {
                    (points[a] - x)
                        .length()
                        .total_cmp(&(points[b] - x).length())
                })
                .map(|i| i as u32);
            let found = tracker.nearest(x, &points);
            match found {
                Some(i) => assert_eq!(Some(i), brute),
                None => {
                    let d = (points[brute.expect("nonempty") as usize] - x).length();
                    assert!(d > 0.8, "missed a point at distance {d}");
                }
            }
        }
    }

    /// The nearest particle by brute force: the lowest index among the
    /// nearest, if within `radius`.
    fn brute_nearest(points: &[DVec3], x: DVec3, radius: f64) -> Option<u32> {
        let mut best: Option<(f64, u32)> = None;
        for (i, p) in points.iter().enumerate() {
            let d = (*p - x).length_squared();
            if best.is_none_or(|(bd, _)| d < bd) {
                best = Some((d, i as u32));
            }
        }
        best.filter(|(d, _)| *d <= radius * radius).map(|(_, i)| i)
    }

    #[test]
    fn the_nearest_beyond_each_neighbourhood_is_what_testing_every_particle_finds() {
        // A sheet rolled into two and a half turns (its turns a little
        // over a cell apart) and a flat one whose neighbourhood is smaller
        // than the radius (particles just beyond it in the next cells),
        // both on lattices with ties, at three radii and neighbourhoods.
        let (n, m) = (60, 8);
        let mut roll = (Vec::new(), Vec::new());
        let mut flat = (Vec::new(), Vec::new());
        for i in 0..n {
            for j in 0..m {
                let a = i as f64 * 0.27;
                let r = 1.0 + 0.04 * a;
                roll.0
                    .push(DVec3::new(r * a.cos(), r * a.sin(), j as f64 * 0.25));
                roll.1.push(DVec2::new(a * 2.0, j as f64 * 0.25));
                let p = DVec2::new(i as f64, j as f64) * 0.25;
                flat.0.push(p.extend(0.0));
                flat.1.push(p);
            }
        }
        for (points, uv) in [&roll, &flat] {
            for (radius, local) in [(0.35, 1.2), (0.8, 0.55), (0.5, 0.3)] {
                let tracker = Tracker::new(points, radius);
                let locality = Locality { uv, local };
                let cells = tracker.cell_bounds(uv);
                let found = tracker.nearest_beyond_each(points, &cells, &locality);
                let mut beyond = 0;
                for (i, &x) in points.iter().enumerate() {
                    let brute = (0..points.len())
                        .filter(|&j| !locality.near(i, j))
                        .map(|j| ((points[j] - x).length_squared(), j as u32))
                        .filter(|&(d, _)| d <= radius * radius)
                        .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
                        .map(|(_, j)| j);
                    assert_eq!(found[i], brute, "particle {i}, radius {radius}");
                    beyond += usize::from(brute.is_some());
                }
                if local < radius || std::ptr::eq(points, &roll.0) {
                    assert!(beyond > 0, "radius {radius}: nothing beyond");
                }
            }
        }
    }

    #[test]
    fn nearest_matches_brute_force_on_a_lattice_with_ties_and_outside_the_grid() {
        // Points on a lattice of the cell size (on cell borders, many at the
        // same distance from a query) and jittered copies; queries on the
        // lattice, between it and far outside it.
        let mut points = Vec::new();
        for i in 0..6 {
            for j in 0..5 {
                for k in 0..3 {
                    let p = DVec3::new(i as f64, j as f64, k as f64) * 0.5;
                    points.push(p);
                    let t = (i * 31 + j * 7 + k) as f64;
                    points.push(p + DVec3::new(t.sin(), t.cos(), (1.7 * t).sin()) * 0.2);
                }
            }
        }
        for radius in [0.5, 0.3, 1.1] {
            let tracker = Tracker::new(&points, radius);
            for q in 0..2000 {
                let t = q as f64;
                let x = match q % 3 {
                    0 => DVec3::new((q % 13) as f64, (q % 11) as f64, (q % 7) as f64) * 0.25,
                    1 => DVec3::new(
                        1.3 + 2.0 * t.sin(),
                        1.0 + 1.5 * (0.7 * t).cos(),
                        0.5 + (0.3 * t).sin(),
                    ),
                    _ => DVec3::new(4.0 * t.sin(), 4.0 * (1.3 * t).cos(), 3.0 * (0.9 * t).sin()),
                };
                assert_eq!(
                    tracker.nearest(x, &points),
                    brute_nearest(&points, x, radius),
                    "query {x} radius {radius}"
                );
            }
        }
    }

    /// A quarter cylinder of radius `radius` around the y axis (`cells`
    /// triangle columns over 90°, vertices every 90°/`cells`), its
    /// normals facing the axis (its inner side).
    struct Cylinder {
        mesh: anthesis_mesh::Mesh,
        normals: Vec<DVec3>,
        rings: TriangleRings,
        rim: Vec<bool>,
        mean_edge: f64,
    }

    impl Cylinder {
        fn new(radius: f64, cells: usize) -> Cylinder {
            let mesh = anthesis_mesh::generate::parametric_grid(cells + 1, cells + 1, |uv| {
                let angle = std::f64::consts::FRAC_PI_2 * uv.x;
                DVec3::new(radius * angle.cos(), 3.0 * uv.y, radius * angle.sin())
            });
            let mut normals = anthesis_mesh::vertex_normals(&mesh.positions, &mesh.triangles);
            if normals[0].dot(mesh.positions[0]) > 0.0 {
                normals.iter_mut().for_each(|n| *n = -*n);
            }
            Cylinder {
                rings: TriangleRings::new(&mesh.triangles, mesh.vertex_count()),
                rim: vec![false; mesh.vertex_count()],
                mean_edge: radius * std::f64::consts::FRAC_PI_2 / cells as f64,
                normals,
                mesh,
            }
        }

        fn surface(&self) -> Surface<'_> {
            Surface {
                positions: &self.mesh.positions,
                normals: &self.normals,
                triangles: &self.mesh.triangles,
                rings: &self.rings,
                rim: &self.rim,
                mean_edge: self.mean_edge,
            }
        }

        /// The contacts of the particles `positions` (the corners of
        /// `triangles`), inside the cylinder (`side` +1) or outside (-1).
        fn contacts(
            &self,
            positions: &[DVec3],
            triangles: &[[u32; 3]],
            side: f64,
            offset: f64,
        ) -> Vec<Contact> {
            let rings = TriangleRings::new(triangles, positions.len());
            let moving = Surface {
                positions,
                normals: &[],
                triangles,
                rings: &rings,
                rim: &[],
                mean_edge: self.mean_edge,
            };
            let other = self.surface();
            let tracker = Tracker::new(other.positions, 2.0 * self.mean_edge);
            let mut out = Vec::new();
            contacts_against(
                &moving,
                &other,
                &tracker,
                side,
                offset,
                Violated::MoveAll,
                &mut out,
            );
            assert_eq!(out.len(), positions.len(), "one contact per particle");
            out
        }
    }

    /// The point at `angle` (radians from the x axis) and height `y`, `r`
    /// from the cylinder's axis.
    fn at(r: f64, angle: f64, y: f64) -> DVec3 {
        DVec3::new(r * angle.cos(), y, r * angle.sin())
    }

    #[test]
    fn a_contact_measures_from_the_curved_surface_whatever_the_mesh() {
        let radius = 5.0;
        // A particle 0.1 outside the cylinder (on its convex side, where the
        // flat triangles lie inside the curved surface), over the middle of
        // a coarse cell (where they sag most) and off the fine grid.
        let angle = 0.37f64;
        let x = at(5.1, angle, 1.43);
        let coarse_cells = 6;
        let half_cell = std::f64::consts::FRAC_PI_2 / coarse_cells as f64 / 2.0;
        let sag = radius * (1.0 - half_cell.cos());
        for cells in [coarse_cells, 2 * coarse_cells, 5 * coarse_cells] {
            let contact = Cylinder::new(radius, cells).contacts(&[x], &[], -1.0, 0.0)[0];
            let distance = (x - contact.point).dot(contact.normal);
            assert!(
                (distance - 0.1).abs() < 0.05 * sag,
                "{cells} cells: {distance} (sag {sag})"
            );
        }
    }

    #[test]
    fn on_the_concave_side_a_particle_is_held_off_the_flat_triangles_too() {
        // Inside the cylinder the flat triangles lie nearer the axis than
        // the curved surface, by `sag` over the middle of a cell. A particle
        // between the two is on its side of the curved surface but past
        // the triangle drawn there: it is pushed onto the triangle.
        let (radius, cells) = (5.0, 6);
        let cylinder = Cylinder::new(radius, cells);
        let half_cell = std::f64::consts::FRAC_PI_2 / cells as f64 / 2.0;
        let sag = radius * (1.0 - half_cell.cos());
        // Over the middle of the second cell.
        let angle = 3.0 * half_cell;
        let mut positions = vec![at(radius - 0.5 * sag, angle, 1.43)];
        let contacts = cylinder.contacts(&positions, &[], 1.0, 0.0);
        let mut moved = vec![false];
        assert_eq!(push_back(&mut positions, &contacts, &mut moved), 1);
        let chord = radius * half_cell.cos();
        let from_axis = positions[0].x.hypot(positions[0].z);
        assert!(
            from_axis <= chord + 1e-12,
            "{from_axis} from the axis, the triangle {chord}"
        );
        assert!(
            from_axis > chord - 1e-3 * sag,
            "pushed just onto it: {from_axis}"
        );
    }

    #[test]
    fn on_the_convex_side_an_edge_between_two_held_particles_stays_off_both_surfaces() {
        // Outside the cylinder a straight edge of another organ across a
        // fold of the flat triangles (a vertex under its middle, on the
        // curved surface) dips towards the cylinder in the middle by about
        // r·(1 - cos(half its angle)), more than the offset: held off the
        // curved surface at its ends only, its middle would pass through
        // the triangles.
        let (radius, cells, offset) = (5.0, 6, 0.01);
        let cylinder = Cylinder::new(radius, cells);
        let vertex = 3.0 * std::f64::consts::FRAC_PI_2 / cells as f64;
        let half = 8f64.to_radians();
        let dip = radius * (1.0 - half.cos());
        assert!(dip > 2.0 * offset);
        // The edge's ends on the curved surface, its third corner along
        // the axis from the middle.
        let mut positions = vec![
            at(radius, vertex - half, 1.5),
            at(radius, vertex + half, 1.5),
            at(radius, vertex, 2.2),
        ];
        let triangles = [[0, 1, 2]];
        let contacts = cylinder.contacts(&positions, &triangles, -1.0, offset);
        let mut moved = vec![false; 3];
        push_back(&mut positions, &contacts, &mut moved);
        let middle = 0.5 * (positions[0] + positions[1]);
        let from_axis = middle.x.hypot(middle.z);
        // The flat triangles and the curved surface both pass through the
        // vertex under it, `radius` from the axis.
        assert!(
            from_axis >= radius + 0.5 * offset,
            "the edge's middle {from_axis} from the axis, the surfaces {radius}"
        );
        // Not much farther than the offset (by less than a tenth of the dip).
        assert!(from_axis < radius + offset + 0.1 * dip, "{from_axis}");
    }

    /// One organ of two flat sheets far apart along its surface (a blade
    /// on z = 0 and a tip, as a rolled petal's): a grid `columns` by 7,
    /// edge 1, through `place` (x, y of the grid, from -3); the tip's UVs
    /// 100 away.
    fn two_sheets(tip: impl Fn(f64, f64) -> DVec3) -> (anthesis_mesh::Mesh, Vec<DVec2>, usize) {
        let sheet = |columns: usize, place: &dyn Fn(f64, f64) -> DVec3| {
            anthesis_mesh::generate::parametric_grid(columns, 7, |uv| {
                place(-3.0 + uv.x * (columns - 1) as f64, -3.0 + 6.0 * uv.y)
            })
        };
        let blade = sheet(7, &|x, y| DVec3::new(x, y, 0.0));
        let tip = sheet(4, &tip);
        let n = blade.positions.len();
        let mut mesh = blade.clone();
        mesh.positions.extend(&tip.positions);
        mesh.triangles
            .extend(tip.triangles.iter().map(|t| t.map(|k| k + n as u32)));
        let uv = blade
            .positions
            .iter()
            .map(|p| DVec2::new(p.x, p.y))
            .chain(
                tip.uvs
                    .iter()
                    .map(|u| DVec2::new(100.0 + 3.0 * u.x, 6.0 * u.y)),
            )
            .collect();
        (mesh, uv, n)
    }

    #[test]
    fn a_particle_the_fold_slid_over_keeps_the_side_the_fold_was_on_against_it() {
        // At the last keyframe the tip came down on the blade tilted, its
        // margin at x = 0, 0.3 over the blade, rising to the left; the blade
        // particle at x = 1 lay beside that margin, a mean edge sideways of
        // it and above the plane of the tilted tip. Now the tip lies flat
        // 0.05 over the blade and has slid right over that particle: the
        // particle belongs under the tip, where the blade under the tip was.
        let (before, uv, blade) = two_sheets(|x, y| DVec3::new(x, y, 0.3 - 0.5 * x));
        let (now, _, _) = two_sheets(|x, y| DVec3::new(x + 1.5, y, 0.05));
        let triangles = &now.triangles;
        let count = now.positions.len();
        let orient = |positions: &[DVec3]| {
            let mut normals = anthesis_mesh::vertex_normals(positions, triangles);
            // Both sheets' inner sides up, as turns of a roll.
            if normals[0].z < 0.0 {
                normals.iter_mut().for_each(|n| *n = -*n);
            }
            normals
        };
        let (normals_before, normals_now) = (orient(&before.positions), orient(&now.positions));
        let rings = TriangleRings::new(triangles, count);
        let mut rim = vec![false; count];
        for e in rim_edges(triangles) {
            rim[e[0] as usize] = true;
            rim[e[1] as usize] = true;
        }
        let surface = |positions, normals| Surface {
            positions,
            normals,
            triangles,
            rings: &rings,
            rim: &rim,
            mean_edge: 1.0,
        };
        let (then, here) = (
            surface(&before.positions, &normals_before),
            surface(&now.positions, &normals_now),
        );
        let locality = Locality {
            uv: &uv,
            local: 6.0,
        };
        let tracker = Tracker::new(here.positions, 2.0);
        let cells = tracker.cell_bounds(&uv);
        let beyond = tracker.nearest_beyond_each(here.positions, &cells, &locality);
        let mut contacts = Vec::new();
        self_contacts(
            &here,
            &beyond,
            &locality,
            &then,
            &vec![false; count],
            0.01,
            Violated::MoveAll,
            &mut contacts,
        );
        // The blade particle at (1, 0, 0).
        let particle = (0..blade)
            .find(|&i| now.positions[i].distance(DVec3::new(1.0, 0.0, 0.0)) < 1e-9)
            .expect("a grid point");
        let contact = contacts
            .iter()
            .find(|c| c.particle as usize == particle)
            .expect("held off the tip over it");
        // Measured beside the tilted margin it was above that plane (the
        // side it used to keep, through the tip); it is held under the tip.
        assert!(contact.normal.z < -0.9, "held along {}", contact.normal);
        let mut positions = now.positions.clone();
        push_back(&mut positions, &[*contact], &mut vec![false; count]);
        assert!(
            positions[particle].z <= 0.05 - 0.01 + 1e-9,
            "pushed to {}",
            positions[particle]
        );
        // The tip's particles over the blade, which lay over it then too,
        // are held above it.
        for c in contacts.iter().filter(|c| c.particle as usize >= blade) {
            assert!(
                c.normal.z > 0.9,
                "tip particle {} held along {}",
                c.particle,
                c.normal
            );
        }
    }

    #[test]
    fn push_back_puts_particles_offset_past_the_surface() {
        let mut positions = vec![DVec3::new(0.0, 0.0, -0.3), DVec3::new(1.0, 0.0, 0.5)];
        let contacts = [
            Contact {
                particle: 0,
                point: DVec3::ZERO,
                normal: DVec3::Z,
                offset: 0.01,
                weight: 1.0,
            },
            Contact {
                particle: 1,
                point: DVec3::new(1.0, 0.0, 0.0),
                normal: DVec3::Z,
                offset: 0.01,
                weight: 1.0,
            },
        ];
        let mut moved = vec![false; positions.len()];
        assert_eq!(push_back(&mut positions, &contacts, &mut moved), 1);
        assert_eq!(moved.iter().filter(|&&m| m).count(), 1);
        assert!((positions[0].z - 0.01).abs() < 1e-15);
        assert_eq!(positions[1].z, 0.5);
    }

    #[test]
    fn a_keyframe_starts_particles_on_or_near_their_contact_just_past_it() {
        // The floor z = 0 (offset 0.01): particles deep below it, on it, a
        // hair above its offset, and well above.
        let floor = |particle| Contact {
            particle,
            point: DVec3::ZERO,
            normal: DVec3::Z,
            offset: 0.01,
            weight: 1.0,
        };
        let mut positions = vec![
            DVec3::new(0.0, 0.0, -0.3),
            DVec3::new(1.0, 0.0, 0.01),
            DVec3::new(2.0, 0.0, 0.01 + 5e-5),
            DVec3::new(3.0, 0.0, 0.01 + 2e-4),
        ];
        let contacts: Vec<Contact> = (0..4).map(floor).collect();
        let (reach, inside) = (1e-4, 1e-6);
        start_on_contacts(&mut positions, &contacts, reach, inside);
        for (i, c) in contacts.iter().enumerate().take(3) {
            let v = c.violation(positions[i]);
            assert!((v - inside).abs() < 1e-15, "particle {i}: violation {v}");
            assert!(v > 0.0, "particle {i} is held: a hair past its contact");
        }
        assert_eq!(positions[3].z, 0.01 + 2e-4, "beyond the reach: left alone");
        assert_eq!(positions[2].x, 2.0, "moved along the contact's normal only");
    }

    #[test]
    fn a_particle_pushed_by_two_neighbours_counts_once() {
        // Particle 0 lies under two outer organs at once.
        let mut positions = vec![DVec3::new(0.0, 0.0, -0.3)];
        let contacts = [
            Contact {
                particle: 0,
                point: DVec3::ZERO,
                normal: DVec3::Z,
                offset: 0.01,
                weight: 1.0,
            },
            Contact {
                particle: 0,
                point: DVec3::new(0.0, 0.0, 0.5),
                normal: DVec3::Z,
                offset: 0.01,
                weight: 1.0,
            },
        ];
        let mut moved = vec![false; positions.len()];
        assert_eq!(push_back(&mut positions, &contacts, &mut moved), 1);
        assert_eq!(moved.iter().filter(|&&m| m).count(), 1);
        assert!((positions[0].z - 0.51).abs() < 1e-15);
    }

    #[test]
    fn a_contact_and_its_reaction_are_equal_and_opposite_and_meet_half_way() {
        // A particle 0.2 below a tilted triangle's surface, held above it.
        let corners = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.3),
            DVec3::new(0.0, 2.0, -0.2),
        ];
        let normal = (corners[1] - corners[0])
            .cross(corners[2] - corners[0])
            .normalize();
        let weights = [0.2, 0.5, 0.3];
        let point: DVec3 = (0..3).map(|k| corners[k] * weights[k]).sum();
        let x = point - normal * 0.2;
        let contact = Contact {
            particle: 7,
            point,
            normal,
            offset: 0.01,
            weight: 1.0,
        };
        let held = Held {
            contact: 0,
            corners: [0, 1, 2],
            weights,
        };
        let mut out = Vec::new();
        reactions(&contact, &held, x, &corners, &mut out);
        assert_eq!(out.len(), 3);
        // The penalty force of each (stiffness k times its share times its
        // violation, along its normal) where the contact was found: the
        // particle's contact moved half way, against the corners'.
        let k = 1000.0;
        let half = move_half(contact, x);
        let on_particle = half.normal * (k * half.weight * half.violation(x));
        let on_corners: DVec3 = out
            .iter()
            .map(|r| r.normal * (k * r.weight * r.violation(corners[r.particle as usize])))
            .sum();
        assert!(on_particle.length() > 100.0);
        assert!(
            (on_particle + on_corners).length() < 1e-12 * on_particle.length(),
            "{on_particle} against {on_corners}"
        );
        // Each corner gives way half the depth, as the particle does.
        for r in &out {
            let v = r.violation(corners[r.particle as usize]);
            assert!((v - 0.5 * (0.2 + 0.01)).abs() < 1e-12, "{v}");
        }
        // Nothing where the contact holds.
        let mut none = Vec::new();
        reactions(&contact, &held, point + normal * 0.5, &corners, &mut none);
        assert!(none.is_empty());
    }

    #[test]
    fn merged_reactions_push_each_particle_as_hard_as_they_did_apart() {
        // Two presser particles over triangles sharing corners 1 and 2,
        // along slightly different normals and depths.
        let corners = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.1),
            DVec3::new(0.0, 2.0, -0.1),
            DVec3::new(2.0, 2.0, 0.0),
        ];
        let k = 1000.0;
        let pressing = [
            (
                DVec3::new(0.1, 0.0, 1.0).normalize(),
                0.2,
                [0, 1, 2],
                [0.2, 0.5, 0.3],
            ),
            (
                DVec3::new(0.0, -0.1, 1.0).normalize(),
                0.1,
                [1, 3, 2],
                [0.4, 0.4, 0.2],
            ),
        ];
        let mut apart = Vec::new();
        for (n, (normal, depth, triangle, weights)) in pressing.into_iter().enumerate() {
            let point: DVec3 = (0..3).map(|i| corners[triangle[i]] * weights[i]).sum();
            let contact = Contact {
                particle: n as u32,
                point,
                normal,
                offset: 0.01,
                weight: 1.0,
            };
            let held = Held {
                contact: 0,
                corners: triangle.map(|i| i as u32),
                weights,
            };
            reactions(
                &contact,
                &held,
                point - normal * depth,
                &corners,
                &mut apart,
            );
        }
        let force = |list: &[Contact], particle: u32| -> DVec3 {
            list.iter()
                .filter(|c| c.particle == particle)
                .map(|c| c.normal * (k * c.weight * c.violation(corners[particle as usize])))
                .sum()
        };
        let merged = merge_reactions(apart.clone(), &corners);
        // One per particle, in order.
        let particles: Vec<u32> = merged.iter().map(|c| c.particle).collect();
        assert_eq!(particles, vec![0, 1, 2, 3]);
        for p in 0..4 {
            let (a, m) = (force(&apart, p), force(&merged, p));
            assert!(a.length() > 1.0);
            assert!(
                (a - m).length() < 1e-12 * a.length(),
                "{p}: {a} against {m}"
            );
        }
        // The stiffness is the sum of the merged ones': corner 1 got
        // 0.5 of one contact's and 0.4 of the other's.
        assert!((merged[1].weight - 0.9).abs() < 1e-15);
    }
}

//! Rim contacts (issue 35): edge–edge proximity between an organ's edges
//! and the rim (boundary) edges of a neighbour or of itself, the way cloth
//! simulators keep edges apart (Bridson, Fedkiw and Anderson, "Robust
//! treatment of collisions, contact and friction for cloth animation",
//! 2002: point–triangle and edge–edge proximities).
//!
//! Particle contacts hold each particle off the neighbour's surface where
//! it lies over it; a particle beside the neighbour's rim has no point of
//! its surface under it, so nothing holds it, and an edge from it to a
//! held particle could pass through the neighbour's rim triangles (a margin
//! through a margin, rim on rim) while every particle stayed on its side.
//! Where two surfaces cross, the line they cross along either closes on
//! itself (then particles of one lie past the other, which the particle
//! contacts see) or ends on a rim, where an edge of one passes through a
//! rim edge of the other. So each pair of edges of which one is a rim edge
//! and which come within reach of each other gets a contact: the nearest
//! points of the two edges are kept `RIM_OFFSET` of the collision offset
//! apart, along the line between them, or, where one edge now passes
//! through a triangle at the other and the side of each other's line they
//! lie on (along their common normal) changed since the last keyframe
//! ended, back along the common normal to the side they were on (a pair
//! that passes through but kept its side is left to the others).
//!
//! The contact acts on the moving organ's edge at the point nearest the
//! other edge, `P(s) = (1 - s) a + s b`: it is given to the two ends as two
//! particle contacts on one plane moved along with the edge, of weights
//! `1 - s` and `s`, so their forces sum to the edge point's (the same
//! gradient; the Hessian leaves out the coupling of the two ends) and the
//! push-back, moving each end by the edge point's violation, moves the
//! edge onto its side.

use anthesis_mesh::crossing::segment_through_triangle;
use anthesis_physics::Contact;
use glam::DVec3;

use super::{Locality, Surface, Tracker};

/// The distance two edges are kept apart, as a fraction of the collision
/// offset: under the particle contacts' whole offset, so that where a
/// margin rests on a neighbour the particle contacts hold it and these
/// stay slack. At half the offset an organ whose joint is driven through
/// its neighbour's base (`collisions.rs`) was squeezed against the
/// neighbour's margin until an edge shrank to 0.81 of its bud length, and
/// Maite Lady took 578 iterations instead of 402; at a quarter margins
/// driven rim on rim 9, 9.8 or 10 apart (`rim_contact.rs`) still cross by
/// a triangle pair or three, which they did not at a half.
pub const RIM_OFFSET: f64 = 0.25;

/// Edge pairs nearer than this, in mean edges (the larger organ's), get a
/// contact (held fixed, like the particle contacts, while the organs
/// settle).
pub const RIM_REACH: f64 = 0.5;

/// One organ as the rim search sees it: where it is, where it was when
/// the last keyframe ended, its nearest-particle lookup where it is and its
/// rim edges (each `[low, high]`).
pub struct RimSide<'a> {
    /// The organ where it is.
    pub surface: Surface<'a>,
    /// Its positions at the end of the last keyframe.
    pub previous: &'a [DVec3],
    /// Its nearest-particle lookup where it is.
    pub tracker: &'a Tracker,
    /// Its boundary edges, each `[low, high]`.
    pub rim_edges: &'a [[u32; 2]],
    /// Its base particles, which attachment places, and those next to
    /// them: no edge from one gets a rim contact, nor is held off by one.
    pub base: &'a [bool],
}

/// Where an organ is near itself along its surface, for its rim contacts
/// against itself: its neighbourhood in the scaled UV layout
/// (`locality`), or less than `bud_near` apart in the bud (`bud`): a
/// petal narrowing to its base has its two margins a few edges apart there
/// but the whole width apart in UV.
pub struct SelfNear<'a> {
    /// The organ's neighbourhood in its scaled UV layout.
    pub locality: Locality<'a>,
    /// Its particles in the bud.
    pub bud: &'a [DVec3],
    /// Particles nearer than this in the bud are near.
    pub bud_near: f64,
    /// Per particle, its nearest particle beyond its neighbourhood within
    /// the organ's tracker's reach ([`Tracker::nearest_beyond_each`]).
    pub beyond: &'a [Option<u32>],
}

impl SelfNear<'_> {
    fn near(&self, a: usize, b: usize) -> bool {
        self.locality.near(a, b)
            || self.bud[a].distance_squared(self.bud[b]) < self.bud_near * self.bud_near
    }
}

/// The pairs of an edge of `moving` and an edge of `other` (each
/// `[low, high]`), one of them a rim edge, that come within reach of each
/// other (see the module), sorted. Those of `other` against `moving`
/// are these, each turned round: the same edges are measured the same way.
pub fn rim_pairs(
    moving: &RimSide,
    other: &RimSide,
    locality: Option<&SelfNear>,
) -> Vec<([u32; 2], [u32; 2])> {
    let reach = rim_reach(moving, other);
    let mut pairs: Vec<([u32; 2], [u32; 2])> = Vec::new();
    let mut near = Vec::new();
    // Against itself, only rim edges with an end that has a particle
    // beyond its neighbourhood within the tracker's reach (two mean
    // edges) can have a pair (a smooth sheet's rim has none).
    let mut rims_near: Vec<[u32; 2]> = Vec::new();
    let (other_rims, moving_rims) = if let Some(l) = locality {
        rims_near.extend(
            moving
                .rim_edges
                .iter()
                .copied()
                .filter(|e| e.iter().any(|&k| l.beyond[k as usize].is_some())),
        );
        (rims_near.as_slice(), rims_near.as_slice())
    } else {
        (other.rim_edges, moving.rim_edges)
    };
    for &q in other_rims {
        near.clear();
        edges_near(
            moving,
            other.surface.positions,
            q,
            reach,
            locality,
            &mut near,
        );
        pairs.extend(near.iter().map(|&p| (p, q)));
    }
    for &p in moving_rims {
        near.clear();
        edges_near(
            other,
            moving.surface.positions,
            p,
            reach,
            locality,
            &mut near,
        );
        pairs.extend(near.iter().map(|&q| (p, q)));
    }
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}

/// Edge pairs nearer than this get a contact: [`RIM_REACH`] mean edges of
/// the larger organ.
fn rim_reach(moving: &RimSide, other: &RimSide) -> f64 {
    RIM_REACH * moving.surface.mean_edge.max(other.surface.mean_edge)
}

/// The rim contacts of the edges of `moving` against `other` (see the
/// module) from their edge pairs `pairs` ([`rim_pairs`]). For an organ
/// against itself (`locality`: where it is near itself) pairs with an end
/// in each other's neighbourhood are left out, and so are edges with a
/// base particle at an end (the bases of organs meet on the receptacle by
/// design). `offset` is the collision offset.
pub fn rim_contacts_of_pairs(
    moving: &RimSide,
    other: &RimSide,
    pairs: &[([u32; 2], [u32; 2])],
    locality: Option<&SelfNear>,
    offset: f64,
    out: &mut Vec<Contact>,
) {
    let reach = rim_reach(moving, other);
    for &(p, q) in pairs {
        if p.iter().any(|&k| moving.base[k as usize]) || q.iter().any(|&k| other.base[k as usize]) {
            continue;
        }
        if let Some(locality) = locality
            && p.iter().any(|&a| {
                q.iter()
                    .any(|&c| a == c || locality.near(a as usize, c as usize))
            })
        {
            continue;
        }
        edge_contact(
            moving,
            other,
            [p, q],
            reach,
            RIM_OFFSET * offset,
            locality.is_some(),
            out,
        );
    }
}

/// The edges (each `[low, high]`, perhaps twice) of `side` within `reach`
/// of the segment `q` of the organ at `positions`; for an organ against
/// itself (`locality`), none with an end in the neighbourhood of `q`'s.
fn edges_near(
    side: &RimSide,
    positions: &[DVec3],
    q: [u32; 2],
    reach: f64,
    locality: Option<&SelfNear>,
    out: &mut Vec<[u32; 2]>,
) {
    let (c, d) = (positions[q[0] as usize], positions[q[1] as usize]);
    let tracker = side.tracker;
    let within = reach + side.surface.mean_edge;
    if !tracker.box_within(c.min(d), c.max(d), within) {
        return;
    }
    // Nothing of `side` within a cell or two of the segment: a look-up
    // per end and the middle.
    let far = |x: DVec3| {
        tracker
            .flat(tracker.cell_of(x))
            .is_none_or(|cell| !tracker.near[cell])
    };
    if far(c) && far(d) && far(0.5 * (c + d)) {
        return;
    }
    // An edge within reach has an end within `within` (reach and an
    // edge of it).
    let lo = tracker.cell_of(c.min(d) - DVec3::splat(within));
    let hi = tracker.cell_of(c.max(d) + DVec3::splat(within));
    if (0..3).any(|k| hi[k] < 0 || lo[k] >= tracker.dims[k]) {
        return;
    }
    let clamp = |v: i64, k: usize| v.clamp(0, tracker.dims[k] - 1);
    let own = side.surface.positions;
    let local = |i: u32| {
        locality
            .is_some_and(|l| l.near(i as usize, q[0] as usize) || l.near(i as usize, q[1] as usize))
    };
    // A particle outside the segment's box grown by `within` is farther.
    let (box_lo, box_hi) = (c.min(d) - within, c.max(d) + within);
    // Rounding allowance of the bound below (it never drops an edge the
    // exact test keeps).
    let slack = 1e-9 * (within + side.surface.mean_edge);
    let mut seen: Vec<u32> = Vec::with_capacity(16);
    // The squared distance of a particle at `x` to the segment, if within
    // `within`.
    let end_gap = |x: DVec3| {
        if x.cmplt(box_lo).any() || x.cmpgt(box_hi).any() {
            return None;
        }
        let (_, t) = closest_between_segments(x, x, c, d);
        let gap = x.distance_squared(c + (d - c) * t);
        (gap <= within * within).then_some(gap)
    };
    for z in clamp(lo[2], 2)..=clamp(hi[2], 2) {
        for y in clamp(lo[1], 1)..=clamp(hi[1], 1) {
            let (Some(first), Some(last)) = (
                tracker.flat([clamp(lo[0], 0), y, z]),
                tracker.flat([clamp(hi[0], 0), y, z]),
            ) else {
                continue;
            };
            let range = tracker.cell_start[first] as usize..tracker.cell_start[last + 1] as usize;
            for &i in &tracker.items[range] {
                let x = own[i as usize];
                let Some(gap_x) = end_gap(x) else {
                    continue;
                };
                if local(i) {
                    continue;
                }
                let gap_x = gap_x.sqrt();
                // Each edge of the ring once from this end (the triangles
                // around `i` share them in pairs).
                seen.clear();
                for &tri in side.surface.rings.around(i) {
                    for k in side.surface.triangles[tri as usize] {
                        if k == i || seen.contains(&k) {
                            continue;
                        }
                        seen.push(k);
                        if local(k) {
                            continue;
                        }
                        let y = own[k as usize];
                        let gap_y = end_gap(y);
                        // Both ends are looked at: the lower one tests it.
                        if k < i && gap_y.is_some() {
                            continue;
                        }
                        // The edge's point nearest the segment lies within
                        // half its length of an end, so the edge lies at
                        // least the nearer end's distance less that.
                        let gap_end = gap_y.map_or(gap_x, |g| gap_x.min(g.sqrt()));
                        if gap_end - 0.5 * x.distance(y) > reach + slack {
                            continue;
                        }
                        let (s, t) = closest_between_segments(x, y, c, d);
                        let gap = (x + (y - x) * s).distance_squared(c + (d - c) * t);
                        if gap <= reach * reach {
                            out.push([i.min(k), i.max(k)]);
                        }
                    }
                }
            }
        }
    }
}

/// The contact of edge `p` of `moving` against edge `q` of `other`
/// (`edges`: `[p, q]`), if they are within `reach` (see the module), kept
/// `apart` apart; `itself` where `other` is `moving`.
fn edge_contact(
    moving: &RimSide,
    other: &RimSide,
    edges: [[u32; 2]; 2],
    reach: f64,
    apart: f64,
    itself: bool,
    out: &mut Vec<Contact>,
) {
    let [p, q] = edges;
    let ends =
        |positions: &[DVec3], e: [u32; 2]| (positions[e[0] as usize], positions[e[1] as usize]);
    let (a, b) = ends(moving.surface.positions, p);
    let (c, d) = ends(other.surface.positions, q);
    let (s, t) = closest_between_segments(a, b, c, d);
    let (on_p, on_q) = (a + (b - a) * s, c + (d - c) * t);
    let between = on_p - on_q;
    let distance = between.length();
    if distance > reach {
        return;
    }
    let through = passes_through(moving, p, other, q) || passes_through(other, q, moving, p);
    let normal = if through {
        // Crossed: back to the side of each other's line they were on
        // when the last keyframe ended, if they were on the other side
        // then (else this pair is not where they crossed).
        let (a0, b0) = ends(moving.previous, p);
        let (c0, d0) = ends(other.previous, q);
        // See `RIM_SIDE_KNOWN`: within one organ, an edge and an edge
        // across the other turn of its fold (not two rim edges, which
        // meet side by side, rim on rim).
        let rim_on_rim =
            moving.rim_edges.binary_search(&p).is_ok() && other.rim_edges.binary_search(&q).is_ok();
        let known = if itself && !rim_on_rim {
            RIM_SIDE_KNOWN
        } else {
            0.0
        };
        match side_changed([a0, b0, c0, d0], [a, b, c, d], known) {
            Some(normal) => normal,
            None => return,
        }
    } else if distance > 1e-9 * reach {
        between / distance
    } else {
        return;
    };
    for (k, weight) in [(p[0], 1.0 - s), (p[1], s)] {
        if weight <= 0.0 {
            continue;
        }
        let x = moving.surface.positions[k as usize];
        out.push(Contact {
            particle: k,
            // The plane through the other edge's point, moved with the
            // edge: this end is as far past it as the edge's point.
            point: on_q + normal * (x - on_p).dot(normal),
            normal,
            offset: apart,
            weight,
        });
    }
}

/// Whether edge `p` of `first` passes through a triangle of `second`
/// with edge `q`.
fn passes_through(first: &RimSide, p: [u32; 2], second: &RimSide, q: [u32; 2]) -> bool {
    let (a, b) = (
        first.surface.positions[p[0] as usize],
        first.surface.positions[p[1] as usize],
    );
    let surface = &second.surface;
    surface.rings.around(q[0]).iter().any(|&t| {
        let tri = surface.triangles[t as usize];
        tri.contains(&q[1])
            && segment_through_triangle(a, b, &tri.map(|k| surface.positions[k as usize])).is_some()
    })
}

/// For an organ against itself, the share of an edge's distance to an
/// edge across the other turn of its fold at the last keyframe that must
/// lie along their common normal for the side they were on to count
/// (unless both are rim edges): an edge that lay beside the other then
/// was over some other part of that turn, which, rolled, curves away from
/// the line's plane. In the scroll (`petal-e-in-x2` in the stress
/// example) the rolled tip's rim edge came down on the blade from 0.75
/// mean edges sideways of a blade edge and 0.03 along their common
/// normal; that sign sent the tip's rim particles through the blade,
/// against their own particle contacts, and the push-back could not
/// settle both (with this, the scroll first crosses itself at keyframe 62
/// instead of 47). Between two organs it is not asked: two petals'
/// margins driven over each other (`rim_contact.rs`) then crossed at
/// keyframe 30.
const RIM_SIDE_KNOWN: f64 = 0.5;

/// Whether segment `a b` lies on the other side of segment `c d`'s line
/// (along their common normal) than `a0 b0` of `c0 d0`'s when the last
/// keyframe ended (`then`: `[a0, b0, c0, d0]`; `now`: `[a, b, c, d]`). If
/// so, the unit common normal now pointing to the side `a b` was on (the
/// normals turn little in a keyframe; turned by more than a right angle,
/// nothing is trusted; nor where less than `known` of their distance then
/// lay along the common normal, see [`RIM_SIDE_KNOWN`]).
fn side_changed(then: [DVec3; 4], now: [DVec3; 4], known: f64) -> Option<DVec3> {
    let [a0, b0, c0, d0] = then;
    let [a, b, c, d] = now;
    let normal = (b - a).cross(d - c).try_normalize()?;
    let then = (b0 - a0).cross(d0 - c0);
    let turned = then.dot(normal);
    let was = then.dot(a0 - c0) * turned.signum();
    let (s0, t0) = closest_between_segments(a0, b0, c0, d0);
    let apart = (a0 + (b0 - a0) * s0).distance(c0 + (d0 - c0) * t0);
    if was.abs() < known * apart * then.length() {
        return None;
    }
    let is = normal.dot(a - c);
    (turned != 0.0 && was != 0.0 && was.signum() != is.signum()).then_some(normal * was.signum())
}

/// The parameters `(s, t)` in `[0, 1]` of the nearest points of segments
/// `a b` and `c d` (`a + s (b - a)`, `c + t (d - c)`); a segment of no
/// length is its point.
pub fn closest_between_segments(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> (f64, f64) {
    let (u, v, w) = (b - a, d - c, a - c);
    let (uu, vv) = (u.dot(u), v.dot(v));
    let (uv, uw, vw) = (u.dot(v), u.dot(w), v.dot(w));
    let tiny = 1e-300;
    if uu <= tiny && vv <= tiny {
        return (0.0, 0.0);
    }
    if uu <= tiny {
        return (0.0, (vw / vv).clamp(0.0, 1.0));
    }
    if vv <= tiny {
        return ((-uw / uu).clamp(0.0, 1.0), 0.0);
    }
    let denominator = uu * vv - uv * uv;
    let mut s = if denominator > 1e-14 * uu * vv {
        ((uv * vw - vv * uw) / denominator).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut t = (uv * s + vw) / vv;
    if t < 0.0 {
        t = 0.0;
        s = (-uw / uu).clamp(0.0, 1.0);
    } else if t > 1.0 {
        t = 1.0;
        s = ((uv - uw) / uu).clamp(0.0, 1.0);
    }
    (s, t)
}

/// The rim edges of a mesh of `triangles`: those of one triangle only,
/// each `[low, high]`, sorted.
pub fn rim_edges(triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let mut all: Vec<[u32; 2]> = triangles
        .iter()
        .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
        .map(|[i, j]| [i.min(j), i.max(j)])
        .collect();
    all.sort_unstable();
    let mut rim = Vec::new();
    let mut k = 0;
    while k < all.len() {
        let mut n = k + 1;
        while n < all.len() && all[n] == all[k] {
            n += 1;
        }
        if n - k == 1 {
            rim.push(all[k]);
        }
        k = n;
    }
    rim
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_nearest_points_of_two_segments_are_those_a_fine_search_finds() {
        let segments = [
            [
                DVec3::ZERO,
                DVec3::X,
                DVec3::new(0.5, -1.0, 0.3),
                DVec3::new(0.5, 1.0, 0.3),
            ],
            [
                DVec3::ZERO,
                DVec3::X,
                DVec3::new(2.0, 0.5, 0.0),
                DVec3::new(3.0, 0.5, 1.0),
            ],
            [
                DVec3::ZERO,
                DVec3::X,
                DVec3::new(0.2, 0.1, 0.0),
                DVec3::new(0.9, 0.1, 0.0),
            ],
            [
                DVec3::ZERO,
                DVec3::X,
                DVec3::new(-1.0, 0.0, 1.0),
                DVec3::new(-0.5, 2.0, 0.0),
            ],
            [
                DVec3::ZERO,
                DVec3::ZERO,
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(1.0, -1.0, 0.0),
            ],
        ];
        for [a, b, c, d] in segments {
            let (s, t) = closest_between_segments(a, b, c, d);
            let found = (a + (b - a) * s).distance(c + (d - c) * t);
            let n = 400;
            let mut best = f64::INFINITY;
            for i in 0..=n {
                for j in 0..=n {
                    let (s, t) = (f64::from(i) / f64::from(n), f64::from(j) / f64::from(n));
                    best = best.min((a + (b - a) * s).distance(c + (d - c) * t));
                }
            }
            assert!(found <= best + 1e-12, "{found} against {best}");
            assert!(found > best - 1e-2, "{found} against {best}");
        }
    }

    /// A sheet of `columns` by `rows` quads, `surface` of its UV square.
    fn sheet(surface: impl Fn(glam::DVec2) -> DVec3) -> anthesis_mesh::Mesh {
        anthesis_mesh::generate::parametric_grid(14, 9, surface)
    }

    #[test]
    fn the_rim_pairs_are_every_edge_pair_within_reach_and_the_same_either_way() {
        use anthesis_mesh::nearest::TriangleRings;
        // Two wavy sheets, the second turned and lifted so that its rim
        // lies on the first here and there, passes through it and stands
        // off it elsewhere.
        let a = sheet(|p| DVec3::new(p.x * 4.0, p.y * 3.0, 0.15 * (5.0 * p.x).sin()));
        let b = sheet(|p| {
            let (x, y) = (p.x * 4.0 - 1.0, p.y * 3.0 + 1.2);
            DVec3::new(
                0.9 * x + 0.3 * y,
                y - 0.2 * x,
                0.1 + 0.3 * (3.0 * p.y).cos() * p.x,
            )
        });
        let mean_edge = 4.0 / 14.0;
        let parts: Vec<_> = [&a, &b]
            .iter()
            .map(|m| {
                (
                    TriangleRings::new(&m.triangles, m.vertex_count()),
                    Tracker::new(&m.positions, 2.0 * mean_edge),
                    rim_edges(&m.triangles),
                    vec![false; m.vertex_count()],
                )
            })
            .collect();
        fn side<'a>(
            m: &'a anthesis_mesh::Mesh,
            part: &'a (TriangleRings, Tracker, Vec<[u32; 2]>, Vec<bool>),
            mean_edge: f64,
        ) -> RimSide<'a> {
            RimSide {
                surface: Surface {
                    positions: &m.positions,
                    normals: &[],
                    triangles: &m.triangles,
                    rings: &part.0,
                    rim: &[],
                    mean_edge,
                },
                previous: &m.positions,
                tracker: &part.1,
                rim_edges: &part.2,
                base: &part.3,
            }
        }
        let (first, second) = (
            side(&a, &parts[0], mean_edge),
            side(&b, &parts[1], mean_edge),
        );
        let found = rim_pairs(&first, &second, None);
        let mut turned: Vec<_> = rim_pairs(&second, &first, None)
            .into_iter()
            .map(|(p, q)| (q, p))
            .collect();
        turned.sort_unstable();
        assert_eq!(found, turned);
        // Every pair of an edge and a rim edge (either way) within reach.
        let edges = |m: &anthesis_mesh::Mesh| {
            let mut all: Vec<[u32; 2]> = m
                .triangles
                .iter()
                .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
                .map(|[i, j]| [i.min(j), i.max(j)])
                .collect();
            all.sort_unstable();
            all.dedup();
            all
        };
        let reach = RIM_REACH * mean_edge;
        let rim_a = &parts[0].2;
        let rim_b = &parts[1].2;
        let mut brute = Vec::new();
        for p in edges(&a) {
            for q in edges(&b) {
                if !(rim_a.contains(&p) || rim_b.contains(&q)) {
                    continue;
                }
                let ends = |m: &anthesis_mesh::Mesh, e: [u32; 2]| {
                    (m.positions[e[0] as usize], m.positions[e[1] as usize])
                };
                let ((x, y), (c, d)) = (ends(&a, p), ends(&b, q));
                let (s, t) = closest_between_segments(x, y, c, d);
                if (x + (y - x) * s).distance(c + (d - c) * t) <= reach {
                    brute.push((p, q));
                }
            }
        }
        brute.sort_unstable();
        assert!(brute.len() > 10, "{} pairs", brute.len());
        assert_eq!(found, brute);
    }

    #[test]
    fn a_square_of_two_triangles_has_four_rim_edges() {
        assert_eq!(
            rim_edges(&[[0, 1, 2], [0, 2, 3]]),
            vec![[0, 1], [0, 3], [1, 2], [2, 3]]
        );
    }

    #[test]
    fn an_edge_turned_past_a_rim_edge_changed_its_side_and_is_sent_back() {
        // The rim edge along x; an edge across it above (z = 0.1) at the
        // last keyframe, now below (z = -0.1): sent back up.
        let (c, d) = (DVec3::ZERO, DVec3::X);
        let (a0, b0) = (DVec3::new(0.5, -0.5, 0.1), DVec3::new(0.5, 0.5, 0.1));
        let (a, b) = (a0 - 0.2 * DVec3::Z, b0 - 0.2 * DVec3::Z);
        let normal = side_changed([a0, b0, c, d], [a, b, c, d], RIM_SIDE_KNOWN).expect("changed");
        assert!((normal - DVec3::Z).length() < 1e-12, "{normal}");
        // Still above: not changed.
        assert_eq!(
            side_changed(
                [a0, b0, c, d],
                [a0, b0 + 0.05 * DVec3::Z, c, d],
                RIM_SIDE_KNOWN
            ),
            None
        );
    }

    #[test]
    fn an_edge_beside_a_rim_edge_at_the_last_keyframe_was_on_no_side_of_it() {
        // The rim edge along x; an edge across its line at the last
        // keyframe but beside its end (x = 1.6), a hair above its plane
        // (z = 0.02): 0.6 apart, almost all of it sideways. Now it lies
        // across the rim edge a hair below: no side to send it back to
        // (over another part of the rim edge's sheet then, which may curve
        // away from the line's plane), unless both are rim edges.
        let (c, d) = (DVec3::ZERO, DVec3::X);
        let (a0, b0) = (DVec3::new(1.6, -0.5, 0.02), DVec3::new(1.6, 0.5, 0.02));
        let (a, b) = (DVec3::new(0.5, -0.5, -0.02), DVec3::new(0.5, 0.5, -0.02));
        assert_eq!(
            side_changed([a0, b0, c, d], [a, b, c, d], RIM_SIDE_KNOWN),
            None
        );
        // Two rim edges side by side (margins rim on rim): it was above.
        let normal = side_changed([a0, b0, c, d], [a, b, c, d], 0.0).expect("changed");
        assert!((normal - DVec3::Z).length() < 1e-12, "{normal}");
        // Over the rim edge then, as far from it: sent back up.
        let (a0, b0) = (DVec3::new(0.5, -0.5, 0.6), DVec3::new(0.5, 0.5, 0.6));
        let normal = side_changed([a0, b0, c, d], [a, b, c, d], RIM_SIDE_KNOWN).expect("changed");
        assert!((normal - DVec3::Z).length() < 1e-12, "{normal}");
    }
}

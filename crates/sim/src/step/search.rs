//! Phase 2 (and again after each settling): the contact search. Where the
//! organs are, which particles lie near a neighbour, a part or their own
//! surface beyond its neighbourhood, each with the side it must stay on:
//! overlap sides, free pairs (organs without an overlap rule), parts and
//! self-contacts (see `collide`).

use anthesis_physics::Contact;
use anthesis_physics::solver::same_position_bits;
use glam::DVec3;
use rayon::prelude::*;
use std::sync::OnceLock;

use super::rim::RimPieces;
use crate::Simulation;
use crate::collide::{
    Held, Surface, Tracker, Violated, contacts_against, contacts_of, held_where,
    kept_side_contacts, merge_reactions, move_half, reactions, self_contacts,
};
use crate::organ::OrganSim;

/// How deep, in mean edges of the pressed organ, a contact may be violated
/// and still push the other organ back (two-sided contact).
const REACTION_DEPTH: f64 = 0.5;
/// How deep, in mean edges of the pressed organ, a contact must be
/// violated to push the other organ back (two-sided contact): one and a
/// half times the depth below which the push-back alone ends a keyframe
/// (`RESETTLE_DEPTH`). Shallower, the presser is put on its side alone, as
/// one-sided. With every violated contact pushing back, the whole lily
/// took 288 iterations instead of 148 one-sided (161 with this): half of
/// its reactions were of particles a hair through their neighbour (0.0101
/// mean edges, about the collision offset), each moved the neighbour a
/// hundredth of an edge, and the petals' iterations per keyframe went from
/// one or two to three to ten from keyframe 67 on. At 0.02 the lily took
/// 156 but the apple's sepal rims passed through its petals at keyframe 99.
const REACTION_MIN_DEPTH: f64 = 0.015;

impl Simulation {
    /// Every overlap side's contacts and every organ's against the parts,
    /// from the current positions (`geometry`: what is known of the organs
    /// there, completed here), each to be put all the way
    /// ([`Violated::MoveAll`]; [`Simulation::contacts`] gives each organ's
    /// list, moved half way where both organs give way).
    pub(crate) fn search(&self, geometry: &mut [Option<Geometry>]) -> Found {
        self.search_with(geometry, false)
    }

    /// [`Simulation::search`], with each organ's rim contacts if `rims`
    /// (see `collide::rim`; after growth none are looked for: where a
    /// margin grew through a neighbour's rim, the particle contacts and
    /// the organs' settling part them, and the searches after settling
    /// hold what is left apart).
    pub(crate) fn search_with(&self, geometry: &mut [Option<Geometry>], rims: bool) -> Found {
        let mut parts = vec![Vec::new(); self.organs.len()];
        self.obstacle_contacts(&mut parts, &vec![true; self.organs.len()]);
        self.drop_base_contacts(&mut parts);
        geometry
            .par_iter_mut()
            .zip(&self.organs)
            .for_each(|(known, organ)| {
                known.get_or_insert_with(|| Geometry::of(organ));
            });
        let geometry: Vec<&Geometry> = geometry.iter().flatten().collect();
        let selves = self.self_contacts(&geometry);
        let rims = if rims {
            self.rim_contacts(&geometry)
        } else {
            vec![RimPieces::default(); self.organs.len()]
        };
        let free = self
            .free
            .par_iter()
            .map(|&(moving, other)| self.free_contacts_of(moving, other, geometry[other]))
            .collect();
        let mut sides = vec![Vec::new(); 2 * self.overlaps.len()];
        if !self.overlaps.is_empty() {
            // A kinematic organ (two-state) gets no contacts.
            let keys: Vec<(usize, usize, usize, f64)> = self
                .sides()
                .filter(|&(_, moving, _, _)| !self.organs[moving].is_kinematic())
                .collect();
            // Each side's contacts on its own thread.
            let found: Vec<Vec<Contact>> = keys
                .par_iter()
                .map(|&(_, moving, other, side)| {
                    self.contacts_between(moving, other, side, geometry[other])
                })
                .collect();
            for (&(key, ..), list) in keys.iter().zip(found) {
                sides[key] = list;
            }
        }
        let side_held = self
            .sides()
            .collect::<Vec<_>>()
            .par_iter()
            .map(|&(key, moving, other, _)| self.held(moving, other, &sides[key], geometry[other]))
            .collect();
        let free_held = self
            .free
            .par_iter()
            .zip(&free)
            .map(
                |(&(moving, other), list): (&(usize, usize), &Vec<Contact>)| {
                    self.held(moving, other, list, geometry[other])
                },
            )
            .collect();
        Found {
            parts,
            sides,
            selves,
            rims,
            free,
            side_held,
            free_held,
        }
    }

    /// Where the violated contacts of `list` (organ `moving`'s against
    /// organ `other`, whose geometry is `known`) press on `other`, for
    /// their reactions (none on a kinematic organ, which does not give
    /// way).
    fn held(&self, moving: usize, other: usize, list: &[Contact], known: &Geometry) -> Vec<Held> {
        let o = &self.organs[other];
        if !self.two_sided || o.is_kinematic() || list.is_empty() {
            return Vec::new();
        }
        held_where(
            list,
            &self.organs[moving].positions,
            &o.surface(&known.normals),
            &known.tracker,
        )
    }

    /// Organ `moving`'s contacts against organ `other` (a free pair;
    /// `known`: the other's geometry where it is), each keeping the side it
    /// was on when the last keyframe ended, to be put all the way.
    pub(crate) fn free_contacts_of(
        &self,
        moving: usize,
        other: usize,
        known: &Geometry,
    ) -> Vec<Contact> {
        let (m, o) = (&self.organs[moving], &self.organs[other]);
        let mut list = Vec::new();
        let (Some(previous_moving), Some(previous_other)) = (
            m.previous(),
            o.previous()
                .or_else(|| o.is_kinematic().then_some(o.positions.as_slice())),
        ) else {
            return list;
        };
        // A kinematic organ has no history: its shape now stands for then.
        let computed;
        let previous_normals = match o.previous_normals() {
            Some(normals) => normals,
            None => {
                computed = anthesis_mesh::vertex_normals(previous_other, &o.mesh.triangles);
                &computed
            }
        };
        let then = Surface {
            positions: previous_other,
            ..o.surface(previous_normals)
        };
        kept_side_contacts(
            &m.surface(&[]),
            &o.surface(&known.normals),
            &known.tracker,
            previous_moving,
            &then,
            &m.is_base,
            self.settings.collision_offset,
            Violated::MoveAll,
            &mut list,
        );
        list
    }

    /// How many of each organ's contacts of `found` are against the parts
    /// and its neighbours: [`Simulation::contacts`] appends the
    /// self-contacts after them.
    pub(crate) fn neighbour_contacts(&self, found: &Found) -> Vec<usize> {
        let mut counts: Vec<usize> = found.parts.iter().map(Vec::len).collect();
        for (key, moving, _, _) in self.sides() {
            counts[moving] += found.sides[key].len();
        }
        for (&(moving, _), list) in self.free.iter().zip(&found.free) {
            counts[moving] += list.len();
        }
        counts
    }

    /// Whether any organ can touch itself (a growing organ: a kinematic
    /// one gets no contacts).
    pub(crate) fn self_contact(&self) -> bool {
        self.organs.iter().any(|o| !o.is_kinematic())
    }

    /// Each organ's self-contacts where it is (`geometry`: each organ's),
    /// each to be put all the way, base particles left out (see
    /// `collide::self_contacts`).
    pub(crate) fn self_contacts(&self, geometry: &[&Geometry]) -> Vec<Vec<Contact>> {
        (0..self.organs.len())
            .into_par_iter()
            .map(|i| self.self_contacts_of(i, geometry[i]))
            .collect()
    }

    /// Organ `i`'s self-contacts where it is (`known`: its geometry).
    pub(crate) fn self_contacts_of(&self, i: usize, known: &Geometry) -> Vec<Contact> {
        let organ = &self.organs[i];
        let mut list = Vec::new();
        let Some(previous) = organ.previous().filter(|_| !organ.is_kinematic()) else {
            return list;
        };
        let locality = organ.locality();
        let then = Surface {
            positions: previous,
            ..organ.surface(organ.previous_normals().unwrap_or(&[]))
        };
        self_contacts(
            &organ.surface(&known.normals),
            known.beyond(organ),
            &locality,
            &then,
            &organ.is_base,
            self.settings.collision_offset,
            Violated::MoveAll,
            &mut list,
        );
        list
    }

    /// Each organ's contacts of `found`: against the parts, then each side
    /// in order, then (with `selves`) against itself. With
    /// [`Violated::MoveHalf`] a violated contact against an organ that
    /// gives way moves half way (a kinematic organ, two-state, never gives
    /// way, so the organ against it moves all the way, as against a part);
    /// so does a self-contact (the other side of the fold is held off this
    /// one too). The statistics count contacts without `selves` (particles
    /// touching a neighbour).
    pub(crate) fn contacts(
        &self,
        found: &Found,
        violated: Violated,
        selves: bool,
    ) -> Vec<Vec<Contact>> {
        let mut contacts = found.parts.clone();
        for (key, moving, other, _) in self.sides() {
            let half = violated == Violated::MoveHalf && !self.organs[other].is_kinematic();
            let positions = &self.organs[moving].positions;
            contacts[moving].extend(found.sides[key].iter().map(|&c| {
                if half {
                    move_half(c, positions[c.particle as usize])
                } else {
                    c
                }
            }));
        }
        for (&(moving, other), list) in self.free.iter().zip(&found.free) {
            let half = violated == Violated::MoveHalf && !self.organs[other].is_kinematic();
            let positions = &self.organs[moving].positions;
            contacts[moving].extend(list.iter().map(|&c| {
                if half {
                    move_half(c, positions[c.particle as usize])
                } else {
                    c
                }
            }));
        }
        if selves {
            for ((list, own), organ) in contacts.iter_mut().zip(&found.selves).zip(&self.organs) {
                list.extend(own.iter().map(|&c| match violated {
                    Violated::MoveHalf => half_gap(c, organ.positions[c.particle as usize]),
                    Violated::MoveAll => c,
                }));
            }
            for ((list, rims), organ) in contacts.iter_mut().zip(&found.rims).zip(&self.organs) {
                list.extend(rims.all().map(|&c| match violated {
                    Violated::MoveHalf => move_half(c, organ.positions[c.particle as usize]),
                    Violated::MoveAll => c,
                }));
            }
            if violated == Violated::MoveHalf && self.two_sided {
                self.add_reactions(found, &mut contacts);
            }
        }
        contacts
    }

    /// Two-sided contact (issue 35): each contact of a side or a free pair
    /// violated by more than `REACTION_MIN_DEPTH` against an organ that
    /// gives way pushes that organ back, at the triangle it presses on (see
    /// `collide::reactions`), so a petal pressing a neighbour moves it.
    /// Appended to the pressed organ's list after its own contacts, one
    /// per particle (`collide::merge_reactions`); its base particles, which
    /// attachment places, are left out.
    fn add_reactions(&self, found: &Found, contacts: &mut [Vec<Contact>]) {
        let lists = self
            .sides()
            .map(|(key, moving, other, _)| {
                (moving, other, &found.sides[key], &found.side_held[key])
            })
            .chain(
                self.free
                    .iter()
                    .zip(found.free.iter().zip(&found.free_held))
                    .map(|(&(moving, other), (list, held))| (moving, other, list, held)),
            );
        let mut pushed: Vec<Vec<Contact>> = vec![Vec::new(); self.organs.len()];
        for (moving, other, list, held) in lists {
            let (m, o) = (&self.organs[moving], &self.organs[other]);
            // A triangle with a base corner is placed by attachment and
            // gets no reaction (driven through a neighbour's base region,
            // the pressing organ was stretched 24 % against it:
            // `collisions.rs`, the organ turned past horizontal).
            for h in held
                .iter()
                .filter(|h| h.corners.iter().all(|&k| !o.is_base[k as usize]))
            {
                let c = &list[h.contact as usize];
                // Only a contact pressed in less than REACTION_DEPTH pushes
                // back: a particle grown or driven deep into a neighbour in
                // one keyframe is put on its side by the presser alone, as
                // before (its reaction moved the neighbour's triangles by
                // half that depth at once, and Newton found no descent
                // from there: `crossings.rs`, the jammed petals).
                // Nor does one pressed in less than REACTION_MIN_DEPTH.
                let depth = c.violation(m.positions[c.particle as usize]);
                if !(REACTION_MIN_DEPTH * o.mean_edge..=REACTION_DEPTH * o.mean_edge)
                    .contains(&depth)
                {
                    continue;
                }
                reactions(
                    c,
                    h,
                    m.positions[c.particle as usize],
                    &o.positions,
                    &mut pushed[other],
                );
            }
        }
        // One reaction per pressed particle (see `collide::merge_reactions`).
        for ((list, pushed), o) in contacts.iter_mut().zip(pushed).zip(&self.organs) {
            let pushed = pushed
                .into_iter()
                .filter(|c| !o.is_base[c.particle as usize])
                .collect();
            list.extend(merge_reactions(pushed, &o.positions));
        }
    }

    /// Base particles sit on the receptacle, where organs meet by design;
    /// attachment, not collision, decides where they go.
    pub(crate) fn drop_base_contacts(&self, contacts: &mut [Vec<Contact>]) {
        for (organ, list) in self.organs.iter().zip(contacts) {
            list.retain(|c| !organ.is_base[c.particle as usize]);
        }
    }

    /// Contacts keeping the particles of every organ `wanted` outside the
    /// parts, each to be put all the way out (a part does not move aside).
    pub(crate) fn obstacle_contacts(&self, contacts: &mut [Vec<Contact>], wanted: &[bool]) {
        let offset = self.settings.collision_offset;
        let obstacles = &self.obstacles;
        if obstacles.is_empty() {
            return;
        }
        self.organs
            .par_iter()
            .zip(contacts)
            .zip(wanted)
            .for_each(|((organ, list), &wanted)| {
                if organ.is_kinematic() || !wanted {
                    return;
                }
                for obstacle in obstacles {
                    let near = organ
                        .positions
                        .iter()
                        .copied()
                        .enumerate()
                        .filter(|&(_, p)| obstacle.reaches(p));
                    contacts_of(
                        near,
                        &organ.surface(&[]),
                        &obstacle.surface(),
                        obstacle.tracker(),
                        1.0,
                        offset,
                        Violated::MoveAll,
                        list,
                    );
                }
            });
    }

    /// Contacts of organ `moving` against organ `other` (`known`: its
    /// normals and tracker where it is) from the current positions, each
    /// moving particle to be put all the way on its side (`side` as in
    /// [`contacts_against`]).
    pub(crate) fn contacts_between(
        &self,
        moving: usize,
        other: usize,
        side: f64,
        known: &Geometry,
    ) -> Vec<Contact> {
        let (m, o) = (&self.organs[moving], &self.organs[other]);
        let other_surface = o.surface(&known.normals);
        let moving_surface = m.surface(&[]);
        let mut contacts = Vec::new();
        contacts_against(
            &moving_surface,
            &other_surface,
            &known.tracker,
            side,
            self.settings.collision_offset,
            Violated::MoveAll,
            &mut contacts,
        );
        contacts.retain(|c| !m.is_base[c.particle as usize]);
        contacts
    }

    /// Which particles of organ `moving` are no longer where `before`
    /// has them (bit for bit).
    pub(crate) fn changed_since(&self, moving: usize, before: &[DVec3]) -> Vec<usize> {
        let now = &self.organs[moving].positions;
        (0..now.len())
            .filter(|&p| !same_position_bits(now[p], before[p]))
            .collect()
    }

    /// `list`, the contacts of organ `moving` against organ `other` found
    /// where `other` is now, brought to where `moving`'s particles are now:
    /// the particles `changed` (ascending) and those sharing an edge with
    /// one are searched again, the others' contacts kept. The same as
    /// [`Simulation::contacts_between`] (each particle's contact depends
    /// only on where it, the particles it shares an edge with and the other
    /// organ are), in the same order (by particle, at most one each).
    pub(crate) fn update_contacts(
        &self,
        moving: usize,
        other: usize,
        side: f64,
        known: &Geometry,
        list: Vec<Contact>,
        changed: &[usize],
    ) -> Vec<Contact> {
        let (m, o) = (&self.organs[moving], &self.organs[other]);
        let own = m.surface(&[]);
        let mut is_changed = vec![false; m.positions.len()];
        for &p in changed {
            for &t in own.rings.around(p as u32) {
                for k in own.triangles[t as usize] {
                    is_changed[k as usize] = true;
                }
            }
        }
        let mut fresh = Vec::new();
        contacts_of(
            (0..m.positions.len())
                .filter(|&p| is_changed[p])
                .map(|p| (p, m.positions[p])),
            &own,
            &o.surface(&known.normals),
            &known.tracker,
            side,
            self.settings.collision_offset,
            Violated::MoveAll,
            &mut fresh,
        );
        fresh.retain(|c| !m.is_base[c.particle as usize]);
        let mut merged = Vec::with_capacity(list.len() + fresh.len());
        let mut fresh = fresh.into_iter().peekable();
        for c in list {
            while let Some(f) = fresh.next_if(|f| f.particle < c.particle) {
                merged.push(f);
            }
            if !is_changed[c.particle as usize] {
                merged.push(c);
            }
        }
        merged.extend(fresh);
        merged
    }

    /// Every overlap side in order: its key in [`Found::sides`], the organ
    /// whose particles it holds, the other organ, and which side of the
    /// other they stay on (+1 its inner side). Inner particles stay on the
    /// outer organ's inner side (key `2 * overlap`), outer particles on the
    /// inner organ's outer side (`2 * overlap + 1`).
    pub(crate) fn sides(&self) -> impl Iterator<Item = (usize, usize, usize, f64)> + '_ {
        self.overlaps
            .iter()
            .enumerate()
            .flat_map(|(index, &(inner, outer))| {
                [
                    (2 * index, inner, outer, 1.0),
                    (2 * index + 1, outer, inner, -1.0),
                ]
            })
    }
}

/// Self-contact `c` of a particle at `x` while the organs settle: moved
/// half way if violated ([`move_half`]), and else moved half the gap
/// towards the particle. Both sides of a fold are held off each other, each
/// against where the other was when the contacts were found, which the
/// contacts keep for the whole round: two turns of a roll closing on each
/// other could each close the whole gap and pass each other, so each
/// closes half of it. On the lily petal rolled into a scroll
/// (`petal-e-in-x2` in the stress example), with each turn free to close
/// the whole gap, each of the four contact rounds of keyframe 27 ended
/// with a particle 0.22 to 0.36 mean edges through the other turn (held
/// off where the other turn was), twelve rounds did no better, and the
/// scroll crossed itself there; closing half, 0.06, and it first crossed
/// at keyframe 62.
fn half_gap(c: Contact, x: DVec3) -> Contact {
    let violation = c.violation(x);
    if violation > 0.0 {
        return move_half(c, x);
    }
    Contact {
        point: c.point - c.normal * (0.5 * violation),
        ..c
    }
}

/// A contact search where the organs are (see `Simulation::search`): each
/// organ's contacts against the parts and each overlap side's (`2 * overlap`
/// for the inner organ's particles, `2 * overlap + 1` for the outer's), each
/// to be put all the way, base particles left out.
pub(crate) struct Found {
    pub(crate) parts: Vec<Vec<Contact>>,
    pub(crate) sides: Vec<Vec<Contact>>,
    /// Each organ's contacts against itself.
    pub(crate) selves: Vec<Vec<Contact>>,
    /// Each organ's rim contacts (see `collide::rim`), appended after its
    /// self-contacts.
    pub(crate) rims: Vec<RimPieces>,
    /// Each free pair's contacts (`Simulation::free`, same order).
    pub(crate) free: Vec<Vec<Contact>>,
    /// Where the violated contacts of each side press on the other organ
    /// (two-sided contact; see `collide::held_where`).
    pub(crate) side_held: Vec<Vec<Held>>,
    /// The same for each free pair's.
    pub(crate) free_held: Vec<Vec<Held>>,
}

/// One organ's unit normals and nearest-particle lookup where it is:
/// every collision search needs them, and an organ that has not moved
/// since keeps them.
pub(crate) struct Geometry {
    pub(crate) normals: Vec<DVec3>,
    pub(crate) tracker: Tracker,
    /// Per particle, its nearest particle beyond its neighbourhood
    /// (self-contact and the rim contacts against itself ask for it),
    /// made on first use.
    beyond: OnceLock<Vec<Option<u32>>>,
}

impl Geometry {
    pub(crate) fn of(organ: &OrganSim) -> Geometry {
        Geometry {
            normals: anthesis_mesh::vertex_normals(&organ.positions, &organ.mesh.triangles),
            tracker: Tracker::new(&organ.positions, 2.0 * organ.mean_edge),
            beyond: OnceLock::new(),
        }
    }

    /// Per particle of `organ` (where this geometry was made), its nearest
    /// particle within the tracker's reach beyond its neighbourhood
    /// ([`Tracker::nearest_beyond_each`]).
    pub(crate) fn beyond(&self, organ: &OrganSim) -> &[Option<u32>] {
        self.beyond.get_or_init(|| {
            let locality = organ.locality();
            let cells = self.tracker.cell_bounds(locality.uv);
            self.tracker
                .nearest_beyond_each(&organ.positions, &cells, &locality)
        })
    }
}

/// Every (moving, other) pair of organs with no overlap rule between them
/// (either way), the moving one growing (a kinematic organ gets no
/// contacts): issue 35's organs of one whorl, which keep the side of each
/// other they were on.
pub(crate) fn free_pairs(organs: &[OrganSim], overlaps: &[(usize, usize)]) -> Vec<(usize, usize)> {
    let ruled = |a: usize, b: usize| {
        overlaps
            .iter()
            .any(|&(i, o)| (i, o) == (a, b) || (i, o) == (b, a))
    };
    let mut pairs = Vec::new();
    for a in 0..organs.len() {
        for b in 0..organs.len() {
            if a != b && !ruled(a, b) && !organs[a].is_kinematic() {
                pairs.push((a, b));
            }
        }
    }
    pairs
}

/// Nothing known yet of `organs` organs' geometry.
pub(crate) fn unknown_geometry(organs: usize) -> Vec<Option<Geometry>> {
    (0..organs).map(|_| None).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Selection;
    use crate::collide::Violated;
    use crate::fixtures::inner_driven_into_outer_by;

    /// The penalty force `c` puts on a particle at `x`, over the contact
    /// stiffness.
    fn force(c: &Contact, x: DVec3) -> DVec3 {
        c.normal * (c.weight * c.violation(x).max(0.0))
    }

    #[test]
    fn a_self_contact_lets_each_turn_close_half_the_gap_while_settling() {
        // The other turn's plane z = 0, held 0.01 off; two turns closing
        // on each other from 0.41 apart meet at the offset in the middle
        // (each allowed 0.2 of the 0.4 left), not each at the other's
        // place.
        let c = Contact {
            particle: 0,
            point: DVec3::ZERO,
            normal: DVec3::Z,
            offset: 0.01,
            weight: 1.0,
        };
        let x = DVec3::new(0.3, -0.2, 0.41);
        let held = half_gap(c, x);
        assert!(
            (held.violation(x) + 0.2).abs() < 1e-12,
            "{}",
            held.violation(x)
        );
        assert!((held.violation(DVec3::new(1.0, 2.0, 0.21)) - 0.0).abs() < 1e-12);
        assert_eq!(held.normal, c.normal);
        // One already 0.1 through goes back half way, as against another
        // organ.
        let through = DVec3::new(0.0, 0.0, -0.1);
        assert_eq!(half_gap(c, through), move_half(c, through));
    }

    #[test]
    fn two_petals_pressed_together_push_each_other_equally_and_oppositely() {
        let keyframes = 12;
        // The inner petal's joint driven 40 degrees, the outer's 10.
        let project = inner_driven_into_outer_by(keyframes, true, 40.0);
        let mut pressed_keyframes = 0;
        for step in 1..=keyframes {
            // The keyframe's contacts as the solve gets them: after growth,
            // where the organs are.
            let mut sim = Simulation::new(&project, &Selection::All).expect("valid");
            sim.two_sided_contact(true);
            for _ in 1..step {
                sim.step(&|| false, &mut |_| {}).expect("the run goes on");
            }
            sim.grow(step);
            let found = sim.search(&mut unknown_geometry(2));
            let both = sim.contacts(&found, Violated::MoveHalf, true);
            sim.two_sided = false;
            let one = sim.contacts(&found, Violated::MoveHalf, true);
            // Each organ's reactions follow its own contacts.
            let mut total = DVec3::ZERO;
            let mut scale = 0.0f64;
            let mut reactions = 0;
            for (organ, (both, one)) in both.iter().zip(&one).enumerate() {
                assert_eq!(both[..one.len()], one[..]);
                let at = &sim.organs[organ].positions;
                for c in &both[one.len()..] {
                    let f = force(c, at[c.particle as usize]);
                    assert!(f.length() > 0.0);
                    total += f;
                    reactions += 1;
                }
            }
            if reactions == 0 {
                continue;
            }
            pressed_keyframes += 1;
            // The contacts that pushed back, on the pressers: those a
            // reaction was made for (see `add_reactions`).
            for (key, moving, other, _) in sim.sides() {
                let (m, o) = (&sim.organs[moving], &sim.organs[other]);
                for h in &found.side_held[key] {
                    let c = found.sides[key][h.contact as usize];
                    let x = m.positions[c.particle as usize];
                    let depth = c.violation(x);
                    if h.corners.iter().any(|&k| o.is_base[k as usize])
                        || !(REACTION_MIN_DEPTH * o.mean_edge..=REACTION_DEPTH * o.mean_edge)
                            .contains(&depth)
                    {
                        continue;
                    }
                    let f = force(&move_half(c, x), x);
                    scale = scale.max(f.length());
                    total += f;
                }
            }
            assert!(
                total.length() < 1e-12 * scale * reactions as f64,
                "keyframe {step}: the contacts' forces sum to {total}, largest {scale}"
            );
        }
        // The petals press from keyframe 5 (`tests/two_sided.rs`).
        assert!(
            pressed_keyframes >= 3,
            "{pressed_keyframes} keyframes pressed"
        );
    }
}

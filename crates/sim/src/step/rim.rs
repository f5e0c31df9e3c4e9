//! Rim contacts in the contact search (issue 35; see `collide::rim`):
//! each organ's edges kept off the rim edges of every organ it has
//! contacts with (an overlap side or a free pair) and of itself beyond its
//! neighbourhood, and its rim edges off theirs.

use anthesis_physics::Contact;
use rayon::prelude::*;

use super::search::Geometry;
use crate::Simulation;
use crate::collide::{RimSide, SelfNear, rim_contacts_of_pairs, rim_pairs};

impl Simulation {
    /// Every organ's rim contacts where the organs are (`geometry`: each
    /// organ's), each to be put all the way. The edge pairs of two organs
    /// that each have contacts with the other are found once, for both
    /// (half the rim search's time on the whole lily).
    pub(crate) fn rim_contacts(&self, geometry: &[&Geometry]) -> Vec<Vec<Contact>> {
        let others: Vec<Vec<usize>> = (0..self.organs.len()).map(|i| self.rim_others(i)).collect();
        // Each pair of organs once, lower first.
        let mut shared: Vec<(usize, usize)> = others
            .iter()
            .enumerate()
            .flat_map(|(i, list)| list.iter().map(move |&o| (i.min(o), i.max(o))))
            .collect();
        shared.sort_unstable();
        shared.dedup();
        let found: Vec<Option<Pairs>> = shared
            .par_iter()
            .map(|&(a, b)| {
                let (first, second) = (self.rim_side(a, geometry)?, self.rim_side(b, geometry)?);
                Some(rim_pairs(&first, &second, None))
            })
            .collect();
        (0..self.organs.len())
            .into_par_iter()
            .map(|i| {
                self.rim_contacts_with(i, geometry, &others[i], |other| {
                    let at = shared.binary_search(&(i.min(other), i.max(other))).ok()?;
                    let pairs = found[at].as_ref()?;
                    Some(if i < other {
                        pairs.clone()
                    } else {
                        let mut turned: Pairs = pairs.iter().map(|&(p, q)| (q, p)).collect();
                        turned.sort_unstable();
                        turned
                    })
                })
            })
            .collect()
    }

    /// Organ `i`'s rim contacts where the organs are: against each organ
    /// it has contacts with, then against itself.
    pub(crate) fn rim_contacts_of(&self, i: usize, geometry: &[&Geometry]) -> Vec<Contact> {
        self.rim_contacts_with(i, geometry, &self.rim_others(i), |_| None)
    }

    /// The organs organ `i` has contacts with (an overlap side or a free
    /// pair), in order.
    fn rim_others(&self, i: usize) -> Vec<usize> {
        let mut others: Vec<usize> = self
            .sides()
            .filter(|&(_, moving, _, _)| moving == i)
            .map(|(_, _, other, _)| other)
            .chain(
                self.free
                    .iter()
                    .filter(|&&(moving, _)| moving == i)
                    .map(|&(_, other)| other),
            )
            .collect();
        others.sort_unstable();
        others.dedup();
        others
    }

    /// Organ `k` as the rim search sees it, if it has a shape to keep the
    /// side of (a grown organ, or a kinematic one, whose shape now stands
    /// for then).
    fn rim_side<'a>(&'a self, k: usize, geometry: &[&'a Geometry]) -> Option<RimSide<'a>> {
        let o = &self.organs[k];
        let then = o
            .previous()
            .or_else(|| o.is_kinematic().then_some(o.positions.as_slice()))?;
        Some(RimSide {
            surface: o.surface(&[]),
            previous: then,
            tracker: &geometry[k].tracker,
            rim_edges: o.rim_edges(),
            base: o.near_base(),
        })
    }

    /// [`Simulation::rim_contacts_of`] against `others`, with the edge
    /// pairs against another organ from `known` where it has them.
    fn rim_contacts_with(
        &self,
        i: usize,
        geometry: &[&Geometry],
        others: &[usize],
        known: impl Fn(usize) -> Option<Pairs> + Sync,
    ) -> Vec<Contact> {
        let organ = &self.organs[i];
        let mut list = Vec::new();
        if organ.is_kinematic() || organ.previous().is_none() {
            return list;
        }
        let Some(moving) = self.rim_side(i, geometry) else {
            return list;
        };
        let offset = self.settings.collision_offset;
        let locality = organ.locality();
        let near = SelfNear {
            bud_near: 0.5 * locality.local,
            beyond: geometry[i].beyond(organ),
            locality,
            bud: &organ.initial,
        };
        // The edge pairs against each organ and itself on rayon's threads
        // (the push-back asks for one organ's at a time); the contacts
        // from them in order.
        let (against, own) = rayon::join(
            || {
                others
                    .par_iter()
                    .map(|&other| {
                        let side = self.rim_side(other, geometry)?;
                        let pairs = known(other).unwrap_or_else(|| rim_pairs(&moving, &side, None));
                        Some((side, pairs))
                    })
                    .collect::<Vec<_>>()
            },
            || rim_pairs(&moving, &moving, Some(&near)),
        );
        for (side, pairs) in against.iter().flatten() {
            rim_contacts_of_pairs(&moving, side, pairs, None, offset, &mut list);
        }
        rim_contacts_of_pairs(&moving, &moving, &own, Some(&near), offset, &mut list);
        list
    }
}

/// Edge pairs of two organs ([`rim_pairs`]).
type Pairs = Vec<([u32; 2], [u32; 2])>;

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
    /// organ's), each to be put all the way, in pieces ([`RimPieces`]).
    /// The edge pairs of two organs that each have contacts with the other
    /// are found once, for both (half the rim search's time on the whole
    /// lily).
    pub(crate) fn rim_contacts(&self, geometry: &[&Geometry]) -> Vec<RimPieces> {
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
                let pieces: Vec<Option<usize>> =
                    others[i].iter().copied().map(Some).chain([None]).collect();
                let lists = self.rim_pieces(i, geometry, &pieces, |other| {
                    let at = shared.binary_search(&(i.min(other), i.max(other))).ok()?;
                    let pairs = found[at].as_ref()?;
                    Some(if i < other {
                        pairs.clone()
                    } else {
                        let mut turned: Pairs = pairs.iter().map(|&(p, q)| (q, p)).collect();
                        turned.sort_unstable();
                        turned
                    })
                });
                RimPieces { pieces, lists }
            })
            .collect()
    }

    /// The organs organ `i` has contacts with (an overlap side or a free
    /// pair), in order: its rim pieces against other organs, before the
    /// one against itself.
    pub(crate) fn rim_others(&self, i: usize) -> Vec<usize> {
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

    /// Organ `i`'s rim contacts against each of `pieces` (another organ,
    /// or itself for `None`), one list each in that order, each piece on
    /// rayon's threads (the push-back asks for one organ's at a time); the
    /// edge pairs against another organ from `known` where it has them.
    pub(crate) fn rim_pieces(
        &self,
        i: usize,
        geometry: &[&Geometry],
        pieces: &[Option<usize>],
        known: impl Fn(usize) -> Option<Pairs> + Sync,
    ) -> Vec<Vec<Contact>> {
        let organ = &self.organs[i];
        let moving = self
            .rim_side(i, geometry)
            .filter(|_| !organ.is_kinematic() && organ.previous().is_some());
        let Some(moving) = moving else {
            return vec![Vec::new(); pieces.len()];
        };
        let offset = self.settings.collision_offset;
        pieces
            .par_iter()
            .map(|&piece| {
                let mut list = Vec::new();
                match piece {
                    Some(other) => {
                        if let Some(side) = self.rim_side(other, geometry) {
                            let pairs =
                                known(other).unwrap_or_else(|| rim_pairs(&moving, &side, None));
                            rim_contacts_of_pairs(&moving, &side, &pairs, None, offset, &mut list);
                        }
                    }
                    None => {
                        let locality = organ.locality();
                        let near = SelfNear {
                            bud_near: 0.5 * locality.local,
                            beyond: geometry[i].beyond(organ),
                            locality,
                            bud: &organ.initial,
                        };
                        let own = rim_pairs(&moving, &moving, Some(&near));
                        rim_contacts_of_pairs(
                            &moving,
                            &moving,
                            &own,
                            Some(&near),
                            offset,
                            &mut list,
                        );
                    }
                }
                list
            })
            .collect()
    }
}

/// One organ's rim contacts in pieces: against each organ it has contacts
/// with (`Some`), then against itself (`None`). A piece depends only on
/// where its two organs are, so the push-back makes again only the pieces
/// of organs it moved.
#[derive(Clone, Default)]
pub(crate) struct RimPieces {
    pub(crate) pieces: Vec<Option<usize>>,
    pub(crate) lists: Vec<Vec<Contact>>,
}

impl RimPieces {
    /// Every contact, piece after piece.
    pub(crate) fn all(&self) -> impl Iterator<Item = &Contact> {
        self.lists.iter().flatten()
    }
}

/// Edge pairs of two organs ([`rim_pairs`]).
pub(crate) type Pairs = Vec<([u32; 2], [u32; 2])>;

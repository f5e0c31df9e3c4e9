//! Rim contacts in the contact search (issue 35; see `collide::rim`):
//! each organ's edges kept off the rim edges of every organ it has
//! contacts with (an overlap side or a free pair) and of itself beyond its
//! neighbourhood, and its rim edges off theirs.

use anthesis_physics::Contact;
use rayon::prelude::*;

use super::search::Geometry;
use crate::Simulation;
use crate::collide::{RimSide, SelfNear, rim_contacts};

impl Simulation {
    /// Every organ's rim contacts where the organs are (`geometry`: each
    /// organ's), each to be put all the way.
    pub(crate) fn rim_contacts(&self, geometry: &[&Geometry]) -> Vec<Vec<Contact>> {
        (0..self.organs.len())
            .into_par_iter()
            .map(|i| self.rim_contacts_of(i, geometry))
            .collect()
    }

    /// Organ `i`'s rim contacts where the organs are: against each organ
    /// it has contacts with, then against itself.
    pub(crate) fn rim_contacts_of(&self, i: usize, geometry: &[&Geometry]) -> Vec<Contact> {
        let organ = &self.organs[i];
        let mut list = Vec::new();
        let Some(previous) = organ.previous().filter(|_| !organ.is_kinematic()) else {
            return list;
        };
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
        let side = |k: usize, previous| RimSide {
            surface: self.organs[k].surface(&[]),
            previous,
            tracker: &geometry[k].tracker,
            rim_edges: self.organs[k].rim_edges(),
            base: self.organs[k].near_base(),
        };
        let moving = side(i, previous);
        let offset = self.settings.collision_offset;
        for other in others {
            let o = &self.organs[other];
            let Some(then) = o
                .previous()
                .or_else(|| o.is_kinematic().then_some(o.positions.as_slice()))
            else {
                continue;
            };
            rim_contacts(&moving, &side(other, then), None, offset, &mut list);
        }
        let locality = organ.locality();
        let near = SelfNear {
            bud_near: 0.5 * locality.local,
            cells: geometry[i].tracker.cell_bounds(locality.uv),
            locality,
            bud: &organ.initial,
        };
        rim_contacts(&moving, &moving, Some(&near), offset, &mut list);
        list
    }
}

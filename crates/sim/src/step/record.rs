//! Phase 6: the keyframe as a run gives it, with its statistics (how many
//! particles touch a neighbour, how many the push-back moved), and the
//! checkpoint an edit resumes from.

use std::time::Instant;

use anthesis_physics::Contact;

use super::search::{Found, Geometry};
use crate::collide::Violated;
use crate::{Keyframe, KeyframeStats, Simulation};

impl Simulation {
    /// Keyframe `step` where the organs are now, started at `started`,
    /// with their summed `energy`, `(iterations, last relative gradient)`
    /// and how many particles the push-back moved; `pressed` and
    /// `contacts` as [`Simulation::particles_in_contact`] takes them. Keeps
    /// the checkpoint if asked to, and moves the run on to the next step.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn record(
        &mut self,
        step: u32,
        started: Instant,
        energy: f64,
        (iterations, gradient): (u32, f64),
        pushed: usize,
        pressed: &[Vec<bool>],
        contacts: Option<Vec<Vec<Contact>>>,
        geometry: &mut [Option<Geometry>],
    ) -> Keyframe {
        self.next_step += 1;
        if self.checkpoints.is_some() {
            let state = self.checkpoint();
            self.checkpoints.get_or_insert_default().push(state);
        }
        Keyframe {
            index: step,
            positions_in_world: self.organs.iter().map(|o| o.positions.clone()).collect(),
            stats: KeyframeStats {
                index: step,
                energy,
                iterations,
                relative_gradient: gradient,
                seconds: started.elapsed().as_secs_f64(),
                pushed_particles: pushed as u32,
                contact_particles: self.particles_in_contact(pressed, contacts, geometry),
            },
        }
    }

    /// Per organ, which particles pressed on a neighbour while the organs
    /// settled against `contacts` (found in `found`; the self-contacts,
    /// appended last, left out), and adds those held off their own organ
    /// to [`Simulation::self_contact_count`].
    pub(crate) fn count_pressed(
        &mut self,
        found: &Found,
        contacts: &[Vec<Contact>],
    ) -> Vec<Vec<bool>> {
        // The contacts held, less the self-contacts (appended last).
        let neighbours = self.neighbour_contacts(found);
        let held: Vec<Vec<Contact>> = contacts
            .iter()
            .zip(&neighbours)
            .map(|(c, &n)| c[..n].to_vec())
            .collect();
        let pressed = self.pressed(&held);
        self.self_pressed += self
            .pressed(&found.selves)
            .iter()
            .flatten()
            .filter(|&&p| p)
            .count() as u64;
        pressed
    }

    /// `fresh`, each organ's contacts of the search `found`, without the
    /// self-contacts (the statistics count particles touching a
    /// neighbour).
    pub(crate) fn neighbours_only(
        &self,
        found: &Found,
        fresh: Vec<Vec<Contact>>,
    ) -> Vec<Vec<Contact>> {
        let neighbours = self.neighbour_contacts(found);
        fresh
            .into_iter()
            .zip(neighbours)
            .map(|(mut c, n)| {
                c.truncate(n);
                c
            })
            .collect()
    }

    /// Per organ, which particles the organs lean on a neighbour with: a
    /// contact of `contacts` (those held while they settled) is violated,
    /// so its force holds them off.
    pub(crate) fn pressed(&self, contacts: &[Vec<Contact>]) -> Vec<Vec<bool>> {
        self.organs
            .iter()
            .zip(contacts)
            .map(|(o, c)| {
                let mut held = vec![false; o.positions.len()];
                for contact in c {
                    let p = contact.particle as usize;
                    held[p] |= contact.violation(o.positions[p]) > 0.0;
                }
                held
            })
            .collect()
    }

    /// How many particles touch a neighbouring organ: `pressed` (held off
    /// it by a contact force while the organs settled), or their contact
    /// is violated or short of it by less than the collision offset now (a
    /// particle with several neighbours counts once). `contacts` are those
    /// of the organs where they are, when known.
    pub(crate) fn particles_in_contact(
        &self,
        pressed: &[Vec<bool>],
        contacts: Option<Vec<Vec<Contact>>>,
        geometry: &mut [Option<Geometry>],
    ) -> u32 {
        let offset = self.settings.collision_offset;
        contacts
            .unwrap_or_else(|| self.contacts(&self.search(geometry), Violated::MoveAll, false))
            .iter()
            .zip(&self.organs)
            .enumerate()
            .map(|(i, (contacts, organ))| {
                let mut touching = pressed
                    .get(i)
                    .cloned()
                    .unwrap_or_else(|| vec![false; organ.positions.len()]);
                for c in contacts {
                    let p = c.particle as usize;
                    touching[p] |= c.violation(organ.positions[p]) > -offset;
                }
                touching.iter().filter(|&&t| t).count() as u32
            })
            .sum()
    }
}

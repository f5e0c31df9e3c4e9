//! Phase 4: the paper's push-back. Nobody ends a keyframe on the wrong
//! side: what the settling left there is moved out, one overlap side (and
//! free pair, organ against the parts, organ against itself) at a time.

use anthesis_physics::Contact;
use glam::DVec3;

use super::search::{Found, Geometry};
use crate::Simulation;
use crate::collide::push_back;

/// Passes of the final push-back at most.
const PUSH_BACK_PASSES: u32 = 3;

/// What the push-back knows between its passes.
struct Pushing {
    /// Per organ, which particles it moved.
    moved: Vec<Vec<bool>>,
    /// How often each organ has been pushed. A search that pushed
    /// nothing finds the same again until one of its organs is pushed,
    /// so it is not made again before (against the parts: per organ; of
    /// an overlap side: per side).
    pushes: Vec<u32>,
    parts_clear: Vec<Option<u32>>,
    side_clear: Vec<Option<(u32, u32)>>,
    free_clear: Vec<Option<(u32, u32)>>,
    self_clear: Vec<Option<u32>>,
    /// Per organ, the pushes of all organs together when its rim
    /// contacts last pushed nothing.
    rim_clear: Vec<Option<u32>>,
    /// Per organ, per piece of its rim contacts (`found.rims`), how often
    /// its two organs had been pushed when the piece was made.
    rim_made: Vec<Vec<(u32, u32)>>,
    /// The last search against the parts, per organ, per side, per free
    /// pair and per organ against itself; at first those of the search
    /// made before anything was pushed.
    found: Found,
    /// Whether an organ's list against the parts is still the one given.
    parts_given: Vec<bool>,
    /// Where each side's moving organ was when its last list was found,
    /// and how often the other organ had been pushed then.
    side_at: Vec<(Vec<DVec3>, u32)>,
}

impl Pushing {
    /// Records that `list` pushed `pushed` particles of `organ`: a push
    /// makes its geometry unknown, no push marks the search clear.
    fn pushed<T: Copy>(
        &mut self,
        organ: usize,
        pushed: usize,
        geometry: &mut [Option<Geometry>],
        clear: &mut Option<T>,
        now: T,
    ) {
        if pushed > 0 {
            self.pushes[organ] += 1;
            geometry[organ] = None;
        } else {
            *clear = Some(now);
        }
    }
}

impl Simulation {
    /// The paper's push-back: nobody ends on the wrong side. Organs are
    /// pushed one overlap side at a time, each against where the other is
    /// now (pushed both at once, two particles on the wrong side of each
    /// other would swap places and stay wrong). Returns how many particles
    /// moved, and, unless the passes ran out, every organ's contacts where
    /// it now is (as `Violated::MoveAll` finds them: its last searches are
    /// those). `geometry` is what is known of the organs where they are, and
    /// is kept up to date; `found` is the search made where they are, which
    /// a side (or an organ against the parts) pushes with until one of its
    /// organs is pushed.
    pub(crate) fn push_back(
        &mut self,
        geometry: &mut [Option<Geometry>],
        found: Found,
    ) -> (usize, Option<Vec<Vec<Contact>>>) {
        let organs = self.organs.len();
        let mut state = Pushing {
            moved: self
                .organs
                .iter()
                .map(|o| vec![false; o.positions.len()])
                .collect(),
            pushes: vec![0; organs],
            parts_clear: vec![None; organs],
            side_clear: vec![None; 2 * self.overlaps.len()],
            free_clear: vec![None; self.free.len()],
            self_clear: vec![None; organs],
            rim_clear: vec![None; organs],
            rim_made: found
                .rims
                .iter()
                .map(|r| vec![(0, 0); r.pieces.len()])
                .collect(),
            found,
            parts_given: vec![true; organs],
            side_at: self
                .sides()
                .map(|(_, moving, _, _)| (self.organs[moving].positions.clone(), 0))
                .collect(),
        };
        let mut settled = false;
        // A pushed particle turns its neighbours' normals a little, which
        // can leave a particle of the other organ just short of its side:
        // pass again while that happens.
        for _ in 0..PUSH_BACK_PASSES {
            let pushed_in_pass = self.push_off_parts(&mut state, geometry)
                + self.push_sides(&mut state, geometry)
                + self.push_free(&mut state, geometry)
                + self.push_selves(&mut state, geometry)
                + self.push_rims(&mut state, geometry);
            if pushed_in_pass == 0 {
                settled = true;
                break;
            }
        }
        let pushed = state.moved.iter().flatten().filter(|&&m| m).count();
        // Every search of the last pass, or the earlier one it skipped,
        // was made where the organs are now, and found nothing to push.
        let found = settled.then(|| {
            let Found {
                parts: mut contacts,
                sides,
                free,
                ..
            } = state.found;
            for (key, moving, _, _) in self.sides() {
                contacts[moving].extend_from_slice(&sides[key]);
            }
            for (&(moving, _), list) in self.free.iter().zip(&free) {
                contacts[moving].extend_from_slice(list);
            }
            contacts
        });
        (pushed, found)
    }

    /// One pass of every organ against the parts; returns the particles
    /// pushed.
    fn push_off_parts(&mut self, state: &mut Pushing, geometry: &mut [Option<Geometry>]) -> usize {
        let mut pushed_in_pass = 0;
        let mut outside = vec![Vec::new(); self.organs.len()];
        let wanted: Vec<bool> = state
            .parts_clear
            .iter()
            .zip(&state.pushes)
            .map(|(clear, &n)| *clear != Some(n))
            .collect();
        // Nothing has been pushed before the first pass's parts.
        let search: Vec<bool> = (0..wanted.len())
            .map(|i| wanted[i] && !state.parts_given[i])
            .collect();
        self.obstacle_contacts(&mut outside, &search);
        self.drop_base_contacts(&mut outside);
        for (i, searched) in outside.into_iter().enumerate() {
            if !wanted[i] {
                continue;
            }
            let list = if state.parts_given[i] {
                state.parts_given[i] = false;
                std::mem::take(&mut state.found.parts[i])
            } else {
                searched
            };
            let pushed = push_back(&mut self.organs[i].positions, &list, &mut state.moved[i]);
            let mut clear = state.parts_clear[i];
            let now = state.pushes[i];
            state.pushed(i, pushed, geometry, &mut clear, now);
            state.parts_clear[i] = clear;
            state.found.parts[i] = list;
            pushed_in_pass += pushed;
        }
        pushed_in_pass
    }

    /// One pass of every overlap side; returns the particles pushed.
    fn push_sides(&mut self, state: &mut Pushing, geometry: &mut [Option<Geometry>]) -> usize {
        let mut pushed_in_pass = 0;
        let sides: Vec<(usize, usize, usize, f64)> = self.sides().collect();
        for &(key, moving, other, side) in &sides {
            if self.organs[moving].is_kinematic()
                || state.side_clear[key] == Some((state.pushes[moving], state.pushes[other]))
            {
                continue;
            }
            // While the other organ stays where it was, only the
            // moving organ's particles that moved since its last
            // list can find other contacts.
            let (before, other_pushes) = &state.side_at[key];
            let list = std::mem::take(&mut state.found.sides[key]);
            let contacts = if *other_pushes == state.pushes[other] {
                let changed = self.changed_since(moving, before);
                if changed.is_empty() {
                    list
                } else {
                    let known =
                        geometry[other].get_or_insert_with(|| Geometry::of(&self.organs[other]));
                    self.update_contacts(moving, other, side, known, list, &changed)
                }
            } else {
                let known =
                    geometry[other].get_or_insert_with(|| Geometry::of(&self.organs[other]));
                self.contacts_between(moving, other, side, known)
            };
            state.side_at[key] = (self.organs[moving].positions.clone(), state.pushes[other]);
            let pushed = push_back(
                &mut self.organs[moving].positions,
                &contacts,
                &mut state.moved[moving],
            );
            let mut clear = state.side_clear[key];
            let now = (state.pushes[moving], state.pushes[other]);
            state.pushed(moving, pushed, geometry, &mut clear, now);
            state.side_clear[key] = clear;
            state.found.sides[key] = contacts;
            pushed_in_pass += pushed;
        }
        pushed_in_pass
    }

    /// One pass of every free pair: the search made before the push-back
    /// while neither organ was pushed, else where they are. Returns the
    /// particles pushed.
    fn push_free(&mut self, state: &mut Pushing, geometry: &mut [Option<Geometry>]) -> usize {
        let mut pushed_in_pass = 0;
        for key in 0..self.free.len() {
            let (moving, other) = self.free[key];
            if state.free_clear[key] == Some((state.pushes[moving], state.pushes[other])) {
                continue;
            }
            let given = std::mem::take(&mut state.found.free[key]);
            let list = if state.pushes[moving] == 0
                && state.pushes[other] == 0
                && state.free_clear[key].is_none()
            {
                given
            } else {
                let known =
                    geometry[other].get_or_insert_with(|| Geometry::of(&self.organs[other]));
                self.free_contacts_of(moving, other, known)
            };
            let pushed = push_back(
                &mut self.organs[moving].positions,
                &list,
                &mut state.moved[moving],
            );
            let mut clear = state.free_clear[key];
            let now = (state.pushes[moving], state.pushes[other]);
            state.pushed(moving, pushed, geometry, &mut clear, now);
            state.free_clear[key] = clear;
            state.found.free[key] = list;
            pushed_in_pass += pushed;
        }
        pushed_in_pass
    }

    /// One pass of each organ against itself: the search made before the
    /// push-back while nothing has pushed it, else where it is. Returns
    /// the particles pushed.
    fn push_selves(&mut self, state: &mut Pushing, geometry: &mut [Option<Geometry>]) -> usize {
        let mut pushed_in_pass = 0;
        for i in 0..self.organs.len() {
            if self.organs[i].is_kinematic() || state.self_clear[i] == Some(state.pushes[i]) {
                continue;
            }
            let given = std::mem::take(&mut state.found.selves[i]);
            let list = if state.pushes[i] == 0 && state.self_clear[i].is_none() {
                given
            } else {
                let known = geometry[i].get_or_insert_with(|| Geometry::of(&self.organs[i]));
                self.self_contacts_of(i, known)
            };
            let pushed = push_back(&mut self.organs[i].positions, &list, &mut state.moved[i]);
            let mut clear = state.self_clear[i];
            let now = state.pushes[i];
            state.pushed(i, pushed, geometry, &mut clear, now);
            state.self_clear[i] = clear;
            pushed_in_pass += pushed;
        }
        pushed_in_pass
    }

    /// What is known of every organ where it is, made where missing.
    fn every_geometry<'a>(&self, geometry: &'a mut [Option<Geometry>]) -> Vec<&'a Geometry> {
        geometry
            .iter_mut()
            .zip(&self.organs)
            .map(|(known, organ)| &*known.get_or_insert_with(|| Geometry::of(organ)))
            .collect()
    }

    /// One pass of each organ's rim contacts. Each piece (against one
    /// organ, or itself) is the one the search made before the push-back,
    /// or the last one made, while neither of its organs has been pushed
    /// since; otherwise it is made again where they are. Returns the
    /// particles pushed.
    fn push_rims(&mut self, state: &mut Pushing, geometry: &mut [Option<Geometry>]) -> usize {
        let mut pushed_in_pass = 0;
        for i in 0..self.organs.len() {
            let all_pushes: u32 = state.pushes.iter().sum();
            if self.organs[i].is_kinematic() || state.rim_clear[i] == Some(all_pushes) {
                continue;
            }
            let stamp = |piece: Option<usize>| (state.pushes[i], state.pushes[piece.unwrap_or(i)]);
            let rims = &mut state.found.rims[i];
            let stale: Vec<usize> = (0..rims.pieces.len())
                .filter(|&k| state.rim_made[i][k] != stamp(rims.pieces[k]))
                .collect();
            if !stale.is_empty() {
                let known = self.every_geometry(geometry);
                let pieces: Vec<Option<usize>> = stale.iter().map(|&k| rims.pieces[k]).collect();
                let lists = self.rim_pieces(i, &known, &pieces, |_| None);
                for (&k, list) in stale.iter().zip(lists) {
                    rims.lists[k] = list;
                    state.rim_made[i][k] = stamp(rims.pieces[k]);
                }
            }
            #[cfg(test)]
            if self.check_rim_pieces {
                self.kept_rim_pieces += rims.pieces.len() - stale.len();
                let known = self.every_geometry(geometry);
                let made = self.rim_pieces(i, &known, &rims.pieces, |_| None);
                assert_eq!(rims.lists, made, "organ {i}'s kept rim pieces");
            }
            let list: Vec<Contact> = rims.all().copied().collect();
            let pushed = push_back(&mut self.organs[i].positions, &list, &mut state.moved[i]);
            let mut clear = state.rim_clear[i];
            state.pushed(i, pushed, geometry, &mut clear, all_pushes);
            state.rim_clear[i] = clear;
            pushed_in_pass += pushed;
        }
        pushed_in_pass
    }
}

#[cfg(test)]
mod tests {
    use crate::fixtures::inner_driven_into_outer_by;
    use crate::{Selection, Simulation};

    #[test]
    fn the_rim_pieces_the_push_back_keeps_are_those_it_would_make_again() {
        // The inner petal driven into the outer one: the push-back moves
        // one at a time, so pieces of the other are kept. Each kept piece
        // is compared with one made again where the organs are.
        let mut sim = Simulation::new(&inner_driven_into_outer_by(12, true, 40.0), &Selection::All)
            .expect("valid");
        sim.check_rim_pieces = true;
        while !sim.finished() {
            sim.step(&|| false, &mut |_| {}).expect("the run goes on");
        }
        assert!(
            sim.kept_rim_pieces > 0,
            "the push-back kept no rim piece: the test shows nothing"
        );
    }
}

//! Phase 5: the checks that end a keyframe. No organ's energy blew up,
//! and no triangle of an organ crosses another organ's, a part's or its
//! own (see [`crate::crossing`]).

use anthesis_mesh::crossing::{Body, Crossing};

use super::search::Found;
use crate::crossing::{Crossed, Crossings, OnCrossing};
use crate::organ::OrganSim;
use crate::{SimError, Simulation};
use rayon::prelude::*;

impl Simulation {
    /// Every organ's energy where it settled, checked against a blow-up
    /// (not finite, or a million-fold rise over the last keyframe; `found`
    /// names what held the organ), and kept for the next keyframe's check.
    /// Returns their sum.
    pub(crate) fn check_energies(&mut self, step: u32, found: &Found) -> Result<f64, SimError> {
        let mut energy = 0.0;
        let energies: Vec<f64> = self.organs.par_iter().map(OrganSim::energy).collect();
        for (i, (organ, &e)) in self.organs.iter().zip(&energies).enumerate() {
            if !e.is_finite()
                || (self.previous_energy[i] > 0.0
                    && e > 1e6 * self.previous_energy[i].max(organ.energy_floor()))
            {
                return Err(SimError::EnergyBlowUp {
                    keyframe: step,
                    organ: organ.name.clone(),
                    energy: e,
                    previous: self.previous_energy[i],
                    held_against: self.held_against(found, i),
                    values: self.values_out_of_range(i),
                });
            }
            self.previous_energy[i] = e;
            energy += e;
        }
        Ok(energy)
    }

    /// No silent crossing (see [`crate::crossing`]): stops the run at a
    /// keyframe with crossing triangles, or keeps what was found, or does
    /// not look, as the caller chose.
    pub(crate) fn check_crossings(&mut self, step: u32) -> Result<(), SimError> {
        let on_crossing = self.on_crossing;
        if on_crossing == OnCrossing::Skip {
            return Ok(());
        }
        if let Some(crossings) = self.find_crossings(step) {
            if on_crossing == OnCrossing::Stop {
                return Err(SimError::Crossed(Box::new(crossings)));
            }
            self.crossings.push(crossings);
        }
        Ok(())
    }

    /// Where the triangles of the organs where they are now cross each
    /// other, themselves or the parts at step `step`'s pose, if anywhere.
    pub(crate) fn find_crossings(&mut self, step: u32) -> Option<Crossings> {
        let organs = self.organs.len();
        let found = self.search_crossings(step, false);
        if found.is_empty() {
            return None;
        }
        let side = |body: u32, triangle: u32, at: [f64; 3]| {
            let body = body as usize;
            match self.organs.get(body) {
                Some(o) => {
                    let corners = o.mesh.triangles[triangle as usize];
                    let uv = (0..3)
                        .map(|k| o.mesh.uvs[corners[k] as usize] * at[k])
                        .sum::<glam::DVec2>();
                    Crossed::Organ {
                        index: body,
                        name: o.name.clone(),
                        uv,
                    }
                }
                None => Crossed::Part {
                    name: self.obstacles[body - organs].name().to_string(),
                },
            }
        };
        let mut between: Vec<((u32, u32), Crossed, Crossed, usize)> = Vec::new();
        for c in &found {
            let key = (c.a.body, c.b.body);
            match between.iter_mut().find(|(k, ..)| *k == key) {
                Some((_, _, _, n)) => *n += 1,
                None => between.push((
                    key,
                    side(c.a.body, c.a.triangle, c.at_a),
                    side(c.b.body, c.b.triangle, c.at_b),
                    1,
                )),
            }
        }
        let mut crossing_organs: Vec<usize> = found
            .iter()
            .flat_map(|c| [c.a.body as usize, c.b.body as usize])
            .filter(|&b| b < organs)
            .collect();
        crossing_organs.sort_unstable();
        crossing_organs.dedup();
        // The first keyframe after the bud: do they cross there already?
        let from_bud = step == 1 && {
            let in_bud = self.crossing_pairs_in_bud();
            between.iter().any(|(key, ..)| in_bud.contains(key))
        };
        Some(Crossings {
            keyframe: step,
            pairs: found.len(),
            between: between.into_iter().map(|(_, a, b, n)| (a, b, n)).collect(),
            organs: crossing_organs,
            from_bud,
        })
    }

    /// The pairs of bodies (organs, then parts, as in
    /// [`Simulation::find_crossings`]) that cross in the bud, at keyframe
    /// 0's pose; the parts are put back at keyframe 1's after.
    fn crossing_pairs_in_bud(&mut self) -> Vec<(u32, u32)> {
        let mut pairs: Vec<(u32, u32)> = self
            .search_crossings(0, true)
            .iter()
            .map(|c| (c.a.body, c.b.body))
            .collect();
        pairs.dedup();
        for obstacle in &mut self.obstacles {
            obstacle.move_to(1);
        }
        pairs
    }

    /// Every crossing among the organs (where they are, or in the bud if
    /// `in_bud`) and the parts at step `step`'s pose; bodies are the
    /// organs, then the parts.
    fn search_crossings(&mut self, step: u32, in_bud: bool) -> Vec<Crossing> {
        for obstacle in &mut self.obstacles {
            obstacle.move_to(step);
        }
        let organs = self.organs.len();
        let bodies: Vec<Body<'_>> = self
            .organs
            .iter()
            .map(|o| Body {
                positions: if in_bud { &o.initial } else { &o.positions },
                triangles: &o.mesh.triangles,
            })
            .chain(self.obstacles.iter().map(|o| {
                let s = o.surface();
                Body {
                    positions: s.positions,
                    triangles: s.triangles,
                }
            }))
            .collect();
        // Parts against parts are not tested: they overlap by design.
        self.crossing_search
            .find(&bodies, &|i, j| i.min(j) < organs)
    }
}

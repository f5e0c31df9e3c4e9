//! Where a flower's organs go, as data: whorls, contorted whorls and
//! golden-angle spirals on the receptacle ([`whorl`]), and the bracketed
//! parametric L-systems and turtle of Qin and Chen 2006 §2–§3
//! ([`lsystem`], [`turtle`]). A project's `[structure]` is one of them
//! ([`Structure`]); its organs and overlap rules are made when the project
//! loads ([`Structure::arrange`]).

pub mod lsystem;
pub mod turtle;
pub mod whorl;

use std::collections::BTreeMap;

use glam::{DMat3, DQuat, DVec3};
use thiserror::Error;

use crate::{Organ, Overlap, Placement, Template};
use lsystem::{LSystem, LSystemError};
use turtle::{Defaults, interpret};
pub use whorl::{Arrangement, GOLDEN_ANGLE_DEG, MAX_OVERLAP_RULES, Spiral, Whorl};

/// The most organs a structure may make (whorls, a spiral or an L-system),
/// checked before any is made: a real flower has tens, a dense
/// inflorescence hundreds; an L-system's `~X` can otherwise place up to
/// [`lsystem::MAX_MODULES`].
pub const MAX_STRUCTURE_ORGANS: usize = 10_000;

/// How far an organ may reach from its base, in multiples of its bud's
/// reach, when an L-system's overlap rules are made: organs whose reaches
/// never meet get no rule (they grow, so the bud's reach alone is too
/// short).
const REACH_GROWTH: f64 = 3.0;

/// The most pairs of L-system organs within reach of each other that are
/// looked at for overlap rules (organs piled on one spot would otherwise
/// make the work grow with the square of their number).
const MAX_NEAR_PAIRS: usize = 10 * MAX_OVERLAP_RULES;

/// Where a project's organs come from, besides those it lists one by one.
#[derive(Debug, Clone, PartialEq)]
pub enum Structure {
    /// Rings of identical organs, innermost first; every organ lies inside
    /// the organs of outer rings whose spans it meets. `contorted`: one ring
    /// whose organs each lie beneath their right-hand neighbour (Eustoma).
    Whorls {
        /// The rings, innermost first.
        whorls: Vec<Whorl>,
        /// One contorted ring instead of nested ones.
        contorted: bool,
    },
    /// A phyllotactic spiral; earlier (outer) organs lie outside later ones
    /// whose spans they meet.
    Spiral(Spiral),
    /// An L-system: every `~X` of the derived word places an organ of the
    /// template `surfaces[X]` at the turtle's position and frame.
    LSystem {
        /// The L-system's text (see [`lsystem`]).
        text: String,
        /// Derivation steps.
        steps: u32,
        /// The template (index) each surface letter places.
        surfaces: BTreeMap<char, usize>,
        /// Project length units per turtle unit (1 by default): every
        /// position and line width the turtle draws is multiplied by it,
        /// so an L-system written in its author's units (the seed's apple
        /// flower: a stem of 500, lines 20 wide) places organs made in the
        /// project's. Organ shapes are not scaled; a `~X(s)` scale is
        /// still refused.
        units: f64,
    },
}

/// Why a structure gives no organs.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum StructureError {
    /// The L-system does not parse or derive.
    #[error(transparent)]
    LSystem(#[from] LSystemError),
    /// A `~X` names a surface no template is given for.
    #[error(
        "the L-system places surface `{0}`, but [structure.lsystem.surfaces] names no template for it"
    )]
    UnknownSurface(char),
    /// A `~X(s)` with `s` other than 1: a growing organ cannot be scaled yet.
    #[error(
        "the L-system scales surface `{surface}` by {scale}; organs can only be placed at scale 1 for now (scale the template's mesh instead)"
    )]
    Scaled {
        /// The surface letter.
        surface: char,
        /// The scale asked for.
        scale: f64,
    },
    /// A contorted ring whose neighbours do not overlap, or where organs two
    /// apart would overlap too.
    #[error(
        "the contorted whorl `{0}` needs neighbours whose spans meet and organs two apart whose spans do not"
    )]
    Contorted(String),
    /// The structure makes more organs than [`MAX_STRUCTURE_ORGANS`].
    #[error(
        "the structure makes {count} organs; at most {MAX_STRUCTURE_ORGANS} are allowed (use fewer organs, fewer derivation steps or a smaller count)"
    )]
    TooManyOrgans {
        /// How many it would make (at least; counting stopped there).
        count: usize,
    },
    /// The structure's organs would need more overlap rules than
    /// [`MAX_OVERLAP_RULES`], or (an L-system) more organs lie within reach
    /// of one another than can be looked at.
    #[error(
        "the structure's organs meet in more than {limit} pairs (overlap rules); spread them out, narrow their spans or use fewer organs"
    )]
    TooManyOverlaps {
        /// The limit that was passed.
        limit: usize,
    },
    /// A whorl or spiral names a template index that does not exist.
    #[error("the structure uses template {index}, but there are {count} templates")]
    NoTemplate {
        /// The index.
        index: usize,
        /// How many templates there are.
        count: usize,
    },
}

impl Structure {
    /// The organs and overlap rules the structure makes, for a project with
    /// `templates` (names of L-system organs: `<template>-<k>`, counted per
    /// template from 1).
    pub fn arrange(&self, templates: &[Template]) -> Result<Arrangement, StructureError> {
        let check = |index: usize| {
            if index < templates.len() {
                Ok(())
            } else {
                Err(StructureError::NoTemplate {
                    index,
                    count: templates.len(),
                })
            }
        };
        let check_count = |count: usize| {
            if count > MAX_STRUCTURE_ORGANS {
                Err(StructureError::TooManyOrgans { count })
            } else {
                Ok(())
            }
        };
        let too_many_rules = |_| StructureError::TooManyOverlaps {
            limit: MAX_OVERLAP_RULES,
        };
        match self {
            Structure::Whorls { whorls, contorted } => {
                for w in whorls {
                    check(w.template)?;
                }
                check_count(whorls.iter().fold(0, |n, w| n.saturating_add(w.count)))?;
                match (contorted, whorls.as_slice()) {
                    (true, [ring]) => whorl::contorted_whorl(ring)
                        .ok_or_else(|| StructureError::Contorted(ring.name.clone())),
                    (true, _) => Err(StructureError::Contorted(
                        "(a contorted structure has exactly one whorl)".to_owned(),
                    )),
                    (false, _) => whorl::nested_whorls_within(whorls, MAX_OVERLAP_RULES)
                        .map_err(too_many_rules),
                }
            }
            Structure::Spiral(spiral) => {
                check(spiral.template)?;
                check_count(spiral.count)?;
                whorl::spiral_within(spiral, MAX_OVERLAP_RULES).map_err(too_many_rules)
            }
            Structure::LSystem {
                text,
                steps,
                surfaces,
                units,
            } => {
                for &t in surfaces.values() {
                    check(t)?;
                }
                lsystem_arrangement(text, *steps, surfaces, *units, templates)
            }
        }
    }
}

impl Structure {
    /// The tubes an L-system's `F` segments draw (the stem, branches,
    /// filaments): one per segment of positive length and width, the width
    /// its diameter. None for whorls and spirals, or an L-system that does
    /// not derive (loading refuses those).
    pub fn segments(&self) -> Vec<turtle::Segment> {
        self.tubes().into_iter().map(|(_, s)| s).collect()
    }

    /// [`Structure::segments`] with their names: after what drew them
    /// ([`LSystem::name_of`]: `stem`, `stamen`, or a module's letter), a
    /// name that several tubes share numbered in the word's order
    /// (`stamen-1`, `stamen-2`, …), one that only one tube has left as it
    /// is (`stem`). The same text and steps always give the same names.
    pub fn tubes(&self) -> Vec<(String, turtle::Segment)> {
        let Structure::LSystem {
            text, steps, units, ..
        } = self
        else {
            return Vec::new();
        };
        let Ok(system) = LSystem::parse(text) else {
            return Vec::new();
        };
        let Ok((word, origins)) = system.derive_with_origins(*steps) else {
            return Vec::new();
        };
        let segments: Vec<turtle::Segment> = interpret(&word, &Defaults::of(&system))
            .segments
            .into_iter()
            .map(|s| turtle::Segment {
                start: s.start * *units,
                end: s.end * *units,
                width: s.width * *units,
                ..s
            })
            .filter(|s| s.width > 0.0 && s.width.is_finite() && s.start.distance(s.end) > 1e-9)
            .collect();
        let bases: Vec<&str> = segments
            .iter()
            .map(|s| system.name_of(origins.get(s.module).copied().unwrap_or_default()))
            .collect();
        let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
        for base in &bases {
            *counts.entry(base).or_default() += 1;
        }
        let mut seen: BTreeMap<&str, usize> = BTreeMap::new();
        bases
            .iter()
            .zip(segments)
            .map(|(base, segment)| {
                let k = seen.entry(base).or_default();
                *k += 1;
                let name = if counts[base] == 1 {
                    (*base).to_owned()
                } else {
                    format!("{base}-{k}")
                };
                (name, segment)
            })
            .collect()
    }
}

/// The organs an L-system places, and their overlap rules.
///
/// Decided (the seed gives none): organs of one template form a ring; the
/// templates are layered in the order their first organ appears in the
/// word, the first outermost (the apple's `[C][P][S]`: calyx outside
/// petals; write a lily's sepals before its petals). An organ lies inside
/// each organ of an earlier template whose outer side (template +Z) faces
/// within 90° of its own, as neighbouring organs of two whorls do; pairs
/// that never come near each other cost nothing, as contacts are only
/// looked for where particles meet. Listed `[[overlaps]]` override a pair.
fn lsystem_arrangement(
    text: &str,
    steps: u32,
    surfaces: &BTreeMap<char, usize>,
    units: f64,
    templates: &[Template],
) -> Result<Arrangement, StructureError> {
    let system = LSystem::parse(text)?;
    let word = system.derive(steps)?;
    let count = word.iter().filter(|m| m.symbol.starts_with('~')).count();
    if count > MAX_STRUCTURE_ORGANS {
        return Err(StructureError::TooManyOrgans { count });
    }
    let drawing = interpret(&word, &Defaults::of(&system));
    let mut organs = Vec::new();
    let mut faces: Vec<DVec3> = Vec::new();
    let mut counts = vec![0usize; templates.len()];
    let mut layer_of_template: Vec<Option<usize>> = vec![None; templates.len()];
    let mut layers = 0;
    for placed in &drawing.surfaces {
        let &template = surfaces
            .get(&placed.surface)
            .ok_or(StructureError::UnknownSurface(placed.surface))?;
        if (placed.scale - 1.0).abs() > 1e-12 {
            return Err(StructureError::Scaled {
                surface: placed.surface,
                scale: placed.scale,
            });
        }
        if layer_of_template[template].is_none() {
            layer_of_template[template] = Some(layers);
            layers += 1;
        }
        counts[template] += 1;
        let rotation: DMat3 = placed.template_rotation();
        faces.push(rotation * DVec3::Z);
        organs.push(Organ {
            name: format!("{}-{}", templates[template].name, counts[template]),
            template,
            placement: Placement {
                position: placed.position * units,
                azimuth_deg: 0.0,
                joint_angle_deg: 0.0,
                orientation: DQuat::from_mat3(&rotation).normalize(),
            },
        });
    }
    // Only organs within reach of each other can meet: a grid of cells as
    // wide as the longest reach finds them without looking at every pair.
    let reach_of_template: Vec<f64> = templates
        .iter()
        .map(|t| {
            let bud = t
                .mesh
                .positions
                .iter()
                .map(|p| p.length())
                .fold(0.0, f64::max);
            REACH_GROWTH * bud
        })
        .collect();
    let reach = |i: usize| reach_of_template[organs[i].template];
    let cell = (0..organs.len()).map(reach).fold(0.0, f64::max) * 2.0;
    let grid = Grid::new(
        organs.iter().map(|o| o.placement.position),
        if cell > 0.0 && cell.is_finite() {
            cell
        } else {
            1.0
        },
    );
    let mut overlaps = Vec::new();
    let mut looked_at = 0usize;
    let mut outers = Vec::new();
    for (i, inner) in organs.iter().enumerate() {
        outers.clear();
        for j in grid.near(inner.placement.position) {
            looked_at += 1;
            if looked_at > MAX_NEAR_PAIRS {
                return Err(StructureError::TooManyOverlaps {
                    limit: MAX_NEAR_PAIRS,
                });
            }
            let outer = &organs[j];
            let (li, lj) = (
                layer_of_template[inner.template],
                layer_of_template[outer.template],
            );
            let near =
                inner.placement.position.distance(outer.placement.position) <= reach(i) + reach(j);
            if li > lj && near && faces[i].dot(faces[j]) > 0.0 {
                outers.push(j);
            }
        }
        // The order of the rules as every pair was once looked at: by
        // inner organ, then outer.
        outers.sort_unstable();
        overlaps.extend(outers.iter().map(|&j| Overlap { inner: i, outer: j }));
        if overlaps.len() > MAX_OVERLAP_RULES {
            return Err(StructureError::TooManyOverlaps {
                limit: MAX_OVERLAP_RULES,
            });
        }
    }
    Ok(Arrangement { organs, overlaps })
}

/// Points binned in cubic cells of one size, to find those near a point
/// by looking in its cell and the 26 around it.
struct Grid {
    cell: f64,
    cells: std::collections::HashMap<[i64; 3], Vec<usize>>,
}

impl Grid {
    fn new(points: impl Iterator<Item = DVec3>, cell: f64) -> Grid {
        let mut cells: std::collections::HashMap<[i64; 3], Vec<usize>> =
            std::collections::HashMap::new();
        for (i, p) in points.enumerate() {
            cells.entry(Grid::key(p, cell)).or_default().push(i);
        }
        Grid { cell, cells }
    }

    fn key(p: DVec3, cell: f64) -> [i64; 3] {
        // `as` saturates: points beyond ±9e18 cells share the outermost.
        let k = (p / cell).floor();
        [k.x as i64, k.y as i64, k.z as i64]
    }

    /// The points in `p`'s cell and its neighbours (each once).
    fn near(&self, p: DVec3) -> impl Iterator<Item = usize> + '_ {
        let [x, y, z] = Grid::key(p, self.cell);
        let mut keys = Vec::with_capacity(27);
        for dx in -1..=1i64 {
            for dy in -1..=1i64 {
                for dz in -1..=1i64 {
                    let key = [
                        x.saturating_add(dx),
                        y.saturating_add(dy),
                        z.saturating_add(dz),
                    ];
                    // Saturated keys repeat at the edges of the range.
                    if !keys.contains(&key) {
                        keys.push(key);
                    }
                }
            }
        }
        keys.into_iter()
            .filter_map(|key| self.cells.get(&key))
            .flatten()
            .copied()
    }
}

#[cfg(test)]
mod tests;

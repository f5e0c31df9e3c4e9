//! Editing a flower's organs as data: what the app's Flower panel does to
//! a [`Flower`], as functions that return the edited flower or say why
//! the edit cannot be made (the flower is left as it was).
//!
//! A flower's organs are the ones its [`Structure`] makes, then the ones
//! listed one by one; its overlap rules are the structure's, with listed
//! rules overriding a made pair (as a project file's `[[overlaps]]` do).
//! Every edit here keeps that shape: it takes the listed organs and the
//! listed rules (by organ name), changes the structure, the templates or
//! the listed organs, and makes the organs and rules again. A listed rule
//! whose organs are gone is dropped.

use std::collections::BTreeMap;

use thiserror::Error;

use crate::structure::whorl::placement;
use crate::structure::{Arrangement, GOLDEN_ANGLE_DEG, Spiral, Structure, StructureError, Whorl};
use crate::{Flower, Organ, Overlap, Template};

/// Why an edit of a flower was refused.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum EditError {
    /// The structure makes no organs (an L-system error, an unknown
    /// surface, a contorted whorl that cannot be).
    #[error(transparent)]
    Structure(#[from] StructureError),
    /// Two organs would have the same name.
    #[error("two organs would be called \"{0}\"; rename a whorl or the organ")]
    DuplicateOrgan(String),
    /// The edit would leave the flower without organs.
    #[error("a flower needs at least one organ")]
    NoOrgans,
    /// A template name that is empty or taken.
    #[error("a template name must be new and not empty: \"{0}\"")]
    TemplateName(String),
    /// The edit would leave the flower without templates.
    #[error("a flower needs at least one template")]
    NoTemplates,
    /// The organ is made by the structure: change the structure instead.
    #[error("organ \"{0}\" is made by the arrangement: change the arrangement to remove it")]
    MadeByStructure(String),
    /// A new template's mesh is not in the project's unit of length.
    #[error("{0}")]
    Scale(Box<crate::scale::ScaleMismatch>),
    /// A shape that cannot be bent or made.
    #[error("{0}")]
    Shape(anthesis_bud::BudError),
    /// A spiral of one template would replace organs of another.
    #[error(
        "the flower has organs of other templates (\"{0}\"); a spiral of one template would \
         replace them: place the petals where the arrangement puts them instead"
    )]
    OtherOrgans(String),
    /// An index that does not exist.
    #[error("there is no {what} {index}")]
    Missing {
        /// What was looked for ("template", "organ", "overlap").
        what: &'static str,
        /// The index.
        index: usize,
    },
}

/// Where an overlap rule of a flower comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RuleOrigin {
    /// The structure makes it.
    Made,
    /// Listed, the other way round from the rule the structure makes for
    /// the pair.
    Overridden,
    /// Listed, for a pair the structure makes no rule for.
    Listed,
}

/// A flower's listed organs and listed rules (by organ name).
struct Listed {
    organs: Vec<Organ>,
    rules: Vec<(String, String)>,
}

impl Flower {
    /// What the flower's structure makes now (nothing without a structure,
    /// or when it no longer arranges, which loading and every edit here
    /// refuse).
    pub fn made(&self) -> Arrangement {
        self.structure
            .as_ref()
            .and_then(|s| s.arrange(&self.templates).ok())
            .unwrap_or_default()
    }

    /// How many of the first organs the structure makes; the rest are
    /// listed.
    pub fn made_organ_count(&self) -> usize {
        self.made().organs.len().min(self.organs.len())
    }

    /// Where each of [`Flower::overlaps`] comes from.
    pub fn rule_origins(&self) -> Vec<RuleOrigin> {
        let made = self.made();
        self.overlaps
            .iter()
            .map(|o| {
                let reversed = Overlap {
                    inner: o.outer,
                    outer: o.inner,
                };
                if made.overlaps.contains(o) {
                    RuleOrigin::Made
                } else if made.overlaps.contains(&reversed) {
                    RuleOrigin::Overridden
                } else {
                    RuleOrigin::Listed
                }
            })
            .collect()
    }

    fn listed(&self) -> Listed {
        let made = self.made();
        let start = made.organs.len().min(self.organs.len());
        let name = |i: usize| self.organs.get(i).map(|o| o.name.clone());
        Listed {
            organs: self.organs[start..].to_vec(),
            rules: self
                .overlaps
                .iter()
                .filter(|o| !made.overlaps.contains(o))
                .filter_map(|o| Some((name(o.inner)?, name(o.outer)?)))
                .collect(),
        }
    }

    /// `self` with its organs and rules made again from its structure and
    /// templates, then `listed`.
    fn remade(mut self, listed: Listed) -> Result<Flower, EditError> {
        if self.templates.is_empty() {
            return Err(EditError::NoTemplates);
        }
        let made = match &self.structure {
            Some(structure) => structure.arrange(&self.templates)?,
            None => Arrangement::default(),
        };
        let mut organs = made.organs;
        organs.extend(
            listed
                .organs
                .into_iter()
                .filter(|o| o.template < self.templates.len()),
        );
        if organs.is_empty() {
            return Err(EditError::NoOrgans);
        }
        for (i, organ) in organs.iter().enumerate() {
            if organs[..i].iter().any(|o| o.name == organ.name) {
                return Err(EditError::DuplicateOrgan(organ.name.clone()));
            }
        }
        let index = |name: &str| organs.iter().position(|o| o.name == name);
        let mut overlaps = made.overlaps;
        for (inner, outer) in &listed.rules {
            let (Some(inner), Some(outer)) = (index(inner), index(outer)) else {
                continue;
            };
            if inner == outer {
                continue;
            }
            let rule = Overlap { inner, outer };
            overlaps.retain(|o| !(o.inner == outer && o.outer == inner));
            if !overlaps.contains(&rule) {
                overlaps.push(rule);
            }
        }
        self.organs = organs;
        self.overlaps = overlaps;
        Ok(self)
    }

    /// The flower with `structure` in place of its own; the listed organs
    /// and rules stay. `None` keeps every organ and rule as they are now,
    /// all listed.
    pub fn with_structure(&self, structure: Option<Structure>) -> Result<Flower, EditError> {
        let Some(structure) = structure else {
            return Ok(Flower {
                structure: None,
                ..self.clone()
            });
        };
        let listed = self.listed();
        Flower {
            structure: Some(structure),
            ..self.clone()
        }
        .remade(listed)
    }

    /// The flower arranged by `structure` alone: its organs and rules
    /// replace all of the flower's (choosing another kind of arrangement).
    pub fn arranged_by(&self, structure: Structure) -> Result<Flower, EditError> {
        Flower {
            structure: Some(structure),
            ..self.clone()
        }
        .remade(Listed {
            organs: Vec::new(),
            rules: Vec::new(),
        })
    }

    /// The flower with `template` added (renamed `<name> 2`, … if its name
    /// is taken). No organ uses it yet.
    pub fn with_template(&self, mut template: Template) -> Flower {
        template.name = unique_name(&template.name, |n| {
            self.templates.iter().any(|t| t.name == n)
        });
        let mut flower = self.clone();
        flower.templates.push(template);
        flower
    }

    /// The flower with `template` added (renamed as [`Flower::with_template`]
    /// does) and one listed organ of it, placed as [`Flower::new_organ`]
    /// places one: a shape made in the app (an imported OBJ, a Bézier
    /// petal) becomes a visible organ at once. Refused when the template's
    /// mesh does not fit its thickness (a mesh in another unit, see
    /// [`crate::scale::check_template`]).
    pub fn with_template_and_organ(&self, template: Template) -> Result<Flower, EditError> {
        if let Some(mismatch) = crate::scale::check_template(&template) {
            return Err(EditError::Scale(Box::new(mismatch)));
        }
        let added = self.with_template(template);
        let index = added.templates.len() - 1;
        let organ = added.new_organ(index).ok_or(EditError::Missing {
            what: "template",
            index,
        })?;
        added.with_organ(organ)
    }

    /// The flower with template `index` given a new shape: `mesh`, made
    /// from `source` in an editor, wound like the mesh it replaces (a
    /// flipped inner side stays flipped) and bent along the template's
    /// vein when it has one ([`Template::shaped`]: a sketched bud keeps
    /// its bend). The maps stay: they live in UV space.
    pub fn with_shape(
        &self,
        index: usize,
        mesh: anthesis_mesh::Mesh,
        source: crate::TemplateSource,
    ) -> Result<Flower, EditError> {
        let template = self.templates.get(index).ok_or(EditError::Missing {
            what: "template",
            index,
        })?;
        let mesh = if anthesis_bud::inner_side_faces_minus_z(&template.mesh) == Some(false) {
            anthesis_bud::with_inner_side_flipped(&mesh)
        } else {
            mesh
        };
        let mesh = template.shaped(mesh).map_err(EditError::Shape)?;
        let mut flower = self.clone();
        flower.templates[index].mesh = mesh;
        flower.templates[index].source = Some(source);
        Ok(flower)
    }

    /// The flower with template `index` called `name`. Organs an L-system
    /// names after their template are renamed with it, and the listed
    /// rules that name them follow.
    pub fn with_template_renamed(&self, index: usize, name: &str) -> Result<Flower, EditError> {
        let name = name.trim();
        if index >= self.templates.len() {
            return Err(EditError::Missing {
                what: "template",
                index,
            });
        }
        let taken = self
            .templates
            .iter()
            .enumerate()
            .any(|(i, t)| i != index && t.name == name);
        if name.is_empty() || taken {
            return Err(EditError::TemplateName(name.to_string()));
        }
        let before = self.made();
        let mut listed = self.listed();
        let mut flower = self.clone();
        flower.templates[index].name = name.to_string();
        let after = match &flower.structure {
            Some(structure) => structure.arrange(&flower.templates)?,
            None => Arrangement::default(),
        };
        for (old, new) in before.organs.iter().zip(&after.organs) {
            for rule in &mut listed.rules {
                for end in [&mut rule.0, &mut rule.1] {
                    if *end == old.name {
                        end.clone_from(&new.name);
                    }
                }
            }
        }
        flower.remade(listed)
    }

    /// The flower without template `index`: its listed organs go, and the
    /// whorls, spiral or L-system surfaces that use it (refused when that
    /// leaves no organ, or an L-system that still places its surface).
    pub fn without_template(&self, index: usize) -> Result<Flower, EditError> {
        if index >= self.templates.len() {
            return Err(EditError::Missing {
                what: "template",
                index,
            });
        }
        if self.templates.len() == 1 {
            return Err(EditError::NoTemplates);
        }
        let mut listed = self.listed();
        listed.organs.retain(|o| o.template != index);
        for organ in &mut listed.organs {
            if organ.template > index {
                organ.template -= 1;
            }
        }
        let shift = |t: usize| if t > index { t - 1 } else { t };
        let structure = match &self.structure {
            None => None,
            Some(Structure::Whorls { whorls, contorted }) => {
                let whorls: Vec<Whorl> = whorls
                    .iter()
                    .filter(|w| w.template != index)
                    .map(|w| Whorl {
                        template: shift(w.template),
                        ..w.clone()
                    })
                    .collect();
                (!whorls.is_empty()).then_some(Structure::Whorls {
                    whorls,
                    contorted: *contorted,
                })
            }
            Some(Structure::Spiral(spiral)) => (spiral.template != index).then(|| {
                Structure::Spiral(Spiral {
                    template: shift(spiral.template),
                    ..spiral.clone()
                })
            }),
            Some(Structure::LSystem {
                text,
                steps,
                surfaces,
                units,
            }) => Some(Structure::LSystem {
                text: text.clone(),
                steps: *steps,
                units: *units,
                surfaces: surfaces
                    .iter()
                    .filter(|(_, t)| **t != index)
                    .map(|(letter, t)| (*letter, shift(*t)))
                    .collect(),
            }),
        };
        let mut flower = self.clone();
        flower.templates.remove(index);
        flower.structure = structure;
        flower.remade(listed)
    }

    /// The flower with `organ` listed after its other organs (renamed
    /// `<name> 2`, … if its name is taken).
    pub fn with_organ(&self, mut organ: Organ) -> Result<Flower, EditError> {
        if organ.template >= self.templates.len() {
            return Err(EditError::Missing {
                what: "template",
                index: organ.template,
            });
        }
        organ.name = unique_name(&organ.name, |n| self.organs.iter().any(|o| o.name == n));
        let mut listed = self.listed();
        listed.organs.push(organ);
        self.clone().remade(listed)
    }

    /// A new organ of template `template`, placed like the flower's last
    /// organ of that template turned a little further round (or at the
    /// distance of the organs from the axis, facing +Z, when it has none),
    /// named `<template>-<n>`.
    pub fn new_organ(&self, template: usize) -> Option<Organ> {
        let name = &self.templates.get(template)?.name;
        let placement = match self.organs.iter().rev().find(|o| o.template == template) {
            Some(last) => {
                let p = &last.placement;
                let radius = p.position.x.hypot(p.position.z);
                let azimuth = p.azimuth_deg + 30.0;
                crate::Placement {
                    orientation: p.orientation,
                    ..placement(azimuth, radius, p.position.y, p.joint_angle_deg)
                }
            }
            None => {
                let radius = self
                    .organs
                    .iter()
                    .map(|o| o.placement.position.x.hypot(o.placement.position.z))
                    .fold(0.0, f64::max);
                placement(0.0, radius, 0.0, 0.0)
            }
        };
        let count = self
            .organs
            .iter()
            .filter(|o| o.template == template)
            .count();
        Some(Organ {
            name: unique_name(&format!("{name}-{}", count + 1), |n| {
                self.organs.iter().any(|o| o.name == n)
            }),
            template,
            placement,
        })
    }

    /// The flower without listed organ `index` and its rules (an organ the
    /// structure makes is refused: change the structure).
    pub fn without_organ(&self, index: usize) -> Result<Flower, EditError> {
        let Some(organ) = self.organs.get(index) else {
            return Err(EditError::Missing {
                what: "organ",
                index,
            });
        };
        if index < self.made_organ_count() {
            return Err(EditError::MadeByStructure(organ.name.clone()));
        }
        let mut listed = self.listed();
        listed.organs.retain(|o| o.name != organ.name);
        self.clone().remade(listed)
    }

    /// The flower with listed organ `index` replaced by `organ` (its name
    /// kept unique; rules naming the old name follow it).
    pub fn with_organ_changed(&self, index: usize, organ: Organ) -> Result<Flower, EditError> {
        let Some(old) = self.organs.get(index) else {
            return Err(EditError::Missing {
                what: "organ",
                index,
            });
        };
        if index < self.made_organ_count() {
            return Err(EditError::MadeByStructure(old.name.clone()));
        }
        let mut listed = self.listed();
        for rule in &mut listed.rules {
            for name in [&mut rule.0, &mut rule.1] {
                if *name == old.name {
                    name.clone_from(&organ.name);
                }
            }
        }
        for listed_organ in &mut listed.organs {
            if listed_organ.name == old.name {
                *listed_organ = organ.clone();
            }
        }
        self.clone().remade(listed)
    }

    /// The flower with overlap rule `index` the other way round (which
    /// organ lies inside which); a listed rule that undoes an override
    /// goes back to the made one.
    pub fn with_rule_swapped(&self, index: usize) -> Result<Flower, EditError> {
        let Some(rule) = self.overlaps.get(index).copied() else {
            return Err(EditError::Missing {
                what: "overlap",
                index,
            });
        };
        let name = |i: usize| {
            self.organs
                .get(i)
                .map(|o| o.name.clone())
                .ok_or(EditError::Missing {
                    what: "organ",
                    index: i,
                })
        };
        let (inner, outer) = (name(rule.inner)?, name(rule.outer)?);
        let swapped = Overlap {
            inner: rule.outer,
            outer: rule.inner,
        };
        // The rule is no longer listed; the swapped one is, unless it is
        // the structure's own (back to the made rule). Remade as loading
        // makes them, so the rules come in the order a saved file gives.
        let mut listed = self.listed();
        listed.rules.retain(|(a, b)| !(*a == inner && *b == outer));
        if !self.made().overlaps.contains(&swapped) {
            listed.rules.push((outer, inner));
        }
        self.clone().remade(listed)
    }
}

/// `base`, or `base 2`, `base 3`, … the first that `taken` refuses.
pub fn unique_name(base: &str, taken: impl Fn(&str) -> bool) -> String {
    if !taken(base) {
        return base.to_string();
    }
    (2..)
        .map(|n| format!("{base} {n}"))
        .find(|name| !taken(name))
        .unwrap_or_else(|| base.to_string())
}

/// The flower's organs as whorls: its own when its structure is whorls;
/// otherwise one whorl per template that has organs, as many organs as it
/// has, at their mean distance from the axis and height, from the first
/// one's azimuth and joint angle, spanning a little more than their share
/// of the circle; innermost first. For choosing whorls (or a spiral or an
/// L-system made from them) in place of another arrangement.
pub fn whorls_like(flower: &Flower) -> Vec<Whorl> {
    if let Some(Structure::Whorls { whorls, .. }) = &flower.structure {
        return whorls.clone();
    }
    let mut whorls: Vec<Whorl> = flower
        .templates
        .iter()
        .enumerate()
        .filter_map(|(t, template)| {
            let organs: Vec<&Organ> = flower.organs.iter().filter(|o| o.template == t).collect();
            let first = organs.first()?;
            let n = organs.len() as f64;
            let radius = organs
                .iter()
                .map(|o| o.placement.position.x.hypot(o.placement.position.z))
                .sum::<f64>()
                / n;
            let height = organs.iter().map(|o| o.placement.position.y).sum::<f64>() / n;
            Some(Whorl {
                name: template.name.clone(),
                template: t,
                count: organs.len(),
                offset_deg: first.placement.azimuth_deg,
                radius,
                height,
                joint_angle_deg: first.placement.joint_angle_deg,
                half_span_deg: (0.55 * 360.0 / n).min(179.0),
            })
        })
        .collect();
    whorls.sort_by(|a, b| a.radius.total_cmp(&b.radius));
    whorls
}

/// A spiral with the organs of `whorls` (their count, their first
/// template, the outermost whorl's radius and height), for choosing a
/// spiral in place of whorls.
pub fn spiral_like(whorls: &[Whorl]) -> Option<Spiral> {
    let outer = whorls.last()?;
    let count: usize = whorls.iter().map(|w| w.count).sum();
    let inner = whorls.first()?;
    let steps = count.saturating_sub(1).max(1) as f64;
    Some(Spiral {
        name: outer.name.clone(),
        template: outer.template,
        count,
        divergence_deg: GOLDEN_ANGLE_DEG,
        first_radius: outer.radius,
        first_height: outer.height,
        radius_step: ((outer.radius - inner.radius) / steps).max(0.0),
        height_step: ((inner.height - outer.height) / steps).max(0.0),
        joint_angle_deg: outer.joint_angle_deg,
        half_span_deg: outer.half_span_deg,
    })
}

/// An L-system that places the organs of `whorls` where the whorls do
/// (outermost whorl first, so the overlap order of the L-system, the
/// first template outermost, is the whorls'): its text, its derivation
/// steps and its surfaces (`a` for the first template used, `b` for the
/// next, …). Each whorl is a production `W -> [/(azimuth) O] …` and each
/// organ `O -> f(height) &(90) f(radius) ^(90) &(joint) ~a`: roll to the
/// organ's azimuth, climb to its height, go out to its distance from the
/// axis and tilt by its joint angle. At most 12 whorls (two letters each).
pub fn lsystem_like(whorls: &[Whorl]) -> (String, u32, BTreeMap<char, usize>) {
    let mut surfaces: BTreeMap<char, usize> = BTreeMap::new();
    let mut axiom = Vec::new();
    let mut productions = Vec::new();
    let letters: Vec<char> = ('A'..='Z').filter(|c| *c != 'F').collect();
    for (i, whorl) in whorls.iter().rev().take(12).enumerate() {
        let (ring, organ) = (letters[2 * i], letters[2 * i + 1]);
        let surface = match surfaces.iter().find(|(_, t)| **t == whorl.template) {
            Some((letter, _)) => *letter,
            None => {
                let letter = char::from(b'a' + surfaces.len() as u8);
                surfaces.insert(letter, whorl.template);
                letter
            }
        };
        axiom.push(ring.to_string());
        let organs: Vec<String> = (0..whorl.count)
            .map(|k| format!("[/({}) {organ}]", short(whorl.azimuth_deg(k))))
            .collect();
        productions.push(format!("{ring} -> {}", organs.join(" ")));
        productions.push(format!(
            "{organ} -> f({}) &(90) f({}) ^(90) &({}) ~{surface}",
            short(whorl.height),
            short(whorl.radius),
            short(whorl.joint_angle_deg)
        ));
    }
    let text = format!("axiom: {}\n{}\n", axiom.join(" "), productions.join("\n"));
    (text, 2, surfaces)
}

/// A number as short as it reads exactly enough (four decimals at most).
fn short(x: f64) -> String {
    let rounded = (x * 1e4).round() / 1e4;
    let text = format!("{rounded}");
    if text == "-0" { "0".to_string() } else { text }
}

#[cfg(test)]
mod tests;

//! Whether a template's mesh is in the project's unit of length.
//!
//! Lengths in a project have no unit: a lily made in centimetres and the
//! same lily made in millimetres (meshes, positions, thickness and
//! collision offset all ×10) simulate alike. What breaks is a mesh in one
//! unit dropped into a project in another, as from a tool that works in
//! millimetres: growth bends an organ by a curvature set by its thickness,
//! so a petal ten times too long for its thickness rolls up ten times as
//! far, and the solver gives up at the first keyframe without a word about
//! why. This module catches that before a run.
//!
//! The first test: an organ's length (the longest side of its mesh's
//! bounding box) against its thickness. Real petals and sepals are 10 to
//! 2,000 thicknesses long (a fleshy magnolia tepal about 50, a lily petal
//! about 200 to 400, the thinnest poppy petals about 1,500); the paper's
//! flowers are 220 (lily) and 442 (*Eustoma*). A mesh outside that range is
//! taken to be in another unit, off by the power of ten that brings it
//! nearest to 300 thicknesses.
//!
//! A fleshy organ ten times too large can still be a plausible number of
//! thicknesses long. The second test then looks at where its organs sit:
//! in a bud, an organ's base is about as wide as the spacing to the nearest
//! organ (1.7 to 2.1 times in the lily and *Eustoma*: neighbours overlap),
//! and an organ is a few to a few tens of times as long as its distance
//! from the flower's axis (16 to 25 there, 2 in a wide open whorl). A base
//! [`CROWDED_BASE_IN_SPACINGS`] spacings wide or more on an organ
//! [`LONG_ON_RECEPTACLE`] times its distance from the axis or more (both:
//! either alone happens in real buds) cannot sit in its place; the mesh is
//! taken to be off by the power of ten that brings its base nearest to
//! [`TYPICAL_BASE_IN_SPACINGS`].

use std::fmt;
use std::ops::RangeInclusive;

use anthesis_mesh::Mesh;
use glam::DVec3;

use crate::{Flower, Template};

/// How many thicknesses long an organ may be.
pub const LENGTH_IN_THICKNESSES: RangeInclusive<f64> = 10.0..=2000.0;

/// The organ length, in thicknesses, that a mesh in the right unit is
/// assumed to be near: about the paper's flowers (220 and 442).
const TYPICAL_LENGTH_IN_THICKNESSES: f64 = 300.0;

/// A template whose mesh does not fit its thickness: most likely a mesh in
/// another unit.
#[derive(Debug, Clone, PartialEq)]
pub struct ScaleMismatch {
    /// The template's name.
    pub template: String,
    /// The longest side of the mesh's bounding box, in project units.
    pub length: f64,
    /// The template's thickness, in project units, that the length is
    /// measured against.
    pub thickness: f64,
    /// The power of ten the mesh looks too large by: 10 for a mesh made in
    /// millimetres in a project in centimetres, 0.001 for one made in
    /// metres in a project in millimetres.
    pub factor: f64,
    /// What the mesh was measured against.
    pub against: Against,
}

/// What showed a mesh to be in another unit.
#[derive(Debug, Clone, PartialEq)]
pub enum Against {
    /// The template's thickness (the length is not 10 to 2,000 of it).
    Thickness,
    /// The mesh it is to replace, this long: a mesh ten times the one it
    /// replaces, though still a plausible number of thicknesses long.
    Replaced {
        /// The replaced mesh's length (longest side of its bounding box),
        /// in project units.
        length: f64,
    },
    /// Where one of its organs sits: `organ`'s base is `base_width` wide
    /// (template units, across the organ near its base), the nearest other
    /// organ's base is `spacing` away and the organ sits `from_axis` from
    /// the flower's axis.
    Receptacle {
        /// The organ's name.
        organ: String,
        /// Width of the template's base, across the organ, as the mesh's
        /// numbers give it (the unit in question).
        base_width: f64,
        /// Distance from this organ's base to the nearest other organ's
        /// base, in project units.
        spacing: f64,
        /// Distance of this organ's base from the flower's axis, in project
        /// units.
        from_axis: f64,
    },
}

impl ScaleMismatch {
    /// The mesh scaled by `1 / factor` about the template origin (the
    /// organ's base): the conversion an import can offer.
    pub fn rescaled(&self, mesh: &Mesh) -> Mesh {
        let mut mesh = mesh.clone();
        for p in &mut mesh.positions {
            *p /= self.factor;
        }
        mesh
    }
}

impl fmt::Display for ScaleMismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (low, high) = (LENGTH_IN_THICKNESSES.start(), LENGTH_IN_THICKNESSES.end());
        let size = if self.factor > 1.0 { "large" } else { "small" };
        let times = if self.factor > 1.0 {
            self.factor
        } else {
            1.0 / self.factor
        };
        if let Against::Receptacle {
            organ,
            base_width,
            spacing,
            from_axis,
        } = &self.against
        {
            return write!(
                f,
                "template \"{}\": organ {organ}'s base is {} wide but the nearest organ sits {} \
                 away ({} spacings; in a bud an organ's base is about 2), and the organ is {} \
                 long, {} times its distance {} from the axis. The mesh looks {times:.0} times \
                 too {size}, perhaps {}. Scale the mesh by {}",
                self.template,
                significant(*base_width),
                significant(*spacing),
                significant(base_width / spacing),
                significant(self.length),
                significant(self.length / from_axis),
                significant(*from_axis),
                unit_guess(self.factor),
                anthesis_files::short_number(1.0 / self.factor),
            );
        }
        if let Against::Replaced { length: replaced } = self.against {
            return write!(
                f,
                "template \"{}\": the new mesh is {} long, {} times the {} of the mesh it \
                 replaces. It looks {times:.0} times too {size}, perhaps {}. Scale it by {}",
                self.template,
                significant(self.length),
                significant(self.length / replaced),
                significant(replaced),
                unit_guess(self.factor),
                anthesis_files::short_number(1.0 / self.factor),
            );
        }
        write!(
            f,
            "template \"{}\": its mesh is {} long, {} times its thickness {}, but organs are \
             {low} to {high} thicknesses long. The mesh looks {times:.0} times too {size}, \
             perhaps {}. Scale the mesh by {} (or the thickness by {})",
            self.template,
            significant(self.length),
            significant(self.length / self.thickness),
            anthesis_files::short_number(self.thickness),
            unit_guess(self.factor),
            anthesis_files::short_number(1.0 / self.factor),
            anthesis_files::short_number(self.factor)
        )
    }
}

/// The units a mesh too large (or small) by `factor` was probably made in.
fn unit_guess(factor: f64) -> String {
    let exponent = factor.log10().round() as i32;
    let units = match exponent {
        1 => "millimetres for a project in centimetres",
        2 => "centimetres for a project in metres",
        3 => "millimetres for a project in metres",
        -1 => "centimetres for a project in millimetres",
        -2 => "metres for a project in centimetres",
        -3 => "metres for a project in millimetres",
        e if e > 0 => return format!("made in a unit 1e{e} times smaller than the project's"),
        e => return format!("made in a unit 1e{} times larger than the project's", -e),
    };
    format!("made in {units}")
}

/// `value` with four significant digits and no trailing zeros.
fn significant(value: f64) -> String {
    let digits_before_point = value.abs().log10().floor() as i32 + 1;
    let decimals = (4 - digits_before_point).clamp(0, 12) as usize;
    let text = format!("{value:.decimals$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

/// The longest side of the bounding box of `mesh` (0 for an empty mesh).
pub fn organ_length(mesh: &Mesh) -> f64 {
    let Some(first) = mesh.positions.first() else {
        return 0.0;
    };
    let (low, high) = mesh
        .positions
        .iter()
        .fold((*first, *first), |(low, high), &p| {
            (low.min(p), high.max(p))
        });
    let extent: DVec3 = high - low;
    extent.max_element()
}

/// The mismatch of one template, if its mesh does not fit its thickness.
pub fn check_template(template: &Template) -> Option<ScaleMismatch> {
    check_length(
        &template.name,
        organ_length(&template.mesh),
        template.thickness,
    )
}

/// The mismatch of an organ `length` long and `thickness` thick, if that
/// is not a plausible organ.
fn check_length(template: &str, length: f64, thickness: f64) -> Option<ScaleMismatch> {
    let in_thicknesses = length / thickness;
    if !in_thicknesses.is_finite()
        || in_thicknesses <= 0.0
        || LENGTH_IN_THICKNESSES.contains(&in_thicknesses)
    {
        // Not a question of units: an empty mesh or a thickness of 0 get
        // their own errors elsewhere.
        return None;
    }
    let exponent = (in_thicknesses / TYPICAL_LENGTH_IN_THICKNESSES)
        .log10()
        .round();
    Some(ScaleMismatch {
        template: template.to_string(),
        length,
        thickness,
        factor: 10f64.powf(exponent),
        against: Against::Thickness,
    })
}

/// A mesh that is off from the one it replaces by this close to a power of
/// ten (a factor within 10^±0.2, about ×0.63 to ×1.58 of it) counts as made
/// in another unit; a new petal half or twice as long is a design change.
const UNIT_STEP_TOLERANCE_LOG10: f64 = 0.2;

/// The mismatch of `mesh` put in place of `template`'s mesh: against the
/// mesh it replaces, when the new one is a power of ten (×10, ×100,
/// ×0.001, …) longer or shorter, or else against the template's thickness
/// (as [`check_template`]). A tool working in millimetres for a project in
/// centimetres makes a petal ten times too long that may still be a
/// plausible number of thicknesses long; the mesh it replaces tells.
pub fn check_replacement(template: &Template, mesh: &Mesh) -> Option<ScaleMismatch> {
    let (length, replaced) = (organ_length(mesh), organ_length(&template.mesh));
    let ratio_log10 = (length / replaced).log10();
    let exponent = ratio_log10.round();
    // The mesh it replaces gives the factor exactly (the thickness only to
    // the nearest power of ten of a typical organ).
    if !ratio_log10.is_finite()
        || exponent == 0.0
        || (ratio_log10 - exponent).abs() > UNIT_STEP_TOLERANCE_LOG10
    {
        return check_length(&template.name, length, template.thickness);
    }
    Some(ScaleMismatch {
        template: template.name.clone(),
        length,
        thickness: template.thickness,
        factor: 10f64.powf(exponent),
        against: Against::Replaced { length: replaced },
    })
}

/// An organ's base this many spacings to the nearest organ wide, or more,
/// cannot sit in its place (with [`LONG_ON_RECEPTACLE`]).
pub const CROWDED_BASE_IN_SPACINGS: f64 = 8.0;

/// An organ this many times its distance from the axis long, or more, is
/// too long for where it sits (with [`CROWDED_BASE_IN_SPACINGS`]).
pub const LONG_ON_RECEPTACLE: f64 = 100.0;

/// An organ's base width, in spacings to the nearest organ, in a bud made
/// in one unit (about the lily's 1.9 and *Eustoma*'s 2.1).
const TYPICAL_BASE_IN_SPACINGS: f64 = 2.0;

/// The part of the organ's length, from its lowest point, that counts as
/// its base.
const BASE_PART: f64 = 0.05;

/// The width of `mesh` across the organ (template x) near its base (the
/// lowest [`BASE_PART`] of its length along template y, where organs
/// grow from).
fn base_width(mesh: &Mesh, length: f64) -> f64 {
    let Some(lowest) = mesh.positions.iter().map(|p| p.y).reduce(f64::min) else {
        return 0.0;
    };
    let across = mesh
        .positions
        .iter()
        .filter(|p| p.y <= lowest + BASE_PART * length)
        .map(|p| p.x);
    let (low, high) = across.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
        (lo.min(x), hi.max(x))
    });
    (high - low).max(0.0)
}

/// The mismatch of `template` (index `index`) against where its organs sit
/// in `flower`, if one of them cannot fit there (see the module's notes).
fn check_placement(flower: &Flower, index: usize) -> Option<ScaleMismatch> {
    let template = flower.templates.get(index)?;
    let length = organ_length(&template.mesh);
    let width = base_width(&template.mesh, length);
    let organs = &flower.organs;
    organs
        .iter()
        .enumerate()
        .filter(|(_, organ)| organ.template == index)
        .find_map(|(i, organ)| {
            let at = organ.placement.position;
            let spacing = organs
                .iter()
                .enumerate()
                .filter(|(j, _)| *j != i)
                .map(|(_, other)| (other.placement.position - at).length())
                .reduce(f64::min)?;
            let from_axis = at.x.hypot(at.z);
            // Organs sharing a place, or sitting on the axis, say nothing
            // about units.
            if spacing <= 0.0 || from_axis <= 0.0 {
                return None;
            }
            let crowded = width / spacing;
            if !(crowded >= CROWDED_BASE_IN_SPACINGS && length / from_axis >= LONG_ON_RECEPTACLE) {
                return None;
            }
            let exponent = (crowded / TYPICAL_BASE_IN_SPACINGS)
                .log10()
                .round()
                .max(1.0);
            Some(ScaleMismatch {
                template: template.name.clone(),
                length,
                thickness: template.thickness,
                factor: 10f64.powf(exponent),
                against: Against::Receptacle {
                    organ: organ.name.clone(),
                    base_width: width,
                    spacing,
                    from_axis,
                },
            })
        })
}

/// Every template of `flower` whose mesh does not fit its thickness or,
/// failing that, the place its organs sit in.
pub fn check_flower(flower: &Flower) -> Vec<ScaleMismatch> {
    (0..flower.templates.len())
        .filter_map(|t| check_template(&flower.templates[t]).or_else(|| check_placement(flower, t)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mesh_a_power_of_ten_off_the_one_it_replaces_is_caught_and_converted_back() {
        // 88 thicknesses long: ×10 (880) stays within 10–2000 thicknesses,
        // so only the mesh it replaces tells; ×100, ×0.001 and ×0.1 (8.8)
        // fail the thickness test too.
        let template = petal(1.0, 0.5);
        for scale in [10.0, 100.0, 0.001, 0.1] {
            let mesh = petal(scale, 0.5).mesh;
            let mismatch = check_replacement(&template, &mesh).expect("caught");
            assert!(
                (mismatch.factor - scale).abs() < 1e-9 * scale,
                "{mismatch:?}"
            );
            let back = mismatch.rescaled(&mesh);
            assert!((organ_length(&back) - organ_length(&template.mesh)).abs() < 1e-9);
            let text = mismatch.to_string();
            assert!(text.contains("petal"), "{text}");
        }
        let ten = check_replacement(&template, &petal(10.0, 0.5).mesh).expect("caught");
        assert_eq!(
            check_template(&Template {
                mesh: petal(10.0, 0.5).mesh,
                ..template.clone()
            }),
            None
        );
        assert!(matches!(ten.against, Against::Replaced { .. }));
        let text = ten.to_string();
        assert!(
            text.contains("10 times too large") && text.contains("millimetres"),
            "{text}"
        );
        // A redesign is not a unit: half, one and a half or twice as long.
        for scale in [0.5, 1.0, 1.5, 2.0] {
            assert_eq!(
                check_replacement(&template, &petal(scale, 0.5).mesh),
                None,
                "×{scale}"
            );
        }
    }

    /// A template like the lily petal: a 13 x 44 sheet, thickness 0.2.
    fn petal(scale: f64, thickness: f64) -> Template {
        let mut mesh = anthesis_mesh::generate::test_petal(44.0, 13.0, 9, 17);
        for p in &mut mesh.positions {
            *p *= scale;
        }
        Template {
            dg: 0.003,
            thickness,
            ..crate::test_template("petal", mesh)
        }
    }

    /// Three organs of `template` around a receptacle `radius` from the
    /// axis (as the lily's inner whorl: radius 2).
    fn whorl(template: Template, radius: f64) -> Flower {
        let organs = (0..3)
            .map(|i| {
                let azimuth_deg = 120.0 * f64::from(i);
                let (sin, cos) = azimuth_deg.to_radians().sin_cos();
                crate::Organ {
                    name: format!("petal-{}", i + 1),
                    template: 0,
                    placement: crate::Placement {
                        position: DVec3::new(radius * sin, 0.0, radius * cos),
                        azimuth_deg,
                        joint_angle_deg: 10.0,
                        orientation: glam::DQuat::IDENTITY,
                    },
                }
            })
            .collect();
        Flower {
            templates: vec![template],
            organs,
            overlaps: Vec::new(),
            structure: None,
            parts: Vec::new(),
            unit: None,
        }
    }

    #[test]
    fn a_fleshy_organ_in_another_unit_is_caught_by_where_it_sits() {
        // 88 thicknesses long: ×10 (880) passes the thickness test, so
        // only where its organs sit tells.
        assert_eq!(check_flower(&whorl(petal(1.0, 0.5), 2.0)), Vec::new());
        let flower = whorl(petal(10.0, 0.5), 2.0);
        assert_eq!(check_template(&flower.templates[0]), None, "in range");
        let found = check_flower(&flower);
        let [mismatch] = found.as_slice() else {
            panic!("one mismatch: {found:?}")
        };
        assert_eq!(mismatch.factor, 10.0);
        let Against::Receptacle {
            organ,
            base_width,
            spacing,
            from_axis,
        } = &mismatch.against
        else {
            panic!("{mismatch:?}")
        };
        assert_eq!(organ, "petal-1");
        assert!((spacing - 2.0 * 3f64.sqrt()).abs() < 1e-9, "{spacing}");
        assert!((from_axis - 2.0).abs() < 1e-9);
        // The test petal's base is a quarter of its width (13 × 10).
        assert!((base_width - 32.5).abs() < 1e-9, "{base_width}");
        let text = mismatch.to_string();
        assert!(
            text.contains("organ petal-1's base is")
                && text.contains("10 times too large")
                && text.contains("Scale the mesh by 0.1"),
            "{text}"
        );
        // Converted back, it fits.
        let mut fixed = flower.clone();
        fixed.templates[0].mesh = mismatch.rescaled(&fixed.templates[0].mesh);
        assert_eq!(check_flower(&fixed), Vec::new());
    }

    #[test]
    fn crowded_or_long_alone_and_organs_on_the_axis_are_not_units() {
        // A wide whorl (the test fixtures), a tight one, organs 88 times as
        // long as their distance from the axis with bases four spacings
        // wide: all plausible buds.
        for (scale, radius) in [(1.0, 8.0), (1.0, 1.2), (1.0, 0.5)] {
            let flower = whorl(petal(scale, 0.5), radius);
            assert_eq!(check_flower(&flower), Vec::new(), "×{scale} at {radius}");
        }
        // All organs at the axis, told apart only by their azimuth.
        let flower = whorl(petal(10.0, 0.5), 0.0);
        assert_eq!(check_flower(&flower), Vec::new());
        // The whole project scaled alike (meshes, positions, thickness).
        for scale in [0.01, 10.0, 1000.0] {
            let flower = whorl(petal(scale, 0.5 * scale), 2.0 * scale);
            assert_eq!(check_flower(&flower), Vec::new(), "×{scale}");
        }
    }

    #[test]
    fn a_mesh_in_the_project_unit_fits_at_any_consistent_scale() {
        for scale in [0.001, 0.1, 1.0, 10.0, 1000.0] {
            let template = petal(scale, 0.2 * scale);
            assert_eq!(check_template(&template), None, "scale {scale}");
        }
    }

    #[test]
    fn a_mesh_in_another_unit_names_the_factor() {
        for (scale, factor) in [
            (10.0, 10.0),
            (100.0, 100.0),
            (1000.0, 1000.0),
            (0.001, 0.001),
        ] {
            let mismatch = check_template(&petal(scale, 0.2)).expect("mismatch");
            assert_eq!(mismatch.factor, factor, "scale {scale}");
            assert!((mismatch.length - 44.0 * scale).abs() < 1e-9 * scale);
            // Converting back fits.
            let mut fixed = petal(scale, 0.2);
            fixed.mesh = mismatch.rescaled(&fixed.mesh);
            assert_eq!(check_template(&fixed), None, "scale {scale}");
        }
    }

    #[test]
    fn the_message_says_what_and_how_to_fix_it() {
        let mismatch = check_template(&petal(10.0, 0.2)).expect("mismatch");
        assert_eq!(
            mismatch.to_string(),
            "template \"petal\": its mesh is 440 long, 2200 times its thickness 0.2, but organs \
             are 10 to 2000 thicknesses long. The mesh looks 10 times too large, perhaps made in \
             millimetres for a project in centimetres. Scale the mesh by 0.1 (or the thickness \
             by 10)"
        );
        let mismatch = check_template(&petal(0.001, 0.2)).expect("mismatch");
        let message = mismatch.to_string();
        assert!(
            message.contains(
                "is 0.044 long, 0.22 times its thickness 0.2, but organs are 10 to 2000 thicknesses \
                 long. The mesh looks 1000 times too small, perhaps made in metres for a project \
                 in millimetres. Scale the mesh by 1000"
            ),
            "{message}"
        );
    }
}

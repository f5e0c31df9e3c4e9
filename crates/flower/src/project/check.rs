//! The rules every loaded or saved project obeys.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use anthesis_files::short_number;
use anthesis_maps::{Blend, MapKind};

use super::error::ProjectError;
use crate::{MAX_KEYFRAMES, MIN_BASE_PARTICLES, Project, Template};

/// All raster maps of a template must share one size. 1x1 maps are
/// constants and fit any size. The size most maps have is the right one
/// (the first read wins a tie: `anthesis_maps::common_raster_size`), so the
/// error names the map that differs.
#[derive(Default)]
pub(super) struct SizeCheck {
    maps: Vec<(PathBuf, (u32, u32))>,
}

impl SizeCheck {
    /// Notes the size of the raster map at `path`.
    pub(super) fn add(&mut self, path: &Path, size: (u32, u32)) {
        if size != (1, 1) {
            self.maps.push((path.to_path_buf(), size));
        }
    }

    /// Fails on the first map whose size is not the one most maps have
    /// (`anthesis_maps::common_raster_size`, the rule the app uses too).
    pub(super) fn finish(&self) -> Result<(), ProjectError> {
        let Some(expected) =
            anthesis_maps::common_raster_size(self.maps.iter().map(|(_, size)| *size))
        else {
            return Ok(());
        };
        match self.maps.iter().find(|(_, size)| *size != expected) {
            None => Ok(()),
            Some((path, found)) => Err(ProjectError::MapSize {
                path: path.clone(),
                expected,
                found: *found,
            }),
        }
    }
}

/// The longest template or organ name, in characters.
pub const MAX_NAME_CHARS: usize = 100;

/// Template and organ names are quoted in messages: they must be short and
/// hold no control characters.
pub(super) fn check_names<'a>(
    templates: impl Iterator<Item = &'a str>,
    organs: impl Iterator<Item = &'a str>,
    path: &Path,
) -> Result<(), ProjectError> {
    let named = templates
        .map(|name| ("template", name))
        .chain(organs.map(|name| ("organ", name)));
    for (what, name) in named {
        let problem = if name.chars().count() > MAX_NAME_CHARS {
            format!("is longer than {MAX_NAME_CHARS} characters")
        } else if name.chars().any(char::is_control) {
            "holds a control character".to_string()
        } else {
            continue;
        };
        return Err(ProjectError::Invalid {
            path: path.to_path_buf(),
            message: format!(
                "the {what} name \"{}\" {problem}",
                anthesis_files::excerpt(name, 40)
            ),
        });
    }
    Ok(())
}

pub(super) fn check_unique<'a>(
    names: impl Iterator<Item = &'a str>,
    what: &'static str,
    path: &Path,
) -> Result<(), ProjectError> {
    let mut seen = HashSet::new();
    for name in names {
        if !seen.insert(name) {
            return Err(ProjectError::DuplicateName {
                path: path.to_path_buf(),
                what,
                name: name.to_string(),
            });
        }
    }
    Ok(())
}

/// The rules every loaded or saved project obeys, apart from the mesh and
/// map-size checks, which need the file names.
pub(super) fn check_project(project: &Project, path: &Path) -> Result<(), ProjectError> {
    check_naming(&project.flower, path)?;
    check_settings(&project.settings, path)?;
    check_references(&project.flower, path)
}

/// The error for a project that breaks a rule, with `message` saying which.
fn invalid_at(path: &Path, message: String) -> Result<(), ProjectError> {
    Err(ProjectError::Invalid {
        path: path.to_path_buf(),
        message,
    })
}

/// Names and counts: short clean names, at least one template and organ,
/// no name used twice (exports name a node after every organ and part
/// instance), and parts that are well formed.
fn check_naming(flower: &crate::Flower, path: &Path) -> Result<(), ProjectError> {
    let invalid = |message: String| invalid_at(path, message);
    check_names(
        flower.templates.iter().map(|t| t.name.as_str()),
        flower.organs.iter().map(|o| o.name.as_str()),
        path,
    )?;
    if flower.templates.is_empty() {
        return invalid(
            "the project defines no templates ([[templates]]); is the file cut short?".to_string(),
        );
    }
    if flower.organs.is_empty() {
        return invalid(
            "the project has no organs ([[organs]]); is the file cut short?".to_string(),
        );
    }
    check_unique(
        flower.templates.iter().map(|t| t.name.as_str()),
        "template",
        path,
    )?;
    check_unique(flower.organs.iter().map(|o| o.name.as_str()), "organ", path)?;
    for part in &flower.parts {
        if let Err(message) = part.check() {
            return invalid(message);
        }
    }
    // Exports name a node after every organ and part instance.
    let instances: Vec<String> = flower
        .parts
        .iter()
        .flat_map(|p| (0..p.count).map(|k| p.instance_name(k)))
        .collect();
    check_unique(
        flower
            .organs
            .iter()
            .map(|o| o.name.as_str())
            .chain(instances.iter().map(String::as_str)),
        "organ or part",
        path,
    )?;
    Ok(())
}

/// The `[simulation]` numbers: keyframe count, solver and collision
/// settings, mesh resolution.
fn check_settings(settings: &crate::SimulationSettings, path: &Path) -> Result<(), ProjectError> {
    let invalid = |message: String| invalid_at(path, message);
    if settings.keyframes == 0 {
        return invalid("simulation: keyframes must be at least 1".to_string());
    }
    if settings.keyframes > MAX_KEYFRAMES {
        return invalid(format!(
            "simulation: keyframes is {}, more than the limit of {MAX_KEYFRAMES}",
            settings.keyframes
        ));
    }
    if !(settings.solver.relative_tolerance > 0.0 && settings.solver.relative_tolerance.is_finite())
    {
        return invalid(format!(
            "simulation: relative_tolerance must be a positive number, found {}",
            short_number(settings.solver.relative_tolerance)
        ));
    }
    if settings.solver.max_iterations == 0 {
        return invalid("simulation: max_iterations must be at least 1".to_string());
    }
    if !(settings.collision_offset >= 0.0 && settings.collision_offset.is_finite()) {
        return invalid(format!(
            "simulation: collision_offset must be 0 or more, found {}",
            short_number(settings.collision_offset)
        ));
    }
    if let Some(edge) = settings.resolution.mean_edge()
        && !(edge > 0.0 && edge.is_finite())
    {
        return invalid(format!(
            "simulation: mean_edge must be a positive length, found {}",
            short_number(edge)
        ));
    }
    Ok(())
}

/// Each template's numbers, then every index into the lists: organs name
/// a template that exists and are placed by finite numbers; overlaps name
/// two different organs that exist.
fn check_references(flower: &crate::Flower, path: &Path) -> Result<(), ProjectError> {
    let invalid = |message: String| invalid_at(path, message);
    for template in &flower.templates {
        if let Some(message) = template.problem() {
            return invalid(format!("template \"{}\": {message}", template.name));
        }
    }
    for organ in &flower.organs {
        let placement = &organ.placement;
        if organ.template >= flower.templates.len() {
            return invalid(format!(
                "organ \"{}\" uses template {}, but there are only {} templates",
                organ.name,
                organ.template,
                flower.templates.len()
            ));
        }
        let finite = placement.position.is_finite()
            && placement.azimuth_deg.is_finite()
            && placement.joint_angle_deg.is_finite();
        if !finite {
            return invalid(format!(
                "organ \"{}\": position and angles must be finite numbers",
                organ.name
            ));
        }
    }
    for overlap in &flower.overlaps {
        let count = flower.organs.len();
        if overlap.inner >= count || overlap.outer >= count {
            return invalid(format!(
                "an overlap refers to organ {} or {}, but there are only {count} organs",
                overlap.inner, overlap.outer
            ));
        }
        if overlap.inner == overlap.outer {
            return invalid(format!(
                "organ \"{}\" cannot overlap itself",
                flower.organs[overlap.inner].name
            ));
        }
    }
    Ok(())
}

/// A note when `mesh`'s UVs leave the unit square (a UDIM tile other than
/// 1001, an unwrap scaled past 1): maps and the base region are read over
/// the unit square, so such a layout is held or painted elsewhere than
/// meant.
pub(super) fn uv_outside_unit_square(mesh: &anthesis_mesh::Mesh) -> Option<String> {
    const SLACK: f64 = 1e-6;
    let (lo, hi) = mesh.uvs.iter().fold(
        (
            glam::DVec2::splat(f64::INFINITY),
            glam::DVec2::splat(f64::NEG_INFINITY),
        ),
        |(lo, hi), uv| (lo.min(*uv), hi.max(*uv)),
    );
    if lo.min_element() >= -SLACK && hi.max_element() <= 1.0 + SLACK {
        return None;
    }
    Some(format!(
        "the mesh's UVs span u {} to {}, v {} to {}; the maps and the base region are read over \
         the unit square, u across and v from the base (0) to the tip (1)",
        short_number(lo.x),
        short_number(hi.x),
        short_number(lo.y),
        short_number(hi.y)
    ))
}

/// A note when `template`'s base particles reach more than half way up the
/// organ (+Y in the template frame, from the base at the origin): the UV
/// layout's `v` then runs across or from tip to base, and the organ is
/// held along a margin or at its tip.
pub(super) fn base_not_at_base(template: &Template) -> Option<String> {
    let mesh = &template.mesh;
    let length = mesh.positions.iter().map(|p| p.y).fold(0.0, f64::max);
    let reach = template
        .base_region
        .particles(mesh)
        .iter()
        .map(|&i| mesh.positions[i as usize].y)
        .fold(0.0, f64::max);
    if !(length > 0.0 && reach > 0.5 * length) {
        return None;
    }
    Some(format!(
        "the base region's particles (v <= {}) reach {} up the organ, which is {} long (+Y from \
         the base): the UV layout's v seems not to run from the base (0) to the tip (1), so the \
         organ would be held along its side or tip; u runs across and v along",
        short_number(template.base_region.v_max),
        short_number(reach),
        short_number(length)
    ))
}

impl Template {
    /// What is wrong with this template's numbers, if anything: the one
    /// set of rules that loading, saving, `anthesis info` and the
    /// simulation apply. The mesh itself is checked by
    /// [`anthesis_mesh::validate`].
    pub fn problem(&self) -> Option<String> {
        template_problem(self)
    }
}

/// What is wrong with a two-state animation of `bud`, if anything.
fn two_state_problem(
    animation: &crate::TwoStateAnimation,
    bud: &anthesis_mesh::Mesh,
) -> Option<String> {
    if animation.open.len() != bud.positions.len() {
        return Some(format!(
            "the open shape has {} vertices but the template mesh has {}",
            animation.open.len(),
            bud.positions.len()
        ));
    }
    if let Some(vertex) = animation.open.iter().position(|p| !p.is_finite()) {
        return Some(format!(
            "vertex {} of the open shape is not a finite point",
            vertex + 1
        ));
    }
    let growth = &animation.growth;
    if !(growth.g > 0.0 && growth.g.is_finite()) {
        return Some(format!(
            "g must be a positive number, found {}",
            short_number(growth.g)
        ));
    }
    if !(growth.duration > 0.0 && growth.duration.is_finite()) {
        return Some(format!(
            "duration (T, in keyframes) must be a positive number, found {}",
            short_number(growth.duration)
        ));
    }
    animation.velocity.check().err()
}

/// The rules of [`Template::problem`], phase by phase; the first problem
/// found is the one reported.
fn template_problem(template: &Template) -> Option<String> {
    scale_problem(template)
        .or_else(|| base_region_problem(template))
        .or_else(|| {
            let animation = template.two_state.as_ref()?;
            let problem = two_state_problem(animation, &template.mesh)?;
            Some(format!("two_state: {problem}"))
        })
        .or_else(|| colour_problem(template))
        .or_else(|| schedule_problem(template))
        .or_else(|| map_key_problem(template))
}

/// The growth factor `dg` and the positive scales: thickness and the two
/// stiffnesses.
fn scale_problem(template: &Template) -> Option<String> {
    let positive = |value: f64| value > 0.0 && value.is_finite();
    if !template.dg.is_finite() || template.dg <= -1.0 {
        return Some(format!(
            "dg must be a number greater than -1 (a growth rate 1 + dg × map value must stay \
             positive), found {}",
            short_number(template.dg)
        ));
    }
    let scales = [
        ("thickness", template.thickness),
        ("stretch_stiffness", template.stretch_stiffness),
        ("bend_stiffness", template.bend_stiffness),
    ];
    for (field, value) in scales {
        if !positive(value) {
            return Some(format!(
                "{field} must be greater than 0, found {}",
                short_number(value)
            ));
        }
    }
    None
}

/// The base region: a band of UV space inside the unit square that holds
/// enough particles to attach the organ.
fn base_region_problem(template: &Template) -> Option<String> {
    let region = &template.base_region;
    let in_unit = |value: f64| (0.0..=1.0).contains(&value);
    if !(in_unit(region.v_max) && in_unit(region.u_min) && in_unit(region.u_max)) {
        return Some(format!(
            "base_region v_max, u_min and u_max must lie in [0, 1], found {}, {}, {}",
            short_number(region.v_max),
            short_number(region.u_min),
            short_number(region.u_max)
        ));
    }
    if region.u_min > region.u_max {
        return Some(format!(
            "base_region u_min ({}) is greater than u_max ({})",
            short_number(region.u_min),
            short_number(region.u_max)
        ));
    }
    let base = region.particles(&template.mesh).len();
    if base < MIN_BASE_PARTICLES {
        return Some(format!(
            "the base region (v <= {}, u from {} to {}) holds {base} particle(s) of the mesh; at \
             least {MIN_BASE_PARTICLES} are needed to attach the organ{}",
            short_number(region.v_max),
            short_number(region.u_min),
            short_number(region.u_max),
            uv_outside_unit_square(&template.mesh)
                .map(|note| format!(" ({note})"))
                .unwrap_or_default()
        ));
    }
    None
}

/// The colours and the colour maps: every component and every mix value
/// in [0, 1].
fn colour_problem(template: &Template) -> Option<String> {
    if template.colour.iter().any(|c| !(0.0..=1.0).contains(c)) {
        return Some(format!(
            "color components must lie in [0, 1], found {:?}",
            template.colour
        ));
    }
    if let Some(colouring) = &template.colouring {
        if colouring
            .second_colour
            .iter()
            .any(|c| !(0.0..=1.0).contains(c))
        {
            return Some(format!(
                "second_color components must lie in [0, 1], found {:?}",
                colouring.second_colour
            ));
        }
        if let Some(layer) = colouring
            .layers
            .iter()
            .find(|l| l.colour.iter().any(|c| !(0.0..=1.0).contains(c)))
        {
            return Some(format!(
                "colour layer components must lie in [0, 1], found {:?}",
                layer.colour
            ));
        }
        let maps = std::iter::once(&colouring.mix).chain(colouring.layers.iter().map(|l| &l.mix));
        if let Some(value) = maps
            .flat_map(|m| m.values())
            .find(|v| !(0.0..=1.0).contains(*v))
        {
            return Some(format!(
                "the colour map holds {}; its values must lie in [0, 1] (0 = color, 1 = \
                 second_color)",
                short_number(f64::from(*value))
            ));
        }
    }
    None
}

/// Motion over time: the joint schedule's ramps and the blend between map
/// keys.
fn schedule_problem(template: &Template) -> Option<String> {
    for ramp in &template.joint_schedule {
        if ramp.from_step > ramp.to_step || !ramp.angle_deg.is_finite() {
            return Some(format!(
                "joint_schedule ramp from step {} to step {} by {} degrees: from_step must not \
                 exceed to_step and degrees must be finite",
                ramp.from_step,
                ramp.to_step,
                short_number(ramp.angle_deg)
            ));
        }
    }
    if let Blend::Logistic { steepness } = template.maps.blend
        && !steepness.is_finite()
    {
        return Some(format!(
            "blend steepness must be a finite number, found {}",
            short_number(steepness)
        ));
    }
    None
}

/// The map keys: each key's `dg`, finite scalar maps with no negative
/// values, and a finite direction map.
fn map_key_problem(template: &Template) -> Option<String> {
    for key in template.maps.keys() {
        if let Some(dg) = key.dg
            && (!dg.is_finite() || dg <= -1.0)
        {
            return Some(format!(
                "map key at step {}: dg must be a number greater than -1 (a growth rate \
                 1 + dg × map value must stay positive), found {}",
                key.step,
                short_number(dg)
            ));
        }
        for kind in MapKind::ALL {
            let values = key.maps.scalar(kind).values();
            if let Some(value) = values.iter().find(|value| !value.is_finite()) {
                return Some(format!(
                    "map key at step {}: the {} map holds {}; map values must be finite",
                    key.step,
                    kind.name(),
                    short_number(f64::from(*value))
                ));
            }
            // A negative growth value shrinks an organ the user meant to
            // grow (e_growth = -5 halved a petal in 5 keyframes); shrinkage
            // is a negative dg. Values above 1 (constants only: a PNG holds
            // 0 to 1) scale a rate or stiffness up.
            if let Some(value) = values.iter().find(|value| **value < 0.0) {
                return Some(format!(
                    "map key at step {}: the {} map holds {}; map values must be 0 or \
                     more (for shrinkage, give the template a negative dg)",
                    key.step,
                    kind.name(),
                    short_number(f64::from(*value))
                ));
            }
        }
        let direction = key.maps.direction.values();
        if direction.iter().flatten().any(|value| !value.is_finite()) {
            return Some(format!(
                "map key at step {}: the direction map holds a value that is not finite",
                key.step
            ));
        }
    }
    None
}

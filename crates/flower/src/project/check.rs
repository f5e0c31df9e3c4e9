//! The rules every loaded or saved project obeys.

use std::collections::HashSet;
use std::path::Path;

use anthesis_maps::{Blend, MapKind};

use super::error::ProjectError;
use crate::{Project, Template};

/// All raster maps of a template must share one size; the first sets it.
/// 1x1 maps are constants and fit any size.
#[derive(Default)]
pub(super) struct SizeCheck {
    pub(super) expected: Option<(u32, u32)>,
}

impl SizeCheck {
    pub(super) fn check(&mut self, path: &Path, found: (u32, u32)) -> Result<(), ProjectError> {
        if found == (1, 1) {
            return Ok(());
        }
        match self.expected {
            None => {
                self.expected = Some(found);
                Ok(())
            }
            Some(expected) if expected == found => Ok(()),
            Some(expected) => Err(ProjectError::MapSize {
                path: path.to_path_buf(),
                expected,
                found,
            }),
        }
    }
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
    let invalid = |message: String| {
        Err(ProjectError::Invalid {
            path: path.to_path_buf(),
            message,
        })
    };
    let flower = &project.flower;
    check_unique(
        flower.templates.iter().map(|t| t.name.as_str()),
        "template",
        path,
    )?;
    check_unique(flower.organs.iter().map(|o| o.name.as_str()), "organ", path)?;

    let settings = &project.settings;
    if settings.keyframes == 0 {
        return invalid("simulation: keyframes must be at least 1".to_string());
    }
    if !(settings.solver.relative_tolerance > 0.0 && settings.solver.relative_tolerance.is_finite())
    {
        return invalid(format!(
            "simulation: relative_tolerance must be a positive number, found {}",
            settings.solver.relative_tolerance
        ));
    }
    if settings.solver.max_iterations == 0 {
        return invalid("simulation: max_iterations must be at least 1".to_string());
    }
    if !(settings.collision_offset >= 0.0 && settings.collision_offset.is_finite()) {
        return invalid(format!(
            "simulation: collision_offset must be 0 or more, found {}",
            settings.collision_offset
        ));
    }

    for template in &flower.templates {
        if let Some(message) = template_problem(template) {
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

/// What is wrong with a template's numbers, if anything.
pub(super) fn template_problem(template: &Template) -> Option<String> {
    let positive = |value: f64| value > 0.0 && value.is_finite();
    if !template.dg.is_finite() {
        return Some(format!("dg must be a finite number, found {}", template.dg));
    }
    let scales = [
        ("thickness", template.thickness),
        ("stretch_stiffness", template.stretch_stiffness),
        ("bend_stiffness", template.bend_stiffness),
    ];
    for (field, value) in scales {
        if !positive(value) {
            return Some(format!("{field} must be greater than 0, found {value}"));
        }
    }
    let region = &template.base_region;
    let in_unit = |value: f64| (0.0..=1.0).contains(&value);
    if !(in_unit(region.v_max) && in_unit(region.u_min) && in_unit(region.u_max)) {
        return Some(format!(
            "base_region v_max, u_min and u_max must lie in [0, 1], found {}, {}, {}",
            region.v_max, region.u_min, region.u_max
        ));
    }
    if region.u_min > region.u_max {
        return Some(format!(
            "base_region u_min ({}) is greater than u_max ({})",
            region.u_min, region.u_max
        ));
    }
    if template.color.iter().any(|c| !(0.0..=1.0).contains(c)) {
        return Some(format!(
            "color components must lie in [0, 1], found {:?}",
            template.color
        ));
    }
    for ramp in &template.joint_schedule {
        if ramp.from_step > ramp.to_step || !ramp.angle_deg.is_finite() {
            return Some(format!(
                "joint_schedule ramp from step {} to step {} by {} degrees: from_step must not \
                 exceed to_step and degrees must be finite",
                ramp.from_step, ramp.to_step, ramp.angle_deg
            ));
        }
    }
    if let Blend::Logistic { steepness } = template.maps.blend
        && !steepness.is_finite()
    {
        return Some(format!(
            "blend steepness must be a finite number, found {steepness}"
        ));
    }
    for key in template.maps.keys() {
        for kind in MapKind::ALL {
            let values = key.maps.scalar(kind).values();
            if let Some(value) = values.iter().find(|value| !value.is_finite()) {
                return Some(format!(
                    "map key at step {}: the {} map holds {value}; map values must be finite",
                    key.step,
                    kind.name()
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

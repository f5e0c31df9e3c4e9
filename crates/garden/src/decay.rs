//! The lily, bloom and decay (issue 15 item 3, after the decay sequence of
//! Chaudhry et al. §VI.B): the built-in lily's 100 keyframes of
//! opening, then 60 of wilting, by the growth simulation alone. From step
//! 100 each tepal's maps blend, over 15 steps, into a decay key whose own
//! growth scale is negative ([`DECAY_DG`], `MapKey::dg`): the tepals
//! shrink (more across than along), their outer side shrinks more than the
//! inner one towards the tip and at the claw, so the reflexed tips curl
//! further down and in and the tepals hang lower, and they soften (stretch
//! and bend maps at half). The joints and the stamens droop a little more.
//!
//! Decided: no gravity (the paper's model has none); the drooping is the
//! tissue's own shrinkage and the joint, as the opening was.

use anthesis_flower::{JointRamp, Project};
use anthesis_maps::{GrowthMaps, MapKey};
use glam::DVec2;

use crate::flowers::{EDGE_SCALE, GardenError, LILY_BASE_V, LILY_MIDRIB_HALF_WIDTH, lily_at};
use crate::paint::{Painting, above_base, midrib_band, smoothstep};

/// Keyframes of the whole sequence: 100 of opening, 60 of decay.
pub const DECAY_KEYFRAMES: u32 = 160;
/// The step the open flower's maps hold until.
pub const DECAY_START: u32 = 100;
/// The step from which the decay key alone holds.
pub const DECAY_FULL: u32 = 115;
/// The decay key's growth scale: a growth value `m` shrinks by `0.4 m` %
/// per step.
pub const DECAY_DG: f64 = -0.004;

/// The maps of a wilting tepal (growth values shrink, see [`DECAY_DG`]).
pub fn decay_maps() -> GrowthMaps {
    let grows = |uv: DVec2| above_base(uv.y, LILY_BASE_V, 0.04);
    let midrib = |uv: DVec2| midrib_band(uv.x, LILY_MIDRIB_HALF_WIDTH);
    let tip = |v: f64| smoothstep(0.5, 0.85, v);
    let claw = |v: f64| 1.0 - smoothstep(0.12, 0.3, v);
    let e = move |uv: DVec2| grows(uv) * 0.6;
    let w = move |uv: DVec2| grows(uv) * (0.8 - 0.3 * midrib(uv));
    // The inner side shrinks less: with a negative dg a smaller value is
    // a longer inner side, which bends the tepal away from it (down).
    let e_in = move |uv: DVec2| e(uv) - grows(uv) * (0.22 * tip(uv.y) + 0.15 * claw(uv.y));
    let w_in = move |uv: DVec2| w(uv) - grows(uv) * 0.1 * tip(uv.y);
    let soft = move |uv: DVec2| 0.5 + 0.3 * midrib(uv);
    let direction = |_: DVec2| DVec2::Y;
    Painting {
        e_growth: &e,
        w_growth: &w,
        e_growth_in: &e_in,
        w_growth_in: &w_in,
        stretch: &soft,
        bend: &soft,
        direction: &direction,
    }
    .paint()
}

/// The lily, bloom and decay (`builtin:lily-decay`).
pub fn lily_decay() -> Result<Project, GardenError> {
    lily_decay_at(EDGE_SCALE)
}

/// [`lily_decay`] with every bud meshed at `edge_scale` times Table 1's
/// edge.
pub(crate) fn lily_decay_at(edge_scale: f64) -> Result<Project, GardenError> {
    let mut project = lily_at(edge_scale)?;
    project.name = "Asiatic lily, bloom and decay".to_string();
    project.settings.keyframes = DECAY_KEYFRAMES;
    let organ = "lily decay";
    for template in &mut project.flower.templates {
        let open = template.maps.keys()[template.maps.keys().len() - 1].clone();
        let mut decay = MapKey::new(DECAY_FULL, decay_maps());
        decay.dg = Some(DECAY_DG);
        for key in [MapKey::new(DECAY_START, open.maps), decay] {
            template
                .maps
                .insert(key)
                .map_err(|error| GardenError::Maps { organ, error })?;
        }
        template.joint_schedule.push(JointRamp {
            from_step: DECAY_START,
            to_step: DECAY_KEYFRAMES,
            angle_deg: 10.0,
        });
    }
    for part in &mut project.flower.parts {
        if !part.schedule.is_empty() {
            part.schedule.push(JointRamp {
                from_step: DECAY_START + 10,
                to_step: DECAY_KEYFRAMES,
                angle_deg: 15.0,
            });
        }
    }
    Ok(project)
}

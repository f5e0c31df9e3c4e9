//! The same opening in another number of keyframes: the time step of a
//! convergence study (`refine --keyframes`).
//!
//! Growth is multiplicative (a rate `1 + dg · m` per step, rest lengths from
//! the current shape), so `N` steps of `dg` and `2N` steps of `dg / 2` end
//! at the same continuum opening as the step shrinks. Everything a project
//! times in steps must be scaled with the step count for that to hold: the
//! keyframe count, each template's `dg` and each key's own `dg`, the keys'
//! steps, the joint schedules, the parts' schedules (stamens that spread
//! over steps 20–80 of 100 must spread over 40–160 of 200, or they reach
//! the petal when it is still closed) and a two-state template's duration.
use anthesis_flower::{JointRamp, Project};

/// `project` opening in `keyframes` steps instead of its own
/// `settings.keyframes`: every growth scale divided and every step-keyed
/// schedule multiplied by `keyframes / settings.keyframes`, so that `dg · N`
/// and the place of each key, ramp and part motion in the opening stay
/// fixed. Steps are rounded to the nearest keyframe (keys that would meet
/// are kept one step apart, in order).
pub fn in_keyframes(mut project: Project, keyframes: u32) -> Project {
    let keyframes = keyframes.max(1);
    let factor = f64::from(keyframes) / f64::from(project.settings.keyframes.max(1));
    let scale = |step: u32| (f64::from(step) * factor).round() as u32;
    let scale_ramps = |ramps: &mut [JointRamp]| {
        for ramp in ramps {
            ramp.from_step = scale(ramp.from_step);
            ramp.to_step = scale(ramp.to_step);
        }
    };
    project.settings.keyframes = keyframes;
    for template in &mut project.flower.templates {
        template.dg /= factor;
        let mut previous: Option<u32> = None;
        for key in template.maps.keys_mut() {
            let step = scale(key.step);
            key.step = previous.map_or(step, |p| step.max(p + 1));
            previous = Some(key.step);
            if let Some(dg) = &mut key.dg {
                *dg /= factor;
            }
        }
        scale_ramps(&mut template.joint_schedule);
        if let Some(two_state) = &mut template.two_state {
            two_state.growth.duration *= factor;
        }
    }
    for part in &mut project.flower.parts {
        scale_ramps(&mut part.schedule);
    }
    project
}

//! Which keyframes an edit can change: the rule that lets a run keep the
//! keyframes before an edit's first effect and go on from there
//! ([`crate::Simulation::edit`]).
//!
//! A keyframe's result depends only on the organs' state at its start and
//! on what the step reads from the project: the time keys its blend weights
//! name (with their maps and weights) and the joint angle at that step.
//! Everything else a run reads (meshes, where organs sit, material
//! constants, the model, the solver and collision settings, the parts that
//! are obstacles) acts from the bud on; changing it starts the run over. Colours are not read at all.

use anthesis_flower::{Project, Template, joint_angle_after};

/// What an edit from one project to another does to a run of `organs` (the
/// project's organ indices the run simulates).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Edit {
    /// No keyframe changes (a colour, an organ not simulated).
    Nothing,
    /// Keyframes before this step stay as they are; this one and later ones
    /// must be computed again (only maps, key steps, the blend, the joint
    /// schedule or the keyframe count changed).
    From(u32),
    /// Something read from the bud on changed: the run starts over.
    Everything,
}

/// What changing `before` into `after` does to a run of `organs`.
pub fn edit_between(before: &Project, after: &Project, organs: &[usize]) -> Edit {
    if !same_from_the_bud(before, after, organs) {
        return Edit::Everything;
    }
    let keyframes = before.settings.keyframes.min(after.settings.keyframes);
    let mut first =
        (before.settings.keyframes != after.settings.keyframes).then_some(keyframes + 1);
    for &organ in organs {
        let old = before.flower.template_of(organ);
        let new = after.flower.template_of(organ);
        if let Some(step) = first_step_reading_a_change(old, new, first.unwrap_or(keyframes + 1)) {
            first = Some(first.map_or(step, |f| f.min(step)));
        }
    }
    match first {
        None => Edit::Nothing,
        Some(1) => Edit::Everything,
        Some(step) => Edit::From(step),
    }
}

/// Whether everything a run reads from the bud on is the same: the
/// simulated organs, their templates' meshes and constants, the overlaps
/// between them, and the settings other than the keyframe count.
fn same_from_the_bud(before: &Project, after: &Project, organs: &[usize]) -> bool {
    let settings = |project: &Project| anthesis_flower::SimulationSettings {
        keyframes: 0,
        ..project.settings
    };
    if settings(before) != settings(after)
        || before.flower.organs.len() != after.flower.organs.len()
        || before.flower.overlaps != after.flower.overlaps
        || anthesis_flower::parts::obstacles(&before.flower)
            != anthesis_flower::parts::obstacles(&after.flower)
    {
        return false;
    }
    organs.iter().all(|&i| {
        let (old, new) = (before.flower.template_of(i), after.flower.template_of(i));
        before.flower.organs[i] == after.flower.organs[i]
            && old.mesh == new.mesh
            && old.dg.to_bits() == new.dg.to_bits()
            && old.thickness.to_bits() == new.thickness.to_bits()
            && old.stretch_stiffness.to_bits() == new.stretch_stiffness.to_bits()
            && old.bend_stiffness.to_bits() == new.bend_stiffness.to_bits()
            && old.base_region == new.base_region
            && old.two_state == new.two_state
    })
}

/// The first step before `limit` that reads something of `new` that differs
/// from `old`: its blend names keys with other maps or gives them other
/// weights, or the joint angle differs. A key named with weight 0 counts as
/// read (the product is a signed zero, which can still differ).
fn first_step_reading_a_change(old: &Template, new: &Template, limit: u32) -> Option<u32> {
    let (old_keys, new_keys) = (old.maps.keys(), new.maps.keys());
    // same[i][j]: old key i and new key j hold the same maps.
    let same: Vec<Vec<bool>> = old_keys
        .iter()
        .map(|o| {
            new_keys
                .iter()
                .map(|n| {
                    // The same maps at the same growth scale.
                    o.maps == n.maps
                        && o.dg.unwrap_or(old.dg).to_bits() == n.dg.unwrap_or(new.dg).to_bits()
                })
                .collect()
        })
        .collect();
    (1..limit).find(|&step| {
        let s = f64::from(step);
        let (was, is) = (old.maps.weights_at(s), new.maps.weights_at(s));
        let keys_differ = was
            .iter()
            .zip(&is)
            .any(|(&(k_old, w_old), &(k_new, w_new))| {
                w_old.to_bits() != w_new.to_bits() || !same[k_old][k_new]
            });
        keys_differ
            || joint_angle_after(&old.joint_schedule, step).to_bits()
                != joint_angle_after(&new.joint_schedule, step).to_bits()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::{stroke_near_tip as paint, whorl};
    use anthesis_flower::JointRamp;

    /// A four-organ whorl whose templates have time keys at steps 40 and
    /// 50, blended linearly (as the lily's), over 60 keyframes.
    fn lily_like() -> Project {
        whorl(4, 6, 10, 60)
    }

    const ALL: [usize; 4] = [0, 1, 2, 3];

    #[test]
    fn a_stroke_on_the_late_key_changes_nothing_before_its_blend_starts() {
        let before = lily_like();
        let mut after = before.clone();
        paint(&mut after, 0, 1);
        // Step 40 names the step-50 key with weight 0; 41 is the first to
        // give it weight.
        assert_eq!(edit_between(&before, &after, &ALL), Edit::From(40));
        // The sepals do not read the petals' maps: a run of one sepal keeps
        // everything.
        assert_eq!(edit_between(&before, &after, &[1]), Edit::Nothing);
    }

    #[test]
    fn a_keys_own_growth_scale_acts_like_its_maps() {
        let before = lily_like();
        let mut after = before.clone();
        after.flower.templates[0].maps.keys_mut()[1].dg = Some(-0.004);
        assert_eq!(edit_between(&before, &after, &ALL), Edit::From(40));
        // The template's own dg, written on the key, changes nothing.
        let mut same = before.clone();
        let dg = same.flower.templates[0].dg;
        same.flower.templates[0].maps.keys_mut()[1].dg = Some(dg);
        assert_eq!(edit_between(&before, &same, &ALL), Edit::Nothing);
    }

    #[test]
    fn a_stroke_on_the_first_key_changes_the_run_from_the_bud() {
        let before = lily_like();
        let mut after = before.clone();
        paint(&mut after, 1, 0);
        assert_eq!(edit_between(&before, &after, &ALL), Edit::Everything);
    }

    #[test]
    fn moving_a_key_changes_the_run_where_the_blend_first_differs() {
        let before = lily_like();
        let mut after = before.clone();
        for key in after.flower.templates[0].maps.keys_mut() {
            if key.step == 50 {
                key.step = 55;
            }
        }
        // Steps up to 40 read the step-40 key alone, with or without the
        // move; at 41 the blend weights differ.
        assert_eq!(edit_between(&before, &after, &ALL), Edit::From(41));
    }

    #[test]
    fn a_later_joint_ramp_changes_the_run_from_its_first_step() {
        let before = lily_like();
        let mut after = before.clone();
        after.flower.templates[1].joint_schedule.push(JointRamp {
            from_step: 30,
            to_step: 45,
            angle_deg: 5.0,
        });
        assert_eq!(edit_between(&before, &after, &ALL), Edit::From(31));
    }

    #[test]
    fn more_or_fewer_keyframes_keep_those_both_runs_share() {
        let before = lily_like();
        let mut longer = before.clone();
        longer.settings.keyframes = 80;
        assert_eq!(edit_between(&before, &longer, &ALL), Edit::From(61));
        let mut shorter = before.clone();
        shorter.settings.keyframes = 30;
        assert_eq!(edit_between(&before, &shorter, &ALL), Edit::From(31));
        // Fewer keyframes and a late stroke: the earlier of the two.
        paint(&mut shorter, 0, 1);
        assert_eq!(edit_between(&before, &shorter, &ALL), Edit::From(31));
    }

    #[test]
    fn what_acts_from_the_bud_starts_over_and_a_colour_changes_nothing() {
        let before = lily_like();
        let mut colour = before.clone();
        colour.flower.templates[0].color = [0.1, 0.2, 0.3, 1.0];
        assert_eq!(edit_between(&before, &colour, &ALL), Edit::Nothing);
        assert_eq!(edit_between(&before, &before.clone(), &ALL), Edit::Nothing);

        type Change = (&'static str, fn(&mut Project));
        let changes: [Change; 6] = [
            ("dg", |p| p.flower.templates[0].dg *= 1.1),
            ("mesh", |p| {
                p.flower.templates[0].mesh.positions[3].x += 1e-9
            }),
            ("placement", |p| {
                p.flower.organs[2].placement.azimuth_deg += 1.0
            }),
            ("tolerance", |p| p.settings.solver.relative_tolerance = 1e-7),
            ("overlaps", |p| {
                p.flower.overlaps.pop();
            }),
            ("base", |p| p.flower.templates[1].base_region.v_max += 0.01),
        ];
        for (what, change) in changes {
            let mut after = before.clone();
            change(&mut after);
            assert_eq!(
                edit_between(&before, &after, &ALL),
                Edit::Everything,
                "{what}"
            );
        }
    }
}

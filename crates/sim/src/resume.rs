//! Which keyframes an edit can change: the rule that lets a run keep the
//! keyframes before an edit's first effect and go on from there
//! ([`crate::Simulation::edit`]).
//!
//! A keyframe's result depends only on the organs' state at its start and
//! on what the step reads from the project: the time keys its blend weights
//! name (with their maps and weights) and the joint angle at that step.
//! The parts that are obstacles are read the same way: their shapes and
//! places from the bud on, their schedules at each step.
//! Everything else a run reads (meshes, where organs sit, material
//! constants, the model, the solver and collision settings) acts from the
//! bud on; changing it starts the run over. Colours, and the parts' names,
//! are not read at all.

use anthesis_flower::parts::PartPiece;
use anthesis_flower::{JointRamp, Placement, Project, Template, joint_angle_after};

/// What an edit from one project to another does to a run of `organs` (the
/// project's organ indices the run simulates).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Edit {
    /// No keyframe changes (a colour, an organ not simulated).
    Nothing,
    /// Keyframes before this step stay as they are; this one and later ones
    /// must be computed again (only maps, key steps, the blend, a joint or
    /// part schedule or the keyframe count changed).
    From(u32),
    /// Something read from the bud on changed: the run starts over.
    Everything,
}

/// What changing `before` into `after` does to a run of `organs`.
pub fn edit_between(before: &Project, after: &Project, organs: &[usize]) -> Edit {
    let (old_parts, new_parts) = (
        anthesis_flower::parts::obstacles(&before.flower),
        anthesis_flower::parts::obstacles(&after.flower),
    );
    if !same_from_the_bud(before, after, organs, (&old_parts, &new_parts)) {
        return Edit::Everything;
    }
    let keyframes = before.settings.keyframes.min(after.settings.keyframes);
    let mut first =
        (before.settings.keyframes != after.settings.keyframes).then_some(keyframes + 1);
    for &organ in organs {
        let old = before.flower.template_of(organ);
        let new = after.flower.template_of(organ);
        // The same in both (`same_from_the_bud`).
        let placement = &before.flower.organs[organ].placement;
        let limit = first.unwrap_or(keyframes + 1);
        if let Some(step) = first_step_reading_a_change(old, new, placement, limit) {
            first = Some(first.map_or(step, |f| f.min(step)));
        }
    }
    // The same shapes and places (`same_from_the_bud`): a part moves
    // otherwise from the first step its schedule turns it otherwise.
    for (old, new) in old_parts.iter().zip(&new_parts) {
        let limit = first.unwrap_or(keyframes + 1);
        let moved = |step: u32| {
            joint_angle_read(&old.placement, &old.schedule, step)
                != joint_angle_read(&new.placement, &new.schedule, step)
        };
        if let Some(step) = (1..limit).find(|&step| moved(step)) {
            first = Some(step);
        }
    }
    match first {
        None => Edit::Nothing,
        Some(1) => Edit::Everything,
        Some(step) => Edit::From(step),
    }
}

/// The joint angle a step reads for something placed at `placement` with
/// `schedule`, as bits: `Placement::world_from_template` and
/// `parts::pose` turn by the placement's angle plus the schedule's, and
/// nothing else reads the schedule. Compared this way, not by the
/// schedule's angle alone: an empty schedule's angle is -0.0 (an empty
/// sum), a ramp that has not started yet gives +0.0, and added to the
/// placement's angle both give the same bits (unless that angle is -0.0),
/// so adding a later ramp where there was none keeps the earlier keyframes
/// (the apple's templates and parts have no schedule).
fn joint_angle_read(placement: &Placement, schedule: &[JointRamp], step: u32) -> u64 {
    (placement.joint_angle_deg.to_radians() + joint_angle_after(schedule, step)).to_bits()
}

/// What a run reads of a part from the bud on: its shape and place (its
/// schedule is read per step, its name and colours never).
fn part_shape(piece: &PartPiece) -> (&anthesis_mesh::Mesh, &Placement) {
    (&piece.mesh, &piece.placement)
}

/// Whether everything a run reads from the bud on is the same: the
/// simulated organs, their templates' meshes and constants, the overlaps
/// between them, the parts' shapes and places (`parts`: the obstacles of
/// each), and the settings other than the keyframe count.
fn same_from_the_bud(
    before: &Project,
    after: &Project,
    organs: &[usize],
    (old_parts, new_parts): (&[PartPiece], &[PartPiece]),
) -> bool {
    let settings = |project: &Project| anthesis_flower::SimulationSettings {
        keyframes: 0,
        ..project.settings
    };
    if settings(before) != settings(after)
        || before.flower.organs.len() != after.flower.organs.len()
        || before.flower.overlaps != after.flower.overlaps
        || !old_parts
            .iter()
            .map(part_shape)
            .eq(new_parts.iter().map(part_shape))
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
/// from `old` for an organ at `placement`: its blend names keys with other
/// maps or gives them other weights, or the joint angle differs. A key
/// named with weight 0 counts as read (the product is a signed zero, which
/// can still differ).
fn first_step_reading_a_change(
    old: &Template,
    new: &Template,
    placement: &Placement,
    limit: u32,
) -> Option<u32> {
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
            || joint_angle_read(placement, &old.joint_schedule, step)
                != joint_angle_read(placement, &new.joint_schedule, step)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::{stroke_near_tip as paint, whorl};
    use anthesis_flower::JointRamp;
    use anthesis_flower::parts::{Part, PartShape, Tube};

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
    fn a_first_ramp_on_a_template_without_one_keeps_the_steps_before_it() {
        // The apple's templates have no schedule: its angle is an empty
        // sum, -0.0, and a ramp not yet started gives +0.0. Both added to
        // the placement's angle are the angle the step reads.
        let mut before = lily_like();
        before.flower.templates[1].joint_schedule.clear();
        let mut after = before.clone();
        after.flower.templates[1].joint_schedule.push(JointRamp {
            from_step: 30,
            to_step: 45,
            angle_deg: 5.0,
        });
        assert_eq!(edit_between(&before, &after, &ALL), Edit::From(31));
    }

    /// A stamen beside each organ of `lily_like`, turning outwards over
    /// the first 20 steps.
    fn with_stamens() -> Project {
        let mut project = lily_like();
        project.flower.parts.push(Part {
            name: "stamen".to_string(),
            shape: PartShape::Stamen {
                filament: Tube {
                    length: 8.0,
                    radius: 0.3,
                    curvature_deg: 0.0,
                },
                anther_length: 1.5,
                anther_radius: 0.4,
                anther_tilt_deg: 60.0,
            },
            count: 3,
            ring_radius: 1.0,
            height: 0.0,
            offset_deg: 0.0,
            angle_deg: 5.0,
            schedule: vec![JointRamp {
                from_step: 0,
                to_step: 20,
                angle_deg: 10.0,
            }],
            colour: [0.8, 0.8, 0.6, 1.0],
            head_colour: [0.6, 0.2, 0.0, 1.0],
        });
        project
    }

    #[test]
    fn a_parts_later_ramp_keeps_the_steps_before_it_and_its_colour_and_name_nothing() {
        let before = with_stamens();
        let mut later = before.clone();
        later.flower.parts[0].schedule.push(JointRamp {
            from_step: 35,
            to_step: 50,
            angle_deg: -4.0,
        });
        assert_eq!(edit_between(&before, &later, &ALL), Edit::From(36));
        // One organ alone still meets the parts.
        assert_eq!(edit_between(&before, &later, &[1]), Edit::From(36));
        // Fewer keyframes too: the earlier.
        later.settings.keyframes = 30;
        assert_eq!(edit_between(&before, &later, &ALL), Edit::From(31));
        // Its first ramp made shorter: the angles part at step 1.
        let mut faster = before.clone();
        faster.flower.parts[0].schedule[0].to_step = 10;
        assert_eq!(edit_between(&before, &faster, &ALL), Edit::Everything);
        let mut recoloured = before.clone();
        recoloured.flower.parts[0].colour = [0.1, 0.2, 0.3, 1.0];
        recoloured.flower.parts[0].head_colour = [0.9, 0.2, 0.3, 1.0];
        recoloured.flower.parts[0].name = "filament".to_string();
        assert_eq!(edit_between(&before, &recoloured, &ALL), Edit::Nothing);
        // Its shape or place acts from the bud on.
        let mut longer = before.clone();
        longer.flower.parts[0].ring_radius = 1.2;
        assert_eq!(edit_between(&before, &longer, &ALL), Edit::Everything);
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
        colour.flower.templates[0].colour = [0.1, 0.2, 0.3, 1.0];
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

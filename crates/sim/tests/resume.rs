//! Going on after an edit (issue 11): a run keeps the keyframes an edit
//! cannot change and computes the others again from the last kept one, and
//! every keyframe is then the same, bit for bit, as a run of the edited
//! project from the bud.

mod common;

use anthesis_flower::{JointRamp, Project, TwoStateAnimation};
use anthesis_sim::fixtures::{stroke_near_tip as paint, whorl};
use anthesis_sim::{Keyframe, Selection, SimError, Simulation};
use anthesis_twostate::{GrowthFunction, VelocityCurve};
use common::{fingerprint, pistil};
use glam::DQuat;

/// Steps `sim` to its last keyframe, collecting the keyframes it computes.
fn finish(sim: &mut Simulation) -> Vec<Keyframe> {
    let mut keyframes = Vec::new();
    while !sim.finished() {
        match sim.step(&|| false, &mut |_| {}) {
            Ok(keyframe) => keyframes.push(keyframe),
            Err(error) => panic!("keyframe {}: {error}", keyframes.len() + 1),
        }
    }
    keyframes
}

/// A whole run from the bud, with checkpoints kept.
fn full_run(project: &Project) -> (Simulation, Vec<Keyframe>) {
    let mut sim = Simulation::new(project, &Selection::All).expect("a valid project");
    sim.keep_checkpoints();
    let mut keyframes = vec![sim.bud()];
    keyframes.extend(finish(&mut sim));
    (sim, keyframes)
}

/// Edits `sim` (which ran `before`) to `after`, checks it goes on from
/// `expected_first`, finishes it and checks the keyframes against a run of
/// `after` from the bud: those before the first recomputed keyframe kept
/// from `kept`, the rest recomputed, all bit for bit.
fn assert_resumes_exactly(
    mut sim: Simulation,
    kept: &[Keyframe],
    before: &Project,
    after: &Project,
    expected_first: u32,
) {
    let first = sim.edit(before, after).expect("the edit is valid");
    assert_eq!(first, expected_first);
    let mut resumed: Vec<Keyframe> = kept[..first as usize].to_vec();
    resumed.extend(finish(&mut sim));
    let (_, reference) = full_run(after);
    assert_eq!(resumed.len(), reference.len());
    for (r, k) in reference.iter().zip(&resumed) {
        assert_eq!(
            fingerprint(std::slice::from_ref(k)),
            fingerprint(std::slice::from_ref(r)),
            "keyframe {} differs from the run from the bud",
            r.index
        );
    }
}

#[test]
fn a_stroke_on_the_late_key_goes_on_from_where_its_blend_starts_bit_for_bit() {
    // Keys at 40 and 50 as the lily's: the step-50 key is first read at 40.
    let before = whorl(4, 8, 14, 48);
    assert!(!before.flower.overlaps.is_empty());
    let mut after = before.clone();
    paint(&mut after, 0, 1);
    let (sim, kept) = full_run(&before);
    // The edit must change something, or the comparison proves nothing.
    let (_, painted) = full_run(&after);
    assert_ne!(fingerprint(&kept[40..]), fingerprint(&painted[40..]));
    assert_eq!(fingerprint(&kept[..40]), fingerprint(&painted[..40]));
    assert_resumes_exactly(sim, &kept, &before, &after, 40);
}

#[test]
fn organs_pressing_on_each_other_go_on_from_a_later_joint_ramp_bit_for_bit() {
    // Contacts in most keyframes: the kept state must carry what the
    // contacts and the push-back read.
    let before = common::inner_driven_into_outer(20, true);
    let mut after = before.clone();
    after.flower.templates[0].joint_schedule.push(JointRamp {
        from_step: 12,
        to_step: 20,
        angle_deg: 4.0,
    });
    let (sim, kept) = full_run(&before);
    assert!(kept[12..].iter().any(|k| k.stats.contact_particles > 0));
    assert_resumes_exactly(sim, &kept, &before, &after, 13);
}

#[test]
fn a_run_cancelled_inside_a_keyframe_goes_on_from_that_keyframe() {
    let before = whorl(4, 8, 14, 48);
    let mut after = before.clone();
    paint(&mut after, 0, 1);
    let mut sim = Simulation::new(&before, &Selection::All).expect("valid");
    sim.keep_checkpoints();
    let mut kept = vec![sim.bud()];
    for _ in 0..20 {
        kept.push(sim.step(&|| false, &mut |_| {}).expect("steps"));
    }
    // Cancelled after the first iteration of keyframe 21: the organs are
    // half way through it.
    // (The check is polled from the threads the organs settle on.)
    let polls = std::sync::atomic::AtomicU32::new(0);
    let cancelled = sim.step(
        &|| polls.fetch_add(1, std::sync::atomic::Ordering::SeqCst) + 1 > 1,
        &mut |_| {},
    );
    assert!(
        matches!(cancelled, Err(SimError::Cancelled)),
        "{cancelled:?}"
    );
    assert_resumes_exactly(sim, &kept, &before, &after, 21);
}

#[test]
fn without_checkpoints_an_edit_starts_over_and_an_edit_that_changes_nothing_keeps_all() {
    let before = whorl(2, 6, 10, 12);
    let mut after = before.clone();
    after.settings.keyframes = 16;
    // No checkpoints: nothing to go on from.
    let mut plain = Simulation::new(&before, &Selection::All).expect("valid");
    let mut kept = vec![plain.bud()];
    kept.extend(finish(&mut plain));
    assert_resumes_exactly(plain, &kept, &before, &after, 1);
    // With them, four more keyframes are four more steps.
    let (sim, kept) = full_run(&before);
    assert_resumes_exactly(sim, &kept, &before, &after, 13);
    // A colour is not simulated.
    let mut recoloured = before.clone();
    recoloured.flower.templates[0].colour = [0.2, 0.3, 0.9, 1.0];
    let (mut sim, _) = full_run(&before);
    assert_eq!(sim.edit(&before, &recoloured).expect("valid"), 13);
    assert!(sim.finished());
    assert_eq!(sim.colour(0), [0.2, 0.3, 0.9, 1.0]);
}

#[test]
fn a_first_ramp_where_there_was_none_goes_on_from_its_first_step_bit_for_bit() {
    // Templates without a schedule (as the apple's): the angle the steps
    // before the ramp read is the same, though the schedule's own angle
    // changes from -0.0 (an empty sum) to +0.0.
    let mut before = whorl(4, 6, 10, 16);
    for template in &mut before.flower.templates {
        template.joint_schedule.clear();
    }
    let mut after = before.clone();
    after.flower.templates[1].joint_schedule.push(JointRamp {
        from_step: 10,
        to_step: 16,
        angle_deg: 6.0,
    });
    let (sim, kept) = full_run(&before);
    let (_, turned) = full_run(&after);
    assert_ne!(fingerprint(&kept[11..]), fingerprint(&turned[11..]));
    assert_resumes_exactly(sim, &kept, &before, &after, 11);
}

#[test]
fn a_part_turned_from_a_later_step_goes_on_from_there_bit_for_bit() {
    // One petal swinging in across the axis, where the pistil stands: the
    // pistil's contacts hold it from the middle of the run on. The edit
    // tilts the pistil from step 8, so the run must take the new schedule
    // (a part's colour changes nothing at all).
    let mut before = whorl(1, 6, 10, 14);
    before.flower.templates[0].joint_schedule = vec![JointRamp {
        from_step: 0,
        to_step: 14,
        angle_deg: -40.0,
    }];
    before.flower.parts.push(pistil());
    let mut after = before.clone();
    after.flower.parts[0].schedule.push(JointRamp {
        from_step: 8,
        to_step: 14,
        angle_deg: 12.0,
    });
    let (sim, kept) = full_run(&before);
    assert!(kept[9..].iter().any(|k| k.stats.contact_particles > 0));
    let (_, tilted) = full_run(&after);
    assert_ne!(fingerprint(&kept[9..]), fingerprint(&tilted[9..]));
    assert_resumes_exactly(sim, &kept, &before, &after, 9);

    let mut recoloured = before.clone();
    recoloured.flower.parts[0].colour = [0.9, 0.1, 0.1, 1.0];
    let (mut sim, _) = full_run(&before);
    assert_eq!(sim.edit(&before, &recoloured).expect("valid"), 15);
}

#[test]
fn a_two_state_organ_goes_on_from_a_later_ramp_bit_for_bit() {
    // The outer organ is kinematic (its two-state in-betweens, placed);
    // the inner one grows into it. Its later ramp moves it from step 9.
    let mut before = common::inner_driven_into_outer_by(12, true, 30.0);
    let outer = &mut before.flower.templates[1];
    let open = outer
        .mesh
        .positions
        .iter()
        .zip(&outer.mesh.uvs)
        .map(|(p, uv)| DQuat::from_rotation_x(0.3 * uv.y * uv.y) * *p)
        .collect();
    outer.two_state = Some(TwoStateAnimation {
        open,
        growth: GrowthFunction {
            g: 6.0,
            duration: 12.0,
        },
        velocity: VelocityCurve::Points(vec![[0.0, 0.0], [1.0, 1.0]]),
    });
    let mut after = before.clone();
    after.flower.templates[1].joint_schedule.push(JointRamp {
        from_step: 8,
        to_step: 12,
        angle_deg: -6.0,
    });
    let (sim, kept) = full_run(&before);
    let (_, moved) = full_run(&after);
    assert_ne!(fingerprint(&kept[9..]), fingerprint(&moved[9..]));
    assert_resumes_exactly(sim, &kept, &before, &after, 9);
}

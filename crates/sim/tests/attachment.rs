//! Attachment (paper §5.3): base particles chosen by a UV region are shape
//! matched after each iteration onto the receptacle with the organ's
//! scheduled joint angle. The base must stay where the receptacle and the
//! scheduled angle put it.

mod common;

use anthesis_flower::{JointRamp, Project, joint_angle_after};
use anthesis_sim::fixtures::whorl;
use anthesis_sim::{Selection, run};
use glam::{DQuat, DVec3};

/// How far organ `organ`'s base particles (`positions_in_world`) are from
/// where the receptacle puts them with `extra_joint` radians added to the
/// organ's initial joint angle. `Err` describes the first check that fails.
fn check_base_placed(
    project: &Project,
    organ: usize,
    positions_in_world: &[DVec3],
    extra_joint: f64,
    mean_edge: f64,
) -> Result<(), String> {
    let template = project.flower.template_of(organ);
    let placement = project.flower.organs[organ].placement;
    let base = template.base_region.particles(&template.mesh);
    let targets_in_world: Vec<DVec3> = base
        .iter()
        .map(|&b| placement.world_from_template(template.mesh.positions[b as usize], extra_joint))
        .collect();
    let actual_in_world: Vec<DVec3> = base
        .iter()
        .map(|&b| positions_in_world[b as usize])
        .collect();
    let n = base.len() as f64;

    // Shape matching moves the base centroid exactly onto the targets'.
    let centroid_error =
        (actual_in_world.iter().sum::<DVec3>() - targets_in_world.iter().sum::<DVec3>()) / n;
    if centroid_error.length() > 1e-9 {
        return Err(format!(
            "base centroid is {:.3e} from its target",
            centroid_error.length()
        ));
    }

    // No growth in the base band: it may deform a little, no more.
    for (i, (a, t)) in actual_in_world.iter().zip(&targets_in_world).enumerate() {
        let d = (*a - *t).length();
        if d > 0.25 * mean_edge {
            return Err(format!(
                "base particle {} is {:.3} mean edges from its target",
                base[i],
                d / mean_edge
            ));
        }
    }

    // The joint angle that best carries the template's base onto the
    // actual base (closed form for a rotation about the template's +X):
    // maximise sum_b p_b . Rx(theta) q_b over theta.
    let unturn = DQuat::from_rotation_y(-placement.azimuth_deg.to_radians());
    let (mut sine, mut cosine) = (0.0, 0.0);
    for &b in &base {
        let q = template.mesh.positions[b as usize];
        let p = unturn * (positions_in_world[b as usize] - placement.position);
        sine += p.z * q.y - p.y * q.z;
        cosine += p.y * q.y + p.z * q.z;
    }
    let fitted_deg = sine.atan2(cosine).to_degrees();
    let scheduled_deg = placement.joint_angle_deg + extra_joint.to_degrees();
    if (fitted_deg - scheduled_deg).abs() > 0.05 {
        return Err(format!(
            "the base sits at joint angle {fitted_deg:.3} degrees, the schedule says {scheduled_deg:.3}"
        ));
    }
    Ok(())
}

#[test]
fn the_base_stays_where_the_receptacle_and_the_scheduled_angle_put_it() {
    // A petal and a sepal (two templates, two rings, opposite azimuths).
    let project = whorl(2, 8, 14, 100);
    let mut checked = 0;
    run(&project, &Selection::All, &mut |sim, keyframe| {
        if keyframe.index != 30 && keyframe.index != 100 {
            return;
        }
        for organ in 0..2 {
            let template = project.flower.template_of(organ);
            let bud_in_world: Vec<DVec3> = template
                .mesh
                .positions
                .iter()
                .map(|p| {
                    project.flower.organs[organ]
                        .placement
                        .world_from_template(*p, 0.0)
                })
                .collect();
            let mean_edge = common::mean_edge(&bud_in_world, sim.triangles(organ));
            let positions = &keyframe.positions_in_world[organ];
            let scheduled = joint_angle_after(&template.joint_schedule, keyframe.index);
            assert!(scheduled > 0.1, "the schedule must have turned the joint");
            if let Err(why) = check_base_placed(&project, organ, positions, scheduled, mean_edge) {
                panic!(
                    "keyframe {}, organ {}: {why}",
                    keyframe.index, project.flower.organs[organ].name
                );
            }
            // The check can fail: a different schedule puts the base
            // elsewhere (20 degrees instead of 23 over steps 1-60).
            let other_schedule = [JointRamp {
                from_step: 0,
                to_step: 60,
                angle_deg: 20.0,
            }];
            let other = joint_angle_after(&other_schedule, keyframe.index);
            assert!(
                check_base_placed(&project, organ, positions, other, mean_edge).is_err(),
                "keyframe {}: the base also fits a schedule 3 degrees off",
                keyframe.index
            );
            checked += 1;
        }
    })
    .unwrap_or_else(|e| panic!("the run failed: {e}"));
    assert_eq!(checked, 4);
}

#[test]
fn a_larger_schedule_turns_the_base_further() {
    // The same organ with 40 degrees over steps 1-20 instead of 23 over
    // 1-60: the base follows the new schedule, not the template's old one.
    let mut project = whorl(1, 8, 14, 20);
    let template = &mut project.flower.templates[0];
    let old_schedule = template.joint_schedule.clone();
    template.joint_schedule = vec![JointRamp {
        from_step: 0,
        to_step: 20,
        angle_deg: 40.0,
    }];
    let (keyframes, error) = common::run_all(&project, &Selection::All);
    assert_eq!(error, None);
    let last = keyframes.last().expect("the bud at least");
    assert_eq!(last.index, 20);
    let template = project.flower.template_of(0);
    let bud: Vec<DVec3> = keyframes[0].positions_in_world[0].clone();
    let mean_edge = common::mean_edge(&bud, &template.mesh.triangles);
    let positions = &last.positions_in_world[0];
    check_base_placed(&project, 0, positions, 40f64.to_radians(), mean_edge)
        .unwrap_or_else(|why| panic!("{why}"));
    let old = joint_angle_after(&old_schedule, 20);
    assert!(check_base_placed(&project, 0, positions, old, mean_edge).is_err());
}

//! Parts that do not grow are obstacles: a petal swung into a pistil stays
//! outside it, checked geometrically (winding number of the pistil's
//! closed surface), not by trusting the solver.

mod common;

use anthesis_flower::JointRamp;
use anthesis_flower::Project;
use anthesis_flower::parts::{Part, obstacles};
use anthesis_mesh::nearest::winding_number;
use anthesis_sim::{Selection, fixtures, run};
use common::pistil;
use glam::DVec3;

/// One petal of a one-organ whorl that tilts 40° inwards over the run, so
/// its tip sweeps across the flower axis.
fn petal_swinging_in() -> Project {
    let mut project = fixtures::whorl(1, 6, 10, 12);
    project.flower.templates[0].joint_schedule = vec![JointRamp {
        from_step: 0,
        to_step: 12,
        angle_deg: -40.0,
    }];
    project
}

/// The most particles inside the pistil (any of its closed components) at
/// any keyframe of a run.
fn most_inside(project: &Project, pistil: &Part) -> usize {
    let mut flower = project.flower.clone();
    flower.parts = vec![pistil.clone()];
    let components = obstacles(&flower);
    let mut most = 0;
    run(project, &Selection::All, &mut |_, keyframe| {
        let surfaces: Vec<Vec<DVec3>> = components
            .iter()
            .map(|c| c.positions_at(keyframe.index))
            .collect();
        let inside = keyframe.positions_in_world[0]
            .iter()
            .filter(|&&p| {
                components
                    .iter()
                    .zip(&surfaces)
                    .any(|(c, s)| winding_number(p, s, &c.mesh.triangles) > 0.5)
            })
            .count();
        most = most.max(inside);
    })
    .expect("the run converges");
    most
}

#[test]
fn a_petal_swung_into_a_pistil_stays_outside_it() {
    let without = petal_swinging_in();
    // Without the part the petal sweeps through where the pistil stands.
    let crossing = most_inside(&without, &pistil());
    assert!(
        crossing > 5,
        "{crossing} particles: the petal never reached the pistil"
    );
    let mut with = petal_swinging_in();
    with.flower.parts = vec![pistil()];
    assert_eq!(most_inside(&with, &pistil()), 0);
}

#[test]
fn the_winding_number_tells_inside_from_outside() {
    let mut flower = petal_swinging_in().flower;
    flower.parts = vec![pistil()];
    let obstacle = obstacles(&flower).remove(0);
    let surface = obstacle.positions_at(0);
    let inside = winding_number(
        DVec3::new(0.1, 5.0, 0.0),
        &surface,
        &obstacle.mesh.triangles,
    );
    let outside = winding_number(
        DVec3::new(1.5, 5.0, 0.0),
        &surface,
        &obstacle.mesh.triangles,
    );
    assert!((inside - 1.0).abs() < 1e-9, "{inside}");
    assert!(outside.abs() < 1e-9, "{outside}");
}

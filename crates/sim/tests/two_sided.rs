//! Two-sided contact (issue 35 item 3): a contact acts on both organs, so
//! an organ pressing a neighbour moves it, also where only the presser's
//! particles reach the other's surface. (That the forces are equal and
//! opposite is `collide`'s unit test.)

mod common;

use anthesis_mesh::generate::test_petal;
use anthesis_sim::crossing::{Crossings, OnCrossing};
use anthesis_sim::{Keyframe, Selection, Simulation};
use common::{inner_driven_into_outer_by, mean_edge, run_all};

/// Every keyframe of a run of `project` with two-sided contact on or off,
/// going on past crossings, and the crossings found.
fn run_two_sided(project: &anthesis_flower::Project, on: bool) -> (Vec<Keyframe>, Vec<Crossings>) {
    let mut sim = Simulation::new(project, &Selection::All).expect("valid");
    sim.on_crossing(OnCrossing::Warn);
    sim.two_sided_contact(on);
    let mut keyframes = vec![sim.bud()];
    while !sim.finished() {
        keyframes.push(sim.step(&|| false, &mut |_| {}).expect("the run goes on"));
    }
    (keyframes, sim.crossings().to_vec())
}

/// A fine inner petal (8 x 14 particles) driven 40 degrees into an outer
/// one of the same size and shape but coarse (4 x 7): the inner one's
/// particles press on the outer one's large triangles between its
/// particles, which reach the inner one's surface late or not at all.
fn fine_into_coarse(keyframes: u32) -> anthesis_flower::Project {
    let mut project = inner_driven_into_outer_by(keyframes, true, 40.0);
    let (length, width) = (1.3 * 14.0, 1.3 * 8.0);
    let coarse = anthesis_sim::fixtures::petal_template("outer petal", 4, 7);
    let outer = &mut project.flower.templates[1];
    outer.mesh = test_petal(length, width, 4, 7);
    outer.base_region = coarse.base_region;
    project
}

#[test]
fn a_petal_pressing_a_coarse_neighbour_pushes_it_away_without_passing_through() {
    let keyframes = 12;
    let project = fine_into_coarse(keyframes);
    let (both, crossings) = run_two_sided(&project, true);
    let (one_sided, one_sided_crossings) = run_two_sided(&project, false);
    let (alone, error) = run_all(&project, &Selection::Only(1));
    assert_eq!(error, None);
    let triangles = &project.flower.templates[1].mesh.triangles;
    let edge = mean_edge(&alone[0].positions_in_world[0], triangles);
    // The petals press from keyframe 5. With one-sided contacts the inner
    // one's particles go through the outer one's triangles there: nothing
    // pushes the outer one aside where only the inner one's particles
    // reach it (from keyframe 6 since rim contacts hold the inner one's
    // edges off the outer one's rim a keyframe longer).
    assert_eq!(one_sided_crossings.first().map(|c| c.keyframe), Some(6));
    let first = crossings.first().map(|c| c.keyframe);
    assert!(
        first.is_none_or(|k| k > 8),
        "the petals cross at keyframe {first:?}"
    );
    // Keyframe 8: how far the outer petal's particles lie outward (+z,
    // away from the axis and the inner petal) of where it grows alone.
    // Two-sided, the inner one's contacts push it. (Rim contacts push it
    // one-sided too, where the inner one's edges meet its rim, as far:
    // 0.47 edges one-sided, 0.45 two-sided since reactions shallower than
    // 0.015 edges are left out; what two-sided adds is that the inner
    // petal passes through between the outer one's particles only after
    // keyframe 8, at 12, instead of from keyframe 6.)
    let pushed = |keyframes: &[Keyframe]| {
        keyframes[8].positions_in_world[1]
            .iter()
            .zip(&alone[8].positions_in_world[0])
            .map(|(p, q)| p.z - q.z)
            .fold(0.0, f64::max)
    };
    let (two, one) = (pushed(&both), pushed(&one_sided));
    assert!(
        two > 0.3 * edge,
        "the pressed petal moved out by {:.3} edges, one-sided {:.3}",
        two / edge,
        one / edge
    );
}

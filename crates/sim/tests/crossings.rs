//! No silent crossing (issue 35): every keyframe is checked for triangles
//! of an organ crossing another organ's, a part's or its own; the run stops
//! there naming them, or goes on with a warning where the caller chose.

mod common;

use anthesis_mesh::Mesh;
use anthesis_sim::crossing::{Crossed, OnCrossing};
use anthesis_sim::{Keyframe, Selection, SimError, Simulation};
use common::inner_driven_into_outer_by;

const KEYFRAMES: u32 = 20;

/// Two petals, the inner one driven by its joint (60 degrees over the
/// run) through the outer one while growing a third a step: a corner of
/// its tip passes through the outer petal within a few keyframes, though
/// every particle is held on its side.
fn jammed() -> anthesis_flower::Project {
    let mut project = inner_driven_into_outer_by(KEYFRAMES, true, 60.0);
    project.flower.templates[0].dg = 0.3;
    project
}

/// The organs of `keyframe` as one mesh, with each triangle's organ.
fn flower_mesh(sim: &Simulation, keyframe: &Keyframe) -> (Mesh, Vec<usize>) {
    let mut mesh = Mesh::default();
    let mut organ_of = Vec::new();
    for (i, positions) in keyframe.positions_in_world.iter().enumerate() {
        let first = mesh.positions.len() as u32;
        mesh.positions.extend_from_slice(positions);
        mesh.uvs.extend_from_slice(sim.uvs(i));
        for t in sim.triangles(i) {
            mesh.triangles.push(t.map(|v| v + first));
            organ_of.push(i);
        }
    }
    (mesh, organ_of)
}

/// Crossing pairs of triangles of different organs, by testing every
/// triangle against the others in `anthesis_bud` (independent of the
/// simulation's search).
fn crossings_between_organs(sim: &Simulation, keyframe: &Keyframe) -> usize {
    let (mesh, organ_of) = flower_mesh(sim, keyframe);
    anthesis_bud::self_intersections(&mesh)
        .into_iter()
        .filter(|[a, b]| organ_of[*a] != organ_of[*b])
        .count()
}

/// Steps `sim` to its end or its first error, keeping the bud and every
/// keyframe made.
fn run(sim: &mut Simulation) -> (Vec<Keyframe>, Option<SimError>) {
    let mut keyframes = vec![sim.bud()];
    while !sim.finished() {
        match sim.step(&|| false, &mut |_| {}) {
            Ok(k) => keyframes.push(k),
            Err(error) => return (keyframes, Some(error)),
        }
    }
    (keyframes, None)
}

#[test]
fn organs_driven_through_each_other_stop_the_run_at_the_first_crossing_keyframe() {
    let project = jammed();
    let mut sim = Simulation::new(&project, &Selection::All).expect("valid");
    let (keyframes, error) = run(&mut sim);
    let Some(SimError::Crossed(found)) = error else {
        panic!("expected a crossing, got {error:?}");
    };
    // The keyframes before it are kept, and are clean.
    assert_eq!(found.keyframe as usize, keyframes.len());
    assert!(found.keyframe >= 2, "crossed already at {}", found.keyframe);
    for k in &keyframes {
        assert_eq!(crossings_between_organs(&sim, k), 0, "keyframe {}", k.index);
    }
    // It names both organs and where on each.
    let (a, b, count) = &found.between[0];
    assert_eq!(found.between.len(), 1);
    assert_eq!(*count, found.pairs);
    let (
        Crossed::Organ {
            name: first,
            uv: uv_a,
            ..
        },
        Crossed::Organ {
            name: second,
            uv: uv_b,
            ..
        },
    ) = (a, b)
    else {
        panic!("organs expected: {a:?} {b:?}");
    };
    assert_eq!((first.as_str(), second.as_str()), ("inner", "outer"));
    for uv in [uv_a, uv_b] {
        assert!(
            (0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y),
            "{uv}"
        );
    }
    assert_eq!(found.organs, vec![0, 1]);
    // Clean in the bud: nothing said about it.
    assert!(!found.from_bud);
    let message = SimError::Crossed(found.clone()).to_string();
    assert!(
        message.starts_with(&format!("keyframe {}: `inner` at uv (", found.keyframe))
            && message.contains("passes through `outer` at uv (")
            && message.ends_with("the keyframes before it are kept"),
        "{message}"
    );
    // The same run told to go on: the crossing keyframe is the one found,
    // with as many crossing pairs as testing every pair of triangles finds.
    let mut warned = Simulation::new(&project, &Selection::All).expect("valid");
    warned.on_crossing(OnCrossing::Warn);
    let (all, warned_error) = run(&mut warned);
    assert!(all.len() > found.keyframe as usize);
    let first = &warned.crossings()[0];
    assert_eq!(first, found.as_ref());
    let crossing = &all[found.keyframe as usize];
    assert_eq!(crossings_between_organs(&warned, crossing), found.pairs);
    // Every later keyframe is reported too, in order.
    let reported: Vec<u32> = warned.crossings().iter().map(|c| c.keyframe).collect();
    let expected: Vec<u32> = (found.keyframe..all.len() as u32)
        .filter(|&k| crossings_between_organs(&warned, &all[k as usize]) > 0)
        .collect();
    assert_eq!(reported, expected);
    // A proxy's run does not look (its converged run does): the same
    // keyframes and the same end, nothing found, no stop at a crossing.
    let mut skipped = Simulation::new(&project, &Selection::All).expect("valid");
    skipped.on_crossing(OnCrossing::Skip);
    let (unchecked, error) = run(&mut skipped);
    assert_eq!(error, warned_error);
    assert!(skipped.crossings().is_empty());
    assert_eq!(unchecked.len(), all.len());
    for (u, w) in unchecked.iter().zip(&all) {
        assert_eq!(
            u.positions_in_world, w.positions_in_world,
            "keyframe {}",
            u.index
        );
    }
}

#[test]
fn organs_without_an_overlap_rule_keep_apart_and_run_clean() {
    // Driven into each other with no rule saying which lies inside: each
    // keeps the side it was on in the bud (issue 35), nothing crosses.
    let project = inner_driven_into_outer_by(10, false, 60.0);
    let mut sim = Simulation::new(&project, &Selection::All).expect("valid");
    let (keyframes, error) = run(&mut sim);
    assert_eq!(error, None);
    for k in &keyframes {
        assert_eq!(crossings_between_organs(&sim, k), 0, "keyframe {}", k.index);
    }
}

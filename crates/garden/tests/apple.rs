//! The apple flower of Qin and Chen 2006 §3–§4 (issue 13 item 3):
//! placed by the seed's own L-system, it opens in 100 keyframes, and at
//! every keyframe, checked geometrically rather than by trusting the
//! solver's contacts, no organ passes through another (or itself): no two
//! of the flat triangles shown cross, not even by a sliver where organs
//! touch, and no particle lies inside the stem or a stamen tube (the
//! winding number of each tube's closed surface).

use anthesis_bud::{crossing_depth, quality, self_intersections};
use anthesis_flower::parts::obstacles;
use anthesis_flower::structure::lsystem::LSystem;
use anthesis_garden::apple::{APPLE_LSYSTEM, APPLE_STEM, APPLE_UNITS, apple};
use anthesis_garden::flower_mesh;
use anthesis_mesh::nearest::winding_number;
use anthesis_sim::Selection;
use glam::DVec3;

/// The distance of `p` from the flower axis.
fn from_axis(p: DVec3) -> f64 {
    p.x.hypot(p.z)
}

#[test]
fn the_apple_is_the_seeds_lsystem_with_six_segments_of_calyx_petal_and_stamen() {
    let project = apple().expect("apple");
    let flower = &project.flower;
    let names: Vec<&str> = flower.organs.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names.len(), 12);
    for k in 1..=6 {
        assert_eq!(names[2 * k - 2], format!("calyx-{k}"));
        assert_eq!(names[2 * k - 1], format!("petal-{k}"));
    }
    // The productions are the seed's L-system (3), line for line.
    for line in [
        "p1: B → D/(60)D/(60)D/(60)D/(60)D/(60)D",
        "p2: D → [C][P][S]",
        "p3: A → F(lenA)",
        "p4: C → ~c",
        "p5: P → ~p",
        "p6: S → F(lenF)[-(18)F(lenF)][+(18)F(lenF)]",
    ] {
        assert!(APPLE_LSYSTEM.contains(line), "{line}");
    }
    let system = LSystem::parse(APPLE_LSYSTEM).expect("parses");
    assert_eq!(system.constant("lenA"), Some(500.0));
    // A stem of lenA, then per segment a stamen line and its two branches.
    let segments = flower.structure.as_ref().expect("structure").segments();
    assert_eq!(segments.len(), 1 + 6 * 3);
    let stem = &segments[0];
    assert!((stem.end - DVec3::new(0.0, APPLE_STEM, 0.0)).length() < 1e-9);
    assert!((stem.width - 25.0 * APPLE_UNITS).abs() < 1e-12);
    // Every organ stands on the stem's end; the six segments 60° apart.
    for organ in &flower.organs {
        assert!((organ.placement.position - stem.end).length() < 1e-9);
    }
    let facing: Vec<DVec3> = flower
        .organs
        .iter()
        .step_by(2)
        .map(|o| o.placement.orientation * DVec3::Z)
        .collect();
    for pair in facing.windows(2) {
        let angle = pair[0].angle_between(pair[1]).to_degrees();
        assert!((angle - 60.0).abs() < 1e-9, "{angle}");
    }
}

#[test]
fn the_apple_opens_without_any_organ_passing_through_another_or_a_tube() {
    let project = apple().expect("apple");
    let tubes = obstacles(&project.flower);
    assert_eq!(tubes.len(), 19, "the stem and 18 stamen lines");
    let petals: Vec<usize> = (0..project.flower.organs.len())
        .filter(|&i| project.flower.organs[i].name.starts_with("petal"))
        .collect();
    let mut crossings = Vec::new();
    let mut inside = Vec::new();
    let mut reach = Vec::new();
    let mut keyframes = 0;
    anthesis_sim::run(&project, &Selection::All, &mut |_, keyframe| {
        keyframes += 1;
        let (mesh, organ_of) = flower_mesh(&project, &keyframe.positions_in_world);
        let edge = quality(&mesh).mean_edge;
        for pair in self_intersections(&mesh) {
            let depth = crossing_depth(&mesh, pair) / edge;
            let [a, b] = pair.map(|t| organ_of[t]);
            crossings.push((keyframe.index, a, b, depth));
        }
        for tube in &tubes {
            let surface = tube.positions_at(keyframe.index);
            let count = keyframe
                .positions_in_world
                .iter()
                .flatten()
                .filter(|p| winding_number(**p, &surface, &tube.mesh.triangles) > 0.5)
                .count();
            if count > 0 {
                inside.push((keyframe.index, tube.name.clone(), count));
            }
        }
        // How far the petals reach from the axis, at their farthest.
        let farthest = petals
            .iter()
            .flat_map(|&i| &keyframe.positions_in_world[i])
            .map(|p| from_axis(*p))
            .fold(0.0, f64::max);
        reach.push(farthest);
    })
    .unwrap_or_else(|error| panic!("{error}"));
    assert_eq!(keyframes, 101, "the bud and 100 keyframes");
    assert!(
        crossings.is_empty(),
        "(keyframe, organ, organ, depth in edges): {crossings:?}"
    );
    assert!(inside.is_empty(), "particles inside tubes: {inside:?}");
    // It opens: the petals end spread to more than half again as far from
    // the axis as in the closed bud.
    let (bud, open) = (reach[0], reach[reach.len() - 1]);
    assert!(
        open > 1.5 * bud,
        "the petals reach {bud:.1} in the bud, {open:.1} open"
    );
}

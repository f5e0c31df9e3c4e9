//! A two-state organ in a run (issue 15 item 1): organs of a template with
//! a two-state animation are not grown; each keyframe is the two-state
//! in-between at that keyframe, placed like any organ. They are kinematic:
//! the growing organs get contacts against them and they never give way.

mod common;

use anthesis_flower::{Project, TwoStateAnimation, joint_angle_after};
use anthesis_sim::Selection;
use anthesis_twostate::{GrowthFunction, TwoState, VelocityCurve};
use common::{inner_driven_into_outer_by, particles_over, run_all, run_all_warned};
use glam::{DQuat, DVec3};

const KEYFRAMES: u32 = 20;

/// The outer petal's bud curled outwards (more towards the tip) and
/// widened, in the template frame: its base (v near 0) stays put.
fn opened(bud: &anthesis_mesh::Mesh) -> Vec<DVec3> {
    bud.positions
        .iter()
        .zip(&bud.uvs)
        .map(|(p, uv)| {
            let widened = DVec3::new(p.x * (1.0 + 0.25 * uv.y), p.y, p.z);
            DQuat::from_rotation_x(0.3 * uv.y * uv.y) * widened
        })
        .collect()
}

/// The inner petal grows and is driven (45 degrees) into the outer one, which opens by
/// its two-state animation (g = 6 over the whole run, the velocity curve a
/// polyline) while its joint schedule tilts it.
fn project() -> Project {
    let mut project = inner_driven_into_outer_by(KEYFRAMES, true, 45.0);
    let outer = &mut project.flower.templates[1];
    outer.two_state = Some(TwoStateAnimation {
        open: opened(&outer.mesh),
        growth: GrowthFunction {
            g: 6.0,
            duration: f64::from(KEYFRAMES),
        },
        velocity: VelocityCurve::Points(vec![[0.0, 0.0], [0.5, 0.7], [1.0, 1.0]]),
    });
    project
}

#[test]
fn a_two_state_organ_is_its_in_betweens_placed_and_the_growing_organ_keeps_off_it() {
    let project = project();
    let (keyframes, error) = run_all(&project, &Selection::All);
    assert!(error.is_none(), "{error:?}");
    assert_eq!(keyframes.len(), KEYFRAMES as usize + 1);

    let outer = &project.flower.templates[1];
    let placement = project.flower.organs[1].placement;
    let animation = outer.two_state.as_ref().expect("two-state");
    let base = outer.base_region.particles(&outer.mesh);
    let mut two = TwoState::new(&outer.mesh, &animation.open, &base).expect("valid");
    two.growth = animation.growth;
    two.velocity = animation.velocity.clone();
    let placed = |shape: &[DVec3], step: u32| -> Vec<DVec3> {
        let extra = joint_angle_after(&outer.joint_schedule, step);
        shape
            .iter()
            .map(|p| placement.world_from_template(*p, extra))
            .collect()
    };
    let distance = |a: &[DVec3], b: &[DVec3]| {
        a.iter()
            .zip(b)
            .map(|(p, q)| p.distance(*q))
            .fold(0.0, f64::max)
    };
    // Every keyframe after the bud is the crate's in-between, placed: the
    // growing organ pressing on it moved nothing.
    for keyframe in &keyframes[1..] {
        let want = placed(&two.shape_at(f64::from(keyframe.index)), keyframe.index);
        let got = &keyframe.positions_in_world[1];
        assert!(
            distance(got, &want) < 1e-12,
            "keyframe {}: {:.3e} from the in-between",
            keyframe.index,
            distance(got, &want)
        );
    }
    // The bud is the bud, and the last keyframe the open shape, placed.
    assert!(
        distance(
            &keyframes[0].positions_in_world[1],
            &placed(&outer.mesh.positions, 0)
        ) < 1e-12
    );
    let length = anthesis_flower::scale::organ_length(&outer.mesh);
    let last = &keyframes[KEYFRAMES as usize].positions_in_world[1];
    let miss = distance(last, &placed(&animation.open, KEYFRAMES));
    assert!(
        miss < 1e-9 * length,
        "last keyframe {miss:.3e} from the open shape (organ length {length})"
    );
    // It did open: the tip moved well away from where the bud's tip is
    // carried by the joint schedule alone.
    let tip_moved = distance(last, &placed(&outer.mesh.positions, KEYFRAMES));
    assert!(tip_moved > 0.1 * length, "opened by {tip_moved}");

    // The growing organ grew, and kept on the inner side of the opening
    // one at every keyframe, pressing on it on the way.
    let inner = &project.flower.templates[0];
    let grown = distance(
        &keyframes[KEYFRAMES as usize].positions_in_world[0],
        &keyframes[0].positions_in_world[0],
    );
    assert!(grown > 0.05 * length, "the inner organ moved by {grown}");
    let inner_base = inner.base_region.particles(&inner.mesh);
    let offset = project.settings.collision_offset;
    let mut over_some = false;
    for keyframe in &keyframes {
        let over = particles_over(
            &keyframe.positions_in_world[0],
            &keyframe.positions_in_world[1],
            &outer.mesh.triangles,
        );
        over_some |= !over.is_empty();
        for s in over
            .iter()
            .filter(|s| !inner_base.contains(&(s.particle as u32)))
        {
            assert!(
                s.along_normal >= offset - 1e-6,
                "keyframe {}: inner particle {} is {:.4} along the inner normal of the two-state organ (needs {offset})",
                keyframe.index,
                s.particle,
                s.along_normal
            );
        }
    }
    assert!(over_some, "the inner organ should lie along the outer one");
    assert!(
        keyframes.iter().any(|k| k.stats.contact_particles > 0),
        "the inner organ was driven into the two-state one and should touch it"
    );

    // Export still works: a .glb of both organs over every keyframe.
    let organs = [0, 1];
    let tracks = anthesis_export::flower_tracks(
        &project.flower,
        &organs,
        keyframes.iter().map(|k| k.positions_in_world.as_slice()),
        0,
    )
    .expect("tracks");
    assert_eq!(tracks[1].keyframes.len(), KEYFRAMES as usize + 1);
    assert_eq!(&tracks[1].keyframes[KEYFRAMES as usize], last);
    let glb = anthesis_export::glb_bytes(
        &tracks,
        &anthesis_export::GlbOptions::default(),
        &mut |_| {},
    )
    .expect("glb");
    assert_eq!(&glb[..4], b"glTF");
}

#[test]
fn without_the_overlap_the_growing_organ_keeps_the_side_it_started_on() {
    // The same run with no overlap rule: the organs keep the side of each
    // other they were on in the bud (issue 35), the inner one inside.
    let mut project = project();
    project.flower.overlaps.clear();
    let (keyframes, crossings, error) = run_all_warned(&project, &Selection::All);
    assert!(error.is_none(), "{error:?}");
    assert_eq!(crossings, Vec::new());
    let outer = &project.flower.templates[1];
    let over: Vec<f64> = keyframes
        .iter()
        .flat_map(|k| {
            particles_over(
                &k.positions_in_world[0],
                &k.positions_in_world[1],
                &outer.mesh.triangles,
            )
        })
        .map(|s| s.along_normal)
        .collect();
    assert!(!over.is_empty());
    let deepest = over.iter().copied().fold(f64::INFINITY, f64::min);
    assert!(deepest > 0.0, "deepest {deepest}");
}

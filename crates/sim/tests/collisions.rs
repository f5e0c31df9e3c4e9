//! Collisions (paper §5.3): two organs grown into each other end with no
//! particle on the wrong side.

mod common;

use anthesis_sim::Selection;
use common::{inner_driven_into_outer, particles_over, run_all};

const KEYFRAMES: u32 = 30;

#[test]
fn an_inner_organ_driven_into_an_outer_one_stays_on_its_inner_side() {
    let project = inner_driven_into_outer(KEYFRAMES, true);
    let offset = project.settings.collision_offset;
    let (keyframes, error) = run_all(&project, &Selection::All);
    assert_eq!(error, None, "the run with collisions failed");
    assert_eq!(keyframes.len(), KEYFRAMES as usize + 1);

    let inner_triangles = &project.flower.templates[0].mesh.triangles;
    let outer_triangles = &project.flower.templates[1].mesh.triangles;
    let mut closest = f64::INFINITY;
    for keyframe in &keyframes {
        let [inner, outer] = [&keyframe.positions[0], &keyframe.positions[1]];
        // Inner particles over the outer organ lie on its inner side,
        // at least `offset` from it.
        let over_outer = particles_over(inner, outer, outer_triangles);
        assert!(
            !over_outer.is_empty(),
            "keyframe {}: the inner organ should lie along the outer one",
            keyframe.index
        );
        for s in &over_outer {
            assert!(
                s.along_normal >= offset - 1e-6,
                "keyframe {}: inner particle {} is {:.4} along the inner normal of outer particle {} (needs {offset})",
                keyframe.index,
                s.particle,
                s.along_normal,
                s.nearest
            );
            closest = closest.min(s.along_normal);
        }
        // Outer particles over the inner organ lie on its outer side.
        for s in particles_over(outer, inner, inner_triangles) {
            assert!(
                -s.along_normal >= offset - 1e-6,
                "keyframe {}: outer particle {} is {:.4} inside inner particle {} (needs {offset} outside)",
                keyframe.index,
                s.particle,
                s.along_normal,
                s.nearest
            );
        }
    }
    // The organs did meet (their bases start 1.5 apart, and without the
    // rule the same run cuts through): otherwise the test would prove nothing.
    assert!(
        closest < 0.15,
        "the organs never came closer than {closest:.3}; the test geometry no longer collides"
    );
    for k in &keyframes {
        assert!(k.positions.iter().flatten().all(|p| p.is_finite()));
    }
}

#[test]
fn without_the_overlap_rule_the_same_organs_cut_through_each_other() {
    // The same geometry with no overlap rule: the check above must fail,
    // or it could not catch a broken collision handler.
    let project = inner_driven_into_outer(KEYFRAMES, false);
    let offset = project.settings.collision_offset;
    let (keyframes, error) = run_all(&project, &Selection::All);
    assert_eq!(error, None);
    let last = keyframes.last().expect("keyframes");
    let outer_triangles = &project.flower.templates[1].mesh.triangles;
    let wrong: Vec<f64> = particles_over(&last.positions[0], &last.positions[1], outer_triangles)
        .iter()
        .map(|s| s.along_normal)
        .filter(|&d| d < offset - 1e-6)
        .collect();
    assert!(
        wrong.len() >= 10,
        "only {} inner particles ended on the wrong side",
        wrong.len()
    );
    let deepest = wrong.iter().copied().fold(f64::INFINITY, f64::min);
    // Clearly through, not just short of the offset.
    assert!(deepest < -0.1, "the deepest was only {deepest:.3}");
    assert!(last.stats.pushed_particles == 0);
}

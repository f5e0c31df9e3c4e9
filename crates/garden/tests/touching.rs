//! Flowers that touch (paper §5.3): the Maite Lady funnel keeps its
//! contorted overlap, so its petals press on their neighbours through the
//! opening. Run whole, a petal ends elsewhere than the same petal run alone,
//! the simulator reports contacts, and, checked geometrically (independent
//! of the simulator's own tracking), no particle ends on the wrong side of
//! a neighbour.

use anthesis_garden::flowers::{self, Cultivar};
use anthesis_garden::shape::{organ_shape, side_check};
use anthesis_sim::{Keyframe, Selection};
use glam::DVec3;

fn run(project: &anthesis_flower::Project, selection: &Selection) -> Vec<Keyframe> {
    let mut keyframes = Vec::new();
    let result = anthesis_sim::run(project, selection, &mut |_, keyframe| {
        keyframes.push(keyframe.clone());
    });
    if let Err(error) = result {
        panic!("{}: {error}", project.name);
    }
    keyframes
}

#[test]
fn the_funnels_petals_press_on_each_other_and_stay_on_their_sides() {
    let project = flowers::eustoma(Cultivar::MaiteLady).expect("Eustoma");
    let template = &project.flower.templates[0];
    let mesh = &template.mesh;
    let whole = run(&project, &Selection::All);
    let alone = run(&project, &Selection::Only(0));
    assert_eq!(whole.len(), alone.len());

    // The simulator reports contacts over a good part of the opening, and
    // pushes particles back.
    let touching = whole
        .iter()
        .filter(|k| k.stats.contact_particles > 0)
        .count();
    let pushed = whole
        .iter()
        .filter(|k| k.stats.pushed_particles > 0)
        .count();
    eprintln!("{touching} keyframes with contacts, {pushed} with pushed particles");
    assert!(touching >= 20, "contacts in only {touching} keyframes");
    assert!(pushed >= 10, "particles pushed in only {pushed} keyframes");

    // Collisions change the shape: petal 0 run whole ends away from petal 0
    // run alone by more than 2 % of its midrib length.
    let last_whole = &whole.last().expect("keyframes").positions_in_world[0];
    let last_alone = &alone.last().expect("keyframes").positions_in_world[0];
    let apart = last_whole
        .iter()
        .zip(last_alone)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f64::max);
    let length = organ_shape(mesh, last_alone)
        .expect("measurable")
        .midrib_length;
    assert!(
        apart > 0.02 * length,
        "whole and alone differ by only {apart:.3} (midrib {length:.1})"
    );

    // No particle on the wrong side of a neighbour: each petal's right side
    // lies beneath (on the inner side of) its right-hand neighbour, which
    // lies over it. Base particles are placed by attachment, not collision.
    let base = template.base_region.particles(mesh);
    let skip: Vec<bool> = (0..mesh.vertex_count() as u32)
        .map(|i| base.contains(&i))
        .collect();
    let reach = 1.0;
    let mut checked = 0;
    for keyframe in whole.iter().step_by(5) {
        let petals: &[Vec<DVec3>] = &keyframe.positions_in_world;
        for i in 0..petals.len() {
            let next = (i + 1) % petals.len();
            let beneath = side_check(&petals[i], &skip, &petals[next], mesh, 1.0, reach, 1e-6)
                .expect("measurable");
            let over = side_check(&petals[next], &skip, &petals[i], mesh, -1.0, reach, 1e-6)
                .expect("measurable");
            for (what, check) in [("beneath", beneath), ("over", over)] {
                assert_eq!(
                    check.wrong, 0,
                    "keyframe {}: petal {i}/{next} {what}: {check:?}",
                    keyframe.index
                );
                checked += check.over;
            }
        }
    }
    assert!(
        checked > 1000,
        "only {checked} particles lay over a neighbour"
    );
}

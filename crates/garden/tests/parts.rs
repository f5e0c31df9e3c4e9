//! The built-in flowers with their stamens and pistils (issue 13 item 4):
//! every keyframe of a whole run, checked geometrically (the winding
//! number of each part's closed surface, independent of the simulator's
//! contacts), has no organ particle inside a stamen, a pistil or the stem,
//! and the stamens spread as the flower opens.

use anthesis_flower::parts::{PartShape, obstacles};
use anthesis_garden::flowers::{self, Cultivar};
use anthesis_mesh::nearest::winding_number;
use anthesis_sim::Selection;
use glam::DVec3;

/// Particles inside a part at each keyframe, and how far the stamens'
/// anthers ended from the axis compared with the bud.
fn check(project: &anthesis_flower::Project) -> (Vec<(u32, String, usize)>, f64) {
    let components = obstacles(&project.flower);
    assert!(!components.is_empty(), "{}: no parts", project.name);
    let mut inside = Vec::new();
    anthesis_sim::run(project, &Selection::All, &mut |_, keyframe| {
        for component in &components {
            let surface = component.positions_at(keyframe.index);
            let (lo, hi) = surface.iter().fold(
                (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
                |(lo, hi), p| (lo.min(*p), hi.max(*p)),
            );
            let count = keyframe
                .positions_in_world
                .iter()
                .flatten()
                .filter(|p| p.cmpge(lo).all() && p.cmple(hi).all())
                .filter(|p| winding_number(**p, &surface, &component.mesh.triangles) > 0.5)
                .count();
            if count > 0 {
                inside.push((keyframe.index, component.name.clone(), count));
            }
        }
    })
    .unwrap_or_else(|error| panic!("{}: {error}", project.name));
    let stamen = project
        .flower
        .parts
        .iter()
        .find(|p| matches!(p.shape, PartShape::Stamen { .. }))
        .expect("stamens");
    let reach = |step: u32| {
        components
            .iter()
            .filter(|c| c.name == stamen.instance_name(0))
            .flat_map(|c| c.positions_at(step))
            .map(|p| p.x.hypot(p.z))
            .fold(0.0, f64::max)
    };
    (inside, reach(project.settings.keyframes) / reach(0))
}

#[test]
fn the_lily_opens_around_its_stamens_and_pistil_without_passing_through() {
    let project = flowers::lily().expect("lily");
    let (inside, spread) = check(&project);
    assert!(inside.is_empty(), "particles inside parts: {inside:?}");
    assert!(spread > 2.0, "the stamens spread {spread} times as far");
}

#[test]
fn a_eustoma_opens_around_its_stamens_and_pistil_without_passing_through() {
    let project = flowers::eustoma(Cultivar::MellowYellow).expect("Eustoma");
    let (inside, spread) = check(&project);
    assert!(inside.is_empty(), "particles inside parts: {inside:?}");
    assert!(spread > 1.3, "the stamens spread {spread} times as far");
}

//! The crossing check that ends every keyframe (issue 35), alone: the
//! default lily is run once from the bud (not timed), keeping every
//! keyframe's organ positions, then `anthesis_mesh::crossing` searches all
//! of them in turn with one search (its hierarchies built once and refitted
//! to each keyframe, as in a run), every organ against the others and
//! itself. The parts are left out (their triangles lie beside almost every
//! organ's box).
//!
//! `cargo bench -p anthesis-garden --bench crossing_check`

use std::hint::black_box;

use anthesis_garden::flowers::{EDGE_SCALE, flower_at_resolution};
use anthesis_mesh::crossing::{Body, CrossingSearch};
use anthesis_sim::Selection;
use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec3;

fn crossing_check(c: &mut Criterion) {
    let project = match flower_at_resolution("lily", EDGE_SCALE) {
        Some(Ok(project)) => project,
        _ => panic!("the default lily does not build"),
    };
    let mut keyframes: Vec<Vec<Vec<DVec3>>> = Vec::new();
    if let Err(error) = anthesis_sim::run(&project, &Selection::All, &mut |_, keyframe| {
        keyframes.push(keyframe.positions_in_world.clone());
    }) {
        panic!("the lily: {error}");
    }
    let triangles: Vec<&[[u32; 3]]> = (0..project.flower.organs.len())
        .map(|i| project.flower.template_of(i).mesh.triangles.as_slice())
        .collect();
    let mut search = CrossingSearch::new();
    let mut group = c.benchmark_group("crossing_check");
    group.sample_size(10);
    group.bench_function(
        format!("lily_{}_keyframes_all_organs", keyframes.len()),
        |b| {
            b.iter(|| {
                let mut found = 0;
                for organs in &keyframes {
                    let bodies: Vec<Body<'_>> = organs
                        .iter()
                        .zip(&triangles)
                        .map(|(positions, triangles)| Body {
                            positions,
                            triangles,
                        })
                        .collect();
                    found += search.find(black_box(&bodies), &|_, _| true).len();
                }
                assert_eq!(found, 0, "the default lily crosses");
                found
            })
        },
    );
    group.finish();
}

criterion_group!(benches, crossing_check);
criterion_main!(benches);

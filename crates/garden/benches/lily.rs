//! The built-in Asiatic lily, 100 keyframes (DESIGN.md §6: a single lily
//! petal and the whole lily, next to the paper's 2.5 and 11.5 minutes).
//! Each iteration runs from the bud to the last keyframe.
//!
//! `cargo bench -p anthesis-garden --bench lily`

use std::hint::black_box;

use anthesis_flower::Project;
use anthesis_sim::{Selection, run};
use criterion::{Criterion, criterion_group, criterion_main};

/// Runs `selection` of `project` to the end and returns the last keyframe's
/// energy (so the work cannot be optimised away). A failed run is a broken
/// benchmark.
fn simulate(project: &Project, selection: &Selection) -> f64 {
    let mut energy = 0.0;
    if let Err(error) = run(project, selection, &mut |_, keyframe| {
        energy = keyframe.stats.energy;
    }) {
        panic!("{}: {error}", project.name);
    }
    energy
}

fn lily(c: &mut Criterion) {
    let project = match anthesis_garden::builtin_lily() {
        Ok(project) => project,
        Err(error) => panic!("the built-in lily does not load: {error}"),
    };
    let petal = project
        .flower
        .organs
        .iter()
        .position(|o| project.flower.templates[o.template].name.contains("petal"))
        .unwrap_or_else(|| panic!("the lily has no petal"));
    let keyframes = project.settings.keyframes;
    c.bench_function(&format!("lily_petal_{keyframes}_keyframes"), |b| {
        b.iter(|| simulate(black_box(&project), &Selection::Only(petal)))
    });
    c.bench_function(&format!("lily_whole_flower_{keyframes}_keyframes"), |b| {
        b.iter(|| simulate(black_box(&project), &Selection::All))
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = lily
}
criterion_main!(benches);

//! How long 100 keyframes take (the project's speed target: a single
//! lily-sized petal and a whole flower; the paper took 11.5 minutes for its lily). Each
//! iteration runs a whole project from the bud to the last keyframe.
//!
//! `cargo bench -p anthesis-sim --bench growth`

use std::hint::black_box;

use anthesis_flower::Project;
use anthesis_sim::fixtures::whorl;
use anthesis_sim::{Selection, run};
use criterion::{Criterion, criterion_group, criterion_main};

/// Runs `project` to the end and returns the last keyframe's energy (so the
/// work cannot be optimised away). A failed run is a broken benchmark.
fn simulate(project: &Project) -> f64 {
    let mut energy = 0.0;
    if let Err(error) = run(project, &Selection::All, &mut |_, keyframe| {
        energy = keyframe.stats.energy;
    }) {
        panic!("{}: {error}", project.name);
    }
    energy
}

fn growth(c: &mut Criterion) {
    let benches = [
        // About 392 particles, the size of the paper's lily petal (388).
        ("one_petal_100_keyframes", whorl(1, 14, 28, 100)),
        // Three petals inside three sepals, with overlap rules between
        // neighbours.
        ("six_organs_collisions_100_keyframes", whorl(6, 14, 28, 100)),
        // About 4050 particles: ten times the paper's petal.
        ("petal_4k_100_keyframes", whorl(1, 45, 90, 100)),
    ];
    for (name, project) in &benches {
        c.bench_function(name, |b| b.iter(|| simulate(black_box(project))));
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = growth
}
criterion_main!(benches);

//! Smooth exports of the built-in lily (issue 11 item 5): its 100
//! keyframes (simulated once, outside the timing) turned into render
//! meshes of two levels of Loop subdivision, and the .glb of those written
//! dense and with meshopt. The sizes are printed once before the timings.
//!
//! `cargo bench -p anthesis-garden --bench export`

use std::hint::black_box;

use anthesis_export::{Encoding, GlbOptions, Track, flower_tracks, glb_bytes};
use anthesis_sim::{Selection, run};
use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec3;

const LEVEL: u32 = 2;

fn export(c: &mut Criterion) {
    let project = match anthesis_garden::builtin_lily() {
        Ok(project) => project,
        Err(error) => panic!("the built-in lily does not load: {error}"),
    };
    // The bud and every keyframe.
    let mut frames: Vec<Vec<Vec<DVec3>>> = Vec::new();
    let sim = match run(&project, &Selection::All, &mut |_, k| {
        frames.push(k.positions_in_world.clone())
    }) {
        Ok(sim) => sim,
        Err(error) => panic!("the lily does not open: {error}"),
    };
    let organs = Selection::All.organs(sim.organs().len());
    let tracks_at = |level: u32| -> Vec<Track> {
        match flower_tracks(
            &project.flower,
            &organs,
            frames.iter().map(Vec::as_slice),
            level,
        ) {
            Ok(tracks) => tracks,
            Err(error) => panic!("no tracks: {error}"),
        }
    };
    let options = |encoding: Encoding| GlbOptions {
        encoding,
        ..GlbOptions::default()
    };
    let encode = |tracks: &[Track], encoding: Encoding| -> Vec<u8> {
        match glb_bytes(tracks, &options(encoding), &mut |_| {}) {
            Ok(bytes) => bytes,
            Err(error) => panic!("no .glb: {error}"),
        }
    };
    let smooth = tracks_at(LEVEL);
    let vertices = |tracks: &[Track]| tracks.iter().map(|t| t.uvs.len()).sum::<usize>();
    println!(
        "lily, {} keyframes: {} vertices as simulated, {} at level {LEVEL}; level {LEVEL} .glb \
         dense {} bytes, meshopt {} bytes",
        frames.len(),
        vertices(&tracks_at(0)),
        vertices(&smooth),
        encode(&smooth, Encoding::Dense).len(),
        encode(&smooth, Encoding::Meshopt).len(),
    );
    c.bench_function("lily_subdivide_level_2", |b| {
        b.iter(|| tracks_at(black_box(LEVEL)))
    });
    c.bench_function("lily_level_2_glb_dense", |b| {
        b.iter(|| encode(black_box(&smooth), Encoding::Dense))
    });
    c.bench_function("lily_level_2_glb_meshopt", |b| {
        b.iter(|| encode(black_box(&smooth), Encoding::Meshopt))
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = export
}
criterion_main!(benches);

//! Peak memory of a run, for fitting `anthesis_sim::memory`: `ORGANS`
//! organs of `COLUMNS x ROWS` particles, `KEYFRAMES` keyframes, every
//! keyframe kept (as the command line keeps them). Measure with
//!
//! ```text
//! cargo build --release -p anthesis-sim --example memory_probe
//! /usr/bin/time -v target/release/examples/memory_probe ORGANS COLUMNS ROWS KEYFRAMES
//! ```
//!
//! and read "Maximum resident set size"; the probe prints the triangle
//! count and the model's estimate beside it.
fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|s| s.parse().ok())
        .collect();
    let organs = args.first().copied().unwrap_or(1);
    let columns = args.get(1).copied().unwrap_or(28);
    let rows = args.get(2).copied().unwrap_or(14);
    let keyframes = args.get(3).copied().unwrap_or(1) as u32;
    let project = anthesis_sim::fixtures::whorl(organs, columns, rows, keyframes);
    let selection = anthesis_sim::Selection::All;
    let mut kept = Vec::new();
    let result = anthesis_sim::run(&project, &selection, &mut |_, keyframe| {
        kept.push(keyframe.positions_in_world.clone());
    });
    let triangles: usize = (0..project.flower.organs.len())
        .map(|i| project.flower.template_of(i).mesh.triangle_count())
        .sum();
    println!(
        "organs {organs} triangles {triangles} keyframes_kept {} run {}",
        kept.len(),
        match &result {
            Ok(_) => "ok".to_string(),
            Err(error) => error.to_string(),
        },
    );
}

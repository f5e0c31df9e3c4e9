//! The scaling table of the README: the built-in lily remeshed to about
//! 0.4k, 1.5k, 4k and 10k particles per petal, one petal alone and the whole
//! flower, 100 keyframes: seconds, Newton iterations per keyframe,
//! factorisations and peak memory.
//!
//! ```text
//! cargo run --release -p anthesis-garden --example scaling
//! cargo run --release -p anthesis-garden --example scaling -- --particles 400,1500
//! ```
//!
//! Each row runs in a child process of its own, so that its peak memory
//! (`VmHWM` of `/proc/self/status`) is that row's alone.
use std::process::Command;
use std::time::Instant;

use anthesis_garden::flowers::{EDGE_SCALE, flower_at_resolution};
use anthesis_sim::{Selection, run};

/// Petal particles of the built-in lily at `EDGE_SCALE` (measured with
/// `anthesis info`); particles grow as the inverse square of the edge.
const DEFAULT_PETAL_PARTICLES: f64 = 1016.0;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(at) = args.iter().position(|a| a == "--row") {
        let scale: f64 = args[at + 1].parse().expect("an edge scale");
        row(scale, args[at + 2] == "whole");
        return;
    }
    let sizes: Vec<f64> = match args.iter().position(|a| a == "--particles") {
        Some(at) => args[at + 1]
            .split(',')
            .map(|v| v.parse().expect("a particle count"))
            .collect(),
        None => vec![400.0, 1500.0, 4000.0, 10000.0],
    };
    println!(
        "| particles per petal | run | organs | particles | seconds | Newton iterations per keyframe | factorisations | peak memory |"
    );
    println!("|---:|---|---:|---:|---:|---:|---:|---:|");
    let me = std::env::current_exe().expect("the example's own path");
    for size in sizes {
        let scale = EDGE_SCALE * (DEFAULT_PETAL_PARTICLES / size).sqrt();
        for what in ["petal", "whole"] {
            let output = Command::new(&me)
                .args(["--row", &scale.to_string(), what])
                .output()
                .expect("the row runs");
            if !output.status.success() {
                println!(
                    "| {size} | {what} | failed: {} |",
                    String::from_utf8_lossy(&output.stderr).trim()
                );
                continue;
            }
            print!("| {size} {}", String::from_utf8_lossy(&output.stdout));
        }
    }
}

/// One row: the lily at `edge_scale`, its first petal alone or whole.
fn row(edge_scale: f64, whole: bool) {
    let project = flower_at_resolution("lily", edge_scale)
        .expect("the lily has a builder")
        .expect("the lily builds");
    let selection = if whole {
        Selection::All
    } else {
        Selection::Only(0)
    };
    let organs = selection.organs(project.flower.organs.len());
    let particles: usize = organs
        .iter()
        .map(|&i| project.flower.template_of(i).mesh.vertex_count())
        .sum();
    let petal = project.flower.template_of(0).mesh.vertex_count();
    let mut iterations = 0u64;
    let started = Instant::now();
    let sim = run(&project, &selection, &mut |_, k| {
        iterations += u64::from(k.stats.iterations)
    })
    .expect("the run converges");
    let seconds = started.elapsed().as_secs_f64();
    let keyframes = f64::from(project.settings.keyframes);
    println!(
        "({petal}) | {} | {} | {particles} | {seconds:.2} | {:.2} | {} | {} MiB |",
        if whole { "whole lily" } else { "one petal" },
        organs.len(),
        iterations as f64 / keyframes,
        sim.factorisations(),
        peak_mib(),
    );
}

/// The peak resident memory of this process so far, in MiB.
fn peak_mib() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|line| line.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        .map_or(0, |kib| kib / 1024)
}

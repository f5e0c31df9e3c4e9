//! Refinement study: runs one organ (or the whole flower) of a default
//! flower at several mesh resolutions and prints how far each run's final
//! shape lies from the finest one.
//!
//!   cargo run --release -p anthesis-garden --example refine -- FLOWER [SCALES] [--whole]
//!
//! SCALES: comma-separated edge scales (default 1,0.707,0.5; 0.5 is about
//! four times the particles).
use std::time::Instant;

use anthesis_garden::flowers::flower_at_resolution;
use anthesis_garden::shape::{UvSampler, organ_shape};
use anthesis_sim::{Selection, run};
use glam::{DVec2, DVec3};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map_or("lily", String::as_str);
    let scales: Vec<f64> = args
        .get(1)
        .filter(|a| !a.starts_with("--"))
        .map_or("1,0.707,0.5", String::as_str)
        .split(',')
        .map(|s| s.parse().expect("scale"))
        .collect();
    let whole = args.iter().any(|a| a == "--whole");
    let selection = if whole {
        Selection::All
    } else {
        Selection::Only(0)
    };
    let mut results = Vec::new();
    for &scale in &scales {
        let mut project = flower_at_resolution(name, scale)
            .expect("known flower")
            .expect("builds");
        if args.iter().any(|a| a == "--paper") {
            project.settings.model = anthesis_physics::Model::Paper;
        }
        if args.iter().any(|a| a == "--from-rest") {
            project.settings.bend_base = anthesis_physics::BendBase::RestAngle;
        }
        let mesh = project.flower.templates[0].mesh.clone();
        let started = Instant::now();
        let mut last = Vec::new();
        let outcome = run(&project, &selection, &mut |_, k| {
            last = k.positions_in_world[0].clone();
        });
        let seconds = started.elapsed().as_secs_f64();
        if let Err(e) = outcome {
            println!("scale {scale}: {e}");
            continue;
        }
        let shape = organ_shape(&mesh, &last).expect("shape");
        let sampler = UvSampler::new(&mesh);
        let probes: Vec<DVec3> = [(0.5, 1.0), (0.5, 0.5), (0.2, 0.7), (0.8, 0.7)]
            .iter()
            .map(|&(u, v)| sampler.point(&last, DVec2::new(u, v)).expect("probe"))
            .collect();
        println!(
            "scale {scale:5.3}: {:5} particles {:6.2} s  turning {:7.1}°  angles {:6.1} {:6.1} {:6.1}  cupping {:+.3}  length {:.2}",
            mesh.vertex_count(),
            seconds,
            shape.midrib_turning_deg,
            shape.midrib_angles_deg[0],
            shape.midrib_angles_deg[1],
            shape.midrib_angles_deg[2],
            shape.cupping,
            shape.midrib_length
        );
        results.push((scale, mesh.vertex_count(), probes, shape.midrib_length));
    }
    if let Some((_, n, finest, length)) = results.last().cloned() {
        println!("distance to the finest run ({n} particles), over its midrib length {length:.2}:");
        for (scale, count, probes, _) in &results {
            let d: Vec<String> = probes
                .iter()
                .zip(&finest)
                .map(|(a, b)| format!("{:5.1} %", 100.0 * a.distance(*b) / length))
                .collect();
            println!(
                "  scale {scale:5.3} ({count:5} particles): tip {}  mid {}  lamina {} {}",
                d[0], d[1], d[2], d[3]
            );
        }
    }
}

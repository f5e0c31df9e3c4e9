//! Convergence study of a default flower: runs it (one organ, or the whole
//! flower with `--whole`) under several resolutions, time steps or solver
//! tolerances and prints how far each run's final shape lies from the last
//! (the most accurate) one, as a percentage of its midrib length.
//!
//! ```text
//! cargo run --release -p anthesis-garden --example refine -- FLOWER [--scales 1,0.6,0.3]
//! cargo run --release -p anthesis-garden --example refine -- FLOWER --keyframes 50,100,200
//! cargo run --release -p anthesis-garden --example refine -- FLOWER --tolerances 1e-5,1e-6,1e-8
//! cargo run --release -p anthesis-garden --example refine -- FLOWER --proxy
//! ```
//!
//! `--scales`: mesh edge as a fraction of Table 1's (the default flowers use
//! `EDGE_SCALE`; half of it is four times the particles). `--keyframes N`:
//! the same opening in N steps (`anthesis_garden::retime::in_keyframes`:
//! dg, time keys, joint and part schedules scaled so that dg·N and their
//! place in the opening stay fixed). `--tolerances`:
//! the solver's relative tolerance. `--proxy`: the window's proxy (every
//! template at `anthesis_flower::resolution::proxy_mesh`) against the
//! default resolution it stands for. Add `--whole` for the whole flower
//! (organ 0 is measured), `--paper` for the paper's model.
use std::time::Instant;

use anthesis_flower::Project;
use anthesis_garden::flowers::{EDGE_SCALE, flower_at_resolution};
use anthesis_garden::retime::in_keyframes;
use anthesis_garden::shape::{UvSampler, organ_shape};
use anthesis_sim::{Selection, run};
use glam::{DVec2, DVec3};

/// Points compared between runs: the tip, the middle of the midrib and two
/// lamina points.
const PROBES: [(f64, f64); 4] = [(0.5, 1.0), (0.5, 0.5), (0.2, 0.7), (0.8, 0.7)];

fn list(args: &[String], flag: &str) -> Option<Vec<f64>> {
    let at = args.iter().position(|a| a == flag)?;
    let values = args
        .get(at + 1)
        .expect("a comma-separated list after the flag");
    Some(
        values
            .split(',')
            .map(|v| v.parse().expect("a number"))
            .collect(),
    )
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map_or("lily", String::as_str);
    let build = |scale: f64| {
        let mut project = flower_at_resolution(name, scale)
            .expect("a default flower's name")
            .expect("the flower builds");
        if args.iter().any(|a| a == "--paper") {
            project.settings.model = anthesis_physics::Model::Paper;
        }
        project
    };
    let variants: Vec<(String, Project)> = if let Some(keyframes) = list(&args, "--keyframes") {
        keyframes
            .iter()
            .map(|&n| {
                (
                    format!("{n:4} keyframes"),
                    in_keyframes(build(EDGE_SCALE), n as u32),
                )
            })
            .collect()
    } else if args.iter().any(|a| a == "--proxy") {
        let converged = build(EDGE_SCALE);
        let proxy = anthesis_flower::resolution::proxy(&converged).expect("the flower has a proxy");
        vec![
            ("proxy".to_string(), proxy),
            (format!("edge scale {EDGE_SCALE:4.2}"), converged),
        ]
    } else if let Some(tolerances) = list(&args, "--tolerances") {
        tolerances
            .iter()
            .map(|&t| {
                let mut project = build(EDGE_SCALE);
                project.settings.solver.relative_tolerance = t;
                (format!("tolerance {t:.0e}"), project)
            })
            .collect()
    } else {
        list(&args, "--scales")
            .unwrap_or(vec![1.0, EDGE_SCALE, 0.5 * EDGE_SCALE])
            .iter()
            .map(|&s| (format!("edge scale {s:4.2}"), build(s)))
            .collect()
    };
    let selection = if args.iter().any(|a| a == "--whole") {
        Selection::All
    } else {
        Selection::Only(0)
    };

    let mut results = Vec::new();
    for (label, project) in &variants {
        let mesh = project.flower.templates[0].mesh.clone();
        let started = Instant::now();
        let mut last = Vec::new();
        // Keyframes in which a particle of a simulated organ touches a
        // neighbour or a part (stamens, pistil), and the particles the
        // push-back moved.
        let (mut touching, mut pushed) = (0u32, 0u64);
        if let Err(e) = run(project, &selection, &mut |_, k| {
            last.clone_from(&k.positions_in_world[0]);
            touching += u32::from(k.stats.contact_particles > 0);
            pushed += u64::from(k.stats.pushed_particles);
        }) {
            println!("{label}: {e}");
            continue;
        }
        let seconds = started.elapsed().as_secs_f64();
        let shape = organ_shape(&mesh, &last).expect("measurable");
        let sampler = UvSampler::new(&mesh);
        let probes: Vec<DVec3> = PROBES
            .iter()
            .map(|&(u, v)| {
                sampler
                    .point(&last, DVec2::new(u, v))
                    .expect("on the organ")
            })
            .collect();
        println!(
            "{label}: {:5} particles {:6.2} s  turning {:6.1}°  angles {:5.1} {:5.1} {:5.1}  cupping {:+.3}  touching in {touching} keyframes, {pushed} pushed",
            mesh.vertex_count(),
            seconds,
            shape.midrib_turning_deg,
            shape.midrib_angles_deg[0],
            shape.midrib_angles_deg[1],
            shape.midrib_angles_deg[2],
            shape.cupping,
        );
        results.push((label.clone(), probes, shape.midrib_length));
    }
    let Some((reference, finest, length)) = results.last().cloned() else {
        return;
    };
    println!(
        "distance to the {reference} run at its last keyframe, over its midrib length {length:.1}:"
    );
    println!("| run | tip | midrib middle | lamina | lamina |\n|---|---|---|---|---|");
    for (label, probes, _) in &results {
        let d: Vec<String> = probes
            .iter()
            .zip(&finest)
            .map(|(a, b)| format!("{:.1} %", 100.0 * a.distance(*b) / length))
            .collect();
        println!("| {label} | {} |", d.join(" | "));
    }
}

//! A digest of every keyframe of a lily run (positions bit for bit, and the
//! per-keyframe iterations), to check that a change to the solver's
//! scheduling leaves the keyframes as they were and that they do not depend
//! on the thread count (`RAYON_NUM_THREADS=1`).
//!
//! ```text
//! cargo run --release -p anthesis-garden --example digest -- whole 0.6
//! cargo run --release -p anthesis-garden --example digest -- petal 0.6 stroke
//! ```
//!
//! `stroke` paints the petals' late key after a full run and digests the
//! rerun from the first keyframe it changes (as the stroke benchmarks do).
use std::hash::{DefaultHasher, Hash, Hasher};
use std::time::Instant;

use anthesis_garden::flowers::flower_at_resolution;
use anthesis_sim::fixtures::stroke_near_tip;
use anthesis_sim::{Keyframe, Selection, Simulation};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let whole = args.get(1).is_none_or(|a| a == "whole");
    let scale: f64 = args
        .get(2)
        .map_or(0.6, |a| a.parse().expect("an edge scale"));
    let stroke = args.get(3).is_some_and(|a| a == "stroke");
    let project = flower_at_resolution("lily", scale)
        .expect("the lily has a builder")
        .expect("the lily builds");
    let selection = if whole {
        Selection::All
    } else {
        Selection::Only(0)
    };
    let mut sim = Simulation::new(&project, &selection).expect("the lily simulates");
    if stroke {
        sim.keep_checkpoints();
    }
    let mut hasher = DefaultHasher::new();
    let mut digest = |k: &Keyframe| {
        k.index.hash(&mut hasher);
        k.stats.iterations.hash(&mut hasher);
        k.stats.pushed_particles.hash(&mut hasher);
        k.stats.contact_particles.hash(&mut hasher);
        for organ in &k.positions_in_world {
            for p in organ {
                p.to_array().map(f64::to_bits).hash(&mut hasher);
            }
        }
    };
    let started = Instant::now();
    let mut iterations = 0;
    while !sim.finished() {
        let k = sim.step(&|| false, &mut |_| {}).expect("converges");
        iterations += k.stats.iterations;
        if !stroke {
            digest(&k);
        }
    }
    if stroke {
        let template = project.flower.organs[0].template;
        let late = project.flower.templates[template].maps.keys().len() - 1;
        let mut painted = project.clone();
        stroke_near_tip(&mut painted, template, late);
        iterations = 0;
        let first = sim.edit(&project, &painted).expect("an edit");
        println!("rerun from keyframe {first}");
        while !sim.finished() {
            let k = sim.step(&|| false, &mut |_| {}).expect("converges");
            iterations += k.stats.iterations;
            digest(&k);
        }
    }
    println!(
        "digest {:016x}  iterations {iterations}  factorisations {}  {:.2} s",
        hasher.finish(),
        sim.factorisations(),
        started.elapsed().as_secs_f64()
    );
}

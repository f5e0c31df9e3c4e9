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
//!
//! To measure how far a change that alters keyframes moves the shapes:
//! `DIGEST_DUMP=FILE` writes the positions of every tenth keyframe of the
//! full run (`DIGEST_EVERY=N`: every N-th) (`DIGEST_TOLERANCE=1e-7` runs with a tighter solver tolerance,
//! for scale); `digest compare FILE FILE` prints the largest particle
//! displacement between two dumps per keyframe, relative to each organ's
//! size (the diagonal of its bounding box), and the largest over all.
//! `DIGEST_FLOWER=NAME` runs another default flower than the lily.
use std::hash::{DefaultHasher, Hash, Hasher};
use std::time::Instant;

use anthesis_garden::flowers::flower_at_resolution;
use anthesis_sim::fixtures::stroke_near_tip;
use anthesis_sim::{Keyframe, Selection, Simulation};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.get(1).is_some_and(|a| a == "compare") {
        compare(&args[2], &args[3]);
        return;
    }
    let whole = args.get(1).is_none_or(|a| a == "whole");
    let scale: f64 = args
        .get(2)
        .map_or(0.6, |a| a.parse().expect("an edge scale"));
    let stroke = args.get(3).is_some_and(|a| a == "stroke");
    let name = std::env::var("DIGEST_FLOWER").unwrap_or_else(|_| "lily".to_owned());
    let mut project = flower_at_resolution(&name, scale)
        .expect("a default flower's name")
        .expect("the flower builds");
    if let Ok(tolerance) = std::env::var("DIGEST_TOLERANCE") {
        project.settings.solver.relative_tolerance = tolerance.parse().expect("a tolerance");
    }
    let dump = std::env::var("DIGEST_DUMP").ok();
    let every: u32 = std::env::var("DIGEST_EVERY").map_or(10, |n| n.parse().expect("a count"));
    let mut dumped = Vec::new();
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
        if k.index.is_multiple_of(every) {
            dumped.push((k.index, k.positions_in_world.clone()));
        }
    }
    if stroke {
        let template = project.flower.organs[0].template;
        let late = project.flower.templates[template].maps.keys().len() - 1;
        let mut painted = project.clone();
        stroke_near_tip(&mut painted, template, late);
        iterations = 0;
        let rerun = Instant::now();
        let first = sim.edit(&project, &painted).expect("an edit");
        println!("rerun from keyframe {first}");
        while !sim.finished() {
            let k = sim.step(&|| false, &mut |_| {}).expect("converges");
            iterations += k.stats.iterations;
            digest(&k);
        }
        println!("rerun {:.3} s", rerun.elapsed().as_secs_f64());
    }
    println!(
        "digest {:016x}  iterations {iterations}  factorisations {}  {:.2} s",
        hasher.finish(),
        sim.factorisations(),
        started.elapsed().as_secs_f64()
    );
    if let Some(path) = dump {
        let text: String = dumped
            .iter()
            .map(|(index, keyframe)| {
                let organs = keyframe
                    .iter()
                    .map(|organ| {
                        organ
                            .iter()
                            .map(|p| format!("{:e} {:e} {:e}", p.x, p.y, p.z))
                            .collect::<Vec<_>>()
                            .join(",")
                    })
                    .collect::<Vec<_>>()
                    .join(";");
                format!("{index}:{organs}")
            })
            .collect::<Vec<_>>()
            .join("\n");
        std::fs::write(path, text).expect("a writable dump");
    }
}

/// The largest particle displacement between two dumps, per keyframe,
/// relative to the organ's bounding-box diagonal.
fn compare(a: &str, b: &str) {
    let read = |path: &str| -> Vec<(u32, Vec<Vec<[f64; 3]>>)> {
        std::fs::read_to_string(path)
            .expect("a dump")
            .lines()
            .map(|line| {
                let (index, keyframe) = line.split_once(':').expect("index:positions");
                let organs = keyframe
                    .split(';')
                    .map(|organ| {
                        organ
                            .split(',')
                            .map(|p| {
                                let v: Vec<f64> =
                                    p.split(' ').map(|c| c.parse().expect("a number")).collect();
                                [v[0], v[1], v[2]]
                            })
                            .collect()
                    })
                    .collect();
                (index.parse().expect("a keyframe index"), organs)
            })
            .collect()
    };
    let (a, b) = (read(a), read(b));
    let mut largest: f64 = 0.0;
    for ((keyframe, ka), (other, kb)) in a.iter().zip(&b) {
        assert_eq!(keyframe, other, "the dumps hold the same keyframes");
        let worst = ka
            .iter()
            .zip(kb)
            .map(|(oa, ob)| {
                let (mut low, mut high) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
                for p in oa {
                    for c in 0..3 {
                        low[c] = low[c].min(p[c]);
                        high[c] = high[c].max(p[c]);
                    }
                }
                let size = (0..3)
                    .map(|c| (high[c] - low[c]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                let moved = oa
                    .iter()
                    .zip(ob)
                    .map(|(p, q)| (0..3).map(|c| (p[c] - q[c]).powi(2)).sum::<f64>().sqrt())
                    .fold(0.0, f64::max);
                moved / size
            })
            .fold(0.0, f64::max);
        println!("keyframe {keyframe}: largest displacement {worst:.3e} of the organ's size");
        largest = largest.max(worst);
    }
    println!("over all: {largest:.3e}");
}

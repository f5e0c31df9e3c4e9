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
//! size (the diagonal of its bounding box), and the largest over all; and
//! in mean edges, apart for the particles within a mean edge of another
//! organ (where organs touch) and the others (the dumps name their flower
//! and edge scale in their first line; older dumps take `DIGEST_FLOWER` at
//! the default scale).
//! `DIGEST_FLOWER=NAME` runs another default flower than the lily.
//! `DIGEST_TWO_SIDED=1` (or `0`) turns two-sided contact on (off) whatever
//! the default (`Simulation::two_sided_contact`).
use std::hash::{DefaultHasher, Hash, Hasher};
use std::time::Instant;

use anthesis_flower::Project;
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
    if let Ok(on) = std::env::var("DIGEST_TWO_SIDED") {
        sim.two_sided_contact(on == "1");
    }
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
        // The flower and its edge scale first, so `compare` meshes the
        // same flower to measure edges.
        std::fs::write(path, format!("flower {name} {scale}\n{text}")).expect("a writable dump");
    }
}

/// The largest particle displacement between two dumps, per keyframe,
/// relative to the organ's bounding-box diagonal.
fn compare(a: &str, b: &str) {
    let read = |path: &str| -> Vec<(u32, Vec<Vec<[f64; 3]>>)> {
        std::fs::read_to_string(path)
            .expect("a dump")
            .lines()
            .filter(|line| !line.starts_with("flower "))
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
    // The flower the dumps were made of (their first line), else the lily
    // at the default scale.
    let header = std::fs::read_to_string(a)
        .ok()
        .and_then(|text| text.lines().next().map(str::to_owned))
        .and_then(|line| {
            let mut words = line.strip_prefix("flower ")?.split(' ');
            Some((words.next()?.to_owned(), words.next()?.parse::<f64>().ok()?))
        });
    let (name, scale) = header.unwrap_or_else(|| {
        let name = std::env::var("DIGEST_FLOWER").unwrap_or_else(|_| "lily".to_owned());
        (name, 0.6)
    });
    let project = flower_at_resolution(&name, scale)
        .expect("a default flower's name")
        .expect("the flower builds");
    let (a, b) = (read(a), read(b));
    let mut largest: f64 = 0.0;
    let (mut largest_near, mut largest_away) = (0.0f64, 0.0f64);
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
        let [near, away] = near_and_away(&project, ka, kb);
        println!(
            "keyframe {keyframe}: largest displacement {worst:.3e} of the organ's size; \
             in mean edges {near:.3e} near another organ, {away:.3e} elsewhere"
        );
        largest = largest.max(worst);
        largest_near = largest_near.max(near);
        largest_away = largest_away.max(away);
    }
    println!(
        "over all: {largest:.3e}; in mean edges {largest_near:.3e} near another organ, \
         {largest_away:.3e} elsewhere"
    );
}

/// The largest particle displacement between two keyframes (organs of
/// particle positions), in mean edges of the particle's organ (the edges
/// of the first keyframe's organs, `project` the flower the dumps were
/// made of): of the particles that lie within a mean edge of
/// another organ's particle in the first (where organs touch), and of the
/// others.
fn near_and_away(project: &Project, a: &[Vec<[f64; 3]>], b: &[Vec<[f64; 3]>]) -> [f64; 2] {
    let point = |p: &[f64; 3]| glam::DVec3::from_array(*p);
    let mut largest = [0.0f64; 2];
    for (i, (oa, ob)) in a.iter().zip(b).enumerate() {
        let mesh = &project.flower.template_of(i).mesh;
        assert_eq!(
            mesh.vertex_count(),
            oa.len(),
            "the dumps are not of {} (organ {i}): name the flower with DIGEST_FLOWER",
            project.name
        );
        let triangles = &mesh.triangles;
        let (sum, count) = triangles
            .iter()
            .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
            .fold((0.0, 0usize), |(sum, count), (u, v)| {
                (
                    sum + point(&oa[u as usize]).distance(point(&oa[v as usize])),
                    count + 1,
                )
            });
        let edge = sum / count.max(1) as f64;
        for (p, q) in oa.iter().zip(ob) {
            let near = a
                .iter()
                .enumerate()
                .filter(|&(j, _)| j != i)
                .any(|(_, other)| other.iter().any(|o| point(o).distance(point(p)) < edge));
            let moved = point(p).distance(point(q)) / edge;
            let k = if near { 0 } else { 1 };
            largest[k] = largest[k].max(moved);
        }
    }
    largest
}

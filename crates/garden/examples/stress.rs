//! The stress cases of issue 35: the default flowers painted past their
//! shipped maps as a user might, run whole and alone, with every keyframe's
//! crossings (an organ through another, a part or itself) reported instead
//! of stopping the run (`OnCrossing::Warn`), and one summary line per case:
//! the keyframes with crossings, the first, the contacts and self-contacts,
//! the time, and how the run ended.
//!
//! ```text
//! cargo run --release -p anthesis-garden --example stress -- [EDGE_SCALE] [CASE...]
//! ```
//!
//! Cases (all without names): `lily-e-in-x2` (the lily with its templates'
//! inner growth along the growth direction doubled: dg doubled, the e, w
//! and w_in maps halved), `petal-e-in-x2` (its first petal alone, the same
//! maps), `lily-maps-x2` (every map value doubled), `eustoma-thin` (the
//! Eustoma Maite Lady at half its thickness) and `lily-random-SEED` for
//! seeds 1 to 3 (the lily's e_in maps replaced by smooth random fields);
//! and `lily-petals-e-x0.9`, a modest edit: the lily's petals' e-growth
//! maps times 0.9 (their margins graze the sepals' from keyframe 33);
//! and `five-petal-wide-sketch`, the five-petal flower with the wide petal
//! the window's sketch test drew before (its petals of one whorl meet);
//! `five-petal-sketch-W` is that petal with its strokes' x times W (the
//! window's sketch test draws `five_petal::SKETCH_WIDTH_THAT_FITS`).

use anthesis_flower::Project;
use anthesis_garden::flowers::{EDGE_SCALE, flower_at_resolution};
use anthesis_maps::MapKind;
use anthesis_sim::batch::step_through;
use anthesis_sim::crossing::OnCrossing;
use anthesis_sim::{Selection, Simulation};

const CASES: [&str; 9] = [
    "five-petal-wide-sketch",
    "lily-petals-e-x0.9",
    "lily-e-in-x2",
    "petal-e-in-x2",
    "lily-maps-x2",
    "eustoma-thin",
    "lily-random-1",
    "lily-random-2",
    "lily-random-3",
];

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let scale: f64 = args
        .get(1)
        .map_or(EDGE_SCALE, |a| a.parse().expect("an edge scale"));
    let cases: Vec<String> = if args.len() > 2 {
        args[2..].to_vec()
    } else {
        CASES.iter().map(|c| c.to_string()).collect()
    };
    let mut summary = Vec::new();
    for case in &cases {
        let (project, selection) = stress_case(case, scale);
        let line = run_case(case, &project, &selection);
        println!("{line}");
        summary.push(line);
    }
    println!("summary (edge scale {scale})");
    for line in summary {
        println!("  {line}");
    }
}

/// The project and selection of stress case `name`.
fn stress_case(name: &str, scale: f64) -> (Project, Selection) {
    let flower = |n: &str| {
        flower_at_resolution(n, scale)
            .expect("a default flower")
            .expect("it builds")
    };
    match name {
        "lily-petals-e-x0.9" => {
            let mut project = flower("lily");
            for t in &mut project.flower.templates {
                if !t.name.contains("petal") {
                    continue;
                }
                for key in t.maps.keys_mut() {
                    for v in key.maps.scalar_mut(MapKind::EGrowth).values_mut() {
                        *v *= 0.9;
                    }
                }
            }
            (project, Selection::All)
        }
        "five-petal-wide-sketch" => (
            anthesis_garden::five_petal::five_petal_wide_sketch().expect("the sketch builds"),
            Selection::All,
        ),
        other if other.starts_with("five-petal-sketch-") => {
            let width: f64 = other["five-petal-sketch-".len()..]
                .parse()
                .unwrap_or_else(|_| panic!("five-petal-sketch-W: W a width factor, not {other}"));
            (
                anthesis_garden::five_petal::five_petal_sketch(width).expect("the sketch builds"),
                Selection::All,
            )
        }
        "lily-e-in-x2" => (e_in_doubled(flower("lily")), Selection::All),
        "petal-e-in-x2" => (e_in_doubled(flower("lily")), Selection::Only(0)),
        "lily-maps-x2" => {
            let mut project = flower("lily");
            scale_maps(&mut project, &MapKind::ALL[..4], 2.0);
            (project, Selection::All)
        }
        "eustoma-thin" => {
            let mut project = flower("eustoma-maite-lady");
            for t in &mut project.flower.templates {
                t.thickness *= 0.5;
            }
            (project, Selection::All)
        }
        other => {
            let seed: u64 = other
                .strip_prefix("lily-random-")
                .and_then(|s| s.parse().ok())
                .unwrap_or_else(|| panic!("unknown case {other}: one of {CASES:?}"));
            let mut project = flower("lily");
            random_e_in(&mut project, seed);
            (project, Selection::All)
        }
    }
}

/// Only the inner growth along the growth direction doubled: every
/// template's growth scale doubled and its other three growth maps halved.
fn e_in_doubled(mut project: Project) -> Project {
    for t in &mut project.flower.templates {
        t.dg *= 2.0;
        for key in t.maps.keys_mut() {
            if let Some(dg) = &mut key.dg {
                *dg *= 2.0;
            }
        }
    }
    scale_maps(
        &mut project,
        &[MapKind::EGrowth, MapKind::WGrowth, MapKind::WGrowthIn],
        0.5,
    );
    project
}

/// Every value of the maps `kinds` of every key of every template times
/// `factor`.
fn scale_maps(project: &mut Project, kinds: &[MapKind], factor: f32) {
    for t in &mut project.flower.templates {
        for key in t.maps.keys_mut() {
            for &kind in kinds {
                for v in key.maps.scalar_mut(kind).values_mut() {
                    *v *= factor;
                }
            }
        }
    }
}

/// Each key's e_in map of every template replaced by a smooth random field
/// between its own smallest and largest value (a sum of a few random
/// waves over the UV square, the same for the same seed).
fn random_e_in(project: &mut Project, seed: u64) {
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut random = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for t in &mut project.flower.templates {
        for key in t.maps.keys_mut() {
            let map = key.maps.scalar_mut(MapKind::EGrowthIn);
            let (lo, hi) = map
                .values()
                .iter()
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &v| {
                    (a.min(v), b.max(v))
                });
            let waves: Vec<[f64; 4]> = (0..4)
                .map(|_| {
                    [
                        1.0 + 3.0 * random(),
                        1.0 + 3.0 * random(),
                        std::f64::consts::TAU * random(),
                        0.5 + 0.5 * random(),
                    ]
                })
                .collect();
            let total: f64 = waves.iter().map(|w| w[3]).sum();
            let (width, height) = map.size();
            let field = anthesis_maps::ScalarMap::from_fn(width.max(64), height.max(64), |uv| {
                let s: f64 = waves
                    .iter()
                    .map(|[fu, fv, phase, amplitude]| {
                        amplitude * (fu * uv.x * 3.0 + fv * uv.y * 3.0 + phase).sin()
                    })
                    .sum();
                let unit = 0.5 + 0.5 * s / total;
                (f64::from(lo) + unit * f64::from(hi - lo)) as f32
            });
            *map = field;
        }
    }
}

/// Runs one case, every crossing reported; returns its summary line.
fn run_case(name: &str, project: &Project, selection: &Selection) -> String {
    let mut sim = Simulation::new(project, selection).expect("the case simulates");
    sim.on_crossing(OnCrossing::Warn);
    let bud = sim.bud();
    let bodies: Vec<anthesis_mesh::crossing::Body> = bud
        .positions_in_world
        .iter()
        .enumerate()
        .map(|(i, positions)| anthesis_mesh::crossing::Body {
            positions,
            triangles: sim.triangles(i),
        })
        .collect();
    let bud_pairs = anthesis_mesh::crossing::CrossingSearch::new()
        .find(&bodies, &|_, _| true)
        .len();
    let mut contacts = 0u64;
    let last = sim.keyframe_count();
    let stepped = step_through(&mut sim, last, &|| false, &mut |_, k| {
        contacts += u64::from(k.stats.contact_particles);
    });
    let (keyframes, seconds) = (stepped.done, stepped.seconds);
    let ended = stepped
        .failure
        .map_or("finished".to_string(), |error| format!("stopped: {error}"));
    let crossed: Vec<u32> = sim.crossings().iter().map(|c| c.keyframe).collect();
    let pairs: usize = sim.crossings().iter().map(|c| c.pairs).sum();
    let first = sim
        .crossings()
        .first()
        .map_or("none".to_string(), |c| c.to_string());
    format!(
        "{name}: bud {bud_pairs} crossing triangle pairs; {keyframes} keyframes in {seconds:.2} s, {} with crossings ({pairs} crossing triangle pairs), contact particles summed {contacts}, self-contacts summed {}; first: {first}; {ended}",
        crossed.len(),
        sim.self_contact_count(),
    )
}

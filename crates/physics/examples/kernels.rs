//! Times one organ's kernels (energy, energy and gradient, Hessian
//! assembly, both in one pass as a keyframe's start, membrane update,
//! regional growth) on a test petal with the edge-smoothed
//! membrane, then a keyframe's first Newton step on it (the organ's usual
//! keyframe: energy, gradient and Hessian in one pass, one factorisation,
//! a few conjugate-gradient iterations, one line-search energy), so the
//! factorisation, the solves and the solver's own work around them show as
//! the difference; each the fastest of several batches (robust on a shared
//! machine).
//!
//! ```text
//! cargo run --release -p anthesis-physics --example kernels -- [COLUMNS ROWS]
//! ```
//!
//! `45 90` is an organ at the 4k film resolution (4,140 particles).

use std::time::Instant;

use anthesis_mesh::Topology;
use anthesis_mesh::generate::{jittered, test_petal};
use anthesis_physics::membrane::EdgeSmoothedMembrane;
use anthesis_physics::{
    Elastic, GrowthModel, GrowthRates, NewtonSolver, RegionalGrowth, SolverSettings,
};
use glam::{DVec2, DVec3};

fn fastest(label: &str, mut work: impl FnMut()) -> f64 {
    fastest_of(9, 20, label, &mut work)
}

/// The fastest of `batches` batches of `calls` calls of `work`, printed and
/// returned in seconds per call.
fn fastest_of(batches: usize, calls: usize, label: &str, work: &mut impl FnMut()) -> f64 {
    let best = (0..batches)
        .map(|_| {
            let start = Instant::now();
            for _ in 0..calls {
                work();
            }
            start.elapsed().as_secs_f64() / calls as f64
        })
        .fold(f64::INFINITY, f64::min);
    println!("{label:<28} {:9.1} µs", best * 1e6);
    best
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("a count"))
        .collect();
    let (columns, rows) = (
        args.first().copied().unwrap_or(22),
        args.get(1).copied().unwrap_or(46),
    );
    let mesh = test_petal(30.0, 12.0, columns, rows);
    let topology = Topology::build(&mesh).expect("a manifold petal");
    let mut elastic = Elastic::at_rest(&mesh.positions, &topology);
    let x = jittered(&mesh.positions, 0.1 * 30.0 / rows as f64, 12345);
    for l in &mut elastic.rest_lengths {
        *l *= 0.95;
    }
    // Moduli spread between 0.5 and 1.5 without a pattern.
    let modulus: Vec<f64> = (0..elastic.rest_lengths.len())
        .map(|e| 1.0 + 0.5 * (e as f64 * 0.618_034).fract().mul_add(2.0, -1.0))
        .collect();
    let mut membrane = EdgeSmoothedMembrane::new(&mesh.triangles, &topology);
    membrane.update(&elastic.rest_lengths, &modulus);
    elastic.membrane = Some(membrane.clone());
    let pattern = elastic.pattern(x.len());
    println!("{} particles, {} edges", x.len(), elastic.edges.len());
    let mut g = vec![DVec3::ZERO; x.len()];
    let mut values = vec![0.0; pattern.nonzeros()];
    let energy = fastest("energy", || {
        std::hint::black_box(elastic.energy(&x, &[]));
    });
    fastest("energy_and_gradient", || {
        std::hint::black_box(elastic.energy_and_gradient(&x, &[], &mut g));
    });
    fastest("hessian", || {
        elastic.hessian(&x, &[], &pattern, &mut values);
        std::hint::black_box(&values);
    });
    let assembly = fastest("e+g and hessian", || {
        std::hint::black_box(elastic.elastic_energy_gradient_and_hessian(
            &x,
            &mut g,
            &pattern,
            &mut values,
        ));
    });
    fastest("membrane update", || {
        membrane.update(&elastic.rest_lengths, &modulus);
        std::hint::black_box(&membrane);
    });
    // Growth of a few percent per step without a pattern, the inner layer
    // mostly faster, directions turning across the petal.
    let rates: Vec<GrowthRates> = (0..mesh.triangles.len())
        .map(|t| {
            let r = (t as f64 * 0.618_034).fract();
            GrowthRates {
                e: 1.0 + 0.02 * r,
                w: 1.0 + 0.01 * r,
                e_in: 1.0 + 0.03 * r,
                w_in: 1.0 + 0.015 * (1.0 - r),
                direction_in_uv: DVec2::new(r - 0.5, 1.0),
            }
        })
        .collect();
    let model = GrowthModel::new(0.3);
    let mut growth = RegionalGrowth::default();
    let (mut lengths, mut angles) = (elastic.rest_lengths.clone(), elastic.rest_angles.clone());
    fastest("regional growth", || {
        growth.grow(
            &x,
            &mesh.uvs,
            &mesh.triangles,
            &topology,
            &rates,
            &model,
            &mut lengths,
            &mut angles,
        );
        std::hint::black_box((&lengths, &angles));
    });

    // The base row held where it is, as the simulation anchors an organ.
    let base = mesh
        .positions
        .iter()
        .map(|p| p.y)
        .fold(f64::INFINITY, f64::min);
    elastic.anchors = (0..x.len() as u32)
        .filter(|&i| mesh.positions[i as usize].y <= base + 1e-9)
        .map(|i| (i, x[i as usize]))
        .collect();
    elastic.anchor_stiffness = 10.0 * elastic.force_scale() / (30.0 / rows as f64);
    let settings = SolverSettings::default();
    let mut solver = NewtonSolver::new(x.len(), &elastic).expect("analysis");
    println!("{solver:?}");
    let mut positions = x.clone();
    let mut report = None;
    let step = fastest_of(7, 5, "first step of a keyframe", &mut || {
        positions.copy_from_slice(&x);
        solver.begin_keyframe();
        report = Some(solver.step(&elastic, &[], &mut positions, &settings));
    });
    println!("  {report:?}");
    println!(
        "  the rest (factorise, solve) {:9.1} µs",
        (step - assembly - energy) * 1e6
    );
}

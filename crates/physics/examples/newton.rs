//! Times a keyframe's first Newton step on a test petal (the organ's usual
//! keyframe: energy, gradient and Hessian in one pass, one factorisation,
//! a few conjugate-gradient iterations, one line-search energy), and the
//! evaluations it contains, so the rest (factorisation, solves and the
//! solver's own work around them) shows as the difference. The fastest of
//! several batches (robust on a shared machine).
//!
//! ```text
//! cargo run --release -p anthesis-physics --example newton -- [COLUMNS ROWS]
//! ```
//!
//! `45 90` is an organ at the 4k film resolution (4,140 particles).

use std::time::Instant;

use anthesis_mesh::Topology;
use anthesis_mesh::generate::{jittered, test_petal};
use anthesis_physics::membrane::EdgeSmoothedMembrane;
use anthesis_physics::{Elastic, NewtonSolver, SolverSettings};
use glam::DVec3;

fn fastest(label: &str, mut work: impl FnMut()) -> f64 {
    let (batches, calls) = (7, 5);
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
    let modulus: Vec<f64> = (0..elastic.rest_lengths.len())
        .map(|e| 1.0 + 0.5 * (e as f64 * 0.618_034).fract().mul_add(2.0, -1.0))
        .collect();
    let mut membrane = EdgeSmoothedMembrane::new(&mesh.triangles, &topology);
    membrane.update(&elastic.rest_lengths, &modulus);
    elastic.membrane = Some(membrane);
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

    let settings = SolverSettings {
        relative_tolerance: 1e-5,
        ..SolverSettings::default()
    };
    let mut solver = NewtonSolver::new(x.len(), &elastic).expect("analysis");
    println!("{} particles, {solver:?}", x.len());
    let mut positions = x.clone();
    let mut report = None;
    let step = fastest("first step of a keyframe", || {
        positions.copy_from_slice(&x);
        solver.begin_keyframe();
        report = Some(solver.step(&elastic, &[], &mut positions, &settings));
    });
    println!("  {report:?}");
    let mut g = vec![DVec3::ZERO; x.len()];
    let pattern = elastic.pattern(x.len());
    let mut values = vec![0.0; pattern.nonzeros()];
    let assembly = fastest("  e+g and hessian", || {
        std::hint::black_box(elastic.elastic_energy_gradient_and_hessian(
            &x,
            &mut g,
            &pattern,
            &mut values,
        ));
    });
    let energy = fastest("  energy", || {
        std::hint::black_box(elastic.energy(&positions, &[]));
    });
    println!(
        "  the rest (factorise, solve) {:9.1} µs",
        (step - assembly - energy) * 1e6
    );
}

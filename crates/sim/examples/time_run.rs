//! Times one run of the benchmark fixtures and prints iteration counts:
//! `cargo run --release -p anthesis-sim --example time_run -- ORGANS [ROWS COLS]`
//! (defaults: 1 organ, 14 x 28, the lily-sized petal; `1 45 90` is the
//! 4k-particle petal of the benchmark).
fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|s| s.parse().ok())
        .collect();
    let organs = args.first().copied().unwrap_or(1);
    let rows = args.get(1).copied().unwrap_or(14);
    let cols = args.get(2).copied().unwrap_or(28);
    let project = anthesis_sim::fixtures::whorl(organs, rows, cols, 100);
    let t = std::time::Instant::now();
    let mut iters = 0;
    let result = anthesis_sim::run(&project, &anthesis_sim::Selection::All, &mut |_, k| {
        iters += k.stats.iterations;
        if k.index % 20 == 0 {
            eprintln!(
                "kf {} E {:.4e} it {} g {:.2e} pushed {}",
                k.index,
                k.stats.energy,
                k.stats.iterations,
                k.stats.relative_gradient,
                k.stats.pushed_particles
            );
        }
    });
    let factorisations = result.as_ref().map(|s| s.factorisations()).unwrap_or(0);
    println!(
        "{organs} organs {rows}x{cols}: {:?} in {:.3}s, {iters} iterations, {factorisations} factorisations",
        result.err(),
        t.elapsed().as_secs_f64()
    );
}

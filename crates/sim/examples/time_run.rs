fn main() {
    let organs: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let project = anthesis_sim::fixtures::whorl(organs, 14, 28, 100);
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
                k.stats.gradient_norm,
                k.stats.pushed_particles
            );
        }
    });
    println!(
        "{organs} organs: {:?} in {:.3}s, {iters} iterations",
        result.err(),
        t.elapsed().as_secs_f64()
    );
}

//! The round-trip benchmark of issue 15: each Eustoma cultivar's final
//! petal, simulated from its own project (one organ), fitted from the
//! shared bud with the growth maps reset to uniform. Prints, per cultivar
//! and run, the fit's RMS and largest distance (fractions of the petal's
//! length), iterations, simulations and seconds, then the medians.
//!
//! `cargo run --release -p anthesis-fit --example eustoma_round_trip [RUNS] [CULTIVAR]
//! [--uniform-stiffness]`: RUNS per cultivar (default 1), CULTIVAR a part
//! of one cultivar's name (e.g. `maite`, default all three); the fit keeps
//! the template's stretch and bend maps (material, not growth) unless
//! `--uniform-stiffness` resets them to 1 too.

use anthesis_fit::{FitSettings, Similarity, Surface, Target, fit, simulate_final};
use anthesis_garden::Cultivar;
use anthesis_maps::{GrowthMaps, KeyedMaps};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let uniform_stiffness = std::env::args().any(|a| a == "--uniform-stiffness");
    let positional: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let runs: usize = positional
        .first()
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(1);
    let only: Option<String> = positional.get(1).map(|s| s.to_lowercase());
    let settings = FitSettings::default();
    for cultivar in [
        Cultivar::MellowYellow,
        Cultivar::MaiteLady,
        Cultivar::Pinocchio,
    ] {
        let name = cultivar.project_name();
        if only
            .as_deref()
            .is_some_and(|o| !name.to_lowercase().contains(o))
        {
            continue;
        }
        let builtin = anthesis_garden::builtin(cultivar.folder_name())
            .ok_or("the Eustoma is not built in")??;
        let project = anthesis_flower::resolution::resolve(&builtin)?;
        let organ = 0;
        let template = project.flower.template_of(organ);
        let target = Target {
            surface: Surface::new(
                simulate_final(&project, organ, template.maps.clone(), &|| false)?,
                template.mesh.triangles.clone(),
            ),
            uvs: Some(template.mesh.uvs.clone()),
            warnings: Vec::new(),
        };
        // The shared bud with uniform growth maps (stiffness kept unless
        // asked).
        let mut start = project.clone();
        let t = start.flower.organs[organ].template;
        let mut uniform = GrowthMaps::uniform();
        if !uniform_stiffness {
            let first = &template.maps.keys()[0].maps;
            uniform.stretch = first.stretch.clone();
            uniform.bend = first.bend.clone();
        }
        start.flower.templates[t].maps = KeyedMaps::single(uniform);
        let mut rms = Vec::new();
        let mut max = Vec::new();
        let mut seconds = Vec::new();
        for run in 0..runs {
            let result = fit(
                &start,
                organ,
                &target,
                Similarity::IDENTITY,
                &settings,
                &mut |p| {
                    eprintln!(
                        "  {name} iteration {}: RMS {:.3} %, max {:.3} %, {} simulations, {:.1} s",
                        p.iteration,
                        100.0 * p.rms,
                        100.0 * p.max,
                        p.simulations,
                        p.seconds
                    )
                },
                &|| false,
            )?;
            println!(
                "{name} run {run}: guess RMS {:.2} %, fitted RMS {:.3} %, max {:.3} % of length {:.2}, \
                 {} iterations, {} simulations, {:.1} s",
                100.0 * result.guess_rms,
                100.0 * result.rms,
                100.0 * result.max,
                result.length,
                result.iterations,
                result.simulations,
                result.seconds
            );
            rms.push(result.rms);
            max.push(result.max);
            seconds.push(result.seconds);
        }
        let median = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        println!(
            "{name} median of {runs}: RMS {:.3} %, max {:.3} %, {:.1} s",
            100.0 * median(&mut rms),
            100.0 * median(&mut max),
            median(&mut seconds)
        );
    }
    Ok(())
}

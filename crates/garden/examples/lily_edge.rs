//! Simulates the edge-growth lily (`lily-edge`, issue 41 item 4) at a
//! chosen resolution and writes every organ at chosen keyframes as OBJ
//! (positions in the world frame, the template's UVs), for
//! `docs/python/lily_edge.py --objs FOLDER` to measure.
//!
//! `cargo run --release -p anthesis-garden --example lily_edge -- EDGE_SCALE OUT_FOLDER [--soft-midrib] [--every N] [--only ORGAN] [--bend-ratio R] [--keyframes N] [--profile-power P] [--layer SHARE POWER] [--lengths-from-shape|--lengths-from-rest] [--bend-from-rest|--bend-from-dihedral] [--max-iterations N] [--no-parts]`
//!
//! `--bend-ratio R` sets each template's bend stiffness `Kb` to `R` times
//! its stretch stiffness `Ks` (the built-in: 0.01); `--keyframes N`
//! the same opening in `N` steps (`anthesis_garden::retime`: larger steps
//! of growth, each one's excess at the margin larger); `--profile-power P`
//! the exponent of the e-growth profile across the width (2 in the
//! built-in; larger puts the excess nearer the margins); `--layer SHARE
//! POWER` the share of the excess in the layer along the margin and its
//! exponent (the built-in: 0.5 and 16); `--lengths-from-shape` the paper's
//! regrowth of the rest lengths from the current shape instead of the
//! built-in's accumulated rest state (`--lengths-from-rest`);
//! `--bend-from-rest` / `--bend-from-dihedral` what a hinge's growth adds
//! to; `--max-iterations N` Newton's limit per keyframe (the built-in: 200);
//! `--no-parts` the flower without its stamens and pistil.
//!
//! `EDGE_SCALE` is the mean edge as a fraction of the paper's (Table 1;
//! the built-in is 0.45). Prints the particles per organ and the run time.

use std::io::BufWriter;
use std::path::PathBuf;
use std::time::Instant;

use anthesis_garden::edge::{LilyEdge, lily_edge_of};
use anthesis_sim::{Selection, run};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let scale: f64 = args.next().ok_or("give an edge scale")?.parse()?;
    let out = PathBuf::from(args.next().ok_or("give an output folder")?);
    let mut edge = LilyEdge::MARGIN;
    let mut every = 10u32;
    let mut selection = Selection::All;
    let mut bend_ratio: Option<f64> = None;
    let mut keyframes: Option<u32> = None;
    let mut length_base: Option<anthesis_physics::LengthBase> = None;
    let mut bend_base: Option<anthesis_physics::BendBase> = None;
    let mut max_iterations: Option<u32> = None;
    let mut no_parts = false;
    while let Some(flag) = args.next() {
        match flag.as_str() {
            "--soft-midrib" => edge = edge.soft_midrib(),
            "--bend-ratio" => {
                bend_ratio = Some(args.next().ok_or("--bend-ratio needs a number")?.parse()?);
            }
            "--profile-power" => {
                edge.profile_power = args
                    .next()
                    .ok_or("--profile-power needs a number")?
                    .parse()?;
            }
            "--layer" => {
                edge.layer_share = args.next().ok_or("--layer needs a share")?.parse()?;
                edge.layer_power = args.next().ok_or("--layer needs a power")?.parse()?;
            }
            "--keyframes" => {
                keyframes = Some(args.next().ok_or("--keyframes needs a count")?.parse()?);
            }
            "--lengths-from-shape" => length_base = Some(anthesis_physics::LengthBase::Shape),
            "--lengths-from-rest" => length_base = Some(anthesis_physics::LengthBase::Rest),
            "--bend-from-dihedral" => bend_base = Some(anthesis_physics::BendBase::Dihedral),
            "--bend-from-rest" => bend_base = Some(anthesis_physics::BendBase::RestAngle),
            "--max-iterations" => {
                max_iterations = Some(
                    args.next()
                        .ok_or("--max-iterations needs a count")?
                        .parse()?,
                );
            }
            "--no-parts" => no_parts = true,
            "--every" => every = args.next().ok_or("--every needs a count")?.parse()?,
            "--only" => {
                selection = Selection::Only(args.next().ok_or("--only needs an organ")?.parse()?);
            }
            other => return Err(format!("unknown flag {other}").into()),
        }
    }
    let mut project = lily_edge_of(edge, scale)?;
    if let Some(keyframes) = keyframes {
        project = anthesis_garden::retime::in_keyframes(project, keyframes);
    }
    if let Some(ratio) = bend_ratio {
        for template in &mut project.flower.templates {
            template.bend_stiffness = template.stretch_stiffness * ratio;
        }
    }
    if let Some(base) = length_base {
        project.settings.length_base = base;
    }
    if let Some(base) = bend_base {
        project.settings.bend_base = base;
    }
    if let Some(iterations) = max_iterations {
        project.settings.solver.max_iterations = iterations;
    }
    if no_parts {
        project.flower.parts.clear();
    }
    std::fs::create_dir_all(&out)?;
    for (i, organ) in project.flower.organs.iter().enumerate() {
        let mesh = &project.flower.template_of(i).mesh;
        println!(
            "organ {i} ({}): {} particles, {} triangles",
            organ.name,
            mesh.positions.len(),
            mesh.triangles.len()
        );
    }
    let organ_ids: Vec<usize> = match selection {
        Selection::Only(i) => vec![i],
        _ => (0..project.flower.organs.len()).collect(),
    };
    let started = Instant::now();
    let mut failed = None;
    let result = run(&project, &selection, &mut |_, keyframe| {
        if keyframe.index % every != 0 || failed.is_some() {
            return;
        }
        for (slot, positions) in keyframe.positions_in_world.iter().enumerate() {
            let organ = organ_ids[slot];
            let mesh = &project.flower.template_of(organ).mesh;
            let path = out.join(format!("k{:03}_organ{organ}.obj", keyframe.index));
            let written = std::fs::File::create(&path).and_then(|file| {
                anthesis_mesh::write_obj(
                    &mut BufWriter::new(file),
                    positions,
                    &mesh.uvs,
                    &mesh.triangles,
                )
            });
            if let Err(error) = written {
                failed = Some(format!("{}: {error}", path.display()));
            }
        }
        eprint!("\rkeyframe {}", keyframe.index);
    });
    eprintln!();
    if let Some(error) = failed {
        return Err(error.into());
    }
    let sim = result?;
    println!(
        "simulated {} keyframes in {:.1} s",
        sim.keyframe_count(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

//! `anthesis pde-blossom`: a swept organ animated between two states by the
//! PDE-driven in-betweening of `pde-surfaces-lily.txt` §V
//! (`anthesis_bud::dynamic`), written as the same animation files
//! `anthesis simulate` writes.

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use anthesis_bud::dynamic::{Dynamics, SweepInBetween};
use anthesis_bud::{RemeshOptions, Surface, build_organ};
use anthesis_export::Track;
use anyhow::{Context, Result, bail};
use clap::Args;
use glam::DVec2;

use super::EncodingArg;
use super::bud::read_pde;
use super::simulate::{animation_options, check_output, write_tracks};

/// `anthesis pde-blossom BUD.json OPEN.json`.
#[derive(Debug, Args)]
pub struct PdeBlossomArgs {
    /// The bud: a PDE sweep surface in the `anthesis bud --pde` format.
    pub bud: PathBuf,
    /// The open state: a PDE sweep surface of the same organ (the same
    /// parameters: u across from margin to margin, v from base to tip).
    pub open: PathBuf,
    /// Keyframes after the bud (the open state is the last).
    #[arg(long, default_value_t = 100)]
    pub keyframes: u32,
    /// Intervals of the generator (across, in u).
    #[arg(long, default_value_t = 32)]
    pub nodes: usize,
    /// Generators solved along the sweep (in v); between them the
    /// deformation is interpolated.
    #[arg(long, default_value_t = 24)]
    pub rows: usize,
    /// k_b of eq. (13).
    #[arg(long, default_value_t = 1.0)]
    pub bend: f64,
    /// k_s of eq. (13).
    #[arg(long, default_value_t = 0.0)]
    pub stretch: f64,
    /// m of eq. (13): more mass, a slower, swinging start.
    #[arg(long, default_value_t = 1.0)]
    pub mass: f64,
    /// The final state must be met within this, as a fraction of the
    /// largest deformation.
    #[arg(long, default_value_t = 1e-6)]
    pub tolerance: f64,
    /// Corrections of the force (eq. 21) at most.
    #[arg(long, default_value_t = 30)]
    pub max_corrections: usize,
    /// Mean edge of the organ's mesh (default: a 40th of its length).
    #[arg(long)]
    pub edge: Option<f64>,
    /// Write the animation: FILE.glb, FILE.usda or FILE.usdc, otherwise a
    /// folder of one OBJ per keyframe.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Write the corrections, the final error and the time as JSON.
    #[arg(long, value_name = "FILE.json")]
    pub report: Option<PathBuf>,
    /// Keyframes per second in the .glb or USD layer (default 24).
    #[arg(long)]
    pub fps: Option<f64>,
    /// How the .glb stores its data.
    #[arg(long, value_enum, default_value_t = EncodingArg::Dense)]
    pub encoding: EncodingArg,
}

pub(super) fn pde_blossom(args: &PdeBlossomArgs) -> Result<()> {
    if args.keyframes == 0 {
        bail!("--keyframes must be at least 1");
    }
    if !(args.tolerance >= 0.0 && args.tolerance.is_finite()) {
        bail!("--tolerance must be 0 or more, got {}", args.tolerance);
    }
    let glb = animation_options(args.fps, args.encoding)?;
    if let Some(out) = &args.out {
        check_output(out, &glb, args.keyframes)?;
    }
    let bud = read_pde(&args.bud)?;
    let open = read_pde(&args.open)?;
    let length = bud
        .point(DVec2::new(0.5, 1.0))
        .distance(bud.point(DVec2::new(0.5, 0.0)));
    let edge = args.edge.unwrap_or(length / 40.0);
    let mesh = build_organ(&bud, &RemeshOptions::new(edge))
        .with_context(|| format!("cannot mesh the bud {}", args.bud.display()))?
        .mesh;
    let started = Instant::now();
    let steps = args.keyframes as usize;
    let motion = SweepInBetween::new(
        &bud,
        &open,
        args.nodes,
        args.rows,
        Dynamics {
            bend: args.bend,
            stretch: args.stretch,
            mass: args.mass,
        },
        steps,
        args.tolerance,
        args.max_corrections,
    )
    .with_context(|| {
        format!(
            "cannot in-between {} and {}",
            args.bud.display(),
            args.open.display()
        )
    })?;
    let keyframes: Vec<Vec<glam::DVec3>> = (0..=steps)
        .map(|level| {
            mesh.uvs
                .iter()
                .map(|uv| bud.point(*uv) + motion.deformation(*uv, level))
                .collect()
        })
        .collect();
    let seconds = started.elapsed().as_secs_f64();
    let summary = motion.summary();
    writeln!(
        std::io::stdout().lock(),
        "{} generators of {} intervals, {} keyframes: force corrections (eq. 21) at most {}{}, \
         final error {:.2e} of the largest deformation (tolerance {:.0e}); {} particles; {seconds:.2} s",
        motion.rows.len(),
        args.nodes,
        steps,
        summary.corrections,
        if summary.solved {
            ", then the force solved from the linear response"
        } else {
            ""
        },
        summary.final_error,
        args.tolerance,
        mesh.positions.len(),
    )?;
    if let Some(path) = &args.report {
        let report = serde_json::json!({
            "generators": motion.rows.len(),
            "intervals": args.nodes,
            "keyframes": steps,
            "corrections": summary.corrections,
            "force_solved": summary.solved,
            "final_error": summary.final_error,
            "tolerance": args.tolerance,
            "seconds": seconds,
        });
        anthesis_files::write_atomic(path, serde_json::to_string_pretty(&report)?.as_bytes())
            .with_context(|| format!("cannot write the report {}", path.display()))?;
    }
    if let Some(out) = &args.out {
        let name = args
            .bud
            .file_stem()
            .map_or_else(|| "organ".to_owned(), |s| s.to_string_lossy().into_owned());
        let track = Track {
            name,
            triangles: mesh.triangles.clone(),
            uvs: mesh.uvs.clone(),
            base_color: [0.95, 0.93, 0.88, 1.0],
            keyframes,
            base_color_png: None,
            rigid: None,
        };
        write_tracks(out, &[track], &glb)?;
        eprintln!("wrote {} (keyframes 0 to {steps})", out.display());
    }
    Ok(())
}

//! `anthesis pde-blossom`: a swept organ animated between two states by the
//! PDE-driven in-betweening of Chaudhry et al. §V
//! (`anthesis_bud::dynamic`), written as the same animation files
//! `anthesis simulate` writes.

use std::path::PathBuf;
use std::time::Instant;

use anthesis_bud::dynamic::{Dynamics, SweepInBetween};
use anthesis_bud::{PdeSweep, RemeshOptions, Surface, build_organ};
use anthesis_export::Track;
use anthesis_flower::MAX_KEYFRAMES;
use anthesis_mesh::Mesh;
use anyhow::{Context, Result, bail};
use clap::Args;
use glam::{DVec2, DVec3};

use super::EncodingArg;
use super::bud::read_pde;
use super::simulate::{animation_options, check_output, write_tracks};
use super::stream::{out, say};

/// The fewest intervals of a generator (`--nodes`; the dynamics need 4).
const MIN_NODES: usize = 4;
/// The most intervals of a generator (`--nodes`).
pub const MAX_NODES: usize = 1024;
/// The most generators solved along the sweep (`--rows`).
pub const MAX_ROWS: usize = 1024;
/// The most force corrections (`--max-corrections`).
pub const MAX_CORRECTIONS: usize = 1000;
/// The most node-steps of a run: (rows + 1) x (nodes + 1) x keyframes,
/// each kept as a deformation (the defaults make 82,500; this is 120 times
/// that, about a gigabyte with the solver's working copies).
pub const MAX_NODE_STEPS: usize = 10_000_000;

/// `anthesis pde-blossom BUD.json OPEN.json`.
#[derive(Debug, Args)]
pub struct PdeBlossomArgs {
    /// The bud: a PDE sweep surface in the `anthesis bud --pde` format.
    pub bud: PathBuf,
    /// The open state: a PDE sweep surface of the same organ (the same
    /// parameters: u across from margin to margin, v from base to tip).
    pub open: PathBuf,
    /// Keyframes after the bud (the open state is the last), 1 to 10,000.
    #[arg(long, default_value_t = 100)]
    pub keyframes: i64,
    /// Intervals of the generator (across, in u), 4 to 1024.
    #[arg(long, default_value_t = 32)]
    pub nodes: i64,
    /// Generators solved along the sweep (in v), 1 to 1024; between them
    /// the deformation is interpolated. Rows x nodes x keyframes is at most
    /// 10,000,000.
    #[arg(long, default_value_t = 24)]
    pub rows: i64,
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
    /// Corrections of the force (eq. 21) at most, 0 to 1000.
    #[arg(long, default_value_t = 30)]
    pub max_corrections: i64,
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
    let sizes = Sizes::checked(args)?;
    let glb = animation_options(args.fps, args.encoding)?;
    if let Some(out) = &args.out {
        check_output(out, &glb, sizes.keyframes as u32)?;
    }
    let (bud, open, mesh) = read_states(args, sizes.keyframes)?;
    let started = Instant::now();
    let steps = sizes.keyframes;
    let motion = in_between(args, &bud, &open, &sizes)?;
    let keyframes = keyframe_positions(args, &bud, &mesh, &motion, steps)?;
    let seconds = started.elapsed().as_secs_f64();
    report(args, &motion, &sizes, mesh.positions.len(), seconds)?;
    if let Some(out) = &args.out {
        let name = args
            .bud
            .file_stem()
            .map_or_else(|| "organ".to_owned(), |s| s.to_string_lossy().into_owned());
        let track = Track {
            name,
            triangles: mesh.triangles.clone(),
            uvs: mesh.uvs.clone(),
            base_colour: [0.95, 0.93, 0.88, 1.0],
            keyframes,
            ..Track::default()
        };
        write_tracks(out, &[track], &glb)?;
        say!("wrote {} (keyframes 0 to {steps})", out.display());
    }
    Ok(())
}

/// The checked sizes of a run.
struct Sizes {
    /// Keyframes after the bud (`--keyframes`): the in-betweening's steps.
    keyframes: usize,
    /// Intervals of a generator (`--nodes`).
    nodes: usize,
    /// Generators along the sweep (`--rows`).
    rows: usize,
    /// Force corrections at most (`--max-corrections`).
    max_corrections: usize,
}

impl Sizes {
    /// Checks the counts, their product and the other numbers of `args`
    /// (`--edge`, `--tolerance`), before any file is read.
    fn checked(args: &PdeBlossomArgs) -> Result<Sizes> {
        let keyframes =
            super::check_count("--keyframes", args.keyframes, 1, MAX_KEYFRAMES as usize)?;
        let nodes = super::check_count("--nodes", args.nodes, MIN_NODES, MAX_NODES)?;
        let rows = super::check_count("--rows", args.rows, 1, MAX_ROWS)?;
        let max_corrections = super::check_count(
            "--max-corrections",
            args.max_corrections,
            0,
            MAX_CORRECTIONS,
        )?;
        // Each generator keeps its nodes' deformation at every keyframe.
        let work = (rows + 1) * (nodes + 1) * keyframes;
        if work > MAX_NODE_STEPS {
            bail!(
                "(--rows {rows} + 1) x (--nodes {nodes} + 1) x --keyframes {keyframes} is {} \
                 node-steps, more than the limit of {}: use fewer rows, nodes or keyframes",
                crate::desktop::params::grouped(work as u64),
                crate::desktop::params::grouped(MAX_NODE_STEPS as u64),
            );
        }
        if let Some(edge) = args.edge
            && !(edge.is_finite() && edge > 0.0)
        {
            bail!("--edge must be a positive length, got {edge}");
        }
        if !(args.tolerance >= 0.0 && args.tolerance.is_finite()) {
            bail!("--tolerance must be 0 or more, got {}", args.tolerance);
        }
        Ok(Sizes {
            keyframes,
            nodes,
            rows,
            max_corrections,
        })
    }
}

/// Reads the two states, checks that their margins correspond and meshes
/// the bud (a mesh of `keyframes` + 1 keyframes must fit the limits).
fn read_states(args: &PdeBlossomArgs, keyframes: usize) -> Result<(PdeSweep, PdeSweep, Mesh)> {
    let bud = read_pde(&args.bud)?;
    let open = read_pde(&args.open)?;
    check_margins_correspond(&bud, &open).with_context(|| {
        format!(
            "cannot in-between {} and {}",
            args.bud.display(),
            args.open.display()
        )
    })?;
    let length = bud
        .point(DVec2::new(0.5, 1.0))
        .distance(bud.point(DVec2::new(0.5, 0.0)));
    let edge = args.edge.unwrap_or(length / 40.0);
    check_edge(&bud, edge)?;
    let mesh = build_organ(&bud, &RemeshOptions::new(edge))
        .with_context(|| format!("cannot mesh the bud {}", args.bud.display()))?
        .mesh;
    super::check_positions(mesh.vertex_count(), keyframes as u32)?;
    Ok((bud, open, mesh))
}

/// Refuses a mean edge that would mesh `bud` into more vertices than a
/// mesh may have, before any meshing (a tiny `--edge` once reported
/// capped, meaningless figures): the count is estimated from the bud's
/// area as an equilateral lattice has it, one vertex per √3/2·edge².
fn check_edge(bud: &PdeSweep, edge: f64) -> Result<()> {
    let limit = RemeshOptions::new(edge).max_vertices;
    let area = surface_area(bud);
    let per_vertex = 3f64.sqrt() / 2.0 * edge * edge;
    let estimated = area / per_vertex;
    if !estimated.is_finite() || estimated > limit as f64 {
        // The shortest edge within the limit, rounded up to 3 digits.
        let shortest = (area / (3f64.sqrt() / 2.0 * limit as f64)).sqrt();
        let magnitude = shortest.log10().floor();
        let unit = 10f64.powf(magnitude - 2.0);
        let decimals = (2.0 - magnitude).max(0.0) as usize;
        // (2 % above: the remesher counts a little more than the area.)
        let suggested = format!("{:.decimals$}", (1.02 * shortest / unit).ceil() * unit);
        bail!(
            "--edge {} would mesh the bud (area {area:.4}) into about {estimated:.2e} vertices; \
             a mesh may have at most {} (the largest organ the solver and the exports handle, as \
             `anthesis info` lists): use --edge {} or longer",
            anthesis_files::short_number(edge),
            crate::desktop::params::grouped(limit as u64),
            suggested,
        );
    }
    Ok(())
}

/// The area of `surface`, from a 64 × 64 grid of its points (two
/// triangles per cell): within a fraction of a percent for a smooth bud,
/// enough for a limit check.
fn surface_area(surface: &PdeSweep) -> f64 {
    const N: usize = 64;
    let at =
        |i: usize, j: usize| surface.point(DVec2::new(i as f64 / N as f64, j as f64 / N as f64));
    let mut area = 0.0;
    for i in 0..N {
        for j in 0..N {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            area += 0.5 * (b - a).cross(c - a).length() + 0.5 * (c - a).cross(d - a).length();
        }
    }
    area
}

/// Solves the in-betweening of `bud` and `open` (Chaudhry et al. §V).
fn in_between(
    args: &PdeBlossomArgs,
    bud: &PdeSweep,
    open: &PdeSweep,
    sizes: &Sizes,
) -> Result<SweepInBetween> {
    SweepInBetween::new(
        bud,
        open,
        sizes.nodes,
        sizes.rows,
        Dynamics {
            bend: args.bend,
            stretch: args.stretch,
            mass: args.mass,
        },
        sizes.keyframes,
        args.tolerance,
        sizes.max_corrections,
    )
    .with_context(|| {
        format!(
            "cannot in-between {} and {}",
            args.bud.display(),
            args.open.display()
        )
    })
}

/// The positions of `mesh`'s vertices at each of the `steps` + 1
/// keyframes: the bud's points moved by `motion`'s deformation. Refuses
/// positions that are not finite numbers.
fn keyframe_positions(
    args: &PdeBlossomArgs,
    bud: &PdeSweep,
    mesh: &Mesh,
    motion: &SweepInBetween,
    steps: usize,
) -> Result<Vec<Vec<DVec3>>> {
    let keyframes: Vec<Vec<glam::DVec3>> = (0..=steps)
        .map(|level| {
            mesh.uvs
                .iter()
                .map(|uv| bud.point(*uv) + motion.deformation(*uv, level))
                .collect()
        })
        .collect();
    if keyframes.iter().flatten().any(|p| !p.is_finite()) {
        bail!(
            "the in-betweening of {} and {} gave positions that are not finite numbers; try a \
             larger --mass or fewer --keyframes",
            args.bud.display(),
            args.open.display()
        );
    }
    Ok(keyframes)
}

/// Prints how the in-betweening went and writes it to `--report` if asked.
fn report(
    args: &PdeBlossomArgs,
    motion: &SweepInBetween,
    sizes: &Sizes,
    particles: usize,
    seconds: f64,
) -> Result<()> {
    let nodes = sizes.nodes;
    let steps = sizes.keyframes;
    let summary = motion.summary();
    out!(
        "{} generators of {} intervals, {} keyframes: force corrections (eq. 21) at most {}{}, \
         final error {:.2e} of the largest deformation (tolerance {:.0e}); {} particles; {seconds:.2} s",
        motion.rows.len(),
        nodes,
        steps,
        summary.corrections,
        if summary.solved {
            ", then the force solved from the linear response"
        } else {
            ""
        },
        summary.final_error,
        args.tolerance,
        particles,
    )?;
    if let Some(path) = &args.report {
        let report = serde_json::json!({
            "generators": motion.rows.len(),
            "intervals": nodes,
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
    Ok(())
}

/// Where along the organ (v) the margins are compared: from near the base
/// to near the tip (a pointed tip has no width).
const MARGIN_SAMPLES: usize = 18;

/// Refuses two states whose margins do not correspond, before anything is
/// solved: the open state's `margin0` must be on the bud's `margin0` side
/// at the base (where the organ is held), and neither state may fold
/// across itself (its width, margin to margin, turning back or vanishing
/// along the organ). Margins swapped in the open state were in-betweened
/// through a petal of zero width into a mirrored one, with "final error
/// 1.56e-14".
fn check_margins_correspond(bud: &impl Surface, open: &impl Surface) -> Result<()> {
    let across =
        |s: &dyn Surface, v: f64| s.point(DVec2::new(1.0, v)) - s.point(DVec2::new(0.0, v));
    let v_at = |k: usize| 0.05 + 0.9 * k as f64 / MARGIN_SAMPLES as f64;
    for (state, name) in [
        (bud as &dyn Surface, "bud"),
        (open as &dyn Surface, "open state"),
    ] {
        let length = state
            .point(DVec2::new(0.5, 1.0))
            .distance(state.point(DVec2::new(0.5, 0.0)));
        // Coordinates as large as a mesh may hold (1e308 overflowed the
        // dynamics into NaN without an error).
        let limit = anthesis_mesh::validate::MAX_COORDINATE;
        for i in 0..=8 {
            for j in 0..=8 {
                let uv = DVec2::new(f64::from(i) / 8.0, f64::from(j) / 8.0);
                let p = state.point(uv);
                if !(p.is_finite() && p.abs().max_element() <= limit) {
                    bail!(
                        "the {name} reaches ({:.3e}, {:.3e}, {:.3e}) at u = {:.2}, v = {:.2}; \
                         coordinates must be finite and within ±{limit:e}",
                        p.x,
                        p.y,
                        p.z,
                        uv.x,
                        uv.y
                    );
                }
            }
        }
        let mut before: Option<(f64, DVec3)> = None;
        for k in 0..=MARGIN_SAMPLES {
            let v = v_at(k);
            let width = across(state, v);
            if width.length().is_nan() || width.length() <= 1e-6 * length {
                bail!(
                    "the {name}'s margins meet at v = {v:.2} (no width between margin0 and \
                     margin1 there)"
                );
            }
            if let Some((v_before, width_before)) = before
                && width.dot(width_before) <= 0.0
            {
                bail!(
                    "the {name} folds across itself between v = {v_before:.2} and v = {v:.2} \
                     (margin0 and margin1 change sides)"
                );
            }
            before = Some((v, width));
        }
    }
    let (bud_width, open_width) = (across(bud, v_at(0)), across(open, v_at(0)));
    if bud_width.dot(open_width) <= 0.0 {
        bail!(
            "the open state's margins are the other way round from the bud's: at the base its \
             margin0 lies where the bud's margin1 is (the organ would pass through zero width \
             and open mirrored); swap margin0 with margin1 and tangent0 with tangent1 in one of \
             the files"
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The PDE reader, the margin check and the in-betweening on random
    /// edits of a valid pair: a valid result or a clean error, never a
    /// panic or a result that is not finite.
    #[test]
    fn fuzz_pde_blossom_reader_and_in_betweening() {
        let dir = tempfile::tempdir().expect("tempdir");
        let valid = super::super::bud::pde_json(&anthesis_bud::lily_petal_surface())
            .expect("the lily petal as JSON");
        let bud_path = dir.path().join("bud.json");
        std::fs::write(&bud_path, &valid).expect("write");
        let bud = read_pde(&bud_path).expect("the valid surface reads");
        let open_path = dir.path().join("open.json");
        let mut accepted = 0;
        super::super::fuzz::run("pde-blossom", |rng| {
            let text = super::super::fuzz::mutate(&valid, rng);
            std::fs::write(&open_path, &text).expect("write");
            let outcome = read_pde(&open_path).and_then(|open| {
                check_margins_correspond(&bud, &open)?;
                let motion = SweepInBetween::new(
                    &bud,
                    &open,
                    8,
                    4,
                    Dynamics {
                        bend: 1.0,
                        stretch: 0.0,
                        mass: 1.0,
                    },
                    5,
                    1e-6,
                    5,
                )?;
                for level in 0..=5 {
                    let d = motion.deformation(DVec2::new(0.3, 0.7), level);
                    anyhow::ensure!(d.is_finite(), "deformation {d} at level {level}");
                }
                Ok(())
            });
            match outcome {
                Ok(()) => accepted += 1,
                Err(error) => {
                    let message = format!("{error:#}");
                    assert!(
                        !message.contains("deformation"),
                        "a result that is not finite from {text}: {message}"
                    );
                    assert!(message.chars().count() < 800, "{message}");
                }
            }
        });
        assert!(accepted > 0, "some edits keep a valid surface");
    }
}

//! `anthesis import-scan`: a scanned petal (an OBJ of any triangulation,
//! UVs not needed) fitted by a PDE sweep surface (`anthesis_bud::fit_scan`)
//! and meshed as a template in the organ template frame, with the fit
//! error printed on one line.

use std::path::PathBuf;

use super::stream::{out, say};
use anthesis_bud::{RemeshOptions, ScanFitOptions, ScanOutline, build_organ, fit_scan};
use anyhow::{Context, Result, bail};
use clap::Args;

#[derive(Debug, Args)]
pub struct ImportScanArgs {
    /// The scan: an OBJ mesh of one petal, any triangulation, one outline
    /// (no holes), texture coordinates not needed.
    #[arg(value_name = "SCAN.obj")]
    pub scan: PathBuf,
    /// Write the fitted petal's mesh here (UVs by convention: u across,
    /// v from base to tip; base at the origin, growing along +Y, inner side
    /// towards -Z).
    #[arg(long, value_name = "FILE.obj")]
    pub out: PathBuf,
    /// The mean edge of the mesh (default: the petal's length / 36).
    #[arg(long, value_name = "LENGTH")]
    pub edge: Option<f64>,
    /// The seed's k_s/k_b of the fitted sweep, 0 to 100 (default: the best
    /// of 0, 2 and 10).
    #[arg(long, value_name = "K")]
    pub stretch_to_bend: Option<f64>,
    /// Take the side the scan is convex to as the inner one (default: the
    /// side it is concave to).
    #[arg(long)]
    pub flip_inner_side: bool,
    /// Write the fitted surface in `anthesis bud --pde` format.
    #[arg(long, value_name = "FILE.json")]
    pub save_surface: Option<PathBuf>,
    /// Write the fit's numbers as JSON.
    #[arg(long, value_name = "FILE.json")]
    pub report: Option<PathBuf>,
}

pub fn import_scan(args: &ImportScanArgs) -> Result<()> {
    if let Some(k) = args.stretch_to_bend
        && !(k.is_finite() && (0.0..=anthesis_bud::MAX_STRETCH_TO_BEND).contains(&k))
    {
        bail!("--stretch-to-bend must be from 0 to 100, got {k}");
    }
    let file = anthesis_mesh::load_obj_shape(&args.scan)
        .with_context(|| format!("cannot read the scan {}", args.scan.display()))?;
    for warning in &file.warnings {
        say!("{}: {warning}", args.scan.display());
    }
    let mesh = file.mesh;
    let outline = ScanOutline::of(&mesh)
        .with_context(|| format!("cannot use {} as a petal", args.scan.display()))?;
    let corners = outline.detect_corners(&mesh);
    let options = ScanFitOptions {
        stretch_to_bend: args.stretch_to_bend,
        flip_inner_side: args.flip_inner_side,
        ..ScanFitOptions::default()
    };
    let fit = fit_scan(&mesh, Some(corners), &options)
        .with_context(|| format!("cannot fit {}", args.scan.display()))?;
    let edge = args.edge.unwrap_or(fit.length / 36.0);
    if !(edge.is_finite() && edge > 0.0) {
        bail!("--edge must be a positive number, got {edge}");
    }
    let bud = build_organ(&fit.sweep, &RemeshOptions::new(edge))
        .context("cannot mesh the fitted surface")?;
    anthesis_files::write_atomic(&args.out, anthesis_mesh::obj_string(&bud.mesh).as_bytes())?;
    if let Some(path) = &args.save_surface {
        anthesis_files::write_atomic(path, super::bud::pde_json(&fit.sweep)?.as_bytes())?;
    }
    let [rms, max] = fit.relative_scan_to_surface();
    let [back_rms, back_max] = fit.relative_surface_to_scan();
    let vertex = |k: usize| mesh.positions[outline.vertex(k) as usize].to_array();
    if let Some(path) = &args.report {
        let report = serde_json::json!({
            "scan": args.scan.display().to_string(),
            "scan_vertices": mesh.vertex_count(),
            "scan_triangles": mesh.triangle_count(),
            "outline_vertices": outline.len(),
            "base_corners": [vertex(fit.corners.base[0]), vertex(fit.corners.base[1])],
            "tip": [vertex(fit.corners.tip[0]), vertex(fit.corners.tip[1])],
            "pointed_tip": fit.corners.pointed(),
            "length": fit.length,
            "scan_to_surface_rms": rms,
            "scan_to_surface_max": max,
            "surface_to_scan_rms": back_rms,
            "surface_to_scan_max": back_max,
            "stretch_to_bend": fit.sweep.stretch_to_bend(),
            "edge": edge,
            "vertices": bud.quality.vertices,
            "min_angle_deg": bud.quality.min_angle_deg,
        });
        anthesis_files::write_atomic(path, serde_json::to_string_pretty(&report)?.as_bytes())
            .with_context(|| format!("cannot write the report {}", path.display()))?;
    }
    out!(
        "length={:.4} rms={:.5} max={:.5} back_rms={:.5} back_max={:.5} stretch_to_bend={} vertices={} min_angle_deg={:.1}",
        fit.length,
        rms,
        max,
        back_rms,
        back_max,
        fit.sweep.stretch_to_bend(),
        bud.quality.vertices,
        bud.quality.min_angle_deg
    )?;
    say!("wrote {}", args.out.display());
    Ok(())
}

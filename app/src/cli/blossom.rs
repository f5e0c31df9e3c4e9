//! `anthesis blossom`: an organ animated from two shapes (its bud and its
//! open state) by the two-state blossom of `anthesis-twostate`, written as
//! the same animation files `anthesis simulate` writes.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anthesis_export::Track;
use anthesis_flower::MAX_KEYFRAMES;
use anthesis_mesh::Mesh;
use anthesis_mesh::obj::{MAX_OBJ_BYTES, object_text, parse_obj};
use anthesis_twostate::{GrowthFunction, TwoState};
use anyhow::{Context, Result, bail};
use clap::Args;

use super::EncodingArg;
use super::simulate::{animation_options, check_output, write_tracks};
use super::stream::{out, say};

/// `anthesis blossom BUD.obj OPEN.obj`.
#[derive(Debug, Args)]
pub struct BlossomArgs {
    /// The organ's bud: an OBJ with UVs (u across, v from base 0 to tip 1).
    pub bud: PathBuf,
    /// The open state: an OBJ with the bud's vertices in the same order and
    /// its triangles (e.g. the last file `anthesis simulate --out FOLDER/`
    /// wrote for one organ, or the bud edited in a modeller).
    pub open: PathBuf,
    /// The object (`o` name) to take from each OBJ, e.g. `petal-1` from the
    /// files `anthesis simulate --out FOLDER/` writes (default: the only
    /// object).
    #[arg(long)]
    pub object: Option<String>,
    /// Keyframes after the bud (the open state is the last), 1 to 10,000.
    #[arg(long, default_value_t = 100)]
    pub keyframes: i64,
    /// The growth rate g of G(t; g, T) (eq. 4): 6 reaches the open state's
    /// ratios at the last keyframe, more overshoots them, less stops short.
    #[arg(long, default_value_t = 6.0)]
    pub g: f64,
    /// Particles with v at most this are the base, held where the organ is
    /// attached (moved from their bud to their open place).
    #[arg(long, default_value_t = 0.06)]
    pub base_v: f64,
    /// Write the animation: FILE.glb, FILE.usda or FILE.usdc, otherwise a
    /// folder of one OBJ per keyframe.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Keyframes per second in the .glb or USD layer (default 24).
    #[arg(long)]
    pub fps: Option<f64>,
    /// How the .glb stores its data.
    #[arg(long, value_enum, default_value_t = EncodingArg::Dense)]
    pub encoding: EncodingArg,
}

pub(super) fn blossom(args: &BlossomArgs) -> Result<()> {
    if !(args.g.is_finite() && args.g > 0.0) {
        bail!("--g must be a positive number, got {}", args.g);
    }
    let keyframes =
        super::check_count("--keyframes", args.keyframes, 1, MAX_KEYFRAMES as usize)? as u32;
    let glb = animation_options(args.fps, args.encoding)?;
    if let Some(out) = &args.out {
        check_output(out, &glb, keyframes)?;
    }
    let read = |path: &Path, what: &str| -> Result<Mesh> {
        let text = anthesis_files::read_regular_text(path, MAX_OBJ_BYTES, "an OBJ mesh")
            .with_context(|| format!("cannot read the {what} {}", path.display()))?;
        object_text(&text, args.object.as_deref())
            .and_then(|text| parse_obj(&text))
            .with_context(|| format!("cannot read the {what} {}", path.display()))
    };
    let bud = read(&args.bud, "bud")?;
    let open = read(&args.open, "open state")?;
    super::check_positions(bud.vertex_count(), keyframes)?;
    let base: Vec<u32> = (0..bud.uvs.len() as u32)
        .filter(|&i| bud.uvs[i as usize].y <= args.base_v)
        .collect();
    let started = Instant::now();
    let mut two = TwoState::from_meshes(&bud, &open, &base).with_context(|| {
        format!(
            "cannot animate {} into {}",
            args.bud.display(),
            args.open.display()
        )
    })?;
    two.growth = GrowthFunction {
        g: args.g,
        duration: f64::from(keyframes),
    };
    let shapes: Vec<_> = (0..=keyframes)
        .map(|k| two.shape_at(f64::from(k)))
        .collect();
    let seconds = started.elapsed().as_secs_f64();

    let cells = two.cells();
    let median = |values: &mut Vec<f64>| {
        values.sort_by(f64::total_cmp);
        values[values.len() / 2]
    };
    let mut adaxial: Vec<f64> = cells.iter().map(|c| c.adaxial).collect();
    let mut abaxial: Vec<f64> = cells.iter().map(|c| c.abaxial).collect();
    let turn_deg = cells
        .iter()
        .map(|c| c.direction.to_axis_angle().1.to_degrees())
        .fold(0.0, f64::max);
    let last = &shapes[shapes.len() - 1];
    let miss = last
        .iter()
        .zip(&open.positions)
        .map(|(p, q)| p.distance(*q))
        .fold(0.0, f64::max);
    out!(
        "{} cells, {} base particles; adaxial variation median {:.3} (min {:.3}, max {:.3}), \
         abaxial median {:.3} (min {:.3}, max {:.3}); largest turn {turn_deg:.1} degrees; \
         last keyframe within {miss:.2e} of the open state; {} keyframes in {seconds:.2} s",
        cells.len(),
        base.len(),
        median(&mut adaxial),
        adaxial[0],
        adaxial[adaxial.len() - 1],
        median(&mut abaxial),
        abaxial[0],
        abaxial[abaxial.len() - 1],
        shapes.len(),
    )?;

    if let Some(out) = &args.out {
        let name = args.object.clone().unwrap_or_else(|| {
            args.bud
                .file_stem()
                .map_or_else(|| "organ".to_owned(), |s| s.to_string_lossy().into_owned())
        });
        let track = Track {
            name,
            triangles: bud.triangles.clone(),
            uvs: bud.uvs.clone(),
            base_colour: [0.95, 0.6, 0.3, 1.0],
            keyframes: shapes,
            ..Track::default()
        };
        write_tracks(out, &[track], &glb)?;
        say!("wrote {} (keyframes 0 to {})", out.display(), keyframes);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The open state's OBJ reader and the two-state blossom on random
    /// edits of a valid open state: a clean error or finite keyframes,
    /// never a panic.
    #[test]
    fn fuzz_blossom_open_state_reader_and_animation() {
        let bud = anthesis_mesh::generate::test_petal(4.0, 1.5, 4, 6);
        let mut open = bud.clone();
        for p in &mut open.positions {
            *p = glam::DVec3::new(p.x * 1.3, p.y * 1.2, p.z + 0.1 * p.y * p.y);
        }
        let valid = anthesis_mesh::obj_string(&open);
        let base: Vec<u32> = (0..bud.uvs.len() as u32)
            .filter(|&i| bud.uvs[i as usize].y <= 0.06)
            .collect();
        let mut accepted = 0;
        super::super::fuzz::run("blossom", |rng| {
            let text = super::super::fuzz::mutate(&valid, rng);
            let Ok(open) = parse_obj(&text) else {
                return;
            };
            match TwoState::from_meshes(&bud, &open, &base) {
                Ok(two) => {
                    for k in 0..=4 {
                        let shape = two.shape_at(f64::from(k) * 25.0);
                        assert!(
                            shape.iter().all(|p| p.is_finite()),
                            "keyframe {k} not finite from:\n{text}"
                        );
                    }
                    accepted += 1;
                }
                Err(error) => assert!(error.to_string().chars().count() < 800),
            }
        });
        assert!(accepted > 0, "some edits keep a valid open state");
    }
}

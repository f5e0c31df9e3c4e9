//! `anthesis bud`: an organ mesh from a parametric surface (a built-in
//! petal, a bicubic Bézier patch or a PDE sweep surface), remeshed by
//! `anthesis-bud` and written as OBJ, with its quality on one line.

use std::path::{Path, PathBuf};

use super::stream::{out, say};
use anthesis_bud::formats::{BezierFile, PdeFile};
use anthesis_bud::{
    BezierPatch, Bud, InnerSide, MeshQuality, PdeSweep, RemeshOptions, Surface, build_organ,
    eustoma_petal_surface, lily_petal_surface,
};
use anyhow::{Context, Result, bail};
use clap::{ArgGroup, Args, ValueEnum};

/// The surface file formats, shown by `anthesis bud --help`.
pub const SURFACE_FILES_HELP: &str = "\
Surfaces are in the organ template frame: the base at the origin, the organ
growing along +Y, its inner side (the side facing the flower axis) towards -Z.
The mesh UVs are the surface parameters: u across the organ, v from the base
(0) to the tip (1). Points are [x, y, z] arrays; unknown fields are refused.

--bezier FILE.json, a bicubic Bézier patch: 4 rows of 4 control points, the
rows along v from the base to the tip, the points of a row along u. The four
corners lie on the surface.
  {\"control\": [
    [[1, 0, 0], [0.3, 0, 0], [-0.3, 0, 0], [-1, 0, 0]],
    [[6, 12, 2], [2, 12, 5], [-2, 12, 5], [-6, 12, 2]],
    [[14, 26, 0], [5, 26, 6], [-5, 26, 6], [-14, 26, 0]],
    [[10, 34, -6], [4, 41, -2], [-4, 41, -2], [-10, 34, -6]]]}

--pde FILE.json, a PDE sweep surface: the two margins (u = 0 and u = 1) as
cubic Bézier curves of 4 control points from the base to the tip, the
derivatives dS/du across the organ at each margin as Bézier curves of 4
vectors, and optionally stretch_to_bend (k_s/k_b, 0 to 100, default 0: 0
sweeps cubic curves across, larger values pull them straight between the
margins). For a flat organ a tangent is about the vector from margin0 to
margin1; tilting tangent0 outwards (+Z) and tangent1 inwards (-Z) cups it
(the margins curl to the inner side).
A pointed tip: margins meeting at their last point, zero tangents there.
This example is the built-in lily petal.
  {\"margin0\":  [[1, 0, -0.1], [10, 15, 2], [9, 32, 0], [0, 47, -3]],
   \"margin1\":  [[-1, 0, -0.1], [-10, 15, 2], [-9, 32, 0], [0, 47, -3]],
   \"tangent0\": [[-2, 0, 0.4], [-20, 0, 12], [-18, 0, 12], [0, 0, 0]],
   \"tangent1\": [[-2, 0, -0.4], [-20, 0, -12], [-18, 0, -12], [0, 0, 0]],
   \"stretch_to_bend\": 0}

--save-surface FILE.json writes the surface in this format (an example
petal's too), a starting point for new shapes.";

#[derive(Debug, Args)]
#[command(
    group(ArgGroup::new("surface").required(true).args(["example", "bezier", "pde"])),
    after_long_help = SURFACE_FILES_HELP
)]
pub struct BudArgs {
    /// A built-in petal of a closed bud.
    #[arg(long, value_enum)]
    pub example: Option<Example>,
    /// A bicubic Bézier patch: 16 control points (format below).
    #[arg(long, value_name = "FILE.json")]
    pub bezier: Option<PathBuf>,
    /// A PDE sweep surface: two margin curves and their tangents (format
    /// below).
    #[arg(long, value_name = "FILE.json")]
    pub pde: Option<PathBuf>,
    /// The mean edge length to aim for, in the surface's units (default for
    /// the examples: the paper's 1.3 for the lily petal, 2.0 for the Eustoma
    /// petal).
    #[arg(long, value_name = "LENGTH", required_unless_present = "example")]
    pub edge: Option<f64>,
    /// Write the mesh as OBJ (positions, UVs, normals). Without it only the
    /// quality line is printed, to try edge lengths.
    #[arg(long, value_name = "FILE.obj")]
    pub out: Option<PathBuf>,
    /// Refuse the mesh if a triangle has a smaller angle (degrees).
    #[arg(long, value_name = "DEG", default_value_t = 20.0)]
    pub min_angle: f64,
    /// Which side of the surface is the organ's inner side: the one facing
    /// -Z on average, or the side dS/du x dS/dv points to, or the other.
    #[arg(long, value_enum, default_value_t = InnerSideArg::Auto)]
    pub inner_side: InnerSideArg,
    /// Also write the surface as JSON in the --bezier or --pde format.
    #[arg(long, value_name = "FILE.json")]
    pub save_surface: Option<PathBuf>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Example {
    /// A lily petal as a PDE sweep, about 40 long.
    LilyPetal,
    /// An Eustoma petal as a Bézier patch, about 38 long.
    EustomaPetal,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum InnerSideArg {
    Auto,
    Along,
    Against,
}

impl From<InnerSideArg> for InnerSide {
    fn from(side: InnerSideArg) -> InnerSide {
        match side {
            InnerSideArg::Auto => InnerSide::Auto,
            InnerSideArg::Along => InnerSide::AlongSurfaceNormal,
            InnerSideArg::Against => InnerSide::AgainstSurfaceNormal,
        }
    }
}

/// A surface read from the command line, kept as its type so it can be
/// saved again.
enum Shape {
    Bezier(BezierPatch),
    Pde(PdeSweep),
}

impl Shape {
    fn surface(&self) -> &dyn Surface {
        match self {
            Shape::Bezier(patch) => patch,
            Shape::Pde(sweep) => sweep,
        }
    }

    fn to_json(&self) -> Result<String> {
        let json = match self {
            Shape::Bezier(patch) => serde_json::to_string_pretty(&BezierFile::from(patch))?,
            Shape::Pde(sweep) => serde_json::to_string_pretty(&PdeFile::from(sweep))?,
        };
        Ok(json + "\n")
    }
}

pub fn bud(args: &BudArgs) -> Result<()> {
    let (shape, default_edge) = match (args.example, &args.bezier, &args.pde) {
        (Some(Example::LilyPetal), _, _) => (Shape::Pde(lily_petal_surface()), Some(1.3)),
        (Some(Example::EustomaPetal), _, _) => (Shape::Bezier(eustoma_petal_surface()), Some(2.0)),
        (None, Some(path), _) => (Shape::Bezier(read_bezier(path)?), None),
        (None, None, Some(path)) => (Shape::Pde(read_pde(path)?), None),
        // clap requires one of the three.
        (None, None, None) => bail!("give --example, --bezier or --pde"),
    };
    let Some(edge) = args.edge.or(default_edge) else {
        bail!("--edge is needed with --bezier and --pde");
    };
    if !(0.0..60.0).contains(&args.min_angle) {
        bail!(
            "--min-angle must be at least 0 and below 60 degrees, got {}",
            args.min_angle
        );
    }
    let options = RemeshOptions {
        min_angle_floor_deg: args.min_angle,
        inner_side: args.inner_side.into(),
        ..RemeshOptions::new(edge)
    };
    if let Some(path) = &args.save_surface {
        // Export errors name the file.
        anthesis_files::write_atomic(path, shape.to_json()?.as_bytes())?;
    }
    let Bud { mesh, quality } =
        build_organ(shape.surface(), &options).context("cannot mesh the surface")?;
    if let Some(out) = &args.out {
        anthesis_files::write_atomic(out, anthesis_mesh::obj_string(&mesh).as_bytes())?;
    }
    out!("{}", quality_line(&quality))?;
    if let Some(out) = &args.out {
        say!("wrote {}", out.display());
    }
    Ok(())
}

/// `vertices=.. triangles=.. edges=.. mean_edge=.. edge_spread=..
/// min_angle_deg=.. max_angle_deg=..` (the spread is the standard deviation
/// of the edge lengths over their mean).
fn quality_line(q: &MeshQuality) -> String {
    format!(
        "vertices={} triangles={} edges={} mean_edge={:.3} edge_spread={:.3} min_angle_deg={:.1} max_angle_deg={:.1}",
        q.vertices,
        q.triangles,
        q.edges,
        q.mean_edge,
        q.edge_spread,
        q.min_angle_deg,
        q.max_angle_deg
    )
}

/// A sweep in the `--pde` file format.
pub(super) fn pde_json(sweep: &PdeSweep) -> Result<String> {
    Ok(serde_json::to_string_pretty(&PdeFile::from(sweep))? + "\n")
}

/// Reads a surface file and parses it with `parse`; errors name the file.
/// The largest surface file read (`--bezier`, `--pde`, `pde-blossom`): a
/// surface is a few dozen numbers.
pub const MAX_SURFACE_BYTES: u64 = 1 << 20;

fn read_surface<T>(path: &Path, what: &str, parse: fn(&str) -> Result<T>) -> Result<T> {
    // A regular file of at most 1 MiB (a FIFO hung, /dev/zero filled the
    // memory).
    let text = anthesis_files::read_regular_text(path, MAX_SURFACE_BYTES, "a JSON surface")
        .with_context(|| format!("cannot read {what} {}", path.display()))?;
    parse(&text).with_context(|| {
        format!(
            "{what} {} is not valid (see `anthesis bud --help`)",
            path.display()
        )
    })
}

fn read_bezier(path: &Path) -> Result<BezierPatch> {
    read_surface(path, "Bézier patch", parse_bezier)
}

pub(super) fn read_pde(path: &Path) -> Result<PdeSweep> {
    read_surface(path, "PDE sweep surface", parse_pde)
}

/// A Bézier patch from the `--bezier` JSON.
fn parse_bezier(json: &str) -> Result<BezierPatch> {
    let file: BezierFile = serde_json::from_str(json)?;
    Ok(file.patch()?)
}

/// A PDE sweep surface from the `--pde` JSON.
fn parse_pde(json: &str) -> Result<PdeSweep> {
    let file: PdeFile = serde_json::from_str(json)?;
    Ok(file.sweep()?)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The JSON in the help text that starts with `start`, up to the next
    /// blank line.
    fn help_example(start: &str) -> &'static str {
        let at = SURFACE_FILES_HELP.find(start).expect("example in the help");
        let rest = &SURFACE_FILES_HELP[at..];
        &rest[..rest.find("\n\n").unwrap_or(rest.len())]
    }

    #[test]
    fn the_help_examples_parse_and_mesh() {
        let bezier = parse_bezier(help_example("{\"control\"")).expect("valid");
        let pde = parse_pde(help_example("{\"margin0\"")).expect("valid");
        for surface in [&bezier as &dyn Surface, &pde] {
            let bud = build_organ(surface, &RemeshOptions::new(1.5)).expect("meshes");
            assert!(bud.quality.vertices > 100, "{:?}", bud.quality);
        }
        // The PDE example is the built-in lily petal.
        assert_eq!(pde, lily_petal_surface());
    }

    #[test]
    fn saved_surfaces_parse_back_unchanged() {
        let pde = lily_petal_surface();
        let json = Shape::Pde(pde).to_json().expect("json");
        assert_eq!(parse_pde(&json).expect("parses"), pde);
        let patch = eustoma_petal_surface();
        let json = Shape::Bezier(patch).to_json().expect("json");
        assert_eq!(parse_bezier(&json).expect("parses"), patch);
    }

    #[test]
    fn control_point_counts_are_checked_by_name() {
        let row = "[[1,0,0],[0,0,0],[-1,0,0],[0,1,0]]";
        let three = format!("{{\"control\": [{row}, {row}, {row}]}}");
        let message = format!("{:#}", parse_bezier(&three).expect_err("3 rows"));
        assert!(
            message.contains("4 rows") && message.contains("found 3"),
            "{message}"
        );
        let short = format!("{{\"control\": [{row}, [[0,0,0]], {row}, {row}]}}");
        let message = format!("{:#}", parse_bezier(&short).expect_err("short row"));
        assert!(message.contains("row 2 of control"), "{message}");
        let pde = format!(
            "{{\"margin0\": {row}, \"margin1\": {row}, \"tangent0\": [[0,0,0]], \"tangent1\": {row}}}"
        );
        let message = format!("{:#}", parse_pde(&pde).expect_err("short tangent"));
        assert!(message.contains("tangent0 needs 4"), "{message}");
    }
}

//! `anthesis fit`: growth maps fitted to a target open shape of one organ
//! (`anthesis-fit`), written as a project that `anthesis simulate` runs
//! like any other, with a JSON report of how close the fit came.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use anthesis_fit::{Fit, FitProgress, FitSettings, Grid, Registered, Target};
use anthesis_mesh::obj::MAX_OBJ_BYTES;
use anyhow::{Context, Result, bail};
use clap::Args;

use super::stream::{out, say, say_part};
use super::{at_resolution, load, selection};

/// `anthesis fit PROJECT --organ NAME --target OPEN.obj --out FITTED_DIR`.
#[derive(Debug, Args)]
pub struct FitArgs {
    /// A project file (*.anthesis.toml), its folder, or builtin:NAME.
    pub project: PathBuf,
    /// The organ whose template's growth maps are fitted (every organ of
    /// that template takes them).
    #[arg(long)]
    pub organ: String,
    /// The open shape: an OBJ whose object named like the organ (or its
    /// only object) is a surface of any triangulation (any vertex count
    /// and order, UVs or none, polygons triangulated), in the project's
    /// world frame and units, or anywhere with --register.
    #[arg(long, value_name = "OPEN.obj")]
    pub target: PathBuf,
    /// First put the target on the organ: the rigid motion that best lays
    /// it on the organ's current shape with its base on the organ's base
    /// (for a scan or model in its own frame); reported, then refined as
    /// the fit goes.
    #[arg(long)]
    pub register: bool,
    /// With the registration, a uniform scale too (a target in other
    /// units); implies --register. The scale is found against the organ's
    /// current shape and then held.
    #[arg(long)]
    pub register_scale: bool,
    /// The target's inner side is the other one: its faces wind clockwise
    /// around the normal of its inner side (an organ's wind
    /// counter-clockwise). The registration lays a target's inner side on
    /// the organ's.
    #[arg(long)]
    pub flip_inner_side: bool,
    /// Time keys of the fitted maps, spread evenly over the run.
    #[arg(long, default_value_t = 1)]
    pub keys: u32,
    /// Nodes of the growth maps' hat basis, across x from base to tip.
    #[arg(long, value_name = "UxV", default_value = "3x4", value_parser = parse_grid)]
    pub nodes: Grid,
    /// Nodes of the growth direction's hat basis (0x0: along v throughout).
    #[arg(long, value_name = "UxV", default_value = "3x2", value_parser = parse_grid)]
    pub direction_nodes: Grid,
    /// The fit's time, from its start (the first guess and the first
    /// Jacobian included) to its result; the best maps so far are written
    /// when it runs out. Reading the project and the registration before,
    /// and simulating the written project once after (for the figures
    /// reported), are not counted.
    #[arg(long, default_value_t = 100.0)]
    pub max_seconds: f64,
    /// Levenberg–Marquardt iterations at most.
    #[arg(long, default_value_t = 30)]
    pub max_iterations: u32,
    /// The folder to write the fitted project to: created, or an empty
    /// folder (checked before the fit; the project is written beside it
    /// and moved in whole, so a failed write leaves nothing).
    #[arg(long, value_name = "FITTED_DIR")]
    pub out: PathBuf,
    /// Write the report (distances as fractions of the organ's length,
    /// iterations, seconds) as JSON.
    #[arg(long, value_name = "FIT.json")]
    pub report: Option<PathBuf>,
}

#[derive(serde::Serialize)]
struct Report<'a> {
    project: String,
    organ: &'a str,
    target: String,
    keys: u32,
    nodes: [usize; 2],
    direction_nodes: [usize; 2],
    parameters: usize,
    target_vertices: usize,
    target_has_uvs: bool,
    registration: Option<RegistrationReport>,
    organ_length: f64,
    guess_rms: f64,
    rms: f64,
    max: f64,
    reached: bool,
    stopped: &'static str,
    iterations: u32,
    simulations: usize,
    seconds: f64,
    threads: usize,
}

#[derive(serde::Serialize)]
struct RegistrationReport {
    /// Turned by this angle (degrees) about `axis`.
    angle_deg: f64,
    axis: [f64; 3],
    scale: f64,
    translation: [f64; 3],
    /// The target against the organ's current shape once registered.
    rms: f64,
    max: f64,
    /// The placement at the end of the fit (refined rigidly as it went).
    final_angle_deg: f64,
    final_translation: [f64; 3],
}

pub(super) fn fit(args: &FitArgs) -> Result<()> {
    check_numbers(args)?;
    let project = load(&args.project)?;
    let Some(organ) = selection(&project, Some(&args.organ))?
        .organs(project.flower.organs.len())
        .first()
        .copied()
    else {
        bail!("no organ named `{}`", args.organ);
    };
    if args.keys > project.settings.keyframes + 1 {
        bail!(
            "--keys {} is more than the run's {} keyframes and the bud",
            args.keys,
            project.settings.keyframes
        );
    }
    // Outputs are checked before the fit: a typo, a folder that cannot be
    // written or one holding a project must not cost a fit.
    let project_file = format!(
        "{}{}",
        file_stem(&args.project),
        anthesis_flower::project::PROJECT_EXTENSION
    );
    let staging = stage_out_folder(&args.out)?;
    if let Some(report) = &args.report {
        anthesis_files::check_destination(report)?;
    }
    let resolved = at_resolution(project.clone(), None, None)?;
    let text = anthesis_files::read_regular_text(&args.target, MAX_OBJ_BYTES, "an OBJ mesh")
        .with_context(|| format!("cannot read the target {}", args.target.display()))?;
    let mesh = &resolved.flower.template_of(organ).mesh;
    let mut target = anthesis_fit::read_target(&text, &args.organ, mesh)
        .with_context(|| format!("target {}", args.target.display()))?;
    if args.flip_inner_side {
        target = target.flipped();
    }
    for warning in &target.warnings {
        say!("target {}: {warning}", args.target.display());
    }

    let registered = if args.register || args.register_scale {
        let registered =
            anthesis_fit::register_target(&resolved, organ, &target, args.register_scale, &|| {
                false
            })
            .with_context(|| format!("cannot register the target on organ `{}`", args.organ))?;
        say!("{}", registered.describe());
        Some(registered)
    } else {
        None
    };
    let placement = registered.map_or(anthesis_fit::Similarity::IDENTITY, |r| {
        r.registration.placement
    });

    let settings = FitSettings {
        growth_nodes: args.nodes,
        direction_nodes: args.direction_nodes,
        keys: args.keys,
        max_iterations: args.max_iterations,
        max_seconds: args.max_seconds,
        refine_placement: registered.is_some(),
        ..FitSettings::default()
    };
    let terminal = std::io::stderr().is_terminal();
    let mut result = anthesis_fit::fit(
        &resolved,
        organ,
        &target,
        placement,
        &settings,
        &mut |p| show_progress(&p, terminal),
        &|| false,
    )
    .with_context(|| format!("cannot fit organ `{}`", args.organ))?;
    if terminal {
        say!();
    }

    // The project as it was, with the template's maps replaced: at its own
    // resolution the fitted maps apply unchanged (they live in UV). It is
    // written into the staging folder and moved into place whole.
    let mut fitted = project;
    let template = fitted.flower.organs[organ].template;
    fitted.flower.templates[template].maps = result.maps.clone();
    let staged_file = staging.path().join(&project_file);
    anthesis_flower::project::save_project(&fitted, &staged_file)
        .with_context(|| format!("cannot write the fitted project to {}", args.out.display()))?;
    // The figures reported are those of the project as written, simulated
    // as `anthesis simulate` will.
    let written = at_resolution(load(&staged_file)?, None, None)?;
    let shape = anthesis_fit::simulate_final(
        &written,
        organ,
        written.flower.template_of(organ).maps.clone(),
        &|| false,
    )
    .context("the fitted project does not simulate")?;
    (result.rms, result.max) = anthesis_fit::distances(
        &shape,
        &written.flower.template_of(organ).mesh.triangles,
        &target,
        result.placement,
        result.length,
    );
    move_into_place(staging, &args.out)?;
    let project_path = args.out.join(&project_file);
    say!("wrote {}", project_path.display());

    if let Some(path) = &args.report {
        write_report(path, args, registered, (&result, &target))?;
    }
    out!("{}", result.verdict())?;
    Ok(())
}

/// Refuses a time limit, node grid or key count that cannot make a fit.
fn check_numbers(args: &FitArgs) -> Result<()> {
    if !(args.max_seconds.is_finite() && args.max_seconds > 0.0) {
        bail!(
            "--max-seconds must be a positive number, got {}",
            args.max_seconds
        );
    }
    if args.nodes.is_empty() {
        bail!("--nodes needs at least one node each way, e.g. 1x3");
    }
    if args.keys == 0 {
        bail!("--keys must be at least 1");
    }
    Ok(())
}

/// One iteration of the fit on stderr: overwritten in place on a
/// terminal, one line each otherwise.
fn show_progress(p: &FitProgress, terminal: bool) {
    let line = format!(
        "iteration {}: RMS {:.3} %, max {:.3} % of the organ's length, {} simulations, \
         {:.1} s",
        p.iteration,
        100.0 * p.rms,
        100.0 * p.max,
        p.simulations,
        p.seconds
    );
    if terminal {
        say_part!("\r{line}   ");
    } else {
        say!("{line}");
    }
}

/// Writes the `--report` JSON: what was fitted, the registration, the
/// error before and after, and how the fit ended.
fn write_report(
    path: &Path,
    args: &FitArgs,
    registered: Option<Registered>,
    (result, target): (&Fit, &Target),
) -> Result<()> {
    let registration = registered.map(|r| {
        let placement = r.registration.placement;
        let (axis, angle) = placement.rotation.to_axis_angle();
        RegistrationReport {
            angle_deg: angle.to_degrees(),
            axis: axis.to_array(),
            scale: placement.scale,
            translation: placement.translation.to_array(),
            rms: r.rms,
            max: r.max,
            final_angle_deg: result.placement.angle_deg(),
            final_translation: result.placement.translation.to_array(),
        }
    });
    let report = Report {
        project: args.project.display().to_string(),
        organ: &args.organ,
        target: args.target.display().to_string(),
        keys: args.keys,
        nodes: [args.nodes.nodes_u, args.nodes.nodes_v],
        direction_nodes: [args.direction_nodes.nodes_u, args.direction_nodes.nodes_v],
        parameters: result.parameters.len(),
        target_vertices: target.vertex_count(),
        target_has_uvs: target.uvs.is_some(),
        registration,
        organ_length: result.length,
        guess_rms: result.guess_rms,
        rms: result.rms,
        max: result.max,
        reached: result.reached(),
        stopped: result.stop.name(),
        iterations: result.iterations,
        simulations: result.simulations,
        seconds: result.seconds,
        threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    let json = serde_json::to_string_pretty(&report)?;
    anthesis_files::write_atomic(path, json.as_bytes())?;
    Ok(())
}

/// The name the fitted project file takes: the built-in flower's name, or
/// the project file's name without its extension.
fn file_stem(project: &Path) -> String {
    if let Some(name) = project.to_str().and_then(|p| p.strip_prefix("builtin:")) {
        return name.to_string();
    }
    let file = anthesis_flower::project::project_file(project).unwrap_or(project.to_path_buf());
    let name = file
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let stem = name
        .strip_suffix(anthesis_flower::project::PROJECT_EXTENSION)
        .unwrap_or(&name);
    if stem.is_empty() {
        "fitted".to_string()
    } else {
        stem.to_string()
    }
}

/// Checks `--out` before the fit and makes the staging folder the project
/// is written into: `out` must be a new folder in an existing one, or an
/// empty folder; the staging folder, made beside it, shows that its
/// parent can be written to, and is removed whatever happens unless
/// [`move_into_place`] moves it.
fn stage_out_folder(out: &Path) -> Result<tempfile::TempDir> {
    if out.exists() && !out.is_dir() {
        bail!("--out {} must be a folder", out.display());
    }
    if out.is_dir() {
        super::refuse_project_folder(out)?;
        let empty = std::fs::read_dir(out)
            .with_context(|| format!("cannot read the folder {}", out.display()))?
            .next()
            .is_none();
        if !empty {
            bail!(
                "--out {} is not empty; choose an empty or new folder",
                out.display()
            );
        }
    } else {
        super::simulate::check_creatable_folder(out)?;
    }
    let parent = anthesis_files::folder_of(out);
    tempfile::Builder::new()
        .prefix(".anthesis-fit-")
        .tempdir_in(&parent)
        .with_context(|| {
            format!(
                "--out {}: cannot write in {}",
                out.display(),
                parent.display()
            )
        })
}

/// Moves the staged project folder to `out` (an empty `out` is replaced).
fn move_into_place(staging: tempfile::TempDir, out: &Path) -> Result<()> {
    if out.is_dir() {
        std::fs::remove_dir(out)
            .with_context(|| format!("cannot replace the empty folder {}", out.display()))?;
    }
    std::fs::rename(staging.path(), out)
        .with_context(|| format!("cannot move the fitted project to {}", out.display()))?;
    // The folder is now `out`; nothing is left to remove.
    let _ = staging.keep();
    Ok(())
}

/// `--nodes 3x4`: nodes across and along, each at least 1 (0x0 only for
/// the direction, meaning no direction nodes).
fn parse_grid(text: &str) -> Result<Grid, String> {
    let bad = || format!("`{text}` is not a node grid: write it as UxV, e.g. 3x4");
    let (u, v) = text.trim().split_once(['x', 'X']).ok_or_else(bad)?;
    let nodes_u: usize = u.trim().parse().map_err(|_| bad())?;
    let nodes_v: usize = v.trim().parse().map_err(|_| bad())?;
    if (nodes_u == 0) != (nodes_v == 0) || nodes_u > 16 || nodes_v > 16 {
        return Err(format!(
            "`{text}`: give 1 to 16 nodes each way (0x0 for no direction nodes)"
        ));
    }
    Ok(Grid { nodes_u, nodes_v })
}

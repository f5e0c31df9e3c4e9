//! `anthesis fit`: growth maps fitted to a target open shape of one organ
//! (`anthesis-fit`), written as a project that `anthesis simulate` runs
//! like any other, with a JSON report of how close the fit came.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};

use anthesis_fit::{FitSettings, Grid};
use anthesis_mesh::obj::MAX_OBJ_BYTES;
use anyhow::{Context, Result, bail};
use clap::Args;

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
    /// only object) has the organ's vertices in the same order, in world
    /// coordinates, as `anthesis simulate --organ NAME --out FOLDER/`
    /// writes them.
    #[arg(long, value_name = "OPEN.obj")]
    pub target: PathBuf,
    /// Time keys of the fitted maps, spread evenly over the run.
    #[arg(long, default_value_t = 1)]
    pub keys: u32,
    /// Nodes of the growth maps' hat basis, across x from base to tip.
    #[arg(long, value_name = "UxV", default_value = "3x4", value_parser = parse_grid)]
    pub nodes: Grid,
    /// Nodes of the growth direction's hat basis (0x0: along v throughout).
    #[arg(long, value_name = "UxV", default_value = "3x2", value_parser = parse_grid)]
    pub direction_nodes: Grid,
    /// Start no fresh Jacobian that would end after this many seconds.
    #[arg(long, default_value_t = 50.0)]
    pub max_seconds: f64,
    /// Levenberg–Marquardt iterations at most.
    #[arg(long, default_value_t = 30)]
    pub max_iterations: u32,
    /// The folder to write the fitted project to (created if missing;
    /// refused if it already holds a project).
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
    organ_length: f64,
    guess_rms: f64,
    rms: f64,
    max: f64,
    reached: bool,
    iterations: u32,
    simulations: usize,
    seconds: f64,
    threads: usize,
}

pub(super) fn fit(args: &FitArgs) -> Result<()> {
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
    // Outputs are checked before the fit: a typo must not cost a fit.
    let project_path = args.out.join(format!(
        "{}{}",
        file_stem(&args.project),
        anthesis_flower::project::PROJECT_EXTENSION
    ));
    check_out_folder(&args.out)?;
    if let Some(report) = &args.report {
        anthesis_files::check_destination(report)?;
    }
    let resolved = at_resolution(project.clone(), None, None)?;
    let text = anthesis_files::read_regular_text(&args.target, MAX_OBJ_BYTES, "an OBJ mesh")
        .with_context(|| format!("cannot read the target {}", args.target.display()))?;
    let mesh = &resolved.flower.template_of(organ).mesh;
    let target = anthesis_fit::read_target(&text, &args.organ, mesh)
        .with_context(|| format!("target {}", args.target.display()))?;

    let settings = FitSettings {
        growth_nodes: args.nodes,
        direction_nodes: args.direction_nodes,
        keys: args.keys,
        max_iterations: args.max_iterations,
        max_seconds: args.max_seconds,
        ..FitSettings::default()
    };
    let terminal = std::io::stderr().is_terminal();
    let mut result = anthesis_fit::fit(
        &resolved,
        organ,
        &target,
        &settings,
        &mut |p| {
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
                eprint!("\r{line}   ");
                let _ = std::io::stderr().flush();
            } else {
                eprintln!("{line}");
            }
        },
        &|| false,
    )
    .with_context(|| format!("cannot fit organ `{}`", args.organ))?;
    if terminal {
        eprintln!();
    }

    // The project as it was, with the template's maps replaced: at its own
    // resolution the fitted maps apply unchanged (they live in UV).
    let mut fitted = project;
    let template = fitted.flower.organs[organ].template;
    fitted.flower.templates[template].maps = result.maps.clone();
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create the folder {}", args.out.display()))?;
    anthesis_flower::project::save_project(&fitted, &project_path)?;
    eprintln!("wrote {}", project_path.display());
    // The figures reported are those of the project as written, simulated
    // as `anthesis simulate` will.
    let written = at_resolution(load(&project_path)?, None, None)?;
    let shape = anthesis_fit::simulate_final(
        &written,
        organ,
        written.flower.template_of(organ).maps.clone(),
        &|| false,
    )
    .with_context(|| {
        format!(
            "the fitted project {} does not simulate",
            project_path.display()
        )
    })?;
    (result.rms, result.max) = anthesis_fit::distances(&shape, &target, result.length);

    if let Some(path) = &args.report {
        let report = Report {
            project: args.project.display().to_string(),
            organ: &args.organ,
            target: args.target.display().to_string(),
            keys: args.keys,
            nodes: [args.nodes.nodes_u, args.nodes.nodes_v],
            direction_nodes: [args.direction_nodes.nodes_u, args.direction_nodes.nodes_v],
            parameters: result.parameters.len(),
            organ_length: result.length,
            guess_rms: result.guess_rms,
            rms: result.rms,
            max: result.max,
            reached: result.reached(),
            iterations: result.iterations,
            simulations: result.simulations,
            seconds: result.seconds,
            threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
        };
        let json = serde_json::to_string_pretty(&report)?;
        anthesis_files::write_atomic(path, json.as_bytes())?;
    }
    writeln!(std::io::stdout().lock(), "{}", result.verdict())?;
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

/// Refuses an `--out` that is a file or a folder already holding a
/// project, or whose parent folder does not exist.
fn check_out_folder(out: &Path) -> Result<()> {
    if out.exists() && !out.is_dir() {
        bail!("--out {} must be a folder", out.display());
    }
    if out.is_dir() {
        super::refuse_project_folder(out)?;
    } else {
        super::simulate::check_creatable_folder(out)?;
    }
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

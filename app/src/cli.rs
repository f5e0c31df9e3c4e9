//! `anthesis info|simulate|render|bud|import-scan|blossom|fit`: the engine without a window, for
//! batch work, CI and benchmarks. Errors print as one line and exit
//! non-zero. Each subcommand lives in a module of `cli/`.

mod blossom;
mod bud;
mod fit;
#[cfg(test)]
mod fuzz;
mod import_scan;
mod measure;
pub mod pde_blossom;
mod render;
mod simulate;
pub(crate) mod stream;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anthesis_export::{Encoding, GlbOptions, Timing};
use anthesis_flower::project::load_project_with_warnings;
use anthesis_flower::{Project, Resolution};
use anthesis_sim::Selection;
use anthesis_sim::memory::KeyframeCost;
use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand, ValueEnum};
use stream::say;

pub use bud::{BudArgs, Example, InnerSideArg};
pub use render::RenderArgs;

#[derive(Debug, Parser)]
#[command(
    name = "anthesis",
    version,
    about = "Author flower-opening animations by painting growth.",
    args_conflicts_with_subcommands = true
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Without a command: the project the window opens (a project file, its
    /// folder, or builtin:NAME; default: the last one, else the lily).
    #[arg(value_name = "PROJECT")]
    pub project: Option<PathBuf>,
    /// Remesh every time instead of keeping remeshed templates in the user
    /// cache (`$ANTHESIS_CACHE_DIR/remesh`, else
    /// `$XDG_CACHE_HOME/anthesis/remesh`, else `~/.cache/anthesis/remesh`;
    /// `ANTHESIS_CACHE_DIR=` set empty turns it off too). Given after the
    /// command: `anthesis simulate --no-cache …`.
    #[arg(long, global = true)]
    pub no_cache: bool,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Print one line per organ: name, template, particles, triangles, edges.
    Info {
        /// A project file (*.anthesis.toml), its folder, or builtin:NAME.
        project: PathBuf,
        /// Count the particles at this resolution (see `simulate --edge`).
        #[arg(long, value_name = "LENGTH|as-built", value_parser = parse_edge)]
        edge: Option<Resolution>,
    },
    /// Simulate a project and write statistics and the animation.
    Simulate {
        /// A project file (*.anthesis.toml), its folder, or builtin:NAME.
        project: PathBuf,
        /// Simulate only this organ (single-organ preview, no collisions).
        #[arg(long)]
        organ: Option<String>,
        /// Number of keyframes, 1 to 10,000 (default: the project's).
        #[arg(long)]
        keyframes: Option<i64>,
        /// Simulate every template remeshed at this mean edge length, in
        /// project units (the painted maps apply unchanged), or `as-built`
        /// for the meshes as they are (default: the project's
        /// `[simulation] mean_edge`, else as built).
        #[arg(long, value_name = "LENGTH|as-built", value_parser = parse_edge)]
        edge: Option<Resolution>,
        /// Write per-keyframe statistics as JSON.
        #[arg(long, value_name = "FILE.json")]
        stats: Option<PathBuf>,
        /// Write the animation: FILE.glb for an animated glTF, FILE.usda
        /// (text) or FILE.usdc (binary) for a USD layer (one time sample
        /// per keyframe), otherwise a
        /// folder that receives one OBJ per keyframe.
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
        /// Keyframes per second in the .glb or USD layer (default 24).
        #[arg(long, conflicts_with = "duration")]
        fps: Option<f64>,
        /// Length of the whole .glb or USD animation in seconds.
        #[arg(long)]
        duration: Option<f64>,
        /// Most morph targets per mesh in the .glb; longer runs are resampled.
        #[arg(long, default_value_t = anthesis_export::DEFAULT_MAX_MORPH_TARGETS)]
        max_targets: usize,
        /// Leave normals out of the .glb or USD layer (smaller; clients compute
        /// them: three.js shades a .glb without normals flat).
        #[arg(long)]
        no_normals: bool,
        /// How the .glb stores its data.
        #[arg(long, value_enum, default_value_t = EncodingArg::Dense)]
        encoding: EncodingArg,
        /// Export each organ as a smooth render mesh: N levels of Loop
        /// subdivision of the simulated mesh, about 4^N times the vertices
        /// (0 = the simulated mesh).
        #[arg(long, value_name = "N", default_value_t = 0)]
        subdivide: u32,
        /// Go on past a keyframe whose triangles cross (an organ through
        /// another, a part or itself), with a warning naming them, instead
        /// of stopping there with an error and a non-zero exit.
        #[arg(long)]
        allow_crossings: bool,
    },
    /// Simulate a project and render chosen keyframes to PNG pictures, all
    /// seen by one camera.
    Render(RenderArgs),
    /// Mesh an organ from a parametric surface (a built-in petal, a Bézier
    /// patch or a PDE sweep surface), write it as OBJ and print its quality.
    Bud(BudArgs),
    /// Fit a scanned petal (an OBJ of any triangulation without UVs) by a
    /// PDE sweep surface, print the fit error as fractions of its length
    /// and write it meshed as a template OBJ.
    ImportScan(import_scan::ImportScanArgs),
    /// Animate one organ from two shapes, its bud and its open state (the
    /// two-state blossom: per-triangle growth ellipses, G(t; g, T) and a
    /// spherical interpolation of directions), without a growth simulation.
    Blossom(blossom::BlossomArgs),
    /// Animate a swept organ between two PDE sweep surfaces (its bud and
    /// its open state) by the PDE-driven in-betweening of
    /// Chaudhry et al. §V: each generator's deformation from the
    /// dynamic equation (13), its force corrected (eq. 21) until the open
    /// state is met.
    PdeBlossom(pde_blossom::PdeBlossomArgs),
    /// Fit growth maps to a target open shape of one organ ("which maps make
    /// it open like this?") and write the project with the fitted maps.
    Fit(fit::FitArgs),
    /// Simulate a project and write its measurements per keyframe and organ
    /// as a CSV table (curvatures, stretches, midrib, margin, contact area).
    Measure(measure::MeasureArgs),
    /// Write a starting point as a project folder: a flower built into the
    /// binary (lily, eustoma-maite-lady, eustoma-mellow-yellow,
    /// eustoma-pinocchio, apple, lily-decay, or five-petal: an empty flower
    /// of five simple petals), to paint and change from there.
    New {
        /// The starting point's name.
        #[arg(long = "from", value_name = "NAME")]
        from: String,
        /// The folder to write (created if missing; refused if it already
        /// holds a project or any file the project would write, so nothing
        /// is overwritten).
        dir: PathBuf,
    },
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum EncodingArg {
    /// Plain 32-bit floats: read by every glTF tool.
    Dense,
    /// Morph targets store only the vertices that move.
    Sparse,
    /// KHR_mesh_quantization: 16- and 8-bit integers.
    Quantized,
    /// Quantized and compressed with EXT_meshopt_compression: the smallest;
    /// readers need a meshopt decoder (three.js: setMeshoptDecoder).
    Meshopt,
}

impl From<EncodingArg> for Encoding {
    fn from(e: EncodingArg) -> Encoding {
        match e {
            EncodingArg::Dense => Encoding::Dense,
            EncodingArg::Sparse => Encoding::Sparse,
            EncodingArg::Quantized => Encoding::Quantized,
            EncodingArg::Meshopt => Encoding::Meshopt,
        }
    }
}

pub fn main() -> ExitCode {
    stream::guard();
    let cli = match parse() {
        Ok(cli) => cli,
        Err(e) => {
            // Help and version are not errors.
            let code = if e.use_stderr() {
                ExitCode::from(2)
            } else if stream::stdout_closed() {
                // The help had nowhere to go.
                say!("error: cannot write to standard output: it is closed");
                ExitCode::FAILURE
            } else {
                ExitCode::SUCCESS
            };
            return match e.print() {
                Ok(()) => code,
                Err(_) if e.use_stderr() => code,
                Err(error) => {
                    say!("error: cannot write to standard output: {error}");
                    ExitCode::FAILURE
                }
            };
        }
    };
    if !cli.no_cache {
        install_remesh_cache();
    }
    let command = cli.command.is_some();
    // `info` says the unit in its size lines already.
    let says_its_unit = matches!(cli.command, Some(Command::Info { .. }));
    let result = run(cli);
    let notes = stream::take_notes();
    if result.is_ok() && !says_its_unit {
        for note in notes {
            say!("{note}");
        }
    }
    match result {
        // A command that could not say what it did on standard error
        // (`2>/dev/full`) has still written its files; it ends non-zero.
        Ok(()) if command && stream::stderr_failure().is_some() => ExitCode::FAILURE,
        Ok(()) => ExitCode::SUCCESS,
        // A reader that stopped reading (`anthesis info … | head -1`) is not
        // an error worth a message.
        Err(e) if is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            say!("error: {}", one_line(&error_message(&e)));
            ExitCode::FAILURE
        }
    }
}

/// The command line, with every option's value allowed to be a negative
/// number (`--keyframes -5`, `--edge -1`: read as values and refused with
/// their range, not taken for unknown options).
fn parse() -> Result<Cli, clap::Error> {
    use clap::{CommandFactory, FromArgMatches};
    let negative_values = |arg: clap::Arg| {
        if arg.get_action().takes_values() {
            arg.allow_negative_numbers(true)
        } else {
            arg
        }
    };
    let command = Cli::command()
        .mut_args(negative_values)
        .mut_subcommands(|sub| sub.mut_args(negative_values));
    Cli::from_arg_matches(&command.try_get_matches()?)
}

/// Keeps remeshed templates in the user's cache for this process (the
/// command line's and the window's remeshes:
/// `anthesis_flower::remesh_cache`).
fn install_remesh_cache() {
    use anthesis_files::cache::Cache;
    anthesis_flower::remesh_cache::install(Cache::user(anthesis_flower::remesh_cache::FOLDER));
}

/// Says on the terminal, once, why the remesh cache could not be written
/// (the command goes on without it).
pub(crate) fn warn_about_the_cache() {
    if let Some(warning) = anthesis_flower::remesh_cache::installed().take_warning() {
        say!("warning: {warning}");
    }
}

/// The error and its causes, outermost first, joined by `: `, each said
/// once: a cause whose text an earlier part already holds is left out, and
/// a context that only repeats the start of its cause gives way to it
/// ("cannot write x.glb" before "cannot write x.glb: no such folder").
fn error_message(error: &anyhow::Error) -> String {
    let mut parts: Vec<String> = Vec::new();
    for cause in error.chain() {
        let text = cause.to_string();
        if parts.iter().any(|part| part.contains(&text)) {
            continue;
        }
        match parts.last_mut() {
            Some(last) if text.starts_with(last.as_str()) => *last = text,
            _ => parts.push(text),
        }
    }
    parts.join(": ")
}

/// Whether `error` comes from writing to a pipe whose reader has gone.
fn is_broken_pipe(error: &anyhow::Error) -> bool {
    error.chain().any(|cause| {
        cause
            .downcast_ref::<std::io::Error>()
            .is_some_and(|e| e.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

/// Folds a multi-line message (TOML errors quote the offending line) into
/// one line.
fn one_line(message: &str) -> String {
    message
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && *l != "|")
        .collect::<Vec<_>>()
        .join(" ")
}

pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        // No subcommand: the desktop window, on PROJECT if one is given.
        None => match cli.project.as_deref() {
            None => crate::desktop::run(None, Vec::new()),
            Some(path) => {
                refuse_unknown_subcommand(path)?;
                let (project, file, warnings) = open(path)?;
                crate::desktop::run(Some((project, file)), warnings)
            }
        },
        Some(Command::Info { project, edge }) => simulate::info(&project, edge),
        Some(Command::Simulate {
            project,
            organ,
            keyframes,
            edge,
            stats,
            out,
            fps,
            duration,
            max_targets,
            no_normals,
            encoding,
            subdivide,
            allow_crossings,
        }) => {
            let keyframes = keyframes
                .map(|n| check_count("--keyframes", n, 1, anthesis_flower::MAX_KEYFRAMES as usize))
                .transpose()?
                .map(|n| n as u32);
            let timing = match (fps, duration) {
                (_, Some(d)) if d > 0.0 && d.is_finite() => Timing::Duration(d),
                (_, Some(d)) => {
                    bail!("--duration must be a number of seconds above 0 (and finite), got {d}")
                }
                (Some(f), None) if f > 0.0 && f.is_finite() => Timing::FramesPerSecond(f),
                (Some(f), None) => bail!(
                    "--fps must be a number of keyframes per second above 0 (and finite), got {f}"
                ),
                (None, None) => Timing::FramesPerSecond(anthesis_export::DEFAULT_FRAMES_PER_SECOND),
            };
            let glb = GlbOptions {
                timing,
                max_morph_targets: max_targets,
                normals: !no_normals,
                encoding: encoding.into(),
            };
            simulate::simulate(
                &project,
                simulate::RunChoice {
                    organ: organ.as_deref(),
                    keyframes,
                    edge,
                    allow_crossings,
                },
                stats.as_deref(),
                out.as_deref(),
                &glb,
                subdivide,
            )
        }
        Some(Command::Render(args)) => render::render(&args),
        Some(Command::Bud(args)) => bud::bud(&args),
        Some(Command::ImportScan(args)) => import_scan::import_scan(&args),
        Some(Command::Blossom(args)) => blossom::blossom(&args),
        Some(Command::PdeBlossom(args)) => pde_blossom::pde_blossom(&args),
        Some(Command::Fit(args)) => fit::fit(&args),
        Some(Command::Measure(args)) => measure::measure(&args),
        Some(Command::New { from, dir }) => new_project(&from, &dir),
    }
}

/// Refuses a first word that is neither a subcommand nor a project
/// (`anthesis grow` said "grow: it does not exist"): a plain word with no
/// file or folder of that name is taken for a mistyped subcommand. A path
/// that exists still opens as a project.
fn refuse_unknown_subcommand(path: &Path) -> Result<()> {
    use clap::CommandFactory;
    let Some(word) = path.to_str() else {
        return Ok(());
    };
    let plain = !word.is_empty()
        && word
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
    if !plain || path.exists() {
        return Ok(());
    }
    let names: Vec<String> = Cli::command()
        .get_subcommands()
        .map(|sub| sub.get_name().to_owned())
        .filter(|name| name != "help")
        .collect();
    bail!(
        "`{word}` is not a subcommand (they are: {}) and no project file or folder of that name \
         exists",
        names.join(", ")
    );
}

/// Loads a project file, or a flower built into the binary when the path
/// is `builtin:NAME` (`builtin:lily`, `builtin:eustoma-maite-lady`, …).
fn load(path: &Path) -> Result<Project> {
    load_with_warnings(path).map(|(project, _)| project)
}

/// [`load`], with what loading read past (an OBJ's loose edges, a mesh
/// wound inside out): said on the terminal, and returned for the window's
/// log; the command goes on.
fn load_with_warnings(path: &Path) -> Result<(Project, Vec<String>)> {
    if let Some(name) = path.to_str().and_then(|p| p.strip_prefix("builtin:")) {
        return match anthesis_garden::builtin(name) {
            Some(project) => Ok((
                project.context("the built-in flower does not load")?,
                Vec::new(),
            )),
            None => bail!(
                "no built-in flower `{name}` (there are: {})",
                anthesis_garden::builtin_names().join(", ")
            ),
        };
    }
    // The project error names the file itself.
    let mut loaded = load_project_with_warnings(path).context("cannot open project")?;
    for warning in &loaded.warnings {
        say!("warning: {warning}");
    }
    check_units(&loaded.project)?;
    if let Some(note) = anthesis_flower::unit::note_if_unstated(&loaded.project) {
        stream::note_at_end(note.clone());
        loaded.warnings.push(note);
    }
    Ok((loaded.project, loaded.warnings))
}

/// The project the window opens at `path`, the file it saves to (none for
/// a built-in flower, which Save asks a place for) and what loading read
/// past.
fn open(path: &Path) -> Result<(Project, Option<PathBuf>, Vec<String>)> {
    let (project, warnings) = load_with_warnings(path)?;
    let file = if path.to_str().is_some_and(|p| p.starts_with("builtin:")) {
        None
    } else {
        Some(anthesis_flower::project::project_file(path).context("cannot open project")?)
    };
    Ok((project, file, warnings))
}

/// Refuses folder `dir` if it already holds a project file, so nothing is
/// overwritten.
fn refuse_project_folder(dir: &Path) -> Result<()> {
    let existing = std::fs::read_dir(dir)
        .with_context(|| format!("cannot read the folder {}", dir.display()))?
        .filter_map(Result::ok)
        .any(|entry| {
            entry
                .file_name()
                .to_string_lossy()
                .ends_with(anthesis_flower::project::PROJECT_EXTENSION)
        });
    if existing {
        bail!(
            "{} already holds a project; choose an empty or new folder",
            dir.display()
        );
    }
    Ok(())
}

/// `anthesis new --from NAME DIR`: the built-in flower NAME saved as
/// `DIR/NAME.anthesis.toml` with its meshes and maps.
///
/// Decided: `new` writes only files it creates. The project is written into
/// a staging folder inside DIR first; if any of its files (the project,
/// `meshes/…`, `maps/…`) is already in DIR, nothing is written and the
/// error names that file (a user's own `meshes/petal.obj` was replaced with
/// exit 0). Each file is then linked into place, which fails rather than
/// replace a file made meanwhile.
fn new_project(from: &str, dir: &Path) -> Result<()> {
    let project = load(Path::new(&format!("builtin:{from}")))?;
    if dir.is_dir() {
        refuse_project_folder(dir)?;
    } else {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create the folder {}", dir.display()))?;
    }
    let name = format!("{from}{}", anthesis_flower::project::PROJECT_EXTENSION);
    let staging = tempfile::Builder::new()
        .prefix(".anthesis-new-")
        .tempdir_in(dir)
        .with_context(|| format!("cannot write in the folder {}", dir.display()))?;
    anthesis_flower::project::save_project(&project, &staging.path().join(&name))?;
    let files = files_under(staging.path())?;
    if let Some(existing) = files
        .iter()
        .map(|relative| dir.join(relative))
        .find(|path| path.symlink_metadata().is_ok())
    {
        bail!(
            "{} already exists; `new` writes only files it creates: choose an empty or new \
             folder, or move that file away",
            existing.display()
        );
    }
    for relative in &files {
        let target = dir.join(relative);
        if let Some(parent) = target.parent() {
            std::fs::create_dir_all(parent)
                .with_context(|| format!("cannot create the folder {}", parent.display()))?;
        }
        std::fs::hard_link(staging.path().join(relative), &target)
            .or_else(|_| move_if_absent(&staging.path().join(relative), &target))
            .with_context(|| format!("cannot write {}", target.display()))?;
    }
    say!("wrote {}", dir.join(&name).display());
    Ok(())
}

/// Moves `from` to `to` unless `to` exists (where hard links are not
/// supported).
fn move_if_absent(from: &Path, to: &Path) -> std::io::Result<()> {
    if to.symlink_metadata().is_ok() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::AlreadyExists,
            "the file already exists",
        ));
    }
    std::fs::rename(from, to)
}

/// The files under `root`, as paths relative to it.
fn files_under(root: &Path) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    let mut folders = vec![PathBuf::new()];
    while let Some(relative) = folders.pop() {
        let folder = root.join(&relative);
        for entry in std::fs::read_dir(&folder)
            .with_context(|| format!("cannot read the folder {}", folder.display()))?
        {
            let entry = entry.with_context(|| format!("cannot read {}", folder.display()))?;
            let path = relative.join(entry.file_name());
            if entry.file_type().is_ok_and(|t| t.is_dir()) {
                folders.push(path);
            } else {
                files.push(path);
            }
        }
    }
    files.sort();
    Ok(files)
}

/// `--edge`: a positive length, or `as-built`.
fn parse_edge(text: &str) -> Result<Resolution, String> {
    if text.trim() == "as-built" {
        return Ok(Resolution::AsBuilt);
    }
    match text.trim().parse::<f64>() {
        Ok(edge) if edge > 0.0 && edge.is_finite() => Ok(Resolution::MeanEdge(edge)),
        _ => Err(format!(
            "`{text}` is not a mean edge length: give a positive number in project units, or \
             as-built"
        )),
    }
}

/// The project to simulate: every template remeshed at the project's
/// resolution, or at `edge` when given (`anthesis_flower::resolution`).
/// With `memory`, the run of `selection` is checked against the memory
/// first, on the sizes the remeshed meshes will have, so that a too-fine
/// edge is refused before anything is remeshed.
fn at_resolution(
    mut project: Project,
    edge: Option<Resolution>,
    memory: Option<(&Selection, KeyframeCost)>,
) -> Result<Project> {
    let from_command_line = edge.is_some();
    if let Some(edge) = edge {
        project.settings.resolution = edge;
    }
    check_particle_limit(&project, from_command_line)?;
    if let Some((selection, cost)) = memory {
        anthesis_sim::memory::check_run(&project, selection, cost)?;
    }
    let resolved = anthesis_flower::resolution::resolve(&project);
    warn_about_the_cache();
    Ok(resolved?)
}

/// Refuses a mean edge that would remesh a template into more particles
/// than [`anthesis_flower::resolution::MAX_PARTICLES_PER_TEMPLATE`], with
/// the finest edge the limit allows, before anything is remeshed (`--edge
/// 1e-9` was refused by the memory check with "16384 PiB" of capped
/// figures, or overflowed in the remesher).
fn check_particle_limit(project: &Project, from_command_line: bool) -> Result<()> {
    use anthesis_flower::resolution::{
        MAX_PARTICLES_PER_TEMPLATE, edge_for_particles, predicted_size,
    };
    let Some(edge) = project.settings.resolution.mean_edge() else {
        return Ok(());
    };
    for template in &project.flower.templates {
        let (particles, _) = predicted_size(&template.mesh, edge);
        if particles > MAX_PARTICLES_PER_TEMPLATE {
            let what = if from_command_line {
                format!("--edge {edge}")
            } else {
                format!("the project's mean_edge {edge}")
            };
            let finest = edge_for_particles(&template.mesh, MAX_PARTICLES_PER_TEMPLATE)
                .map(|finest| format!("; give a mean edge of at least {}", round_up(finest)))
                .unwrap_or_default();
            bail!(
                "{what} would remesh template \"{}\" into about {} particles, more than the \
                 limit of {} per template{finest}",
                template.name,
                crate::desktop::params::grouped(particles as u64),
                crate::desktop::params::grouped(MAX_PARTICLES_PER_TEMPLATE as u64),
            );
        }
    }
    Ok(())
}

/// `value` rounded up to three significant digits (an edge the limit
/// allows, said in a message).
fn round_up(value: f64) -> f64 {
    if !(value > 0.0 && value.is_finite()) {
        return value;
    }
    let scale = 10f64.powi(2 - value.log10().floor() as i32);
    (value * scale).ceil() / scale
}

/// Refuses a count given on the command line outside `min..=max`, naming
/// the option and the range.
/// (Counts are read as any whole number, so `--keyframes -5` is refused
/// with its range, not taken for an unknown option.)
pub(crate) fn check_count(option: &str, value: i64, min: usize, max: usize) -> Result<usize> {
    match usize::try_from(value) {
        Ok(count) if (min..=max).contains(&count) => Ok(count),
        _ => bail!(
            "{option} must be a whole number from {min} to {}, got {value}",
            crate::desktop::params::grouped(max as u64)
        ),
    }
}

/// Refuses an animation of `vertices` per keyframe over `keyframes` (and
/// the first shape) that holds more positions than an export may
/// ([`anthesis_export::MAX_RENDER_POSITIONS`]), before any is computed.
pub(crate) fn check_positions(vertices: usize, keyframes: u32) -> Result<()> {
    let positions = (vertices as u64).saturating_mul(u64::from(keyframes) + 1);
    if positions > anthesis_export::MAX_RENDER_POSITIONS {
        bail!(
            "{} vertices x {} shapes is {} positions, more than the limit of {}: use fewer \
             keyframes or a coarser mesh",
            vertices,
            u64::from(keyframes) + 1,
            crate::desktop::params::grouped(positions),
            crate::desktop::params::grouped(anthesis_export::MAX_RENDER_POSITIONS),
        );
    }
    Ok(())
}

/// Refuses a project with a mesh in another unit than the project (see
/// `anthesis_flower::scale`): it would fail at the first keyframe with a
/// message that says nothing about the cause.
fn check_units(project: &Project) -> Result<()> {
    match anthesis_flower::scale::check_flower(&project.flower).first() {
        Some(mismatch) => bail!("{mismatch}"),
        None => Ok(()),
    }
}

/// All organs, or the one named `organ` (an error lists the names).
fn selection(project: &Project, organ: Option<&str>) -> Result<Selection> {
    let Some(name) = organ else {
        return Ok(Selection::All);
    };
    match project.flower.organ_index(name) {
        Some(i) => Ok(Selection::Only(i)),
        None => {
            let names: Vec<&str> = project
                .flower
                .organs
                .iter()
                .map(|o| o.name.as_str())
                .collect();
            bail!("no organ named `{name}` (organs: {})", names.join(", "));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_project_opened_in_the_window_brings_what_loading_read_past() {
        // `anthesis PROJECT` opens the window: the loader's warnings go to
        // its log (they were said on the terminal only).
        let dir = tempfile::tempdir().expect("temp dir");
        let mut project = anthesis_garden::five_petal::five_petal().expect("the five-petal start");
        project.flower.templates[0].mesh =
            anthesis_bud::with_inner_side_flipped(&project.flower.templates[0].mesh);
        let path = dir.path().join("flipped.anthesis.toml");
        anthesis_flower::project::save_project(&project, &path).expect("save");
        let (opened, file, warnings) = open(&path).expect("opens with a warning");
        assert_eq!(file.as_deref(), Some(path.as_path()));
        assert_eq!(
            opened.flower.templates.len(),
            project.flower.templates.len()
        );
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        assert!(
            warnings[0].contains("the inner side faces +Z"),
            "{warnings:?}"
        );
        // A built-in flower reads nothing past.
        let (_, file, warnings) = open(Path::new("builtin:lily")).expect("the lily");
        assert_eq!((file, warnings.len()), (None, 0));
    }

    #[test]
    fn each_cause_is_said_once() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "No such file or directory");
        // What `cannot write /proc/x.glb` used to print twice over.
        let error = anyhow::Error::new(io)
            .context("cannot write /proc/x.glb: No such file or directory")
            .context("cannot write /proc/x.glb");
        assert_eq!(
            error_message(&error),
            "cannot write /proc/x.glb: No such file or directory"
        );
        let error = anyhow::anyhow!("not converged").context("keyframe 3");
        assert_eq!(error_message(&error), "keyframe 3: not converged");
    }
}

//! `anthesis info|simulate`: the engine without a window, for batch work,
//! CI and benchmarks. Errors print as one line and exit non-zero.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anthesis_export::{Encoding, GlbOptions, Timing, Track};
use anthesis_flower::Project;
use anthesis_flower::project::load_project;
use anthesis_sim::{KeyframeStats, Selection, Simulation};
use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand, ValueEnum};
use glam::DVec3;

#[derive(Debug, Parser)]
#[command(
    name = "anthesis",
    version,
    about = "Author flower-opening animations by painting growth."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Print one line per organ: name, template, particles, triangles, edges.
    Info {
        /// A project file (*.anthesis.toml).
        project: PathBuf,
    },
    /// Simulate a project and write statistics and the animation.
    Simulate {
        /// A project file (*.anthesis.toml).
        project: PathBuf,
        /// Simulate only this organ (single-organ preview, no collisions).
        #[arg(long)]
        organ: Option<String>,
        /// Number of keyframes (default: the project's).
        #[arg(long)]
        keyframes: Option<u32>,
        /// Write per-keyframe statistics as JSON.
        #[arg(long, value_name = "FILE.json")]
        stats: Option<PathBuf>,
        /// Write the animation: FILE.glb for an animated glTF, otherwise a
        /// folder that receives one OBJ per keyframe.
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
        /// Keyframes per second in the .glb (default 24).
        #[arg(long, conflicts_with = "duration")]
        fps: Option<f64>,
        /// Length of the whole .glb animation in seconds.
        #[arg(long)]
        duration: Option<f64>,
        /// Most morph targets per mesh in the .glb; longer runs are resampled.
        #[arg(long, default_value_t = anthesis_export::DEFAULT_MAX_MORPH_TARGETS)]
        max_targets: usize,
        /// Leave normals out of the .glb (smaller; clients compute them).
        #[arg(long)]
        no_normals: bool,
        /// How the .glb stores its data.
        #[arg(long, value_enum, default_value_t = EncodingArg::Dense)]
        encoding: EncodingArg,
    },
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum EncodingArg {
    Dense,
    Sparse,
    Quantized,
}

impl From<EncodingArg> for Encoding {
    fn from(e: EncodingArg) -> Encoding {
        match e {
            EncodingArg::Dense => Encoding::Dense,
            EncodingArg::Sparse => Encoding::Sparse,
            EncodingArg::Quantized => Encoding::Quantized,
        }
    }
}

pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            // Help and version are not errors.
            let code = if e.use_stderr() {
                ExitCode::from(2)
            } else {
                ExitCode::SUCCESS
            };
            let _ = e.print();
            return code;
        }
    };
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", one_line(&format!("{e:#}")));
            ExitCode::FAILURE
        }
    }
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
        None => {
            println!(
                "anthesis: the desktop application is not built yet. The command line works:\n  \
                 anthesis info PROJECT\n  anthesis simulate PROJECT [--organ NAME] [--keyframes N] [--stats FILE.json] [--out FILE.glb|DIR]\n\
                 (see `anthesis --help`)"
            );
            Ok(())
        }
        Some(Command::Info { project }) => info(&project),
        Some(Command::Simulate {
            project,
            organ,
            keyframes,
            stats,
            out,
            fps,
            duration,
            max_targets,
            no_normals,
            encoding,
        }) => {
            let timing = match (fps, duration) {
                (_, Some(d)) if d > 0.0 && d.is_finite() => Timing::Duration(d),
                (_, Some(d)) => bail!("--duration must be a positive number of seconds, got {d}"),
                (Some(f), None) if f > 0.0 && f.is_finite() => Timing::FramesPerSecond(f),
                (Some(f), None) => bail!("--fps must be positive, got {f}"),
                (None, None) => Timing::FramesPerSecond(anthesis_export::DEFAULT_FRAMES_PER_SECOND),
            };
            let glb = GlbOptions {
                timing,
                max_morph_targets: max_targets,
                normals: !no_normals,
                encoding: encoding.into(),
            };
            simulate(
                &project,
                organ.as_deref(),
                keyframes,
                stats.as_deref(),
                out.as_deref(),
                &glb,
            )
        }
    }
}

fn load(path: &Path) -> Result<Project> {
    // The project error names the file itself.
    load_project(path).context("cannot open project")
}

fn info(path: &Path) -> Result<()> {
    let project = load(path)?;
    let flower = &project.flower;
    for (i, organ) in flower.organs.iter().enumerate() {
        let template = flower.template_of(i);
        let topology = anthesis_mesh::validate(&template.mesh)
            .with_context(|| format!("template `{}` has a bad mesh", template.name))?;
        println!(
            "{} {} {} {} {}",
            organ.name,
            template.name,
            template.mesh.vertex_count(),
            template.mesh.triangle_count(),
            topology.edges.len()
        );
    }
    Ok(())
}

#[derive(serde::Serialize)]
struct StatsFile<'a> {
    project: &'a str,
    organs: Vec<String>,
    keyframes: &'a [KeyframeStats],
    total_seconds: f64,
    threads: usize,
}

fn simulate(
    path: &Path,
    organ: Option<&str>,
    keyframes: Option<u32>,
    stats_path: Option<&Path>,
    out: Option<&Path>,
    glb: &GlbOptions,
) -> Result<()> {
    let mut project = load(path)?;
    if let Some(n) = keyframes {
        if n == 0 {
            bail!("--keyframes must be at least 1");
        }
        project.settings.keyframes = n;
    }
    let selection = match organ {
        None => Selection::All,
        Some(name) => match project.flower.organ_index(name) {
            Some(i) => Selection::Only(i),
            None => {
                let names: Vec<&str> = project
                    .flower
                    .organs
                    .iter()
                    .map(|o| o.name.as_str())
                    .collect();
                bail!("no organ named `{name}` (organs: {})", names.join(", "));
            }
        },
    };
    if let Some(out) = out {
        check_output(out)?;
    }

    let started = Instant::now();
    let mut sim = Simulation::new(&project, &selection)?;
    let total = sim.keyframe_count();
    let mut frames: Vec<Vec<Vec<DVec3>>> = vec![sim.bud().positions];
    let mut stats = Vec::with_capacity(total as usize);
    let show_progress = std::io::stderr().is_terminal();
    while !sim.finished() {
        let keyframe = sim.step(&|| false, &mut |_| {})?;
        if show_progress {
            let done = keyframe.index;
            let elapsed = started.elapsed().as_secs_f64();
            let left = elapsed / f64::from(done) * f64::from(total - done);
            eprint!("\rkeyframe {done}/{total}  {elapsed:.1} s, about {left:.1} s left   ");
            let _ = std::io::stderr().flush();
        }
        stats.push(keyframe.stats);
        frames.push(keyframe.positions);
    }
    let seconds = started.elapsed().as_secs_f64();
    if show_progress {
        eprintln!();
    }
    eprintln!(
        "simulated {total} keyframes of {} organ(s) in {seconds:.2} s",
        sim.organs().len()
    );

    if let Some(stats_path) = stats_path {
        let file = StatsFile {
            project: &project.name,
            organs: sim.organs().iter().map(|s| s.to_string()).collect(),
            keyframes: &stats,
            total_seconds: seconds,
            threads: rayon_threads(),
        };
        let json = serde_json::to_string_pretty(&file)?;
        anthesis_export::write_atomic(stats_path, json.as_bytes())
            .with_context(|| format!("cannot write statistics to {}", stats_path.display()))?;
    }
    if let Some(out) = out {
        let tracks = tracks(&sim, &frames);
        if is_glb(out) {
            anthesis_export::write_glb(out, &tracks, glb, &mut |_| {})
                .with_context(|| format!("cannot write {}", out.display()))?;
        } else {
            anthesis_export::write_obj_sequence(out, &tracks)
                .with_context(|| format!("cannot write OBJ files to {}", out.display()))?;
        }
        eprintln!("wrote {}", out.display());
    }
    Ok(())
}

fn is_glb(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"))
}

/// Fails early, before a long simulation, when the output cannot be written.
fn check_output(out: &Path) -> Result<()> {
    if is_glb(out) {
        let parent = out
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        if !parent.is_dir() {
            bail!(
                "cannot write {}: folder {} does not exist",
                out.display(),
                parent.display()
            );
        }
    } else if out.exists() && !out.is_dir() {
        bail!(
            "--out {} must be a .glb file or a folder for OBJ files",
            out.display()
        );
    }
    Ok(())
}

fn tracks(sim: &Simulation, frames: &[Vec<Vec<DVec3>>]) -> Vec<Track> {
    sim.organs()
        .iter()
        .enumerate()
        .map(|(i, name)| Track {
            name: name.to_string(),
            triangles: sim.triangles(i).to_vec(),
            uvs: sim.uvs(i).to_vec(),
            base_color: sim.color(i),
            keyframes: frames.iter().map(|f| f[i].clone()).collect(),
            base_color_png: None,
        })
        .collect()
}

fn rayon_threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

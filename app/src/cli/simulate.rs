//! `anthesis info` and `anthesis simulate`, and the keyframe loop with
//! progress that `anthesis render` shares.

use std::io::IsTerminal;
use std::path::Path;
use std::time::Instant;

use anthesis_export::GlbOptions;
use anthesis_flower::{MAX_KEYFRAMES, Resolution};
use anthesis_sim::batch::{self, Format};
use anthesis_sim::crossing::OnCrossing;
use anthesis_sim::memory::KeyframeCost;
use anthesis_sim::{KeyframeStats, SimError, Simulation};
use anyhow::{Context, Result, bail};

use super::stream::{out, say, say_part};
use super::{
    EncodingArg, at_resolution, check_particle_limit, load, selection, warn_about_the_cache,
};

pub(super) fn info(path: &Path, edge: Option<Resolution>) -> Result<()> {
    let project = at_resolution(load(path)?, edge, None)?;
    let flower = &project.flower;
    // Each template's mesh checked once, not once per organ (10,000 organs).
    let edges = flower
        .templates
        .iter()
        .map(|template| {
            anthesis_mesh::validate(&template.mesh)
                .map(|topology| topology.edges.len())
                .with_context(|| format!("template `{}` has a bad mesh", template.name))
        })
        .collect::<Result<Vec<_>>>()?;
    for (i, organ) in flower.organs.iter().enumerate() {
        let template = flower.template_of(i);
        out!(
            "{} {} {} {} {}",
            organ.name,
            template.name,
            template.mesh.vertex_count(),
            template.mesh.triangle_count(),
            edges[organ.template]
        )?;
    }
    let parts = anthesis_flower::parts::part_lines(flower);
    for line in parts
        .iter()
        .chain(&anthesis_flower::unit::size_lines(flower))
    {
        out!("{line}")?;
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

/// What a run simulates besides the project: one organ or all, how many
/// keyframes, at which resolution (each `None`: the project's).
pub(super) struct RunChoice<'a> {
    pub(super) organ: Option<&'a str>,
    pub(super) keyframes: Option<u32>,
    pub(super) edge: Option<Resolution>,
    /// Go on past crossing keyframes with a warning (`--allow-crossings`).
    pub(super) allow_crossings: bool,
}

pub(super) fn simulate(
    path: &Path,
    RunChoice {
        organ,
        keyframes,
        edge,
        allow_crossings,
    }: RunChoice<'_>,
    stats_path: Option<&Path>,
    out: Option<&Path>,
    glb: &GlbOptions,
    render_level: u32,
) -> Result<()> {
    let mut project = load(path)?;
    set_keyframes(&mut project, keyframes)?;
    if let Some(edge) = edge {
        project.settings.resolution = edge;
    }
    let selection = selection(&project, organ)?;
    // Every output is checked before the run: a typo must not cost a
    // simulation.
    if let Some(stats_path) = stats_path {
        anthesis_files::check_destination(stats_path)?;
    }
    if let Some(out) = out {
        check_output(out, glb, project.settings.keyframes)?;
    }
    let cost = out.map_or(KeyframeCost::Kept, |out| output_format(out).keyframe_cost());
    check_particle_limit(&project, edge.is_some())?;
    let prepared = batch::prepare(&project, &selection, cost, out.map(|_| render_level));
    warn_about_the_cache();
    let project = prepared?;

    let (run, run_result) = run_with_progress(&project, &selection, allow_crossings)?;
    let done = run.stepped.done;

    if let Some(stats_path) = stats_path {
        let stats: Vec<KeyframeStats> = run.keyframes[1..].iter().map(|k| k.stats).collect();
        let file = StatsFile {
            project: &project.name,
            organs: run
                .simulation
                .organs()
                .iter()
                .map(|s| s.to_string())
                .collect(),
            keyframes: &stats,
            total_seconds: run.stepped.seconds,
            threads: rayon_threads(),
        };
        let json = serde_json::to_string_pretty(&file)?;
        // The error names the file.
        anthesis_files::write_atomic(stats_path, json.as_bytes())?;
    }
    let mut written = None;
    if let Some(out) = out
        && done > 0
    {
        let tracks = run.tracks(&project, &selection, render_level)?;
        write_tracks(out, &tracks, glb)?;
        say!("wrote {} (keyframes 0 to {done})", out.display());
        written = Some(out);
    }
    match (run_result, written) {
        (Ok(_), _) => Ok(()),
        (Err(failure), Some(out)) => Err(failure.context(format!(
            "the keyframes before it were written to {} (keyframes 0 to {done})",
            out.display()
        ))),
        (Err(failure), None) if out.is_some() => {
            Err(failure.context("no keyframe was computed, nothing was written"))
        }
        (Err(failure), None) => Err(failure),
    }
}

/// Sets the run's keyframe count from `--keyframes`, within the limits
/// (a billion keyframes aborted on a 40 GB allocation).
pub(super) fn set_keyframes(
    project: &mut anthesis_flower::Project,
    keyframes: Option<u32>,
) -> Result<()> {
    if let Some(n) = keyframes {
        if n == 0 {
            bail!("--keyframes must be at least 1");
        }
        if n > MAX_KEYFRAMES {
            bail!("--keyframes {n} is more than the limit of {MAX_KEYFRAMES}");
        }
        project.settings.keyframes = n;
    }
    Ok(())
}
/// Runs `project` to the end with the terminal's progress line, stopping at
/// a crossing unless `allow_crossings`: the run, and what `Progress::finish`
/// made of it (the seconds, or the failure that ended it early).
pub(super) fn run_with_progress(
    project: &anthesis_flower::Project,
    selection: &anthesis_sim::Selection,
    allow_crossings: bool,
) -> Result<(batch::BatchRun, Result<f64>)> {
    let on_crossing = if allow_crossings {
        OnCrossing::Warn
    } else {
        OnCrossing::Stop
    };
    let mut progress = Progress::new();
    let mut run = batch::simulate(project, selection, on_crossing, &|| false, &mut |sim, k| {
        progress.show(sim, k.index, sim.keyframe_count())
    })?;
    let finished = progress.finish(&run.simulation, run.stepped.failure.take());
    Ok((run, finished))
}

/// The progress of a run on stderr: the keyframe and the time left while
/// stderr is a terminal, the crossings it goes on past as warnings, and a
/// summary line at the end.
pub(super) struct Progress {
    started: Instant,
    show: bool,
    /// The crossings already warned about.
    warned: usize,
    done: u32,
}

impl Progress {
    pub(super) fn new() -> Progress {
        Progress {
            started: Instant::now(),
            show: std::io::stderr().is_terminal(),
            warned: 0,
            done: 0,
        }
    }

    /// Shows that `sim` computed keyframe `done` of `last`.
    pub(super) fn show(&mut self, sim: &Simulation, done: u32, last: u32) {
        for crossing in &sim.crossings()[self.warned.min(sim.crossings().len())..] {
            if self.show {
                say!();
            }
            say!("warning: {crossing}");
        }
        self.warned = sim.crossings().len();
        self.done = done;
        if self.show {
            let elapsed = self.started.elapsed().as_secs_f64();
            let left = elapsed / f64::from(done) * f64::from(last - done);
            say_part!("\rkeyframe {done}/{last}  {elapsed:.1} s, about {left:.1} s left   ");
        }
    }

    /// Ends the progress of `sim`'s run, which stopped with `failure` if
    /// it did; returns the run's seconds or why it stopped.
    pub(super) fn finish(self, sim: &Simulation, failure: Option<SimError>) -> Result<f64> {
        let seconds = self.started.elapsed().as_secs_f64();
        if self.show && self.done > 0 {
            say!();
        }
        match failure {
            None => {
                say!(
                    "simulated {} keyframes of {} organ(s) in {seconds:.2} s ({} Hessian factorisations)",
                    self.done,
                    sim.organs().len(),
                    sim.factorisations()
                );
                Ok(seconds)
            }
            Some(error @ SimError::Crossed(_)) => Err(anyhow::Error::new(error).context(
                "the run stopped where organs cross (`--allow-crossings` goes on with a warning)",
            )),
            Some(error) => Err(anyhow::Error::new(error)),
        }
    }
}

/// What `--out` writes: the format its extension names, else a folder
/// that receives one OBJ per keyframe.
pub(super) fn output_format(out: &Path) -> Format {
    Format::from_path(out).unwrap_or(Format::ObjFolder)
}

/// Writes `tracks` to `out` in the format its name asks for
/// ([`output_format`]): a .glb, a USD layer, or one OBJ per keyframe into a
/// folder (created when missing).
pub(super) fn write_tracks(
    out: &Path,
    tracks: &[anthesis_export::Track],
    glb: &GlbOptions,
) -> Result<()> {
    batch::write(out, output_format(out), tracks, glb, &mut |_| {})?;
    Ok(())
}

/// Fails early, before a long simulation, when `--out` cannot be written:
/// a .glb needs a folder and export options that fit `keyframes`; a folder
/// for OBJ files may be missing if its parent exists (it is created when
/// the files are written).
pub(super) fn check_output(out: &Path, glb: &GlbOptions, keyframes: u32) -> Result<()> {
    match output_format(out) {
        Format::Glb => {
            anthesis_files::check_destination(out)?;
            // The bud and every keyframe.
            glb.check(keyframes as usize + 1)?;
        }
        Format::Usd => anthesis_export::check_usd_destination(out)?,
        Format::Gif => bail!(
            "--out {}: a GIF is rendered, by `anthesis render --animation`; --out takes a \
             .glb, .usda or .usdc file or a folder for OBJ files",
            out.display()
        ),
        Format::ObjFolder if out.exists() && !out.is_dir() => bail!(
            "--out {} must be a .glb, .usda or .usdc file or a folder for OBJ files",
            out.display()
        ),
        Format::ObjFolder if out.is_dir() => {}
        Format::ObjFolder => check_creatable_folder(out)?,
    }
    Ok(())
}

/// `--out` folder `out`, which does not exist yet, can be made: its parent
/// folder exists.
pub(super) fn check_creatable_folder(out: &Path) -> Result<()> {
    let parent = anthesis_files::folder_of(out);
    if !parent.is_dir() {
        bail!(
            "--out {}: cannot create the folder, {} does not exist",
            out.display(),
            parent.display()
        );
    }
    Ok(())
}

/// The .glb options of a two-state or PDE animation at `fps` keyframes per
/// second (default [`anthesis_export::DEFAULT_FRAMES_PER_SECOND`]).
pub(super) fn animation_options(fps: Option<f64>, encoding: EncodingArg) -> Result<GlbOptions> {
    let fps = fps.unwrap_or(anthesis_export::DEFAULT_FRAMES_PER_SECOND);
    if !(fps.is_finite() && fps > 0.0) {
        bail!("--fps must be a number of keyframes per second above 0 (and finite), got {fps}");
    }
    Ok(GlbOptions {
        timing: anthesis_export::Timing::FramesPerSecond(fps),
        max_morph_targets: anthesis_export::DEFAULT_MAX_MORPH_TARGETS,
        normals: true,
        encoding: encoding.into(),
    })
}

fn rayon_threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

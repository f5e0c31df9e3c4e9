//! `anthesis info` and `anthesis simulate`, and the keyframe loop with
//! progress that `anthesis render` shares.

use std::io::IsTerminal;
use std::path::Path;
use std::time::Instant;

use anthesis_export::{GlbOptions, UsdOptions};
use anthesis_flower::{MAX_KEYFRAMES, Resolution};
use anthesis_sim::crossing::OnCrossing;
use anthesis_sim::memory::{self, KeyframeCost};
use anthesis_sim::{Keyframe, KeyframeStats, SimError, Simulation};
use anyhow::{Context, Result, bail};
use glam::DVec3;

use super::stream::{out, say, say_part};
use super::{EncodingArg, at_resolution, load, selection};

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
    let selection = selection(&project, organ)?;
    // Every output is checked before the run: a typo must not cost a
    // simulation.
    if let Some(stats_path) = stats_path {
        anthesis_files::check_destination(stats_path)?;
    }
    if let Some(out) = out {
        check_output(out, glb, project.settings.keyframes)?;
    }
    let cost = match out.map(OutputKind::of) {
        None => KeyframeCost::Kept,
        Some(OutputKind::Glb) => KeyframeCost::Glb,
        Some(OutputKind::Usd) => KeyframeCost::Usd,
        Some(OutputKind::ObjFolder) => KeyframeCost::Obj,
    };
    let project = at_resolution(project, edge, Some((&selection, cost)))?;
    if out.is_some() {
        // The bud and every keyframe, at the render level asked for, of
        // the meshes at the project's resolution.
        anthesis_export::check_render_level(
            &project.flower,
            &selection.organs(project.flower.organs.len()),
            project.settings.keyframes as usize + 1,
            render_level,
        )?;
    }
    memory::check_run(&project, &selection, cost)?;

    let mut sim = Simulation::new(&project, &selection)?;
    if allow_crossings {
        sim.on_crossing(OnCrossing::Warn);
    }
    let total = sim.keyframe_count();
    let mut frames: Vec<Vec<Vec<DVec3>>> = vec![sim.bud().positions_in_world];
    let mut stats = Vec::new();
    let run = run_keyframes(&mut sim, total, &mut |keyframe| {
        stats.push(keyframe.stats);
        frames.push(keyframe.positions_in_world);
    });
    // What was computed is kept even when the run failed part way.
    let done = run.done;
    let seconds = run.seconds;

    if let Some(stats_path) = stats_path {
        let file = StatsFile {
            project: &project.name,
            organs: sim.organs().iter().map(|s| s.to_string()).collect(),
            keyframes: &stats,
            total_seconds: seconds,
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
        let tracks = anthesis_export::flower_tracks(
            &project.flower,
            &selection.organs(project.flower.organs.len()),
            frames.iter().map(Vec::as_slice),
            render_level,
        )?;
        write_tracks(out, OutputKind::of(out), &tracks, glb)?;
        say!("wrote {} (keyframes 0 to {done})", out.display());
        written = Some(out);
    }
    match (run.failure, written) {
        (None, _) => Ok(()),
        (Some(failure), Some(out)) => Err(failure.context(format!(
            "the keyframes before it were written to {} (keyframes 0 to {done})",
            out.display()
        ))),
        (Some(failure), None) if out.is_some() => {
            Err(failure.context("no keyframe was computed, nothing was written"))
        }
        (Some(failure), None) => Err(failure),
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

/// How far a run got: the keyframes computed, the wall time, and why it
/// stopped early if it did.
pub(super) struct Run {
    pub done: u32,
    pub seconds: f64,
    pub failure: Option<anyhow::Error>,
}

impl Run {
    /// The run as a result: an error if it stopped early.
    pub fn into_result(self) -> Result<f64> {
        match self.failure {
            None => Ok(self.seconds),
            Some(failure) => Err(failure),
        }
    }
}

/// Steps `sim` through keyframe `last` (at most its keyframe count), handing
/// each keyframe to `on_keyframe`. Shows progress with the time left when
/// stderr is a terminal and ends with a summary line on stderr. A failed
/// step ends the run; the keyframes before it have been handed over.
pub(super) fn run_keyframes(
    sim: &mut Simulation,
    last: u32,
    on_keyframe: &mut dyn FnMut(Keyframe),
) -> Run {
    let last = last.min(sim.keyframe_count());
    let started = Instant::now();
    let show_progress = std::io::stderr().is_terminal();
    let mut done = 0;
    let mut failure = None;
    while done < last && !sim.finished() {
        let warned = sim.crossings().len();
        let keyframe = match sim.step(&|| false, &mut |_| {}) {
            Ok(keyframe) => keyframe,
            Err(error @ SimError::Crossed(_)) => {
                failure = Some(anyhow::Error::new(error).context(
                    "the run stopped where organs cross (`--allow-crossings` goes on with a warning)",
                ));
                break;
            }
            Err(error) => {
                failure = Some(anyhow::Error::new(error));
                break;
            }
        };
        for crossing in &sim.crossings()[warned..] {
            if show_progress {
                say!();
            }
            say!("warning: {crossing}");
        }
        done = keyframe.index;
        if show_progress {
            let elapsed = started.elapsed().as_secs_f64();
            let left = elapsed / f64::from(done) * f64::from(last - done);
            say_part!("\rkeyframe {done}/{last}  {elapsed:.1} s, about {left:.1} s left   ");
        }
        on_keyframe(keyframe);
    }
    let seconds = started.elapsed().as_secs_f64();
    if show_progress && done > 0 {
        say!();
    }
    if failure.is_none() {
        say!(
            "simulated {done} keyframes of {} organ(s) in {seconds:.2} s ({} Hessian factorisations)",
            sim.organs().len(),
            sim.factorisations()
        );
    }
    Run {
        done,
        seconds,
        failure,
    }
}

/// What `--out` asks for, by its extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum OutputKind {
    Glb,
    Usd,
    ObjFolder,
}

impl OutputKind {
    pub(super) fn of(path: &Path) -> OutputKind {
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("glb"))
        {
            OutputKind::Glb
        } else if anthesis_export::is_usd_path(path) {
            OutputKind::Usd
        } else {
            OutputKind::ObjFolder
        }
    }
}

/// Writes `tracks` to `out` as `kind` says: a .glb, a USD layer, or one OBJ
/// per keyframe into a folder (created when missing).
pub(super) fn write_tracks(
    out: &Path,
    kind: OutputKind,
    tracks: &[anthesis_export::Track],
    glb: &GlbOptions,
) -> Result<()> {
    match kind {
        OutputKind::Glb => anthesis_export::write_glb(out, tracks, glb, &mut |_| {})
            .with_context(|| format!("cannot write {}", out.display()))?,
        OutputKind::Usd => {
            let usd = UsdOptions {
                timing: glb.timing,
                normals: glb.normals,
            };
            anthesis_export::write_usd(out, tracks, &usd, &mut |_| {})
                .with_context(|| format!("cannot write {}", out.display()))?
        }
        OutputKind::ObjFolder => {
            if !out.is_dir() {
                std::fs::create_dir(out)
                    .with_context(|| format!("cannot create the folder {}", out.display()))?;
            }
            anthesis_export::write_obj_sequence(out, tracks)
                .with_context(|| format!("cannot write OBJ files to {}", out.display()))?;
        }
    }
    Ok(())
}

/// Fails early, before a long simulation, when `--out` cannot be written:
/// a .glb needs a folder and export options that fit `keyframes`; a folder
/// for OBJ files may be missing if its parent exists (it is created when
/// the files are written).
pub(super) fn check_output(out: &Path, glb: &GlbOptions, keyframes: u32) -> Result<()> {
    match OutputKind::of(out) {
        OutputKind::Glb => {
            anthesis_files::check_destination(out)?;
            // The bud and every keyframe.
            glb.check(keyframes as usize + 1)?;
        }
        OutputKind::Usd => anthesis_export::check_usd_destination(out)?,
        OutputKind::ObjFolder if out.exists() && !out.is_dir() => bail!(
            "--out {} must be a .glb, .usda or .usdc file or a folder for OBJ files",
            out.display()
        ),
        OutputKind::ObjFolder if out.is_dir() => {}
        OutputKind::ObjFolder => check_creatable_folder(out)?,
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

//! One batch run, the one the command line (`anthesis simulate`), the
//! window's export and the examples share: the run checked against the
//! memory and every template remeshed at the project's resolution
//! ([`prepare`]), stepped to its end with progress and cancellation
//! ([`simulate`], [`step_through`]), made into the tracks of an export
//! ([`BatchRun::tracks`]) and written by format ([`write`]).
//!
//! [`Format`] is the one list of the export formats, their extensions and
//! their options.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anthesis_export::{ExportError, GlbOptions, Track, UsdOptions};
use anthesis_flower::Project;
use anthesis_flower::resolution::{ResolutionError, resolve};

use crate::crossing::OnCrossing;
use crate::memory::{self, KeyframeCost, MemoryError};
use crate::{Keyframe, Selection, SimError, Simulation};

/// What an export is written as, told by the path's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// An animated glTF binary (`.glb`): morph targets between keyframes.
    Glb,
    /// A USD layer, as text (`.usda`, `.usd`) or binary (`.usdc`): one time
    /// sample per keyframe.
    Usd,
    /// One OBJ file per keyframe in a folder (a path without one of the
    /// other formats' extensions, on the command line).
    ObjFolder,
    /// A rendered animated GIF (`.gif`): drawn by the app's renderer, so
    /// [`write`] refuses it.
    Gif,
}

impl Format {
    /// The files an export can be saved as, in the order a file dialog
    /// offers them.
    pub const FILES: [Format; 3] = [Format::Glb, Format::Usd, Format::Gif];

    /// The extensions of the format's files, lower case, without the dot
    /// (none for a folder).
    pub fn extensions(self) -> &'static [&'static str] {
        match self {
            Format::Glb => &["glb"],
            Format::Usd => &["usda", "usdc", "usd"],
            Format::ObjFolder => &[],
            Format::Gif => &["gif"],
        }
    }

    /// What a file dialog calls the format.
    pub fn name(self) -> &'static str {
        match self {
            Format::Glb => "glTF binary",
            Format::Usd => "USD layer",
            Format::ObjFolder => "folder of OBJ files",
            Format::Gif => "GIF animation",
        }
    }

    /// The format whose extension `path` has (in any case), or `None`
    /// (each caller says what such a path means: the command line writes
    /// a folder of OBJ files, the window a .glb).
    pub fn from_path(path: &Path) -> Option<Format> {
        let extension = path.extension()?.to_str()?.to_ascii_lowercase();
        Format::FILES
            .into_iter()
            .find(|format| format.extensions().contains(&extension.as_str()))
    }

    /// Every extension of [`Format::FILES`], in their order: the file
    /// dialog's list of what an export can be saved as.
    pub fn file_extensions() -> Vec<&'static str> {
        Format::FILES
            .iter()
            .flat_map(|format| format.extensions().iter().copied())
            .collect()
    }

    /// The memory a keyframe costs on its way into this format.
    pub fn keyframe_cost(self) -> KeyframeCost {
        match self {
            Format::Glb => KeyframeCost::Glb,
            Format::Usd => KeyframeCost::Usd,
            Format::ObjFolder => KeyframeCost::Obj,
            Format::Gif => KeyframeCost::Kept,
        }
    }

    /// Whether the file holds the animation's timing (keyframes per
    /// second or a duration) and may leave normals out: .glb and USD.
    pub fn has_timing(self) -> bool {
        matches!(self, Format::Glb | Format::Usd)
    }

    /// Whether the file stores morph targets with an encoding: .glb.
    pub fn has_morph_targets(self) -> bool {
        self == Format::Glb
    }
}

/// Why a batch run could not start or its file could not be written.
#[derive(Debug, thiserror::Error)]
pub enum BatchError {
    /// The run would not fit in the memory available.
    #[error(transparent)]
    Memory(#[from] MemoryError),
    /// A template cannot be remeshed at the project's resolution.
    #[error(transparent)]
    Resolution(#[from] ResolutionError),
    /// The simulation cannot start (a bad mesh or setting).
    #[error(transparent)]
    Simulation(#[from] SimError),
    /// The export asks for more than it can hold (a render level too fine)
    /// or its tracks cannot be made.
    #[error(transparent)]
    Export(#[from] ExportError),
    /// The .glb or USD file at `path` could not be written.
    #[error("cannot write {}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        source: ExportError,
    },
    /// The folder for OBJ files at `path` could not be created.
    #[error("cannot create the folder {}", path.display())]
    CreateFolder {
        /// The folder.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The OBJ files could not be written into the folder at `path`.
    #[error("cannot write OBJ files to {}", path.display())]
    WriteObj {
        /// The folder.
        path: PathBuf,
        /// Why.
        source: ExportError,
    },
    /// A GIF is rendered by the app; the engine does not draw.
    #[error("{} is a GIF, which the app renders; the engine writes .glb, USD and OBJ", path.display())]
    Rendered {
        /// The file asked for.
        path: PathBuf,
    },
}

/// Makes `project` ready for a batch run of `selection`: checks that the
/// run fits in memory with `cost` per keyframe, remeshes every template at
/// the project's resolution, checks the memory again on the meshes as
/// remeshed, and, when the run is exported as render meshes of
/// `render_level` levels of subdivision, that the export fits too. Returns
/// the project to simulate (at [`anthesis_flower::Resolution::AsBuilt`]).
pub fn prepare(
    project: &Project,
    selection: &Selection,
    cost: KeyframeCost,
    render_level: Option<u32>,
) -> Result<Project, BatchError> {
    memory::check_run(project, selection, cost)?;
    let resolved = resolve(project)?;
    if let Some(render_level) = render_level {
        // The bud and every keyframe, at the render level asked for, of
        // the meshes at the project's resolution.
        anthesis_export::check_render_level(
            &resolved.flower,
            &selection.organs(resolved.flower.organs.len()),
            resolved.settings.keyframes as usize + 1,
            render_level,
        )?;
    }
    memory::check_run(&resolved, selection, cost)?;
    Ok(resolved)
}

/// How far [`step_through`] got: the keyframes computed, the wall time in
/// seconds, and why it stopped early if it did.
#[derive(Debug)]
pub struct Stepped {
    /// The last keyframe computed (0: none after the bud).
    pub done: u32,
    /// Wall time of the steps, in seconds.
    pub seconds: f64,
    /// Why the run stopped before the keyframe asked for
    /// ([`SimError::Cancelled`] when `cancelled` said so).
    pub failure: Option<SimError>,
}

/// Steps `sim` through keyframe `last` (at most its keyframe count),
/// handing each keyframe to `on_keyframe` with the simulation that made
/// it; `cancelled` is asked during each step. A failed step ends the run;
/// the keyframes before it have been handed over.
pub fn step_through(
    sim: &mut Simulation,
    last: u32,
    cancelled: &(dyn Fn() -> bool + Sync),
    on_keyframe: &mut dyn FnMut(&Simulation, Keyframe),
) -> Stepped {
    let last = last.min(sim.keyframe_count());
    let started = Instant::now();
    let mut done = 0;
    let mut failure = None;
    while done < last && !sim.finished() {
        match sim.step(cancelled, &mut |_| {}) {
            Ok(keyframe) => {
                done = keyframe.index;
                on_keyframe(sim, keyframe);
            }
            Err(error) => {
                failure = Some(error);
                break;
            }
        }
    }
    Stepped {
        done,
        seconds: started.elapsed().as_secs_f64(),
        failure,
    }
}

/// A batch run to its end: the simulation, the bud and every keyframe it
/// computed (kept even when it stopped early), and how far it got.
pub struct BatchRun {
    /// The simulation, at the last keyframe computed.
    pub simulation: Simulation,
    /// The bud (keyframe 0) and each keyframe computed, in order.
    pub keyframes: Vec<Keyframe>,
    /// How far the steps got.
    pub stepped: Stepped,
}

impl BatchRun {
    /// The tracks of an export of the keyframes computed: the simulated
    /// organs of `project` (the project simulated), as render meshes of
    /// `render_level` levels of subdivision (0: the simulated meshes), and
    /// the parts ([`anthesis_export::flower_tracks`]).
    pub fn tracks(
        &self,
        project: &Project,
        selection: &Selection,
        render_level: u32,
    ) -> Result<Vec<Track>, ExportError> {
        anthesis_export::flower_tracks(
            &project.flower,
            &selection.organs(project.flower.organs.len()),
            self.keyframes
                .iter()
                .map(|keyframe| keyframe.positions_in_world.as_slice()),
            render_level,
        )
    }
}

/// Simulates `selection` of `project` (as [`prepare`] returns it) from the
/// bud to its last keyframe, going on past crossings as `on_crossing`
/// says, handing each keyframe to `on_keyframe` before it is kept;
/// `cancelled` is asked during each step. An error when the run cannot
/// start; a run that stops part way keeps what it computed.
pub fn simulate(
    project: &Project,
    selection: &Selection,
    on_crossing: OnCrossing,
    cancelled: &(dyn Fn() -> bool + Sync),
    on_keyframe: &mut dyn FnMut(&Simulation, &Keyframe),
) -> Result<BatchRun, SimError> {
    let mut simulation = Simulation::new(project, selection)?;
    simulation.on_crossing(on_crossing);
    let mut keyframes = vec![simulation.bud()];
    let last = simulation.keyframe_count();
    let stepped = step_through(&mut simulation, last, cancelled, &mut |sim, keyframe| {
        on_keyframe(sim, &keyframe);
        keyframes.push(keyframe);
    });
    Ok(BatchRun {
        simulation,
        keyframes,
        stepped,
    })
}

/// Writes `tracks` to `path` as `format`: a .glb with `options`, a USD
/// layer (text or binary by the extension) with their timing and normals,
/// or one OBJ per keyframe into the folder `path` (created when missing).
/// `progress` goes from 0 to 1 while a .glb or USD layer is written.
pub fn write(
    path: &Path,
    format: Format,
    tracks: &[Track],
    options: &GlbOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(), BatchError> {
    let wrote = |result: Result<(), ExportError>| {
        result.map_err(|source| BatchError::Write {
            path: path.to_path_buf(),
            source,
        })
    };
    match format {
        Format::Glb => wrote(anthesis_export::write_glb(path, tracks, options, progress)),
        Format::Usd => {
            let usd = UsdOptions {
                timing: options.timing,
                normals: options.normals,
            };
            wrote(anthesis_export::write_usd(path, tracks, &usd, progress))
        }
        Format::ObjFolder => {
            if !path.is_dir() {
                std::fs::create_dir(path).map_err(|source| BatchError::CreateFolder {
                    path: path.to_path_buf(),
                    source,
                })?;
            }
            anthesis_export::write_obj_sequence(path, tracks)
                .map(|_| ())
                .map_err(|source| BatchError::WriteObj {
                    path: path.to_path_buf(),
                    source,
                })
        }
        Format::Gif => Err(BatchError::Rendered {
            path: path.to_path_buf(),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_are_told_by_their_extension_in_any_case() {
        let of = |path: &str| Format::from_path(Path::new(path));
        assert_eq!(of("a/flower.glb"), Some(Format::Glb));
        assert_eq!(of("flower.GLB"), Some(Format::Glb));
        assert_eq!(of("flower.usda"), Some(Format::Usd));
        assert_eq!(of("flower.usd"), Some(Format::Usd));
        assert_eq!(of("flower.Usdc"), Some(Format::Usd));
        assert_eq!(of("opening.gif"), Some(Format::Gif));
        assert_eq!(of("frames"), None);
        assert_eq!(of("flower.obj"), None);
        assert_eq!(
            Format::file_extensions(),
            ["glb", "usda", "usdc", "usd", "gif"]
        );
        for format in Format::FILES {
            for extension in format.extensions() {
                let path = format!("x.{extension}");
                assert_eq!(of(&path), Some(format), "{path}");
            }
        }
    }

    #[test]
    fn a_batch_run_is_the_engines_run_and_its_file_reads_back() {
        let project = crate::fixtures::whorl(2, 4, 6, 2);
        let resolved =
            prepare(&project, &Selection::All, KeyframeCost::Glb, Some(0)).expect("prepares");
        let mut seen = Vec::new();
        let run = simulate(
            &resolved,
            &Selection::All,
            OnCrossing::Stop,
            &|| false,
            &mut |_, k| seen.push(k.index),
        )
        .expect("starts");
        assert!(run.stepped.failure.is_none());
        assert_eq!(run.stepped.done, 2);
        assert_eq!(seen, [1, 2]);
        let mut engine = Vec::new();
        crate::run(&resolved, &Selection::All, &mut |_, k| {
            engine.push(k.bits())
        })
        .expect("simulates");
        let bits: Vec<_> = run.keyframes.iter().map(Keyframe::bits).collect();
        assert_eq!(bits, engine);

        let tracks = run.tracks(&resolved, &Selection::All, 0).expect("tracks");
        let dir = tempfile::tempdir().expect("temp dir");
        let glb = dir.path().join("out.glb");
        write(
            &glb,
            Format::Glb,
            &tracks,
            &GlbOptions::default(),
            &mut |_| {},
        )
        .expect("writes");
        assert_eq!(&std::fs::read(&glb).expect("file")[..4], b"glTF");
        let gif = dir.path().join("out.gif");
        let refused = write(
            &gif,
            Format::Gif,
            &tracks,
            &GlbOptions::default(),
            &mut |_| {},
        );
        assert!(matches!(refused, Err(BatchError::Rendered { .. })));
        assert!(!gif.exists());
    }

    #[test]
    fn a_cancelled_run_stops_and_keeps_the_bud() {
        let project = crate::fixtures::whorl(1, 4, 6, 3);
        let run = simulate(
            &project,
            &Selection::All,
            OnCrossing::Stop,
            &|| true,
            &mut |_, _| {},
        )
        .expect("starts");
        assert_eq!(run.stepped.failure, Some(SimError::Cancelled));
        assert_eq!(run.stepped.done, 0);
        assert_eq!(run.keyframes.len(), 1, "the bud");
    }
}

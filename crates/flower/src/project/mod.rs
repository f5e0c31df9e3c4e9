//! The project file format: one TOML file a person can read and diff, with
//! each template's mesh as an OBJ file and its painted maps as PNG files
//! beside it.
//!
//! ```toml
//! format = "anthesis-project"
//! version = 3
//! name = "Asiatic lily"
//! unit = "1.8 mm"              # optional (version 9): what one length is in
//!                              # the real world (a number and µm, mm, cm or
//!                              # m); exports write the flower at that size.
//!                              # Absent: one unit is one metre, as before
//!                              # (`anthesis info` says so)
//!
//! [simulation]                 # optional; each field defaults as shown
//! keyframes = 100
//! relative_tolerance = 0.00001
//! max_iterations = 50
//! collision_offset = 0.01
//! model = "consistent"         # or "paper" (see anthesis_physics::model);
//!                              # version 1 files, which have no model, are
//!                              # read as "paper", the model they were made with
//! bend_from = "dihedral"       # or "rest_angle": what a hinge's growth adds
//!                              # to, its current dihedral or its rest angle
//! lengths_from = "shape"       # or "rest" (version 10): what grows into the
//!                              # new rest lengths, each triangle as it is now
//!                              # (growth the shape could not take is
//!                              # forgotten) or its rest triangle (the rest
//!                              # state accumulates the growth)
//! mean_edge = 0.8              # absent: the meshes as built; a length:
//!                              # every template simulated remeshed at this
//!                              # mean edge (crate::resolution; the meshes
//!                              # saved stay as built). Version 3; files
//!                              # without it are written as version 2
//!
//! [[templates]]
//! name = "petal"
//! mesh = "meshes/petal.obj"    # paths are relative to the project file
//! dg = 0.003
//! thickness = 0.2
//! stretch_stiffness = 20.0
//! bend_stiffness = 20.0
//! color = [0.98, 0.62, 0.32, 1.0]          # optional, default opaque white
//! second_color = [0.6, 0.02, 0.08, 1.0]    # optional (version 5), with colour_map:
//! colour_map = "maps/petal-colour.png"     # where second_color shows over color
//!                                           # (0 = color, 1 = second_color; a
//!                                           # PNG like the growth maps, of any
//!                                           # size, or a number)
//! [[templates.colour_layers]]               # optional (version 5): more colours
//! color = [0.5, 0.02, 0.05, 1.0]            # painted over, in order
//! map = "maps/petal-colour-2.png"
//! blend = "linear"                          # optional: "linear" (default),
//!                                           # "smooth" or
//!                                           # { logistic = { steepness = 10.0 } }
//! base_region = { v_max = 0.06 }            # optional: v_max 0.05, u_min 0, u_max 1
//! joint_schedule = [{ from_step = 0, to_step = 60, degrees = 23.0 }]  # optional
//!
//! [templates.two_state]        # optional (version 7): the organs are not
//!                              # grown but go from the mesh (the bud) to this
//!                              # open shape by the two-state blossom
//! open_mesh = "meshes/petal.open.obj"  # the mesh's vertices moved (same order
//!                              # and triangles), in the template frame
//! g = 6.0                      # optional: g of G(t; g, T), eq. (4); 6 ends
//!                              # at the open shape
//! duration = 100.0             # T, in keyframes
//! velocity = [[0.0, 0.0], [0.5, 0.8], [1.0, 1.0]]  # optional: [t / T,
//!                              # fraction] of the directions' turn; absent:
//!                              # it follows G
//! [templates.source]           # optional (version 7): how the mesh was made
//! kind = "bezier"              # a bicubic Bézier patch (the app's editor)
//! net = [[-1.2, 0.0, -0.3], [-0.4, 0.0, 0.0], ...]  # 16 points [x, y, z]:
//!                              # four rows of four, base to tip
//! edge = 1.2                   # the mean edge it was meshed at
//! # or (version 8) a sketched petal's strokes as drawn, [x, y] points in
//! # the base plane (any order and direction; see anthesis_bud::PetalSketch):
//! # kind = "sketch"
//! # left = [[-0.5, 0.0], ...]   right = [...]   vein = [...]
//! # sections = [[[-4.0, 9.0], ...], ...]   # optional cross-sections
//! # edge = 1.2
//! # or (version 8) a PDE sweep (eq. 12 of Chaudhry et al.):
//! # kind = "pde"
//! # margin0 = [[1.2, 0, -0.3], ...]  # 4 Bézier control points, base to tip
//! # margin1 = [...]; tangent0 = [...]; tangent1 = [...]  # dS/du there
//! # stretch_to_bend = 0.0      # k_s/k_b, 0 to 100 (0: the cubic)
//! # edge = 1.2
//! [templates.vein]             # optional (version 8): the primary vein the
//! points = [[0.0, 0.0], [0.3, 0.1], ...]  # bud was sketched with, [y, z]
//!                              # in the template frame from the base; the
//!                              # mesh's midrib follows it
//!
//! [[templates.keys]]
//! step = 40
//! e_growth = "maps/petal-step40-e_growth.png"   # a PNG, or a number
//! w_growth = 0.2
//! e_growth_in = "maps/petal-step40-e_growth_in.png"
//! w_growth_in = 0.2
//! stretch = 1.0
//! bend = 1
//! direction = [0.0, 1.0]                        # a [u, v] vector, or a PNG
//! dg = -0.004                  # optional (version 6): this key's growth
//!                              # scale in place of the template's, blended
//!                              # between keys like the maps (negative:
//!                              # the organ shrinks, e.g. wilting)
//!
//! [[organs]]
//! name = "petal-1"
//! template = "petal"
//! position = [0.0, 0.0, 0.8]   # optional, default the origin
//! azimuth_deg = 0.0            # optional, default 0
//! joint_angle_deg = 10.0       # optional, default 0
//! orientation = [0, 0, 0, 1]   # optional (version 4): a quaternion [x, y, z, w]
//!
//! [[overlaps]]                 # organ names; overrides a made rule of the pair
//! inner = "petal-1"
//! outer = "sepal-1"
//!
//! # Version 4: organs made by a structure, before the listed ones.
//! [structure]
//! kind = "whorls"              # or "spiral" or "lsystem"
//! contorted = false            # whorls: one contorted whorl (Eustoma)
//!
//! [[structure.whorls]]         # innermost first; organs <name>-1, <name>-2, ...
//! name = "tepal"
//! template = "petal"
//! count = 3
//! offset_deg = 0.0             # optional
//! radius = 0.8
//! height = 0.0                 # optional
//! joint_angle_deg = 10.0       # optional
//! half_span_deg = 50.0         # the angle an organ covers: rules where spans meet
//!
//! # kind = "spiral": [structure.spiral] with name, template, count,
//! # divergence_deg (default the golden angle 137.5°), first_radius,
//! # first_height, radius_step, height_step, joint_angle_deg, half_span_deg:
//! # organ k at radius first_radius − k·radius_step and height
//! # first_height + k·height_step.
//! #
//! # kind = "lsystem": [structure.lsystem] with steps, text (the L-system,
//! # see `structure::lsystem`) and surfaces = { p = "petal", c = "sepal" }:
//! # each ~X places an organ of that template in the turtle's frame;
//! # optional units = 0.05 (project units per turtle unit, default 1)
//! # scales every position and line width the turtle draws.
//!
//! # Version 5: organs that do not grow (see `crate::parts`).
//! [[parts]]
//! name = "stamen"              # instances stamen-1, stamen-2, ... (count > 1)
//! kind = "stamen"              # or "pistil", "pedicel", "receptacle"
//! count = 6                    # optional, default 1
//! ring_radius = 0.9            # optional: bases this far from the axis
//! height = 0.4                 # optional
//! offset_deg = 30.0            # optional: azimuth of the first
//! angle_deg = 3.0              # optional: initial tilt outwards
//! length = 27.0                # stamen, pistil, pedicel: the tube
//! radius = 0.22                # (receptacle: its radius, with depth)
//! curvature_deg = 6.0          # optional: the tube turns outwards
//! anther_length = 4.0          # stamen
//! anther_radius = 0.55         # stamen
//! anther_tilt_deg = 90.0       # stamen, optional: 90 lies across the tip
//! # pistil: stigma_radius, stigma_lobes (default 1), ovary_length and
//! # ovary_radius (default 0: none); receptacle: radius, depth.
//! color = [0.9, 0.62, 0.3, 1.0]        # optional, a default per kind
//! head_color = [0.3, 0.06, 0.02, 1.0]  # stamen, pistil: anther or stigma
//!
//! [[parts.schedule]]           # optional: turns it like a joint schedule
//! from_step = 20
//! to_step = 80
//! degrees = 30.0
//! ```
//!
//! # Rules
//!
//! - `format` must be `"anthesis-project"` and `version` at most
//!   [`FORMAT_VERSION`]; both are checked before anything else, so a file
//!   from a newer Anthesis gets [`ProjectError::NewerVersion`] rather than a
//!   complaint about fields this build does not know.
//! - Every table refuses unknown fields, so a misspelt field is an error
//!   naming it, with its line and column.
//! - A map entry of a key is a number (a constant map), a path to a PNG, or
//!   for `direction` a `[u, v]` pair. An omitted entry is the map kind's
//!   default: growth 0, stretch and bend 1, direction `[0, 1]`. PNG formats
//!   are those of [`anthesis_maps`] (greyscale for scalar maps, red = u and
//!   green = v for directions). A 1x1 PNG is a constant.
//! - All raster maps of one template, over all its keys, must have the same
//!   size; the first one read sets it ([`ProjectError::MapSize`]).
//!
//! # Saving
//!
//! [`save_project`] writes the TOML, each template's mesh as
//! `meshes/<template>.obj` and each map that is not constant as
//! `maps/<template>-step<step>-<map>.png`, where `<template>` is the template
//! name in lower case with anything but ASCII letters, digits, `-` and `_`
//! replaced by `_` (and `-2`, `-3`, … appended if two templates would share
//! a name). Constant (1x1) maps are written as numbers.
//!
//! Raster maps are written as 16-bit PNGs: painted values are floats, and
//! 8 bits (steps of 1/255) would visibly quantise a growth rate that is
//! applied a hundred times over, while 16 bits (steps of 1/65535) change a
//! value by at most 0.0000077. Saving quantises once; saving what was loaded
//! writes the same codes again, so repeated saves do not drift. Scalar
//! rasters must hold values in `[0, 1]` and direction rasters components in
//! `[-1, 1]` (what a PNG can hold); other values are refused, not clamped.
//!
//! Saving first checks the project by the same rules as loading and refuses
//! (writing nothing) a project it could not load again, so a good file is
//! never replaced by one that cannot be opened. Each file is written with
//! [`anthesis_files::write_atomic`] (a temporary file in the same folder,
//! then a rename; a symbolic link is followed and a replaced file keeps its
//! permissions), the meshes and maps first and the TOML last. Map and mesh
//! files that the new TOML no longer names are left in place.

mod check;
mod error;
mod load;
mod parts;
pub mod recovery;
mod save;
mod schema;

use std::io;
use std::path::Path;

use crate::Project;

use anthesis_files::FileError;
pub use check::MAX_NAME_CHARS;
pub use error::ProjectError;
pub use load::MAX_PROJECT_BYTES;
use load::{FileKind, Loader};
use save::{plan_save, write_file};

/// The value of the `format` field of every project file.
pub const FORMAT_NAME: &str = "anthesis-project";

/// The newest file format version this build reads, and the one it writes.
pub const FORMAT_VERSION: u32 = 10;

/// Checks `project` by the rules every loaded or saved project obeys
/// (names, counts, numbers, parts), as the app does before it takes an
/// edit of the flower; errors name [`UNNAMED_PROJECT`] as the file.
pub fn check(project: &Project) -> Result<(), ProjectError> {
    check::check_project(project, Path::new(UNNAMED_PROJECT))
}

/// Where saved meshes go, relative to the project file.
pub const MESH_FOLDER: &str = "meshes";

/// Where saved PNG maps go, relative to the project file.
pub const MAP_FOLDER: &str = "maps";

/// What [`parse_project`] calls the project text in its errors.
pub const UNNAMED_PROJECT: &str = "(project text)";

/// A loaded project and the warnings met loading it.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadedProject {
    /// The project as read, with its meshes and maps loaded and checked.
    pub project: Project,
    /// Things read past, each naming its file (e.g. an OBJ's loose edges).
    pub warnings: Vec<String>,
}

/// Reads the project file at `path` and the meshes and PNG maps it names
/// (see [`load_project_with_warnings`]; warnings are dropped).
pub fn load_project(path: &Path) -> Result<Project, ProjectError> {
    load_project_with_warnings(path).map(|loaded| loaded.project)
}

/// Reads the project file at `path` (or in the project folder `path`, see
/// [`project_file`]) and the meshes and PNG maps it names,
/// as a file from a stranger: only regular files within their size limits
/// ([`MAX_PROJECT_BYTES`], `anthesis_mesh::obj::MAX_OBJ_BYTES`,
/// `anthesis_maps::MAX_PNG_BYTES`), and only files inside the project's
/// folder: a path that is absolute, climbs out with `..` or leads out
/// through a symbolic link is refused, naming the entry and why.
pub fn load_project_with_warnings(path: &Path) -> Result<LoadedProject, ProjectError> {
    let file = project_file(path)?;
    let path = file.as_path();
    let text = anthesis_files::read_regular_text(path, MAX_PROJECT_BYTES, "a project file")
        .map_err(|error| ProjectError::Io {
            path: path.to_path_buf(),
            message: error.to_string(),
        })?;
    let folder = path.parent().unwrap_or(Path::new(""));
    let read = |relative: &str, kind: FileKind| {
        let resolved = anthesis_files::resolve_inside(folder, relative)?;
        anthesis_files::read_regular(&resolved, kind.limit(), kind.what())
    };
    let loader = Loader {
        project_path: path,
        folder,
        files: &read,
        warnings: Default::default(),
    };
    let project = loader.load(&text)?;
    Ok(LoadedProject {
        project,
        warnings: loader.warnings.into_inner(),
    })
}

/// The extension a project file's name ends with.
pub const PROJECT_EXTENSION: &str = ".anthesis.toml";

/// The project file `path` names: `path` itself, or for a folder the one
/// `*.anthesis.toml` file directly inside it (as `assets/flowers/lily`
/// holds `lily.anthesis.toml`), so a project folder works wherever a
/// project file does. A folder with none or several is refused, naming
/// what it holds.
pub fn project_file(path: &Path) -> Result<std::path::PathBuf, ProjectError> {
    if !path.is_dir() {
        return Ok(path.to_path_buf());
    }
    let refuse = |message: String| ProjectError::Io {
        path: path.to_path_buf(),
        message,
    };
    let entries = std::fs::read_dir(path).map_err(|e| refuse(e.to_string()))?;
    let mut found: Vec<std::path::PathBuf> = entries
        .filter_map(Result::ok)
        .map(|entry| entry.path())
        .filter(|p| {
            p.is_file()
                && p.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| n.ends_with(PROJECT_EXTENSION))
        })
        .collect();
    found.sort();
    match found.len() {
        1 => Ok(found.remove(0)),
        0 => Err(refuse(format!(
            "the folder holds no project file (*{PROJECT_EXTENSION})"
        ))),
        _ => Err(refuse(format!(
            "the folder holds several project files ({}): name one",
            found
                .iter()
                .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
                .collect::<Vec<_>>()
                .join(", ")
        ))),
    }
}

/// Reads a project from its TOML text; `files` returns the bytes of a mesh
/// or map given its path as written in the file. For projects that are not
/// on disk, e.g. embedded in the binary with `include_bytes!`. Errors call
/// the project file [`UNNAMED_PROJECT`] and other files by their path as
/// written. Paths follow the rules of [`load_project_with_warnings`] that
/// need no disk (relative, not climbing out), and so do the size limits.
pub fn parse_project(
    text: &str,
    files: &dyn Fn(&str) -> Result<Vec<u8>, io::Error>,
) -> Result<Project, ProjectError> {
    let read = |relative: &str, kind: FileKind| {
        anthesis_files::check_relative(Path::new(relative))?;
        let bytes = files(relative).map_err(FileError::Io)?;
        if bytes.len() as u64 > kind.limit() {
            return Err(FileError::TooLarge {
                size: bytes.len() as u64,
                limit: kind.limit(),
                what: kind.what(),
            });
        }
        Ok(bytes)
    };
    let loader = Loader {
        project_path: Path::new(UNNAMED_PROJECT),
        folder: Path::new(""),
        files: &read,
        warnings: Default::default(),
    };
    loader.load(text)
}

/// Writes `project` to `path` with its meshes and maps beside it (see the
/// module documentation); creates the folders it needs.
pub fn save_project(project: &Project, path: &Path) -> Result<(), ProjectError> {
    let folder = path.parent().unwrap_or(Path::new(""));
    let plan = plan_save(project, path, folder)?;
    for (relative, bytes) in &plan.files {
        write_file(&folder.join(relative), bytes)?;
    }
    write_file(path, plan.toml.as_bytes())
}

/// The folder beside a project file where [`keep_backup`] keeps the
/// version it replaces.
pub const BACKUP_FOLDER: &str = "backup";

/// Before saving over the project file at `path`: keeps the project there
/// now, with its meshes and maps, as `backup/NAME` beside it (replacing an
/// older backup), as Blender keeps `.blend1`. A project that no longer
/// loads is kept as its file alone. Returns the backup's project file, or
/// `None` when there was nothing to keep.
pub fn keep_backup(path: &Path) -> Result<Option<std::path::PathBuf>, ProjectError> {
    if !path.is_file() {
        return Ok(None);
    }
    let folder = path.parent().unwrap_or(Path::new(""));
    let backup_folder = folder.join(BACKUP_FOLDER);
    let io = |at: &Path, error: io::Error| ProjectError::Io {
        path: at.to_path_buf(),
        message: error.to_string(),
    };
    if backup_folder.exists() {
        std::fs::remove_dir_all(&backup_folder).map_err(|e| io(&backup_folder, e))?;
    }
    let file_name = path.file_name().unwrap_or_default();
    let backup = backup_folder.join(file_name);
    match load_project(path) {
        Ok(previous) => save_project(&previous, &backup)?,
        Err(_) => {
            std::fs::create_dir_all(&backup_folder).map_err(|e| io(&backup_folder, e))?;
            std::fs::copy(path, &backup).map_err(|e| io(&backup, e))?;
        }
    }
    Ok(Some(backup))
}

/// The TOML text [`save_project`] would write for `project` at `path`
/// (checked the same way; no file is written).
pub fn project_to_toml(project: &Project, path: &Path) -> Result<String, ProjectError> {
    let folder = path.parent().unwrap_or(Path::new(""));
    Ok(plan_save(project, path, folder)?.toml)
}

//! The project file format: one TOML file a person can read and diff, with
//! each template's mesh as an OBJ file and its painted maps as PNG files
//! beside it.
//!
//! ```toml
//! format = "anthesis-project"
//! version = 1
//! name = "Asiatic lily"
//!
//! [simulation]                 # optional; each field defaults as shown
//! keyframes = 100
//! relative_tolerance = 0.000001
//! max_iterations = 50
//! collision_offset = 0.01
//!
//! [[templates]]
//! name = "petal"
//! mesh = "meshes/petal.obj"    # paths are relative to the project file
//! dg = 0.003
//! thickness = 0.2
//! stretch_stiffness = 20.0
//! bend_stiffness = 20.0
//! color = [0.98, 0.62, 0.32, 1.0]          # optional, default opaque white
//! blend = "linear"                          # optional: "linear" (default),
//!                                           # "smooth" or
//!                                           # { logistic = { steepness = 10.0 } }
//! base_region = { v_max = 0.06 }            # optional: v_max 0.05, u_min 0, u_max 1
//! joint_schedule = [{ from_step = 0, to_step = 60, degrees = 23.0 }]  # optional
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
//!
//! [[organs]]
//! name = "petal-1"
//! template = "petal"
//! position = [0.0, 0.0, 0.8]   # optional, default the origin
//! azimuth_deg = 0.0            # optional, default 0
//! joint_angle_deg = 10.0       # optional, default 0
//!
//! [[overlaps]]                 # organ names
//! inner = "petal-1"
//! outer = "sepal-1"
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
//! never replaced by one that cannot be opened. Each file is written
//! atomically (a temporary file in the same folder, then a rename), the
//! meshes and maps first and the TOML last. Map and mesh files that the new
//! TOML no longer names are left in place.

use std::collections::HashSet;
use std::fmt;
use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use anthesis_maps::{
    BitDepth, Blend, DirectionMap, GrowthMaps, KeyedMaps, MapError, MapKey, MapKind, ScalarMap,
};
use anthesis_mesh::{Mesh, MeshError};
use anthesis_physics::SolverSettings;
use glam::{DVec2, DVec3};
use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::{Deserialize, Serialize, Serializer};

use crate::{
    BaseRegion, Flower, JointRamp, Organ, Overlap, Placement, Project, SimulationSettings, Template,
};

/// The value of the `format` field of every project file.
pub const FORMAT_NAME: &str = "anthesis-project";

/// The newest file format version this build reads, and the one it writes.
pub const FORMAT_VERSION: u32 = 1;

/// Where saved meshes go, relative to the project file.
pub const MESH_FOLDER: &str = "meshes";

/// Where saved PNG maps go, relative to the project file.
pub const MAP_FOLDER: &str = "maps";

/// What [`parse_project`] calls the project text in its errors.
pub const UNNAMED_PROJECT: &str = "(project text)";

/// Everything that can go wrong reading or writing a project. Every message
/// names the file it is about.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProjectError {
    #[error("{}: {message}", path.display())]
    Io { path: PathBuf, message: String },
    /// Invalid or truncated TOML, a missing or unknown field, a value of the
    /// wrong type. The message is the TOML reader's, with line and column.
    #[error("{}: {message}", path.display())]
    Syntax { path: PathBuf, message: String },
    #[error(
        "{} was written by a newer Anthesis (format version {found}; this build reads up to \
         {supported})",
        path.display()
    )]
    NewerVersion {
        path: PathBuf,
        found: i64,
        supported: u32,
    },
    #[error(
        "{} is not an Anthesis project: its `format` is {found}, expected \"{FORMAT_NAME}\"",
        path.display()
    )]
    WrongFormat {
        path: PathBuf,
        /// The `format` value as written (strings quoted), or `missing`.
        found: String,
    },
    #[error("{}: {error}", path.display())]
    Mesh { path: PathBuf, error: MeshError },
    #[error("{}: {error}", path.display())]
    Map { path: PathBuf, error: MapError },
    #[error(
        "{}: the map is {}x{} pixels but the template's other maps are {}x{}; all maps of a \
         template must have the same size",
        path.display(), found.0, found.1, expected.0, expected.1
    )]
    MapSize {
        path: PathBuf,
        expected: (u32, u32),
        found: (u32, u32),
    },
    #[error(
        "{}: organ \"{organ}\" uses template \"{template}\", which the project does not define",
        path.display()
    )]
    UnknownTemplate {
        path: PathBuf,
        organ: String,
        template: String,
    },
    #[error(
        "{}: an overlap names organ \"{name}\", which the project does not define",
        path.display()
    )]
    UnknownOrgan { path: PathBuf, name: String },
    #[error("{}: two {what}s are named \"{name}\"; names must be unique", path.display())]
    DuplicateName {
        path: PathBuf,
        /// `template` or `organ`.
        what: &'static str,
        name: String,
    },
    /// A value out of its range, e.g. a thickness of 0 or no map keys.
    #[error("{}: {message}", path.display())]
    Invalid { path: PathBuf, message: String },
}

/// Reads the project file at `path` and the meshes and PNG maps it names
/// (paths relative to the project file's folder).
pub fn load_project(path: &Path) -> Result<Project, ProjectError> {
    let bytes = fs::read(path).map_err(|error| io_error(path, "cannot read", &error))?;
    let text = String::from_utf8(bytes).map_err(|_| ProjectError::Syntax {
        path: path.to_path_buf(),
        message: "the file is not UTF-8 text".to_string(),
    })?;
    let folder = path.parent().unwrap_or(Path::new(""));
    let read = |relative: &str| fs::read(folder.join(relative));
    let loader = Loader {
        project_path: path,
        folder,
        files: &read,
    };
    loader.load(&text)
}

/// Reads a project from its TOML text; `files` returns the bytes of a mesh
/// or map given its path as written in the file. For projects that are not
/// on disk, e.g. embedded in the binary with `include_bytes!`. Errors call
/// the project file [`UNNAMED_PROJECT`] and other files by their path as
/// written.
pub fn parse_project(
    text: &str,
    files: &dyn Fn(&str) -> Result<Vec<u8>, io::Error>,
) -> Result<Project, ProjectError> {
    let loader = Loader {
        project_path: Path::new(UNNAMED_PROJECT),
        folder: Path::new(""),
        files,
    };
    loader.load(text)
}

/// Writes `project` to `path` with its meshes and maps beside it (see the
/// module documentation); creates the folders it needs.
pub fn save_project(project: &Project, path: &Path) -> Result<(), ProjectError> {
    let folder = path.parent().unwrap_or(Path::new(""));
    let plan = plan_save(project, path, folder)?;
    for (relative, bytes) in &plan.files {
        write_atomically(&folder.join(relative), bytes)?;
    }
    write_atomically(path, plan.toml.as_bytes())
}

/// The TOML text [`save_project`] would write for `project` at `path`
/// (checked the same way; no file is written).
pub fn project_to_toml(project: &Project, path: &Path) -> Result<String, ProjectError> {
    let folder = path.parent().unwrap_or(Path::new(""));
    Ok(plan_save(project, path, folder)?.toml)
}

// ---------------------------------------------------------------------------
// The file structures, as serde reads and writes them.

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ProjectFile {
    format: String,
    version: u32,
    name: String,
    #[serde(default)]
    simulation: SimulationFile,
    #[serde(default)]
    templates: Vec<TemplateFile>,
    #[serde(default)]
    organs: Vec<OrganFile>,
    #[serde(default)]
    overlaps: Vec<OverlapFile>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct SimulationFile {
    keyframes: u32,
    relative_tolerance: f64,
    max_iterations: u32,
    collision_offset: f64,
}

impl Default for SimulationFile {
    fn default() -> Self {
        SimulationFile::from(&SimulationSettings::default())
    }
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct TemplateFile {
    name: String,
    mesh: String,
    dg: f64,
    thickness: f64,
    stretch_stiffness: f64,
    bend_stiffness: f64,
    #[serde(default = "opaque_white")]
    color: [f32; 4],
    #[serde(default)]
    blend: BlendFile,
    #[serde(default)]
    base_region: BaseRegionFile,
    #[serde(default)]
    joint_schedule: Vec<JointRampFile>,
    keys: Vec<KeyFile>,
}

fn opaque_white() -> [f32; 4] {
    [1.0; 4]
}

/// Like [`Blend`], but refusing unknown fields.
#[derive(Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
enum BlendFile {
    #[default]
    Linear,
    Smooth,
    Logistic {
        #[serde(default = "default_steepness")]
        steepness: f64,
    },
}

fn default_steepness() -> f64 {
    Blend::DEFAULT_STEEPNESS
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct BaseRegionFile {
    v_max: f64,
    u_min: f64,
    u_max: f64,
}

impl Default for BaseRegionFile {
    fn default() -> Self {
        let region = BaseRegion::default();
        BaseRegionFile {
            v_max: region.v_max,
            u_min: region.u_min,
            u_max: region.u_max,
        }
    }
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct JointRampFile {
    from_step: u32,
    to_step: u32,
    degrees: f64,
}

#[derive(Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct KeyFile {
    step: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    e_growth: Option<ScalarEntry>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    w_growth: Option<ScalarEntry>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    e_growth_in: Option<ScalarEntry>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    w_growth_in: Option<ScalarEntry>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    stretch: Option<ScalarEntry>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    bend: Option<ScalarEntry>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    direction: Option<DirectionEntry>,
}

impl KeyFile {
    /// The entry of one scalar map: the one place that pairs field and kind.
    fn scalar_mut(&mut self, kind: MapKind) -> &mut Option<ScalarEntry> {
        match kind {
            MapKind::EGrowth => &mut self.e_growth,
            MapKind::WGrowth => &mut self.w_growth,
            MapKind::EGrowthIn => &mut self.e_growth_in,
            MapKind::WGrowthIn => &mut self.w_growth_in,
            MapKind::Stretch => &mut self.stretch,
            MapKind::Bend => &mut self.bend,
        }
    }
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct OrganFile {
    name: String,
    template: String,
    #[serde(default)]
    position: [f64; 3],
    #[serde(default)]
    azimuth_deg: f64,
    #[serde(default)]
    joint_angle_deg: f64,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct OverlapFile {
    inner: String,
    outer: String,
}

/// A scalar map entry: a number or a PNG path.
#[derive(Debug, Clone, PartialEq)]
enum ScalarEntry {
    Constant(f32),
    File(String),
}

/// A direction map entry: a `[u, v]` pair or a PNG path.
#[derive(Debug, Clone, PartialEq)]
enum DirectionEntry {
    Constant([f32; 2]),
    File(String),
}

impl Serialize for ScalarEntry {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            ScalarEntry::Constant(value) => serializer.serialize_f32(*value),
            ScalarEntry::File(path) => serializer.serialize_str(path),
        }
    }
}

impl Serialize for DirectionEntry {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            DirectionEntry::Constant(pair) => pair.serialize(serializer),
            DirectionEntry::File(path) => serializer.serialize_str(path),
        }
    }
}

impl<'de> Deserialize<'de> for ScalarEntry {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(ScalarEntryVisitor)
    }
}

impl<'de> Deserialize<'de> for DirectionEntry {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(DirectionEntryVisitor)
    }
}

struct ScalarEntryVisitor;

impl Visitor<'_> for ScalarEntryVisitor {
    type Value = ScalarEntry;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number (a constant map) or the path of a PNG file")
    }

    fn visit_f64<E: de::Error>(self, value: f64) -> Result<ScalarEntry, E> {
        Ok(ScalarEntry::Constant(value as f32))
    }

    fn visit_i64<E: de::Error>(self, value: i64) -> Result<ScalarEntry, E> {
        Ok(ScalarEntry::Constant(value as f32))
    }

    fn visit_u64<E: de::Error>(self, value: u64) -> Result<ScalarEntry, E> {
        Ok(ScalarEntry::Constant(value as f32))
    }

    fn visit_str<E: de::Error>(self, path: &str) -> Result<ScalarEntry, E> {
        Ok(ScalarEntry::File(path.to_string()))
    }
}

struct DirectionEntryVisitor;

impl<'de> Visitor<'de> for DirectionEntryVisitor {
    type Value = DirectionEntry;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a [u, v] pair of numbers (a constant direction) or the path of a PNG file")
    }

    fn visit_str<E: de::Error>(self, path: &str) -> Result<DirectionEntry, E> {
        Ok(DirectionEntry::File(path.to_string()))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<DirectionEntry, A::Error> {
        let mut pair = [0.0f32; 2];
        for (index, component) in pair.iter_mut().enumerate() {
            let value: f64 = seq
                .next_element()?
                .ok_or_else(|| de::Error::invalid_length(index, &self))?;
            *component = value as f32;
        }
        if seq.next_element::<de::IgnoredAny>()?.is_some() {
            return Err(de::Error::invalid_length(3, &self));
        }
        Ok(DirectionEntry::Constant(pair))
    }
}

// ---------------------------------------------------------------------------
// Conversions of the plain parts.

impl From<&SimulationSettings> for SimulationFile {
    fn from(settings: &SimulationSettings) -> Self {
        SimulationFile {
            keyframes: settings.keyframes,
            relative_tolerance: settings.solver.relative_tolerance,
            max_iterations: settings.solver.max_iterations,
            collision_offset: settings.collision_offset,
        }
    }
}

impl From<&SimulationFile> for SimulationSettings {
    fn from(file: &SimulationFile) -> Self {
        SimulationSettings {
            keyframes: file.keyframes,
            solver: SolverSettings {
                relative_tolerance: file.relative_tolerance,
                max_iterations: file.max_iterations,
            },
            collision_offset: file.collision_offset,
            ..SimulationSettings::default()
        }
    }
}

impl From<Blend> for BlendFile {
    fn from(blend: Blend) -> Self {
        match blend {
            Blend::Linear => BlendFile::Linear,
            Blend::Smooth => BlendFile::Smooth,
            Blend::Logistic { steepness } => BlendFile::Logistic { steepness },
        }
    }
}

impl From<&BlendFile> for Blend {
    fn from(file: &BlendFile) -> Self {
        match *file {
            BlendFile::Linear => Blend::Linear,
            BlendFile::Smooth => Blend::Smooth,
            BlendFile::Logistic { steepness } => Blend::Logistic { steepness },
        }
    }
}

impl From<&JointRamp> for JointRampFile {
    fn from(ramp: &JointRamp) -> Self {
        JointRampFile {
            from_step: ramp.from_step,
            to_step: ramp.to_step,
            degrees: ramp.degrees,
        }
    }
}

impl From<&JointRampFile> for JointRamp {
    fn from(file: &JointRampFile) -> Self {
        JointRamp {
            from_step: file.from_step,
            to_step: file.to_step,
            degrees: file.degrees,
        }
    }
}

// ---------------------------------------------------------------------------
// Loading.

struct Loader<'a> {
    /// The project file, for messages.
    project_path: &'a Path,
    /// What relative paths are shown relative to in messages.
    folder: &'a Path,
    files: &'a dyn Fn(&str) -> Result<Vec<u8>, io::Error>,
}

impl Loader<'_> {
    fn load(&self, text: &str) -> Result<Project, ProjectError> {
        // The header first, leniently: a newer version may have fields this
        // build does not know, and its error should say so.
        let table: toml::Table = toml::from_str(text).map_err(|error| self.syntax(&error))?;
        check_header(&table, self.project_path)?;
        let file: ProjectFile = toml::from_str(text).map_err(|error| self.syntax(&error))?;
        let project = self.project(file)?;
        check_project(&project, self.project_path)?;
        Ok(project)
    }

    fn syntax(&self, error: &toml::de::Error) -> ProjectError {
        ProjectError::Syntax {
            path: self.project_path.to_path_buf(),
            message: error.to_string().trim_end().to_string(),
        }
    }

    fn invalid(&self, message: String) -> ProjectError {
        ProjectError::Invalid {
            path: self.project_path.to_path_buf(),
            message,
        }
    }

    fn project(&self, file: ProjectFile) -> Result<Project, ProjectError> {
        let path = self.project_path;
        check_unique(
            file.templates.iter().map(|t| t.name.as_str()),
            "template",
            path,
        )?;
        check_unique(file.organs.iter().map(|o| o.name.as_str()), "organ", path)?;
        let templates = file
            .templates
            .into_iter()
            .map(|template| self.template(template))
            .collect::<Result<Vec<_>, _>>()?;
        let organs = file
            .organs
            .iter()
            .map(|organ| {
                let template = templates
                    .iter()
                    .position(|t| t.name == organ.template)
                    .ok_or_else(|| ProjectError::UnknownTemplate {
                        path: path.to_path_buf(),
                        organ: organ.name.clone(),
                        template: organ.template.clone(),
                    })?;
                Ok(Organ {
                    name: organ.name.clone(),
                    template,
                    placement: Placement {
                        position: DVec3::from_array(organ.position),
                        azimuth_deg: organ.azimuth_deg,
                        joint_angle_deg: organ.joint_angle_deg,
                    },
                })
            })
            .collect::<Result<Vec<_>, ProjectError>>()?;
        let organ_index = |name: &str| {
            organs
                .iter()
                .position(|organ| organ.name == name)
                .ok_or_else(|| ProjectError::UnknownOrgan {
                    path: path.to_path_buf(),
                    name: name.to_string(),
                })
        };
        let overlaps = file
            .overlaps
            .iter()
            .map(|overlap| {
                Ok(Overlap {
                    inner: organ_index(&overlap.inner)?,
                    outer: organ_index(&overlap.outer)?,
                })
            })
            .collect::<Result<Vec<_>, ProjectError>>()?;
        Ok(Project {
            name: file.name,
            flower: Flower {
                templates,
                organs,
                overlaps,
            },
            settings: SimulationSettings::from(&file.simulation),
        })
    }

    fn template(&self, file: TemplateFile) -> Result<Template, ProjectError> {
        let name = &file.name;
        if file.keys.is_empty() {
            return Err(self.invalid(format!(
                "template \"{name}\" has no map keys; it needs at least one [[templates.keys]]"
            )));
        }
        let mut steps = HashSet::new();
        if let Some(key) = file.keys.iter().find(|key| !steps.insert(key.step)) {
            return Err(self.invalid(format!(
                "template \"{name}\" has two map keys at step {}; each key needs its own step",
                key.step
            )));
        }
        let mesh = self.mesh(&file.mesh)?;
        let mut size = SizeCheck::default();
        let mut keys = Vec::with_capacity(file.keys.len());
        for mut key in file.keys {
            let mut maps = GrowthMaps::uniform();
            for kind in MapKind::ALL {
                if let Some(entry) = key.scalar_mut(kind).take() {
                    *maps.scalar_mut(kind) = self.scalar_map(entry, &mut size)?;
                }
            }
            if let Some(entry) = key.direction.take() {
                maps.direction = self.direction_map(entry, &mut size)?;
            }
            keys.push(MapKey {
                step: key.step,
                maps,
            });
        }
        let maps = KeyedMaps::new(keys, Blend::from(&file.blend))
            .map_err(|error| self.invalid(format!("template \"{name}\": {error}")))?;
        Ok(Template {
            name: file.name,
            mesh,
            maps,
            dg: file.dg,
            thickness: file.thickness,
            stretch_stiffness: file.stretch_stiffness,
            bend_stiffness: file.bend_stiffness,
            base_region: BaseRegion {
                v_max: file.base_region.v_max,
                u_min: file.base_region.u_min,
                u_max: file.base_region.u_max,
            },
            joint_schedule: file.joint_schedule.iter().map(JointRamp::from).collect(),
            color: file.color,
        })
    }

    /// The bytes of a file named in the project, and the path to show for it.
    fn read(&self, relative: &str) -> Result<(Vec<u8>, PathBuf), ProjectError> {
        let path = self.folder.join(relative);
        match (self.files)(relative) {
            Ok(bytes) => Ok((bytes, path)),
            Err(error) => Err(io_error(&path, "cannot read", &error)),
        }
    }

    fn mesh(&self, relative: &str) -> Result<Mesh, ProjectError> {
        let (bytes, path) = self.read(relative)?;
        let parsed = match String::from_utf8(bytes) {
            Ok(text) => anthesis_mesh::parse_obj(&text),
            Err(_) => Err(MeshError::Io("the file is not UTF-8 text".to_string())),
        };
        parsed.map_err(|error| ProjectError::Mesh { path, error })
    }

    fn scalar_map(
        &self,
        entry: ScalarEntry,
        size: &mut SizeCheck,
    ) -> Result<ScalarMap, ProjectError> {
        match entry {
            ScalarEntry::Constant(value) => Ok(ScalarMap::constant(value)),
            ScalarEntry::File(relative) => {
                let (bytes, path) = self.read(&relative)?;
                let map =
                    ScalarMap::from_png_bytes(&bytes).map_err(|error| map_error(&path, error))?;
                size.check(&path, map.size())?;
                Ok(map)
            }
        }
    }

    fn direction_map(
        &self,
        entry: DirectionEntry,
        size: &mut SizeCheck,
    ) -> Result<DirectionMap, ProjectError> {
        match entry {
            DirectionEntry::Constant([u, v]) => Ok(DirectionMap::constant(DVec2::new(
                f64::from(u),
                f64::from(v),
            ))),
            DirectionEntry::File(relative) => {
                let (bytes, path) = self.read(&relative)?;
                let map = DirectionMap::from_png_bytes(&bytes)
                    .map_err(|error| map_error(&path, error))?;
                size.check(&path, map.size())?;
                Ok(map)
            }
        }
    }
}

/// Checks `format` and `version` in the parsed TOML table.
fn check_header(table: &toml::Table, path: &Path) -> Result<(), ProjectError> {
    match table.get("format") {
        Some(toml::Value::String(format)) if format == FORMAT_NAME => {}
        found => {
            return Err(ProjectError::WrongFormat {
                path: path.to_path_buf(),
                found: found.map_or_else(|| "missing".to_string(), |value| value.to_string()),
            });
        }
    }
    let invalid = |message: String| ProjectError::Invalid {
        path: path.to_path_buf(),
        message,
    };
    match table.get("version") {
        Some(toml::Value::Integer(version)) if *version > i64::from(FORMAT_VERSION) => {
            Err(ProjectError::NewerVersion {
                path: path.to_path_buf(),
                found: *version,
                supported: FORMAT_VERSION,
            })
        }
        Some(toml::Value::Integer(version)) if *version >= 1 => Ok(()),
        Some(toml::Value::Integer(version)) => Err(invalid(format!(
            "format version {version} does not exist; versions start at 1"
        ))),
        Some(other) => Err(invalid(format!(
            "`version` must be a whole number, found {other}"
        ))),
        None => Err(invalid(format!(
            "the file has no `version`; write `version = {FORMAT_VERSION}` after `format`"
        ))),
    }
}

/// All raster maps of a template must share one size; the first sets it.
/// 1x1 maps are constants and fit any size.
#[derive(Default)]
struct SizeCheck {
    expected: Option<(u32, u32)>,
}

impl SizeCheck {
    fn check(&mut self, path: &Path, found: (u32, u32)) -> Result<(), ProjectError> {
        if found == (1, 1) {
            return Ok(());
        }
        match self.expected {
            None => {
                self.expected = Some(found);
                Ok(())
            }
            Some(expected) if expected == found => Ok(()),
            Some(expected) => Err(ProjectError::MapSize {
                path: path.to_path_buf(),
                expected,
                found,
            }),
        }
    }
}

fn check_unique<'a>(
    names: impl Iterator<Item = &'a str>,
    what: &'static str,
    path: &Path,
) -> Result<(), ProjectError> {
    let mut seen = HashSet::new();
    for name in names {
        if !seen.insert(name) {
            return Err(ProjectError::DuplicateName {
                path: path.to_path_buf(),
                what,
                name: name.to_string(),
            });
        }
    }
    Ok(())
}

/// The rules every loaded or saved project obeys, apart from the mesh and
/// map-size checks, which need the file names.
fn check_project(project: &Project, path: &Path) -> Result<(), ProjectError> {
    let invalid = |message: String| {
        Err(ProjectError::Invalid {
            path: path.to_path_buf(),
            message,
        })
    };
    let flower = &project.flower;
    check_unique(
        flower.templates.iter().map(|t| t.name.as_str()),
        "template",
        path,
    )?;
    check_unique(flower.organs.iter().map(|o| o.name.as_str()), "organ", path)?;

    let settings = &project.settings;
    if settings.keyframes == 0 {
        return invalid("simulation: keyframes must be at least 1".to_string());
    }
    if !(settings.solver.relative_tolerance > 0.0 && settings.solver.relative_tolerance.is_finite())
    {
        return invalid(format!(
            "simulation: relative_tolerance must be a positive number, found {}",
            settings.solver.relative_tolerance
        ));
    }
    if settings.solver.max_iterations == 0 {
        return invalid("simulation: max_iterations must be at least 1".to_string());
    }
    if !(settings.collision_offset >= 0.0 && settings.collision_offset.is_finite()) {
        return invalid(format!(
            "simulation: collision_offset must be 0 or more, found {}",
            settings.collision_offset
        ));
    }

    for template in &flower.templates {
        if let Some(message) = template_problem(template) {
            return invalid(format!("template \"{}\": {message}", template.name));
        }
    }

    for organ in &flower.organs {
        let placement = &organ.placement;
        if organ.template >= flower.templates.len() {
            return invalid(format!(
                "organ \"{}\" uses template {}, but there are only {} templates",
                organ.name,
                organ.template,
                flower.templates.len()
            ));
        }
        let finite = placement.position.is_finite()
            && placement.azimuth_deg.is_finite()
            && placement.joint_angle_deg.is_finite();
        if !finite {
            return invalid(format!(
                "organ \"{}\": position and angles must be finite numbers",
                organ.name
            ));
        }
    }

    for overlap in &flower.overlaps {
        let count = flower.organs.len();
        if overlap.inner >= count || overlap.outer >= count {
            return invalid(format!(
                "an overlap refers to organ {} or {}, but there are only {count} organs",
                overlap.inner, overlap.outer
            ));
        }
        if overlap.inner == overlap.outer {
            return invalid(format!(
                "organ \"{}\" cannot overlap itself",
                flower.organs[overlap.inner].name
            ));
        }
    }
    Ok(())
}

/// What is wrong with a template's numbers, if anything.
fn template_problem(template: &Template) -> Option<String> {
    let positive = |value: f64| value > 0.0 && value.is_finite();
    if !template.dg.is_finite() {
        return Some(format!("dg must be a finite number, found {}", template.dg));
    }
    let scales = [
        ("thickness", template.thickness),
        ("stretch_stiffness", template.stretch_stiffness),
        ("bend_stiffness", template.bend_stiffness),
    ];
    for (field, value) in scales {
        if !positive(value) {
            return Some(format!("{field} must be greater than 0, found {value}"));
        }
    }
    let region = &template.base_region;
    let in_unit = |value: f64| (0.0..=1.0).contains(&value);
    if !(in_unit(region.v_max) && in_unit(region.u_min) && in_unit(region.u_max)) {
        return Some(format!(
            "base_region v_max, u_min and u_max must lie in [0, 1], found {}, {}, {}",
            region.v_max, region.u_min, region.u_max
        ));
    }
    if region.u_min > region.u_max {
        return Some(format!(
            "base_region u_min ({}) is greater than u_max ({})",
            region.u_min, region.u_max
        ));
    }
    if template.color.iter().any(|c| !(0.0..=1.0).contains(c)) {
        return Some(format!(
            "color components must lie in [0, 1], found {:?}",
            template.color
        ));
    }
    for ramp in &template.joint_schedule {
        if ramp.from_step > ramp.to_step || !ramp.degrees.is_finite() {
            return Some(format!(
                "joint_schedule ramp from step {} to step {} by {} degrees: from_step must not \
                 exceed to_step and degrees must be finite",
                ramp.from_step, ramp.to_step, ramp.degrees
            ));
        }
    }
    if let Blend::Logistic { steepness } = template.maps.blend
        && !steepness.is_finite()
    {
        return Some(format!(
            "blend steepness must be a finite number, found {steepness}"
        ));
    }
    for key in template.maps.keys() {
        for kind in MapKind::ALL {
            let values = key.maps.scalar(kind).values();
            if let Some(value) = values.iter().find(|value| !value.is_finite()) {
                return Some(format!(
                    "map key at step {}: the {} map holds {value}; map values must be finite",
                    key.step,
                    kind.name()
                ));
            }
        }
        let direction = key.maps.direction.values();
        if direction.iter().flatten().any(|value| !value.is_finite()) {
            return Some(format!(
                "map key at step {}: the direction map holds a value that is not finite",
                key.step
            ));
        }
    }
    None
}

fn io_error(path: &Path, doing: &str, error: &io::Error) -> ProjectError {
    ProjectError::Io {
        path: path.to_path_buf(),
        message: format!("{doing}: {error}"),
    }
}

fn map_error(path: &Path, error: MapError) -> ProjectError {
    ProjectError::Map {
        path: path.to_path_buf(),
        error,
    }
}

// ---------------------------------------------------------------------------
// Saving.

/// The files of a saved project: the TOML text and the meshes and maps, by
/// path relative to the project file.
struct SavePlan {
    toml: String,
    files: Vec<(String, Vec<u8>)>,
}

/// Checks `project` and encodes every file [`save_project`] writes.
/// `folder` is where relative paths are shown from in errors.
fn plan_save(project: &Project, path: &Path, folder: &Path) -> Result<SavePlan, ProjectError> {
    check_project(project, path)?;
    let flower = &project.flower;
    let mut files = Vec::new();
    let stems = file_stems(flower.templates.iter().map(|t| t.name.as_str()));
    let mut templates = Vec::with_capacity(flower.templates.len());
    for (template, stem) in flower.templates.iter().zip(&stems) {
        templates.push(template_file(template, stem, folder, &mut files)?);
    }
    let organs = flower
        .organs
        .iter()
        .map(|organ| OrganFile {
            name: organ.name.clone(),
            template: flower.templates[organ.template].name.clone(),
            position: organ.placement.position.to_array(),
            azimuth_deg: organ.placement.azimuth_deg,
            joint_angle_deg: organ.placement.joint_angle_deg,
        })
        .collect();
    let overlaps = flower
        .overlaps
        .iter()
        .map(|overlap| OverlapFile {
            inner: flower.organs[overlap.inner].name.clone(),
            outer: flower.organs[overlap.outer].name.clone(),
        })
        .collect();
    let file = ProjectFile {
        format: FORMAT_NAME.to_string(),
        version: FORMAT_VERSION,
        name: project.name.clone(),
        simulation: SimulationFile::from(&project.settings),
        templates,
        organs,
        overlaps,
    };
    let body = toml::to_string(&file).map_err(|error| ProjectError::Invalid {
        path: path.to_path_buf(),
        message: format!("cannot write the project as TOML: {error}"),
    })?;
    let toml = format!(
        "# Anthesis project. Meshes are OBJ files in {MESH_FOLDER}/, painted maps 16-bit PNG \
         files in {MAP_FOLDER}/.\n{body}"
    );
    Ok(SavePlan { toml, files })
}

/// The file entry of one template; adds its mesh and raster maps to `files`.
fn template_file(
    template: &Template,
    stem: &str,
    folder: &Path,
    files: &mut Vec<(String, Vec<u8>)>,
) -> Result<TemplateFile, ProjectError> {
    let mesh_relative = format!("{MESH_FOLDER}/{stem}.obj");
    anthesis_mesh::validate(&template.mesh).map_err(|error| ProjectError::Mesh {
        path: folder.join(&mesh_relative),
        error,
    })?;
    files.push((
        mesh_relative.clone(),
        anthesis_mesh::obj_string(&template.mesh).into_bytes(),
    ));

    let mut size = SizeCheck::default();
    let mut keys = Vec::with_capacity(template.maps.keys().len());
    for key in template.maps.keys() {
        let mut key_file = KeyFile {
            step: key.step,
            ..KeyFile::default()
        };
        let map_relative =
            |map_name: &str| format!("{MAP_FOLDER}/{stem}-step{}-{map_name}.png", key.step);
        for kind in MapKind::ALL {
            let map = key.maps.scalar(kind);
            let entry = if map.size() == (1, 1) {
                ScalarEntry::Constant(map.values()[0])
            } else {
                let relative = map_relative(kind.name());
                let path = folder.join(&relative);
                size.check(&path, map.size())?;
                if let Some(value) = map.values().iter().find(|v| !(0.0..=1.0).contains(*v)) {
                    return Err(out_of_range(&path, kind.name(), *value, "0 to 1"));
                }
                let bytes = map
                    .to_png_bytes(BitDepth::Sixteen)
                    .map_err(|error| map_error(&path, error))?;
                files.push((relative.clone(), bytes));
                ScalarEntry::File(relative)
            };
            *key_file.scalar_mut(kind) = Some(entry);
        }
        let direction = &key.maps.direction;
        let entry = if direction.size() == (1, 1) {
            DirectionEntry::Constant(direction.values()[0])
        } else {
            let relative = map_relative(anthesis_maps::DIRECTION_MAP_NAME);
            let path = folder.join(&relative);
            size.check(&path, direction.size())?;
            let components = direction.values().iter().flatten();
            if let Some(value) = components.into_iter().find(|v| !(-1.0..=1.0).contains(*v)) {
                return Err(out_of_range(&path, "direction", *value, "-1 to 1"));
            }
            let bytes = direction
                .to_png_bytes(BitDepth::Sixteen)
                .map_err(|error| map_error(&path, error))?;
            files.push((relative.clone(), bytes));
            DirectionEntry::File(relative)
        };
        key_file.direction = Some(entry);
        keys.push(key_file);
    }

    let region = &template.base_region;
    Ok(TemplateFile {
        name: template.name.clone(),
        mesh: mesh_relative,
        dg: template.dg,
        thickness: template.thickness,
        stretch_stiffness: template.stretch_stiffness,
        bend_stiffness: template.bend_stiffness,
        color: template.color,
        blend: BlendFile::from(template.maps.blend),
        base_region: BaseRegionFile {
            v_max: region.v_max,
            u_min: region.u_min,
            u_max: region.u_max,
        },
        joint_schedule: template
            .joint_schedule
            .iter()
            .map(JointRampFile::from)
            .collect(),
        keys,
    })
}

fn out_of_range(path: &Path, map_name: &str, value: f32, range: &str) -> ProjectError {
    ProjectError::Invalid {
        path: path.to_path_buf(),
        message: format!(
            "the {map_name} map holds {value}, but a PNG map holds values from {range}; \
             the project was not saved"
        ),
    }
}

/// One file-name stem per template: the name in lower case with everything
/// but ASCII letters, digits, `-` and `_` replaced by `_`, made unique by
/// appending `-2`, `-3`, ….
fn file_stems<'a>(names: impl Iterator<Item = &'a str>) -> Vec<String> {
    let mut used = HashSet::new();
    names
        .map(|name| {
            let mut base: String = name
                .chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                        c.to_ascii_lowercase()
                    } else {
                        '_'
                    }
                })
                .collect();
            if base.is_empty() {
                base = "template".to_string();
            }
            let mut stem = base.clone();
            let mut number = 2;
            while !used.insert(stem.clone()) {
                stem = format!("{base}-{number}");
                number += 1;
            }
            stem
        })
        .collect()
}

/// Writes `bytes` to `path` through a temporary file in the same folder and
/// a rename, so `path` holds either its old contents or all of the new ones.
/// Creates the folder if needed.
fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), ProjectError> {
    static NEXT_TEMP: AtomicU64 = AtomicU64::new(0);
    let folder = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    let Some(file_name) = path.file_name() else {
        return Err(ProjectError::Io {
            path: path.to_path_buf(),
            message: "cannot write: the path does not name a file".to_string(),
        });
    };
    fs::create_dir_all(folder).map_err(|error| io_error(folder, "cannot create folder", &error))?;
    let temp_path = folder.join(format!(
        ".{}.{}-{}.tmp",
        file_name.to_string_lossy(),
        std::process::id(),
        NEXT_TEMP.fetch_add(1, Ordering::Relaxed)
    ));
    let written = fs::File::create(&temp_path).and_then(|mut file| {
        file.write_all(bytes)?;
        file.sync_all()
    });
    let result = written.and_then(|()| fs::rename(&temp_path, path));
    if let Err(error) = result {
        // The temporary file is of no use now; failing to remove it changes
        // nothing for the caller.
        let _ = fs::remove_file(&temp_path);
        return Err(io_error(path, "cannot write", &error));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stems_are_file_safe_lower_case_and_unique() {
        let names = ["Petal", "petal", "Outer sepal/2", "", "ünï", "petal-2"];
        let stems = file_stems(names.into_iter());
        assert_eq!(
            stems,
            [
                "petal",
                "petal-2",
                "outer_sepal_2",
                "template",
                "_n_",
                "petal-2-2"
            ]
        );
    }

    #[test]
    fn atomic_write_replaces_the_file_and_leaves_no_temporary() {
        let folder = tempfile::tempdir().expect("temp dir");
        let path = folder.path().join("sub").join("a.txt");
        write_atomically(&path, b"old").expect("first write");
        write_atomically(&path, b"new contents").expect("second write");
        assert_eq!(fs::read(&path).expect("read"), b"new contents");
        let entries: Vec<_> = fs::read_dir(folder.path().join("sub"))
            .expect("list")
            .map(|entry| entry.expect("entry").file_name())
            .collect();
        assert_eq!(entries, ["a.txt"]);
    }

    #[test]
    fn atomic_write_into_a_file_reports_the_path() {
        let folder = tempfile::tempdir().expect("temp dir");
        let blocker = folder.path().join("blocker");
        fs::write(&blocker, b"a file, not a folder").expect("write");
        let path = blocker.join("a.txt");
        let error = write_atomically(&path, b"x").expect_err("parent is a file");
        assert!(matches!(error, ProjectError::Io { .. }), "{error:?}");
        assert!(error.to_string().contains("blocker"), "{error}");
    }
}

//! [`ProjectError`]: what can go wrong reading or writing a project.

use std::path::{Path, PathBuf};

use anthesis_maps::MapError;
use anthesis_mesh::MeshError;

use super::FORMAT_NAME;

/// Everything that can go wrong reading or writing a project. Every message
/// names the file it is about.
#[derive(Debug, PartialEq, thiserror::Error)]
pub enum ProjectError {
    /// A file named in the project could not be read.
    #[error("{}: {message}", path.display())]
    Io {
        /// The file that could not be read: the project file or a mesh or
        /// map it names.
        path: PathBuf,
        /// Why, from the operating system or the file checks (too large,
        /// not a regular file, outside the project's folder).
        message: String,
    },
    /// Invalid or truncated TOML, a missing or unknown field, a value of the
    /// wrong type. The message is the TOML reader's, with line and column.
    #[error("{}: {message}", path.display())]
    Syntax {
        /// The project file.
        path: PathBuf,
        /// The TOML reader's message, with line and column.
        message: String,
    },
    /// The project's `version` is newer than this build reads; the user
    /// needs a newer Anthesis (the file is not touched).
    #[error(
        "{} was written by a newer Anthesis (format version {found}; this build reads up to \
         {supported})",
        path.display()
    )]
    NewerVersion {
        /// The project file.
        path: PathBuf,
        /// The `version` written in the file.
        found: i64,
        /// The newest format version this build reads.
        supported: u32,
    },
    /// The file is TOML but its `format` field does not say it is an
    /// Anthesis project (another program's file, or a typo).
    #[error(
        "{} is not an Anthesis project: its `format` is {found}, expected \"{FORMAT_NAME}\"",
        path.display()
    )]
    WrongFormat {
        /// The file that was opened as a project.
        path: PathBuf,
        /// The `format` value as written (strings quoted), or `missing`.
        found: String,
    },
    /// A template's mesh file was read but is not a usable mesh.
    #[error("{}: {error}", path.display())]
    Mesh {
        /// The mesh file.
        path: PathBuf,
        /// What is wrong with it.
        error: MeshError,
    },
    /// A growth map image of a template was read but cannot be used (or
    /// could not be encoded when saving).
    #[error("{}: {error}", path.display())]
    Map {
        /// The map image.
        path: PathBuf,
        /// What is wrong with it.
        error: MapError,
    },
    /// One map of a template differs in size from the template's other
    /// maps; all of a template's maps share one raster.
    #[error(
        "{}: the map is {}x{} pixels but the template's other maps are {}x{}; all maps of a \
         template must have the same size",
        path.display(), found.0, found.1, expected.0, expected.1
    )]
    MapSize {
        /// The map image whose size differs.
        path: PathBuf,
        /// Width and height in pixels of the template's other maps.
        expected: (u32, u32),
        /// Width and height in pixels of this map.
        found: (u32, u32),
    },
    /// An organ names a template the project does not define.
    #[error(
        "{}: organ \"{organ}\" uses template \"{template}\", which the project does not define",
        path.display()
    )]
    UnknownTemplate {
        /// The project file.
        path: PathBuf,
        /// The organ's name.
        organ: String,
        /// The template name it gives.
        template: String,
    },
    /// An overlap (which organ lies inside which) names an organ the
    /// project does not define.
    #[error(
        "{}: an overlap names organ \"{name}\", which the project does not define",
        path.display()
    )]
    UnknownOrgan {
        /// The project file.
        path: PathBuf,
        /// The organ name the overlap gives.
        name: String,
    },
    /// Two templates, or two organs, share a name; names identify them
    /// in the file and must be unique.
    #[error("{}: two {what}s are named \"{name}\"; names must be unique", path.display())]
    DuplicateName {
        /// The project file.
        path: PathBuf,
        /// `template` or `organ`.
        what: &'static str,
        /// The shared name.
        name: String,
    },
    /// A file of the project could not be written (saving).
    #[error(transparent)]
    Write(#[from] anthesis_files::WriteError),
    /// A value out of its range, e.g. a thickness of 0 or no map keys.
    #[error("{}: {message}", path.display())]
    Invalid {
        /// The project file, or the file the value belongs to.
        path: PathBuf,
        /// Which value is wrong and its allowed range.
        message: String,
    },
}

pub(super) fn map_error(path: &Path, error: MapError) -> ProjectError {
    ProjectError::Map {
        path: path.to_path_buf(),
        error,
    }
}

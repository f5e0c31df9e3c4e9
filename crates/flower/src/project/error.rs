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
    /// A file of the project could not be written (saving).
    #[error(transparent)]
    Write(#[from] anthesis_files::WriteError),
    /// A value out of its range, e.g. a thickness of 0 or no map keys.
    #[error("{}: {message}", path.display())]
    Invalid { path: PathBuf, message: String },
}

pub(super) fn map_error(path: &Path, error: MapError) -> ProjectError {
    ProjectError::Map {
        path: path.to_path_buf(),
        error,
    }
}

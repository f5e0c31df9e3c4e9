use std::io;
use std::path::PathBuf;

use thiserror::Error;

/// Everything that can go wrong while exporting. File errors name the path
/// and say what went wrong in words a user can act on; input errors name the
/// track and the offending keyframe, vertex or triangle (0-based).
#[derive(Debug, Error)]
pub enum ExportError {
    #[error("cannot write {}: the folder {} does not exist", .path.display(), .folder.display())]
    MissingFolder { path: PathBuf, folder: PathBuf },
    #[error("cannot write {}: {} is a file, not a folder", .path.display(), .folder.display())]
    NotAFolder { path: PathBuf, folder: PathBuf },
    #[error("cannot write {}: a folder of that name exists", .path.display())]
    IsAFolder { path: PathBuf },
    #[error("cannot write {}: the location is not writable ({source})", .path.display())]
    NotWritable { path: PathBuf, source: io::Error },
    #[error("cannot write {}: the disk is full or the quota is exceeded ({source})", .path.display())]
    DiskFull { path: PathBuf, source: io::Error },
    #[error("cannot write {}: {source}", .path.display())]
    Io { path: PathBuf, source: io::Error },
    #[error("nothing to export: there are no tracks")]
    NoTracks,
    #[error("track {track} ({name:?}): {problem}")]
    InvalidTrack {
        track: usize,
        name: String,
        problem: TrackProblem,
    },
    #[error(
        "track {track} ({name:?}) has {found} keyframes but the animated tracks before it have {expected}: all animated tracks need the same keyframes"
    )]
    KeyframeCountMismatch {
        track: usize,
        name: String,
        expected: usize,
        found: usize,
    },
    #[error("invalid export option: {0}")]
    InvalidOptions(String),
    #[error("the .glb would be {bytes} bytes, more than the 4 GiB the format allows")]
    TooLarge { bytes: u64 },
}

/// What is wrong with one track's data.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TrackProblem {
    #[error("it has no keyframes")]
    NoKeyframes,
    #[error("it has no vertices")]
    NoVertices,
    #[error("it has no triangles")]
    NoTriangles,
    #[error("it has {found} UVs for {expected} vertices: every vertex needs one UV")]
    UvCount { expected: usize, found: usize },
    #[error("keyframe {keyframe} has {found} vertices but keyframe 0 has {expected}")]
    KeyframeVertexCount {
        keyframe: usize,
        expected: usize,
        found: usize,
    },
    #[error("triangle {triangle} refers to vertex {index}, but there are only {vertex_count}")]
    IndexOutOfRange {
        triangle: usize,
        index: u32,
        vertex_count: usize,
    },
    #[error(
        "vertex {vertex} at keyframe {keyframe} has a non-finite or huge coordinate (NaN, infinite or beyond f32)"
    )]
    NonFinitePosition { keyframe: usize, vertex: usize },
    #[error("the UV of vertex {vertex} is not finite")]
    NonFiniteUv { vertex: usize },
    #[error("its base colour {color:?} is not four numbers in [0, 1]")]
    BaseColor { color: [f32; 4] },
    #[error("its base-colour texture is not a PNG file")]
    TextureNotPng,
}

impl ExportError {
    /// Turns an I/O error met while writing `path` into the specific
    /// variant a user can act on.
    pub(crate) fn from_io(path: PathBuf, source: io::Error) -> Self {
        match source.kind() {
            io::ErrorKind::PermissionDenied | io::ErrorKind::ReadOnlyFilesystem => {
                ExportError::NotWritable { path, source }
            }
            io::ErrorKind::StorageFull | io::ErrorKind::QuotaExceeded => {
                ExportError::DiskFull { path, source }
            }
            io::ErrorKind::IsADirectory => ExportError::IsAFolder { path },
            io::ErrorKind::NotFound | io::ErrorKind::NotADirectory => {
                let folder = folder_of(&path);
                if folder.is_file() {
                    ExportError::NotAFolder { path, folder }
                } else if !folder.exists() {
                    ExportError::MissingFolder { path, folder }
                } else {
                    ExportError::Io { path, source }
                }
            }
            _ => ExportError::Io { path, source },
        }
    }
}

/// The folder a file at `path` is written into (`.` for a bare file name).
pub(crate) fn folder_of(path: &std::path::Path) -> PathBuf {
    match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kind_error(kind: io::ErrorKind) -> ExportError {
        ExportError::from_io(PathBuf::from("/tmp/flower.glb"), io::Error::from(kind))
    }

    #[test]
    fn io_error_kinds_map_to_specific_variants() {
        assert!(matches!(
            kind_error(io::ErrorKind::PermissionDenied),
            ExportError::NotWritable { .. }
        ));
        assert!(matches!(
            kind_error(io::ErrorKind::ReadOnlyFilesystem),
            ExportError::NotWritable { .. }
        ));
        assert!(matches!(
            kind_error(io::ErrorKind::StorageFull),
            ExportError::DiskFull { .. }
        ));
        assert!(matches!(
            kind_error(io::ErrorKind::QuotaExceeded),
            ExportError::DiskFull { .. }
        ));
        assert!(matches!(
            kind_error(io::ErrorKind::IsADirectory),
            ExportError::IsAFolder { .. }
        ));
        assert!(matches!(
            kind_error(io::ErrorKind::Interrupted),
            ExportError::Io { .. }
        ));
    }

    #[test]
    fn enospc_from_the_os_reads_as_disk_full() {
        // ENOSPC as the kernel reports it (28 on Linux).
        let error = ExportError::from_io(
            PathBuf::from("/data/flower.glb"),
            io::Error::from_raw_os_error(28),
        );
        assert!(matches!(error, ExportError::DiskFull { .. }), "{error:?}");
        let message = error.to_string();
        assert!(message.contains("/data/flower.glb"), "{message}");
        assert!(message.contains("disk is full"), "{message}");
    }

    #[test]
    fn messages_name_the_path_and_folder() {
        let error = ExportError::MissingFolder {
            path: PathBuf::from("/nowhere/x/flower.glb"),
            folder: PathBuf::from("/nowhere/x"),
        };
        assert_eq!(
            error.to_string(),
            "cannot write /nowhere/x/flower.glb: the folder /nowhere/x does not exist"
        );
    }

    #[test]
    fn bare_file_names_live_in_the_current_folder() {
        assert_eq!(
            folder_of(std::path::Path::new("flower.glb")),
            PathBuf::from(".")
        );
        assert_eq!(
            folder_of(std::path::Path::new("a/flower.glb")),
            PathBuf::from("a")
        );
    }
}

//! Writing the files Anthesis saves so that nothing is lost: every project,
//! map, mesh, export, picture and statistics file goes through
//! [`write_atomic`].
//!
//! A write goes to a new temporary file in the destination folder, is
//! flushed to disk, and is then renamed over the destination. A crash, a
//! full disk or any other failure leaves the previous file untouched and
//! removes the temporary file. The temporary file is made by the `tempfile`
//! crate (unique name, removed on every error path).
//!
//! - A symbolic link at the destination is followed: the file it points to
//!   is replaced and the link stays a link.
//! - What is not ours to replace is never replaced: a character device or
//!   a named pipe (`/dev/stdout`, `/dev/null`, a terminal, `mkfifo`) is
//!   written to directly, as a shell redirection would; a block device or
//!   a socket is refused ([`WriteError::NotAFile`]). Renaming over them
//!   would put a plain file in their place (as root, `/dev/null` itself).
//! - A replaced file keeps its permissions; a new file gets the usual
//!   permissions for the user (`0o666` less the umask on Unix), as if
//!   created with [`std::fs::File::create`].
//! - Errors name the path and say what a user can do about it
//!   ([`WriteError`]).

use std::fs::{self, File};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// Why a file could not be written. Every message names the file.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// The folder the file should go in does not exist (it is not created
    /// here; the user picks an existing folder or [`create_folder`] makes it).
    #[error("cannot write {}: the folder {} does not exist", .path.display(), .folder.display())]
    MissingFolder {
        /// The file that was to be written.
        path: PathBuf,
        /// The folder that does not exist: the file's folder, or where it
        /// could be found, the outermost missing ancestor of it.
        folder: PathBuf,
    },
    /// A part of the path that must be a folder is a regular file.
    #[error("cannot write {}: {} is a file, not a folder", .path.display(), .folder.display())]
    NotAFolder {
        /// The file that was to be written.
        path: PathBuf,
        /// The ancestor of `path` that is a file where a folder should be.
        folder: PathBuf,
    },
    /// The destination is a folder, which is never replaced by a file.
    #[error("cannot write {}: a folder of that name exists", .path.display())]
    IsAFolder {
        /// The destination, an existing folder.
        path: PathBuf,
    },
    /// The destination is a block device or a socket, which is refused and
    /// left untouched (character devices and named pipes are written to).
    #[error("cannot write {}: it is {what}, not a file, and is left as it is", .path.display())]
    NotAFile {
        /// The destination.
        path: PathBuf,
        /// What it is instead, in words, e.g. "a socket".
        what: &'static str,
    },
    /// The user may not write there (permission denied or a read-only
    /// file system); another location is needed.
    #[error("cannot write {}: the location is not writable ({source})", .path.display())]
    NotWritable {
        /// The file that was to be written.
        path: PathBuf,
        /// The operating system's error.
        source: io::Error,
    },
    /// The disk is full or the user's quota is used up; the previous file,
    /// if any, is unchanged.
    #[error("cannot write {}: the disk is full or the quota is exceeded ({source})", .path.display())]
    DiskFull {
        /// The file that was to be written.
        path: PathBuf,
        /// The operating system's error.
        source: io::Error,
    },
    /// Any other I/O failure while writing; the previous file, if any, is
    /// unchanged.
    #[error("cannot write {}: {source}", .path.display())]
    Io {
        /// The file that was to be written.
        path: PathBuf,
        /// The operating system's error.
        source: io::Error,
    },
}

impl WriteError {
    /// The file that could not be written.
    pub fn path(&self) -> &Path {
        match self {
            WriteError::MissingFolder { path, .. }
            | WriteError::NotAFolder { path, .. }
            | WriteError::IsAFolder { path }
            | WriteError::NotAFile { path, .. }
            | WriteError::NotWritable { path, .. }
            | WriteError::DiskFull { path, .. }
            | WriteError::Io { path, .. } => path,
        }
    }

    /// Turns an I/O error met while writing `path` into the specific
    /// variant a user can act on.
    pub fn from_io(path: PathBuf, source: io::Error) -> Self {
        match source.kind() {
            io::ErrorKind::PermissionDenied | io::ErrorKind::ReadOnlyFilesystem => {
                WriteError::NotWritable { path, source }
            }
            io::ErrorKind::StorageFull | io::ErrorKind::QuotaExceeded => {
                WriteError::DiskFull { path, source }
            }
            io::ErrorKind::IsADirectory => WriteError::IsAFolder { path },
            io::ErrorKind::NotFound | io::ErrorKind::NotADirectory => {
                let folder = folder_of(&path);
                if folder.is_file() {
                    WriteError::NotAFolder { path, folder }
                } else if !folder.exists() {
                    WriteError::MissingFolder { path, folder }
                } else {
                    WriteError::Io { path, source }
                }
            }
            _ => WriteError::Io { path, source },
        }
    }
}

/// Errors are equal when they are the same variant about the same paths with
/// the same kind of I/O error (`io::Error` itself has no equality), so
/// callers can compare whole error values in tests.
impl PartialEq for WriteError {
    fn eq(&self, other: &Self) -> bool {
        use WriteError as E;
        match (self, other) {
            (E::MissingFolder { path: a, folder: f }, E::MissingFolder { path: b, folder: g })
            | (E::NotAFolder { path: a, folder: f }, E::NotAFolder { path: b, folder: g }) => {
                a == b && f == g
            }
            (E::IsAFolder { path: a }, E::IsAFolder { path: b }) => a == b,
            (E::NotAFile { path: a, what: w }, E::NotAFile { path: b, what: v }) => {
                a == b && w == v
            }
            (E::NotWritable { path: a, source: s }, E::NotWritable { path: b, source: t })
            | (E::DiskFull { path: a, source: s }, E::DiskFull { path: b, source: t })
            | (E::Io { path: a, source: s }, E::Io { path: b, source: t }) => {
                a == b && s.kind() == t.kind()
            }
            _ => false,
        }
    }
}

/// The folder a file at `path` is written into (`.` for a bare file name).
pub fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Writes `bytes` to `path` atomically: readers see either the old file or
/// the complete new one, never a partial file. The folder must exist (see
/// [`create_folder`]).
///
/// A character device or named pipe at `path` is written to directly and
/// a block device or socket refused (see the module documentation).
///
/// Errors name the path: [`WriteError::MissingFolder`],
/// [`WriteError::NotAFolder`] (a parent is a file),
/// [`WriteError::IsAFolder`], [`WriteError::NotAFile`] (a block device or
/// a socket), [`WriteError::NotWritable`] (permissions or
/// a read-only file system), [`WriteError::DiskFull`], or
/// [`WriteError::Io`] for anything else.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), WriteError> {
    write_atomic_with(path, |file| {
        file.write_all(bytes)?;
        file.flush()
    })
}

/// [`write_atomic`] with the contents produced by `write`, for writers that
/// stream into the file. An error from `write` is mapped like any other
/// I/O error and leaves the old file in place.
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut File) -> io::Result<()>,
) -> Result<(), WriteError> {
    let path = resolve_symlink(path);
    check_destination(&path)?;
    if is_stream(&path) {
        return write_stream(&path, write);
    }
    let folder = folder_of(&path);
    let mut temp = temp_file_beside(&path, &folder)?;

    // From here on, dropping `temp` on an error removes the temporary file.
    let written = write(temp.as_file_mut()).and_then(|()| temp.as_file().sync_all());
    if let Err(error) = written {
        return Err(WriteError::from_io(path, error));
    }
    if let Ok(meta) = fs::metadata(&path) {
        // Keep the mode of the file being replaced (best effort: the new
        // contents matter more than its mode).
        let _ = temp.as_file().set_permissions(meta.permissions());
    }
    temp.persist(&path)
        .map_err(|error| WriteError::from_io(path.clone(), error.error))?;
    // Make the rename itself durable where the platform allows it.
    if let Ok(dir) = File::open(&folder) {
        let _ = dir.sync_all();
    }
    Ok(())
}

/// Checks that a file could be created at `path`: its folder exists and is
/// a folder, and `path` is not itself a folder. For writers that do long
/// work before writing, so a typo in the folder is reported at once.
pub fn check_destination(path: &Path) -> Result<(), WriteError> {
    if path.file_name().is_none() {
        return Err(WriteError::Io {
            path: path.to_path_buf(),
            source: io::Error::new(io::ErrorKind::InvalidInput, "this is not a file name"),
        });
    }
    let folder = folder_of(path);
    match fs::metadata(&folder) {
        Ok(meta) if meta.is_dir() => {}
        Ok(_) => {
            return Err(WriteError::NotAFolder {
                path: path.to_path_buf(),
                folder,
            });
        }
        Err(error) => return Err(folder_error(path, &folder, error)),
    }
    if path.is_dir() {
        return Err(WriteError::IsAFolder {
            path: path.to_path_buf(),
        });
    }
    if let Some(what) = refused_kind(path) {
        return Err(WriteError::NotAFile {
            path: path.to_path_buf(),
            what,
        });
    }
    Ok(())
}

/// Whether `path` (links followed) is a character device or a named pipe,
/// which are written to rather than replaced.
#[cfg(unix)]
fn is_stream(path: &Path) -> bool {
    use std::os::unix::fs::FileTypeExt;
    fs::metadata(path).is_ok_and(|meta| {
        let kind = meta.file_type();
        kind.is_char_device() || kind.is_fifo()
    })
}

#[cfg(not(unix))]
fn is_stream(_path: &Path) -> bool {
    false
}

/// What `path` (links followed) is when it may be neither replaced nor
/// written to: a block device or a socket.
#[cfg(unix)]
fn refused_kind(path: &Path) -> Option<&'static str> {
    use std::os::unix::fs::FileTypeExt;
    let kind = fs::metadata(path).ok()?.file_type();
    if kind.is_block_device() {
        Some("a block device (a disk)")
    } else if kind.is_socket() {
        Some("a socket")
    } else {
        None
    }
}

#[cfg(not(unix))]
fn refused_kind(_path: &Path) -> Option<&'static str> {
    None
}

/// Writes to the device or pipe at `path` in place. Opening a pipe waits
/// for a reader, as a shell redirection does.
fn write_stream(
    path: &Path,
    write: impl FnOnce(&mut File) -> io::Result<()>,
) -> Result<(), WriteError> {
    let mut file = File::options()
        .write(true)
        .open(path)
        .map_err(|error| WriteError::from_io(path.to_path_buf(), error))?;
    write(&mut file)
        .and_then(|()| file.flush())
        .map_err(|error| WriteError::from_io(path.to_path_buf(), error))
}

/// Creates `folder` and its missing parents, as [`fs::create_dir_all`], with
/// the errors of [`write_atomic`] for `file`, the file to be written there
/// (a parent that is a file is [`WriteError::NotAFolder`] naming it).
pub fn create_folder(folder: &Path, file: &Path) -> Result<(), WriteError> {
    if folder.as_os_str().is_empty() || folder.is_dir() {
        return Ok(());
    }
    if let Some(blocker) = folder.ancestors().find(|a| a.is_file()) {
        return Err(WriteError::NotAFolder {
            path: file.to_path_buf(),
            folder: blocker.to_path_buf(),
        });
    }
    fs::create_dir_all(folder).map_err(|error| WriteError::from_io(file.to_path_buf(), error))
}

/// Names the first ancestor of `folder` that is missing or is a file.
fn folder_error(path: &Path, folder: &Path, error: io::Error) -> WriteError {
    match error.kind() {
        io::ErrorKind::NotFound | io::ErrorKind::NotADirectory => {
            // Walk up to the nearest ancestor that exists to say precisely
            // which folder is missing or which "folder" is really a file.
            let mut missing = folder.to_path_buf();
            for ancestor in folder.ancestors() {
                if ancestor.as_os_str().is_empty() {
                    break;
                }
                match fs::metadata(ancestor) {
                    Ok(meta) if meta.is_dir() => break,
                    Ok(_) => {
                        return WriteError::NotAFolder {
                            path: path.to_path_buf(),
                            folder: ancestor.to_path_buf(),
                        };
                    }
                    Err(_) => missing = ancestor.to_path_buf(),
                }
            }
            WriteError::MissingFolder {
                path: path.to_path_buf(),
                folder: missing,
            }
        }
        _ => WriteError::from_io(path.to_path_buf(), error),
    }
}

/// The file a symbolic link at `path` points to (so the rename replaces the
/// target and leaves the link), or `path` itself.
fn resolve_symlink(path: &Path) -> PathBuf {
    match fs::symlink_metadata(path) {
        Ok(meta) if meta.file_type().is_symlink() => {
            fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
        }
        _ => path.to_path_buf(),
    }
}

/// A new, uniquely named hidden file next to `path`: `.NAME.XXXXXX.tmp`.
fn temp_file_beside(path: &Path, folder: &Path) -> Result<tempfile::NamedTempFile, WriteError> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let prefix = format!(".{name}.");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    // tempfile makes private (0o600) files by default; a saved project is
    // an ordinary file, so ask for what `File::create` gives (the umask
    // still applies).
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(fs::Permissions::from_mode(0o666));
    }
    builder
        .tempfile_in(folder)
        .map_err(|error| WriteError::from_io(path.to_path_buf(), without_temp_path(error)))
}

/// tempfile's errors end in `at path ".NAME.XXXXXX.tmp"`, a file that was
/// never made and that the user never named: keep the system's own words
/// (and the error's kind).
fn without_temp_path(error: io::Error) -> io::Error {
    let text = error.to_string();
    match text.rfind(" at path \"") {
        Some(end) if error.get_ref().is_some() => io::Error::new(error.kind(), &text[..end]),
        _ => error,
    }
}

#[cfg(test)]
mod tests;

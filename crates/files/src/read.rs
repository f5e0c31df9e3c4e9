//! Reading files that may come from someone else: a project shared as an
//! archive, a mesh or a map downloaded from the web.
//!
//! - [`read_regular`] reads only regular files (a named pipe would block
//!   forever, `/dev/zero` never ends) and never more than a stated number of
//!   bytes, checked before and while reading.
//! - [`resolve_inside`] turns a path written in a project file into a path
//!   that stays inside the project's folder, after `..` and symbolic links
//!   are resolved, or says why it does not.
//! - [`excerpt`] is what an error message may show of a file's content: a
//!   short, escaped piece.
//!
//! Errors say what is wrong without the path; the caller's error names the
//! file, once.
//!
//! Hand-written rather than through a capability file-system crate
//! (`cap-std`): the threat is a file that names another file, not a local
//! attacker racing the loader, and `canonicalize` plus a prefix check answers
//! it in a few lines that say in words why a path was refused.

use std::fs::{self, File, Metadata};
use std::io::{self, Read};
use std::path::{Component, Path, PathBuf};

/// Why a file was not read. The messages leave the path to the caller.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    /// Nothing exists at the path (or a folder on the way is missing).
    #[error("it does not exist")]
    NotFound,
    /// The path is a folder, a named pipe, a device or a socket; it was
    /// not opened (reading a pipe could block forever).
    #[error("it is {kind}, not a regular file; only regular files are read")]
    NotARegularFile {
        /// What it is instead, e.g. "a named pipe (FIFO)".
        kind: &'static str,
    },
    /// The file is larger than the caller's limit for its kind; it was not
    /// read (or reading stopped at the limit).
    #[error(
        "it is {} ({size} bytes), more than the limit of {} for {what}",
        human_bytes(*size),
        human_bytes(*limit)
    )]
    TooLarge {
        /// Its size, or for a file that grew while being read, a lower bound.
        size: u64,
        /// The most bytes the caller accepts for this kind of file.
        limit: u64,
        /// What kind of file the limit is for, e.g. "an OBJ mesh".
        what: &'static str,
    },
    /// The operating system could not read the file (permissions, an I/O
    /// failure) or its text is not UTF-8; holds the underlying error.
    #[error("cannot read it: {0}")]
    Io(io::Error),
    /// A project file names a file with an empty path.
    #[error("the path is empty")]
    EmptyPath,
    /// A project file names a file by an absolute path; paths in a project
    /// are relative to its folder so the project can be moved and shared.
    #[error(
        "the path is absolute; files named in a project must be given relative to the \
         project's folder"
    )]
    Absolute,
    /// A path's `..` components climb above the project's folder.
    #[error("the path leaves the project's folder through `..`")]
    ClimbsOut,
    /// A path stays inside the project's folder as written, but a symbolic
    /// link on the way leads outside it.
    #[error(
        "the path leads outside the project's folder through a symbolic link; files named \
         in a project must lie inside its folder"
    )]
    LinksOut,
}

impl FileError {
    fn from_io(error: io::Error) -> FileError {
        match error.kind() {
            io::ErrorKind::NotFound => FileError::NotFound,
            _ => FileError::Io(error),
        }
    }
}

/// Reads the whole file at `path` if it is a regular file (a symbolic link
/// to one is followed) of at most `limit` bytes. `what` names the kind of
/// file in the size message, e.g. "an OBJ mesh".
///
/// Named pipes, devices, sockets and folders are refused before they are
/// opened, so reading never blocks on a pipe nor runs on forever. The file
/// is opened non-blocking and checked again once open (it may have been
/// swapped meanwhile), and no more than `limit + 1` bytes are read whatever
/// its size claims (files in `/proc` claim 0).
pub fn read_regular(path: &Path, limit: u64, what: &'static str) -> Result<Vec<u8>, FileError> {
    let before = fs::metadata(path).map_err(FileError::from_io)?;
    check_regular(&before)?;
    check_size(before.len(), limit, what)?;
    let file = open_non_blocking(path).map_err(FileError::from_io)?;
    let opened = file.metadata().map_err(FileError::from_io)?;
    check_regular(&opened)?;
    check_size(opened.len(), limit, what)?;
    let expected = usize::try_from(opened.len()).unwrap_or(usize::MAX);
    let mut bytes = Vec::with_capacity(expected);
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(FileError::from_io)?;
    check_size(bytes.len() as u64, limit, what)?;
    Ok(bytes)
}

/// [`read_regular`] of text: the bytes must be UTF-8 (a leading byte-order
/// mark is kept; parsers skip it).
pub fn read_regular_text(path: &Path, limit: u64, what: &'static str) -> Result<String, FileError> {
    let bytes = read_regular(path, limit, what)?;
    String::from_utf8(bytes).map_err(|error| {
        FileError::Io(io::Error::new(
            io::ErrorKind::InvalidData,
            format!(
                "it is not UTF-8 text (byte {} is not part of a character)",
                error.utf8_error().valid_up_to() + 1
            ),
        ))
    })
}

#[cfg(unix)]
fn open_non_blocking(path: &Path) -> io::Result<File> {
    use std::os::unix::fs::OpenOptionsExt;
    // Opening a named pipe for reading blocks until a writer comes; with
    // O_NONBLOCK it returns at once (and the kind check then refuses it).
    // For a regular file the flag changes nothing.
    File::options()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
}

#[cfg(not(unix))]
fn open_non_blocking(path: &Path) -> io::Result<File> {
    File::open(path)
}

fn check_size(size: u64, limit: u64, what: &'static str) -> Result<(), FileError> {
    if size > limit {
        Err(FileError::TooLarge { size, limit, what })
    } else {
        Ok(())
    }
}

fn check_regular(meta: &Metadata) -> Result<(), FileError> {
    if meta.is_file() {
        Ok(())
    } else {
        Err(FileError::NotARegularFile {
            kind: kind_of(meta),
        })
    }
}

/// What a file that is not a regular file is, in words.
fn kind_of(meta: &Metadata) -> &'static str {
    if meta.is_dir() {
        return "a folder";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let kind = meta.file_type();
        if kind.is_fifo() {
            return "a named pipe (FIFO)";
        }
        if kind.is_char_device() {
            return "a character device (like /dev/zero)";
        }
        if kind.is_block_device() {
            return "a block device (a disk)";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    "a special file"
}

/// The file that `relative`, as written in a project file, names inside
/// `folder`: an existing path inside `folder` once `..` and symbolic links
/// are resolved.
///
/// Refused: an empty path ([`FileError::EmptyPath`]), an absolute one
/// ([`FileError::Absolute`]), one whose `..` climb above `folder`
/// ([`FileError::ClimbsOut`]), one that resolves outside `folder` through
/// a symbolic link ([`FileError::LinksOut`]); a path that does not exist is
/// [`FileError::NotFound`]. `meshes/../maps/a.png` is fine. A `\` is a
/// separator as on Windows (`maps\a.png`, as a project written by hand
/// there names its files; elsewhere it was looked for as one file name and
/// not found), and the rules above apply to the path with `/`.
pub fn resolve_inside(folder: &Path, relative: &str) -> Result<PathBuf, FileError> {
    let relative = relative.replace('\\', "/");
    let path = Path::new(&relative);
    check_relative(path)?;
    let folder = if folder.as_os_str().is_empty() {
        Path::new(".")
    } else {
        folder
    };
    let real_folder = fs::canonicalize(folder).map_err(FileError::from_io)?;
    let real_path = fs::canonicalize(folder.join(path)).map_err(FileError::from_io)?;
    if real_path.starts_with(&real_folder) {
        Ok(real_path)
    } else {
        Err(FileError::LinksOut)
    }
}

/// The checks of [`resolve_inside`] that need no file system: not empty,
/// not absolute, and no `..` that climbs above the folder the path starts
/// in. For projects that are not on disk.
pub fn check_relative(path: &Path) -> Result<(), FileError> {
    if path.as_os_str().is_empty() {
        return Err(FileError::EmptyPath);
    }
    let mut depth: i64 = 0;
    for component in path.components() {
        match component {
            Component::Prefix(_) | Component::RootDir => return Err(FileError::Absolute),
            Component::CurDir => {}
            Component::ParentDir => {
                depth -= 1;
                if depth < 0 {
                    return Err(FileError::ClimbsOut);
                }
            }
            Component::Normal(_) => depth += 1,
        }
    }
    Ok(())
}

/// At most `max_chars` characters of `text` for an error message, with
/// control characters escaped (`\n`, `\u{1b}`: a file cannot move the
/// terminal's cursor or colour its text) and `…` where it was cut: what a
/// message may show of a file's content.
pub fn excerpt(text: &str, max_chars: usize) -> String {
    let mut shown = String::new();
    for (count, c) in text.chars().enumerate() {
        if count == max_chars {
            shown.push('…');
            break;
        }
        if c.is_control() {
            shown.extend(c.escape_default());
        } else {
            shown.push(c);
        }
    }
    shown
}

/// A number as a message may show it: as Rust writes it when that is short
/// (`0.06`, `-5`, `NaN`), in exponent form when not (`1e-320` written out
/// is 322 characters).
pub fn short_number(value: f64) -> String {
    let plain = value.to_string();
    if plain.len() <= 24 {
        plain
    } else {
        format!("{value:e}")
    }
}

/// A byte count in words: "512 bytes", "1.5 KiB", "256 MiB", "8.0 GiB".
pub fn human_bytes(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["KiB", "MiB", "GiB", "TiB", "PiB"];
    if bytes < 1024 {
        return format!("{bytes} bytes");
    }
    let mut value = bytes as f64 / 1024.0;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if value.fract() == 0.0 || value >= 100.0 {
        format!("{value:.0} {}", UNITS[unit])
    } else {
        format!("{value:.1} {}", UNITS[unit])
    }
}

#[cfg(test)]
mod tests;

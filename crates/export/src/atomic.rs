//! Atomic file writes: write a temporary file in the destination folder,
//! flush it to disk, then rename it over the destination. A crash, a full
//! disk or any other failure leaves the previous file untouched and removes
//! the temporary file.

use std::fs::{self, File};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{ExportError, folder_of};

/// Writes `bytes` to `path` atomically: readers see either the old file or
/// the complete new one, never a partial file. The folder must exist.
///
/// Errors name the path: [`ExportError::MissingFolder`],
/// [`ExportError::NotAFolder`] (a parent is a file),
/// [`ExportError::IsAFolder`], [`ExportError::NotWritable`] (permissions or
/// a read-only file system), [`ExportError::DiskFull`], or
/// [`ExportError::Io`] for anything else.
///
/// A symbolic link at `path` is followed: its target is replaced. The
/// permissions of a replaced file are kept.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), ExportError> {
    write_atomic_with(path, |file| write_contents(file, bytes))
}

fn write_contents(file: &mut File, bytes: &[u8]) -> io::Result<()> {
    file.write_all(bytes)?;
    file.flush()
}

/// Checks that a file could be created at `path`: its folder exists and is
/// a folder, and `path` is not itself a folder.
pub(crate) fn check_destination(path: &Path) -> Result<(), ExportError> {
    if path.file_name().is_none() {
        return Err(ExportError::Io {
            path: path.to_path_buf(),
            source: io::Error::new(io::ErrorKind::InvalidInput, "this is not a file name"),
        });
    }
    let folder = folder_of(path);
    match fs::metadata(&folder) {
        Ok(meta) if meta.is_dir() => {}
        Ok(_) => {
            return Err(ExportError::NotAFolder {
                path: path.to_path_buf(),
                folder,
            });
        }
        Err(error) => return Err(folder_error(path, &folder, error)),
    }
    if path.is_dir() {
        return Err(ExportError::IsAFolder {
            path: path.to_path_buf(),
        });
    }
    Ok(())
}

/// Names the first ancestor of `folder` that is missing or is a file.
fn folder_error(path: &Path, folder: &Path, error: io::Error) -> ExportError {
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
                        return ExportError::NotAFolder {
                            path: path.to_path_buf(),
                            folder: ancestor.to_path_buf(),
                        };
                    }
                    Err(_) => missing = ancestor.to_path_buf(),
                }
            }
            ExportError::MissingFolder {
                path: path.to_path_buf(),
                folder: missing,
            }
        }
        _ => ExportError::from_io(path.to_path_buf(), error),
    }
}

/// The atomic write with the file contents produced by `write`; errors of
/// `write` are mapped like any other I/O error and roll the write back.
pub(crate) fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut File) -> io::Result<()>,
) -> Result<(), ExportError> {
    let path = resolve_symlink(path);
    check_destination(&path)?;
    let folder = folder_of(&path);
    let (temp_path, mut file) = create_temp(&path, &folder)?;

    let written = write(&mut file).and_then(|()| file.sync_all());
    if let Err(error) = written {
        drop(file);
        let _ = fs::remove_file(&temp_path);
        return Err(ExportError::from_io(path, error));
    }
    if let Ok(meta) = fs::metadata(&path) {
        // Keep the mode of the file being replaced (best effort).
        let _ = file.set_permissions(meta.permissions());
    }
    drop(file);

    if let Err(error) = fs::rename(&temp_path, &path) {
        let _ = fs::remove_file(&temp_path);
        return Err(ExportError::from_io(path, error));
    }
    // Make the rename itself durable where the platform allows it.
    if let Ok(dir) = File::open(&folder) {
        let _ = dir.sync_all();
    }
    Ok(())
}

fn resolve_symlink(path: &Path) -> PathBuf {
    match fs::symlink_metadata(path) {
        Ok(meta) if meta.file_type().is_symlink() => {
            fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
        }
        _ => path.to_path_buf(),
    }
}

/// Creates a new, uniquely named hidden file next to `path`.
fn create_temp(path: &Path, folder: &Path) -> Result<(PathBuf, File), ExportError> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut last_error = None;
    for _ in 0..64 {
        let serial = COUNTER.fetch_add(1, Ordering::Relaxed);
        let temp_path = folder.join(format!(".{name}.{}-{serial}.tmp", std::process::id()));
        match File::options()
            .write(true)
            .create_new(true)
            .open(&temp_path)
        {
            Ok(file) => return Ok((temp_path, file)),
            Err(error) if error.kind() == io::ErrorKind::AlreadyExists => {
                last_error = Some(error);
            }
            Err(error) => return Err(ExportError::from_io(path.to_path_buf(), error)),
        }
    }
    Err(ExportError::Io {
        path: path.to_path_buf(),
        source: last_error
            .unwrap_or_else(|| io::Error::other("no free temporary file name next to it")),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn leftover_temp_files(dir: &Path) -> Vec<PathBuf> {
        fs::read_dir(dir)
            .expect("read dir")
            .map(|e| e.expect("entry").path())
            .filter(|p| p.extension().is_some_and(|e| e == "tmp"))
            .collect()
    }

    #[test]
    fn writes_and_replaces_a_file() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("flower.glb");
        write_atomic(&path, b"first").expect("first write");
        assert_eq!(fs::read(&path).expect("read"), b"first");
        write_atomic(&path, b"second, longer").expect("second write");
        assert_eq!(fs::read(&path).expect("read"), b"second, longer");
        assert!(leftover_temp_files(dir.path()).is_empty());
    }

    #[test]
    fn a_failed_write_keeps_the_old_file_and_removes_the_temporary() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("project.toml");
        write_atomic(&path, b"good project").expect("write");
        let error = write_atomic_with(&path, |file| {
            // Half the new contents reach the temporary file, then the disk
            // fills up (ENOSPC as the kernel reports it).
            file.write_all(b"half of the new")?;
            Err(io::Error::from_raw_os_error(28))
        })
        .expect_err("the write must fail");
        assert!(matches!(error, ExportError::DiskFull { .. }), "{error:?}");
        assert_eq!(fs::read(&path).expect("read"), b"good project");
        assert!(leftover_temp_files(dir.path()).is_empty());
    }

    #[test]
    fn writing_to_dev_full_is_reported_as_a_full_disk() {
        // /dev/full fails every write with ENOSPC: the real kernel error goes
        // through the same mapping as a write to a full file system.
        let mut full = File::options()
            .write(true)
            .open("/dev/full")
            .expect("/dev/full exists on Linux");
        let io_error = write_contents(&mut full, &[0u8; 4096]).expect_err("/dev/full is full");
        let error = ExportError::from_io(PathBuf::from("/data/flower.glb"), io_error);
        assert!(matches!(error, ExportError::DiskFull { .. }), "{error:?}");
        assert!(error.to_string().contains("disk is full"), "{error}");
    }

    #[test]
    fn missing_folder_names_the_first_missing_folder() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("no/such/flower.glb");
        let error = write_atomic(&path, b"x").expect_err("must fail");
        match &error {
            ExportError::MissingFolder { path: p, folder } => {
                assert_eq!(p, &path);
                assert_eq!(folder, &dir.path().join("no"));
            }
            other => panic!("expected MissingFolder, got {other:?}"),
        }
        assert!(error.to_string().contains("does not exist"), "{error}");
        assert!(!dir.path().join("no").exists());
    }

    #[test]
    fn a_file_in_place_of_a_folder_is_named() {
        let dir = tempfile::tempdir().expect("tempdir");
        let file = dir.path().join("notes.txt");
        fs::write(&file, b"x").expect("write");
        let error = write_atomic(&file.join("sub/flower.glb"), b"x").expect_err("must fail");
        match &error {
            ExportError::NotAFolder { folder, .. } => assert_eq!(folder, &file),
            other => panic!("expected NotAFolder, got {other:?}"),
        }
        assert!(error.to_string().contains("is a file, not a folder"));
    }

    #[test]
    fn a_folder_in_place_of_the_file_is_refused() {
        let dir = tempfile::tempdir().expect("tempdir");
        let error = write_atomic(dir.path(), b"x").expect_err("must fail");
        assert!(matches!(error, ExportError::IsAFolder { .. }), "{error:?}");
    }

    #[test]
    fn an_unwritable_location_is_reported_as_not_writable() {
        // Tests run as root, for whom permission bits do not apply; sysfs
        // refuses to create files for everyone (EACCES, or EROFS where it is
        // mounted read-only).
        let error = write_atomic(Path::new("/sys/anthesis-flower.glb"), b"x")
            .expect_err("sysfs takes no new files");
        assert!(
            matches!(error, ExportError::NotWritable { .. }),
            "{error:?}"
        );
        let message = error.to_string();
        assert!(message.contains("/sys/anthesis-flower.glb"), "{message}");
        assert!(message.contains("not writable"), "{message}");
    }

    #[cfg(unix)]
    #[test]
    fn permissions_of_a_replaced_file_are_kept() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("flower.glb");
        fs::write(&path, b"old").expect("write");
        fs::set_permissions(&path, fs::Permissions::from_mode(0o640)).expect("chmod");
        write_atomic(&path, b"new").expect("write");
        let mode = fs::metadata(&path).expect("meta").permissions().mode() & 0o777;
        assert_eq!(mode, 0o640);
    }

    #[cfg(unix)]
    #[test]
    fn a_symlink_is_followed_and_kept() {
        let dir = tempfile::tempdir().expect("tempdir");
        let target = dir.path().join("real.glb");
        let link = dir.path().join("link.glb");
        fs::write(&target, b"old").expect("write");
        std::os::unix::fs::symlink(&target, &link).expect("symlink");
        write_atomic(&link, b"new").expect("write");
        assert!(
            fs::symlink_metadata(&link)
                .expect("meta")
                .file_type()
                .is_symlink()
        );
        assert_eq!(fs::read(&target).expect("read"), b"new");
    }
}

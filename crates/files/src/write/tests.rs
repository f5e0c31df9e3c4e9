use std::fs::{self, File};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

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
    assert!(matches!(error, WriteError::DiskFull { .. }), "{error:?}");
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
    let io_error = full
        .write_all(&[0u8; 4096])
        .and_then(|()| full.flush())
        .expect_err("/dev/full is full");
    let error = WriteError::from_io(PathBuf::from("/data/flower.glb"), io_error);
    assert!(matches!(error, WriteError::DiskFull { .. }), "{error:?}");
    assert!(error.to_string().contains("disk is full"), "{error}");
}

#[test]
fn missing_folder_names_the_first_missing_folder() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("no/such/flower.glb");
    let error = write_atomic(&path, b"x").expect_err("must fail");
    match &error {
        WriteError::MissingFolder { path: p, folder } => {
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
        WriteError::NotAFolder { folder, .. } => assert_eq!(folder, &file),
        other => panic!("expected NotAFolder, got {other:?}"),
    }
    assert!(error.to_string().contains("is a file, not a folder"));
}

#[test]
fn a_folder_in_place_of_the_file_is_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let error = write_atomic(dir.path(), b"x").expect_err("must fail");
    assert!(matches!(error, WriteError::IsAFolder { .. }), "{error:?}");
}

#[test]
fn an_unwritable_location_is_reported_as_not_writable() {
    // Tests run as root, for whom permission bits do not apply; sysfs
    // refuses to create files for everyone (EACCES, or EROFS where it is
    // mounted read-only).
    let error = write_atomic(Path::new("/sys/anthesis-flower.glb"), b"x")
        .expect_err("sysfs takes no new files");
    assert!(matches!(error, WriteError::NotWritable { .. }), "{error:?}");
    let message = error.to_string();
    assert!(message.contains("/sys/anthesis-flower.glb"), "{message}");
    assert!(message.contains("not writable"), "{message}");
}

#[test]
fn io_error_kinds_map_to_specific_variants() {
    let kind_error =
        |kind: io::ErrorKind| WriteError::from_io(PathBuf::from("/tmp/f.glb"), kind.into());
    use io::ErrorKind as K;
    assert!(matches!(
        kind_error(K::PermissionDenied),
        WriteError::NotWritable { .. }
    ));
    assert!(matches!(
        kind_error(K::ReadOnlyFilesystem),
        WriteError::NotWritable { .. }
    ));
    assert!(matches!(
        kind_error(K::StorageFull),
        WriteError::DiskFull { .. }
    ));
    assert!(matches!(
        kind_error(K::QuotaExceeded),
        WriteError::DiskFull { .. }
    ));
    assert!(matches!(
        kind_error(K::IsADirectory),
        WriteError::IsAFolder { .. }
    ));
    assert!(matches!(kind_error(K::Interrupted), WriteError::Io { .. }));
}

#[test]
fn messages_name_the_path_and_folder() {
    let error = WriteError::MissingFolder {
        path: PathBuf::from("/nowhere/x/flower.glb"),
        folder: PathBuf::from("/nowhere/x"),
    };
    assert_eq!(
        error.to_string(),
        "cannot write /nowhere/x/flower.glb: the folder /nowhere/x does not exist"
    );
    assert_eq!(error.path(), Path::new("/nowhere/x/flower.glb"));
}

#[test]
fn errors_compare_by_variant_path_and_kind() {
    let denied =
        |path: &str| WriteError::from_io(path.into(), io::ErrorKind::PermissionDenied.into());
    assert_eq!(denied("/a"), denied("/a"));
    assert_ne!(denied("/a"), denied("/b"));
    assert_ne!(
        denied("/a"),
        WriteError::from_io("/a".into(), io::ErrorKind::Interrupted.into())
    );
    assert_ne!(
        WriteError::IsAFolder { path: "/a".into() },
        WriteError::MissingFolder {
            path: "/a".into(),
            folder: "/".into()
        }
    );
}

#[test]
fn bare_file_names_live_in_the_current_folder() {
    assert_eq!(folder_of(Path::new("flower.glb")), PathBuf::from("."));
    assert_eq!(folder_of(Path::new("a/flower.glb")), PathBuf::from("a"));
}

#[test]
fn create_folder_makes_missing_parents_and_names_a_file_in_the_way() {
    let dir = tempfile::tempdir().expect("tempdir");
    let folder = dir.path().join("lily/maps");
    let file = folder.join("petal.png");
    create_folder(&folder, &file).expect("create");
    assert!(folder.is_dir());
    create_folder(&folder, &file).expect("an existing folder is fine");

    let blocker = dir.path().join("blocker");
    fs::write(&blocker, b"a file, not a folder").expect("write");
    let file = blocker.join("maps/a.png");
    let error = create_folder(&blocker.join("maps"), &file).expect_err("blocked");
    match &error {
        WriteError::NotAFolder { path, folder } => {
            assert_eq!(path, &file);
            assert_eq!(folder, &blocker);
        }
        other => panic!("expected NotAFolder, got {other:?}"),
    }
}

#[cfg(unix)]
mod unix {
    use std::os::unix::fs::{PermissionsExt, symlink};

    use super::*;

    fn mode(path: &Path) -> u32 {
        fs::metadata(path).expect("meta").permissions().mode() & 0o777
    }

    #[test]
    fn permissions_of_a_replaced_file_are_kept() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("flower.glb");
        for kept in [0o640, 0o600, 0o666, 0o444] {
            fs::write(&path, b"old").expect("write");
            fs::set_permissions(&path, fs::Permissions::from_mode(kept)).expect("chmod");
            write_atomic(&path, b"new").expect("write");
            assert_eq!(mode(&path), kept, "mode {kept:o}");
            assert_eq!(fs::read(&path).expect("read"), b"new");
            fs::set_permissions(&path, fs::Permissions::from_mode(0o644)).expect("chmod");
            fs::remove_file(&path).expect("remove");
        }
    }

    #[test]
    fn a_new_file_gets_the_permissions_file_create_gives() {
        // Not tempfile's private 0o600: what File::create makes under the
        // same umask.
        let dir = tempfile::tempdir().expect("tempdir");
        let reference = dir.path().join("reference");
        File::create(&reference).expect("create");
        let path = dir.path().join("new.toml");
        write_atomic(&path, b"x").expect("write");
        assert_eq!(mode(&path), mode(&reference));
    }

    #[test]
    fn a_symlink_is_followed_and_kept() {
        let dir = tempfile::tempdir().expect("tempdir");
        let target = dir.path().join("real.glb");
        let link = dir.path().join("link.glb");
        fs::write(&target, b"old").expect("write");
        fs::set_permissions(&target, fs::Permissions::from_mode(0o640)).expect("chmod");
        symlink(&target, &link).expect("symlink");
        write_atomic(&link, b"new").expect("write");
        let link_meta = fs::symlink_metadata(&link).expect("meta");
        assert!(link_meta.file_type().is_symlink(), "the link stays a link");
        assert_eq!(fs::read_link(&link).expect("read link"), target);
        assert_eq!(fs::read(&target).expect("read"), b"new");
        assert_eq!(mode(&target), 0o640, "the target keeps its mode");
        assert!(leftover_temp_files(dir.path()).is_empty());
    }

    #[test]
    fn a_relative_symlink_into_another_folder_replaces_its_target_there() {
        let dir = tempfile::tempdir().expect("tempdir");
        fs::create_dir(dir.path().join("real")).expect("mkdir");
        fs::create_dir(dir.path().join("links")).expect("mkdir");
        let target = dir.path().join("real/flower.toml");
        fs::write(&target, b"old").expect("write");
        let link = dir.path().join("links/flower.toml");
        symlink("../real/flower.toml", &link).expect("symlink");
        write_atomic(&link, b"new").expect("write");
        assert_eq!(fs::read(&target).expect("read"), b"new");
        assert!(
            fs::symlink_metadata(&link)
                .expect("meta")
                .file_type()
                .is_symlink()
        );
        // The temporary file was made beside the target (same file system
        // for the rename), and removed.
        assert!(leftover_temp_files(&dir.path().join("real")).is_empty());
        assert!(leftover_temp_files(&dir.path().join("links")).is_empty());
    }

    #[test]
    fn a_dangling_symlink_is_replaced_by_the_file() {
        // canonicalize fails on a link to nothing: the link itself is
        // replaced by the new file rather than refusing to save.
        let dir = tempfile::tempdir().expect("tempdir");
        let link = dir.path().join("link.toml");
        symlink(dir.path().join("gone.toml"), &link).expect("symlink");
        write_atomic(&link, b"new").expect("write");
        assert_eq!(fs::read(&link).expect("read"), b"new");
    }

    /// Makes a device node or named pipe at `path` with the system's
    /// `mknod` (`kind` is `c`, `b` or `p`; devices need root, as CI runs).
    fn mknod(path: &Path, args: &[&str]) {
        let status = std::process::Command::new("mknod")
            .arg(path)
            .args(args)
            .status()
            .expect("mknod runs");
        assert!(status.success(), "mknod {} {args:?}", path.display());
    }

    fn file_type(path: &Path) -> fs::FileType {
        fs::symlink_metadata(path).expect("meta").file_type()
    }

    #[test]
    fn a_character_device_is_written_to_and_stays_a_device() {
        use std::os::unix::fs::FileTypeExt;
        // The null device (1, 3) made in a temporary folder, as /dev/null.
        let dir = tempfile::tempdir().expect("tempdir");
        let device = dir.path().join("null");
        mknod(&device, &["c", "1", "3"]);
        write_atomic(&device, b"statistics").expect("written to the device");
        assert!(file_type(&device).is_char_device(), "not replaced");
        // Through a link, as /dev/stdout is one: the link stays a link and
        // the device a device.
        let link = dir.path().join("stats.json");
        symlink(&device, &link).expect("symlink");
        write_atomic(&link, b"statistics").expect("written through the link");
        assert!(file_type(&link).is_symlink());
        assert!(file_type(&device).is_char_device());
        assert!(leftover_temp_files(dir.path()).is_empty());
    }

    #[test]
    fn a_named_pipe_is_written_to_and_stays_a_pipe() {
        use std::os::unix::fs::FileTypeExt;
        let dir = tempfile::tempdir().expect("tempdir");
        let pipe = dir.path().join("pipe");
        mknod(&pipe, &["p"]);
        let reader = {
            let pipe = pipe.clone();
            std::thread::Builder::new()
                .name("pipe reader".into())
                .spawn(move || fs::read(&pipe).expect("read the pipe"))
                .expect("spawn")
        };
        write_atomic(&pipe, b"through the pipe").expect("written to the pipe");
        assert_eq!(reader.join().expect("reader"), b"through the pipe");
        assert!(file_type(&pipe).is_fifo(), "not replaced");
        assert!(leftover_temp_files(dir.path()).is_empty());
    }

    #[test]
    fn a_block_device_or_socket_is_refused_and_left_alone() {
        use std::os::unix::fs::FileTypeExt;
        let dir = tempfile::tempdir().expect("tempdir");
        // A loop device node (7, 0): refused before it is opened.
        let disk = dir.path().join("disk");
        mknod(&disk, &["b", "7", "0"]);
        let error = write_atomic(&disk, b"x").expect_err("a disk is refused");
        assert_eq!(
            error,
            WriteError::NotAFile {
                path: disk.clone(),
                what: "a block device (a disk)"
            }
        );
        assert_eq!(
            error.to_string(),
            format!(
                "cannot write {}: it is a block device (a disk), not a file, and is left as it is",
                disk.display()
            )
        );
        assert!(file_type(&disk).is_block_device());
        assert_eq!(check_destination(&disk), Err(error));

        let socket_path = dir.path().join("socket");
        let _socket = std::os::unix::net::UnixListener::bind(&socket_path).expect("bind a socket");
        let error = write_atomic(&socket_path, b"x").expect_err("a socket is refused");
        assert!(matches!(
            error,
            WriteError::NotAFile {
                what: "a socket",
                ..
            }
        ));
        assert!(file_type(&socket_path).is_socket());
        assert!(leftover_temp_files(dir.path()).is_empty());
    }
}

#[test]
fn a_folder_that_takes_no_new_files_is_named_without_the_temporary_file() {
    // /proc exists but no file can be made in it.
    let error = write_atomic(Path::new("/proc/x.glb"), b"data").expect_err("refused");
    let message = error.to_string();
    assert!(
        message.starts_with("cannot write /proc/x.glb: "),
        "{message}"
    );
    assert!(!message.contains(".tmp"), "{message}");
    assert!(message.contains("os error"), "{message}");
}

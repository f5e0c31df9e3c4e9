use std::process::Command;
use std::time::{Duration, Instant};

use super::*;

/// Makes a named pipe at `path` with the system's `mkfifo`.
fn mkfifo(path: &Path) {
    let status = Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo runs");
    assert!(status.success(), "mkfifo {}", path.display());
}

#[test]
fn reads_a_regular_file_and_follows_a_link_to_one() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("petal.obj");
    fs::write(&path, b"v 0 0 0\n").expect("write");
    assert_eq!(
        read_regular(&path, 100, "a mesh").expect("reads"),
        b"v 0 0 0\n"
    );
    let link = dir.path().join("link.obj");
    std::os::unix::fs::symlink(&path, &link).expect("symlink");
    assert_eq!(
        read_regular(&link, 100, "a mesh").expect("reads"),
        b"v 0 0 0\n"
    );
}

#[test]
fn a_file_over_the_limit_is_refused_with_its_size_and_the_limit() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("big.png");
    fs::write(&path, vec![7u8; 1536]).expect("write");
    assert_eq!(
        read_regular(&path, 1536, "a map")
            .expect("at the limit")
            .len(),
        1536
    );
    let error = read_regular(&path, 1024, "a map").expect_err("over the limit");
    assert!(
        matches!(
            error,
            FileError::TooLarge {
                size: 1536,
                limit: 1024,
                what: "a map"
            }
        ),
        "{error:?}"
    );
    assert_eq!(
        error.to_string(),
        "it is 1.5 KiB (1536 bytes), more than the limit of 1 KiB for a map"
    );
}

#[test]
fn a_file_that_claims_no_size_is_still_cut_at_the_limit() {
    // /proc files report a length of 0 but have content.
    let bytes = read_regular(Path::new("/proc/self/status"), 1 << 20, "text").expect("reads");
    assert!(!bytes.is_empty());
    let error = read_regular(Path::new("/proc/self/status"), 10, "text").expect_err("cut");
    assert!(
        matches!(
            error,
            FileError::TooLarge {
                size: 11,
                limit: 10,
                ..
            }
        ),
        "{error:?}"
    );
}

#[test]
fn devices_pipes_and_folders_are_refused_without_blocking() {
    let dir = tempfile::tempdir().expect("temp dir");
    let fifo = dir.path().join("pipe.png");
    mkfifo(&fifo);
    let fifo_link = dir.path().join("link-to-pipe.png");
    std::os::unix::fs::symlink(&fifo, &fifo_link).expect("symlink");
    let cases: [(&Path, &str); 6] = [
        (
            Path::new("/dev/zero"),
            "a character device (like /dev/zero)",
        ),
        (
            Path::new("/dev/urandom"),
            "a character device (like /dev/zero)",
        ),
        (
            Path::new("/dev/null"),
            "a character device (like /dev/zero)",
        ),
        (&fifo, "a named pipe (FIFO)"),
        (&fifo_link, "a named pipe (FIFO)"),
        (dir.path(), "a folder"),
    ];
    for (path, expected) in cases {
        let started = Instant::now();
        let error = read_regular(path, 1 << 30, "a map").expect_err("not a regular file");
        assert!(
            started.elapsed() < Duration::from_secs(5),
            "{path:?} blocked"
        );
        match &error {
            FileError::NotARegularFile { kind } => assert_eq!(*kind, expected, "{path:?}"),
            other => panic!("{path:?}: expected NotARegularFile, got {other:?}"),
        }
        assert!(error.to_string().contains("not a regular file"), "{error}");
    }
}

#[test]
fn a_missing_file_is_not_found() {
    let dir = tempfile::tempdir().expect("temp dir");
    let error = read_regular(&dir.path().join("missing.obj"), 10, "a mesh").expect_err("missing");
    assert!(matches!(error, FileError::NotFound), "{error:?}");
    assert_eq!(error.to_string(), "it does not exist");
}

#[test]
fn text_must_be_utf8_and_the_message_names_the_byte() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("latin1.obj");
    fs::write(&path, b"v 0 0 0\n# caf\xe9\n").expect("write");
    let error = read_regular_text(&path, 100, "a mesh").expect_err("not UTF-8");
    assert_eq!(
        error.to_string(),
        "cannot read it: it is not UTF-8 text (byte 14 is not part of a character)"
    );
}

#[test]
fn paths_inside_the_folder_resolve() {
    let dir = tempfile::tempdir().expect("temp dir");
    fs::create_dir_all(dir.path().join("meshes")).expect("mkdir");
    fs::create_dir_all(dir.path().join("maps")).expect("mkdir");
    fs::write(dir.path().join("maps/a.png"), b"x").expect("write");
    let real = fs::canonicalize(dir.path().join("maps/a.png")).expect("canonical");
    for relative in ["maps/a.png", "./maps/a.png", "meshes/../maps/a.png"] {
        assert_eq!(resolve_inside(dir.path(), relative).expect(relative), real);
    }
    // A link that stays inside the folder is fine.
    std::os::unix::fs::symlink("../maps/a.png", dir.path().join("meshes/a.png")).expect("symlink");
    assert_eq!(
        resolve_inside(dir.path(), "meshes/a.png").expect("inside"),
        real
    );
}

#[test]
fn a_backslash_separates_folders_as_on_windows_and_the_same_rules_apply() {
    let outer = tempfile::tempdir().expect("temp dir");
    let dir = outer.path().join("project");
    fs::create_dir_all(dir.join("maps")).expect("mkdir");
    fs::write(dir.join("maps/a.png"), b"x").expect("write");
    fs::write(outer.path().join("secret.txt"), b"secret").expect("write");
    let real = fs::canonicalize(dir.join("maps/a.png")).expect("canonical");
    assert_eq!(resolve_inside(&dir, "maps\\a.png").expect("found"), real);
    assert_eq!(resolve_inside(&dir, ".\\maps/a.png").expect("found"), real);
    assert!(matches!(
        resolve_inside(&dir, "..\\secret.txt"),
        Err(FileError::ClimbsOut)
    ));
    assert!(matches!(
        resolve_inside(&dir, "\\etc\\hostname"),
        Err(FileError::Absolute)
    ));
}

#[test]
fn paths_leaving_the_folder_are_refused_with_the_reason() {
    let outer = tempfile::tempdir().expect("temp dir");
    let dir = outer.path().join("project");
    fs::create_dir_all(dir.join("maps")).expect("mkdir");
    fs::write(outer.path().join("secret.txt"), b"secret").expect("write");
    std::os::unix::fs::symlink("/etc/hostname", dir.join("maps/host.png")).expect("symlink");
    std::os::unix::fs::symlink(outer.path(), dir.join("up")).expect("symlink");
    let cases: [(&str, FileError); 7] = [
        ("", FileError::EmptyPath),
        ("/etc/hostname", FileError::Absolute),
        ("../secret.txt", FileError::ClimbsOut),
        ("../../../../etc/passwd", FileError::ClimbsOut),
        ("maps/../../secret.txt", FileError::ClimbsOut),
        ("maps/host.png", FileError::LinksOut),
        ("up/secret.txt", FileError::LinksOut),
    ];
    for (relative, expected) in cases {
        let error = resolve_inside(&dir, relative).expect_err(relative);
        assert_eq!(
            std::mem::discriminant(&error),
            std::mem::discriminant(&expected),
            "{relative:?}: {error:?}"
        );
    }
    assert!(matches!(
        resolve_inside(&dir, "maps/missing.png"),
        Err(FileError::NotFound)
    ));
}

#[test]
fn excerpts_are_short_and_escaped() {
    assert_eq!(excerpt("petal", 10), "petal");
    assert_eq!(
        excerpt("root:x:0:0:root:/root:/bin/bash", 10),
        "root:x:0:0…"
    );
    assert_eq!(excerpt("a\u{1b}[31mred\n", 20), "a\\u{1b}[31mred\\n");
    assert_eq!(excerpt("\"quoted\" \\ ü", 20), "\"quoted\" \\ ü");
}

#[test]
fn byte_counts_read_well() {
    assert_eq!(human_bytes(0), "0 bytes");
    assert_eq!(human_bytes(1023), "1023 bytes");
    assert_eq!(human_bytes(1536), "1.5 KiB");
    assert_eq!(human_bytes(256 << 20), "256 MiB");
    assert_eq!(human_bytes(8 << 30), "8 GiB");
    assert_eq!(human_bytes(40_000_000_000), "37.3 GiB");
}

#[test]
fn numbers_in_messages_stay_short() {
    assert_eq!(short_number(0.06), "0.06");
    assert_eq!(short_number(-5.0), "-5");
    assert_eq!(short_number(f64::NAN), "NaN");
    assert_eq!(short_number(1e-320), "1e-320");
    assert_eq!(short_number(1e300), "1e300");
    assert_eq!(short_number(0.1 + 0.2), "0.30000000000000004");
}

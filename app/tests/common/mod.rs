//! Running the `anthesis` binary from the end-to-end tests.

#![allow(dead_code)] // each test binary uses its own part of this

use std::process::{Command, Output};

pub fn anthesis(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_anthesis"))
        .args(args)
        .output()
        .expect("the binary runs")
}

pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Runs the binary with `args`, asserts it fails with exactly one line on
/// stderr starting `error: `, and returns what it did.
pub fn one_line_error(args: &[&str]) -> Output {
    let out = anthesis(args);
    assert!(!out.status.success(), "{args:?} should fail");
    let stderr = text(&out.stderr);
    assert_eq!(
        stderr.trim_end().lines().count(),
        1,
        "{args:?}: one line expected, got:\n{stderr}"
    );
    assert!(stderr.starts_with("error: "), "{stderr}");
    out
}

//! Running the `anthesis` binary from the end-to-end tests.

#![allow(dead_code)] // each test binary uses its own part of this

use std::process::{Command, Output};

pub fn anthesis(args: &[&str]) -> Output {
    command().args(args).output().expect("the binary runs")
}

/// The binary as a command, with the remesh cache off (`ANTHESIS_CACHE_DIR`
/// set empty), so tests never write into the user's cache; a test of the
/// cache sets the variable to a folder of its own.
pub fn command() -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_anthesis"));
    command.env("ANTHESIS_CACHE_DIR", "");
    command
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

/// Runs the binary with `args` and asserts it succeeds.
pub fn run_ok(args: &[&str]) {
    let out = anthesis(args);
    assert!(
        out.status.success(),
        "anthesis {args:?} failed: {}",
        text(&out.stderr)
    );
}

/// The picture at `path`, as RGBA.
pub fn image_at(path: &str) -> image::RgbaImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("cannot read {path}: {e}"))
        .to_rgba8()
}

/// Pixels `anthesis render` drew an organ or a part on: anything clearly
/// away from the magenta background, which the ground shadow darkens but
/// leaves magenta (red as strong as blue, no green); antialiased edges
/// half-way count. Red and blue in proportion, not just close: a shaded
/// anther or stigma (deep red, little green and blue) is no background.
pub fn anthesis_mask(picture: &image::RgbaImage) -> Vec<bool> {
    picture
        .pixels()
        .map(|p| {
            let [r, g, b, _] = p.0.map(i32::from);
            let magenta = g < 80 && (r - b).abs() < 10 + r.max(b) * 35 / 100;
            !magenta
        })
        .collect()
}

/// `anthesis render builtin:lily` of `keyframes` at `width` x `height` on a
/// magenta background into folder `renders` (created), and the camera it
/// wrote (`camera.json`), which the three.js and Blender checks look
/// through.
pub fn render_lily(renders: &str, keyframes: &[u32], width: u32, height: u32) -> serde_json::Value {
    std::fs::create_dir(renders).expect("mkdir");
    let frames: Vec<String> = keyframes.iter().map(u32::to_string).collect();
    run_ok(&[
        "render",
        "builtin:lily",
        "--frames",
        &frames.join(","),
        "--size",
        &format!("{width}x{height}"),
        "--background",
        "ff00ff",
        "--out",
        renders,
    ]);
    let camera = std::path::Path::new(renders).join("camera.json");
    let camera: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(camera).expect("camera.json"))
            .expect("camera JSON");
    in_metres(camera)
}

/// `anthesis render`'s camera (in the lily's units) in metres, as the
/// exports write the lily (one unit is its `unit`).
fn in_metres(mut camera: serde_json::Value) -> serde_json::Value {
    let lily = anthesis_garden::builtin_lily().expect("the built-in lily");
    let metres = lily.flower.unit.unwrap_or_default().metres();
    for key in ["eye", "target"] {
        if let Some(v) = camera[key].as_array_mut() {
            for x in v.iter_mut() {
                *x = (x.as_f64().expect("a number") * metres).into();
            }
        }
    }
    if let Some(near) = camera["near"].as_f64() {
        camera["near"] = (near * metres).into();
    }
    camera
}

//! The built-in lily's .glb in every encoding, played by three.js (pinned
//! in `tests/browser/package.json`, with its meshopt decoder) inside
//! Debian's headless Chromium with software WebGL: no console error, every
//! organ drawn, and silhouettes that match `anthesis render` of the same
//! keyframes seen by the same camera. Fails, never skips, when Node.js,
//! the npm packages or Chromium are missing: `.ci/run` installs them.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{anthesis_mask, image_at, render_lily, run_ok, text};
use image::RgbaImage;
use serde_json::{Value, json};

const INSTALL_HINT: &str = "install Debian's `chromium` and Node.js, then run `npm ci --prefix tests/browser` in the repository root (.ci/run does both)";

/// Keyframes compared: the bud, two stages of the opening, the open flower.
const KEYFRAMES: [u32; 4] = [0, 25, 50, 100];
/// The default frame rate of the export (keyframes per second).
const FRAMES_PER_SECOND: f64 = 24.0;
const ORGANS: [&str; 6] = [
    "petal-1", "petal-2", "petal-3", "sepal-1", "sepal-2", "sepal-3",
];
const WIDTH: u32 = 480;
const HEIGHT: u32 = 360;

fn browser_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/browser")
}

/// Pixels three.js drew an organ on in the ids picture (black background).
fn three_mask(ids: &RgbaImage) -> Vec<bool> {
    ids.pixels().map(|p| p.0[1] == 255).collect()
}

/// Pixels three.js drew a tepal on in the ids picture: the first meshes of
/// the file are the organs (`ORGANS`), mesh `i` drawn as red `32 (i + 1)`,
/// full green, no blue (page.html's `idColor`).
fn tepal_mask(ids: &RgbaImage) -> Vec<bool> {
    ids.pixels()
        .map(|p| {
            let [r, g, b, _] = p.0;
            g == 255 && b == 0 && r % 32 == 0 && (1..=ORGANS.len()).contains(&usize::from(r / 32))
        })
        .collect()
}

/// Intersection over union of two masks.
fn overlap(a: &[bool], b: &[bool]) -> f64 {
    let both = a.iter().zip(b).filter(|(x, y)| **x && **y).count();
    let either = a.iter().zip(b).filter(|(x, y)| **x || **y).count();
    both as f64 / either.max(1) as f64
}

/// Mean absolute difference of two pictures' colour channels, in 0..255.
fn mean_difference(a: &RgbaImage, b: &RgbaImage) -> f64 {
    let sum: u64 = a
        .pixels()
        .zip(b.pixels())
        .map(|(p, q)| {
            (0..3)
                .map(|c| u64::from(p.0[c].abs_diff(q.0[c])))
                .sum::<u64>()
        })
        .sum();
    sum as f64 / (3 * a.width() * a.height()) as f64
}

/// The size README.md's glTF size table states for the meshopt lily with
/// normals (the row starting `| meshopt`, its first `N.NN MB`), in bytes.
fn readme_meshopt_lily_bytes() -> u64 {
    let readme = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../README.md"))
        .expect("README.md");
    let row = readme
        .lines()
        .find(|l| l.starts_with("| meshopt"))
        .expect("README.md has a meshopt row in its size table");
    let megabytes: f64 = row
        .split('|')
        .find_map(|cell| cell.trim().strip_suffix(" MB")?.parse().ok())
        .expect("the meshopt row states a size in MB");
    (megabytes * 1e6).round() as u64
}

#[test]
fn every_encoding_of_the_lily_plays_in_three_js_like_anthesis_renders_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = |name: &str| dir.path().join(name).display().to_string();

    let encodings = ["dense", "sparse", "quantized", "meshopt"];
    let mut files = Vec::new();
    for encoding in encodings {
        let path = d(&format!("lily-{encoding}.glb"));
        run_ok(&[
            "simulate",
            "builtin:lily",
            "--encoding",
            encoding,
            "--out",
            &path,
        ]);
        files.push(json!({ "name": encoding, "path": path }));
    }
    // The compressed built-in lily with normals is no larger than the
    // README's size table says (its meshopt row, first column).
    let meshopt_bytes = std::fs::metadata(d("lily-meshopt.glb"))
        .expect("exported file")
        .len();
    let stated = readme_meshopt_lily_bytes();
    assert!(
        meshopt_bytes <= stated,
        "meshopt lily: {meshopt_bytes} bytes, more than the {stated} README.md states; \
         measure again and update its glTF size table if the growth is meant"
    );
    let renders = d("anthesis");
    let camera = render_lily(&renders, &KEYFRAMES, WIDTH, HEIGHT);

    let three_out = d("three");
    std::fs::create_dir(&three_out).expect("mkdir");
    let job = json!({
        "width": WIDTH,
        "height": HEIGHT,
        "times": KEYFRAMES.map(|k| f64::from(k) / FRAMES_PER_SECOND),
        "camera": camera,
        // anthesis render draws the organs and the parts: nothing hidden.
        "hide": [],
        // Every keyframe's shape is compared with the dense file's.
        "shape_times": (0..=100).map(|k| f64::from(k) / FRAMES_PER_SECOND).collect::<Vec<_>>(),
        "files": files,
        "out": three_out,
    });
    let job_path = d("job.json");
    std::fs::write(&job_path, job.to_string()).expect("write job");

    let script = browser_dir().join("render.mjs");
    assert!(
        browser_dir()
            .join("node_modules/three/package.json")
            .is_file(),
        "three.js is not installed: {INSTALL_HINT}"
    );
    let output = Command::new("node")
        .arg(&script)
        .arg(&job_path)
        .output()
        .unwrap_or_else(|e| panic!("cannot run node ({e}): {INSTALL_HINT}"));
    assert!(
        output.status.success(),
        "the browser check failed ({}): {}\n{INSTALL_HINT}",
        output.status,
        text(&output.stderr)
    );
    let report: Value = serde_json::from_slice(&output.stdout).expect("report JSON");

    // No console error, page error or failed request, and no three.js
    // warning (Chromium's own GL performance notes are allowed).
    for message in report["messages"].as_array().expect("messages") {
        let body = message["text"].as_str().unwrap_or_default();
        assert!(
            message["kind"] != "error" && !body.contains("THREE."),
            "the browser reported: {message}"
        );
    }

    let reports = report["files"].as_array().expect("files");
    assert_eq!(reports.len(), encodings.len());
    let mut dense_shaded: Vec<RgbaImage> = Vec::new();
    for (file, encoding) in reports.iter().zip(encodings) {
        assert_eq!(file["three"], "187", "{encoding}");
        // The organs, then the parts: those their schedule turns hang their
        // mesh (named `<part> mesh`, which three.js spells `<part>_mesh`)
        // below a moving node.
        let lily = anthesis_garden::flowers::lily().expect("lily");
        let mut meshes: Vec<String> = ORGANS.iter().map(|o| o.to_string()).collect();
        meshes.extend(
            anthesis_flower::parts::part_pieces(&lily.flower)
                .iter()
                .map(|p| {
                    if p.moves() {
                        format!("{}_mesh", p.name)
                    } else {
                        p.name.clone()
                    }
                }),
        );
        assert_eq!(file["meshes"], json!(meshes), "{encoding}");
        for organ in ORGANS {
            assert_eq!(file["morph_targets"][organ], 100, "{encoding} {organ}");
            assert_eq!(file["morph_normals"][organ], 100, "{encoding} {organ}");
            assert_eq!(file["flat_shading"][organ], false, "{encoding} {organ}");
        }
        let animation = &file["animations"][0];
        assert_eq!(animation["name"], "opening");
        let duration = animation["duration"].as_f64().expect("duration");
        assert!(
            (duration - 100.0 / FRAMES_PER_SECOND).abs() < 1e-5,
            "{duration}"
        );

        let errors = &file["shape_errors"];
        if encoding == "dense" {
            assert!(errors.is_null(), "the dense file is the reference");
        } else {
            // What three.js draws at every keyframe stays within the
            // quantization's error of the dense file: positions on a 16-bit
            // grid over each organ's box (well under a 10,000th of the
            // flower), normals on an 8-bit grid (0.4 degrees).
            assert_eq!(errors["times"], 101, "{encoding}");
            let position = errors["max_position"].as_f64().expect("position");
            let size = errors["flower_size"].as_f64().expect("size");
            let normal_deg = errors["max_normal_deg"].as_f64().expect("normal");
            eprintln!(
                "{encoding}: every keyframe within {position:.3e} (flower size {size:.3}) \
                 and {normal_deg:.3} degrees of dense"
            );
            assert!(
                position <= 1e-4 * size,
                "{encoding}: positions off by {position}"
            );
            assert!(
                normal_deg <= 0.5,
                "{encoding}: normals off by {normal_deg} degrees"
            );
        }

        let frames = file["frames"].as_array().expect("frames");
        assert_eq!(frames.len(), KEYFRAMES.len());
        for (i, (frame, keyframe)) in frames.iter().zip(KEYFRAMES).enumerate() {
            let what = format!("{encoding} at keyframe {keyframe}");
            let ours = image_at(&format!("{renders}/frame-{keyframe:03}.png"));
            let ids = image_at(frame["ids"].as_str().expect("ids"));
            let iou = overlap(&anthesis_mask(&ours), &three_mask(&ids));
            assert!(iou >= 0.95, "{what}: silhouettes overlap only {iou:.3}");
            eprintln!("{what}: silhouette overlap {iou:.4}");

            let shaded = image_at(frame["shaded"].as_str().expect("shaded"));
            if encoding == "dense" {
                dense_shaded.push(shaded);
            } else {
                // The same shapes and normals shade the same: storage
                // must not change what a viewer sees.
                let difference = mean_difference(&dense_shaded[i], &shaded);
                eprintln!("{what}: mean shading difference from dense {difference:.3}");
                assert!(
                    difference < 1.0,
                    "{what}: shading differs by {difference:.2}"
                );
            }
        }
        // Every organ shows in the open flower (in the bud the sepals hide
        // the petals).
        let open = &frames[KEYFRAMES.len() - 1]["pixels"];
        for organ in ORGANS {
            let pixels = open[organ].as_u64().unwrap_or(0);
            assert!(pixels > 100, "{encoding}: {organ} covers {pixels} pixels");
        }
    }

    // The tepals' colour side by side: the lily's colour maps (white, a
    // greenish-yellow throat, crimson spots) reach three.js as base-colour
    // textures and look as `anthesis render` paints them. The lights
    // differ (three.js: a hemisphere and a key light on a PBR material;
    // anthesis: its petal shading), so brightness is compared loosely and
    // the colour itself (chromaticity) tightly, over the pixels both draw
    // a tepal on, at every compared keyframe.
    let dense = &reports[0]["frames"];
    for (i, keyframe) in KEYFRAMES.iter().enumerate() {
        let ours = image_at(&format!("{renders}/frame-{keyframe:03}.png"));
        let ids = image_at(dense[i]["ids"].as_str().expect("ids"));
        let theirs = image_at(dense[i]["shaded"].as_str().expect("shaded"));
        let both: Vec<bool> = anthesis_mask(&ours)
            .iter()
            .zip(tepal_mask(&ids))
            .map(|(a, b)| *a && b)
            .collect();
        let (ours, theirs) = (mean_colour(&ours, &both), mean_colour(&theirs, &both));
        let (c_ours, c_theirs) = (chromaticity(ours), chromaticity(theirs));
        let brightness = (theirs.iter().sum::<f64>()) / (ours.iter().sum::<f64>());
        eprintln!(
            "keyframe {keyframe}: mean tepal colour (sRGB) anthesis {:.0?}, three.js {:.0?}; \
             chromaticity {:.3?} vs {:.3?}; brightness ratio {brightness:.2}",
            ours, theirs, c_ours, c_theirs
        );
        for channel in 0..3 {
            assert!(
                (c_ours[channel] - c_theirs[channel]).abs() <= COLOUR_TOLERANCE,
                "keyframe {keyframe}: three.js's tepals {theirs:.0?} are another colour than \
                 anthesis render's {ours:.0?}"
            );
        }
        // Warmer than white (blue's share below red's): the throat and the
        // spots tint the mean, in three.js too (a white material under its
        // bluish ground light would not be). Single spots are not compared:
        // three.js samples the texture through mipmaps, so at this size the
        // small spots blur into a pink tint there.
        assert!(
            c_theirs[0] - c_theirs[2] > 0.006,
            "keyframe {keyframe}: three.js's tepals {theirs:.0?} show no colour map"
        );
        assert!(
            (0.6..=1.6).contains(&brightness),
            "keyframe {keyframe}: three.js's tepals {theirs:.0?} against {ours:.0?}"
        );
    }
}

/// How far the chromaticities (each channel's share of the sum) of the two
/// pictures' mean tepal colours may differ.
const COLOUR_TOLERANCE: f64 = 0.01;

/// The mean sRGB colour of `picture` over the pixels `mask` holds.
fn mean_colour(picture: &RgbaImage, mask: &[bool]) -> [f64; 3] {
    let mut sum = [0.0; 3];
    let mut count = 0.0;
    for (p, _) in picture.pixels().zip(mask).filter(|(_, m)| **m) {
        for (s, c) in sum.iter_mut().zip(p.0) {
            *s += f64::from(c);
        }
        count += 1.0;
    }
    sum.map(|s| s / f64::max(count, 1.0))
}

/// Each channel's share of the sum of the three.
fn chromaticity(colour: [f64; 3]) -> [f64; 3] {
    let sum = colour.iter().sum::<f64>().max(1e-9);
    colour.map(|c| c / sum)
}

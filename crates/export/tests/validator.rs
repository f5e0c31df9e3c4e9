//! Exported files checked by the Khronos glTF-Validator (zero errors, zero
//! warnings). These tests fail, never skip, when Node.js or the validator is
//! missing: run `npm ci --prefix tests/gltf-validator` first.

mod common;

use anthesis_export::{Encoding, GlbOptions, Timing, glb_bytes, write_glb};
use common::*;

fn options(encoding: Encoding, normals: bool) -> GlbOptions {
    GlbOptions {
        encoding,
        normals,
        ..GlbOptions::default()
    }
}

#[test]
fn every_encoding_passes_the_validator_with_and_without_normals() {
    let tracks = fixture(21);
    for encoding in Encoding::ALL {
        for normals in [true, false] {
            let bytes =
                glb_bytes(&tracks, &options(encoding, normals), &mut |_| {}).expect("export");
            let report = assert_valid_glb(&bytes, &format!("{encoding}-normals-{normals}"));
            let info = &report["info"];
            assert_eq!(info["animationCount"], 1, "{encoding}");
            assert_eq!(info["hasMorphTargets"], true, "{encoding}");
            assert_eq!(info["drawCallCount"], 3, "{encoding}");
            assert_eq!(info["materialCount"], 3, "{encoding}");
            assert_eq!(info["totalVertexCount"], 153 + 91 + 36, "{encoding}");
            let required = info["extensionsRequired"]
                .as_array()
                .cloned()
                .unwrap_or_default();
            if encoding == Encoding::Quantized {
                assert_eq!(required, vec![serde_json::json!("KHR_mesh_quantization")]);
            } else if encoding == Encoding::Meshopt {
                assert_eq!(
                    required,
                    vec![
                        serde_json::json!("KHR_mesh_quantization"),
                        serde_json::json!("EXT_meshopt_compression")
                    ]
                );
            } else {
                assert!(required.is_empty(), "{encoding}: {required:?}");
            }
        }
    }
}

#[test]
fn a_file_written_by_write_glb_passes_the_validator() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("flower.glb");
    let mut last = -1.0f32;
    write_glb(&path, &fixture(21), &GlbOptions::default(), &mut |p| {
        assert!(p >= last, "progress went back from {last} to {p}");
        last = p;
    })
    .expect("write");
    assert_eq!(last, 1.0);
    let report = validator_report(&path);
    let problems = errors_and_warnings(&report);
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    assert_eq!(report["issues"]["numErrors"], 0);
}

#[test]
fn resampled_and_timed_animations_pass_the_validator() {
    let tracks = fixture(21);
    for encoding in Encoding::ALL {
        let options = GlbOptions {
            timing: Timing::Duration(3.5),
            max_morph_targets: 6,
            normals: true,
            encoding,
        };
        let bytes = glb_bytes(&tracks, &options, &mut |_| {}).expect("export");
        assert_valid_glb(&bytes, &format!("resampled-{encoding}"));
    }
}

#[test]
fn a_static_only_export_passes_the_validator() {
    let bytes = glb_bytes(&[receptacle()], &GlbOptions::default(), &mut |_| {}).expect("export");
    let report = assert_valid_glb(&bytes, "static");
    assert_eq!(report["info"]["animationCount"], 0);
}

fn png(width: u32, height: u32) -> Vec<u8> {
    let image = image::RgbaImage::from_fn(width, height, |x, y| {
        image::Rgba([(x * 255 / width) as u8, (y * 255 / height) as u8, 200, 255])
    });
    let mut bytes = Vec::new();
    image::DynamicImage::ImageRgba8(image)
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .expect("encode png");
    bytes
}

#[test]
fn a_textured_export_passes_the_validator() {
    let mut tracks = fixture(5);
    tracks[0].base_colour_png = Some(png(64, 128));
    tracks[0].base_colour = [1.0, 1.0, 1.0, 1.0];
    tracks[1].base_colour_png = Some(png(32, 32));
    tracks[1].base_colour = [1.0, 1.0, 1.0, 0.5];
    for encoding in Encoding::ALL {
        let bytes = glb_bytes(&tracks, &options(encoding, true), &mut |_| {}).expect("export");
        let report = assert_valid_glb(&bytes, &format!("textured-{encoding}"));
        assert_eq!(
            report["info"]["resources"].as_array().map(|r| r
                .iter()
                .filter(|r| r["pointer"]
                    .as_str()
                    .is_some_and(|p| p.starts_with("/images")))
                .count()),
            Some(2)
        );
    }
}

/// The validator check itself can fail: a broken accessor is caught.
#[test]
fn a_broken_accessor_makes_the_validator_fail() {
    let bytes = glb_bytes(&fixture(5), &GlbOptions::default(), &mut |_| {}).expect("export");
    assert_valid_glb(&bytes, "unbroken");
    let glb = parse_glb(&bytes);
    let position = glb.json["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
        .as_u64()
        .expect("POSITION") as usize;

    // 1. A POSITION maximum that does not match the data.
    let mut json = glb.json.clone();
    let max_x = json["accessors"][position]["max"][0].as_f64().expect("max");
    json["accessors"][position]["max"][0] = (max_x + 1.0).into();
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("wrong-max.glb");
    std::fs::write(&path, pack_glb(&json, &glb.bin)).expect("write");
    let report = validator_report(&path);
    assert!(report["issues"]["numErrors"].as_u64() > Some(0), "{report}");
    assert!(!errors_and_warnings(&report).is_empty());
    assert!(
        issue_codes(&report)
            .iter()
            .any(|c| c == "ACCESSOR_MAX_MISMATCH"),
        "{report}"
    );

    // 2. An accessor that reads past the end of its buffer view.
    let mut json = glb.json.clone();
    let count = json["accessors"][position]["count"]
        .as_u64()
        .expect("count");
    json["accessors"][position]["count"] = (count * 2).into();
    let path = dir.path().join("overrun.glb");
    std::fs::write(&path, pack_glb(&json, &glb.bin)).expect("write");
    let report = validator_report(&path);
    assert!(report["issues"]["numErrors"].as_u64() > Some(0), "{report}");
    assert!(
        std::panic::catch_unwind(|| assert_valid_glb(&pack_glb(&json, &glb.bin), "overrun"))
            .is_err(),
        "assert_valid_glb must reject a broken file"
    );
}

#[test]
fn smooth_render_meshes_pass_the_validator_in_every_encoding() {
    // The organs subdivided twice (the receptacle as it is), as
    // `anthesis simulate --subdivide 2` exports them.
    let mut tracks = fixture(11);
    let coarse: usize = tracks.iter().map(|t| t.uvs.len()).sum();
    for track in tracks.iter_mut().take(2) {
        *track = track.subdivided(2).expect("subdivides");
    }
    let fine: usize = tracks.iter().map(|t| t.uvs.len()).sum();
    assert!(fine > 10 * (coarse - 36), "{coarse} -> {fine} vertices");
    for encoding in Encoding::ALL {
        let bytes = glb_bytes(&tracks, &options(encoding, true), &mut |_| {}).expect("export");
        let report = assert_valid_glb(&bytes, &format!("subdivided-{encoding}"));
        assert_eq!(report["info"]["totalVertexCount"], fine, "{encoding}");
    }
}

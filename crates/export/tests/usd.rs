//! USD export read back by Pixar's own library (pip package `usd-core`,
//! through `tests/usd/read_stage.py`): the stage's metadata, every mesh's
//! points and normals per keyframe, texture coordinates, colours, the bound
//! material, and USD's compliance checker. These tests fail, never skip,
//! when Python or usd-core is missing: `.ci/run` installs them.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use anthesis_export::{ExportError, Timing, Track, UsdOptions, is_usd_path, usd_bytes, write_usd};
use anthesis_files::WriteError;
use common::*;
use glam::DVec3;
use serde_json::Value;

const USD_INSTALL_HINT: &str = "run `python3 -m venv tests/usd/.venv && tests/usd/.venv/bin/pip install -r tests/usd/requirements.txt` in the repository root";

fn usd_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/usd")
}

/// Runs `read_stage.py` on `path`; returns its exit status and output.
fn run_reader(path: &Path) -> std::process::Output {
    let python = usd_dir().join(".venv/bin/python");
    assert!(
        python.is_file(),
        "Pixar's USD for Python is not installed ({} is missing): {USD_INSTALL_HINT}",
        python.display()
    );
    Command::new(&python)
        .arg(usd_dir().join("read_stage.py"))
        .arg(path)
        .output()
        .unwrap_or_else(|error| {
            panic!(
                "cannot run {} ({error}): {USD_INSTALL_HINT}",
                python.display()
            )
        })
}

/// What Pixar's USD reads from `path`.
fn stage_report(path: &Path) -> Value {
    let output = run_reader(path);
    assert!(
        output.status.success(),
        "USD could not read {} ({}): {}",
        path.display(),
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).unwrap_or_else(|error| {
        panic!(
            "read_stage.py printed no JSON ({error}): {}",
            String::from_utf8_lossy(&output.stdout)
        )
    })
}

fn vec3s_of(value: &Value) -> Vec<DVec3> {
    value
        .as_array()
        .expect("an array of vectors")
        .iter()
        .map(|v| {
            let c: Vec<f64> = v
                .as_array()
                .expect("a vector")
                .iter()
                .map(|x| x.as_f64().expect("a number"))
                .collect();
            DVec3::new(c[0], c[1], c[2])
        })
        .collect()
}

fn assert_close(found: &[DVec3], expected: &[DVec3], tolerance: f64, what: &str) {
    assert_eq!(found.len(), expected.len(), "{what}: count");
    for (i, (a, b)) in found.iter().zip(expected).enumerate() {
        assert!(
            (*a - *b).abs().max_element() <= tolerance,
            "{what}: vertex {i} is {a}, expected {b}"
        );
    }
}

/// Area-weighted unit vertex normals, computed here independently of the
/// exporter.
fn expected_normals(points: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let mut sums = vec![DVec3::ZERO; points.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| points[i as usize]);
        let twice_area_normal = (b - a).cross(c - a);
        for &i in t {
            sums[i as usize] += twice_area_normal;
        }
    }
    sums.iter().map(|n| n.normalize()).collect()
}

fn write_and_read(tracks: &[Track], options: &UsdOptions, file_name: &str) -> Value {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join(file_name);
    let mut last = -1.0f32;
    write_usd(&path, tracks, options, &mut |p| {
        assert!(p >= last, "progress went back from {last} to {p}");
        last = p;
    })
    .expect("write usd");
    assert_eq!(last, 1.0);
    stage_report(&path)
}

#[test]
fn layers_read_back_in_pixars_usd_with_every_keyframe() {
    let keyframes = 5;
    let tracks = fixture(keyframes);
    // USD reads a text layer named .usd as well (it looks at the contents);
    // .usdc is the binary crate file.
    for (file_name, format_id) in [
        ("flower.usda", "usda"),
        ("flower.usd", "usd"),
        ("flower.usdc", "usdc"),
    ] {
        let report = write_and_read(&tracks, &UsdOptions::default(), file_name);
        assert_eq!(report["file_format"], format_id, "{file_name}");
        assert_eq!(report["default_prim"], "/flower");
        assert_eq!(report["default_prim_type"], "Xform");
        assert_eq!(report["default_prim_kind"], "component");
        assert_eq!(report["up_axis"], "Y");
        assert_eq!(report["meters_per_unit"], 1.0);
        assert_eq!(report["start_time_code"], 0.0);
        assert_eq!(report["end_time_code"], (keyframes - 1) as f64);
        assert_eq!(report["time_codes_per_second"], 24.0);
        assert_eq!(report["frames_per_second"], 24.0);
        assert_eq!(
            report["validation_findings"],
            serde_json::json!([]),
            "{file_name}"
        );
        let validators = report["validators"].as_array().expect("validators");
        for name in [
            "usdGeomValidators:StageMetadataChecker",
            "usdShadeValidators:MaterialBindingApiAppliedValidator",
            "usdValidation:AttributeTypeMismatch",
        ] {
            assert!(validators.contains(&name.into()), "{name} did not run");
        }

        let meshes = report["meshes"].as_array().expect("meshes");
        assert_eq!(meshes.len(), tracks.len(), "{file_name}");
        for (mesh, track) in meshes.iter().zip(&tracks) {
            let what = format!("{file_name} {}", track.name);
            assert_eq!(mesh["path"], format!("/flower/{}", track.name), "{what}");
            assert_eq!(mesh["type"], "Mesh");
            assert_eq!(mesh["double_sided"], true);
            assert_eq!(mesh["orientation"], "rightHanded");
            assert_eq!(mesh["subdivision_scheme"], "none");
            assert_eq!(
                mesh["face_vertex_counts"],
                serde_json::json!(vec![3; track.triangles.len()])
            );
            let indices: Vec<u32> = track.triangles.iter().flatten().copied().collect();
            assert_eq!(mesh["face_vertex_indices"], serde_json::json!(indices));

            let animated = track.keyframes.len() > 1;
            let times: Vec<f64> = if animated {
                (0..keyframes).map(|k| k as f64).collect()
            } else {
                Vec::new()
            };
            assert_eq!(mesh["point_times"], serde_json::json!(times), "{what}");
            assert_eq!(mesh["normal_times"], serde_json::json!(times), "{what}");
            assert_eq!(mesh["normals_interpolation"], "vertex");
            let points = mesh["points"].as_array().expect("points");
            let normals = mesh["normals"].as_array().expect("normals");
            assert_eq!(points.len(), track.keyframes.len(), "{what}");
            for (k, positions) in track.keyframes.iter().enumerate() {
                let what = format!("{what} keyframe {k}");
                // Stored as f32: the error is below 1e-6 of the coordinates.
                assert_close(&vec3s_of(&points[k]), positions, 1e-5, &what);
                let normals_k = vec3s_of(&normals[k]);
                assert_close(
                    &normals_k,
                    &expected_normals(positions, &track.triangles),
                    1e-6,
                    &format!("{what} normals"),
                );
                let extent = vec3s_of(&mesh["extents"][k]);
                let computed = vec3s_of(&mesh["computed_extents"][k]);
                assert_close(&extent, &computed, 0.0, &format!("{what} extent"));
            }
            if animated {
                // USD blends neighbouring samples linearly, as the .glb does.
                let halfway = &mesh["points_halfway"];
                assert_eq!(halfway["time"], 0.5);
                let expected: Vec<DVec3> = track.keyframes[0]
                    .iter()
                    .zip(&track.keyframes[1])
                    .map(|(a, b)| a.lerp(*b, 0.5))
                    .collect();
                assert_close(&vec3s_of(&halfway["points"]), &expected, 1e-5, &what);
            }

            let st = &mesh["st"];
            assert_eq!(st["interpolation"], "vertex");
            assert_eq!(st["type"], "texCoord2f[]");
            let expected_st: Vec<[f32; 2]> =
                track.uvs.iter().map(|uv| uv.as_vec2().to_array()).collect();
            assert_eq!(st["value"], serde_json::json!(expected_st), "{what}");

            let [r, g, b, a] = track.base_colour;
            assert_eq!(mesh["display_color"]["interpolation"], "constant");
            assert_eq!(
                mesh["display_color"]["value"],
                serde_json::json!([[r, g, b]])
            );
            assert_eq!(mesh["display_opacity"]["value"], serde_json::json!([a]));
            let material = &mesh["material"];
            assert_eq!(material["shader_id"], "UsdPreviewSurface", "{what}");
            assert_eq!(material["diffuse_color"], serde_json::json!([r, g, b]));
            assert_eq!(material["opacity"], serde_json::json!(a));
        }
    }
}

#[test]
fn names_become_valid_distinct_prim_names() {
    let mut tracks = fixture(3);
    tracks.push(tracks[0].clone());
    tracks[0].name = "petal-1".into();
    tracks[1].name = "3rd whorl".into();
    tracks[2].name = "materials".into();
    tracks[3].name = "petal 1".into();
    let report = write_and_read(&tracks, &UsdOptions::default(), "names.usda");
    let paths: Vec<&str> = report["meshes"]
        .as_array()
        .expect("meshes")
        .iter()
        .map(|m| m["path"].as_str().expect("path"))
        .collect();
    assert_eq!(
        paths,
        [
            "/flower/petal_1",
            "/flower/_3rd_whorl",
            "/flower/materials_2",
            "/flower/petal_1_2"
        ]
    );
}

#[test]
fn a_duration_sets_the_frame_rate_and_normals_can_be_left_out() {
    let tracks = fixture(9);
    let options = UsdOptions {
        timing: Timing::Duration(2.0),
        normals: false,
    };
    let report = write_and_read(&tracks, &options, "short.usda");
    // 8 keyframe intervals in 2 seconds.
    assert_eq!(report["time_codes_per_second"], 4.0);
    assert_eq!(report["frames_per_second"], 4.0);
    assert_eq!(report["end_time_code"], 8.0);
    for mesh in report["meshes"].as_array().expect("meshes") {
        assert_eq!(mesh["normals"], Value::Null, "{}", mesh["path"]);
    }
    assert_eq!(report["validation_findings"], serde_json::json!([]));
}

#[test]
fn the_checks_catch_a_broken_file() {
    // The checks themselves can fail: a truncated layer does not open, and
    // the validators report a stage without its scale or a binding without
    // the binding API.
    let text = usd_bytes(&fixture(3), &UsdOptions::default(), &mut |_| {}).expect("export");
    let dir = tempfile::tempdir().expect("tempdir");
    let truncated = dir.path().join("truncated.usda");
    std::fs::write(&truncated, &text[..text.len() / 2]).expect("write");
    let output = run_reader(&truncated);
    assert_eq!(output.status.code(), Some(3), "{output:?}");

    let text = String::from_utf8(text).expect("usda is text");
    let stripped: String = text
        .lines()
        .filter(|l| !l.contains("metersPerUnit") && !l.contains("apiSchemas"))
        .map(|l| format!("{l}\n"))
        .collect();
    let path = dir.path().join("stripped.usda");
    std::fs::write(&path, stripped).expect("write");
    let findings = stage_report(&path)["validation_findings"].to_string();
    assert!(
        findings.contains("MissingMetersPerUnitMetadata"),
        "{findings}"
    );
    assert!(findings.contains("MissingMaterialBindingAPI"), "{findings}");
}

#[test]
fn bad_requests_fail_clearly_and_leave_an_existing_file_alone() {
    let dir = tempfile::tempdir().expect("tempdir");
    let tracks = fixture(3);

    let wrong = dir.path().join("flower.txt");
    let error = write_usd(&wrong, &tracks, &UsdOptions::default(), &mut |_| {})
        .expect_err("not a USD name");
    assert!(
        error.to_string().contains(".usda, .usd or .usdc"),
        "{error}"
    );
    assert!(!wrong.exists());

    let missing = dir.path().join("no/such/flower.usda");
    let error = write_usd(&missing, &tracks, &UsdOptions::default(), &mut |_| {})
        .expect_err("missing folder");
    assert!(
        matches!(error, ExportError::Write(WriteError::MissingFolder { .. })),
        "{error:?}"
    );

    let existing = dir.path().join("flower.usda");
    std::fs::write(&existing, b"the user's earlier export").expect("write");
    let mut broken = tracks.clone();
    broken[0].keyframes[1][3].x = f64::NAN;
    let error = write_usd(&existing, &broken, &UsdOptions::default(), &mut |_| {})
        .expect_err("NaN position");
    assert!(error.to_string().contains("keyframe 1"), "{error}");
    let bad_rate = UsdOptions {
        timing: Timing::FramesPerSecond(0.0),
        normals: true,
    };
    let error = write_usd(&existing, &tracks, &bad_rate, &mut |_| {}).expect_err("zero fps");
    assert!(error.to_string().contains("frame rate"), "{error}");
    assert_eq!(
        std::fs::read(&existing).expect("read"),
        b"the user's earlier export"
    );

    let error = write_usd(
        Path::new("/sys/anthesis-flower.usda"),
        &tracks,
        &UsdOptions::default(),
        &mut |_| {},
    )
    .expect_err("sysfs takes no new files");
    assert!(
        matches!(error, ExportError::Write(WriteError::NotWritable { .. })),
        "{error:?}"
    );
}

#[test]
fn usd_paths_are_told_by_their_extension() {
    for usd in ["a/b.usda", "b.USDA", "b.usd", "b.usdc"] {
        assert!(is_usd_path(Path::new(usd)), "{usd}");
    }
    for other in ["b.usdz", "b.glb", "usda", "folder/"] {
        assert!(!is_usd_path(Path::new(other)), "{other}");
    }
}

/// sRGB code to linear, as the exporter decodes a texture.
fn srgb_to_linear(code: u8) -> f32 {
    let s = f32::from(code) / 255.0;
    if s <= 0.04045 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }
}

#[test]
fn a_textured_track_gets_its_colour_map_as_a_texture_and_per_vertex() {
    let mut tracks = fixture(3);
    // 2 x 2 pixels, row 0 the top: the left column red, the right blue.
    let (red, blue) = ([230u8, 20, 20, 255], [20u8, 40, 220, 255]);
    let image =
        image::RgbaImage::from_fn(2, 2, |x, _| image::Rgba(if x == 0 { red } else { blue }));
    let mut png = Vec::new();
    image::DynamicImage::ImageRgba8(image)
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .expect("encode");
    tracks[0].base_colour_png = Some(png);
    tracks[0].base_colour = [1.0; 4];
    let report = write_and_read(&tracks, &UsdOptions::default(), "coloured.usda");
    assert_eq!(report["validation_findings"], serde_json::json!([]));
    let mesh = &report["meshes"][0];
    let colours = &mesh["display_color"];
    assert_eq!(colours["interpolation"], "vertex");
    let values = vec3s_of(&colours["value"]);
    assert_eq!(values.len(), tracks[0].uvs.len());
    let linear = |c: [u8; 4]| {
        DVec3::new(
            f64::from(srgb_to_linear(c[0])),
            f64::from(srgb_to_linear(c[1])),
            f64::from(srgb_to_linear(c[2])),
        )
    };
    for (uv, colour) in tracks[0].uvs.iter().zip(&values) {
        // Left of the first pixel centre all red, right of the second all
        // blue, linear in between.
        let t = ((uv.x - 0.25) / 0.5).clamp(0.0, 1.0);
        let expected = linear(red).lerp(linear(blue), t);
        assert!(
            (*colour - expected).abs().max_element() < 1e-4,
            "at {uv}: {colour} against {expected}"
        );
    }
    assert_eq!(mesh["display_opacity"]["interpolation"], "vertex");
    // The material reads the colour map as a texture at `st`; the file
    // is beside the layer, where USD finds it.
    let source = &mesh["material"]["diffuse_source"];
    assert_eq!(source["shader_id"], "UsdUVTexture", "{source}");
    assert_eq!(source["output"], "rgb");
    assert_eq!(source["file"], "./coloured_textures/petal.png");
    let resolved = source["resolved_file"]
        .as_str()
        .expect("USD finds the file");
    assert!(
        resolved.ends_with("coloured_textures/petal.png"),
        "{resolved}"
    );
    let files = anthesis_export::usd_files(
        &tracks,
        &UsdOptions::default(),
        Path::new("coloured.usda"),
        false,
        &mut |_| {},
    )
    .expect("export");
    let png = tracks[0].base_colour_png.clone().expect("textured");
    assert_eq!(
        files.textures,
        [("coloured_textures/petal.png".to_owned(), png)]
    );
    assert_eq!(source["sourceColorSpace"], "sRGB");
    assert_eq!(
        (&source["wrapS"], &source["wrapT"]),
        (&"clamp".into(), &"clamp".into())
    );
    assert_eq!(source["scale"], serde_json::json!([1.0, 1.0, 1.0, 1.0]));
    assert_eq!(source["st"]["shader_id"], "UsdPrimvarReader_float2");
    assert_eq!(source["st"]["varname"], "st");
    // Untextured tracks keep one constant colour and no reader.
    assert_eq!(
        report["meshes"][1]["display_color"]["interpolation"],
        "constant"
    );
    assert!(
        report["meshes"][1]["material"]
            .get("diffuse_source")
            .is_none()
    );
}

/// A track whose unit is 1.8 mm is written in metres with `metersPerUnit`
/// 1, so a client that ignores `metersPerUnit` still gets the real size.
#[test]
fn a_stated_unit_is_written_in_metres() {
    let unit = anthesis_flower::Unit::parse("1.8 mm").expect("unit");
    let mut tracks = fixture(3);
    for track in &mut tracks {
        track.unit = unit;
    }
    let report = write_and_read(&tracks, &UsdOptions::default(), "flower.usdc");
    assert_eq!(report["meters_per_unit"], 1.0);
    assert_eq!(report["validation_findings"], serde_json::json!([]));
    let meshes = report["meshes"].as_array().expect("meshes");
    for (mesh, track) in meshes.iter().zip(&tracks) {
        let points = mesh["points"].as_array().expect("samples");
        let last = points.len() - 1;
        for (sample, k) in [(0, 0), (last, track.keyframes.len() - 1)] {
            let expected: Vec<DVec3> = track.keyframes[k].iter().map(|p| *p * 0.0018).collect();
            assert_close(&vec3s_of(&points[sample]), &expected, 1e-8, &track.name);
        }
    }
}

/// A PNG of one colour, 2 x 2 pixels.
fn plain_png(rgba: [u8; 4]) -> Vec<u8> {
    let image = image::RgbaImage::from_pixel(2, 2, image::Rgba(rgba));
    let mut png = Vec::new();
    image::DynamicImage::ImageRgba8(image)
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .expect("encode");
    png
}

/// A track whose sides look different is two single-sided meshes: the
/// outer one references the inner one's points, winds its triangles the
/// other way and has its own texture.
#[test]
fn a_two_sided_track_gets_an_outer_mesh_over_the_same_points() {
    let mut tracks = fixture(3);
    tracks[0].base_colour_png = Some(plain_png([230, 20, 20, 255]));
    tracks[0].outer_colour_png = Some(plain_png([20, 40, 220, 255]));
    tracks[0].base_colour = [1.0; 4];
    for file in ["two.usda", "two.usdc"] {
        let report = write_and_read(&tracks, &UsdOptions::default(), file);
        assert_eq!(
            report["validation_findings"],
            serde_json::json!([]),
            "{file}"
        );
        let meshes = report["meshes"].as_array().expect("meshes");
        let mesh = |path: &str| {
            meshes
                .iter()
                .find(|m| m["path"] == path)
                .unwrap_or_else(|| panic!("{path} in {file}"))
        };
        let (inner, outer) = (mesh("/flower/petal"), mesh("/flower/petal_outer"));
        assert_eq!(
            (&inner["double_sided"], &outer["double_sided"]),
            (&false.into(), &false.into())
        );
        assert_eq!(outer["points"], inner["points"], "{file}: the same points");
        assert!(
            outer["normals"].is_null(),
            "{file}: normals left to the client"
        );
        let reversed: Vec<i64> = inner["face_vertex_indices"]
            .as_array()
            .expect("indices")
            .chunks(3)
            .flat_map(|t| [t[0].as_i64(), t[2].as_i64(), t[1].as_i64()])
            .map(|i| i.expect("index"))
            .collect();
        assert_eq!(outer["face_vertex_indices"], serde_json::json!(reversed));
        assert_eq!(
            inner["material"]["diffuse_source"]["file"],
            "./two_textures/petal.png"
        );
        assert_eq!(
            outer["material"]["diffuse_source"]["file"],
            "./two_textures/petal_outer.png"
        );
        // The sepal, one colour on both sides, stays one double-sided mesh.
        assert_eq!(mesh("/flower/sepal")["double_sided"], true);
        assert!(meshes.iter().all(|m| m["path"] != "/flower/sepal_outer"));
    }
}

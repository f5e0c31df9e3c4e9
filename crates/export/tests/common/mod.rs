//! Shared test helpers: an analytic flower fixture, the Khronos validator
//! runner, and a small GLB reader independent of the writer.
#![allow(dead_code)] // each test binary uses a different subset

use std::path::{Path, PathBuf};
use std::process::Command;

use anthesis_export::Track;
use anthesis_mesh::Mesh;
use anthesis_mesh::generate::{flat_sheet, parametric_grid, test_petal};
use glam::{DVec2, DVec3};
use serde_json::Value;

// ---------------------------------------------------------------------------
// Fixture: organs moving along a known analytic motion.

/// Where an organ sits on the receptacle: radius from the axis, height, and
/// azimuth about +Y.
#[derive(Clone, Copy)]
pub struct Placement {
    pub radius: f64,
    pub height: f64,
    pub azimuth: f64,
}

/// The organ at opening fraction `s` in [0, 1]: lengthened by up to 30 %
/// along +Y, tilted outwards about the joint axis +X by up to 1.2 rad, then
/// placed on the receptacle. Points with y = z = 0 in the template (the base
/// row of a flat sheet) never move.
pub fn organ_at(template: &Mesh, placement: Placement, s: f64) -> Vec<DVec3> {
    let tilt = 1.2 * s;
    let stretch = 1.0 + 0.3 * s;
    let (sin_t, cos_t) = tilt.sin_cos();
    let (sin_a, cos_a) = placement.azimuth.sin_cos();
    template
        .positions
        .iter()
        .map(|p| {
            let y = p.y * stretch;
            // Positive tilt moves +Y towards +Z (outwards).
            let tilted = DVec3::new(p.x, y * cos_t - p.z * sin_t, y * sin_t + p.z * cos_t);
            let on_receptacle = tilted + DVec3::new(0.0, placement.height, placement.radius);
            DVec3::new(
                cos_a * on_receptacle.x + sin_a * on_receptacle.z,
                on_receptacle.y,
                -sin_a * on_receptacle.x + cos_a * on_receptacle.z,
            )
        })
        .collect()
}

pub fn organ_track(
    name: &str,
    template: &Mesh,
    placement: Placement,
    keyframes: usize,
    colour: [f32; 4],
) -> Track {
    Track {
        name: name.to_owned(),
        triangles: template.triangles.clone(),
        uvs: template.uvs.clone(),
        base_colour: colour,
        keyframes: (0..keyframes)
            .map(|k| organ_at(template, placement, k as f64 / (keyframes - 1) as f64))
            .collect(),
        base_colour_png: None,
        rigid: None,
        unit: anthesis_flower::Unit::METRE,
        outer_colour_png: None,
    }
}

/// A static dome around the origin, normal +Y.
pub fn receptacle() -> Track {
    let mesh = parametric_grid(6, 6, |uv| {
        let x = (uv.y - 0.5) * 3.0;
        let z = (uv.x - 0.5) * 3.0;
        DVec3::new(x, 0.5 * (1.0 - (x * x + z * z) / 4.5), z)
    });
    Track::still("receptacle", mesh, [0.35, 0.55, 0.2, 1.0])
}

/// Two organs (a cupped petal and a flat sepal-like sheet whose base row
/// stays still) over `keyframes` keyframes, plus the static receptacle.
pub fn fixture(keyframes: usize) -> Vec<Track> {
    let petal = test_petal(10.0, 4.0, 9, 17);
    let sheet = flat_sheet(3.0, 8.0, 7, 13);
    vec![
        organ_track(
            "petal",
            &petal,
            Placement {
                radius: 1.0,
                height: 0.4,
                azimuth: 0.0,
            },
            keyframes,
            [0.95, 0.85, 0.9, 1.0],
        ),
        organ_track(
            "sepal",
            &sheet,
            Placement {
                radius: 1.2,
                height: 0.2,
                azimuth: std::f64::consts::PI,
            },
            keyframes,
            [0.4, 0.7, 0.3, 1.0],
        ),
        receptacle(),
    ]
}

/// The size of the default lily: 6 organs of 390 vertices (13 x 30) over 100
/// keyframes, plus the receptacle.
pub fn lily_sized_fixture() -> Vec<Track> {
    let petal = test_petal(12.0, 4.0, 13, 30);
    let mut tracks: Vec<Track> = (0..6)
        .map(|i| {
            organ_track(
                &format!("tepal {i}"),
                &petal,
                Placement {
                    radius: if i % 2 == 0 { 1.0 } else { 1.3 },
                    height: 0.3,
                    azimuth: i as f64 * std::f64::consts::TAU / 6.0,
                },
                100,
                [1.0, 0.95, 0.9, 1.0],
            )
        })
        .collect();
    tracks.push(receptacle());
    tracks
}

pub fn uv_f64(uv: DVec2) -> [f64; 2] {
    [uv.x, uv.y]
}

// ---------------------------------------------------------------------------
// The Khronos glTF-Validator (npm package `gltf-validator`).

pub const INSTALL_HINT: &str =
    "run `npm ci --prefix tests/gltf-validator` in the repository root (needs Node.js 20 and npm)";

pub fn validator_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/gltf-validator")
}

/// Runs the validator on `path` and returns its JSON report. Panics (the
/// test fails, it is not skipped) when Node.js or the validator is missing.
pub fn validator_report(path: &Path) -> Value {
    let dir = validator_dir();
    let package = dir.join("node_modules/gltf-validator/package.json");
    assert!(
        package.is_file(),
        "the Khronos glTF-Validator is not installed ({} is missing): {INSTALL_HINT}",
        package.display()
    );
    let output = match Command::new("node")
        .arg(dir.join("validate.mjs"))
        .arg(path)
        .output()
    {
        Ok(output) => output,
        Err(error) => {
            panic!("cannot run `node` ({error}): install Node.js 20, then {INSTALL_HINT}")
        }
    };
    assert!(
        output.status.success(),
        "the validator failed on {} ({}): {}",
        path.display(),
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).unwrap_or_else(|error| {
        panic!(
            "the validator printed no JSON report ({error}): {}",
            String::from_utf8_lossy(&output.stdout)
        )
    })
}

/// The validator's errors and warnings (severity 0 and 1) as
/// `CODE at POINTER: message` lines.
pub fn errors_and_warnings(report: &Value) -> Vec<String> {
    let messages = report["issues"]["messages"]
        .as_array()
        .cloned()
        .unwrap_or_default();
    messages
        .iter()
        .filter(|m| m["severity"].as_u64().is_some_and(|s| s <= 1))
        .map(|m| format!("{} at {}: {}", m["code"], m["pointer"], m["message"]))
        .collect()
}

pub fn issue_codes(report: &Value) -> Vec<String> {
    report["issues"]["messages"]
        .as_array()
        .cloned()
        .unwrap_or_default()
        .iter()
        .filter_map(|m| m["code"].as_str().map(str::to_owned))
        .collect()
}

/// Validates `bytes` (written to a temporary file) and fails the test on
/// any error or warning. Returns the report.
pub fn assert_valid_glb(bytes: &[u8], label: &str) -> Value {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join(format!("{label}.glb"));
    std::fs::write(&path, bytes).expect("write glb");
    let report = validator_report(&path);
    assert_eq!(
        report["mimeType"], "model/gltf-binary",
        "{label}: the validator did not read a GLB"
    );
    let problems = errors_and_warnings(&report);
    assert!(
        problems.is_empty()
            && report["issues"]["numErrors"] == 0
            && report["issues"]["numWarnings"] == 0,
        "{label}: the validator found errors or warnings:\n{}",
        problems.join("\n")
    );
    report
}

// ---------------------------------------------------------------------------
// A GLB reader independent of the writer (and of the `gltf` crate).

pub struct Glb {
    pub json: Value,
    pub bin: Vec<u8>,
}

fn u32_at(bytes: &[u8], at: usize) -> usize {
    u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes")) as usize
}

pub fn parse_glb(bytes: &[u8]) -> Glb {
    assert_eq!(&bytes[0..4], b"glTF");
    assert_eq!(u32_at(bytes, 4), 2);
    assert_eq!(u32_at(bytes, 8), bytes.len());
    let json_len = u32_at(bytes, 12);
    assert_eq!(&bytes[16..20], b"JSON");
    let json = serde_json::from_slice(&bytes[20..20 + json_len]).expect("JSON chunk");
    let bin_at = 20 + json_len;
    let bin_len = u32_at(bytes, bin_at);
    assert_eq!(&bytes[bin_at + 4..bin_at + 8], b"BIN\0");
    let bin = bytes[bin_at + 8..bin_at + 8 + bin_len].to_vec();
    decompress_meshopt(Glb { json, bin })
}

/// Replaces every `EXT_meshopt_compression` buffer view by its data as
/// meshoptimizer's own decoder restores it (appended to the binary chunk),
/// so the reader below sees plain views. Checks the fallback buffer is
/// declared as the extension asks.
fn decompress_meshopt(mut glb: Glb) -> Glb {
    let views = glb.json["bufferViews"]
        .as_array()
        .cloned()
        .unwrap_or_default();
    for (index, view) in views.iter().enumerate() {
        let Some(extension) = view["extensions"].get("EXT_meshopt_compression") else {
            continue;
        };
        let fallback = &glb.json["buffers"][view["buffer"].as_u64().expect("buffer") as usize];
        assert_eq!(
            fallback["extensions"]["EXT_meshopt_compression"]["fallback"], true,
            "view {index} decodes into a buffer that is not a fallback"
        );
        assert!(fallback.get("uri").is_none());
        assert_eq!(
            extension["buffer"], 0,
            "compressed data lives in the GLB chunk"
        );
        let at = extension["byteOffset"].as_u64().unwrap_or(0) as usize;
        let length = extension["byteLength"].as_u64().expect("byteLength") as usize;
        let stride = extension["byteStride"].as_u64().expect("byteStride") as usize;
        let count = extension["count"].as_u64().expect("count") as usize;
        let filter = extension["filter"].as_str().unwrap_or("NONE");
        let encoded = &glb.bin[at..at + length];
        let decoded: Vec<u8> = match extension["mode"].as_str().expect("mode") {
            "ATTRIBUTES" => {
                assert_eq!(
                    meshopt::decode_vertex_version(encoded),
                    Some(0),
                    "EXT_meshopt_compression wants the version 0 vertex codec"
                );
                match filter {
                    "NONE" => decode_vertices(encoded, stride, count),
                    "EXPONENTIAL" => {
                        assert_eq!(stride, 12, "the filter is used on f32 3-vectors");
                        let mut values = meshopt::decode_vertex_buffer::<[u32; 3]>(encoded, count)
                            .expect("vertices decode");
                        meshopt::decode_filter_exp(&mut values);
                        values
                            .iter()
                            .flatten()
                            .flat_map(|v| v.to_le_bytes())
                            .collect()
                    }
                    other => panic!("unexpected filter {other}"),
                }
            }
            "TRIANGLES" => match stride {
                2 => meshopt::decode_index_buffer::<u16>(encoded, count)
                    .expect("indices decode")
                    .iter()
                    .flat_map(|i| i.to_le_bytes())
                    .collect(),
                4 => meshopt::decode_index_buffer::<u32>(encoded, count)
                    .expect("indices decode")
                    .iter()
                    .flat_map(|i| i.to_le_bytes())
                    .collect(),
                other => panic!("index stride {other}"),
            },
            other => panic!("unexpected meshopt mode {other}"),
        };
        assert_eq!(
            decoded.len(),
            view["byteLength"].as_u64().expect("byteLength") as usize,
            "view {index}: decoded size"
        );
        while !glb.bin.len().is_multiple_of(4) {
            glb.bin.push(0);
        }
        let plain = &mut glb.json["bufferViews"][index];
        plain["buffer"] = 0.into();
        plain["byteOffset"] = glb.bin.len().into();
        plain.as_object_mut().expect("view").remove("extensions");
        glb.bin.extend_from_slice(&decoded);
    }
    glb
}

fn decode_vertices(encoded: &[u8], stride: usize, count: usize) -> Vec<u8> {
    fn decode<const N: usize>(encoded: &[u8], count: usize) -> Vec<u8>
    where
        [u8; N]: Default,
    {
        meshopt::decode_vertex_buffer::<[u8; N]>(encoded, count)
            .expect("vertices decode")
            .concat()
    }
    match stride {
        4 => decode::<4>(encoded, count),
        8 => decode::<8>(encoded, count),
        12 => decode::<12>(encoded, count),
        other => panic!("vertex stride {other}"),
    }
}

/// Whether the encoding stores quantized accessors (`KHR_mesh_quantization`).
pub fn is_quantized(encoding: anthesis_export::Encoding) -> bool {
    matches!(
        encoding,
        anthesis_export::Encoding::Quantized | anthesis_export::Encoding::Meshopt
    )
}

pub fn pack_glb(json: &Value, bin: &[u8]) -> Vec<u8> {
    let mut json_bytes = serde_json::to_vec(json).expect("json");
    while !json_bytes.len().is_multiple_of(4) {
        json_bytes.push(b' ');
    }
    let total = 12 + 8 + json_bytes.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json_bytes);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(bin);
    out
}

fn component_count(type_: &str) -> usize {
    match type_ {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" => 4,
        other => panic!("unexpected accessor type {other}"),
    }
}

fn component_size(component_type: u64) -> usize {
    match component_type {
        5120 | 5121 => 1,
        5122 | 5123 => 2,
        5125 | 5126 => 4,
        other => panic!("unexpected component type {other}"),
    }
}

/// One component as glTF defines its value (normalized integers mapped to
/// [-1, 1] or [0, 1]).
fn component(bytes: &[u8], component_type: u64, normalized: bool) -> f64 {
    let (raw, scale) = match component_type {
        5120 => (bytes[0] as i8 as f64, 127.0),
        5121 => (bytes[0] as f64, 255.0),
        5122 => (i16::from_le_bytes([bytes[0], bytes[1]]) as f64, 32767.0),
        5123 => (u16::from_le_bytes([bytes[0], bytes[1]]) as f64, 65535.0),
        5125 => (
            u32::from_le_bytes(bytes[..4].try_into().expect("4")) as f64,
            1.0,
        ),
        5126 => (
            f32::from_le_bytes(bytes[..4].try_into().expect("4")) as f64,
            1.0,
        ),
        other => panic!("unexpected component type {other}"),
    };
    if normalized && component_type != 5126 {
        (raw / scale).max(-1.0)
    } else {
        raw
    }
}

fn read_elements(
    glb: &Glb,
    view_index: &Value,
    byte_offset: usize,
    count: usize,
    components: usize,
    component_type: u64,
    normalized: bool,
) -> Vec<Vec<f64>> {
    let view = &glb.json["bufferViews"][view_index.as_u64().expect("view index") as usize];
    let view_offset = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    let size = component_size(component_type);
    let stride = view["byteStride"]
        .as_u64()
        .map_or(size * components, |s| s as usize);
    (0..count)
        .map(|i| {
            let at = view_offset + byte_offset + i * stride;
            (0..components)
                .map(|c| component(&glb.bin[at + c * size..], component_type, normalized))
                .collect()
        })
        .collect()
}

/// The values of accessor `index`: dense data, zeros when it has no buffer
/// view, then sparse substitutions.
pub fn read_accessor(glb: &Glb, index: usize) -> Vec<Vec<f64>> {
    let accessor = &glb.json["accessors"][index];
    let count = accessor["count"].as_u64().expect("count") as usize;
    let components = component_count(accessor["type"].as_str().expect("type"));
    let component_type = accessor["componentType"].as_u64().expect("componentType");
    let normalized = accessor["normalized"].as_bool().unwrap_or(false);
    let mut values = if accessor["bufferView"].is_null() {
        vec![vec![0.0; components]; count]
    } else {
        read_elements(
            glb,
            &accessor["bufferView"],
            accessor["byteOffset"].as_u64().unwrap_or(0) as usize,
            count,
            components,
            component_type,
            normalized,
        )
    };
    if let Some(sparse) = accessor.get("sparse") {
        let sparse_count = sparse["count"].as_u64().expect("sparse count") as usize;
        let indices = read_elements(
            glb,
            &sparse["indices"]["bufferView"],
            sparse["indices"]["byteOffset"].as_u64().unwrap_or(0) as usize,
            sparse_count,
            1,
            sparse["indices"]["componentType"]
                .as_u64()
                .expect("index type"),
            false,
        );
        let replacements = read_elements(
            glb,
            &sparse["values"]["bufferView"],
            sparse["values"]["byteOffset"].as_u64().unwrap_or(0) as usize,
            sparse_count,
            components,
            component_type,
            normalized,
        );
        for (i, value) in indices.iter().zip(replacements) {
            values[i[0] as usize] = value;
        }
    }
    values
}

pub fn vec3s(values: &[Vec<f64>]) -> Vec<DVec3> {
    values
        .iter()
        .map(|v| DVec3::new(v[0], v[1], v[2]))
        .collect()
}

/// The node transform `translation + scale * p` (uniform scale, no
/// rotation, as the exporter writes).
pub fn node_transform(node: &Value) -> (DVec3, f64) {
    let translation = node["translation"].as_array().map_or(DVec3::ZERO, |t| {
        DVec3::new(
            t[0].as_f64().expect("t"),
            t[1].as_f64().expect("t"),
            t[2].as_f64().expect("t"),
        )
    });
    let scale = node["scale"].as_array().map_or(1.0, |s| {
        let s: Vec<f64> = s.iter().map(|x| x.as_f64().expect("s")).collect();
        assert!(s[0] == s[1] && s[1] == s[2], "uniform scale");
        s[0]
    });
    assert!(node.get("rotation").is_none() && node.get("matrix").is_none());
    (translation, scale)
}

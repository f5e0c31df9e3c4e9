//! Round trips through the `gltf` crate and an independent GLB reader: every
//! morph target rebuilds its keyframe, normals and UVs come back, and the
//! animation blends consecutive keyframes linearly.

mod common;

use anthesis_export::{Encoding, ExportError, GlbOptions, Timing, Track, glb_bytes, write_glb};
use anthesis_files::WriteError;
use anthesis_mesh::vertex_normals;
use common::*;
use glam::DVec3;
use gltf::animation::util::ReadOutputs;

const KEYFRAMES: usize = 21;

fn export(tracks: &[Track], options: &GlbOptions) -> Vec<u8> {
    glb_bytes(tracks, options, &mut |_| {}).expect("export")
}

/// Keyframe positions the exporter should have written for `track`: the
/// keyframes themselves, or linear interpolation at `j (K-1) / max`.
fn expected_frames(track: &Track, max_targets: usize) -> Vec<Vec<DVec3>> {
    let k = track.keyframes.len();
    if k - 1 <= max_targets {
        return track.keyframes.clone();
    }
    (0..=max_targets)
        .map(|j| {
            let x = j as f64 * (k - 1) as f64 / max_targets as f64;
            let i = (x.floor() as usize).min(k - 2);
            let f = x - i as f64;
            track.keyframes[i]
                .iter()
                .zip(&track.keyframes[i + 1])
                .map(|(a, b)| *a * (1.0 - f) + *b * f)
                .collect()
        })
        .collect()
}

fn normals(positions: &[DVec3], track: &Track) -> Vec<DVec3> {
    vertex_normals(positions, &track.triangles)
}

fn assert_close(actual: &[DVec3], expected: &[DVec3], tolerance: f64, what: &str) {
    assert_eq!(actual.len(), expected.len(), "{what}: vertex count");
    let worst = actual
        .iter()
        .zip(expected)
        .map(|(a, e)| (*a - *e).abs().max_element())
        .fold(0.0, f64::max);
    assert!(
        worst <= tolerance,
        "{what}: off by {worst} (tolerance {tolerance})"
    );
}

fn f32_triples(iter: impl Iterator<Item = [f32; 3]>) -> Vec<DVec3> {
    iter.map(|v| DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64))
        .collect()
}

/// The `gltf` crate reads the Dense and Sparse files: every morph target
/// plus the base rebuilds its keyframe, normals included.
#[test]
fn gltf_crate_rebuilds_every_keyframe_from_its_target() {
    let tracks = fixture(KEYFRAMES);
    for encoding in [Encoding::Dense, Encoding::Sparse] {
        let options = GlbOptions {
            encoding,
            ..GlbOptions::default()
        };
        let bytes = export(&tracks, &options);
        let gltf = gltf::Gltf::from_slice(&bytes).expect("the gltf crate accepts the file");
        let blob = gltf.blob.clone().expect("GLB binary chunk");
        let buffers = |_: gltf::Buffer| Some(&blob[..]);

        let scene = gltf.default_scene().expect("default scene");
        assert_eq!(scene.nodes().count(), tracks.len());
        for (node, track) in scene.nodes().zip(&tracks) {
            assert_eq!(node.name(), Some(track.name.as_str()));
            let mesh = node.mesh().expect("node has a mesh");
            assert_eq!(mesh.name(), Some(track.name.as_str()));
            let primitives: Vec<_> = mesh.primitives().collect();
            assert_eq!(primitives.len(), 1);
            let primitive = &primitives[0];
            assert_eq!(primitive.mode(), gltf::mesh::Mode::Triangles);
            let reader = primitive.reader(buffers);

            let indices: Vec<u32> = reader.read_indices().expect("indices").into_u32().collect();
            let triangles: Vec<u32> = track.triangles.iter().flatten().copied().collect();
            assert_eq!(indices, triangles);

            let texcoords: Vec<[f32; 2]> =
                reader.read_tex_coords(0).expect("uvs").into_f32().collect();
            for (t, uv) in texcoords.iter().zip(&track.uvs) {
                assert!(
                    (t[0] as f64 - uv.x).abs() < 1e-6 && (t[1] as f64 - (1.0 - uv.y)).abs() < 1e-6
                );
            }

            let frames = &track.keyframes;
            let base = f32_triples(reader.read_positions().expect("positions"));
            assert_close(&base, &frames[0], 1e-5, "base = keyframe 0");
            let base_normals = f32_triples(reader.read_normals().expect("normals"));
            assert_close(
                &base_normals,
                &normals(&frames[0], track),
                1e-6,
                "base normals",
            );

            let targets: Vec<_> = reader.read_morph_targets().collect();
            assert_eq!(
                targets.len(),
                frames.len() - 1,
                "{}: one target per later keyframe",
                track.name
            );
            for (k, (positions, normal_deltas, tangents)) in targets.into_iter().enumerate() {
                let what = format!("{} {encoding} target {k}", track.name);
                let deltas = f32_triples(positions.expect("POSITION deltas"));
                let rebuilt: Vec<DVec3> = base.iter().zip(&deltas).map(|(b, d)| *b + *d).collect();
                assert_close(&rebuilt, &frames[k + 1], 2e-5, &what);
                let deltas = f32_triples(normal_deltas.expect("NORMAL deltas"));
                let rebuilt: Vec<DVec3> = base_normals
                    .iter()
                    .zip(&deltas)
                    .map(|(b, d)| *b + *d)
                    .collect();
                assert_close(&rebuilt, &normals(&frames[k + 1], track), 1e-6, &what);
                assert!(tangents.is_none());
            }
        }

        // One animation, a LINEAR weights channel per animated mesh, none for
        // the receptacle.
        let animations: Vec<_> = gltf.animations().collect();
        assert_eq!(animations.len(), 1);
        let channels: Vec<_> = animations[0].channels().collect();
        let animated: Vec<usize> = channels.iter().map(|c| c.target().node().index()).collect();
        assert_eq!(animated, vec![0, 1]);
        for channel in &channels {
            assert_eq!(
                channel.target().property(),
                gltf::animation::Property::MorphTargetWeights
            );
            assert_eq!(
                channel.sampler().interpolation(),
                gltf::animation::Interpolation::Linear
            );
            let reader = channel.reader(buffers);
            let times: Vec<f32> = reader.read_inputs().expect("times").collect();
            let expected: Vec<f32> = (0..KEYFRAMES).map(|k| (k as f64 / 24.0) as f32).collect();
            assert_eq!(times, expected);
            let Some(ReadOutputs::MorphTargetWeights(weights)) = reader.read_outputs() else {
                panic!("weights output");
            };
            let weights: Vec<f32> = weights.into_f32().collect();
            assert_one_hot(&weights, KEYFRAMES);
        }
    }
}

/// At t_0 all weights are 0; at t_k (k >= 1) target k-1 is 1 and the rest 0.
fn assert_one_hot(weights: &[f32], keyframes: usize) {
    assert_weights(weights, keyframes, |k, t| k >= 1 && t == k - 1);
}

/// At t_k targets 0..k are 1 and the rest 0 (targets hold the step from
/// the previous keyframe).
fn assert_cumulative(weights: &[f32], keyframes: usize) {
    assert_weights(weights, keyframes, |k, t| t < k);
}

fn assert_weights(weights: &[f32], keyframes: usize, one: impl Fn(usize, usize) -> bool) {
    let targets = keyframes - 1;
    assert_eq!(weights.len(), keyframes * targets);
    for k in 0..keyframes {
        for t in 0..targets {
            let expected = if one(k, t) { 1.0 } else { 0.0 };
            assert_eq!(
                weights[k * targets + t],
                expected,
                "keyframe {k}, target {t}"
            );
        }
    }
}

/// `base + sum_i weights[i] * deltas[i]`, vertex by vertex: what a
/// renderer draws.
fn morphed(base: &[DVec3], deltas: &[Vec<DVec3>], weights: &[f64]) -> Vec<DVec3> {
    (0..base.len())
        .map(|v| {
            base[v]
                + deltas
                    .iter()
                    .zip(weights)
                    .map(|(d, w)| d[v] * *w)
                    .sum::<DVec3>()
        })
        .collect()
}

/// The JSON part that the `gltf` crate does not expose without extra
/// features: target names, default weights, materials.
#[test]
fn meshes_name_their_targets_and_carry_materials() {
    let tracks = fixture(KEYFRAMES);
    let glb = parse_glb(&export(&tracks, &GlbOptions::default()));
    let json = &glb.json;
    for (i, track) in tracks.iter().enumerate() {
        let mesh = &json["meshes"][i];
        let material = &json["materials"][mesh["primitives"][0]["material"]
            .as_u64()
            .expect("material") as usize];
        let colour: Vec<f32> = material["pbrMetallicRoughness"]["baseColorFactor"]
            .as_array()
            .expect("base colour")
            .iter()
            .map(|c| c.as_f64().expect("number") as f32)
            .collect();
        assert_eq!(colour, track.base_colour.to_vec());
        assert_eq!(material["doubleSided"], true);
        if track.keyframes.len() == 1 {
            assert!(mesh.get("extras").is_none() && mesh["primitives"][0].get("targets").is_none());
            continue;
        }
        let names: Vec<&str> = mesh["extras"]["targetNames"]
            .as_array()
            .expect("targetNames")
            .iter()
            .map(|n| n.as_str().expect("name"))
            .collect();
        let expected: Vec<String> = (1..KEYFRAMES).map(|k| format!("keyframe {k}")).collect();
        assert_eq!(names, expected);
        assert_eq!(
            mesh["weights"].as_array().expect("weights").len(),
            KEYFRAMES - 1
        );
        assert!(
            mesh["weights"]
                .as_array()
                .expect("weights")
                .iter()
                .all(|w| w == 0.0)
        );
    }
}

/// Playing the animation between two keyframe times blends those two
/// keyframes linearly, as the application's timeline does.
#[test]
fn playback_between_keyframes_blends_the_two_neighbours() {
    let tracks = fixture(KEYFRAMES);
    for encoding in Encoding::ALL {
        let options = GlbOptions {
            timing: Timing::FramesPerSecond(10.0),
            encoding,
            ..GlbOptions::default()
        };
        let glb = parse_glb(&export(&tracks, &options));
        let json = &glb.json;
        let sampler = &json["animations"][0]["samplers"][0];
        let times: Vec<f64> =
            read_accessor(&glb, sampler["input"].as_u64().expect("input") as usize)
                .iter()
                .map(|t| t[0])
                .collect();
        let weights: Vec<f64> =
            read_accessor(&glb, sampler["output"].as_u64().expect("output") as usize)
                .iter()
                .map(|w| w[0])
                .collect();
        let targets = KEYFRAMES - 1;
        let (translation, scale) = node_transform(&json["nodes"][0]);
        let mesh = &json["meshes"][0]["primitives"][0];
        let base = vec3s(&read_accessor(
            &glb,
            mesh["attributes"]["POSITION"].as_u64().expect("p") as usize,
        ));
        let deltas: Vec<Vec<DVec3>> = mesh["targets"]
            .as_array()
            .expect("targets")
            .iter()
            .map(|t| {
                vec3s(&read_accessor(
                    &glb,
                    t["POSITION"].as_u64().expect("p") as usize,
                ))
            })
            .collect();
        // Quantized positions: within half a step of the i16 grid.
        let tolerance = if is_quantized(encoding) {
            scale / 32767.0
        } else {
            5e-5
        };

        for (k, fraction) in [(0usize, 0.25f64), (7, 0.5), (19, 0.9)] {
            // glTF LINEAR sampling of the weights at a time between t_k and t_k+1.
            let t = times[k] + fraction * (times[k + 1] - times[k]);
            let f = (t - times[k]) / (times[k + 1] - times[k]);
            let w: Vec<f64> = (0..targets)
                .map(|i| (1.0 - f) * weights[k * targets + i] + f * weights[(k + 1) * targets + i])
                .collect();
            let played: Vec<DVec3> = morphed(&base, &deltas, &w)
                .iter()
                .map(|p| translation + *p * scale)
                .collect();
            let blended: Vec<DVec3> = tracks[0].keyframes[k]
                .iter()
                .zip(&tracks[0].keyframes[k + 1])
                .map(|(a, b)| a.lerp(*b, f))
                .collect();
            assert_close(
                &played,
                &blended,
                tolerance,
                &format!("{encoding} between keyframes {k} and {}", k + 1),
            );
        }
    }
}

/// Every encoding, read by the independent reader (sparse and quantized
/// accessors included), rebuilds each keyframe within the encoding's error.
#[test]
fn every_encoding_rebuilds_every_keyframe() {
    let tracks = fixture(KEYFRAMES);
    for encoding in Encoding::ALL {
        let bytes = export(
            &tracks,
            &GlbOptions {
                encoding,
                ..GlbOptions::default()
            },
        );
        let glb = parse_glb(&bytes);
        let json = &glb.json;
        let output = json["animations"][0]["samplers"][0]["output"]
            .as_u64()
            .expect("output") as usize;
        let weights: Vec<f64> = read_accessor(&glb, output).iter().map(|w| w[0]).collect();
        let as_f32: Vec<f32> = weights.iter().map(|&w| w as f32).collect();
        // meshopt's targets hold the step from the keyframe before (they
        // compress far better); the others hold the change from the bud.
        if encoding == Encoding::Meshopt {
            assert_cumulative(&as_f32, KEYFRAMES);
        } else {
            assert_one_hot(&as_f32, KEYFRAMES);
        }
        for (i, track) in tracks.iter().enumerate() {
            let (translation, scale) = node_transform(&json["nodes"][i]);
            let to_world = |p: DVec3| translation + p * scale;
            // Quantized positions are within half a step of the normalized
            // i16 grid, i.e. scale / 65534, plus f32 rounding.
            let tolerance = if is_quantized(encoding) {
                assert!(scale > 1.0, "quantized meshes are scaled from [-1, 1]");
                scale / 32767.0
            } else {
                assert_eq!((translation, scale), (DVec3::ZERO, 1.0));
                2e-5
            };
            let primitive = &json["meshes"][i]["primitives"][0];
            let read = |index: &serde_json::Value| {
                vec3s(&read_accessor(
                    &glb,
                    index.as_u64().expect("accessor") as usize,
                ))
            };
            let base = read(&primitive["attributes"]["POSITION"]);
            let base_normals = read(&primitive["attributes"]["NORMAL"]);
            let texcoords = read_accessor(
                &glb,
                primitive["attributes"]["TEXCOORD_0"].as_u64().expect("uv") as usize,
            );
            for (t, uv) in texcoords.iter().zip(&track.uvs) {
                // glTF's v runs down the image: (u, 1 - v), within a u16 step.
                assert!(
                    (t[0] - uv.x).abs() < 2e-5 && (t[1] - (1.0 - uv.y)).abs() < 2e-5,
                    "{t:?} vs {uv}"
                );
            }
            assert_close(
                &base.iter().map(|p| to_world(*p)).collect::<Vec<_>>(),
                &track.keyframes[0],
                tolerance,
                "base",
            );
            let empty = Vec::new();
            let targets = primitive["targets"].as_array().unwrap_or(&empty);
            let animated = track.keyframes.len() > 1;
            assert_eq!(targets.len(), track.keyframes.len() - 1);
            if !animated {
                continue;
            }
            let deltas: Vec<Vec<DVec3>> = targets.iter().map(|t| read(&t["POSITION"])).collect();
            let normal_deltas: Vec<Vec<DVec3>> =
                targets.iter().map(|t| read(&t["NORMAL"])).collect();
            for k in 1..track.keyframes.len() {
                let what = format!("{} {encoding} keyframe {k}", track.name);
                let w = &weights[k * (KEYFRAMES - 1)..(k + 1) * (KEYFRAMES - 1)];
                let rebuilt: Vec<DVec3> = morphed(&base, &deltas, w)
                    .iter()
                    .map(|p| to_world(*p))
                    .collect();
                assert_close(&rebuilt, &track.keyframes[k], tolerance, &what);
                // Normals as a renderer sees them: base + deltas, renormalized.
                let rebuilt: Vec<DVec3> = morphed(&base_normals, &normal_deltas, w)
                    .iter()
                    .map(|n| n.normalize())
                    .collect();
                let normal_tolerance = if is_quantized(encoding) { 0.01 } else { 1e-6 };
                assert_close(
                    &rebuilt,
                    &normals(&track.keyframes[k], track),
                    normal_tolerance,
                    &what,
                );
            }
        }
    }
}

/// More keyframes than allowed targets: resampled uniformly in time, the
/// duration kept, targets named by their keyframe position.
#[test]
fn too_many_keyframes_are_resampled_to_the_target_limit() {
    let tracks = fixture(KEYFRAMES);
    let options = GlbOptions {
        timing: Timing::Duration(3.5),
        max_morph_targets: 6,
        ..GlbOptions::default()
    };
    let bytes = export(&tracks, &options);
    let gltf = gltf::Gltf::from_slice(&bytes).expect("parse");
    let blob = gltf.blob.clone().expect("blob");
    let glb = parse_glb(&bytes);
    for (mesh, track) in gltf.meshes().zip(&tracks).take(2) {
        let primitive = mesh.primitives().next().expect("primitive");
        let reader = primitive.reader(|_| Some(&blob[..]));
        let base = f32_triples(reader.read_positions().expect("positions"));
        let frames = expected_frames(track, 6);
        assert_eq!(frames.len(), 7);
        let targets: Vec<_> = reader.read_morph_targets().collect();
        assert_eq!(targets.len(), 6);
        for (k, (positions, _, _)) in targets.into_iter().enumerate() {
            let deltas = f32_triples(positions.expect("positions"));
            let rebuilt: Vec<DVec3> = base.iter().zip(&deltas).map(|(b, d)| *b + *d).collect();
            assert_close(
                &rebuilt,
                &frames[k + 1],
                2e-5,
                &format!("resampled target {k}"),
            );
        }
        // The last sample is the last keyframe exactly (up to f32).
        let names: Vec<&str> = glb.json["meshes"][mesh.index()]["extras"]["targetNames"]
            .as_array()
            .expect("names")
            .iter()
            .map(|n| n.as_str().expect("str"))
            .collect();
        assert_eq!(
            names,
            [
                "keyframe 3.33",
                "keyframe 6.67",
                "keyframe 10",
                "keyframe 13.33",
                "keyframe 16.67",
                "keyframe 20"
            ]
        );
    }
    let animation = gltf.animations().next().expect("animation");
    let channel = animation.channels().next().expect("channel");
    let times: Vec<f32> = channel
        .reader(|_| Some(&blob[..]))
        .read_inputs()
        .expect("times")
        .collect();
    let expected: Vec<f32> = (0..7).map(|j| (j as f64 * 3.5 / 6.0) as f32).collect();
    assert_eq!(times, expected);
}

#[test]
fn normals_can_be_left_out() {
    let tracks = fixture(5);
    for encoding in Encoding::ALL {
        let glb = parse_glb(&export(
            &tracks,
            &GlbOptions {
                normals: false,
                encoding,
                ..GlbOptions::default()
            },
        ));
        for mesh in glb.json["meshes"].as_array().expect("meshes") {
            let primitive = &mesh["primitives"][0];
            assert!(primitive["attributes"].get("NORMAL").is_none());
            for target in primitive["targets"].as_array().into_iter().flatten() {
                assert!(target.get("NORMAL").is_none() && target.get("POSITION").is_some());
            }
        }
    }
}

#[test]
fn sparse_targets_leave_still_vertices_out() {
    // The sepal's first 45 vertices (its lower rows) stay still, and it does
    // not move at all between keyframes 0 and 1.
    let mut tracks = fixture(KEYFRAMES);
    let sepal = &mut tracks[1];
    let bud = sepal.keyframes[0].clone();
    sepal.keyframes[1] = bud.clone();
    for frame in &mut sepal.keyframes {
        frame[..45].copy_from_slice(&bud[..45]);
    }
    let options = GlbOptions {
        encoding: Encoding::Sparse,
        normals: false,
        ..GlbOptions::default()
    };
    let bytes = export(&tracks, &options);
    assert_valid_glb(&bytes, "sparse-still");
    let glb = parse_glb(&bytes);
    let targets = glb.json["meshes"][1]["primitives"][0]["targets"]
        .as_array()
        .expect("targets")
        .clone();
    for (k, target) in targets.iter().enumerate() {
        let accessor = &glb.json["accessors"][target["POSITION"].as_u64().expect("p") as usize];
        assert!(accessor.get("bufferView").is_none(), "{accessor}");
        if k == 0 {
            // Nothing moved: a single explicit zero.
            assert_eq!(accessor["sparse"]["count"], 1, "{accessor}");
            assert_eq!(accessor["max"], serde_json::json!([0.0, 0.0, 0.0]));
        } else {
            assert_eq!(accessor["sparse"]["count"], 91 - 45, "{accessor}");
        }
    }
    let rebuilt = vec3s(&read_accessor(
        &glb,
        targets[3]["POSITION"].as_u64().expect("p") as usize,
    ));
    let expected: Vec<DVec3> = tracks[1].keyframes[4]
        .iter()
        .zip(&tracks[1].keyframes[0])
        .map(|(p, p0)| *p - *p0)
        .collect();
    assert_close(&rebuilt, &expected, 1e-5, "sparse deltas");

    // The gltf crate reads the sparse accessors the same way.
    let gltf = gltf::Gltf::from_slice(&bytes).expect("parse");
    let blob = gltf.blob.clone().expect("blob");
    let mesh = gltf.meshes().nth(1).expect("sepal");
    let primitive = mesh.primitives().next().expect("primitive");
    let reader = primitive.reader(|_| Some(&blob[..]));
    let (positions, _, _) = reader.read_morph_targets().nth(3).expect("target 3");
    assert_close(
        &f32_triples(positions.expect("sparse positions")),
        &expected,
        1e-5,
        "gltf sparse",
    );

    let dense = export(
        &tracks,
        &GlbOptions {
            normals: false,
            ..GlbOptions::default()
        },
    );
    assert!(
        bytes.len() < dense.len(),
        "sparse {} vs dense {}",
        bytes.len(),
        dense.len()
    );
}

#[test]
fn progress_rises_from_zero_to_one() {
    let mut seen = Vec::new();
    glb_bytes(&fixture(KEYFRAMES), &GlbOptions::default(), &mut |p| {
        seen.push(p)
    })
    .expect("export");
    assert_eq!(seen.first(), Some(&0.0));
    assert_eq!(seen.last(), Some(&1.0));
    assert!(seen.windows(2).all(|w| w[0] <= w[1]), "{seen:?}");
    // Reported about once per keyframe of each organ, not just at the ends.
    assert!(seen.len() > 2 * KEYFRAMES, "{}", seen.len());
}

#[test]
fn invalid_input_is_a_typed_error_and_keeps_the_old_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("flower.glb");
    write_glb(&path, &fixture(3), &GlbOptions::default(), &mut |_| {}).expect("good export");
    let good = std::fs::read(&path).expect("read");

    let mut broken = fixture(3);
    broken[1].keyframes[2][5].x = f64::NAN;
    let error = write_glb(&path, &broken, &GlbOptions::default(), &mut |_| {}).expect_err("NaN");
    assert!(
        matches!(error, ExportError::InvalidTrack { track: 1, .. }),
        "{error:?}"
    );
    assert!(
        error.to_string().contains("vertex 5 at keyframe 2"),
        "{error}"
    );

    let mut broken = fixture(3);
    broken[0].keyframes[1].pop();
    let error = write_glb(&path, &broken, &GlbOptions::default(), &mut |_| {}).expect_err("count");
    assert!(
        error
            .to_string()
            .contains("keyframe 1 has 152 vertices but keyframe 0 has 153"),
        "{error}"
    );

    assert_eq!(
        std::fs::read(&path).expect("read"),
        good,
        "the good file is untouched"
    );
}

#[test]
fn write_glb_reports_a_missing_folder_before_exporting() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("renders/flower.glb");
    let mut calls = 0;
    let error = write_glb(&path, &fixture(3), &GlbOptions::default(), &mut |_| {
        calls += 1
    })
    .expect_err("missing folder");
    assert!(
        matches!(error, ExportError::Write(WriteError::MissingFolder { .. })),
        "{error:?}"
    );
    assert!(error.to_string().contains("renders"), "{error}");
    assert_eq!(calls, 0, "no work done for a destination that cannot exist");
}

/// meshopt's targets are steps between keyframes; their rounding must not
/// pile up along the animation. A sheet creeping by a third of a
/// quantization step per keyframe over 250 targets: rounding each step on
/// its own would lose the whole motion (every step rounds to zero); the
/// sum of the stored steps stays within half a grid step of every
/// keyframe, the same bound as a single quantized position.
#[test]
fn meshopt_steps_do_not_accumulate_rounding() {
    let sheet = anthesis_mesh::generate::flat_sheet(3.0, 8.0, 7, 13);
    let keyframes = 251;
    // The box spans the sheet and its drift: about 8.4 units from the centre
    // to a corner, so a grid step is about 8.4 / 32767.
    let step = 8.4 / 32767.0;
    let track = Track {
        name: "creeping".into(),
        triangles: sheet.triangles.clone(),
        uvs: sheet.uvs.clone(),
        base_colour: [1.0; 4],
        keyframes: (0..keyframes)
            .map(|k| {
                let shift = DVec3::new(0.0, 0.0, k as f64 * step / 3.0);
                sheet.positions.iter().map(|p| *p + shift).collect()
            })
            .collect(),
        base_colour_png: None,
        rigid: None,
        unit: anthesis_flower::Unit::METRE,
        outer_colour_png: None,
    };
    let options = GlbOptions {
        encoding: Encoding::Meshopt,
        ..GlbOptions::default()
    };
    let glb = parse_glb(&export(std::slice::from_ref(&track), &options));
    let json = &glb.json;
    let (translation, scale) = node_transform(&json["nodes"][0]);
    let primitive = &json["meshes"][0]["primitives"][0];
    let read = |index: &serde_json::Value| {
        vec3s(&read_accessor(
            &glb,
            index.as_u64().expect("accessor") as usize,
        ))
    };
    let base = read(&primitive["attributes"]["POSITION"]);
    let targets = primitive["targets"].as_array().expect("targets");
    assert_eq!(targets.len(), keyframes - 1);
    let deltas: Vec<Vec<DVec3>> = targets.iter().map(|t| read(&t["POSITION"])).collect();
    let output = json["animations"][0]["samplers"][0]["output"]
        .as_u64()
        .expect("output") as usize;
    let weights: Vec<f64> = read_accessor(&glb, output).iter().map(|w| w[0]).collect();
    let half_step = 0.5 * scale / 32767.0;
    let mut worst = 0.0f64;
    for k in 0..keyframes {
        let w = &weights[k * (keyframes - 1)..(k + 1) * (keyframes - 1)];
        let rebuilt = morphed(&base, &deltas, w);
        for (p, expected) in rebuilt.iter().zip(&track.keyframes[k]) {
            worst = worst.max((translation + *p * scale - *expected).abs().max_element());
        }
    }
    assert!(
        worst <= half_step * 1.001,
        "worst error {worst}, half a grid step {half_step}"
    );
}

/// A track whose unit is 1.8 mm arrives in metres in every encoding: its
/// bud and its last keyframe are the project's positions times 0.0018.
#[test]
fn a_stated_unit_is_written_in_metres() {
    let unit = anthesis_flower::Unit::parse("1.8 mm").expect("unit");
    let mut tracks = fixture(KEYFRAMES);
    for track in &mut tracks {
        track.unit = unit;
    }
    for encoding in Encoding::ALL {
        let glb = parse_glb(&export(
            &tracks,
            &GlbOptions {
                encoding,
                ..GlbOptions::default()
            },
        ));
        let json = &glb.json;
        let output = json["animations"][0]["samplers"][0]["output"]
            .as_u64()
            .expect("output") as usize;
        let weights: Vec<f64> = read_accessor(&glb, output).iter().map(|w| w[0]).collect();
        for (i, track) in tracks.iter().enumerate() {
            let (translation, scale) = node_transform(&json["nodes"][i]);
            let primitive = &json["meshes"][i]["primitives"][0];
            let read = |index: &serde_json::Value| {
                vec3s(&read_accessor(
                    &glb,
                    index.as_u64().expect("accessor") as usize,
                ))
            };
            let base = read(&primitive["attributes"]["POSITION"]);
            let tolerance = if is_quantized(encoding) {
                scale / 32767.0
            } else {
                1e-8
            };
            let in_metres = |k: usize| -> Vec<DVec3> {
                track.keyframes[k].iter().map(|p| *p * 0.0018).collect()
            };
            let world = |ps: &[DVec3]| -> Vec<DVec3> {
                ps.iter().map(|p| translation + *p * scale).collect()
            };
            let what = format!("{} {encoding}", track.name);
            assert_close(&world(&base), &in_metres(0), tolerance, &what);
            let Some(targets) = primitive["targets"].as_array() else {
                continue;
            };
            let deltas: Vec<Vec<DVec3>> = targets.iter().map(|t| read(&t["POSITION"])).collect();
            let last = KEYFRAMES - 1;
            let w = &weights[last * (KEYFRAMES - 1)..(last + 1) * (KEYFRAMES - 1)];
            let rebuilt = world(&morphed(&base, &deltas, w));
            assert_close(&rebuilt, &in_metres(last), tolerance, &what);
        }
    }
}

/// A track whose sides look different gets a second primitive for its
/// outer side: the same positions, UVs and position targets (the same
/// accessors), triangles wound the other way, normals pointing the other
/// way, and single-sided materials with each side's texture.
#[test]
fn a_two_sided_track_shares_its_data_between_its_two_primitives() {
    let png = |rgba: [u8; 4]| {
        let image = image::RgbaImage::from_pixel(2, 2, image::Rgba(rgba));
        let mut png = Vec::new();
        image::DynamicImage::ImageRgba8(image)
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .expect("encode");
        png
    };
    let mut tracks = fixture(KEYFRAMES);
    tracks[0].base_colour_png = Some(png([230, 20, 20, 255]));
    tracks[0].outer_colour_png = Some(png([20, 40, 220, 255]));
    for encoding in Encoding::ALL {
        let bytes = export(
            &tracks,
            &GlbOptions {
                encoding,
                ..GlbOptions::default()
            },
        );
        assert_valid_glb(&bytes, &format!("two-sided {encoding}"));
        let glb = parse_glb(&bytes);
        let json = &glb.json;
        let primitives = json["meshes"][0]["primitives"]
            .as_array()
            .expect("primitives");
        assert_eq!(primitives.len(), 2, "{encoding}");
        let (inner, outer) = (&primitives[0], &primitives[1]);
        for attribute in ["POSITION", "TEXCOORD_0"] {
            assert_eq!(
                inner["attributes"][attribute],
                outer["attributes"][attribute]
            );
        }
        let targets = |p: &serde_json::Value| p["targets"].as_array().expect("targets").clone();
        for (a, b) in targets(inner).iter().zip(&targets(outer)) {
            assert_eq!(a["POSITION"], b["POSITION"], "{encoding}");
        }
        let read = |index: &serde_json::Value| {
            read_accessor(&glb, index.as_u64().expect("accessor") as usize)
        };
        let normals = |p: &serde_json::Value| vec3s(&read(&p["attributes"]["NORMAL"]));
        for (n, m) in normals(inner).iter().zip(&normals(outer)) {
            assert!((*n + *m).length() < 1e-6, "{encoding}: {n} and {m}");
        }
        let indices = |p: &serde_json::Value| read(&p["indices"]);
        let (a, b) = (indices(inner), indices(outer));
        // The same triangles the other way round (meshopt may start a
        // triangle at another corner).
        for (s, t) in a.chunks(3).zip(b.chunks(3)) {
            let flipped = [&s[0], &s[2], &s[1]];
            let turns = [
                [&t[0], &t[1], &t[2]],
                [&t[1], &t[2], &t[0]],
                [&t[2], &t[0], &t[1]],
            ];
            assert!(turns.contains(&flipped), "{encoding}: {s:?} and {t:?}");
        }
        let materials = json["materials"].as_array().expect("materials");
        let (mi, mo) = (
            inner["material"].as_u64().expect("m"),
            outer["material"].as_u64().expect("m"),
        );
        assert_ne!(mi, mo);
        for m in [mi, mo] {
            assert_eq!(materials[m as usize]["doubleSided"], false);
        }
        // The other tracks stay one double-sided primitive.
        assert_eq!(
            json["meshes"][1]["primitives"].as_array().expect("p").len(),
            1
        );
    }
}

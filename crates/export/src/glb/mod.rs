//! The animated .glb writer. The glTF JSON is built with `serde_json`
//! values rather than the `gltf-json` types: the writer needs exact control
//! over optional fields (sparse accessors without a buffer view, normalized
//! quantized accessors, `mesh.extras.targetNames`, extensions), and
//! `serde_json` keeps the `gltf` crate a test-only dependency.

mod builder;
mod encode;

use glam::DVec3;
use serde_json::{Value, json};

use crate::prepare::{
    animation_times, sample_keyframes, sample_positions, target_name, validate_options,
    validate_tracks,
};
use crate::{ExportError, GlbOptions, Pose, Track};
use builder::{
    CLAMP_TO_EDGE, GltfBuilder, KHR_MESH_QUANTIZATION, LINEAR, LINEAR_MIPMAP_LINEAR, TRIANGLES,
    f32_json,
};
use encode::{TargetDeltas, encode_mesh};

/// Builds the animated .glb of `tracks` in memory (see the crate
/// documentation for its layout). `progress` is called with values rising
/// from 0 to 1, about once per exported keyframe of each track.
///
/// Fails with a typed error, before any work, on invalid tracks (no
/// keyframes, vertex counts that differ between keyframes or from the UVs,
/// indices out of range, NaN or infinite coordinates, base colours outside
/// `[0, 1]`, a texture that is not a PNG, animated tracks with different
/// keyframe counts) and on invalid options.
pub fn glb_bytes(
    tracks: &[Track],
    options: &GlbOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<Vec<u8>, ExportError> {
    let keyframe_count = validate_tracks(tracks)?;
    validate_options(options, keyframe_count)?;
    progress(0.0);

    let sample_at = sample_positions(keyframe_count, options.max_morph_targets);
    let target_count = sample_at.len() - 1;
    let target_names: Vec<Value> = sample_at[1..]
        .iter()
        .map(|&x| Value::from(target_name(x)))
        .collect();

    let total_work = tracks
        .iter()
        .map(|t| {
            if t.keyframes.len() > 1 {
                sample_at.len()
            } else {
                1
            }
        })
        .sum::<usize>() as f32
        + 1.0;
    let mut work_done = 0usize;
    let mut tick = |progress: &mut dyn FnMut(f32)| {
        work_done += 1;
        progress(work_done as f32 / total_work);
    };

    let mut gltf = GltfBuilder::new(options.encoding);
    let mut nodes = Vec::with_capacity(tracks.len());
    let mut meshes = Vec::with_capacity(tracks.len());
    let mut materials = Vec::with_capacity(tracks.len());
    let mut images = Vec::new();
    let mut textures = Vec::new();
    let mut stored_pngs: Vec<&Vec<u8>> = Vec::new();
    let mut animated_nodes = Vec::new();
    let mut top_nodes = Vec::with_capacity(tracks.len());
    // Rigid tracks: the node that moves, and its pose at each exported
    // keyframe.
    let mut moving_nodes: Vec<(usize, Vec<Pose>)> = Vec::new();

    for (index, track) in tracks.iter().enumerate() {
        let rigid = track.rigid.as_ref().filter(|_| track.keyframes.len() > 1);
        let frames: Vec<Vec<DVec3>> = if let Some(rigid) = rigid {
            vec![rigid.local.clone()]
        } else if track.keyframes.len() > 1 {
            sample_at
                .iter()
                .map(|&x| sample_keyframes(&track.keyframes, x))
                .collect()
        } else {
            vec![track.keyframes[0].clone()]
        };

        let mut material = json!({
            "name": track.name,
            "pbrMetallicRoughness": {
                "baseColorFactor": track.base_color.map(f32_json),
                "metallicFactor": 0.0,
                "roughnessFactor": 0.7,
            },
            "doubleSided": true,
        });
        if track.base_color[3] < 1.0 {
            material["alphaMode"] = json!("BLEND");
        }
        if let Some(png) = &track.base_color_png {
            // Organs of one template share its colour map: one image and
            // texture for each distinct PNG.
            let texture = match stored_pngs.iter().position(|stored| *stored == png) {
                Some(texture) => texture,
                None => {
                    let view = gltf.view(png, None, None);
                    images.push(json!({
                        "name": track.name,
                        "bufferView": view,
                        "mimeType": "image/png",
                    }));
                    textures.push(json!({ "sampler": 0, "source": images.len() - 1 }));
                    stored_pngs.push(png);
                    textures.len() - 1
                }
            };
            material["pbrMetallicRoughness"]["baseColorTexture"] = json!({ "index": texture });
        }
        materials.push(material);

        let encoded = encode_mesh(&mut gltf, track, &frames, options, &mut || tick(progress));

        let mut primitive = json!({
            "attributes": encoded.attributes,
            "indices": encoded.indices,
            "material": index,
            "mode": TRIANGLES,
        });
        let mut mesh = json!({ "name": track.name });
        if !encoded.targets.is_empty() {
            primitive["targets"] = Value::Array(encoded.targets);
            mesh["weights"] = Value::Array(vec![json!(0.0); target_count]);
            mesh["extras"] = json!({ "targetNames": target_names });
            animated_nodes.push(nodes.len());
        }
        mesh["primitives"] = json!([primitive]);
        meshes.push(mesh);

        let top = nodes.len();
        let mut node = json!({ "name": track.name, "mesh": index });
        if let Some(qbox) = encoded.dequantization {
            node["translation"] = json!(qbox.center.map(f32_json));
            node["scale"] = json!([
                f32_json(qbox.scale),
                f32_json(qbox.scale),
                f32_json(qbox.scale)
            ]);
        }
        if let Some(rigid) = rigid {
            // The mesh (with its dequantisation) hangs below a node that
            // carries the rigid motion.
            let poses: Vec<Pose> = sample_at
                .iter()
                .map(|&x| sample_pose(&rigid.poses, x))
                .collect();
            let mover_index = nodes.len();
            let mut mover = json!({ "name": track.name, "children": [mover_index + 1] });
            set_pose(&mut mover, &poses[0]);
            node["name"] = json!(format!("{} mesh", track.name));
            nodes.push(mover);
            moving_nodes.push((mover_index, poses));
        }
        top_nodes.push(top);
        nodes.push(node);
    }

    let mut root = json!({
        "asset": {
            "version": "2.0",
            "generator": concat!("Anthesis (anthesis-export ", env!("CARGO_PKG_VERSION"), ")"),
        },
        "scene": 0,
        "scenes": [{ "name": "flower", "nodes": top_nodes }],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
    });

    if !animated_nodes.is_empty() || !moving_nodes.is_empty() {
        let sample_times = animation_times(options.timing, keyframe_count, &sample_at)?;
        let input = gltf.times(&sample_times);
        let mut samplers = Vec::new();
        let mut channels = Vec::new();
        if !animated_nodes.is_empty() {
            let output = gltf.weights(
                sample_at.len(),
                target_count,
                options.encoding,
                TargetDeltas::of(options.encoding),
            );
            // All animated meshes share the keyframe times and the weights,
            // so they share one sampler's accessors.
            for &node in &animated_nodes {
                channels.push(json!({
                    "sampler": samplers.len(),
                    "target": { "node": node, "path": "weights" }
                }));
                samplers
                    .push(json!({ "input": input, "output": output, "interpolation": "LINEAR" }));
            }
        }
        for (node, poses) in &moving_nodes {
            let translations: Vec<[f32; 3]> = poses
                .iter()
                .map(|p| p.translation.as_vec3().to_array())
                .collect();
            let rotations: Vec<[f32; 4]> = poses
                .iter()
                .map(|p| p.rotation.normalize().as_quat().to_array())
                .collect();
            for (path, output) in [
                ("translation", gltf.animation_output(&translations)),
                ("rotation", gltf.animation_output(&rotations)),
            ] {
                channels.push(json!({
                    "sampler": samplers.len(),
                    "target": { "node": node, "path": path }
                }));
                samplers
                    .push(json!({ "input": input, "output": output, "interpolation": "LINEAR" }));
            }
        }
        root["animations"] =
            json!([{ "name": "opening", "samplers": samplers, "channels": channels }]);
    }
    if !images.is_empty() {
        root["images"] = Value::Array(images);
        root["textures"] = Value::Array(textures);
        root["samplers"] = json!([{
            "magFilter": LINEAR,
            "minFilter": LINEAR_MIPMAP_LINEAR,
            "wrapS": CLAMP_TO_EDGE,
            "wrapT": CLAMP_TO_EDGE,
        }]);
    }
    if gltf.uses_quantization {
        root["extensionsUsed"] = json!([KHR_MESH_QUANTIZATION]);
        root["extensionsRequired"] = json!([KHR_MESH_QUANTIZATION]);
    }

    let bytes = gltf.finish(root)?;
    progress(1.0);
    Ok(bytes)
}

/// The pose at `x` (in keyframes) of a sequence of poses: a keyframe's own,
/// or the blend of its neighbours as [`crate::KeyframeBlend`] places it.
fn sample_pose(poses: &[Pose], x: f64) -> Pose {
    match crate::KeyframeBlend::at(poses.len(), x) {
        Some(blend) => poses[blend.below].towards(&poses[blend.above], blend.fraction),
        None => poses[0],
    }
}

/// Writes `pose` as the node's translation and rotation.
fn set_pose(node: &mut Value, pose: &Pose) {
    node["translation"] = json!(pose.translation.as_vec3().to_array().map(f32_json));
    node["rotation"] = json!(pose.rotation.normalize().as_quat().to_array().map(f32_json));
}

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
use encode::{QuantizationBox, TargetDeltas, encode_mesh};

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

    let samples = Samples::new(keyframe_count, options.max_morph_targets);
    let mut work = Work::new(progress, tracks, samples.at.len());
    let mut scene = Scene::new(options, tracks.len());
    for (index, track) in tracks.iter().enumerate() {
        scene.add_track(index, track, &samples, options, &mut work);
    }
    let bytes = scene.finish(&samples, keyframe_count, options)?;
    progress(1.0);
    Ok(bytes)
}

/// Where the exported keyframes are sampled (`at[0]` is the base mesh,
/// each later sample a morph target) and the morph targets' names.
struct Samples {
    at: Vec<f64>,
    target_names: Vec<Value>,
}

impl Samples {
    /// The samples of `keyframe_count` keyframes with at most
    /// `max_morph_targets` morph targets.
    fn new(keyframe_count: usize, max_morph_targets: usize) -> Samples {
        let at = sample_positions(keyframe_count, max_morph_targets);
        let target_names = at[1..]
            .iter()
            .map(|&x| Value::from(target_name(x)))
            .collect();
        Samples { at, target_names }
    }

    /// How many morph targets an animated mesh has.
    fn target_count(&self) -> usize {
        self.at.len() - 1
    }
}

/// The export's progress: one unit of work per exported keyframe of each
/// animated track, one per still track, and one for writing the file.
struct Work<'p> {
    progress: &'p mut dyn FnMut(f32),
    done: usize,
    total: f32,
}

impl<'p> Work<'p> {
    /// Counts the work of `tracks` with `sample_count` samples each.
    fn new(progress: &'p mut dyn FnMut(f32), tracks: &[Track], sample_count: usize) -> Work<'p> {
        let total = tracks
            .iter()
            .map(|t| {
                if t.keyframes.len() > 1 {
                    sample_count
                } else {
                    1
                }
            })
            .sum::<usize>() as f32
            + 1.0;
        Work {
            progress,
            done: 0,
            total,
        }
    }

    /// One more unit done: reports the fraction done so far.
    fn tick(&mut self) {
        self.done += 1;
        (self.progress)(self.done as f32 / self.total);
    }
}

/// The glTF document being built, one track at a time.
struct Scene<'a> {
    gltf: GltfBuilder,
    nodes: Vec<Value>,
    meshes: Vec<Value>,
    materials: Vec<Value>,
    textures: Textures<'a>,
    /// The nodes whose meshes have morph targets.
    animated_nodes: Vec<usize>,
    /// The scene's top nodes, one per track.
    top_nodes: Vec<usize>,
    /// Rigid tracks: the node that moves, and its pose at each exported
    /// keyframe.
    moving_nodes: Vec<(usize, Vec<Pose>)>,
}

impl<'a> Scene<'a> {
    /// An empty document for `track_count` tracks.
    fn new(options: &GlbOptions, track_count: usize) -> Scene<'a> {
        Scene {
            gltf: GltfBuilder::new(options.encoding),
            nodes: Vec::with_capacity(track_count),
            meshes: Vec::with_capacity(track_count),
            materials: Vec::with_capacity(track_count),
            textures: Textures::default(),
            animated_nodes: Vec::new(),
            top_nodes: Vec::with_capacity(track_count),
            moving_nodes: Vec::new(),
        }
    }

    /// Adds `track` (the `index`th, whose mesh is the `index`th): its
    /// materials, its mesh and the nodes that place it.
    fn add_track(
        &mut self,
        index: usize,
        track: &'a Track,
        samples: &Samples,
        options: &GlbOptions,
        work: &mut Work<'_>,
    ) {
        let frames = frames_in_metres(track, &samples.at);
        let dequantization = self.add_mesh(track, &frames, samples, options, work);
        self.add_nodes(index, track, dequantization, &samples.at);
    }

    /// Adds the mesh of `track` at `frames` with its materials: one
    /// primitive, or two when its sides differ. Returns how the node must
    /// dequantize the mesh's positions, if they are quantized.
    fn add_mesh(
        &mut self,
        track: &'a Track,
        frames: &[Vec<DVec3>],
        samples: &Samples,
        options: &GlbOptions,
        work: &mut Work<'_>,
    ) -> Option<QuantizationBox> {
        let inner_material = self.materials.len();
        self.materials.push(material(
            &mut self.gltf,
            &mut self.textures,
            track,
            Face::Inner,
        ));

        // A two-sided track's outer primitive shares every accessor whose
        // data is the same as the inner one's (all but normals and indices).
        self.gltf.share_accessors(track.outer_colour_png.is_some());
        let encoded = encode_mesh(&mut self.gltf, track, frames, options, &mut || work.tick());

        let mut primitive = json!({
            "attributes": encoded.attributes,
            "indices": encoded.indices,
            "material": inner_material,
            "mode": TRIANGLES,
        });
        let mut mesh = json!({ "name": track.name });
        if !encoded.targets.is_empty() {
            primitive["targets"] = Value::Array(encoded.targets);
            mesh["weights"] = Value::Array(vec![json!(0.0); samples.target_count()]);
            mesh["extras"] = json!({ "targetNames": samples.target_names });
            self.animated_nodes.push(self.nodes.len());
        }
        let mut primitives = vec![primitive];
        if track.outer_colour_png.is_some() {
            let outer_material = self.materials.len();
            self.materials.push(material(
                &mut self.gltf,
                &mut self.textures,
                track,
                Face::Outer,
            ));
            primitives.push(outer_primitive(
                &mut self.gltf,
                track,
                frames,
                options,
                outer_material,
            ));
        }
        self.gltf.share_accessors(false);
        mesh["primitives"] = Value::Array(primitives);
        self.meshes.push(mesh);
        encoded.dequantization
    }

    /// Adds the node of `track`'s mesh (the `index`th), which applies
    /// `dequantization`, below a node that carries its rigid motion if it
    /// has one.
    fn add_nodes(
        &mut self,
        index: usize,
        track: &Track,
        dequantization: Option<QuantizationBox>,
        sample_at: &[f64],
    ) {
        let rigid = track.rigid.as_ref().filter(|_| track.keyframes.len() > 1);
        let top = self.nodes.len();
        let mut node = json!({ "name": track.name, "mesh": index });
        if let Some(qbox) = dequantization {
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
            let poses = poses_in_metres(&rigid.poses, sample_at, track.unit.metres());
            let mover_index = self.nodes.len();
            let mut mover = json!({ "name": track.name, "children": [mover_index + 1] });
            set_pose(&mut mover, &poses[0]);
            node["name"] = json!(format!("{} mesh", track.name));
            self.nodes.push(mover);
            self.moving_nodes.push((mover_index, poses));
        }
        self.top_nodes.push(top);
        self.nodes.push(node);
    }

    /// The .glb of the document: the glTF root with the scene, its
    /// animation (if anything moves), textures and extensions, and the
    /// binary chunk.
    fn finish(
        mut self,
        samples: &Samples,
        keyframe_count: usize,
        options: &GlbOptions,
    ) -> Result<Vec<u8>, ExportError> {
        let mut root = json!({
            "asset": {
                "version": "2.0",
                "generator": concat!("Anthesis (anthesis-export ", env!("CARGO_PKG_VERSION"), ")"),
            },
            "scene": 0,
            "scenes": [{ "name": "flower", "nodes": self.top_nodes }],
            "nodes": self.nodes,
            "meshes": self.meshes,
            "materials": self.materials,
        });

        if !self.animated_nodes.is_empty() || !self.moving_nodes.is_empty() {
            let animation = Animation {
                sample_at: &samples.at,
                keyframe_count,
                target_count: samples.target_count(),
                morphed: &self.animated_nodes,
                moving: &self.moving_nodes,
            };
            root["animations"] = json!([animation.json(&mut self.gltf, options)?]);
        }
        self.textures.add_to(&mut root);
        if self.gltf.uses_quantization {
            root["extensionsUsed"] = json!([KHR_MESH_QUANTIZATION]);
            root["extensionsRequired"] = json!([KHR_MESH_QUANTIZATION]);
        }
        self.gltf.finish(root)
    }
}

/// The outer side of a two-sided track: the same surface wound the other
/// way (its normals point outwards), drawn with `material` (the outer
/// texture); its accessors with the same data as the inner side's are the
/// inner side's while the builder shares them.
fn outer_primitive(
    gltf: &mut GltfBuilder,
    track: &Track,
    frames: &[Vec<DVec3>],
    options: &GlbOptions,
    material: usize,
) -> Value {
    let flipped = Track {
        triangles: track.triangles.iter().map(|&[a, b, c]| [a, c, b]).collect(),
        ..track.clone()
    };
    let outer = encode_mesh(gltf, &flipped, frames, options, &mut || {});
    let mut primitive = json!({
        "attributes": outer.attributes,
        "indices": outer.indices,
        "material": material,
        "mode": TRIANGLES,
    });
    if !outer.targets.is_empty() {
        primitive["targets"] = Value::Array(outer.targets);
    }
    primitive
}

/// A rigid track's poses at the exported keyframe positions `sample_at`,
/// their translations in metres.
fn poses_in_metres(poses: &[Pose], sample_at: &[f64], metres: f64) -> Vec<Pose> {
    sample_at
        .iter()
        .map(|&x| {
            let pose = sample_pose(poses, x);
            Pose {
                translation: pose.translation * metres,
                ..pose
            }
        })
        .collect()
}

/// The positions of `track` the .glb stores, in metres: a rigid track's
/// mesh in its own frame, an animated track's at each exported keyframe
/// position `sample_at`, a still track's one keyframe.
fn frames_in_metres(track: &Track, sample_at: &[f64]) -> Vec<Vec<DVec3>> {
    let frames: Vec<Vec<DVec3>> = match &track.rigid {
        Some(rigid) if track.keyframes.len() > 1 => vec![rigid.local.clone()],
        _ if track.keyframes.len() > 1 => sample_at
            .iter()
            .map(|&x| sample_keyframes(&track.keyframes, x))
            .collect(),
        _ => vec![track.keyframes[0].clone()],
    };
    let metres = track.unit.metres();
    if metres == 1.0 {
        return frames;
    }
    frames
        .into_iter()
        .map(|frame| frame.into_iter().map(|p| p * metres).collect())
        .collect()
}

/// The images and textures of a .glb: one for each distinct PNG.
#[derive(Default)]
struct Textures<'a> {
    images: Vec<Value>,
    textures: Vec<Value>,
    stored: Vec<&'a Vec<u8>>,
}

impl<'a> Textures<'a> {
    /// The texture of `png` (named after `name` when it is new).
    fn texture(&mut self, gltf: &mut GltfBuilder, png: &'a Vec<u8>, name: &str) -> usize {
        if let Some(texture) = self.stored.iter().position(|stored| *stored == png) {
            return texture;
        }
        let view = gltf.view(png, None, None);
        self.images.push(json!({
            "name": name,
            "bufferView": view,
            "mimeType": "image/png",
        }));
        self.textures
            .push(json!({ "sampler": 0, "source": self.images.len() - 1 }));
        self.stored.push(png);
        self.textures.len() - 1
    }

    /// Adds the images, textures and their one sampler to the glTF root.
    fn add_to(self, root: &mut Value) {
        if self.images.is_empty() {
            return;
        }
        root["images"] = Value::Array(self.images);
        root["textures"] = Value::Array(self.textures);
        root["samplers"] = json!([{
            "magFilter": LINEAR,
            "minFilter": LINEAR_MIPMAP_LINEAR,
            "wrapS": CLAMP_TO_EDGE,
            "wrapT": CLAMP_TO_EDGE,
        }]);
    }
}

/// Which faces of a track a material is for.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Face {
    /// The track's triangles as they are: both sides, or the inner side of
    /// a track whose sides differ.
    Inner,
    /// The outer side of a track whose sides differ.
    Outer,
}

/// The material of `track` (of its `face`): its base colour (blended when
/// not opaque), its texture if it has one, non-metallic, double-sided
/// unless its sides differ ([`Track::outer_color_png`]), when each side's
/// material is single-sided.
fn material<'a>(
    gltf: &mut GltfBuilder,
    textures: &mut Textures<'a>,
    track: &'a Track,
    face: Face,
) -> Value {
    let two_sided = track.outer_colour_png.is_none();
    let name = match face {
        Face::Inner => track.name.clone(),
        Face::Outer => format!("{} outer", track.name),
    };
    let mut material = json!({
        "name": name,
        "pbrMetallicRoughness": {
            "baseColorFactor": track.base_colour.map(f32_json),
            "metallicFactor": 0.0,
            "roughnessFactor": 0.7,
        },
        "doubleSided": two_sided,
    });
    if track.base_colour[3] < 1.0 {
        material["alphaMode"] = json!("BLEND");
    }
    let png = match face {
        Face::Inner => &track.base_colour_png,
        Face::Outer => &track.outer_colour_png,
    };
    if let Some(png) = png {
        // Organs of one template share its colour map: one image and
        // texture for each distinct PNG.
        let texture = textures.texture(gltf, png, &name);
        material["pbrMetallicRoughness"]["baseColorTexture"] = json!({ "index": texture });
    }
    material
}

/// The one animation of a .glb: morph weights of the animated meshes'
/// nodes and poses of the rigid tracks' nodes, at the exported keyframes.
struct Animation<'a> {
    sample_at: &'a [f64],
    keyframe_count: usize,
    target_count: usize,
    morphed: &'a [usize],
    moving: &'a [(usize, Vec<Pose>)],
}

impl Animation<'_> {
    fn json(&self, gltf: &mut GltfBuilder, options: &GlbOptions) -> Result<Value, ExportError> {
        let sample_times = animation_times(options.timing, self.keyframe_count, self.sample_at)?;
        let input = gltf.times(&sample_times);
        let mut samplers = Vec::new();
        let mut channels = Vec::new();
        if !self.morphed.is_empty() {
            let output = gltf.weights(
                self.sample_at.len(),
                self.target_count,
                options.encoding,
                TargetDeltas::of(options.encoding),
            );
            // All animated meshes share the keyframe times and the weights,
            // so they share one sampler's accessors.
            for &node in self.morphed {
                channels.push(json!({
                    "sampler": samplers.len(),
                    "target": { "node": node, "path": "weights" }
                }));
                samplers
                    .push(json!({ "input": input, "output": output, "interpolation": "LINEAR" }));
            }
        }
        for (node, poses) in self.moving {
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
        Ok(json!({ "name": "opening", "samplers": samplers, "channels": channels }))
    }
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

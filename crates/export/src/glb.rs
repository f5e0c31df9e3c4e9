//! The animated .glb writer. The glTF JSON is built with `serde_json`
//! values rather than the `gltf-json` types: the writer needs exact control
//! over optional fields (sparse accessors without a buffer view, normalized
//! quantized accessors, `mesh.extras.targetNames`, extensions), and
//! `serde_json` keeps the `gltf` crate a test-only dependency.

use glam::{DVec2, DVec3};
use serde_json::{Map, Value, json};

use crate::prepare::{
    animation_times, sample_keyframes, sample_positions, target_name, unit_normals,
    validate_options, validate_tracks,
};
use crate::{Encoding, ExportError, GlbOptions, Track};

const BYTE: u32 = 5120;
const UNSIGNED_BYTE: u32 = 5121;
const SHORT: u32 = 5122;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_INT: u32 = 5125;
const FLOAT: u32 = 5126;

const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

const LINEAR: u32 = 9729;
const LINEAR_MIPMAP_LINEAR: u32 = 9987;
const CLAMP_TO_EDGE: u32 = 33071;

const TRIANGLES: u32 = 4;

const KHR_MESH_QUANTIZATION: &str = "KHR_mesh_quantization";

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

    let mut gltf = GltfBuilder::default();
    let mut nodes = Vec::with_capacity(tracks.len());
    let mut meshes = Vec::with_capacity(tracks.len());
    let mut materials = Vec::with_capacity(tracks.len());
    let mut images = Vec::new();
    let mut textures = Vec::new();
    let mut animated_nodes = Vec::new();

    for (index, track) in tracks.iter().enumerate() {
        let frames: Vec<Vec<DVec3>> = if track.keyframes.len() > 1 {
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
            let view = gltf.view(png, None, None);
            images.push(json!({
                "name": track.name,
                "bufferView": view,
                "mimeType": "image/png",
            }));
            textures.push(json!({ "sampler": 0, "source": images.len() - 1 }));
            material["pbrMetallicRoughness"]["baseColorTexture"] =
                json!({ "index": textures.len() - 1 });
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
            animated_nodes.push(index);
        }
        mesh["primitives"] = json!([primitive]);
        meshes.push(mesh);

        let mut node = json!({ "name": track.name, "mesh": index });
        if let Some(qbox) = encoded.dequantization {
            node["translation"] = json!(qbox.center.map(f32_json));
            node["scale"] = json!([
                f32_json(qbox.scale),
                f32_json(qbox.scale),
                f32_json(qbox.scale)
            ]);
        }
        nodes.push(node);
    }

    let mut root = json!({
        "asset": {
            "version": "2.0",
            "generator": concat!("Anthesis (anthesis-export ", env!("CARGO_PKG_VERSION"), ")"),
        },
        "scene": 0,
        "scenes": [{ "name": "flower", "nodes": (0..tracks.len()).collect::<Vec<_>>() }],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
    });

    if !animated_nodes.is_empty() {
        let sample_times = animation_times(options.timing, keyframe_count, &sample_at)?;
        let input = gltf.times(&sample_times);
        let output = gltf.weights(sample_at.len(), target_count, options.encoding);
        // All animated meshes share the keyframe times and the one-hot
        // weights, so they share one sampler's accessors.
        let samplers: Vec<Value> = animated_nodes
            .iter()
            .map(|_| json!({ "input": input, "output": output, "interpolation": "LINEAR" }))
            .collect();
        let channels: Vec<Value> = animated_nodes
            .iter()
            .enumerate()
            .map(|(sampler, &node)| {
                json!({ "sampler": sampler, "target": { "node": node, "path": "weights" } })
            })
            .collect();
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

/// The accessors of one mesh.
struct EncodedMesh {
    attributes: Map<String, Value>,
    indices: usize,
    targets: Vec<Value>,
    dequantization: Option<QuantizationBox>,
}

/// Quantized positions `q` (normalized `i16`) mean `center + scale * q`;
/// the node's translation and uniform scale apply it.
#[derive(Debug, Clone, Copy)]
struct QuantizationBox {
    center: [f32; 3],
    scale: f32,
}

const I16_MAX: f64 = 32767.0;
const I8_MAX: f64 = 127.0;

impl QuantizationBox {
    /// The box around every frame that also holds every delta from frame 0,
    /// so both base positions and position deltas fit in `[-1, 1]`.
    fn around(frames: &[Vec<DVec3>]) -> Self {
        let mut min = DVec3::splat(f64::INFINITY);
        let mut max = DVec3::splat(f64::NEG_INFINITY);
        for p in frames.iter().flatten() {
            min = min.min(*p);
            max = max.max(*p);
        }
        let center = ((min + max) * 0.5).as_vec3();
        let center_f64 = center.as_dvec3();
        let mut extent = 0.0f64;
        for frame in frames {
            for (p, p0) in frame.iter().zip(&frames[0]) {
                extent = extent
                    .max((*p - center_f64).abs().max_element())
                    .max((*p - *p0).abs().max_element());
            }
        }
        // Round the scale up to an f32 so the box never shrinks.
        let mut scale = extent as f32;
        if (scale as f64) < extent {
            scale = scale.next_up();
        }
        if !(scale.is_normal()) {
            scale = 1.0;
        }
        Self {
            center: center.to_array(),
            scale,
        }
    }

    /// Position in the box's normalized `i16` units (not rounded).
    fn units(&self, p: DVec3) -> DVec3 {
        (p - glam::Vec3::from_array(self.center).as_dvec3()) / self.scale as f64 * I16_MAX
    }
}

fn to_i16(x: f64) -> i16 {
    x.round().clamp(-I16_MAX, I16_MAX) as i16
}

fn to_i8(x: f64) -> i8 {
    x.round().clamp(-I8_MAX, I8_MAX) as i8
}

fn encode_mesh(
    gltf: &mut GltfBuilder,
    track: &Track,
    frames: &[Vec<DVec3>],
    options: &GlbOptions,
    tick: &mut dyn FnMut(),
) -> EncodedMesh {
    let base = &frames[0];
    let quantized = options.encoding == Encoding::Quantized;
    let mut attributes = Map::new();
    let normal_of = |frame: &[DVec3]| unit_normals(frame, &track.triangles);
    let base_normals = options.normals.then(|| normal_of(base));

    let dequantization = quantized.then(|| QuantizationBox::around(frames));
    let base_units: Option<Vec<[i16; 3]>> = dequantization.map(|qbox| {
        base.iter()
            .map(|p| qbox.units(*p).to_array().map(to_i16))
            .collect()
    });
    let position = match &base_units {
        Some(units) => gltf.vec3_i16(units, true),
        None => gltf.vec3_f32(&to_f32(base), true),
    };
    attributes.insert("POSITION".to_owned(), position.into());

    let base_normals_i16: Option<Vec<[i16; 3]>> = match (&base_normals, quantized) {
        (Some(normals), true) => Some(
            normals
                .iter()
                .map(|n| (*n * I16_MAX).to_array().map(to_i16))
                .collect(),
        ),
        _ => None,
    };
    if let Some(normals) = &base_normals {
        let accessor = match &base_normals_i16 {
            Some(units) => gltf.vec3_i16(units, false),
            None => gltf.vec3_f32(&to_f32(normals), false),
        };
        attributes.insert("NORMAL".to_owned(), accessor.into());
    }

    // glTF images have their origin at the top-left; Anthesis maps put
    // v = 0 on the bottom row.
    let texcoords: Vec<DVec2> = track
        .uvs
        .iter()
        .map(|uv| DVec2::new(uv.x, 1.0 - uv.y))
        .collect();
    let in_unit_square = texcoords
        .iter()
        .all(|t| (0.0..=1.0).contains(&t.x) && (0.0..=1.0).contains(&t.y));
    let texcoord = if quantized && in_unit_square {
        let units: Vec<[u16; 2]> = texcoords
            .iter()
            .map(|t| (*t * 65535.0).round().to_array().map(|x| x as u16))
            .collect();
        gltf.vec2_u16_normalized(&units)
    } else {
        let values: Vec<[f32; 2]> = texcoords.iter().map(|t| t.as_vec2().to_array()).collect();
        gltf.vec2_f32(&values)
    };
    attributes.insert("TEXCOORD_0".to_owned(), texcoord.into());

    let indices = gltf.indices(&track.triangles, base.len());
    tick();

    let mut targets = Vec::with_capacity(frames.len().saturating_sub(1));
    for frame in &frames[1..] {
        let mut target = Map::new();
        let accessor = match (&base_units, dequantization) {
            (Some(base_units), Some(qbox)) => {
                let deltas: Vec<[i16; 3]> = frame
                    .iter()
                    .zip(base_units)
                    .map(|(p, q0)| {
                        let q = qbox.units(*p).to_array().map(|x| x.round());
                        [0, 1, 2].map(|i| to_i16(q[i] - q0[i] as f64))
                    })
                    .collect();
                gltf.vec3_i16(&deltas, true)
            }
            _ => gltf.vec3_f32_target(&f32_deltas(frame, base), true, options.encoding),
        };
        target.insert("POSITION".to_owned(), accessor.into());

        if let Some(base_normals) = &base_normals {
            let normals = normal_of(frame);
            let accessor = match &base_normals_i16 {
                Some(base_units) => {
                    // Deltas from the dequantized base normal, in i8 units.
                    let deltas: Vec<DVec3> = normals
                        .iter()
                        .zip(base_units)
                        .map(|(n, q0)| {
                            (*n - DVec3::from_array(q0.map(f64::from)) / I16_MAX) * I8_MAX
                        })
                        .collect();
                    if deltas.iter().all(|d| d.abs().max_element() <= I8_MAX) {
                        let units: Vec<[i8; 3]> =
                            deltas.iter().map(|d| d.to_array().map(to_i8)).collect();
                        gltf.vec3_i8_normalized(&units)
                    } else {
                        let deltas: Vec<[f32; 3]> = normals
                            .iter()
                            .zip(base_units)
                            .map(|(n, q0)| {
                                (*n - DVec3::from_array(q0.map(f64::from)) / I16_MAX)
                                    .as_vec3()
                                    .to_array()
                            })
                            .collect();
                        gltf.vec3_f32_target(&deltas, false, Encoding::Dense)
                    }
                }
                None => {
                    let deltas = f32_deltas(&normals, base_normals);
                    gltf.vec3_f32_target(&deltas, false, options.encoding)
                }
            };
            target.insert("NORMAL".to_owned(), accessor.into());
        }
        targets.push(Value::Object(target));
        tick();
    }

    EncodedMesh {
        attributes,
        indices,
        targets,
        dequantization,
    }
}

fn to_f32(values: &[DVec3]) -> Vec<[f32; 3]> {
    values.iter().map(|v| v.as_vec3().to_array()).collect()
}

/// An `f32` as the shortest JSON number that reads back as the same `f32`
/// (`0.1` rather than `0.10000000149011612`).
fn f32_json(x: f32) -> Value {
    x.to_string()
        .parse::<f64>()
        .ok()
        .and_then(serde_json::Number::from_f64)
        .map_or(Value::Null, Value::Number)
}

/// Per-component minimum and maximum, as JSON arrays.
fn min_max<const N: usize, T: Copy + PartialOrd + Into<f64>>(values: &[[T; N]]) -> (Value, Value) {
    let mut min = values[0];
    let mut max = values[0];
    for v in values {
        for i in 0..N {
            if v[i] < min[i] {
                min[i] = v[i];
            }
            if v[i] > max[i] {
                max[i] = v[i];
            }
        }
    }
    // Every T used here (f32, i16) is exactly an f32.
    let as_json = |a: [T; N]| {
        Value::from(
            a.iter()
                .map(|&x| f32_json(x.into() as f32))
                .collect::<Vec<_>>(),
        )
    };
    (as_json(min), as_json(max))
}

/// `values - base`, vertex by vertex, as `f32`: a morph target's deltas.
fn f32_deltas(values: &[DVec3], base: &[DVec3]) -> Vec<[f32; 3]> {
    values
        .iter()
        .zip(base)
        .map(|(v, v0)| (*v - *v0).as_vec3().to_array())
        .collect()
}

/// Adds the per-component `min` and `max` of `values` to `accessor`.
fn set_min_max<const N: usize, T: Copy + PartialOrd + Into<f64>>(
    accessor: &mut Value,
    values: &[[T; N]],
) {
    let (min, max) = min_max(values);
    accessor["min"] = min;
    accessor["max"] = max;
}

/// The little-endian bytes of `values`, as glTF buffers hold numbers.
fn le_bytes<T, const B: usize>(
    values: impl IntoIterator<Item = T>,
    to_le_bytes: fn(T) -> [u8; B],
) -> Vec<u8> {
    values.into_iter().flat_map(to_le_bytes).collect()
}

/// What an accessor's elements are: the component type, whether integer
/// components are normalized to `[0, 1]` or `[-1, 1]`, and the glTF type
/// (`SCALAR`, `VEC2`, `VEC3`).
#[derive(Clone, Copy)]
struct Element {
    component_type: u32,
    normalized: bool,
    kind: &'static str,
}

const VEC3_F32: Element = Element::plain(FLOAT, "VEC3");
const SCALAR_F32: Element = Element::plain(FLOAT, "SCALAR");

impl Element {
    const fn plain(component_type: u32, kind: &'static str) -> Element {
        Element {
            component_type,
            normalized: false,
            kind,
        }
    }

    const fn normalized(component_type: u32, kind: &'static str) -> Element {
        Element {
            component_type,
            normalized: true,
            kind,
        }
    }

    /// An accessor of `count` such elements, over buffer view `view` (with
    /// none, all zeros unless made sparse).
    fn accessor(self, view: Option<usize>, count: usize) -> Value {
        let mut accessor = Map::new();
        if let Some(view) = view {
            accessor.insert("bufferView".into(), view.into());
        }
        accessor.insert("componentType".into(), self.component_type.into());
        if self.normalized {
            accessor.insert("normalized".into(), true.into());
        }
        accessor.insert("count".into(), count.into());
        accessor.insert("type".into(), self.kind.into());
        Value::Object(accessor)
    }
}

/// The binary chunk and the buffer views and accessors that describe it.
#[derive(Default)]
struct GltfBuilder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    uses_quantization: bool,
}

impl GltfBuilder {
    /// Appends `bytes` 4-byte aligned as a new buffer view.
    fn view(&mut self, bytes: &[u8], stride: Option<usize>, target: Option<u32>) -> usize {
        self.pad();
        let mut view = json!({
            "buffer": 0,
            "byteOffset": self.bin.len(),
            "byteLength": bytes.len(),
        });
        if let Some(stride) = stride {
            view["byteStride"] = stride.into();
        }
        if let Some(target) = target {
            view["target"] = target.into();
        }
        self.bin.extend_from_slice(bytes);
        self.views.push(view);
        self.views.len() - 1
    }

    fn pad(&mut self) {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
    }

    fn accessor(&mut self, accessor: Value) -> usize {
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// Stores `bytes` as a new buffer view (see [`GltfBuilder::view`]) and
    /// returns an accessor of `count` `element`s over it.
    fn stored(
        &mut self,
        bytes: &[u8],
        stride: Option<usize>,
        target: Option<u32>,
        element: Element,
        count: usize,
    ) -> Value {
        let view = self.view(bytes, stride, target);
        element.accessor(Some(view), count)
    }

    fn vec3_f32(&mut self, values: &[[f32; 3]], with_min_max: bool) -> usize {
        let bytes = le_bytes(values.iter().flatten().copied(), f32::to_le_bytes);
        let mut accessor = self.stored(&bytes, None, Some(ARRAY_BUFFER), VEC3_F32, values.len());
        if with_min_max {
            set_min_max(&mut accessor, values);
        }
        self.accessor(accessor)
    }

    /// A morph-target delta accessor; with [`Encoding::Sparse`] only the
    /// vertices with a non-zero delta are stored, when that is smaller.
    fn vec3_f32_target(
        &mut self,
        deltas: &[[f32; 3]],
        with_min_max: bool,
        encoding: Encoding,
    ) -> usize {
        if encoding != Encoding::Sparse {
            return self.vec3_f32(deltas, with_min_max);
        }
        let mut moved: Vec<usize> = deltas
            .iter()
            .enumerate()
            .filter(|(_, d)| d.iter().any(|&x| x != 0.0))
            .map(|(i, _)| i)
            .collect();
        if moved.is_empty() {
            // Nothing moved. glTF allows an accessor with neither buffer view
            // nor sparse data (all zeros), but some readers (the `gltf`
            // crate) reject it, so store one explicit zero instead.
            moved.push(0);
        }
        let index_type = index_component_type(deltas.len());
        let index_size = component_size(index_type);
        let dense_bytes = 12 * deltas.len();
        let sparse_bytes = moved.len() * (index_size + 12);
        if sparse_bytes >= dense_bytes {
            return self.vec3_f32(deltas, with_min_max);
        }
        let mut accessor = VEC3_F32.accessor(None, deltas.len());
        if with_min_max {
            set_min_max(&mut accessor, deltas);
        }
        let values = le_bytes(moved.iter().flat_map(|&i| deltas[i]), f32::to_le_bytes);
        self.add_sparse(&mut accessor, &moved, index_type, &values);
        self.accessor(accessor)
    }

    /// Makes `accessor` (one with no buffer view, so all zeros) sparse:
    /// the elements at `positions` hold `values`.
    fn add_sparse(
        &mut self,
        accessor: &mut Value,
        positions: &[usize],
        index_type: u32,
        values: &[u8],
    ) {
        let indices_view = self.view(&index_bytes(positions, index_type), None, None);
        let values_view = self.view(values, None, None);
        accessor["sparse"] = json!({
            "count": positions.len(),
            "indices": { "bufferView": indices_view, "componentType": index_type },
            "values": { "bufferView": values_view },
        });
    }

    /// Normalized `i16` VEC3, padded to an 8-byte stride as vertex
    /// attributes must be 4-byte aligned.
    fn vec3_i16(&mut self, values: &[[i16; 3]], with_min_max: bool) -> usize {
        self.uses_quantization = true;
        let padded = values.iter().flat_map(|v| [v[0], v[1], v[2], 0]);
        let bytes = le_bytes(padded, i16::to_le_bytes);
        let element = Element::normalized(SHORT, "VEC3");
        let mut accessor = self.stored(&bytes, Some(8), Some(ARRAY_BUFFER), element, values.len());
        if with_min_max {
            set_min_max(&mut accessor, values);
        }
        self.accessor(accessor)
    }

    /// Normalized `i8` VEC3, padded to a 4-byte stride.
    fn vec3_i8_normalized(&mut self, values: &[[i8; 3]]) -> usize {
        self.uses_quantization = true;
        let padded = values.iter().flat_map(|v| [v[0], v[1], v[2], 0]);
        let bytes = le_bytes(padded, i8::to_le_bytes);
        let element = Element::normalized(BYTE, "VEC3");
        let accessor = self.stored(&bytes, Some(4), Some(ARRAY_BUFFER), element, values.len());
        self.accessor(accessor)
    }

    fn vec2_f32(&mut self, values: &[[f32; 2]]) -> usize {
        let bytes = le_bytes(values.iter().flatten().copied(), f32::to_le_bytes);
        let element = Element::plain(FLOAT, "VEC2");
        let accessor = self.stored(&bytes, None, Some(ARRAY_BUFFER), element, values.len());
        self.accessor(accessor)
    }

    fn vec2_u16_normalized(&mut self, values: &[[u16; 2]]) -> usize {
        let bytes = le_bytes(values.iter().flatten().copied(), u16::to_le_bytes);
        let element = Element::normalized(UNSIGNED_SHORT, "VEC2");
        let accessor = self.stored(&bytes, None, Some(ARRAY_BUFFER), element, values.len());
        self.accessor(accessor)
    }

    fn indices(&mut self, triangles: &[[u32; 3]], vertex_count: usize) -> usize {
        let flat: Vec<usize> = triangles.iter().flatten().map(|&i| i as usize).collect();
        // At least u16: some graphics APIs have no 8-bit index buffers.
        let component_type = match index_component_type(vertex_count) {
            UNSIGNED_BYTE => UNSIGNED_SHORT,
            other => other,
        };
        let bytes = index_bytes(&flat, component_type);
        let element = Element::plain(component_type, "SCALAR");
        let accessor = self.stored(
            &bytes,
            None,
            Some(ELEMENT_ARRAY_BUFFER),
            element,
            flat.len(),
        );
        self.accessor(accessor)
    }

    fn times(&mut self, times: &[f32]) -> usize {
        let bytes = le_bytes(times.iter().copied(), f32::to_le_bytes);
        let mut accessor = self.stored(&bytes, None, None, SCALAR_F32, times.len());
        let first = times.first().copied().unwrap_or(0.0);
        let last = times.last().copied().unwrap_or(0.0);
        accessor["min"] = json!([f32_json(first)]);
        accessor["max"] = json!([f32_json(last)]);
        self.accessor(accessor)
    }

    /// One-hot weights: at exported keyframe `k >= 1` target `k - 1` has
    /// weight 1, all else 0.
    fn weights(&mut self, keyframes: usize, targets: usize, encoding: Encoding) -> usize {
        let count = keyframes * targets;
        let ones = (1..keyframes).map(|k| k * targets + (k - 1));
        let accessor = match encoding {
            Encoding::Dense => {
                let mut values = vec![0.0f32; count];
                for i in ones {
                    values[i] = 1.0;
                }
                let bytes = le_bytes(values, f32::to_le_bytes);
                self.stored(&bytes, None, None, SCALAR_F32, count)
            }
            Encoding::Sparse => {
                let positions: Vec<usize> = ones.collect();
                let index_type = index_component_type(count);
                let values = le_bytes(positions.iter().map(|_| 1.0f32), f32::to_le_bytes);
                let mut accessor = SCALAR_F32.accessor(None, count);
                self.add_sparse(&mut accessor, &positions, index_type, &values);
                accessor
            }
            Encoding::Quantized => {
                let mut values = vec![0u8; count];
                for i in ones {
                    values[i] = u8::MAX;
                }
                let element = Element::normalized(UNSIGNED_BYTE, "SCALAR");
                self.stored(&values, None, None, element, count)
            }
        };
        self.accessor(accessor)
    }

    /// Assembles the GLB container: header, JSON chunk, binary chunk.
    fn finish(mut self, mut root: Value) -> Result<Vec<u8>, ExportError> {
        self.pad();
        root["buffers"] = json!([{ "byteLength": self.bin.len() }]);
        root["bufferViews"] = Value::Array(self.views);
        root["accessors"] = Value::Array(self.accessors);
        let mut json_chunk = serde_json::to_vec(&root).map_err(|e| ExportError::Io {
            path: "<glTF JSON>".into(),
            source: std::io::Error::other(e),
        })?;
        while !json_chunk.len().is_multiple_of(4) {
            json_chunk.push(b' ');
        }
        let total = 12 + 8 + json_chunk.len() + 8 + self.bin.len();
        let too_large = || ExportError::TooLarge {
            bytes: total as u64,
        };
        let total_u32 = u32::try_from(total).map_err(|_| too_large())?;
        let json_len = u32::try_from(json_chunk.len()).map_err(|_| too_large())?;
        let bin_len = u32::try_from(self.bin.len()).map_err(|_| too_large())?;

        let mut glb = Vec::with_capacity(total);
        glb.extend_from_slice(b"glTF");
        glb.extend_from_slice(&2u32.to_le_bytes());
        glb.extend_from_slice(&total_u32.to_le_bytes());
        glb.extend_from_slice(&json_len.to_le_bytes());
        glb.extend_from_slice(b"JSON");
        glb.extend_from_slice(&json_chunk);
        glb.extend_from_slice(&bin_len.to_le_bytes());
        glb.extend_from_slice(b"BIN\0");
        glb.extend_from_slice(&self.bin);
        Ok(glb)
    }
}

/// The smallest index type for indices below `count`. The maximum value of
/// each type is avoided: glTF reserves it for primitive restart.
fn index_component_type(count: usize) -> u32 {
    if count <= u8::MAX as usize {
        UNSIGNED_BYTE
    } else if count <= u16::MAX as usize {
        UNSIGNED_SHORT
    } else {
        UNSIGNED_INT
    }
}

fn component_size(component_type: u32) -> usize {
    match component_type {
        BYTE | UNSIGNED_BYTE => 1,
        SHORT | UNSIGNED_SHORT => 2,
        _ => 4,
    }
}

fn index_bytes(indices: &[usize], component_type: u32) -> Vec<u8> {
    match component_type {
        UNSIGNED_BYTE => indices.iter().map(|&i| i as u8).collect(),
        UNSIGNED_SHORT => indices
            .iter()
            .flat_map(|&i| (i as u16).to_le_bytes())
            .collect(),
        _ => indices
            .iter()
            .flat_map(|&i| (i as u32).to_le_bytes())
            .collect(),
    }
}

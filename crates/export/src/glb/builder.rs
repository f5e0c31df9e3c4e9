//! The binary chunk of a .glb and the buffer views and accessors that
//! describe it, and the GLB container around the JSON.

use serde_json::{Map, Value, json};

use super::encode::TargetDeltas;
use crate::{Encoding, ExportError};

const BYTE: u32 = 5120;
const UNSIGNED_BYTE: u32 = 5121;
const SHORT: u32 = 5122;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_INT: u32 = 5125;
const FLOAT: u32 = 5126;

const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

pub(super) const LINEAR: u32 = 9729;
pub(super) const LINEAR_MIPMAP_LINEAR: u32 = 9987;
pub(super) const CLAMP_TO_EDGE: u32 = 33071;

pub(super) const TRIANGLES: u32 = 4;

pub(super) const KHR_MESH_QUANTIZATION: &str = "KHR_mesh_quantization";
const EXT_MESHOPT_COMPRESSION: &str = "EXT_meshopt_compression";

/// An `f32` as the shortest JSON number that reads back as the same `f32`
/// (`0.1` rather than `0.10000000149011612`).
pub(super) fn f32_json(x: f32) -> Value {
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

/// How a buffer view's bytes may be compressed with `EXT_meshopt_compression`.
#[derive(Clone, Copy)]
enum Layout {
    /// Stored as they are (images, animation data, sparse parts).
    Raw,
    /// Vertex attributes of `element_size` bytes each (a multiple of 4):
    /// meshopt's `ATTRIBUTES` mode.
    Vertices { element_size: usize },
    /// Triangle indices of `index_size` bytes each (2 or 4): meshopt's
    /// `TRIANGLES` mode.
    Triangles { index_size: usize },
}

/// The binary chunk and the buffer views and accessors that describe it.
pub(super) struct GltfBuilder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    pub(super) uses_quantization: bool,
    /// Compress vertex and index views with `EXT_meshopt_compression`.
    meshopt: bool,
    /// Size of the uncompressed data the compressed views decode into (the
    /// fallback buffer, which holds no bytes in the file).
    fallback_len: usize,
    /// With meshopt, vertex attributes of one element size share one buffer
    /// view, written by [`GltfBuilder::finish`]: one
    /// compressed stream instead of one per accessor keeps the JSON and
    /// the per-stream overhead small (hundreds of morph targets).
    groups: Vec<Group>,
    /// While set ([`GltfBuilder::share_accessors`]): the vertex accessors
    /// made so far by their kind and bytes, so an identical one asked for
    /// again is the same accessor (the outer side of a two-sided track
    /// shares its positions, UVs and position targets with the inner side).
    shared: Option<Vec<(Vec<u8>, usize)>>,
}

/// Vertex data waiting to become one shared buffer view.
struct Group {
    element_size: usize,
    bytes: Vec<u8>,
    /// The accessors over this data, each at its byte offset.
    accessors: Vec<usize>,
}

impl GltfBuilder {
    pub(super) fn new(encoding: Encoding) -> GltfBuilder {
        GltfBuilder {
            bin: Vec::new(),
            views: Vec::new(),
            accessors: Vec::new(),
            uses_quantization: false,
            meshopt: encoding == Encoding::Meshopt,
            fallback_len: 0,
            groups: Vec::new(),
            shared: None,
        }
    }

    /// Starts (`true`) or ends sharing identical vertex accessors (see
    /// [`GltfBuilder::shared`]).
    pub(super) fn share_accessors(&mut self, on: bool) {
        self.shared = on.then(Vec::new);
    }

    /// The accessor made earlier for `key` while sharing.
    fn recall(&self, key: &[u8]) -> Option<usize> {
        let shared = self.shared.as_ref()?;
        shared.iter().find(|(k, _)| k == key).map(|(_, i)| *i)
    }

    /// Keeps `accessor` as the one for `key` while sharing.
    fn remember(&mut self, key: Vec<u8>, accessor: usize) -> usize {
        if let Some(shared) = &mut self.shared {
            shared.push((key, accessor));
        }
        accessor
    }

    /// The sharing key of an accessor: what kind it is and its bytes.
    fn key(&self, kind: &str, bytes: &[u8]) -> Option<Vec<u8>> {
        self.shared.as_ref()?;
        let mut key = kind.as_bytes().to_vec();
        key.push(0);
        key.extend_from_slice(bytes);
        Some(key)
    }

    /// Appends `bytes` 4-byte aligned as a new buffer view.
    pub(super) fn view(
        &mut self,
        bytes: &[u8],
        stride: Option<usize>,
        target: Option<u32>,
    ) -> usize {
        self.view_of(bytes, stride, target, Layout::Raw)
    }

    /// Appends `bytes` as a new buffer view, compressed with meshopt when
    /// the builder compresses and `layout` allows it.
    fn view_of(
        &mut self,
        bytes: &[u8],
        stride: Option<usize>,
        target: Option<u32>,
        layout: Layout,
    ) -> usize {
        let compressed = if self.meshopt {
            compress(bytes, layout)
        } else {
            None
        };
        self.pad();
        let mut view = match compressed {
            Some(Compressed {
                bytes: compressed,
                stride: extension_stride,
                count,
                mode,
            }) => {
                let fallback_offset = self.fallback_len;
                self.fallback_len += bytes.len().next_multiple_of(4);
                let extension = json!({
                    "buffer": 0,
                    "byteOffset": self.bin.len(),
                    "byteLength": compressed.len(),
                    "byteStride": extension_stride,
                    "count": count,
                    "mode": mode,
                });
                self.bin.extend_from_slice(&compressed);
                json!({
                    "buffer": 1,
                    "byteOffset": fallback_offset,
                    "byteLength": bytes.len(),
                    "extensions": { EXT_MESHOPT_COMPRESSION: extension },
                })
            }
            None => {
                let view = json!({
                    "buffer": 0,
                    "byteOffset": self.bin.len(),
                    "byteLength": bytes.len(),
                });
                self.bin.extend_from_slice(bytes);
                view
            }
        };
        if let Some(stride) = stride {
            view["byteStride"] = stride.into();
        }
        if let Some(target) = target {
            view["target"] = target.into();
        }
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

    /// Adds an accessor of `count` `element`s over `bytes`, appended to the
    /// shared view of its element size (see [`GltfBuilder::groups`]).
    fn grouped(
        &mut self,
        bytes: &[u8],
        element_size: usize,
        element: Element,
        count: usize,
    ) -> Value {
        let at = match self
            .groups
            .iter()
            .position(|g| g.element_size == element_size)
        {
            Some(at) => at,
            None => {
                self.groups.push(Group {
                    element_size,
                    bytes: Vec::new(),
                    accessors: Vec::new(),
                });
                self.groups.len() - 1
            }
        };
        let group = &mut self.groups[at];
        let mut accessor = element.accessor(None, count);
        if !group.bytes.is_empty() {
            accessor["byteOffset"] = group.bytes.len().into();
        }
        group.bytes.extend_from_slice(bytes);
        // The accessor's index is the next one pushed.
        group.accessors.push(self.accessors.len());
        accessor
    }

    /// Writes each group as one buffer view and points its accessors at it.
    fn write_groups(&mut self) {
        for group in std::mem::take(&mut self.groups) {
            let layout = Layout::Vertices {
                element_size: group.element_size,
            };
            let view = self.view_of(
                &group.bytes,
                Some(group.element_size),
                Some(ARRAY_BUFFER),
                layout,
            );
            for accessor in group.accessors {
                self.accessors[accessor]["bufferView"] = view.into();
            }
        }
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

    /// Like [`GltfBuilder::stored`] for vertex attributes whose elements
    /// are `element_size` bytes apart (compressible with meshopt).
    fn stored_vertices(
        &mut self,
        bytes: &[u8],
        element_size: usize,
        padded: bool,
        element: Element,
        count: usize,
    ) -> Value {
        if self.meshopt {
            return self.grouped(bytes, element_size, element, count);
        }
        // A padded element needs its stride spelt out.
        let stride = padded.then_some(element_size);
        let layout = Layout::Vertices { element_size };
        let view = self.view_of(bytes, stride, Some(ARRAY_BUFFER), layout);
        element.accessor(Some(view), count)
    }

    pub(super) fn vec3_f32(&mut self, values: &[[f32; 3]], with_min_max: bool) -> usize {
        let bytes = le_bytes(values.iter().flatten().copied(), f32::to_le_bytes);
        let key = self.key(&format!("vec3 f32 {with_min_max}"), &bytes);
        if let Some(shared) = key.as_deref().and_then(|k| self.recall(k)) {
            return shared;
        }
        let mut accessor = self.stored_vertices(&bytes, 12, false, VEC3_F32, values.len());
        if with_min_max {
            set_min_max(&mut accessor, values);
        }
        let index = self.accessor(accessor);
        match key {
            Some(key) => self.remember(key, index),
            None => index,
        }
    }

    /// A morph-target delta accessor; with [`Encoding::Sparse`] only the
    /// vertices with a non-zero delta are stored, when that is smaller.
    pub(super) fn vec3_f32_target(
        &mut self,
        deltas: &[[f32; 3]],
        with_min_max: bool,
        encoding: Encoding,
    ) -> usize {
        if encoding != Encoding::Sparse {
            return self.vec3_f32(deltas, with_min_max);
        }
        let bytes = le_bytes(deltas.iter().flatten().copied(), f32::to_le_bytes);
        let key = self.key(&format!("sparse vec3 f32 {with_min_max}"), &bytes);
        if let Some(shared) = key.as_deref().and_then(|k| self.recall(k)) {
            return shared;
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
        let index = self.accessor(accessor);
        match key {
            Some(key) => self.remember(key, index),
            None => index,
        }
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
    pub(super) fn vec3_i16(&mut self, values: &[[i16; 3]], with_min_max: bool) -> usize {
        self.uses_quantization = true;
        let padded = values.iter().flat_map(|v| [v[0], v[1], v[2], 0]);
        let bytes = le_bytes(padded, i16::to_le_bytes);
        let key = self.key(&format!("vec3 i16 {with_min_max}"), &bytes);
        if let Some(shared) = key.as_deref().and_then(|k| self.recall(k)) {
            return shared;
        }
        let element = Element::normalized(SHORT, "VEC3");
        let mut accessor = self.stored_vertices(&bytes, 8, true, element, values.len());
        if with_min_max {
            set_min_max(&mut accessor, values);
        }
        let index = self.accessor(accessor);
        match key {
            Some(key) => self.remember(key, index),
            None => index,
        }
    }

    /// Normalized `i8` VEC3, padded to a 4-byte stride.
    pub(super) fn vec3_i8_normalized(&mut self, values: &[[i8; 3]]) -> usize {
        self.uses_quantization = true;
        let padded = values.iter().flat_map(|v| [v[0], v[1], v[2], 0]);
        let bytes = le_bytes(padded, i8::to_le_bytes);
        let element = Element::normalized(BYTE, "VEC3");
        let accessor = self.stored_vertices(&bytes, 4, true, element, values.len());
        self.accessor(accessor)
    }

    pub(super) fn vec2_f32(&mut self, values: &[[f32; 2]]) -> usize {
        let bytes = le_bytes(values.iter().flatten().copied(), f32::to_le_bytes);
        let key = self.key("vec2 f32", &bytes);
        if let Some(shared) = key.as_deref().and_then(|k| self.recall(k)) {
            return shared;
        }
        let element = Element::plain(FLOAT, "VEC2");
        let accessor = self.stored_vertices(&bytes, 8, false, element, values.len());
        let index = self.accessor(accessor);
        match key {
            Some(key) => self.remember(key, index),
            None => index,
        }
    }

    pub(super) fn vec2_u16_normalized(&mut self, values: &[[u16; 2]]) -> usize {
        let bytes = le_bytes(values.iter().flatten().copied(), u16::to_le_bytes);
        let key = self.key("vec2 u16", &bytes);
        if let Some(shared) = key.as_deref().and_then(|k| self.recall(k)) {
            return shared;
        }
        let element = Element::normalized(UNSIGNED_SHORT, "VEC2");
        let accessor = self.stored_vertices(&bytes, 4, false, element, values.len());
        let index = self.accessor(accessor);
        match key {
            Some(key) => self.remember(key, index),
            None => index,
        }
    }

    pub(super) fn indices(&mut self, triangles: &[[u32; 3]], vertex_count: usize) -> usize {
        let flat: Vec<usize> = triangles.iter().flatten().map(|&i| i as usize).collect();
        // At least u16: some graphics APIs have no 8-bit index buffers.
        let component_type = match index_component_type(vertex_count) {
            UNSIGNED_BYTE => UNSIGNED_SHORT,
            other => other,
        };
        let bytes = index_bytes(&flat, component_type);
        let element = Element::plain(component_type, "SCALAR");
        let layout = Layout::Triangles {
            index_size: component_size(component_type),
        };
        let view = self.view_of(&bytes, None, Some(ELEMENT_ARRAY_BUFFER), layout);
        self.accessor(element.accessor(Some(view), flat.len()))
    }

    /// Animation output values, `N` floats per element (a translation or a
    /// rotation quaternion per keyframe), stored as they are.
    pub(super) fn animation_output<const N: usize>(&mut self, values: &[[f32; N]]) -> usize {
        let kind = match N {
            3 => "VEC3",
            _ => "VEC4",
        };
        let bytes = le_bytes(values.iter().flatten().copied(), f32::to_le_bytes);
        let accessor = self.stored(
            &bytes,
            None,
            None,
            Element::plain(FLOAT, kind),
            values.len(),
        );
        self.accessor(accessor)
    }

    pub(super) fn times(&mut self, times: &[f32]) -> usize {
        let bytes = le_bytes(times.iter().copied(), f32::to_le_bytes);
        let mut accessor = self.stored(&bytes, None, None, SCALAR_F32, times.len());
        let first = times.first().copied().unwrap_or(0.0);
        let last = times.last().copied().unwrap_or(0.0);
        accessor["min"] = json!([f32_json(first)]);
        accessor["max"] = json!([f32_json(last)]);
        self.accessor(accessor)
    }

    /// The weights at each exported keyframe: one-hot for targets from the
    /// bud (at keyframe `k >= 1` target `k - 1` has weight 1, all else 0),
    /// cumulative for targets from the previous keyframe (at keyframe `k`
    /// targets `0..k` have weight 1), see [`TargetDeltas`].
    pub(super) fn weights(
        &mut self,
        keyframes: usize,
        targets: usize,
        encoding: Encoding,
        deltas: TargetDeltas,
    ) -> usize {
        let count = keyframes * targets;
        let ones: Vec<usize> = (1..keyframes)
            .flat_map(|k| {
                let first = match deltas {
                    TargetDeltas::FromBud => k - 1,
                    TargetDeltas::FromPrevious => 0,
                };
                (first..k).map(move |t| k * targets + t)
            })
            .collect();
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
                let positions = ones;
                let index_type = index_component_type(count);
                let values = le_bytes(positions.iter().map(|_| 1.0f32), f32::to_le_bytes);
                let mut accessor = SCALAR_F32.accessor(None, count);
                self.add_sparse(&mut accessor, &positions, index_type, &values);
                accessor
            }
            Encoding::Quantized | Encoding::Meshopt => {
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
    pub(super) fn finish(mut self, mut root: Value) -> Result<Vec<u8>, ExportError> {
        self.write_groups();
        self.pad();
        let mut buffers = vec![json!({ "byteLength": self.bin.len() })];
        if self.fallback_len > 0 {
            // The compressed views decode into this buffer; it has no data
            // in the file, so every reader needs the extension.
            buffers.push(json!({
                "byteLength": self.fallback_len,
                "extensions": { EXT_MESHOPT_COMPRESSION: { "fallback": true } },
            }));
            for key in ["extensionsUsed", "extensionsRequired"] {
                let mut names = root[key].as_array().cloned().unwrap_or_default();
                names.push(EXT_MESHOPT_COMPRESSION.into());
                root[key] = Value::Array(names);
            }
        }
        root["buffers"] = Value::Array(buffers);
        root["bufferViews"] = Value::Array(self.views);
        root["accessors"] = Value::Array(self.accessors);
        let mut json_chunk = serde_json::to_vec(&root)?;
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

/// A buffer view's bytes as `EXT_meshopt_compression` stores them, with the
/// extension's `byteStride`, `count` and `mode`.
struct Compressed {
    bytes: Vec<u8>,
    stride: usize,
    count: usize,
    mode: &'static str,
}

/// `bytes` compressed with meshoptimizer for `EXT_meshopt_compression`;
/// `None` when `layout` is not compressible or compression would not make
/// the view smaller.
///
/// Vertex streams use the version 0 vertex codec, the one the extension
/// specifies (meshoptimizer 1.x writes version 1 unless asked);
/// the index codec's version 1 is the extension's.
fn compress(bytes: &[u8], layout: Layout) -> Option<Compressed> {
    let (compressed, stride, mode) = match layout {
        Layout::Raw => return None,
        Layout::Vertices { element_size } => {
            if !bytes.len().is_multiple_of(element_size) {
                return None;
            }
            let compressed = match element_size {
                4 => encode_vertices::<4>(bytes),
                8 => encode_vertices::<8>(bytes),
                12 => encode_vertices::<12>(bytes),
                _ => return None,
            }?;
            (compressed, element_size, "ATTRIBUTES")
        }
        Layout::Triangles { index_size } => {
            let indices: Vec<u32> = match index_size {
                2 => bytes
                    .chunks_exact(2)
                    .map(|c| u32::from(u16::from_le_bytes([c[0], c[1]])))
                    .collect(),
                4 => bytes
                    .chunks_exact(4)
                    .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                    .collect(),
                _ => return None,
            };
            if !indices.len().is_multiple_of(3) {
                return None;
            }
            let vertex_count = indices.iter().max().map_or(0, |&i| i as usize + 1);
            let compressed = meshopt::encode_index_buffer(&indices, vertex_count).ok()?;
            (compressed, index_size, "TRIANGLES")
        }
    };
    (compressed.len() < bytes.len()).then(|| Compressed {
        count: bytes.len() / stride,
        bytes: compressed,
        stride,
        mode,
    })
}

/// Vertex codec version 0 over elements of `N` bytes.
fn encode_vertices<const N: usize>(bytes: &[u8]) -> Option<Vec<u8>> {
    let elements: Vec<[u8; N]> = bytes
        .chunks_exact(N)
        .map(|c| c.try_into().unwrap_or([0; N]))
        .collect();
    meshopt::encode_vertex_buffer_level(&elements, 2, Some(0)).ok()
}

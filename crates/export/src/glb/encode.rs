//! One track's mesh as glTF accessors: base attributes and morph-target
//! deltas, dense, sparse or quantized (`KHR_mesh_quantization`, also the
//! accessors that `EXT_meshopt_compression` compresses).

use glam::{DVec2, DVec3};
use serde_json::{Map, Value};

use super::builder::GltfBuilder;
use crate::prepare::unit_normals;
use crate::{Encoding, GlbOptions, Track};

/// The accessors of one mesh.
pub(super) struct EncodedMesh {
    pub(super) attributes: Map<String, Value>,
    pub(super) indices: usize,
    pub(super) targets: Vec<Value>,
    pub(super) dequantization: Option<QuantizationBox>,
}

/// Quantized positions `q` (normalized `i16`) mean `center + scale * q`;
/// the node's translation and uniform scale apply it.
#[derive(Debug, Clone, Copy)]
pub(super) struct QuantizationBox {
    pub(super) center: [f32; 3],
    pub(super) scale: f32,
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

pub(super) fn encode_mesh(
    gltf: &mut GltfBuilder,
    track: &Track,
    frames: &[Vec<DVec3>],
    options: &GlbOptions,
    tick: &mut dyn FnMut(),
) -> EncodedMesh {
    let base = &frames[0];
    let quantized = matches!(options.encoding, Encoding::Quantized | Encoding::Meshopt);
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

/// `values - base`, vertex by vertex, as `f32`: a morph target's deltas.
fn f32_deltas(values: &[DVec3], base: &[DVec3]) -> Vec<[f32; 3]> {
    values
        .iter()
        .zip(base)
        .map(|(v, v0)| (*v - *v0).as_vec3().to_array())
        .collect()
}

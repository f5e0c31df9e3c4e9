//! One track's mesh as glTF accessors: base attributes and morph-target
//! deltas, dense, sparse or quantized (`KHR_mesh_quantization`, also the
//! accessors that `EXT_meshopt_compression` compresses).

use glam::{DVec2, DVec3};
use serde_json::{Map, Value};

use super::builder::GltfBuilder;
use crate::prepare::unit_normals;
use crate::{Encoding, GlbOptions, Track};

/// What a morph target's deltas are measured from, and so how the
/// animation weights reach a keyframe.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum TargetDeltas {
    /// Target `k - 1` holds keyframe `k` minus the bud (keyframe 0); at
    /// keyframe `k` it alone has weight 1 (one-hot weights). A single target
    /// is a whole keyframe: what Blender shows as one shape key.
    FromBud,
    /// Target `k - 1` holds keyframe `k` minus keyframe `k - 1`; at keyframe
    /// `k` targets `0..k` all have weight 1 (cumulative weights), and
    /// between two keyframes only the later one's target ramps, so playback
    /// still blends the two neighbours linearly. The deltas are small, so
    /// they compress several times better. Quantized, they are differences
    /// of the rounded positions on one grid, so their sum telescopes to the
    /// rounded keyframe: the error does not grow along the animation.
    FromPrevious,
}

impl TargetDeltas {
    /// `FromPrevious` for meshopt (the encoding meant for size), `FromBud`
    /// for the others.
    pub(super) fn of(encoding: Encoding) -> TargetDeltas {
        match encoding {
            Encoding::Meshopt => TargetDeltas::FromPrevious,
            Encoding::Dense | Encoding::Sparse | Encoding::Quantized => TargetDeltas::FromBud,
        }
    }
}

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
    /// The box around every frame that also holds every delta from frame 0
    /// and from the previous frame, so base positions and position deltas
    /// (one-hot or relative, see [`TargetDeltas`]) fit in `[-1, 1]`.
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
        for (k, frame) in frames.iter().enumerate() {
            for (p, p0) in frame.iter().zip(&frames[0]) {
                extent = extent
                    .max((*p - center_f64).abs().max_element())
                    .max((*p - *p0).abs().max_element());
            }
            if k > 0 {
                for (p, previous) in frame.iter().zip(&frames[k - 1]) {
                    // Two units of slack: the difference of two rounded
                    // positions is at most one unit more than their
                    // distance, and must stay within the i16 range.
                    let delta = (*p - *previous).abs().max_element();
                    extent = extent.max(delta * I16_MAX / (I16_MAX - 2.0));
                }
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

    let relative = TargetDeltas::of(options.encoding) == TargetDeltas::FromPrevious;
    // Relative targets keep every normal on the i8 grid (the base included),
    // so their deltas sum exactly to each keyframe's rounded normal.
    let base_normals_i8: Option<Vec<[i8; 3]>> = match &base_normals {
        Some(normals) if relative => Some(normals.iter().map(|n| i8_normal(*n)).collect()),
        _ => None,
    };
    let base_normals_i16: Option<Vec<[i16; 3]>> = match (&base_normals, quantized) {
        (Some(normals), true) if !relative => Some(
            normals
                .iter()
                .map(|n| (*n * I16_MAX).to_array().map(to_i16))
                .collect(),
        ),
        _ => None,
    };
    if let Some(normals) = &base_normals {
        let accessor = match (&base_normals_i8, &base_normals_i16) {
            (Some(units), _) => gltf.vec3_i8_normalized(units),
            (None, Some(units)) => gltf.vec3_i16(units, false),
            (None, None) => gltf.vec3_f32(&to_f32(normals), false),
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

    let targets = match (relative, dequantization, &base_units) {
        (true, Some(qbox), Some(base_units)) => relative_targets(
            gltf,
            track,
            frames,
            qbox,
            base_units,
            base_normals_i8.as_deref(),
            tick,
        ),
        _ => from_bud_targets(
            gltf,
            track,
            frames,
            options.encoding,
            dequantization.zip(base_units.as_deref()),
            base_normals.as_deref().map(|normals| BudNormals {
                normals,
                stored_i16: base_normals_i16.as_deref(),
            }),
            tick,
        ),
    };

    EncodedMesh {
        attributes,
        indices,
        targets,
        dequantization,
    }
}

/// The bud's normals, and their stored `i16` units when quantized.
struct BudNormals<'a> {
    normals: &'a [DVec3],
    stored_i16: Option<&'a [[i16; 3]]>,
}

/// Targets holding each keyframe's deltas from the bud
/// ([`TargetDeltas::FromBud`]): `quantized` is the box and the bud's stored
/// box units when positions are quantized.
fn from_bud_targets(
    gltf: &mut GltfBuilder,
    track: &Track,
    frames: &[Vec<DVec3>],
    encoding: Encoding,
    quantized: Option<(QuantizationBox, &[[i16; 3]])>,
    normals: Option<BudNormals>,
    tick: &mut dyn FnMut(),
) -> Vec<Value> {
    let base = &frames[0];
    let normal_of = |frame: &[DVec3]| unit_normals(frame, &track.triangles);
    let mut targets = Vec::with_capacity(frames.len().saturating_sub(1));
    for frame in &frames[1..] {
        let mut target = Map::new();
        let accessor = match quantized {
            Some((qbox, base_units)) => {
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
            None => gltf.vec3_f32_target(&f32_deltas(frame, base), true, encoding),
        };
        target.insert("POSITION".to_owned(), accessor.into());

        if let Some(bud) = &normals {
            let (base_normals, base_normals_i16) = (bud.normals, bud.stored_i16);
            let normals = normal_of(frame);
            let accessor = match base_normals_i16 {
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
                    gltf.vec3_f32_target(&deltas, false, encoding)
                }
            };
            target.insert("NORMAL".to_owned(), accessor.into());
        }
        targets.push(Value::Object(target));
        tick();
    }
    targets
}

/// Targets holding each keyframe's deltas from the keyframe before
/// ([`TargetDeltas::FromPrevious`]), quantized: position deltas are
/// differences of the rounded `i16` box units of consecutive keyframes,
/// normal deltas differences of the rounded `i8` normals (exact `f32` for a
/// target whose normal deltas leave `[-1, 1]`, which needs a normal to turn
/// by more than about 60 degrees between two exported keyframes).
fn relative_targets(
    gltf: &mut GltfBuilder,
    track: &Track,
    frames: &[Vec<DVec3>],
    qbox: QuantizationBox,
    base_units: &[[i16; 3]],
    base_normals_i8: Option<&[[i8; 3]]>,
    tick: &mut dyn FnMut(),
) -> Vec<Value> {
    let mut previous_units: Vec<[i32; 3]> = base_units.iter().map(|u| u.map(i32::from)).collect();
    let mut previous_normals: Option<Vec<[i32; 3]>> =
        base_normals_i8.map(|units| units.iter().map(|u| u.map(i32::from)).collect());
    let mut targets = Vec::with_capacity(frames.len().saturating_sub(1));
    for frame in &frames[1..] {
        let mut target = Map::new();
        let units: Vec<[i32; 3]> = frame
            .iter()
            .map(|p| qbox.units(*p).to_array().map(|x| i32::from(to_i16(x))))
            .collect();
        // The box holds every step between keyframes, so these fit.
        let deltas: Vec<[i16; 3]> = units
            .iter()
            .zip(&previous_units)
            .map(|(u, v)| [0, 1, 2].map(|i| to_i16(f64::from(u[i] - v[i]))))
            .collect();
        target.insert("POSITION".to_owned(), gltf.vec3_i16(&deltas, true).into());
        previous_units = units;

        if let Some(previous) = &mut previous_normals {
            let normals: Vec<[i32; 3]> = unit_normals(frame, &track.triangles)
                .iter()
                .map(|n| i8_normal(*n).map(i32::from))
                .collect();
            let deltas: Vec<[i32; 3]> = normals
                .iter()
                .zip(previous.iter())
                .map(|(n, m)| [0, 1, 2].map(|i| n[i] - m[i]))
                .collect();
            let fits = |d: &i32| d.unsigned_abs() <= I8_MAX as u32;
            let accessor = if deltas.iter().flatten().all(fits) {
                let units: Vec<[i8; 3]> = deltas
                    .iter()
                    .map(|d| d.map(|x| to_i8(f64::from(x))))
                    .collect();
                gltf.vec3_i8_normalized(&units)
            } else {
                let values: Vec<[f32; 3]> = deltas
                    .iter()
                    .map(|d| d.map(|x| (f64::from(x) / I8_MAX) as f32))
                    .collect();
                gltf.vec3_f32(&values, false)
            };
            target.insert("NORMAL".to_owned(), accessor.into());
            *previous = normals;
        }
        targets.push(Value::Object(target));
        tick();
    }
    targets
}

/// A unit normal on the normalized `i8` grid.
fn i8_normal(n: DVec3) -> [i8; 3] {
    (n * I8_MAX).to_array().map(to_i8)
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

//! The USD writer, for film pipelines (Blender, Houdini, Maya, usdview):
//! text layers (`.usda`, or `.usd`) and binary crate files (`.usdc`).
//!
//! The layer is built and written with the `openusd` crate (a Rust
//! implementation of USD's scene description and file formats) rather than
//! by hand, so quoting, value syntax, metadata and the crate file's layout
//! follow the format. Its version 0.6 (the last that builds with this
//! project's Rust) has two flaws Pixar's USD trips over, both fixed
//! upstream in 0.8 and both repaired here after writing: a one-item
//! `apiSchemas` list loses its brackets in text, and crate files type prim
//! and property child lists as token arrays instead of token vectors (see
//! the `usdc` module).
//!
//! # The stage
//!
//! - Layer metadata: `defaultPrim = "flower"`, `upAxis = "Y"` (the flower
//!   axis), `metersPerUnit = 1`: points are written in metres (each
//!   length times the track's [`Unit::metres`](anthesis_flower::Unit::metres)),
//!   as in the .glb, so the flower imports at its real size whether or not a
//!   client applies `metersPerUnit`, `startTimeCode = 0`,
//!   `endTimeCode = K - 1` and `timeCodesPerSecond = framesPerSecond =` the
//!   keyframes per second: keyframe `k` is time code (frame) `k`.
//! - `/flower` is an `Xform` (kind `component`) holding one `Mesh` per
//!   [`Track`], named after the track made into a valid USD identifier
//!   (`petal-1` becomes `petal_1`), and a `Scope` `/flower/materials`.
//! - Each `Mesh`: `points` (and `normals`, vertex interpolation, unless
//!   [`UsdOptions::normals`] is off) as one time sample per keyframe, or as
//!   a default value for a track that does not move; `extent` likewise;
//!   `faceVertexCounts` (all 3) and `faceVertexIndices`; `primvars:st`
//!   (vertex interpolation, `v = 0` at the organ's base, which is also the
//!   bottom row of a map image as USD expects); `primvars:displayColor` and
//!   `primvars:displayOpacity` (constant, the track's linear base colour;
//!   per vertex, `vertex` interpolation, when the track has a base-colour
//!   texture: the base colour times the texture sampled at the vertex's
//!   UV, bilinear in linear light, as a template's colour map);
//!   `doubleSided = true`, `orientation = "rightHanded"` (triangles wind
//!   counter-clockwise around the inner side's normal) and
//!   `subdivisionScheme = "none"` (the triangles are the surface, not a
//!   subdivision cage).
//! - Each mesh is bound (`MaterialBindingAPI`, `material:binding`) to a
//!   `Material` whose `UsdPreviewSurface` has the base colour as
//!   `diffuseColor`, its alpha as `opacity`, roughness 0.7 and metallic 0,
//!   like the .glb's material. A base-colour texture is written as a PNG
//!   beside the layer (`<layer stem>_textures/<prim>.png`, one per distinct
//!   image, see [`usd_files`]) and read by a `UsdUVTexture` (`colourMap`,
//!   sRGB, clamped, scaled by the base colour) at the mesh's `st`
//!   (`UsdPrimvarReader_float2` `stReader`) into `diffuseColor`.
//! - A track whose sides look different ([`Track::outer_color_png`]) is two
//!   single-sided meshes: its own and `<name>_outer`, which references the
//!   first in this layer (points and extent stored once), winds the
//!   triangles the other way, blocks the normals (clients make them from
//!   the points, facing out) and is bound to a material with the outer
//!   texture.

use std::path::Path;

use glam::DVec3;
use openusd::gf;
use openusd::sdf::{self, ChildrenKey, FieldKey, ListOp, SpecType, Specifier, Value, Variability};

use crate::prepare::{unit_normals, validate_timing, validate_tracks};
use crate::{ExportError, Timing, Track};

/// Whether `path` names a USD file (`.usda`, `.usd` or `.usdc`), so that a
/// caller sends it to [`write_usd`] (which writes text to `.usda` and
/// `.usd`, USD telling text from binary by the contents, and the binary
/// crate form to `.usdc`).
pub fn is_usd_path(path: &Path) -> bool {
    usd_extension(path).is_some_and(|e| matches!(e.as_str(), "usda" | "usd" | "usdc"))
}

fn usd_extension(path: &Path) -> Option<String> {
    Some(path.extension()?.to_str()?.to_ascii_lowercase())
}

/// Options of the USD export.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UsdOptions {
    /// Sets `timeCodesPerSecond` and `framesPerSecond`: keyframes per
    /// second, or the whole animation's length (then the rate is
    /// `(K - 1) / seconds`).
    pub timing: Timing,
    /// Write `normals` (default `true`); without them clients compute
    /// smooth normals themselves.
    pub normals: bool,
}

impl Default for UsdOptions {
    fn default() -> Self {
        Self {
            timing: Timing::FramesPerSecond(crate::DEFAULT_FRAMES_PER_SECOND),
            normals: true,
        }
    }
}

/// Name of the root `Xform` (also the layer's `defaultPrim`).
pub const USD_ROOT_PRIM: &str = "flower";

/// A USD export in memory: the layer and the colour maps it names.
#[derive(Debug, Clone, PartialEq)]
pub struct UsdFiles {
    /// The layer, `.usda` text or a `.usdc` crate file.
    pub layer: Vec<u8>,
    /// Each distinct colour map as a PNG file, by its path relative to the
    /// layer's folder (`<layer stem>_textures/<prim>.png`, the path the
    /// layer's `UsdUVTexture` names with `./` in front).
    pub textures: TextureFiles,
}

/// Files by their path relative to a layer's folder, with their bytes.
pub type TextureFiles = Vec<(String, Vec<u8>)>;

/// The folder beside a layer named `layer_file` that holds its colour maps:
/// `lily.usdc` keeps them in `lily_textures/`.
pub fn usd_texture_folder(layer_file: &Path) -> String {
    let stem = layer_file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    format!("{stem}_textures")
}

/// Builds the USD export of `tracks` in memory for a layer named
/// `layer_file` (which sets the textures' folder, see
/// [`usd_texture_folder`]): `.usdc` binary when `binary`, else `.usda`
/// text. `progress` rises from 0 to 1, about once per keyframe of each
/// track. Fails with a typed error, before any work, on the same invalid
/// input as [`glb_bytes`](crate::glb_bytes).
pub fn usd_files(
    tracks: &[Track],
    options: &UsdOptions,
    layer_file: &Path,
    binary: bool,
    progress: &mut dyn FnMut(f32),
) -> Result<UsdFiles, ExportError> {
    let (layer, textures) =
        build_layer(tracks, options, &usd_texture_folder(layer_file), progress)?;
    let layer = if binary {
        crate::usdc::crate_bytes(&layer.data)?
    } else {
        layer.into_text()?.into_bytes()
    };
    progress(1.0);
    Ok(UsdFiles { layer, textures })
}

/// The `.usda` text of [`usd_files`] for a layer `flower.usda` (its
/// textures, if any, named in `flower_textures/`).
pub fn usd_bytes(
    tracks: &[Track],
    options: &UsdOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<Vec<u8>, ExportError> {
    usd_files(tracks, options, Path::new("flower.usda"), false, progress).map(|f| f.layer)
}

/// The same layer as [`usd_bytes`], as a binary crate file (`.usdc`).
pub fn usdc_bytes(
    tracks: &[Track],
    options: &UsdOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<Vec<u8>, ExportError> {
    usd_files(tracks, options, Path::new("flower.usdc"), true, progress).map(|f| f.layer)
}

/// The layer of [`usd_files`] and its textures, with `progress` rising to
/// 0.95.
fn build_layer(
    tracks: &[Track],
    options: &UsdOptions,
    texture_folder: &str,
    progress: &mut dyn FnMut(f32),
) -> Result<(LayerBuilder, TextureFiles), ExportError> {
    let keyframe_count = validate_tracks(tracks)?;
    validate_timing(options.timing)?;
    let frames_per_second = match options.timing {
        Timing::FramesPerSecond(fps) => fps,
        Timing::Duration(seconds) => (keyframe_count.max(2) - 1) as f64 / seconds,
    };
    if !(frames_per_second.is_finite() && frames_per_second > 0.0) {
        return Err(ExportError::InvalidOptions(format!(
            "{:?} gives no usable frame rate for {keyframe_count} keyframes",
            options.timing
        )));
    }
    progress(0.0);

    let mut layer = LayerBuilder::new();
    write_stage_metadata(&mut layer, keyframe_count, frames_per_second)?;
    let names = prim_names(tracks);
    let flower = layer.prim(&sdf::Path::abs_root(), USD_ROOT_PRIM, "Xform")?;
    layer.set_field(&flower, FieldKey::Kind, Value::Token("component".into()))?;
    let materials = layer.prim(&flower, "materials", "Scope")?;

    let total_work = tracks
        .iter()
        .map(|t| t.keyframes.len())
        .sum::<usize>()
        .max(1) as f32;
    let mut work_done = 0usize;
    let mut textures = TextureFiles::new();
    for (index, (track, name)) in tracks.iter().zip(&names).enumerate() {
        let mut sides = vec![(track.clone(), name.clone())];
        if let Some(outer) = &track.outer_colour_png {
            // The outer side: the same surface wound the other way, with
            // the outer texture (each side's mesh single-sided).
            sides.push((
                Track {
                    triangles: track.triangles.iter().map(|&[a, b, c]| [a, c, b]).collect(),
                    base_colour_png: Some(outer.clone()),
                    ..track.clone()
                },
                format!("{name}_outer"),
            ));
        }
        let mut inner_mesh: Option<sdf::Path> = None;
        for (side, name) in &sides {
            let colours = crate::colour::vertex_colours(side).map_err(|problem| {
                ExportError::InvalidTrack {
                    track: index,
                    name: track.name.clone(),
                    problem,
                }
            })?;
            let texture = side
                .base_colour_png
                .as_ref()
                .map(|png| texture_file(&mut textures, texture_folder, name, png));
            let material = write_material(
                &mut layer,
                &materials,
                name,
                side.base_colour,
                texture.as_deref(),
            )?;
            let mesh = layer.prim(&flower, name, "Mesh")?;
            match &inner_mesh {
                None => {
                    write_mesh(
                        &mut layer,
                        &mesh,
                        &material,
                        side,
                        colours.as_deref(),
                        options.normals,
                        &mut || {
                            work_done += 1;
                            progress(0.95 * work_done as f32 / total_work);
                        },
                    )?;
                    inner_mesh = Some(mesh);
                }
                Some(inner) => {
                    write_outer_mesh(&mut layer, &mesh, inner, &material, side, colours)?;
                }
            }
        }
    }
    Ok((layer, textures))
}

/// The outer side of a two-sided track: a mesh that references the inner
/// side's `inner` mesh in this layer (so its points and extent are stored
/// once) and overrides the triangles (`outer`'s, wound the other way), its
/// colours, its material, and blocks the inner side's normals (clients make
/// them from the points, facing out with the reversed winding).
fn write_outer_mesh(
    layer: &mut LayerBuilder,
    mesh: &sdf::Path,
    inner: &sdf::Path,
    material: &sdf::Path,
    outer: &Track,
    colours: Option<Vec<[f32; 4]>>,
) -> Result<(), ExportError> {
    let reference = sdf::Reference {
        prim_path: inner.clone(),
        ..sdf::Reference::default()
    };
    layer.set_field(
        mesh,
        FieldKey::References,
        Value::ReferenceListOp(ListOp::prepended([reference])),
    )?;
    face_vertex_indices(layer, mesh, &outer.triangles)?;
    layer.attribute(mesh, "normals", "normal3f[]", None, Value::ValueBlock)?;
    if let Some(colours) = colours {
        let rgb = colours
            .iter()
            .map(|c| gf::vec3f(c[0], c[1], c[2]))
            .collect();
        let colour = layer.attribute(
            mesh,
            "primvars:displayColor",
            "color3f[]",
            None,
            Value::Vec3fVec(rgb),
        )?;
        layer.set_field(&colour, "interpolation", Value::Token("vertex".into()))?;
    }
    layer.relationship(mesh, "material:binding", material)
}

/// The asset path (`./<folder>/<name>.png`) of `png`, added to `textures`
/// unless the same PNG is there already (organs of one template share it).
fn texture_file(textures: &mut TextureFiles, folder: &str, name: &str, png: &[u8]) -> String {
    let file = match textures.iter().find(|(_, bytes)| bytes == png) {
        Some((file, _)) => file.clone(),
        None => {
            let file = format!("{folder}/{name}.png");
            textures.push((file.clone(), png.to_vec()));
            file
        }
    };
    format!("./{file}")
}

/// The layer's metadata: default prim, +Y up, metres, the time codes.
fn write_stage_metadata(
    layer: &mut LayerBuilder,
    keyframe_count: usize,
    frames_per_second: f64,
) -> Result<(), ExportError> {
    let root = layer.pseudo_root()?;
    root.add(FieldKey::DefaultPrim, Value::Token(USD_ROOT_PRIM.into()));
    root.add("upAxis", Value::Token("Y".into()));
    root.add("metersPerUnit", Value::Double(1.0));
    root.add(FieldKey::StartTimeCode, Value::Double(0.0));
    root.add(
        FieldKey::EndTimeCode,
        Value::Double((keyframe_count - 1) as f64),
    );
    root.add(
        FieldKey::TimeCodesPerSecond,
        Value::Double(frames_per_second),
    );
    root.add(FieldKey::FramesPerSecond, Value::Double(frames_per_second));
    root.add(
        FieldKey::Documentation,
        Value::String(concat!("Anthesis (anthesis-export ", env!("CARGO_PKG_VERSION"), ")").into()),
    );
    Ok(())
}

/// Builds the USD export (see [`usd_files`]) and writes it to `path`: the
/// colour maps first, into [`usd_texture_folder`] beside it (made when
/// missing), then the layer, each atomically (see
/// [`anthesis_files::write_atomic`]): an existing file is replaced only by
/// a completely written one. A `.usda` or `.usd` file gets the text form,
/// a `.usdc` file the binary crate form.
pub fn write_usd(
    path: &Path,
    tracks: &[Track],
    options: &UsdOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(), ExportError> {
    check_usd_destination(path)?;
    let binary = usd_extension(path).as_deref() == Some("usdc");
    let files = usd_files(tracks, options, path, binary, progress)?;
    let folder = path.parent().unwrap_or(Path::new(""));
    for (relative, png) in &files.textures {
        let file = folder.join(relative);
        if let Some(parent) = file.parent() {
            anthesis_files::create_folder(parent, &file)?;
        }
        anthesis_files::write_atomic(&file, png)?;
    }
    Ok(anthesis_files::write_atomic(path, &files.layer)?)
}

/// The checks [`write_usd`] makes before any work, for callers that want
/// to fail before a long simulation: the file name ends in `.usda`, `.usd`
/// or `.usdc`, and its folder exists and is a folder.
pub fn check_usd_destination(path: &Path) -> Result<(), ExportError> {
    match usd_extension(path).as_deref() {
        Some("usda" | "usd" | "usdc") => Ok(anthesis_files::check_destination(path)?),
        _ => Err(ExportError::InvalidOptions(format!(
            "{} does not end in .usda, .usd or .usdc",
            path.display()
        ))),
    }
}

/// Valid, distinct USD prim names for the tracks: every character that is
/// not an ASCII letter, digit or `_` becomes `_`, a leading digit gets a
/// `_` in front, and repeats get `_2`, `_3`, … (`materials` is taken by the
/// materials scope).
fn prim_names(tracks: &[Track]) -> Vec<String> {
    let mut taken = vec!["materials".to_owned()];
    tracks
        .iter()
        .map(|track| {
            let mut base: String = track
                .name
                .chars()
                .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
                .collect();
            if base.is_empty() || base.starts_with(|c: char| c.is_ascii_digit()) {
                base.insert(0, '_');
            }
            let mut name = base.clone();
            let mut n = 2;
            while taken.contains(&name) {
                name = format!("{base}_{n}");
                n += 1;
            }
            taken.push(name.clone());
            name
        })
        .collect()
}

fn vec3f(v: DVec3) -> gf::Vec3f {
    let v = v.as_vec3();
    gf::vec3f(v.x, v.y, v.z)
}

/// `values` times `scale` as single-precision vectors.
fn vec3fs(values: &[DVec3], scale: f64) -> Value {
    Value::Vec3fVec(values.iter().map(|&v| vec3f(v * scale)).collect())
}

/// `[min, max]` of the points times `scale`, as USD's `extent` wants it.
fn extent(points: &[DVec3], scale: f64) -> Value {
    let (mut min, mut max) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for p in points {
        min = min.min(*p * scale);
        max = max.max(*p * scale);
    }
    Value::Vec3fVec(vec![vec3f(min), vec3f(max)])
}

/// A value that is either constant or sampled once per keyframe (at time
/// code `k` for keyframe `k`).
enum Sampled {
    Constant(Value),
    PerKeyframe(Vec<Value>),
}

impl Sampled {
    fn of(frames: &[Vec<DVec3>], mut value: impl FnMut(&[DVec3]) -> Value) -> Sampled {
        match frames {
            [only] => Sampled::Constant(value(only)),
            _ => Sampled::PerKeyframe(frames.iter().map(|f| value(f)).collect()),
        }
    }
}

fn write_mesh(
    layer: &mut LayerBuilder,
    mesh: &sdf::Path,
    material: &sdf::Path,
    track: &Track,
    colours: Option<&[[f32; 4]]>,
    normals: bool,
    tick: &mut dyn FnMut(),
) -> Result<(), ExportError> {
    layer.set_field(
        mesh,
        FieldKey::ApiSchemas,
        Value::TokenListOp(ListOp::prepended(["MaterialBindingAPI".into()])),
    )?;
    let uniform = Some(Variability::Uniform);
    // A track whose sides look different is two single-sided meshes.
    let double_sided = track.outer_colour_png.is_none();
    layer.attribute(
        mesh,
        "doubleSided",
        "bool",
        uniform,
        Value::Bool(double_sided),
    )?;
    layer.attribute(
        mesh,
        "orientation",
        "token",
        uniform,
        Value::Token("rightHanded".into()),
    )?;
    layer.attribute(
        mesh,
        "subdivisionScheme",
        "token",
        uniform,
        Value::Token("none".into()),
    )?;
    layer.attribute(
        mesh,
        "faceVertexCounts",
        "int[]",
        None,
        Value::IntVec(vec![3; track.triangles.len()]),
    )?;
    face_vertex_indices(layer, mesh, &track.triangles)?;

    let frames = &track.keyframes;
    let metres = track.unit.metres();
    let points = Sampled::of(frames, |f| {
        tick();
        vec3fs(f, metres)
    });
    layer.sampled_attribute(mesh, "points", "point3f[]", points)?;
    let extents = Sampled::of(frames, |f| extent(f, metres));
    layer.sampled_attribute(mesh, "extent", "float3[]", extents)?;
    if normals {
        let values = Sampled::of(frames, |f| vec3fs(&unit_normals(f, &track.triangles), 1.0));
        let normals = layer.sampled_attribute(mesh, "normals", "normal3f[]", values)?;
        layer.set_field(&normals, "interpolation", Value::Token("vertex".into()))?;
    }

    let st: Vec<gf::Vec2f> = track
        .uvs
        .iter()
        .map(|uv| {
            let uv = uv.as_vec2();
            gf::vec2f(uv.x, uv.y)
        })
        .collect();
    let st = layer.attribute(
        mesh,
        "primvars:st",
        "texCoord2f[]",
        None,
        Value::Vec2fVec(st),
    )?;
    layer.set_field(&st, "interpolation", Value::Token("vertex".into()))?;

    // One colour, or one per vertex from the colour map.
    let (rgb, alpha, interpolation) = match colours {
        None => {
            let [r, g, b, a] = track.base_colour;
            (vec![gf::vec3f(r, g, b)], vec![a], "constant")
        }
        Some(colours) => (
            colours
                .iter()
                .map(|c| gf::vec3f(c[0], c[1], c[2]))
                .collect(),
            colours.iter().map(|c| c[3]).collect(),
            "vertex",
        ),
    };
    let colour = layer.attribute(
        mesh,
        "primvars:displayColor",
        "color3f[]",
        None,
        Value::Vec3fVec(rgb),
    )?;
    layer.set_field(&colour, "interpolation", Value::Token(interpolation.into()))?;
    let opacity = layer.attribute(
        mesh,
        "primvars:displayOpacity",
        "float[]",
        None,
        Value::FloatVec(alpha),
    )?;
    layer.set_field(
        &opacity,
        "interpolation",
        Value::Token(interpolation.into()),
    )?;

    layer.relationship(mesh, "material:binding", material)?;
    Ok(())
}

/// A `Material` with a `UsdPreviewSurface` of `color` under `scope`;
/// returns the material's path. With a `texture` (an asset path), its
/// `diffuseColor` comes from a `UsdUVTexture` of that file (sRGB, clamped,
/// scaled by `color`) read at the mesh's `st` by a
/// `UsdPrimvarReader_float2`; `color` stays its value where shader
/// networks are not followed (and the mesh's per-vertex `displayColor`
/// where materials are not).
fn write_material(
    layer: &mut LayerBuilder,
    scope: &sdf::Path,
    name: &str,
    colour: [f32; 4],
    texture: Option<&str>,
) -> Result<sdf::Path, ExportError> {
    let material = layer.prim(scope, name, "Material")?;
    let shader = layer.prim(&material, "surface", "Shader")?;
    layer.shader_id(&shader, "UsdPreviewSurface")?;
    let [r, g, b, a] = colour;
    let diffuse = layer.attribute(
        &shader,
        "inputs:diffuseColor",
        "color3f",
        None,
        Value::Vec3f(gf::vec3f(r, g, b)),
    )?;
    if let Some(file) = texture {
        let rgb = write_texture(layer, &material, file, colour)?;
        layer.set_field(
            &diffuse,
            FieldKey::ConnectionPaths,
            Value::PathListOp(ListOp::explicit([rgb])),
        )?;
    }
    layer.attribute(&shader, "inputs:opacity", "float", None, Value::Float(a))?;
    layer.attribute(
        &shader,
        "inputs:roughness",
        "float",
        None,
        Value::Float(0.7),
    )?;
    layer.attribute(&shader, "inputs:metallic", "float", None, Value::Float(0.0))?;
    let shader_output = layer.declared_attribute(&shader, "outputs:surface", "token")?;
    let material_output = layer.declared_attribute(&material, "outputs:surface", "token")?;
    layer.set_field(
        &material_output,
        FieldKey::ConnectionPaths,
        Value::PathListOp(ListOp::explicit([shader_output])),
    )?;
    Ok(material)
}

/// The texture network under `material`: a `UsdPrimvarReader_float2` of
/// `st` feeding a `UsdUVTexture` of `file`; returns the texture's
/// `outputs:rgb`.
fn write_texture(
    layer: &mut LayerBuilder,
    material: &sdf::Path,
    file: &str,
    colour: [f32; 4],
) -> Result<sdf::Path, ExportError> {
    let reader = layer.prim(material, "stReader", "Shader")?;
    layer.shader_id(&reader, "UsdPrimvarReader_float2")?;
    layer.attribute(
        &reader,
        "inputs:varname",
        "string",
        None,
        Value::String("st".into()),
    )?;
    let st = layer.declared_attribute(&reader, "outputs:result", "float2")?;
    let texture = layer.prim(material, "colourMap", "Shader")?;
    layer.shader_id(&texture, "UsdUVTexture")?;
    layer.attribute(
        &texture,
        "inputs:file",
        "asset",
        None,
        Value::AssetPath(file.into()),
    )?;
    let st_input = layer.declared_attribute(&texture, "inputs:st", "float2")?;
    layer.set_field(
        &st_input,
        FieldKey::ConnectionPaths,
        Value::PathListOp(ListOp::explicit([st])),
    )?;
    let token = |t: &str| Value::Token(t.into());
    layer.attribute(
        &texture,
        "inputs:sourceColorSpace",
        "token",
        None,
        token("sRGB"),
    )?;
    layer.attribute(&texture, "inputs:wrapS", "token", None, token("clamp"))?;
    layer.attribute(&texture, "inputs:wrapT", "token", None, token("clamp"))?;
    let [r, g, b, a] = colour;
    layer.attribute(
        &texture,
        "inputs:scale",
        "float4",
        None,
        Value::Vec4f(gf::vec4f(r, g, b, a)),
    )?;
    layer.declared_attribute(&texture, "outputs:a", "float")?;
    layer.declared_attribute(&texture, "outputs:rgb", "float3")
}

/// An `sdf::Data` layer built top-down, keeping each spec's lists of prim
/// and property children as USD requires.
struct LayerBuilder {
    data: sdf::Data,
}

fn usd_error(error: impl std::fmt::Display) -> ExportError {
    ExportError::Usd(error.to_string())
}

impl LayerBuilder {
    /// A layer holding only its pseudo-root.
    fn new() -> LayerBuilder {
        let mut data = sdf::Data::new();
        data.create_spec(sdf::Path::abs_root(), SpecType::PseudoRoot);
        LayerBuilder { data }
    }

    /// The spec of the layer's metadata and root prims.
    fn pseudo_root(&mut self) -> Result<&mut sdf::SpecData, ExportError> {
        self.spec(&sdf::Path::abs_root())
    }

    /// The spec at `path`, which this builder created before.
    fn spec(&mut self, path: &sdf::Path) -> Result<&mut sdf::SpecData, ExportError> {
        self.data
            .spec_mut(path)
            .ok_or_else(|| ExportError::Usd(format!("no spec at {path} to edit")))
    }

    fn set_field(
        &mut self,
        path: &sdf::Path,
        key: impl AsRef<str>,
        value: Value,
    ) -> Result<(), ExportError> {
        self.spec(path)?.add(key, value);
        Ok(())
    }

    /// Appends `name` to the `children` list of `parent`.
    fn add_child(
        &mut self,
        parent: &sdf::Path,
        children: ChildrenKey,
        name: &str,
    ) -> Result<(), ExportError> {
        let spec = self.spec(parent)?;
        match spec.get_mut(children.as_str()) {
            Some(Value::TokenVec(names)) => names.push(name.into()),
            _ => spec.add(children, Value::TokenVec(vec![name.into()])),
        }
        Ok(())
    }

    /// Defines a prim `name` of `type_name` under `parent`.
    fn prim(
        &mut self,
        parent: &sdf::Path,
        name: &str,
        type_name: &str,
    ) -> Result<sdf::Path, ExportError> {
        let path = parent.append_path(name).map_err(usd_error)?;
        let spec = self.data.create_spec(path.clone(), SpecType::Prim);
        spec.add(FieldKey::Specifier, Value::Specifier(Specifier::Def));
        spec.add(FieldKey::TypeName, Value::Token(type_name.into()));
        self.add_child(parent, ChildrenKey::PrimChildren, name)?;
        Ok(path)
    }

    /// A shader's uniform `info:id`.
    fn shader_id(&mut self, shader: &sdf::Path, id: &str) -> Result<(), ExportError> {
        self.attribute(
            shader,
            "info:id",
            "token",
            Some(Variability::Uniform),
            Value::Token(id.into()),
        )
        .map(|_| ())
    }

    /// A non-custom attribute of `type_name` without a value (an output).
    fn declared_attribute(
        &mut self,
        prim: &sdf::Path,
        name: &str,
        type_name: &str,
    ) -> Result<sdf::Path, ExportError> {
        let path = prim.append_property(name).map_err(usd_error)?;
        let spec = self.data.create_spec(path.clone(), SpecType::Attribute);
        spec.add(FieldKey::TypeName, Value::Token(type_name.into()));
        spec.add(FieldKey::Custom, Value::Bool(false));
        self.add_child(prim, ChildrenKey::PropertyChildren, name)?;
        Ok(path)
    }

    /// A non-custom attribute with a default value.
    fn attribute(
        &mut self,
        prim: &sdf::Path,
        name: &str,
        type_name: &str,
        variability: Option<Variability>,
        value: Value,
    ) -> Result<sdf::Path, ExportError> {
        let path = self.declared_attribute(prim, name, type_name)?;
        if let Some(variability) = variability {
            self.set_field(
                &path,
                FieldKey::Variability,
                Value::Variability(variability),
            )?;
        }
        self.set_field(&path, FieldKey::Default, value)?;
        Ok(path)
    }

    /// An attribute with a default value or one time sample per keyframe.
    fn sampled_attribute(
        &mut self,
        prim: &sdf::Path,
        name: &str,
        type_name: &str,
        value: Sampled,
    ) -> Result<sdf::Path, ExportError> {
        match value {
            Sampled::Constant(value) => self.attribute(prim, name, type_name, None, value),
            Sampled::PerKeyframe(values) => {
                let path = self.declared_attribute(prim, name, type_name)?;
                let samples = values
                    .into_iter()
                    .enumerate()
                    .map(|(k, v)| (k as f64, v))
                    .collect();
                self.set_field(&path, FieldKey::TimeSamples, Value::TimeSamples(samples))?;
                Ok(path)
            }
        }
    }

    /// A relationship `name` on `prim` targeting `target`.
    fn relationship(
        &mut self,
        prim: &sdf::Path,
        name: &str,
        target: &sdf::Path,
    ) -> Result<(), ExportError> {
        let path = prim.append_property(name).map_err(usd_error)?;
        let spec = self.data.create_spec(path, SpecType::Relationship);
        spec.add(FieldKey::Custom, Value::Bool(false));
        spec.add(
            FieldKey::TargetPaths,
            Value::PathListOp(ListOp::explicit([target.clone()])),
        );
        self.add_child(prim, ChildrenKey::PropertyChildren, name)?;
        Ok(())
    }

    fn into_text(self) -> Result<String, ExportError> {
        let text = openusd::usda::TextWriter::write_to_string(&self.data).map_err(usd_error)?;
        Ok(bracket_single_api_schemas(&text))
    }
}

/// openusd 0.6 writes a one-item token list op without brackets
/// (`prepend apiSchemas = "MaterialBindingAPI"`), which USD's text parser
/// rejects (it wants `["MaterialBindingAPI"]`; fixed in openusd 0.8, which
/// needs a newer Rust than this project's). Adds the brackets on the
/// `apiSchemas` lines, the only token list op this writer authors.
fn bracket_single_api_schemas(text: &str) -> String {
    let mut fixed = String::with_capacity(text.len() + 64);
    for line in text.lines() {
        let unbracketed = line
            .split_once("prepend apiSchemas = \"")
            .filter(|(indent, rest)| indent.trim().is_empty() && !rest.contains(','));
        match unbracketed {
            Some((indent, rest)) => {
                fixed.push_str(&format!("{indent}prepend apiSchemas = [\"{rest}]"));
            }
            None => fixed.push_str(line),
        }
        fixed.push('\n');
    }
    fixed
}

/// A mesh prim's `faceVertexIndices`: its triangles' corners in order.
fn face_vertex_indices(
    layer: &mut LayerBuilder,
    mesh: &sdf::Path,
    triangles: &[[u32; 3]],
) -> Result<(), ExportError> {
    let indices: Vec<i32> = triangles
        .iter()
        .flatten()
        .map(|&i| i32::try_from(i).unwrap_or(i32::MAX))
        .collect();
    layer.attribute(
        mesh,
        "faceVertexIndices",
        "int[]",
        None,
        Value::IntVec(indices),
    )?;
    Ok(())
}

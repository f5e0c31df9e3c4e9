//! Exports a simulated flower: an animated glTF binary (.glb) with one morph
//! target per keyframe, a USD layer (.usda text or .usdc binary) with one
//! time-sampled mesh per organ (see [`write_usd`]), and one Wavefront OBJ
//! per keyframe, each file
//! written with [`anthesis_files::write_atomic`].
//!
//! [`organ_tracks`] turns a simulation's keyframes into one [`Track`] per
//! organ and [`Track::still`] makes the track of a mesh that does not move
//! (the receptacle).
//!
//! # The .glb
//!
//! Every [`Track`] (an organ, or the static receptacle) becomes one node and
//! one mesh with one triangle primitive, both named after the track:
//! - the base attributes are keyframe 0 (the bud): `POSITION`, `NORMAL`
//!   (area-weighted vertex normals computed in `f64`, stored as `f32`),
//!   `TEXCOORD_0` and the triangle indices. Positions are in the world frame
//!   (flower axis +Y, receptacle centre at the origin);
//! - each later keyframe `k` is morph target `k - 1`, holding `POSITION` and
//!   (optionally) `NORMAL` deltas from keyframe 0; `mesh.extras.targetNames`
//!   names them (`keyframe 7`, or `keyframe 6.93` for resampled ones);
//! - one animation drives every animated mesh's `weights` with `LINEAR`
//!   interpolation; at time `t_0` all weights are zero and at `t_k` target
//!   `k - 1` has weight 1 and the others 0, so playback blends two
//!   consecutive keyframes linearly, just like the application's timeline;
//! - except with [`Encoding::Meshopt`], whose targets hold the step from
//!   keyframe `k - 1` to `k` (compressing several times better) and whose
//!   weights are cumulative: at `t_k` targets `0..k` have weight 1, so the
//!   steps add up to keyframe `k`, and between `t_k` and `t_k+1` only target
//!   `k` ramps, which blends the two keyframes linearly as well;
//! - a material per track: `baseColorFactor` = [`Track::base_color`],
//!   optionally a PNG base-colour texture, non-metallic, double-sided (organs
//!   are thin sheets seen from both sides).
//!
//! glTF puts the image origin at the top-left while Anthesis puts `v = 0` on
//! the bottom row of its images, so `TEXCOORD_0` stores `(u, 1 - v)`: a
//! growth map exported as PNG lands on the organ exactly as in the app.
//!
//! Tracks with a single keyframe (the receptacle) get no morph targets and
//! no animation channel.
//!
//! ## Client limits
//!
//! three.js stores each morph target as one layer of a `DataArrayTexture`;
//! WebGL 2 guarantees only 256 layers (`MAX_ARRAY_TEXTURE_LAYERS`), and its
//! shaders keep one uniform per target influence, so the default cap is
//! [`GlbOptions::max_morph_targets`] = 250. With more keyframes than that,
//! the sequence is resampled uniformly in time (linear interpolation between
//! neighbouring keyframes) to `max + 1` keyframes; the animation keeps its
//! duration. Blender imports morph targets as shape keys (the weights
//! animation becomes shape-key F-curves) and has no such hard limit, but
//! import time grows with the target count.
//!
//! See [`Encoding`] for the three storage modes and [`glb_size_report`] for
//! the file size in each.

#![warn(missing_docs)]

mod between;
mod colour;
mod error;
mod glb;
mod obj;
mod prepare;
mod report;
mod tracks;
mod usd;
mod usdc;

use std::path::Path;

use anthesis_flower::Unit;
use glam::{DQuat, DVec2, DVec3};

pub use between::KeyframeBlend;
pub use colour::{colour_png, colour_png_on};
pub use error::{ExportError, TrackProblem};
pub use glb::glb_bytes;
pub use obj::{obj_file_name, write_obj_sequence};
pub use report::{GlbSize, GlbSizeReport, glb_size_report};
pub use tracks::{
    MAX_RENDER_POSITIONS, TrackLook, check_render_level, flower_tracks, organ_tracks, part_track,
};
pub use usd::{
    USD_ROOT_PRIM, UsdFiles, UsdOptions, check_usd_destination, is_usd_path, usd_bytes, usd_files,
    usd_texture_folder, usdc_bytes, write_usd,
};

/// One organ (or the receptacle) over time: a fixed triangulation and UV
/// layout, and its positions at every keyframe in the world frame.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Track {
    /// Node and mesh name in the .glb, object name (`o`) in OBJ files.
    pub name: String,
    /// Triangles, counter-clockwise around the inner-side normal.
    pub triangles: Vec<[u32; 3]>,
    /// One UV per vertex (Anthesis convention: `v = 0` at the base).
    pub uvs: Vec<DVec2>,
    /// Linear RGBA in `[0, 1]`; an alpha below 1 makes the material blended.
    pub base_colour: [f32; 4],
    /// Positions per keyframe: `keyframes[0]` is the bud (keyframe 0); a
    /// static mesh such as the receptacle has exactly one keyframe.
    pub keyframes: Vec<Vec<DVec3>>,
    /// Optional base-colour texture as the bytes of a PNG file, multiplied
    /// by `base_color` (so use white there to show the texture as it is).
    pub base_colour_png: Option<Vec<u8>>,
    /// Set when the track moves as a rigid body (a part turned by its
    /// schedule): `keyframes[k][i]` is `poses[k]` applied to `local[i]`.
    /// The .glb then animates the node's translation and rotation instead
    /// of storing a morph target per keyframe; other formats use
    /// `keyframes`.
    pub rigid: Option<RigidMotion>,
    /// What one length of `keyframes` (and `rigid`) is in the real world:
    /// the .glb and USD layers write metres (each length times
    /// [`Unit::metres`]), OBJ files the lengths as they are with the unit
    /// in a comment. Default one metre.
    pub unit: Unit,
    /// The outer side's base-colour texture (a PNG), when the sides look
    /// different (a template's colour layer on one side only):
    /// `base_color_png` is then the inner side's. The .glb gives such a
    /// mesh a second primitive of the same triangles wound the other way
    /// with this texture, the USD layer a second mesh `<name>_outer`, each
    /// side single-sided, so every client shows each side its own colours.
    pub outer_colour_png: Option<Vec<u8>>,
}

/// A rigid track's mesh in its own frame and its pose at every keyframe.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RigidMotion {
    /// Positions in the track's own frame.
    pub local: Vec<DVec3>,
    /// One pose per keyframe: world = translation + rotation · local.
    pub poses: Vec<Pose>,
}

/// A rigid placement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Where the local origin goes.
    pub translation: DVec3,
    /// A unit quaternion.
    pub rotation: DQuat,
}

impl Pose {
    /// The pose a fraction `t` of the way from `self` to `other` (linear
    /// translation, spherical rotation, as glTF players interpolate).
    pub fn towards(&self, other: &Pose, t: f64) -> Pose {
        Pose {
            translation: self.translation.lerp(other.translation, t),
            rotation: self.rotation.slerp(other.rotation, t),
        }
    }
}

/// How keyframes map to animation time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Timing {
    /// Keyframes per second: keyframe `k` plays at `k / fps` seconds.
    FramesPerSecond(f64),
    /// Seconds for the whole animation: keyframe `k` of `K` plays at
    /// `k * duration / (K - 1)`.
    Duration(f64),
}

/// How the .glb stores its data. All pass the Khronos validator with no
/// errors and no warnings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Encoding {
    /// Everything as `f32` (indices as `u16`/`u32`): the most widely
    /// supported form.
    Dense,
    /// Like `Dense`, but each morph-target accessor stores only the vertices
    /// whose delta is not exactly zero (a sparse accessor without a buffer
    /// view) when that is smaller than storing every vertex; the one-hot
    /// animation weights are stored sparsely too. Saves space when parts of
    /// the flower stay still (pinned bases, a late-opening whorl); with every
    /// vertex moving it is the same size as `Dense`.
    Sparse,
    /// `KHR_mesh_quantization` (listed in `extensionsRequired`): positions
    /// and position deltas as normalized `i16` in a per-mesh box that the
    /// node's translation and uniform scale undo (error below 1/65534 of the
    /// box size), base normals as normalized `i16`, normal deltas as
    /// normalized `i8` (as `f32` for a target whose deltas leave `[-1, 1]`),
    /// UVs as normalized `u16` when they lie in `[0, 1]`, and the animation
    /// weights as normalized `u8` (exact for 0 and 1). About 55 % of the
    /// size of `Dense` with normals, 70 % without. three.js and Blender
    /// import the extension; Blender shows the dequantization as the
    /// object's scale and location (the mesh itself spans `[-1, 1]`).
    Quantized,
    /// Quantized like `Quantized`, with morph targets holding the step from
    /// the previous keyframe (cumulative weights, see the crate
    /// documentation) and every vertex and index buffer view compressed by
    /// meshoptimizer (`EXT_meshopt_compression`, required: the file holds
    /// only the compressed bytes). Position steps are differences of the
    /// keyframes' rounded `i16` box positions, so they add up to each
    /// keyframe within half a grid step however many there are; normals
    /// (the bud's and every step) live on the normalized `i8` grid, so the
    /// steps add up exactly to each keyframe's rounded normal (within
    /// 0.004 per component). A normal step leaves `[-1, 1]` only when a
    /// normal turns by about 60 degrees between two keyframes; such a
    /// target's normal steps are stored as exact `f32` rather than clamped
    /// (clamping shades curled petal tips wrongly). three.js decodes it
    /// with its `MeshoptDecoder` (`GLTFLoader.setMeshoptDecoder`); three.js
    /// sizes a mesh's bounds as if one target at a time were on, so with
    /// steps they cover the bud and one step: set `frustumCulled = false`
    /// on the meshes for close-ups. Blender (3.4 and 4.5: "Extension
    /// EXT_meshopt_compression is not available") and the `gltf` crate do
    /// not read it.
    Meshopt,
}

impl Encoding {
    /// Every encoding, in the order the documentation lists them.
    pub const ALL: [Encoding; 4] = [
        Encoding::Dense,
        Encoding::Sparse,
        Encoding::Quantized,
        Encoding::Meshopt,
    ];

    /// Which clients import a file of this encoding, as checked by this
    /// project's tests and by hand (three.js r187, Blender 4.5 LTS as a
    /// Python module and Blender 3.4), for export dialogs.
    pub fn clients(&self) -> &'static str {
        match self {
            Encoding::Dense | Encoding::Sparse => {
                "opens everywhere: three.js, Blender 3.4 and 4.5, any glTF 2.0 reader"
            }
            Encoding::Quantized => {
                "three.js and Blender 3.4 and 4.5 (Blender shows the dequantization as the \
                 object's scale)"
            }
            Encoding::Meshopt => {
                "three.js with its MeshoptDecoder only: Blender (3.4 and 4.5) cannot import \
                 it, so export quantized for Blender"
            }
        }
    }
}

impl std::fmt::Display for Encoding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Encoding::Dense => "dense",
            Encoding::Sparse => "sparse",
            Encoding::Quantized => "quantized",
            Encoding::Meshopt => "meshopt",
        })
    }
}

/// Options of the .glb export.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GlbOptions {
    /// How keyframes map to seconds.
    pub timing: Timing,
    /// At most this many morph targets per mesh (default 250, see the crate
    /// documentation); longer keyframe sequences are resampled.
    pub max_morph_targets: usize,
    /// Store `NORMAL` attributes and normal deltas (default `true`). Without
    /// them clients compute flat or smooth normals themselves and the file is
    /// about half as large.
    pub normals: bool,
    /// How the morph targets are stored.
    pub encoding: Encoding,
}

/// Default frame rate of the exported animation, in keyframes per second.
pub const DEFAULT_FRAMES_PER_SECOND: f64 = 24.0;
/// Default [`GlbOptions::max_morph_targets`].
pub const DEFAULT_MAX_MORPH_TARGETS: usize = 250;

impl Default for GlbOptions {
    fn default() -> Self {
        Self {
            timing: Timing::FramesPerSecond(DEFAULT_FRAMES_PER_SECOND),
            max_morph_targets: DEFAULT_MAX_MORPH_TARGETS,
            normals: true,
            encoding: Encoding::Dense,
        }
    }
}

impl GlbOptions {
    /// Checks the options for an animation of `keyframe_count` keyframes
    /// (the bud included) the way [`glb_bytes`] does, without any data: a
    /// frame rate or duration that is not a positive number, or that puts
    /// the keyframes too close or too far apart for the file's 32-bit times,
    /// and no morph targets for an animation. For checking command-line
    /// options before a long simulation.
    pub fn check(&self, keyframe_count: usize) -> Result<(), ExportError> {
        prepare::validate_options(self, keyframe_count)?;
        let positions = prepare::sample_positions(keyframe_count, self.max_morph_targets);
        prepare::animation_times(self.timing, keyframe_count, &positions).map(|_| ())
    }
}

/// Builds the .glb (see [`glb_bytes`]) and writes it to `path` atomically
/// (see [`anthesis_files::write_atomic`]): an existing file at `path` is replaced only by a
/// completely written new one. `progress` goes from 0 to 1.
pub fn write_glb(
    path: &Path,
    tracks: &[Track],
    options: &GlbOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(), ExportError> {
    // Check the destination before the (possibly long) encoding, so a typo
    // in the folder is reported at once.
    anthesis_files::check_destination(path)?;
    let bytes = glb_bytes(tracks, options, &mut |p| progress(0.95 * p))?;
    anthesis_files::write_atomic(path, &bytes)?;
    progress(1.0);
    Ok(())
}

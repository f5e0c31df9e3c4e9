//! Rendering of flower organs with wgpu: the only Anthesis crate that uses
//! wgpu.
//!
//! Layers, from the inside out:
//! - [`OrganPipeline`] holds the shader pipelines, the organs' GPU buffers
//!   and the frame uniforms. It works with any `wgpu::Device`/`Queue` (the
//!   desktop app passes egui_wgpu's) and draws into a render pass whose
//!   attachments match its [`TargetFormat`]: [`OrganPipeline::render`]
//!   records a whole pass into caller-owned colour and depth views,
//!   [`OrganPipeline::draw`] draws into a pass the caller began.
//! - [`RenderTarget`] owns a colour (optionally multisampled), a resolved
//!   single-sample colour texture and a depth texture of one size.
//! - [`OffscreenRenderer`] creates its own headless device (any backend;
//!   the software Vulkan adapter lavapipe is fine) and renders organs to an
//!   [`image::RgbaImage`].
//! - [`BlitPipeline`] copies a [`RenderTarget`]'s image into another pass
//!   (the desktop viewport draws into egui's pass with it).
//!
//! Depth is reversed (near = 1, infinitely far = 0, compare
//! `GreaterEqual`): a pass that draws organs must clear its depth to
//! [`DEPTH_CLEAR_VALUE`].

#![warn(missing_docs)]

mod blit;
mod camera;
mod error;
mod mesh;
mod offscreen;
mod orbit;
mod pipeline;
mod target;

pub use blit::{BLIT_SHADER_SOURCE, BLIT_SOURCE_FORMAT, BlitPipeline};
pub use camera::Camera;
pub use error::RenderError;
pub use mesh::{OrganMesh, OrganTexture, organs_bounds_in_world};
pub use offscreen::OffscreenRenderer;
pub use orbit::{ORBIT_FOV_DEG, OrbitCamera};
pub use pipeline::{
    Background, DEPTH_CLEAR_VALUE, OVERLAY_RAMP_LINEAR, OrganPipeline, SHADER_SOURCE, TargetFormat,
    organ_shader_source, overlay_ramp_linear,
};
pub use target::RenderTarget;

/// The wgpu this crate is built against, for callers that must name its
/// types (devices, texture formats) without depending on it themselves.
pub use wgpu;

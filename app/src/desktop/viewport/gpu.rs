//! The viewport's GPU side: an egui_wgpu paint callback that renders the
//! organs with `anthesis-render`'s [`OrganPipeline`] into the viewport's
//! own colour + depth target in `prepare` (egui's render pass has no depth
//! attachment) and copies that image into egui's pass in `paint` with the
//! render crate's [`BlitPipeline`]. The organ pass is recorded only when
//! the meshes, the camera or the size changed: a frame drawn for the rest
//! of the window (a panel, the timeline, the log) copies the image it
//! already has.

use std::sync::Arc;

use anthesis_render::{
    BLIT_SOURCE_FORMAT, BlitPipeline, Camera, OrganMesh, OrganPipeline, RenderTarget,
};
use eframe::egui;
use eframe::egui_wgpu::{self, wgpu};

/// The paint callback: renders `meshes` from `camera` into the viewport.
pub struct ViewportCallback {
    pub meshes: Arc<Vec<OrganMesh>>,
    /// Changes whenever `meshes` does, so unchanged frames skip the upload.
    pub revision: u64,
    pub camera: Camera,
    pub size_in_pixels: [u32; 2],
}

/// GPU state of the viewport, kept in egui_wgpu's callback resources.
pub struct ViewportGpu {
    organs: OrganPipeline,
    target: Option<RenderTarget>,
    uploaded_revision: Option<u64>,
    /// What the target's image shows: meshes revision, camera, size.
    rendered: Option<(u64, Camera, (u32, u32))>,
    blit: BlitPipeline,
    /// The blit's source: the current target.
    image: Option<wgpu::BindGroup>,
}

impl ViewportGpu {
    /// Creates the pipelines for egui's pass of `egui_target_format`
    /// (single-sampled, no depth: eframe's and egui_kittest's defaults).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        egui_target_format: wgpu::TextureFormat,
    ) -> ViewportGpu {
        ViewportGpu {
            organs: OrganPipeline::new(device, queue, BLIT_SOURCE_FORMAT),
            target: None,
            uploaded_revision: None,
            rendered: None,
            blit: BlitPipeline::new(device, egui_target_format),
            image: None,
        }
    }

    /// Registers the viewport's GPU state with eframe's renderer.
    pub fn install(render_state: &egui_wgpu::RenderState) {
        let gpu = ViewportGpu::new(
            &render_state.device,
            &render_state.queue,
            render_state.target_format,
        );
        render_state.renderer.write().callback_resources.insert(gpu);
    }
}

impl egui_wgpu::CallbackTrait for ViewportCallback {
    fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        _screen_descriptor: &egui_wgpu::ScreenDescriptor,
        egui_encoder: &mut wgpu::CommandEncoder,
        resources: &mut egui_wgpu::CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        let Some(gpu) = resources.get_mut::<ViewportGpu>() else {
            return Vec::new();
        };
        let [width, height] = self.size_in_pixels;
        let max = device.limits().max_texture_dimension_2d;
        let (width, height) = (width.clamp(1, max), height.clamp(1, max));
        if gpu.target.as_ref().map(RenderTarget::size) != Some((width, height)) {
            let target = RenderTarget::new(device, BLIT_SOURCE_FORMAT, width, height);
            gpu.image = Some(gpu.blit.bind(device, &target));
            gpu.target = Some(target);
            gpu.rendered = None;
        }
        if gpu.uploaded_revision != Some(self.revision) {
            // Meshes come from validated templates; a malformed one is
            // skipped (the previous upload stays) rather than drawn wrong.
            let _ = gpu.organs.set_organs(device, queue, &self.meshes);
            gpu.uploaded_revision = Some(self.revision);
        }
        let wanted = (self.revision, self.camera, (width, height));
        if let Some(target) = &gpu.target
            && gpu.rendered != Some(wanted)
        {
            gpu.organs.set_camera(queue, &self.camera, target.aspect());
            target.render(&gpu.organs, egui_encoder);
            gpu.rendered = Some(wanted);
        }
        Vec::new()
    }

    fn paint(
        &self,
        _info: egui::PaintCallbackInfo,
        render_pass: &mut wgpu::RenderPass<'static>,
        resources: &egui_wgpu::CallbackResources,
    ) {
        let Some(gpu) = resources.get::<ViewportGpu>() else {
            return;
        };
        if let Some(image) = &gpu.image {
            gpu.blit.draw(render_pass, image);
        }
    }
}

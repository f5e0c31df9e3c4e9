use crate::{OrganPipeline, TargetFormat};

/// Colour and depth textures of one size for [`OrganPipeline::render`].
///
/// The resolved colour texture is single-sampled with usages
/// `RENDER_ATTACHMENT | TEXTURE_BINDING | COPY_SRC`, so it can be copied to
/// a buffer, sampled, or registered as an egui texture.
pub struct RenderTarget {
    format: TargetFormat,
    width: u32,
    height: u32,
    /// The multisampled colour texture when `sample_count > 1`.
    multisampled_view: Option<wgpu::TextureView>,
    resolved: wgpu::Texture,
    resolved_view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
}

impl RenderTarget {
    /// Creates the textures. `width` and `height` must be within the
    /// device's `max_texture_dimension_2d` (wgpu reports a validation error
    /// otherwise).
    pub fn new(device: &wgpu::Device, format: TargetFormat, width: u32, height: u32) -> Self {
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let texture = |label, sample_count, texture_format, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count: 1,
                sample_count,
                dimension: wgpu::TextureDimension::D2,
                format: texture_format,
                usage,
                view_formats: &[],
            })
        };
        let resolved = texture(
            "anthesis colour",
            1,
            format.colour,
            wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
        );
        let multisampled_view = (format.sample_count > 1).then(|| {
            texture(
                "anthesis colour (multisampled)",
                format.sample_count,
                format.colour,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            )
            .create_view(&Default::default())
        });
        let depth_view = texture(
            "anthesis depth",
            format.sample_count,
            format.depth,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        )
        .create_view(&Default::default());
        let resolved_view = resolved.create_view(&Default::default());
        RenderTarget {
            format,
            width,
            height,
            multisampled_view,
            resolved,
            resolved_view,
            depth_view,
        }
    }

    /// The formats the textures were made with.
    pub fn format(&self) -> TargetFormat {
        self.format
    }

    /// `(width, height)` in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// `width / height`, for [`crate::Camera::view_projection`].
    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height.max(1) as f32
    }

    /// The final single-sample colour texture.
    pub fn texture(&self) -> &wgpu::Texture {
        &self.resolved
    }

    /// A view of [`RenderTarget::texture`].
    pub fn view(&self) -> &wgpu::TextureView {
        &self.resolved_view
    }

    /// Records the organ pass of `pipeline` (whose format must equal this
    /// target's) into this target.
    pub fn render(&self, pipeline: &OrganPipeline, encoder: &mut wgpu::CommandEncoder) {
        match &self.multisampled_view {
            Some(multisampled) => pipeline.render(
                encoder,
                multisampled,
                Some(&self.resolved_view),
                &self.depth_view,
            ),
            None => pipeline.render(encoder, &self.resolved_view, None, &self.depth_view),
        }
    }
}

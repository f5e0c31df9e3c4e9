//! Copies a rendered image into another render pass, such as egui's: the
//! desktop viewport renders organs into its own [`RenderTarget`] (egui's
//! pass has no depth attachment) and draws that image into egui's pass
//! with [`BlitPipeline`], using `shaders/viewport_blit.wgsl`.

use crate::{RenderTarget, TargetFormat};

/// The WGSL of the copy.
pub const BLIT_SHADER_SOURCE: &str = include_str!("../../../shaders/viewport_blit.wgsl");

/// The format of an image that [`BlitPipeline`] copies: not sRGB, so the
/// organ shader writes encoded values and the copy passes them on (or
/// decodes them for an sRGB destination); multisampled 4x, resolved by
/// the [`RenderTarget`].
pub const BLIT_SOURCE_FORMAT: TargetFormat = TargetFormat {
    colour: wgpu::TextureFormat::Rgba8Unorm,
    depth: wgpu::TextureFormat::Depth32Float,
    sample_count: 4,
};

/// The copy pipeline for one destination format (single-sampled, no
/// depth: egui's pass).
pub struct BlitPipeline {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
}

impl BlitPipeline {
    /// A pipeline that draws into passes of `destination_format`.
    pub fn new(device: &wgpu::Device, destination_format: wgpu::TextureFormat) -> BlitPipeline {
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("anthesis blit"),
            source: wgpu::ShaderSource::Wgsl(BLIT_SHADER_SOURCE.into()),
        });
        let layout = crate::pipeline::texture_layout(device, "anthesis blit image");
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("anthesis blit"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let fragment_entry = if destination_format.is_srgb() {
            "fs_blit_decoded"
        } else {
            "fs_blit_encoded"
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("anthesis blit"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &shader,
                entry_point: Some("vs_blit"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &shader,
                entry_point: Some(fragment_entry),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: destination_format,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("anthesis blit image"),
            mag_filter: wgpu::FilterMode::Nearest,
            min_filter: wgpu::FilterMode::Nearest,
            ..Default::default()
        });
        BlitPipeline {
            pipeline,
            layout,
            sampler,
        }
    }

    /// The bind group that makes `image` (of [`BLIT_SOURCE_FORMAT`]) the
    /// source of [`BlitPipeline::draw`]; make a new one when the target is
    /// replaced.
    pub fn bind(&self, device: &wgpu::Device, image: &RenderTarget) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("anthesis blit image"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(image.view()),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
            ],
        })
    }

    /// Draws the bound image over the pass's viewport (a full-screen
    /// triangle).
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, image: &wgpu::BindGroup) {
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, image, &[]);
        pass.draw(0..3, 0..1);
    }
}

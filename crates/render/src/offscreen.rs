use std::sync::mpsc;
use std::time::Duration;

use crate::pipeline::Background;
use crate::{Camera, OrganMesh, OrganPipeline, RenderError, RenderTarget, TargetFormat};

/// Renders organs to images on a headless device of its own.
pub struct OffscreenRenderer {
    // Kept alive for the device's lifetime.
    _instance: wgpu::Instance,
    adapter_info: wgpu::AdapterInfo,
    device: wgpu::Device,
    queue: wgpu::Queue,
    pipeline: OrganPipeline,
    target: Option<RenderTarget>,
    readback: Option<wgpu::Buffer>,
}

/// The backend sets to try in turn: `WGPU_BACKEND` when it names some
/// (an empty `WGPU_BACKEND=` would otherwise mean none); else the primary
/// backends (Vulkan, Metal, DX12) and only then the rest (GL), so that
/// machines with Vulkan never probe EGL.
fn backend_attempts() -> (wgpu::Backends, Option<wgpu::Backends>) {
    match wgpu::Backends::from_env() {
        Some(backends) if !backends.is_empty() => (backends, None),
        _ => (wgpu::Backends::PRIMARY, Some(wgpu::Backends::SECONDARY)),
    }
}

fn request_adapter_on(
    backends: wgpu::Backends,
) -> Result<(wgpu::Instance, wgpu::Adapter), wgpu::RequestAdapterError> {
    let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle();
    descriptor.backends = backends;
    let instance = wgpu::Instance::new(descriptor);
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        force_fallback_adapter: false,
        compatible_surface: None,
        apply_limit_buckets: false,
    }))?;
    Ok((instance, adapter))
}

/// Finds an adapter, trying the backend sets of [`backend_attempts`].
fn request_adapter() -> Result<(wgpu::Instance, wgpu::Adapter), RenderError> {
    let (first, second) = backend_attempts();
    let mut outcome = request_adapter_on(first);
    if let (Err(_), Some(second)) = (&outcome, second) {
        outcome = request_adapter_on(second);
    }
    outcome.map_err(|source| RenderError::NoAdapter {
        backends: format!("{:?}", first | second.unwrap_or(wgpu::Backends::empty())),
        source,
    })
}

impl OffscreenRenderer {
    /// Creates an instance, adapter and device without a window. Any adapter
    /// is accepted, a software one (Mesa's lavapipe) included. Uses 4x MSAA
    /// when the adapter supports it for the colour and depth formats.
    pub fn new() -> Result<OffscreenRenderer, RenderError> {
        let (instance, adapter) = request_adapter()?;
        let adapter_info = adapter.get_info();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("anthesis offscreen"),
            required_features: wgpu::Features::empty(),
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|source| RenderError::DeviceRequest {
            adapter: format!("{} ({:?})", adapter_info.name, adapter_info.backend),
            source,
        })?;

        let mut format = TargetFormat::DEFAULT;
        let supports = |texture_format| {
            adapter
                .get_texture_format_features(texture_format)
                .flags
                .sample_count_supported(format.sample_count)
        };
        if !(supports(format.colour) && supports(format.depth)) {
            format.sample_count = 1;
        }
        let pipeline = OrganPipeline::new(&device, &queue, format);
        Ok(OffscreenRenderer {
            _instance: instance,
            adapter_info,
            device,
            queue,
            pipeline,
            target: None,
            readback: None,
        })
    }

    /// Which adapter renders (name, backend, device type).
    pub fn adapter_info(&self) -> &wgpu::AdapterInfo {
        &self.adapter_info
    }

    /// The device this renderer created (for callers that add their own
    /// passes).
    pub fn device(&self) -> &wgpu::Device {
        &self.device
    }

    /// The device's queue.
    pub fn queue(&self) -> &wgpu::Queue {
        &self.queue
    }

    /// The formats in use (`sample_count` tells whether MSAA is on).
    pub fn format(&self) -> TargetFormat {
        self.pipeline.format()
    }

    /// The gradient drawn behind the organs from the next render on.
    pub fn set_background(&mut self, background: Background) {
        self.pipeline.set_background(background);
    }

    /// Renders `organs` seen by `camera` into a `width x height` image
    /// (sRGB-encoded RGBA, alpha 255 everywhere the background is).
    pub fn render(
        &mut self,
        organs: &[OrganMesh],
        camera: &Camera,
        width: u32,
        height: u32,
    ) -> Result<image::RgbaImage, RenderError> {
        let max = self.device.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(RenderError::InvalidSize { width, height, max });
        }
        let validation_scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let memory_scope = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);

        self.pipeline
            .set_organs(&self.device, &self.queue, organs)?;
        if self.target.as_ref().map(RenderTarget::size) != Some((width, height)) {
            self.target = Some(RenderTarget::new(
                &self.device,
                self.pipeline.format(),
                width,
                height,
            ));
        }
        let bytes_per_pixel = 4_u32;
        let padded_row_bytes = (width * bytes_per_pixel)
            .div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let readback_size = u64::from(padded_row_bytes) * u64::from(height);
        if self.readback.as_ref().map(wgpu::Buffer::size) != Some(readback_size) {
            self.readback = Some(self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("anthesis readback"),
                size: readback_size,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            }));
        }
        let (Some(target), Some(readback)) = (&self.target, &self.readback) else {
            return Err(RenderError::Readback("render target missing".into()));
        };

        self.pipeline
            .set_camera(&self.queue, camera, target.aspect());
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("anthesis offscreen"),
            });
        target.render(&self.pipeline, &mut encoder);
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: target.texture(),
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded_row_bytes),
                    rows_per_image: Some(height),
                },
            },
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
        );
        self.queue.submit([encoder.finish()]);

        // One mapping result.
        let (sender, receiver) = mpsc::sync_channel(1);
        readback.map_async(wgpu::MapMode::Read, .., move |result| {
            // The receiver waits below; a failed send only means it gave up.
            let _ = sender.send(result);
        });
        self.device
            .poll(wgpu::PollType::Wait {
                submission_index: None,
                timeout: Some(Duration::from_secs(60)),
            })
            .map_err(|e| RenderError::Readback(format!("waiting for the GPU: {e}")))?;

        if let Some(error) = pollster::block_on(memory_scope.pop()) {
            return Err(RenderError::Gpu(error.to_string()));
        }
        if let Some(error) = pollster::block_on(validation_scope.pop()) {
            return Err(RenderError::Gpu(error.to_string()));
        }
        receiver
            .recv_timeout(Duration::from_secs(60))
            .map_err(|e| RenderError::Readback(format!("no mapping result: {e}")))?
            .map_err(|e| RenderError::Readback(e.to_string()))?;

        let row_bytes = (width * bytes_per_pixel) as usize;
        let mut pixels = Vec::with_capacity(row_bytes * height as usize);
        {
            let mapped = readback
                .get_mapped_range(..)
                .map_err(|e| RenderError::Readback(e.to_string()))?;
            for row in mapped.chunks_exact(padded_row_bytes as usize) {
                pixels.extend_from_slice(&row[..row_bytes]);
            }
        }
        readback.unmap();
        image::RgbaImage::from_raw(width, height, pixels)
            .ok_or_else(|| RenderError::Readback("pixel buffer has the wrong size".into()))
    }
}

use thiserror::Error;

/// Everything that can go wrong while setting up or using the renderer.
#[derive(Debug, Error)]
pub enum RenderError {
    #[error(
        "no graphics adapter found for backends {backends}: {source}. On Linux without a GPU \
         install Mesa's software Vulkan driver (`apt-get install mesa-vulkan-drivers libvulkan1`); \
         an empty WGPU_BACKEND variable is ignored, any other value restricts the backends"
    )]
    NoAdapter {
        backends: String,
        #[source]
        source: wgpu::RequestAdapterError,
    },
    #[error("the graphics device could not be created on adapter {adapter}: {source}")]
    DeviceRequest {
        adapter: String,
        #[source]
        source: wgpu::RequestDeviceError,
    },
    #[error("image size {width}x{height} is invalid (each side must be 1..={max})")]
    InvalidSize { width: u32, height: u32, max: u32 },
    #[error("organ {organ}: {reason}")]
    InvalidMesh { organ: usize, reason: String },
    #[error("reading the rendered image back failed: {0}")]
    Readback(String),
    #[error("the GPU reported an error: {0}")]
    Gpu(String),
}

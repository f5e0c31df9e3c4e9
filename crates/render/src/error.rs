use thiserror::Error;

/// Everything that can go wrong while setting up or using the renderer.
#[derive(Debug, Error)]
pub enum RenderError {
    #[error(
        "no graphics adapter found for backends {backends}: {source}. On Linux without a GPU \
         install Mesa's software Vulkan driver (`apt-get install mesa-vulkan-drivers libvulkan1`); \
         an empty WGPU_BACKEND variable is ignored, any other value restricts the backends"
    )]
    /// No adapter of the allowed backends.
    NoAdapter {
        /// The backends that were searched.
        backends: String,
        /// What wgpu said.
        #[source]
        source: wgpu::RequestAdapterError,
    },
    #[error("the graphics device could not be created on adapter {adapter}: {source}")]
    /// The adapter was found but refused a device.
    DeviceRequest {
        /// The adapter's name and backend.
        adapter: String,
        /// What wgpu said.
        #[source]
        source: wgpu::RequestDeviceError,
    },
    #[error("image size {width}x{height} is invalid (each side must be 1..={max})")]
    /// An image side is 0 or larger than the device allows.
    InvalidSize {
        /// Asked width in pixels.
        width: u32,
        /// Asked height in pixels.
        height: u32,
        /// The device's largest texture side.
        max: u32,
    },
    #[error("organ {organ}: {reason}")]
    /// An organ's mesh cannot be drawn.
    InvalidMesh {
        /// Index of the organ in the list given.
        organ: usize,
        /// What is wrong with it.
        reason: String,
    },
    #[error("reading the rendered image back failed: {0}")]
    /// The rendered image could not be copied back from the GPU.
    Readback(String),
    #[error("the GPU reported an error: {0}")]
    /// The GPU reported a validation or out-of-memory error.
    Gpu(String),
}

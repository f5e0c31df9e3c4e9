use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use crate::{Camera, OrganMesh, RenderError};

/// The WGSL source of `shaders/organ.wgsl`, compiled into the crate; the
/// shader the pipeline builds is [`organ_shader_source`], which adds the
/// overlay ramp's stops in front of it.
pub const SHADER_SOURCE: &str = include_str!("../../../shaders/organ.wgsl");

/// The map overlay's colour ramp, linear RGB, at 0 (blue), 0.5 (pale
/// yellow) and 1 (red), blended linearly in between: the one definition
/// the viewport's shader and the app's canvas and legend share.
pub const OVERLAY_RAMP_LINEAR: [[f32; 3]; 3] =
    [[0.02, 0.10, 0.55], [0.95, 0.90, 0.60], [0.65, 0.02, 0.02]];

/// The overlay ramp at `value` (clamped to `[0, 1]`), linear RGB, computed
/// as the shader's `overlay_ramp` does.
pub fn overlay_ramp_linear(value: f32) -> [f32; 3] {
    let t = if value.is_nan() {
        0.0
    } else {
        value.clamp(0.0, 1.0)
    };
    let [low, middle, high] = OVERLAY_RAMP_LINEAR;
    let (a, b, s) = if t < 0.5 {
        (low, middle, t * 2.0)
    } else {
        (middle, high, t * 2.0 - 1.0)
    };
    // As WGSL's mix: exactly a at s = 0 and b at s = 1.
    [0, 1, 2].map(|i| a[i] * (1.0 - s) + b[i] * s)
}

/// The organ shader as compiled: the overlay ramp's stops
/// ([`OVERLAY_RAMP_LINEAR`]) as WGSL constants, then `shaders/organ.wgsl`.
pub fn organ_shader_source() -> String {
    let [low, middle, high] =
        OVERLAY_RAMP_LINEAR.map(|[r, g, b]| format!("vec3<f32>({r:?}, {g:?}, {b:?})"));
    format!(
        "const RAMP_LOW: vec3<f32> = {low};\nconst RAMP_MIDDLE: vec3<f32> = {middle};\n\
         const RAMP_HIGH: vec3<f32> = {high};\n{SHADER_SOURCE}"
    )
}

/// The depth a pass must clear to before drawing organs (reversed depth:
/// 0 is infinitely far).
pub const DEPTH_CLEAR_VALUE: f32 = 0.0;

/// Brightness of an organ's back (outer) side relative to its front: a
/// little less, so the two sides read apart, not so much that the outer
/// side of a bud goes muddy.
const BACK_SIDE_BRIGHTNESS: f32 = 0.92;

/// How far below the flower's lowest point the ground is, in flower radii
/// (the shadow is a contact shadow: close under the flower).
const GROUND_GAP_IN_RADII: f64 = 0.02;

/// The attachments a pipeline draws into. Render passes must match it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TargetFormat {
    /// Any renderable colour format. For `…Srgb` formats the hardware
    /// encodes; for others the shader writes sRGB-encoded values itself, so
    /// the image looks the same either way.
    pub colour: wgpu::TextureFormat,
    /// A depth format (`Depth32Float` recommended: depth is reversed).
    pub depth: wgpu::TextureFormat,
    /// 1 (no MSAA) or a count the device supports for both formats (4 is
    /// guaranteed by WebGPU for the usual formats).
    pub sample_count: u32,
}

impl TargetFormat {
    /// `Rgba8UnormSrgb` colour, `Depth32Float` depth, 4x MSAA.
    pub const DEFAULT: TargetFormat = TargetFormat {
        colour: wgpu::TextureFormat::Rgba8UnormSrgb,
        depth: wgpu::TextureFormat::Depth32Float,
        sample_count: 4,
    };
}

impl Default for TargetFormat {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// A vertical gradient behind the organs, sRGB-encoded RGB in `[0, 1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Background {
    /// The colour at the top of the image.
    pub top_srgb: [f32; 3],
    /// The colour at the bottom of the image.
    pub bottom_srgb: [f32; 3],
}

impl Background {
    /// A soft blue-grey gradient, light at the top, against which white,
    /// pink and green organs all read.
    pub const SOFT_GRADIENT: Background = Background {
        top_srgb: [0.80, 0.83, 0.87],
        bottom_srgb: [0.50, 0.53, 0.58],
    };

    /// A plain colour.
    pub const fn plain(srgb: [f32; 3]) -> Background {
        Background {
            top_srgb: srgb,
            bottom_srgb: srgb,
        }
    }

    /// The sRGB colour at `down` (0 = top edge of the image, 1 = bottom).
    pub fn srgb_at(&self, down: f32) -> [f32; 3] {
        let t = down.clamp(0.0, 1.0);
        std::array::from_fn(|i| self.top_srgb[i] + (self.bottom_srgb[i] - self.top_srgb[i]) * t)
    }
}

impl Default for Background {
    fn default() -> Self {
        Self::SOFT_GRADIENT
    }
}

/// Matches `Frame` in organ.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct FrameUniform {
    view_projection: [[f32; 4]; 4],
    eye_in_world: [f32; 4],
    light_direction_in_world: [f32; 4],
    background_top_srgb: [f32; 4],
    background_bottom_srgb: [f32; 4],
    output_flags: [f32; 4],
    inverse_view_projection: [[f32; 4]; 4],
    ground: [f32; 4],
}

/// Matches `Organ` in organ.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct OrganUniform {
    colour_linear: [f32; 4],
    overlay_mix: [f32; 4],
}

/// Matches `VertexIn` in organ.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct Vertex {
    position_in_world: [f32; 3],
    normal_in_world: [f32; 3],
    overlay: f32,
    uv: [f32; 2],
}

const VERTEX_ATTRIBUTES: [wgpu::VertexAttribute; 4] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32, 3 => Float32x2];

/// One organ's GPU buffers. Buffers are kept and rewritten while the new
/// data fits, so streaming animation frames does not reallocate.
struct GpuOrgan {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
    /// The organ's colour texture and the image it was uploaded from (kept
    /// while the same image comes back); `None`: the white texture.
    texture: Option<(Arc<image::RgbaImage>, wgpu::BindGroup)>,
}

/// The organ and background pipelines with their buffers, usable with any
/// device and queue. See the crate docs for the depth convention.
pub struct OrganPipeline {
    format: TargetFormat,
    organ_pipeline: wgpu::RenderPipeline,
    background_pipeline: wgpu::RenderPipeline,
    frame_buffer: wgpu::Buffer,
    frame_bind_group: wgpu::BindGroup,
    organ_layout: wgpu::BindGroupLayout,
    organ_uniform_stride: u64,
    organ_uniform_capacity: usize,
    organ_uniform_buffer: wgpu::Buffer,
    organ_bind_group: wgpu::BindGroup,
    texture_layout: wgpu::BindGroupLayout,
    texture_sampler: wgpu::Sampler,
    /// A 1x1 white texture: what an organ without a texture is drawn with.
    white_texture: wgpu::BindGroup,
    organs: Vec<GpuOrgan>,
    background: Background,
    /// The ground shadow's place, as `Frame.ground` in organ.wgsl: set from
    /// the organs' bounds, written with the camera.
    ground: [f32; 4],
}

/// The layout of a filtered 2D texture (binding 0) and its sampler
/// (binding 1), read by the fragment stage: an organ's colour texture, the
/// viewport's copied image.
pub(crate) fn texture_layout(device: &wgpu::Device, label: &str) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: true },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 1,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                count: None,
            },
        ],
    })
}

fn round_up(value: u64, alignment: u64) -> u64 {
    value.div_ceil(alignment.max(1)) * alignment.max(1)
}

/// The bind group layouts the organ shader reads and the pipeline layout
/// that lists them as groups 0, 1 and 2.
struct OrganLayouts {
    /// Group 0: the frame's uniforms, one per draw.
    frame: wgpu::BindGroupLayout,
    /// Group 1: one organ's uniforms, at a dynamic offset.
    organ: wgpu::BindGroupLayout,
    /// Group 2: the organ's texture and sampler.
    texture: wgpu::BindGroupLayout,
    /// Both pipelines' layout.
    pipeline: wgpu::PipelineLayout,
}

/// Creates the three bind group layouts and the pipeline layout over them.
fn organ_layouts(device: &wgpu::Device) -> OrganLayouts {
    let uniform_entry = |has_dynamic_offset: bool, size: usize| wgpu::BindGroupLayoutEntry {
        binding: 0,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset,
            min_binding_size: wgpu::BufferSize::new(size as u64),
        },
        count: None,
    };
    let frame = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("anthesis frame uniforms"),
        entries: &[uniform_entry(false, size_of::<FrameUniform>())],
    });
    let organ = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("anthesis organ uniforms"),
        entries: &[uniform_entry(true, size_of::<OrganUniform>())],
    });
    let texture = texture_layout(device, "anthesis organ texture");
    let pipeline = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("anthesis organs"),
        bind_group_layouts: &[Some(&frame), Some(&organ), Some(&texture)],
        immediate_size: 0,
    });
    OrganLayouts {
        frame,
        organ,
        texture,
        pipeline,
    }
}

/// The one colour attachment both pipelines write, unblended.
fn colour_targets(format: TargetFormat) -> [Option<wgpu::ColorTargetState>; 1] {
    [Some(wgpu::ColorTargetState {
        format: format.colour,
        blend: None,
        write_mask: wgpu::ColorWrites::ALL,
    })]
}

/// Multisampling at the target's sample count, every sample written.
fn multisample(format: TargetFormat) -> wgpu::MultisampleState {
    wgpu::MultisampleState {
        count: format.sample_count,
        mask: !0,
        alpha_to_coverage_enabled: false,
    }
}

/// The organ pipeline: two-sided triangles from the vertex buffer,
/// depth-tested (reversed depth) and written.
fn create_organ_pipeline(
    device: &wgpu::Device,
    shader: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    format: TargetFormat,
) -> wgpu::RenderPipeline {
    let colour_targets = colour_targets(format);
    let vertex_buffers = [Some(wgpu::VertexBufferLayout {
        array_stride: size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &VERTEX_ATTRIBUTES,
    })];
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("anthesis organs"),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module: shader,
            entry_point: Some("vs_organ"),
            compilation_options: Default::default(),
            buffers: &vertex_buffers,
        },
        primitive: wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleList,
            front_face: wgpu::FrontFace::Ccw,
            // Two-sided: both sides are drawn and shaded.
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: format.depth,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::GreaterEqual),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: multisample(format),
        fragment: Some(wgpu::FragmentState {
            module: shader,
            entry_point: Some("fs_organ"),
            compilation_options: Default::default(),
            targets: &colour_targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// The background pipeline: a full-screen triangle made in the vertex
/// shader, drawn everywhere and leaving depth untouched.
fn create_background_pipeline(
    device: &wgpu::Device,
    shader: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    format: TargetFormat,
) -> wgpu::RenderPipeline {
    let colour_targets = colour_targets(format);
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("anthesis background"),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module: shader,
            entry_point: Some("vs_background"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: format.depth,
            depth_write_enabled: Some(false),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: multisample(format),
        fragment: Some(wgpu::FragmentState {
            module: shader,
            entry_point: Some("fs_background"),
            compilation_options: Default::default(),
            targets: &colour_targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// The frame's uniform buffer and its bind group (group 0).
fn create_frame_uniforms(
    device: &wgpu::Device,
    frame_layout: &wgpu::BindGroupLayout,
) -> (wgpu::Buffer, wgpu::BindGroup) {
    let frame_buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("anthesis frame uniforms"),
        size: size_of::<FrameUniform>() as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let frame_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("anthesis frame uniforms"),
        layout: frame_layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: frame_buffer.as_entire_binding(),
        }],
    });
    (frame_buffer, frame_bind_group)
}

impl OrganPipeline {
    /// Builds the pipelines for passes with attachments of `format`
    /// (`queue` uploads the white texture untextured organs are drawn with).
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, format: TargetFormat) -> OrganPipeline {
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("anthesis organ.wgsl"),
            source: wgpu::ShaderSource::Wgsl(organ_shader_source().into()),
        });
        let OrganLayouts {
            frame: frame_layout,
            organ: organ_layout,
            texture: texture_layout,
            pipeline: layout,
        } = organ_layouts(device);
        let organ_pipeline = create_organ_pipeline(device, &shader, &layout, format);
        let background_pipeline = create_background_pipeline(device, &shader, &layout, format);

        let (frame_buffer, frame_bind_group) = create_frame_uniforms(device, &frame_layout);
        let organ_uniform_stride = round_up(
            size_of::<OrganUniform>() as u64,
            u64::from(device.limits().min_uniform_buffer_offset_alignment),
        );
        let (organ_uniform_buffer, organ_bind_group) =
            Self::create_organ_uniforms(device, &organ_layout, organ_uniform_stride, 1);
        // Bilinear within the image, clamped at its edges (the UV square's
        // rim is the organ's rim).
        let texture_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("anthesis organ texture"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let white = image::RgbaImage::from_pixel(1, 1, image::Rgba([255; 4]));
        let white_texture =
            Self::create_texture(device, queue, &texture_layout, &texture_sampler, &white);
        OrganPipeline {
            format,
            organ_pipeline,
            background_pipeline,
            frame_buffer,
            frame_bind_group,
            organ_layout,
            organ_uniform_stride,
            organ_uniform_capacity: 1,
            organ_uniform_buffer,
            organ_bind_group,
            texture_layout,
            texture_sampler,
            white_texture,
            organs: Vec::new(),
            ground: [0.0; 4],
            background: Background::default(),
        }
    }

    /// Uploads `image` (sRGB-encoded RGBA8: sampled as linear colours) and
    /// binds it with `sampler` as `layout` describes.
    fn create_texture(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        layout: &wgpu::BindGroupLayout,
        sampler: &wgpu::Sampler,
        image: &image::RgbaImage,
    ) -> wgpu::BindGroup {
        let texture = device.create_texture_with_data(
            queue,
            &wgpu::TextureDescriptor {
                label: Some("anthesis organ texture"),
                size: wgpu::Extent3d {
                    width: image.width(),
                    height: image.height(),
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba8UnormSrgb,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            image.as_raw(),
        );
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("anthesis organ texture"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(sampler),
                },
            ],
        })
    }

    fn create_organ_uniforms(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        stride: u64,
        capacity: usize,
    ) -> (wgpu::Buffer, wgpu::BindGroup) {
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("anthesis organ uniforms"),
            size: stride * capacity as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("anthesis organ uniforms"),
            layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &buffer,
                    offset: 0,
                    size: wgpu::BufferSize::new(size_of::<OrganUniform>() as u64),
                }),
            }],
        });
        (buffer, bind_group)
    }

    /// The attachment formats this pipeline was built for.
    pub fn format(&self) -> TargetFormat {
        self.format
    }

    /// The background drawn by [`OrganPipeline::draw`] from the next
    /// [`OrganPipeline::set_camera`] on.
    pub fn set_background(&mut self, background: Background) {
        self.background = background;
    }

    /// The gradient drawn behind the organs.
    pub fn background(&self) -> Background {
        self.background
    }

    /// How many organs are uploaded.
    pub fn organ_count(&self) -> usize {
        self.organs.len()
    }

    /// Writes each organ's colour and flags into the uniform buffer (which
    /// holds at least `organs.len()` of them).
    fn write_organ_uniforms(&self, queue: &wgpu::Queue, organs: &[OrganMesh]) {
        let stride = self.organ_uniform_stride as usize;
        let mut uniform_bytes = vec![0_u8; stride * organs.len()];
        let flag = |on: bool| if on { 1.0 } else { 0.0 };
        for (i, mesh) in organs.iter().enumerate() {
            let uniform = OrganUniform {
                colour_linear: mesh.colour_linear,
                overlay_mix: [
                    flag(mesh.overlay.is_some()),
                    flag(mesh.texture.as_ref().is_some_and(|t| t.two_sided)),
                    0.0,
                    0.0,
                ],
            };
            uniform_bytes[i * stride..i * stride + size_of::<OrganUniform>()]
                .copy_from_slice(bytemuck::bytes_of(&uniform));
        }
        if !uniform_bytes.is_empty() {
            queue.write_buffer(&self.organ_uniform_buffer, 0, &uniform_bytes);
        }
    }

    /// Uploads `organs`, replacing the previous ones. Buffers are reused
    /// while the new data fits, so calling this every animation frame is
    /// fine. Nothing is uploaded when an organ is malformed.
    pub fn set_organs(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        organs: &[OrganMesh],
    ) -> Result<(), RenderError> {
        for (organ, mesh) in organs.iter().enumerate() {
            mesh.check()
                .map_err(|reason| RenderError::InvalidMesh { organ, reason })?;
        }
        self.ground = ground_under(organs);
        if organs.len() > self.organ_uniform_capacity {
            let capacity = organs.len().next_power_of_two();
            let (buffer, bind_group) = Self::create_organ_uniforms(
                device,
                &self.organ_layout,
                self.organ_uniform_stride,
                capacity,
            );
            self.organ_uniform_buffer = buffer;
            self.organ_bind_group = bind_group;
            self.organ_uniform_capacity = capacity;
        }
        self.write_organ_uniforms(queue, organs);

        self.organs.truncate(organs.len());
        for (i, mesh) in organs.iter().enumerate() {
            let vertices: Vec<Vertex> = (0..mesh.positions_in_world.len())
                .map(|v| Vertex {
                    position_in_world: mesh.positions_in_world[v],
                    normal_in_world: mesh.normals_in_world[v],
                    overlay: mesh.overlay.as_ref().map_or(0.0, |o| o[v]),
                    uv: mesh.texture.as_ref().map_or([0.0; 2], |t| t.uvs[v]),
                })
                .collect();
            // The texture: kept while the same image comes back.
            let previous = self.organs.get_mut(i).and_then(|gpu| gpu.texture.take());
            let texture = mesh.texture.as_ref().map(|t| match previous {
                Some((image, bind_group)) if Arc::ptr_eq(&image, &t.image) => (image, bind_group),
                _ => {
                    let bind_group = Self::create_texture(
                        device,
                        queue,
                        &self.texture_layout,
                        &self.texture_sampler,
                        &t.image,
                    );
                    (Arc::clone(&t.image), bind_group)
                }
            });
            let vertex_bytes: &[u8] = bytemuck::cast_slice(&vertices);
            let index_bytes: &[u8] = bytemuck::cast_slice(&mesh.triangles);
            let index_count = (mesh.triangles.len() * 3) as u32;
            let fits = self.organs.get(i).is_some_and(|gpu| {
                gpu.vertices.size() >= vertex_bytes.len() as u64
                    && gpu.indices.size() >= index_bytes.len() as u64
            });
            if fits {
                let gpu = &mut self.organs[i];
                if !vertex_bytes.is_empty() {
                    queue.write_buffer(&gpu.vertices, 0, vertex_bytes);
                }
                if !index_bytes.is_empty() {
                    queue.write_buffer(&gpu.indices, 0, index_bytes);
                }
                gpu.index_count = index_count;
                gpu.texture = texture;
            } else {
                let create = |label, contents: &[u8], usage| {
                    // Zero-sized buffers cannot be bound: keep at least one word.
                    let padded;
                    let contents = if contents.is_empty() {
                        padded = [0_u8; 4];
                        &padded[..]
                    } else {
                        contents
                    };
                    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some(label),
                        contents,
                        usage: usage | wgpu::BufferUsages::COPY_DST,
                    })
                };
                let gpu = GpuOrgan {
                    vertices: create(
                        "anthesis organ vertices",
                        vertex_bytes,
                        wgpu::BufferUsages::VERTEX,
                    ),
                    indices: create(
                        "anthesis organ indices",
                        index_bytes,
                        wgpu::BufferUsages::INDEX,
                    ),
                    index_count,
                    texture,
                };
                if i < self.organs.len() {
                    self.organs[i] = gpu;
                } else {
                    self.organs.push(gpu);
                }
            }
        }
        Ok(())
    }

    /// Writes the camera (and the background) for an image of
    /// `width / height` = `aspect`.
    pub fn set_camera(&self, queue: &wgpu::Queue, camera: &Camera, aspect: f32) {
        let [tr, tg, tb] = self.background.top_srgb;
        let [br, bg, bb] = self.background.bottom_srgb;
        let eye = camera.eye.as_vec3();
        let light = camera.key_light_direction().as_vec3();
        let uniform = FrameUniform {
            view_projection: camera.view_projection(aspect).to_cols_array_2d(),
            eye_in_world: [eye.x, eye.y, eye.z, 1.0],
            light_direction_in_world: [light.x, light.y, light.z, 0.0],
            background_top_srgb: [tr, tg, tb, 1.0],
            background_bottom_srgb: [br, bg, bb, 1.0],
            output_flags: [
                if self.format.colour.is_srgb() {
                    0.0
                } else {
                    1.0
                },
                BACK_SIDE_BRIGHTNESS,
                0.0,
                0.0,
            ],
            inverse_view_projection: camera.view_projection(aspect).inverse().to_cols_array_2d(),
            ground: self.ground,
        };
        queue.write_buffer(&self.frame_buffer, 0, bytemuck::bytes_of(&uniform));
    }

    /// Draws the background gradient (without touching depth) and then the
    /// organs into a pass the caller began. The pass's attachments must
    /// match [`OrganPipeline::format`] and its depth must have been cleared
    /// to [`DEPTH_CLEAR_VALUE`].
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        self.draw_background(pass);
        self.draw_organs(pass);
    }

    /// Only the background gradient (a full-screen triangle).
    pub fn draw_background(&self, pass: &mut wgpu::RenderPass<'_>) {
        pass.set_pipeline(&self.background_pipeline);
        pass.set_bind_group(0, &self.frame_bind_group, &[]);
        pass.set_bind_group(1, &self.organ_bind_group, &[0]);
        pass.set_bind_group(2, &self.white_texture, &[]);
        pass.draw(0..3, 0..1);
    }

    /// Only the organs, depth-tested.
    pub fn draw_organs(&self, pass: &mut wgpu::RenderPass<'_>) {
        pass.set_pipeline(&self.organ_pipeline);
        pass.set_bind_group(0, &self.frame_bind_group, &[]);
        for (i, organ) in self.organs.iter().enumerate() {
            if organ.index_count == 0 {
                continue;
            }
            let offset = (i as u64 * self.organ_uniform_stride) as u32;
            pass.set_bind_group(1, &self.organ_bind_group, &[offset]);
            let texture = organ.texture.as_ref().map_or(&self.white_texture, |t| &t.1);
            pass.set_bind_group(2, texture, &[]);
            pass.set_vertex_buffer(0, organ.vertices.slice(..));
            pass.set_index_buffer(organ.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..organ.index_count, 0, 0..1);
        }
    }

    /// Records a complete pass: clears `depth_view` to
    /// [`DEPTH_CLEAR_VALUE`], draws the background and the organs into
    /// `color_view`, and resolves into `resolve_view` when given (needed
    /// when `sample_count > 1`; both views then have the colour format).
    pub fn render(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        colour_view: &wgpu::TextureView,
        resolve_view: Option<&wgpu::TextureView>,
        depth_view: &wgpu::TextureView,
    ) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("anthesis organs"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: colour_view,
                depth_slice: None,
                resolve_target: resolve_view,
                ops: wgpu::Operations {
                    // The background covers everything; the clear only
                    // avoids loading stale contents.
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: if resolve_view.is_some() {
                        wgpu::StoreOp::Discard
                    } else {
                        wgpu::StoreOp::Store
                    },
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(DEPTH_CLEAR_VALUE),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        self.draw(&mut pass);
    }
}

/// Where the ground shadow goes under `organs`, as `Frame.ground` in
/// organ.wgsl: the centre of their bounds across (xz), the ground just
/// below their lowest point (y), and their radius across (w; 0 when there
/// is nothing to cast a shadow).
fn ground_under(organs: &[OrganMesh]) -> [f32; 4] {
    let Some((low, high)) = crate::organs_bounds_in_world(organs) else {
        return [0.0; 4];
    };
    let centre = 0.5 * (low + high);
    let radius = 0.5 * (high.x - low.x).max(high.z - low.z);
    if !radius.is_finite() || radius <= 0.0 {
        return [0.0; 4];
    }
    let ground_y = low.y - GROUND_GAP_IN_RADII * radius;
    [
        centre.x as f32,
        ground_y as f32,
        centre.z as f32,
        radius as f32,
    ]
}

/// egui_wgpu keeps callback resources in a map that requires `Send + Sync`.
const _: () = {
    const fn send_sync<T: Send + Sync>() {}
    send_sync::<OrganPipeline>();
    send_sync::<crate::RenderTarget>();
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_layouts_match_the_wgsl_structs() {
        let module =
            naga::front::wgsl::parse_str(&organ_shader_source()).expect("organ.wgsl parses");
        let size_of_struct = |name: &str| {
            let (_, ty) = module
                .types
                .iter()
                .find(|(_, ty)| ty.name.as_deref() == Some(name))
                .unwrap_or_else(|| panic!("struct {name} in organ.wgsl"));
            match &ty.inner {
                naga::TypeInner::Struct { span, .. } => *span as usize,
                other => panic!("{name} is not a struct: {other:?}"),
            }
        };
        assert_eq!(size_of_struct("Frame"), size_of::<FrameUniform>());
        assert_eq!(size_of_struct("Organ"), size_of::<OrganUniform>());
        assert_eq!(size_of::<Vertex>(), 36);
    }

    #[test]
    fn the_shader_gets_the_ramp_stops_the_crate_defines() {
        let source = organ_shader_source();
        assert!(source.starts_with("const RAMP_LOW: vec3<f32> = vec3<f32>(0.02, 0.1, 0.55);"));
        assert!(source.contains("const RAMP_HIGH: vec3<f32> = vec3<f32>(0.65, 0.02, 0.02);"));
        // The file itself names the stops and defines no colours of its own.
        assert!(
            !SHADER_SOURCE.contains("0.55"),
            "a ramp stop is hard-coded in organ.wgsl"
        );
        assert_eq!(overlay_ramp_linear(0.0), OVERLAY_RAMP_LINEAR[0]);
        assert_eq!(overlay_ramp_linear(0.5), OVERLAY_RAMP_LINEAR[1]);
        assert_eq!(overlay_ramp_linear(7.0), OVERLAY_RAMP_LINEAR[2]);
        let quarter = overlay_ramp_linear(0.25);
        for i in 0..3 {
            let halfway = 0.5 * (OVERLAY_RAMP_LINEAR[0][i] + OVERLAY_RAMP_LINEAR[1][i]);
            assert!((quarter[i] - halfway).abs() < 1e-6);
        }
    }
}

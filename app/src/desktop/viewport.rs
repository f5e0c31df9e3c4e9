//! The 3D viewport: an orbit camera, the scene of organs at the current
//! time, picking (ray → triangle → UV) and the egui_wgpu paint callback
//! that draws through `anthesis-render`'s pipeline.
//!
//! The callback renders into its own colour + depth target in `prepare`
//! (egui's render pass has no depth attachment) and copies that image into
//! egui's pass in `paint` with the small pipeline of
//! `shaders/viewport_blit.wgsl`.

use std::sync::Arc;

use anthesis_flower::Project;
use anthesis_maps::MapKind;
use anthesis_mesh::{Mesh, Topology};
use anthesis_render::{Camera, OrganMesh, OrganPipeline, RenderTarget, TargetFormat};
use eframe::egui::{self, Color32, Pos2, Rect, Sense, Stroke, Vec2};
use eframe::egui_wgpu::{self, wgpu};
use glam::{DMat4, DVec2, DVec3, DVec4};

use super::session::SimSession;

/// The WGSL that copies the rendered image into egui's pass.
pub const BLIT_SHADER_SOURCE: &str = include_str!("../../../shaders/viewport_blit.wgsl");

/// An orbit camera around `target`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OrbitCamera {
    pub target: DVec3,
    pub distance: f64,
    /// Around +Y, 0 = looking from +Z.
    pub azimuth_deg: f64,
    /// Above the XZ plane.
    pub elevation_deg: f64,
}

impl Default for OrbitCamera {
    fn default() -> Self {
        OrbitCamera {
            target: DVec3::new(0.0, 15.0, 0.0),
            distance: 90.0,
            azimuth_deg: 30.0,
            elevation_deg: 25.0,
        }
    }
}

/// Field of view of the viewport across its shorter side.
const FOV_DEG: f64 = 30.0;

impl OrbitCamera {
    fn towards_eye(&self) -> DVec3 {
        let (az, el) = (
            self.azimuth_deg.to_radians(),
            self.elevation_deg.to_radians(),
        );
        DVec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos())
    }

    pub fn camera(&self) -> Camera {
        let el = self.elevation_deg.to_radians();
        let az = self.azimuth_deg.to_radians();
        Camera {
            eye: self.target + self.distance * self.towards_eye(),
            target: self.target,
            up: DVec3::new(-el.sin() * az.sin(), el.cos(), -el.sin() * az.cos()),
            fov_y_deg: FOV_DEG,
        }
    }

    /// Looks at the box `[min, max]` from the current direction so that
    /// all of it is in view.
    pub fn frame(&mut self, bounds_in_world: (DVec3, DVec3)) {
        let framed = Camera::framing(
            bounds_in_world.0,
            bounds_in_world.1,
            self.azimuth_deg,
            self.elevation_deg,
        );
        self.target = framed.target;
        self.distance = framed.eye.distance(framed.target).max(1e-3);
    }

    pub fn orbit(&mut self, drag_in_points: Vec2) {
        self.azimuth_deg = (self.azimuth_deg - 0.4 * f64::from(drag_in_points.x)) % 360.0;
        self.elevation_deg =
            (self.elevation_deg + 0.4 * f64::from(drag_in_points.y)).clamp(-89.0, 89.0);
    }

    /// Moves the target with the image: `drag` in points over a viewport
    /// `height` points tall.
    pub fn pan(&mut self, drag_in_points: Vec2, height_in_points: f32) {
        let camera = self.camera();
        let towards_eye = self.towards_eye();
        let right = camera.up.cross(towards_eye).normalize_or_zero();
        let world_per_point = 2.0 * self.distance * (0.5 * FOV_DEG.to_radians()).tan()
            / f64::from(height_in_points.max(1.0));
        self.target += world_per_point
            * (-f64::from(drag_in_points.x) * right + f64::from(drag_in_points.y) * camera.up);
    }

    /// `factor` > 1 moves closer.
    pub fn zoom(&mut self, factor: f64) {
        self.distance = (self.distance / factor.max(1e-3)).clamp(1e-3, 1e6);
    }
}

/// One organ as displayed.
#[derive(Debug, Clone)]
pub struct SceneOrgan {
    /// Index into the project's organs.
    pub organ: usize,
    pub positions_in_world: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    pub uvs: Vec<DVec2>,
    /// Simulated in the current run (false: shown in its bud state).
    pub simulated: bool,
}

/// What the viewport shows besides the organs.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ViewOptions {
    pub wireframe: bool,
    /// A scalar map shown as a colour ramp on the surface.
    pub overlay: Option<MapKind>,
    /// Arrows of the growth direction on the selected organ.
    pub direction_arrows: bool,
    /// In single-organ preview: show the other organs in their bud state
    /// (otherwise hidden).
    pub show_others: bool,
}

/// The organs at keyframe time `time`: simulated organs from the run,
/// the others (when `show_others`) in their bud placement. An organ whose
/// keyframes no longer fit its template (the mesh was replaced) is shown as
/// a bud.
pub fn build_scene(
    project: &Project,
    session: &SimSession,
    time: f64,
    show_others: bool,
) -> Vec<SceneOrgan> {
    let positions = session.positions_at(time);
    let flower = &project.flower;
    let mut scene = Vec::new();
    for (i, organ) in flower.organs.iter().enumerate() {
        let template = flower.template_of(i);
        let slot = session.organs().iter().position(|&o| o == i);
        let simulated = slot
            .and_then(|s| positions.as_ref().and_then(|p| p.get(s)))
            .filter(|p| p.len() == template.mesh.vertex_count())
            .cloned();
        let (positions_in_world, simulated) = match simulated {
            Some(p) => (p, true),
            None if slot.is_some() || show_others => (
                template
                    .mesh
                    .positions
                    .iter()
                    .map(|p| organ.placement.world_from_template(*p, 0.0))
                    .collect(),
                false,
            ),
            None => continue,
        };
        scene.push(SceneOrgan {
            organ: i,
            positions_in_world,
            triangles: template.mesh.triangles.clone(),
            uvs: template.mesh.uvs.clone(),
            simulated,
        });
    }
    scene
}

/// Axis-aligned bounds of the scene.
pub fn scene_bounds(scene: &[SceneOrgan]) -> Option<(DVec3, DVec3)> {
    let mut points = scene.iter().flat_map(|o| o.positions_in_world.iter());
    let first = *points.next()?;
    Some(points.fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p))))
}

/// The selection highlight, linear RGB (a warm yellow, sRGB 255, 219, 115).
const HIGHLIGHT_LINEAR: [f32; 3] = [1.0, 0.71, 0.17];

/// Meshes for the renderer: each organ in its template colour (linear, as
/// the renderer takes it); the selected one tinted towards a warm
/// highlight; organs not simulated (bud placeholders in preview) washed out
/// towards grey; the overlay map as a ramp.
pub fn scene_meshes(
    project: &Project,
    scene: &[SceneOrgan],
    selected: Option<usize>,
    overlay: Option<(MapKind, usize)>,
) -> Vec<OrganMesh> {
    scene
        .iter()
        .map(|o| {
            let template = project.flower.template_of(o.organ);
            let mut color_linear = template.color;
            if selected == Some(o.organ) {
                for (c, h) in color_linear.iter_mut().zip(HIGHLIGHT_LINEAR) {
                    *c += 0.45 * (h - *c);
                }
            } else if !o.simulated {
                for c in color_linear.iter_mut().take(3) {
                    *c = 0.26 + 0.43 * *c;
                }
            }
            let mesh = OrganMesh::from_positions(&o.positions_in_world, &o.triangles, color_linear);
            match overlay {
                Some((kind, key)) => {
                    let map = template.maps.key_clamped(key).maps.scalar(kind);
                    let values = o.uvs.iter().map(|uv| map.sample(*uv) as f32).collect();
                    mesh.with_overlay(values)
                }
                None => mesh,
            }
        })
        .collect()
}

/// A hit of a ray on the scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Index into the project's organs.
    pub organ: usize,
    pub triangle: usize,
    pub point_in_uv: DVec2,
    pub distance: f64,
}

/// The ray from the eye through `ndc` (x right, y up, in [-1, 1]).
pub fn ray_through(camera: &Camera, aspect: f32, ndc: DVec2) -> (DVec3, DVec3) {
    let inverse: DMat4 = camera.view_projection(aspect).as_dmat4().inverse();
    let on_near = inverse * DVec4::new(ndc.x, ndc.y, 1.0, 1.0);
    let further = inverse * DVec4::new(ndc.x, ndc.y, 0.5, 1.0);
    let a = on_near.truncate() / on_near.w;
    let b = further.truncate() / further.w;
    (camera.eye, (b - a).normalize_or(DVec3::NEG_Z))
}

/// The nearest triangle the ray `origin + t direction` hits (Möller–Trumbore).
pub fn pick(scene: &[SceneOrgan], origin: DVec3, direction: DVec3) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    for o in scene {
        for (t, tri) in o.triangles.iter().enumerate() {
            let [p0, p1, p2] = tri.map(|i| o.positions_in_world[i as usize]);
            let (e1, e2) = (p1 - p0, p2 - p0);
            let h = direction.cross(e2);
            let det = e1.dot(h);
            if det.abs() < 1e-12 {
                continue;
            }
            let s = origin - p0;
            let u = s.dot(h) / det;
            if !(0.0..=1.0).contains(&u) {
                continue;
            }
            let q = s.cross(e1);
            let v = direction.dot(q) / det;
            if v < 0.0 || u + v > 1.0 {
                continue;
            }
            let distance = e2.dot(q) / det;
            if distance <= 0.0 || best.is_some_and(|b| b.distance <= distance) {
                continue;
            }
            let [uv0, uv1, uv2] = tri.map(|i| o.uvs[i as usize]);
            best = Some(Hit {
                organ: o.organ,
                triangle: t,
                point_in_uv: uv0 + u * (uv1 - uv0) + v * (uv2 - uv0),
                distance,
            });
        }
    }
    best
}

/// Screen position of a world point, `None` behind the eye.
fn project_to_screen(view_projection: &DMat4, rect: Rect, point_in_world: DVec3) -> Option<Pos2> {
    let clip = *view_projection * point_in_world.extend(1.0);
    if clip.w <= 1e-9 {
        return None;
    }
    let ndc = clip.truncate() / clip.w;
    Some(Pos2::new(
        rect.left() + (0.5 + 0.5 * ndc.x as f32) * rect.width(),
        rect.top() + (0.5 - 0.5 * ndc.y as f32) * rect.height(),
    ))
}

/// What happened in the viewport this frame.
#[derive(Debug, Default, Clone, Copy, PartialEq)]
pub struct ViewportResponse {
    /// A click that hit an organ.
    pub clicked: Option<Hit>,
    /// Where the pointer is over an organ.
    pub hovered: Option<Hit>,
    /// The primary button is down and the pointer on an organ, with a
    /// paint modifier held (for painting on the 3D organ).
    pub painting: Option<Hit>,
}

/// Draws the viewport into the rest of `ui`: the organs through the paint
/// callback, the wireframe / outline / arrows overlays, and handles the
/// camera. With `paint_mode` the primary button reports paint hits instead
/// of orbiting.
#[allow(clippy::too_many_arguments)]
pub fn viewport_ui(
    ui: &mut egui::Ui,
    camera: &mut OrbitCamera,
    project: &Project,
    scene: &[SceneOrgan],
    meshes: Arc<Vec<OrganMesh>>,
    revision: u64,
    options: &ViewOptions,
    selected: Option<(usize, &[[u32; 2]])>,
    direction_key: Option<usize>,
    paint_modifier: bool,
) -> ViewportResponse {
    let rect = ui.available_rect_before_wrap();
    let response = ui.allocate_rect(rect, Sense::click_and_drag());
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Canvas, true, "3D viewport"));
    let mut result = ViewportResponse::default();

    // In paint mode the primary button paints and Shift+drag orbits;
    // otherwise it orbits and Shift+drag pans.
    let shift = ui.input(|i| i.modifiers.shift);
    let painting = paint_modifier && !shift && ui.input(|i| i.pointer.primary_down());
    if response.dragged_by(egui::PointerButton::Primary) && !painting {
        if shift && !paint_modifier {
            camera.pan(response.drag_delta(), rect.height());
        } else {
            camera.orbit(response.drag_delta());
        }
    }
    if response.dragged_by(egui::PointerButton::Secondary)
        || response.dragged_by(egui::PointerButton::Middle)
    {
        camera.pan(response.drag_delta(), rect.height());
    }
    if response.hovered() {
        let (scroll, zoom) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
        if scroll != 0.0 {
            camera.zoom((f64::from(scroll) * 0.0025).exp());
        }
        if zoom != 1.0 {
            camera.zoom(f64::from(zoom));
        }
    }
    if response.double_clicked()
        && let Some(bounds) = scene_bounds(scene)
    {
        camera.frame(bounds);
    }

    let aspect = rect.width() / rect.height().max(1.0);
    let render_camera = camera.camera();
    let hit_at = |pos: Pos2| {
        let ndc = DVec2::new(
            f64::from((pos.x - rect.left()) / rect.width() * 2.0 - 1.0),
            f64::from(1.0 - (pos.y - rect.top()) / rect.height() * 2.0),
        );
        let (origin, direction) = ray_through(&render_camera, aspect, ndc);
        pick(scene, origin, direction)
    };
    if let Some(pos) = response.hover_pos() {
        result.hovered = hit_at(pos);
        if painting {
            result.painting = result.hovered;
        }
    }
    if response.clicked()
        && let Some(pos) = response.interact_pointer_pos()
    {
        result.clicked = hit_at(pos);
    }

    let pixels_per_point = ui.ctx().pixels_per_point();
    let size_in_pixels = [
        (rect.width() * pixels_per_point).round().max(1.0) as u32,
        (rect.height() * pixels_per_point).round().max(1.0) as u32,
    ];
    ui.painter().add(egui_wgpu::Callback::new_paint_callback(
        rect,
        ViewportCallback {
            meshes,
            revision,
            camera: render_camera,
            size_in_pixels,
        },
    ));

    let view_projection = render_camera.view_projection(aspect).as_dmat4();
    let painter = ui.painter_at(rect);
    let to_screen = |p: DVec3| project_to_screen(&view_projection, rect, p);
    if options.wireframe {
        let stroke = Stroke::new(0.6, Color32::from_black_alpha(110));
        let mut shapes = Vec::new();
        for o in scene {
            let screen: Vec<Option<Pos2>> =
                o.positions_in_world.iter().map(|p| to_screen(*p)).collect();
            for tri in &o.triangles {
                for (a, b) in [(tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])] {
                    // Each interior edge is drawn from one side only.
                    if a < b
                        && let (Some(pa), Some(pb)) = (screen[a as usize], screen[b as usize])
                    {
                        shapes.push(egui::Shape::line_segment([pa, pb], stroke));
                    }
                }
            }
        }
        painter.extend(shapes);
    }
    if let Some((o, outline)) =
        selected.and_then(|(s, outline)| Some((scene.iter().find(|o| o.organ == s)?, outline)))
    {
        let stroke = Stroke::new(2.0, Color32::from_rgb(255, 170, 40));
        let mut shapes = Vec::new();
        for &[a, b] in outline {
            if let (Some(pa), Some(pb)) = (
                to_screen(o.positions_in_world[a as usize]),
                to_screen(o.positions_in_world[b as usize]),
            ) {
                shapes.push(egui::Shape::line_segment([pa, pb], stroke));
            }
        }
        painter.extend(shapes);
        if options.direction_arrows
            && let Some(key) = direction_key
        {
            direction_arrows(&painter, project, o, key, &to_screen);
        }
    }
    if scene.is_empty() {
        painter.text(
            rect.center(),
            egui::Align2::CENTER_CENTER,
            "Waiting for the bud…",
            egui::FontId::proportional(16.0),
            ui.visuals().weak_text_color(),
        );
    }
    result
}

/// The outline (boundary edges) of the selected organ's mesh, taken from
/// its [`Topology`] and rebuilt only when the mesh's triangles change, not
/// every frame.
#[derive(Debug, Default)]
pub struct Outline {
    triangles: Vec<[u32; 3]>,
    edges: Vec<[u32; 2]>,
}

impl Outline {
    /// The boundary edges of `mesh` (none when it has no valid topology;
    /// template meshes are validated when they are loaded).
    pub fn edges_of(&mut self, mesh: &Mesh) -> &[[u32; 2]] {
        if self.triangles != mesh.triangles {
            self.edges = Topology::build(mesh)
                .map(|topology| topology.boundary_edges().collect())
                .unwrap_or_default();
            self.triangles.clone_from(&mesh.triangles);
        }
        &self.edges
    }
}

/// Arrows of the direction map on a sample of the organ's triangles: each
/// triangle's UV direction pushed through its UV → world Jacobian.
fn direction_arrows(
    painter: &egui::Painter,
    project: &Project,
    organ: &SceneOrgan,
    key: usize,
    to_screen: &dyn Fn(DVec3) -> Option<Pos2>,
) {
    let template = project.flower.template_of(organ.organ);
    let map = &template.maps.key_clamped(key).maps.direction;
    // About 60 arrows per organ, each a little shorter than an edge.
    let stride = (organ.triangles.len() / 60).max(2);
    let stroke = Stroke::new(1.2, Color32::from_rgb(20, 60, 160));
    for tri in organ.triangles.iter().step_by(stride) {
        let [p0, p1, p2] = tri.map(|i| organ.positions_in_world[i as usize]);
        let [u0, u1, u2] = tri.map(|i| organ.uvs[i as usize]);
        let (du1, du2) = (u1 - u0, u2 - u0);
        let det = du1.x * du2.y - du2.x * du1.y;
        if det.abs() < 1e-12 {
            continue;
        }
        let centre_uv = (u0 + u1 + u2) / 3.0;
        let d = map.sample(centre_uv);
        // Solve d = a du1 + b du2, then map to world with the edges.
        let a = (d.x * du2.y - du2.x * d.y) / det;
        let b = (du1.x * d.y - d.x * du1.y) / det;
        let world = a * (p1 - p0) + b * (p2 - p0);
        let mean_edge = ((p1 - p0).length() + (p2 - p0).length()) * 0.5;
        let direction = world.normalize_or_zero() * mean_edge * 0.8 * d.length().min(1.0);
        let centre = (p0 + p1 + p2) / 3.0;
        if let (Some(from), Some(to)) = (to_screen(centre), to_screen(centre + direction)) {
            painter.arrow(from, to - from, stroke);
        }
    }
}

/// The paint callback: renders `meshes` from `camera` into the viewport.
struct ViewportCallback {
    meshes: Arc<Vec<OrganMesh>>,
    /// Changes whenever `meshes` does, so unchanged frames skip the upload.
    revision: u64,
    camera: Camera,
    size_in_pixels: [u32; 2],
}

/// GPU state of the viewport, kept in egui_wgpu's callback resources.
pub struct ViewportGpu {
    organs: OrganPipeline,
    target: Option<RenderTarget>,
    uploaded_revision: Option<u64>,
    blit: wgpu::RenderPipeline,
    blit_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    blit_bind_group: Option<wgpu::BindGroup>,
}

/// The offscreen image's format: not sRGB, so the organ shader writes
/// encoded values and the copy passes them on (or decodes them for an sRGB
/// egui target).
const OFFSCREEN_FORMAT: TargetFormat = TargetFormat {
    color: wgpu::TextureFormat::Rgba8Unorm,
    depth: wgpu::TextureFormat::Depth32Float,
    sample_count: 4,
};

impl ViewportGpu {
    /// Creates the pipelines for egui's pass of `egui_target_format`
    /// (single-sampled, no depth: eframe's and egui_kittest's defaults).
    pub fn new(device: &wgpu::Device, egui_target_format: wgpu::TextureFormat) -> ViewportGpu {
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("anthesis viewport blit"),
            source: wgpu::ShaderSource::Wgsl(BLIT_SHADER_SOURCE.into()),
        });
        let blit_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("anthesis viewport image"),
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
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("anthesis viewport blit"),
            bind_group_layouts: &[Some(&blit_layout)],
            immediate_size: 0,
        });
        let fragment_entry = if egui_target_format.is_srgb() {
            "fs_blit_decoded"
        } else {
            "fs_blit_encoded"
        };
        let blit = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("anthesis viewport blit"),
            layout: Some(&layout),
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
                    format: egui_target_format,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("anthesis viewport image"),
            mag_filter: wgpu::FilterMode::Nearest,
            min_filter: wgpu::FilterMode::Nearest,
            ..Default::default()
        });
        ViewportGpu {
            organs: OrganPipeline::new(device, OFFSCREEN_FORMAT),
            target: None,
            uploaded_revision: None,
            blit,
            blit_layout,
            sampler,
            blit_bind_group: None,
        }
    }

    /// Registers the viewport's GPU state with eframe's renderer.
    pub fn install(render_state: &egui_wgpu::RenderState) {
        let gpu = ViewportGpu::new(&render_state.device, render_state.target_format);
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
            let target = RenderTarget::new(device, OFFSCREEN_FORMAT, width, height);
            gpu.blit_bind_group = Some(device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("anthesis viewport image"),
                layout: &gpu.blit_layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(target.view()),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::Sampler(&gpu.sampler),
                    },
                ],
            }));
            gpu.target = Some(target);
        }
        if gpu.uploaded_revision != Some(self.revision) {
            // Meshes come from validated templates; a malformed one is
            // skipped (the previous upload stays) rather than drawn wrong.
            let _ = gpu.organs.set_organs(device, queue, &self.meshes);
            gpu.uploaded_revision = Some(self.revision);
        }
        if let Some(target) = &gpu.target {
            gpu.organs.set_camera(queue, &self.camera, target.aspect());
            target.render(&gpu.organs, egui_encoder);
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
        if let Some(bind_group) = &gpu.blit_bind_group {
            render_pass.set_pipeline(&gpu.blit);
            render_pass.set_bind_group(0, bind_group, &[]);
            render_pass.draw(0..3, 0..1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat_square() -> SceneOrgan {
        SceneOrgan {
            organ: 3,
            positions_in_world: vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            uvs: vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(1.0, 0.0),
                DVec2::new(1.0, 1.0),
                DVec2::new(0.0, 1.0),
            ],
            simulated: true,
        }
    }

    #[test]
    fn a_ray_through_the_image_centre_hits_the_target_and_gives_its_uv() {
        let scene = [flat_square()];
        let mut orbit = OrbitCamera {
            azimuth_deg: 0.0,
            elevation_deg: 0.0,
            ..OrbitCamera::default()
        };
        orbit.target = DVec3::new(0.25, 0.75, 0.0);
        orbit.distance = 5.0;
        let camera = orbit.camera();
        let (origin, direction) = ray_through(&camera, 1.5, DVec2::ZERO);
        let hit = pick(&scene, origin, direction).expect("hits the square");
        assert_eq!(hit.organ, 3);
        assert_eq!(hit.triangle, 1);
        assert!((hit.point_in_uv - DVec2::new(0.25, 0.75)).length() < 1e-9);
        assert!((hit.distance - 5.0).abs() < 1e-9);
        // Looking away from the square misses.
        let (origin, direction) = ray_through(&camera, 1.5, DVec2::new(0.9, 0.9));
        assert!(pick(&scene, origin, direction).is_none());
    }

    #[test]
    fn framing_puts_the_whole_box_in_front_of_the_camera() {
        let mut orbit = OrbitCamera::default();
        orbit.frame((DVec3::new(-5.0, 0.0, -5.0), DVec3::new(5.0, 30.0, 5.0)));
        assert!((orbit.target - DVec3::new(0.0, 15.0, 0.0)).length() < 1e-9);
        assert!(orbit.distance > 30.0, "{}", orbit.distance);
        let before = orbit.distance;
        orbit.zoom(2.0);
        assert!((orbit.distance - before / 2.0).abs() < 1e-9);
    }

    #[test]
    fn the_outline_of_a_square_is_its_four_sides_until_the_mesh_changes() {
        let square = flat_square();
        let mut mesh = Mesh {
            positions: square.positions_in_world.clone(),
            uvs: square.uvs.clone(),
            triangles: square.triangles.clone(),
        };
        let mut outline = Outline::default();
        let sorted = |outline: &mut Outline, mesh: &Mesh| {
            let mut edges: Vec<[u32; 2]> = outline
                .edges_of(mesh)
                .iter()
                .map(|&[a, b]| [a.min(b), a.max(b)])
                .collect();
            edges.sort_unstable();
            edges
        };
        assert_eq!(
            sorted(&mut outline, &mesh),
            [[0, 1], [0, 3], [1, 2], [2, 3]]
        );
        // One triangle left: its three sides.
        mesh.triangles.truncate(1);
        mesh.positions.truncate(3);
        mesh.uvs.truncate(3);
        assert_eq!(sorted(&mut outline, &mesh), [[0, 1], [0, 2], [1, 2]]);
    }
}

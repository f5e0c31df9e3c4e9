//! The 3D viewport: the widget that turns the orbit camera
//! (`anthesis_render::OrbitCamera`), picks organs (ray casting from
//! `anthesis_mesh::ray`, giving the UV under the pointer) and draws them. The organs
//! shown are built in [`scene`], drawn on the GPU by [`gpu`] (through
//! `anthesis-render`), with egui overlays from [`overlays`].

pub mod field;
pub mod gpu;
pub mod organ;
pub mod overlays;
pub mod scene;

use std::sync::Arc;

use anthesis_flower::Project;
use anthesis_maps::MapKind;
use anthesis_mesh::ray::nearest_hit;
use anthesis_render::{OrbitCamera, OrganMesh};
use eframe::egui::{self, Color32, Pos2, Sense, Stroke, Vec2};
use eframe::egui_wgpu;
use glam::{DVec2, DVec3};

pub use field::{FieldShown, Quantity, ScalarField, ViewField};
pub use gpu::ViewportGpu;
pub use overlays::Outline;
pub use scene::{
    SceneCache, SceneKey, SceneOrgan, build_scene, build_scene_of, scene_bounds, scene_meshes,
};

/// What the viewport shows besides the organs.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct ViewOptions {
    pub wireframe: bool,
    /// A scalar map shown as a colour ramp on the surface.
    pub overlay: Option<MapKind>,
    /// A per-vertex field ([`field`]) shown as a colour ramp with a legend,
    /// instead of the map overlay.
    pub field: Option<ViewField>,
    /// Arrows of the growth direction on the selected organ.
    pub direction_arrows: bool,
    /// In single-organ preview: show the other organs in their bud state
    /// (otherwise hidden).
    pub show_others: bool,
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

/// The nearest organ triangle the ray `origin + t direction` meets
/// (anthesis-mesh's ray casting), with the UV of the point hit.
pub fn pick(scene: &[SceneOrgan], origin: DVec3, direction: DVec3) -> Option<Hit> {
    scene
        .iter()
        .filter_map(|o| {
            let hit = nearest_hit(origin, direction, &o.positions_in_world, &o.triangles)?;
            let corners = o.triangles[hit.triangle].map(|i| o.uvs[i as usize]);
            Some(Hit {
                organ: o.organ,
                triangle: hit.triangle,
                point_in_uv: hit.interpolate(corners),
                distance: hit.distance,
            })
        })
        .min_by(|a, b| a.distance.total_cmp(&b.distance))
}

/// A drag in egui points as a vector for the camera.
fn points(drag: Vec2) -> DVec2 {
    DVec2::new(f64::from(drag.x), f64::from(drag.y))
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
    /// Painting, but the pointer is on no organ (the stroke breaks there).
    pub painting_off_organ: bool,
}

/// A badge in the top-left corner of the viewport `rect` saying what the
/// view shows when it is not the converged result ("PROXY", "STALE") or is
/// wrong ("CROSSING: …"): white text on `color`, `row` badges down.
pub fn badge(ui: &egui::Ui, rect: egui::Rect, row: usize, text: &str, colour: egui::Color32) {
    let font = egui::FontId::proportional(13.0);
    let galley = ui
        .painter()
        .layout_no_wrap(text.to_string(), font, egui::Color32::WHITE);
    let at = rect.left_top() + Vec2::new(10.0, 10.0 + 26.0 * row as f32);
    let frame = egui::Rect::from_min_size(at, galley.size() + Vec2::new(12.0, 6.0));
    let painter = ui.painter_at(rect);
    painter.rect_filled(frame, 4.0, colour);
    painter.galley(at + Vec2::new(6.0, 3.0), galley, egui::Color32::WHITE);
    // Said to screen readers (and found by tests) as a label.
    ui.interact(
        frame,
        ui.scope_id().with(("viewport badge", row)),
        Sense::hover(),
    )
    .widget_info(|| egui::WidgetInfo::labeled(egui::Role::Label, true, text));
}

/// The zoom of one mouse-wheel line (egui scrolls
/// [`egui::InputOptions::line_scroll_speed`], 40 points, per line on the
/// desktop): 4 % closer or further, so that a few notches frame a petal
/// precisely (it was 10.5 % a line).
pub const WHEEL_ZOOM_PER_LINE: f64 = 1.04;

/// The zoom factor of a wheel scroll of `scroll_in_points` (up: closer).
pub fn wheel_zoom_factor(scroll_in_points: f32) -> f64 {
    WHEEL_ZOOM_PER_LINE.powf(f64::from(scroll_in_points) / 40.0)
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
    brush_radius_in_uv: f64,
) -> ViewportResponse {
    let rect = ui.available_rect_before_wrap();
    let response = ui.allocate_rect(rect, Sense::click_and_drag());
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Canvas, true, "3D viewport"));
    let mut result = ViewportResponse::default();

    // In paint mode the primary button paints and Shift+drag orbits;
    // otherwise it orbits and Shift+drag pans.
    let shift = ui.input(|i| i.modifiers.shift);
    let painting = paint_modifier && !shift && ui.input(|i| i.pointer.primary_down());
    // A dab where the pointer is pressed or moves while held: holding
    // still does not paint again on every redraw.
    let fresh = ui.input(|i| i.pointer.primary_pressed() || i.pointer.delta() != Vec2::ZERO);
    if response.dragged_by(egui::PointerButton::Primary) && !painting {
        if shift && !paint_modifier {
            camera.pan(points(response.drag_delta()), f64::from(rect.height()));
        } else {
            camera.orbit(points(response.drag_delta()));
        }
    }
    if response.dragged_by(egui::PointerButton::Secondary)
        || response.dragged_by(egui::PointerButton::Middle)
    {
        camera.pan(points(response.drag_delta()), f64::from(rect.height()));
    }
    if response.hovered() {
        let (scroll, zoom) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
        if scroll != 0.0 {
            camera.zoom(wheel_zoom_factor(scroll));
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
        let (origin, direction) = render_camera.ray_through(aspect, ndc);
        pick(scene, origin, direction)
    };
    if let Some(pos) = response.hover_pos() {
        result.hovered = hit_at(pos);
        if painting && fresh {
            result.painting = result.hovered;
            result.painting_off_organ = result.hovered.is_none();
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
        gpu::ViewportCallback {
            meshes,
            revision,
            camera: render_camera,
            size_in_pixels,
        },
    ));

    let view_projection = render_camera.view_projection(aspect).as_dmat4();
    let painter = ui.painter_at(rect);
    overlays::draw(
        &painter,
        &view_projection,
        project,
        scene,
        options,
        selected,
        direction_key,
    );
    if paint_modifier
        && let (Some(pos), Some(hit), Some((organ, _))) =
            (response.hover_pos(), result.hovered, selected)
        && hit.organ == organ
        && let Some(radius) = brush_radius_on_screen(scene, &hit, brush_radius_in_uv, &|p| {
            overlays::project_to_screen(&view_projection, rect, p)
        })
    {
        // The brush outline on the organ: a screen-space circle of the
        // brush's UV radius scaled by the picked triangle (see
        // `brush_radius_on_screen`).
        painter.circle_stroke(
            pos,
            radius + 1.0,
            Stroke::new(1.0, Color32::from_black_alpha(160)),
        );
        painter.circle_stroke(pos, radius, Stroke::new(1.0, Color32::WHITE));
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

/// The brush radius in screen points at `hit`: `radius_in_uv` times the
/// picked triangle's screen size per UV unit (the square root of its
/// screen area over its UV area, so a stretched or foreshortened triangle
/// gives the mean of its two scales). `None` for a triangle degenerate in
/// UV or behind the camera.
fn brush_radius_on_screen(
    scene: &[SceneOrgan],
    hit: &Hit,
    radius_in_uv: f64,
    to_screen: &dyn Fn(glam::DVec3) -> Option<Pos2>,
) -> Option<f32> {
    let organ = scene.iter().find(|o| o.organ == hit.organ)?;
    let corners = organ.triangles.get(hit.triangle)?;
    let uv = corners.map(|i| organ.uvs[i as usize]);
    let screen = [
        to_screen(organ.positions_in_world[corners[0] as usize])?,
        to_screen(organ.positions_in_world[corners[1] as usize])?,
        to_screen(organ.positions_in_world[corners[2] as usize])?,
    ];
    let area_in_uv = 0.5 * (uv[1] - uv[0]).perp_dot(uv[2] - uv[0]).abs();
    let (a, b) = (screen[1] - screen[0], screen[2] - screen[0]);
    let area_on_screen = 0.5 * f64::from((a.x * b.y - a.y * b.x).abs());
    if area_in_uv < 1e-12 {
        return None;
    }
    Some((radius_in_uv * (area_on_screen / area_in_uv).sqrt()) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use anthesis_mesh::Mesh;

    #[test]
    fn one_wheel_line_zooms_four_percent_and_back_again() {
        let line = egui::InputOptions::default().line_scroll_speed;
        assert!((wheel_zoom_factor(line) - 1.04).abs() < 1e-6);
        assert!((wheel_zoom_factor(line) * wheel_zoom_factor(-line) - 1.0).abs() < 1e-12);
        // Smooth scrolling spreads a line over frames: the same zoom in all.
        let spread: f64 = (0..7).map(|_| wheel_zoom_factor(line / 7.0)).product();
        assert!((spread - 1.04).abs() < 1e-6);
    }

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
        let (origin, direction) = camera.ray_through(1.5, DVec2::ZERO);
        let hit = pick(&scene, origin, direction).expect("hits the square");
        assert_eq!(hit.organ, 3);
        assert_eq!(hit.triangle, 1);
        assert!((hit.point_in_uv - DVec2::new(0.25, 0.75)).length() < 1e-9);
        assert!((hit.distance - 5.0).abs() < 1e-9);
        // Looking away from the square misses.
        let (origin, direction) = camera.ray_through(1.5, DVec2::new(0.9, 0.9));
        assert!(pick(&scene, origin, direction).is_none());
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

    #[test]
    fn the_brush_outline_on_the_organ_scales_with_the_picked_triangle_on_screen() {
        // The unit square in UV shown 200 points wide: 200 points per UV
        // unit, whatever the triangle.
        let scene = [flat_square()];
        let to_screen = |p: DVec3| {
            Some(Pos2::new(
                100.0 + 200.0 * p.x as f32,
                50.0 - 200.0 * p.y as f32,
            ))
        };
        for triangle in 0..2 {
            let hit = Hit {
                organ: 3,
                triangle,
                point_in_uv: DVec2::splat(0.5),
                distance: 1.0,
            };
            let radius = brush_radius_on_screen(&scene, &hit, 0.05, &to_screen);
            assert!(
                radius.is_some_and(|r| (r - 10.0).abs() < 1e-4),
                "{radius:?}"
            );
        }
        // Squashed to half height on screen: the mean scale, sqrt(1/2).
        let squashed = |p: DVec3| {
            Some(Pos2::new(
                100.0 + 200.0 * p.x as f32,
                50.0 - 100.0 * p.y as f32,
            ))
        };
        let hit = Hit {
            organ: 3,
            triangle: 0,
            point_in_uv: DVec2::splat(0.5),
            distance: 1.0,
        };
        let radius = brush_radius_on_screen(&scene, &hit, 0.05, &squashed);
        assert!(
            radius.is_some_and(|r| (r - 10.0 * 0.5_f32.sqrt()).abs() < 1e-4),
            "{radius:?}"
        );
        // Behind the camera: no outline.
        assert!(brush_radius_on_screen(&scene, &hit, 0.05, &|_| None).is_none());
    }
}

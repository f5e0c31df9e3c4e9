//! What the viewport draws over the rendered organs with egui's painter:
//! the wireframe, the selected organ's outline and its growth-direction
//! arrows.

use anthesis_flower::Project;
use anthesis_mesh::{Mesh, Topology};
use anthesis_physics::growth::growth_direction;
use eframe::egui::{self, Color32, Pos2, Rect, Stroke};
use glam::{DMat4, DVec3};

use super::ViewOptions;
use super::scene::SceneOrgan;

/// Screen position of a world point, `None` behind the eye.
pub fn project_to_screen(
    view_projection: &DMat4,
    rect: Rect,
    point_in_world: DVec3,
) -> Option<Pos2> {
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
        self.edges_of_triangles(&mesh.triangles)
    }

    /// The boundary edges of the mesh of `triangles` (an organ as shown:
    /// a proxy frame's mesh is not the template's).
    pub fn edges_of_triangles(&mut self, triangles: &[[u32; 3]]) -> &[[u32; 2]] {
        if self.triangles != triangles {
            self.edges = Topology::from_triangles(triangles)
                .map(|topology| topology.boundary_edges().collect())
                .unwrap_or_default();
            self.triangles = triangles.to_vec();
        }
        &self.edges
    }
}

/// Arrows of the direction map on a sample of the organ's triangles: the
/// direction each triangle grows along, as the solver computes it
/// (`anthesis_physics::growth::growth_direction`, the UV direction through
/// the triangle's UV → world Jacobian), as long as the painted direction.
pub fn direction_arrows(
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
        let corners = tri.map(|i| organ.positions_in_world[i as usize]);
        let uvs = tri.map(|i| organ.uvs[i as usize]);
        let [p0, p1, p2] = corners;
        let d = map.sample((uvs[0] + uvs[1] + uvs[2]) / 3.0);
        let normal = (p1 - p0).cross(p2 - p0).normalize_or_zero();
        let along = growth_direction(corners, uvs, d, normal);
        let mean_edge = ((p1 - p0).length() + (p2 - p0).length()) * 0.5;
        let arrow = along * mean_edge * 0.8 * d.length().min(1.0);
        let centre = (p0 + p1 + p2) / 3.0;
        if let (Some(from), Some(to)) = (to_screen(centre), to_screen(centre + arrow)) {
            painter.arrow(from, to - from, stroke);
        }
    }
}

/// Draws the overlays `options` asks for over `scene` as seen through
/// `view_projection`, clipped to the painter's rectangle (the viewport):
/// the wireframe, the selected organ's `outline` (boundary edges) and its
/// direction-map arrows of time key `direction_key`.
pub fn draw(
    painter: &egui::Painter,
    view_projection: &DMat4,
    project: &Project,
    scene: &[SceneOrgan],
    options: &ViewOptions,
    selected: Option<(usize, &[[u32; 2]])>,
    direction_key: Option<usize>,
) {
    let rect = painter.clip_rect();
    let to_screen = |p: DVec3| project_to_screen(view_projection, rect, p);
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
            direction_arrows(painter, project, o, key, &to_screen);
        }
    }
}

//! The scene the viewport shows: the organs at the playhead (simulated or
//! in their bud placement), their bounds, and the meshes handed to the
//! renderer (template colour, selection highlight, map overlay).

use anthesis_flower::Project;
use anthesis_maps::MapKind;
use anthesis_render::OrganMesh;
use glam::{DVec2, DVec3};

use crate::desktop::session::SimSession;

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

//! Pictures of a project's bud (keyframe 0), rendered offscreen with
//! `anthesis-render`: the organs where their placements put the template
//! meshes, in their looks, with the parts, from the same side as
//! `anthesis render`'s default camera. The New gallery shows these.

use anthesis_flower::Project;
use anthesis_render::{Camera, OffscreenRenderer, OrganMesh, organs_bounds_in_world};
use anyhow::{Context, Result, bail};
use image::RgbaImage;

/// The camera's direction around the axis and height, in degrees (as
/// `anthesis render`'s defaults).
const AZIMUTH_DEG: f64 = 30.0;
const ELEVATION_DEG: f64 = 20.0;

/// The organs and parts of `project` at the bud, ready to draw.
pub fn bud_meshes(project: &Project) -> Vec<OrganMesh> {
    let flower = &project.flower;
    let mut meshes: Vec<OrganMesh> = flower
        .organs
        .iter()
        .filter_map(|organ| {
            let template = flower.templates.get(organ.template)?;
            let positions: Vec<_> = template
                .mesh
                .positions
                .iter()
                .map(|p| organ.placement.world_from_template(*p, 0.0))
                .collect();
            let (colour, texture) = crate::look::template_look(template);
            let mesh = OrganMesh::from_positions(&positions, &template.mesh.triangles, colour);
            Some(crate::look::with_texture(
                mesh,
                &template.mesh.uvs,
                texture.as_ref(),
            ))
        })
        .collect();
    meshes.extend(crate::parts::part_meshes(flower, 0.0));
    meshes
}

/// A `width` × `height` picture of `project`'s bud.
pub fn bud_picture(
    renderer: &mut OffscreenRenderer,
    project: &Project,
    width: u32,
    height: u32,
) -> Result<RgbaImage> {
    let meshes = bud_meshes(project);
    let Some((lo, hi)) = organs_bounds_in_world(&meshes) else {
        bail!("{} has nothing to draw", project.name);
    };
    let camera = Camera::framing(lo, hi, AZIMUTH_DEG, ELEVATION_DEG);
    renderer
        .render(&meshes, &camera, width, height)
        .with_context(|| format!("cannot render {}", project.name))
}

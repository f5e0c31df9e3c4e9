//! What organs look like on screen and in pictures: a template's colour map
//! as the renderer's texture, one rule for the desktop viewport,
//! `anthesis render` and the desktop's GIF export.

use std::sync::Arc;

use anthesis_flower::Template;
use anthesis_render::OrganMesh;
use glam::DVec2;

/// What the renderer draws an organ with: the colour it multiplies the
/// texture with, and the texture (`None`: the colour alone).
pub type Look = ([f32; 4], Option<Arc<image::RgbaImage>>);

/// The colour the renderer multiplies the texture with, and the texture:
/// a template with a colour map draws white times its baked colour image
/// ([`Template::colour_image`] at its own size); one without draws its
/// colour.
pub fn template_look(template: &Template) -> Look {
    if template.colouring.is_none() {
        return (template.color, None);
    }
    let (width, height) = template.colour_image_size();
    (
        [1.0; 4],
        Some(Arc::new(template.colour_image(width, height))),
    )
}

/// `mesh` painted with `texture` over `uvs` (one per vertex), or as it is
/// without a texture.
pub fn with_texture(
    mesh: OrganMesh,
    uvs: &[DVec2],
    texture: Option<&Arc<image::RgbaImage>>,
) -> OrganMesh {
    match texture {
        Some(image) => mesh.with_texture(
            uvs.iter().map(|uv| uv.as_vec2().to_array()).collect(),
            Arc::clone(image),
        ),
        None => mesh,
    }
}

/// The texture of an export track's base-colour PNG (what
/// `anthesis_export::flower_tracks` baked from the template), `None` when
/// it has none or it does not decode.
pub fn png_texture(png: Option<&[u8]>) -> Option<Arc<image::RgbaImage>> {
    let image = image::load_from_memory_with_format(png?, image::ImageFormat::Png).ok()?;
    Some(Arc::new(image.into_rgba8()))
}

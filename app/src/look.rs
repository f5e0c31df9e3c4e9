//! What organs look like on screen and in pictures: a template's colour map
//! as the renderer's texture, one rule for the desktop viewport,
//! `anthesis render` and the desktop's GIF export.

use std::sync::Arc;

use anthesis_flower::Template;
use anthesis_render::OrganMesh;
use glam::DVec2;

/// What the renderer draws an organ with: the colour it multiplies the
/// texture with, and the texture (`None`: the colour alone).
pub type Look = ([f32; 4], Option<Texture>);

/// A colour texture: one image for both sides, or (`two_sided`) the inner
/// side on its left half and the outer side on its right.
#[derive(Debug, Clone)]
pub struct Texture {
    pub image: Arc<image::RgbaImage>,
    pub two_sided: bool,
}

/// The colour the renderer multiplies the texture with, and the texture:
/// a template with a colour map draws white times its baked colour image
/// ([`Template::colour_image`] at its own size; both sides,
/// [`Template::colour_atlas`], when they differ); one without draws its
/// colour.
pub fn template_look(template: &Template) -> Look {
    if template.colouring.is_none() {
        return (template.colour, None);
    }
    let (width, height) = template.colour_image_size();
    let two_sided = template.is_two_sided();
    let image = if two_sided {
        template.colour_atlas(width, height)
    } else {
        template.colour_image(width, height)
    };
    let image = Arc::new(image);
    ([1.0; 4], Some(Texture { image, two_sided }))
}

/// `mesh` painted with `texture` over `uvs` (one per vertex), or as it is
/// without a texture.
pub fn with_texture(mesh: OrganMesh, uvs: &[DVec2], texture: Option<&Texture>) -> OrganMesh {
    let uvs = || uvs.iter().map(|uv| uv.as_vec2().to_array()).collect();
    match texture {
        Some(t) if t.two_sided => mesh.with_two_sided_texture(uvs(), Arc::clone(&t.image)),
        Some(t) => mesh.with_texture(uvs(), Arc::clone(&t.image)),
        None => mesh,
    }
}

/// The texture of an export track's base-colour PNGs (what
/// `anthesis_export::flower_tracks` baked from the template: both sides
/// when its outer side differs), `None` when it has none or one does not
/// decode.
pub fn track_texture(track: &anthesis_export::Track) -> Option<Texture> {
    let decode = |png: &[u8]| {
        image::load_from_memory_with_format(png, image::ImageFormat::Png)
            .ok()
            .map(|image| image.into_rgba8())
    };
    let inner = decode(track.base_colour_png.as_deref()?)?;
    let Some(outer) = &track.outer_colour_png else {
        return Some(Texture {
            image: Arc::new(inner),
            two_sided: false,
        });
    };
    let outer = decode(outer)?;
    let (w, h) = inner.dimensions();
    let atlas = image::RgbaImage::from_fn(2 * w, h, |x, y| {
        if x < w {
            *inner.get_pixel(x, y)
        } else {
            *outer.get_pixel((x - w).min(outer.width() - 1), y.min(outer.height() - 1))
        }
    });
    Some(Texture {
        image: Arc::new(atlas),
        two_sided: true,
    })
}

//! A template's colour map in the exports: baked into a PNG base-colour
//! texture for the .glb ([`Track::base_color_png`], with a white
//! `base_color` so the texture carries the colour), and sampled at each
//! vertex's UV for USD's per-vertex `primvars:displayColor`.

use anthesis_flower::{Flower, Side, Template, srgb8_to_linear};
use glam::DVec2;
use image::ImageEncoder;

use crate::{ExportError, Track, TrackProblem};

/// The PNG of `template`'s colour over its UV square
/// ([`Template::colour_image`] at [`Template::colour_image_size`]), or
/// `None` when the template has no colour map (its one colour is the
/// track's `base_color`).
pub fn colour_png(template: &Template) -> Result<Option<Vec<u8>>, ExportError> {
    colour_png_on(template, Side::Inner)
}

/// [`colour_png`] of one side of the organ (the inner side is what
/// [`colour_png`] gives).
pub fn colour_png_on(template: &Template, side: Side) -> Result<Option<Vec<u8>>, ExportError> {
    if template.colouring.is_none() {
        return Ok(None);
    }
    let (width, height) = template.colour_image_size();
    let image = template.colour_image_on(side, width, height);
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(
            image.as_raw(),
            width,
            height,
            image::ExtendedColorType::Rgba8,
        )
        .map_err(|error| ExportError::Texture {
            template: template.name.clone(),
            message: error.to_string(),
        })?;
    Ok(Some(bytes))
}

/// Gives each organ track (`tracks[i]` is organ `organs[i]`) whose template
/// has a colour map that map's PNG as its texture and a white base colour,
/// and the outer side's PNG where the sides differ
/// ([`Template::is_two_sided`]). Each template's PNGs are encoded once.
pub(crate) fn paint_tracks(
    tracks: &mut [Track],
    flower: &Flower,
    organs: &[usize],
) -> Result<(), ExportError> {
    type Pngs = (Option<Vec<u8>>, Option<Vec<u8>>);
    let mut pngs: Vec<Option<Pngs>> = vec![None; flower.templates.len()];
    for (track, &organ) in tracks.iter_mut().zip(organs) {
        let index = flower.organs[organ].template;
        let template = &flower.templates[index];
        if pngs[index].is_none() {
            let outer = if template.is_two_sided() {
                colour_png_on(template, Side::Outer)?
            } else {
                None
            };
            pngs[index] = Some((colour_png(template)?, outer));
        }
        if let Some((Some(png), outer)) = &pngs[index] {
            track.base_colour_png = Some(png.clone());
            track.outer_colour_png = outer.clone();
            track.base_colour = [1.0; 4];
        }
    }
    Ok(())
}

/// The linear RGBA colour of each vertex of `track`: its base colour times
/// its texture sampled at the vertex's UV (bilinear between pixel centres
/// in linear light, clamped at the edges, `v = 0` the bottom row, as the
/// renderer and glTF clients sample it); `None` without a texture.
pub(crate) fn vertex_colours(track: &Track) -> Result<Option<Vec<[f32; 4]>>, TrackProblem> {
    let Some(png) = &track.base_colour_png else {
        return Ok(None);
    };
    let image = image::load_from_memory_with_format(png, image::ImageFormat::Png)
        .map_err(|error| TrackProblem::TextureUnreadable {
            message: error.to_string(),
        })?
        .into_rgba8();
    let (width, height) = image.dimensions();
    let texel = |x: i64, y_up: i64| -> [f32; 4] {
        let x = x.clamp(0, i64::from(width) - 1) as u32;
        let row = (i64::from(height) - 1 - y_up.clamp(0, i64::from(height) - 1)) as u32;
        let p = image.get_pixel(x, row).0;
        [
            srgb8_to_linear(p[0]),
            srgb8_to_linear(p[1]),
            srgb8_to_linear(p[2]),
            f32::from(p[3]) / 255.0,
        ]
    };
    let sample = |uv: DVec2| -> [f32; 4] {
        let x = uv.x * f64::from(width) - 0.5;
        let y = uv.y * f64::from(height) - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let [a, b, c, d] = [
            texel(x0, y0),
            texel(x0 + 1, y0),
            texel(x0, y0 + 1),
            texel(x0 + 1, y0 + 1),
        ];
        std::array::from_fn(|i| {
            let bottom = a[i] + (b[i] - a[i]) * fx;
            let top = c[i] + (d[i] - c[i]) * fx;
            bottom + (top - bottom) * fy
        })
    };
    Ok(Some(
        track
            .uvs
            .iter()
            .map(|&uv| {
                let t = sample(uv);
                std::array::from_fn(|i| track.base_colour[i] * t[i])
            })
            .collect(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vertex_colours_follow_the_texture_by_uv() {
        // 2 x 1 pixels: left red, right blue (sRGB 255 is linear 1).
        let image = image::RgbaImage::from_fn(2, 1, |x, _| {
            image::Rgba(if x == 0 {
                [255, 0, 0, 255]
            } else {
                [0, 0, 255, 255]
            })
        });
        let mut png = Vec::new();
        image::codecs::png::PngEncoder::new(&mut png)
            .write_image(image.as_raw(), 2, 1, image::ExtendedColorType::Rgba8)
            .expect("encode");
        let track = Track {
            uvs: vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(1.0, 1.0),
                DVec2::new(0.5, 0.5),
            ],
            base_colour: [1.0, 1.0, 0.5, 1.0],
            base_colour_png: Some(png),
            ..Track::default()
        };
        let colours = vertex_colours(&track).expect("decodes").expect("textured");
        assert_eq!(colours[0], [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(colours[1], [0.0, 0.0, 0.5, 1.0]);
        // Halfway between the pixel centres: half of each, in linear light.
        assert_eq!(colours[2], [0.5, 0.0, 0.25, 1.0]);
        let plain = Track::default();
        assert_eq!(vertex_colours(&plain), Ok(None));
        let broken = Track {
            base_colour_png: Some(b"\x89PNG\r\n\x1a\nbroken".to_vec()),
            ..Track::default()
        };
        assert!(matches!(
            vertex_colours(&broken),
            Err(TrackProblem::TextureUnreadable { .. })
        ));
    }
}

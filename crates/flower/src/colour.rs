//! What a template looks like: its base colour and, optionally, a second
//! colour painted over it with a mix map, as growth maps are painted (the
//! same rasters, brushes and PNG files). The viewport, `anthesis render`
//! and the exports all take a template's colour from here.

use anthesis_maps::ScalarMap;
use glam::DVec2;

use crate::Template;

/// A second colour painted over a template's base colour
/// ([`Template::color`]): where the mix map is 0 the organ shows the base
/// colour, where it is 1 the second colour, linearly blended between.
#[derive(Debug, Clone, PartialEq)]
pub struct Colouring {
    /// Linear RGBA in `[0, 1]` (as [`Template::color`]).
    pub second_colour: [f32; 4],
    /// How much of the second colour shows, over the mesh's UV square
    /// (`v = 0` on the bottom row, as growth maps); values in `[0, 1]`.
    /// Its size is its own: it need not match the growth maps'.
    pub mix: ScalarMap,
    /// Further colours painted over the second one in order, as layers in
    /// a paint program (the lily's crimson spots over its green-yellow
    /// throat); usually none. The app paints `mix` only.
    pub layers: Vec<ColourLayer>,
}

/// A colour painted over what lies under it where its mix map says (0:
/// what is under it, 1: this colour).
#[derive(Debug, Clone, PartialEq)]
pub struct ColourLayer {
    /// Linear RGBA in `[0, 1]`.
    pub colour: [f32; 4],
    /// How much of `color` shows, values in `[0, 1]`, any size.
    pub mix: ScalarMap,
    /// The side of the organ it is painted on (the lily's spots are on the
    /// inner side only).
    pub side: Side,
}

/// A side of an organ: the inner (adaxial) side faces the flower axis in
/// the bud (the side mesh normals point to), the outer (abaxial) side away.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Side {
    /// Both sides alike.
    #[default]
    Both,
    /// The inner side only.
    Inner,
    /// The outer side only.
    Outer,
}

impl Side {
    /// Whether something on this side shows on `seen` (`Inner` or `Outer`;
    /// `Both` sees everything).
    pub fn shows_on(self, seen: Side) -> bool {
        self == Side::Both || seen == Side::Both || self == seen
    }
}

/// `under` blended towards `over` by `t` in `[0, 1]`.
fn blend(under: [f32; 4], over: [f32; 4], t: f64) -> [f32; 4] {
    let t = t.clamp(0.0, 1.0) as f32;
    std::array::from_fn(|i| under[i] + (over[i] - under[i]) * t)
}

/// The second colour a template gets when its colour map is first painted
/// or its second colour first picked (a deep crimson, linear RGBA).
pub const DEFAULT_SECOND_COLOUR: [f32; 4] = [0.45, 0.02, 0.06, 1.0];

/// The size a colour map is painted at when it is first painted (finer than
/// growth maps: spots and veins are small).
pub const COLOUR_PAINT_SIZE: u32 = 256;

/// The largest side of an image [`Template::colour_image`] bakes by
/// default: a 1x1 (constant) mix map bakes to 1x1, a painted one at its
/// own size up to this.
pub const MAX_BAKED_SIDE: u32 = 1024;

impl Template {
    /// The linear RGBA colour at `uv` on the organ: the base colour blended
    /// towards the second colour by the mix map's (bilinear) value there
    /// (then towards each further layer's colour by its map), or the base
    /// colour when the template has no colouring.
    ///
    /// This is the inner side (what the paint panel shows): see
    /// [`Template::colour_on`] for either side.
    pub fn colour_at(&self, uv: DVec2) -> [f32; 4] {
        self.colour_on(Side::Inner, uv)
    }

    /// The linear RGBA colour at `uv` on `side`, as [`Template::colour_at`]
    /// with only the layers painted on that side.
    pub fn colour_on(&self, side: Side, uv: DVec2) -> [f32; 4] {
        match &self.colouring {
            None => self.colour,
            Some(colouring) => {
                let second = blend(
                    self.colour,
                    colouring.second_colour,
                    colouring.mix.sample(uv),
                );
                colouring
                    .layers
                    .iter()
                    .filter(|layer| layer.side.shows_on(side))
                    .fold(second, |under, layer| {
                        blend(under, layer.colour, layer.mix.sample(uv))
                    })
            }
        }
    }

    /// Whether the two sides of the organ look different (a colour layer on
    /// one side only).
    pub fn is_two_sided(&self) -> bool {
        self.colouring
            .as_ref()
            .is_some_and(|c| c.layers.iter().any(|layer| layer.side != Side::Both))
    }

    /// The template's colouring, ready to paint: made when missing (the
    /// [`DEFAULT_SECOND_COLOR`], nothing painted yet) and a constant mix map
    /// made a raster of [`COLOUR_PAINT_SIZE`] holding the same value.
    pub fn colouring_to_paint(&mut self) -> &mut Colouring {
        let colouring = self.colouring.get_or_insert_with(|| Colouring {
            second_colour: DEFAULT_SECOND_COLOUR,
            mix: ScalarMap::constant(0.0),
            layers: Vec::new(),
        });
        anthesis_maps::brush::ensure_scalar_raster(
            &mut colouring.mix,
            (COLOUR_PAINT_SIZE, COLOUR_PAINT_SIZE),
        );
        colouring
    }

    /// The size [`Template::colour_image`] bakes at when asked for the
    /// template's own: the largest of its mix maps' sizes (each side at
    /// most [`MAX_BAKED_SIDE`]), 1x1 without colouring.
    pub fn colour_image_size(&self) -> (u32, u32) {
        match &self.colouring {
            None => (1, 1),
            Some(colouring) => {
                let sizes = std::iter::once(colouring.mix.size())
                    .chain(colouring.layers.iter().map(|l| l.mix.size()));
                let (w, h) = sizes.fold((1, 1), |(w, h), (a, b)| (w.max(a), h.max(b)));
                (w.clamp(1, MAX_BAKED_SIDE), h.clamp(1, MAX_BAKED_SIDE))
            }
        }
    }

    /// The template's colour over its UV square as an 8-bit sRGB-encoded
    /// RGBA image of `width` x `height` pixels (each at least 1), each pixel
    /// [`Template::colour_at`] its centre. Row 0 of the image is the top
    /// (`v` near 1), so `v = 0` is the bottom row, as map images are; alpha
    /// is stored linearly.
    pub fn colour_image(&self, width: u32, height: u32) -> image::RgbaImage {
        self.colour_image_on(Side::Inner, width, height)
    }

    /// [`Template::colour_image`] of `side`.
    pub fn colour_image_on(&self, side: Side, width: u32, height: u32) -> image::RgbaImage {
        let (width, height) = (width.max(1), height.max(1));
        image::RgbaImage::from_fn(width, height, |x, y| {
            let uv = DVec2::new(
                (f64::from(x) + 0.5) / f64::from(width),
                1.0 - (f64::from(y) + 0.5) / f64::from(height),
            );
            image::Rgba(srgb8(self.colour_on(side, uv)))
        })
    }

    /// Both sides in one image for the renderer: the inner side's
    /// [`Template::colour_image_on`] on the left half, the outer side's on
    /// the right (`2 width` x `height` pixels).
    pub fn colour_atlas(&self, width: u32, height: u32) -> image::RgbaImage {
        let inner = self.colour_image_on(Side::Inner, width, height);
        let outer = self.colour_image_on(Side::Outer, width, height);
        let (w, h) = inner.dimensions();
        image::RgbaImage::from_fn(2 * w, h, |x, y| {
            if x < w {
                *inner.get_pixel(x, y)
            } else {
                *outer.get_pixel(x - w, y)
            }
        })
    }
}

/// A linear RGBA colour as 8-bit sRGB-encoded RGB and linear alpha.
pub fn srgb8(linear: [f32; 4]) -> [u8; 4] {
    let encode = |c: f32| {
        let c = c.clamp(0.0, 1.0);
        let s = if c <= 0.003_130_8 {
            12.92 * c
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        };
        (s * 255.0).round() as u8
    };
    [
        encode(linear[0]),
        encode(linear[1]),
        encode(linear[2]),
        (linear[3].clamp(0.0, 1.0) * 255.0).round() as u8,
    ]
}

/// The linear value of an 8-bit sRGB-encoded channel.
pub fn srgb8_to_linear(code: u8) -> f32 {
    let s = f32::from(code) / 255.0;
    if s <= 0.040_45 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn template(colouring: Option<Colouring>) -> Template {
        let mesh = anthesis_mesh::generate::test_petal(1.0, 0.5, 4, 4);
        Template {
            name: "petal".into(),
            mesh,
            maps: anthesis_maps::KeyedMaps::single(anthesis_maps::GrowthMaps::uniform()),
            dg: 0.0,
            thickness: 0.1,
            stretch_stiffness: 1.0,
            bend_stiffness: 1.0,
            base_region: crate::BaseRegion::default(),
            joint_schedule: Vec::new(),
            colour: [1.0, 0.0, 0.0, 1.0],
            colouring,
            two_state: None,
            source: None,
            vein: None,
        }
    }

    #[test]
    fn without_colouring_the_base_colour_is_everywhere() {
        let t = template(None);
        assert_eq!(t.colour_at(DVec2::new(0.3, 0.9)), [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(t.colour_image_size(), (1, 1));
        assert_eq!(t.colour_image(1, 1).get_pixel(0, 0).0, [255, 0, 0, 255]);
    }

    #[test]
    fn the_mix_map_blends_linearly_and_v_0_is_the_bottom_row() {
        // Mix 0 at the base (v = 0), 1 at the tip: red to blue.
        let mix = ScalarMap::from_fn(8, 8, |uv| uv.y as f32);
        let t = template(Some(Colouring {
            second_colour: [0.0, 0.0, 1.0, 1.0],
            mix,
            layers: Vec::new(),
        }));
        let middle = t.colour_at(DVec2::new(0.5, 0.5));
        assert!((middle[0] - 0.5).abs() < 1e-6 && (middle[2] - 0.5).abs() < 1e-6);
        assert_eq!(t.colour_image_size(), (8, 8));
        let image = t.colour_image(8, 8);
        let top = image.get_pixel(4, 0).0;
        let bottom = image.get_pixel(4, 7).0;
        assert!(top[2] > 240 && top[0] < 90, "top row is the tip: {top:?}");
        assert!(
            bottom[0] > 240 && bottom[2] < 90,
            "bottom row is the base: {bottom:?}"
        );
        // Halfway in linear light is 0.5, which sRGB encodes as 188.
        assert_eq!(srgb8([0.5, 0.5, 0.5, 0.5]), [188, 188, 188, 128]);
        assert!((srgb8_to_linear(188) - 0.5).abs() < 0.003);
    }

    #[test]
    fn further_layers_paint_over_in_order() {
        // Green over the left half of the red base, then blue over the
        // bottom half of everything.
        let t = template(Some(Colouring {
            second_colour: [0.0, 1.0, 0.0, 1.0],
            mix: ScalarMap::from_fn(8, 8, |uv| if uv.x < 0.5 { 1.0 } else { 0.0 }),
            layers: vec![ColourLayer {
                colour: [0.0, 0.0, 1.0, 1.0],
                mix: ScalarMap::from_fn(4, 16, |uv| if uv.y < 0.5 { 1.0 } else { 0.0 }),
                side: Side::Both,
            }],
        }));
        assert!(!t.is_two_sided());
        assert_eq!(t.colour_at(DVec2::new(0.1, 0.9)), [0.0, 1.0, 0.0, 1.0]);
        assert_eq!(t.colour_at(DVec2::new(0.9, 0.9)), [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(t.colour_at(DVec2::new(0.1, 0.1)), [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(t.colour_at(DVec2::new(0.9, 0.1)), [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(t.colour_image_size(), (8, 16));
    }

    #[test]
    fn a_layer_on_one_side_shows_on_that_side_only() {
        // Blue spots over the bottom half of the inner side; green over the
        // left half of both sides.
        let t = template(Some(Colouring {
            second_colour: [0.0, 1.0, 0.0, 1.0],
            mix: ScalarMap::from_fn(8, 8, |uv| if uv.x < 0.5 { 1.0 } else { 0.0 }),
            layers: vec![ColourLayer {
                colour: [0.0, 0.0, 1.0, 1.0],
                mix: ScalarMap::from_fn(4, 16, |uv| if uv.y < 0.5 { 1.0 } else { 0.0 }),
                side: Side::Inner,
            }],
        }));
        assert!(t.is_two_sided());
        let bottom_left = DVec2::new(0.1, 0.1);
        assert_eq!(t.colour_on(Side::Inner, bottom_left), [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(t.colour_at(bottom_left), [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(t.colour_on(Side::Outer, bottom_left), [0.0, 1.0, 0.0, 1.0]);
        assert_eq!(
            t.colour_on(Side::Outer, DVec2::new(0.9, 0.1)),
            [1.0, 0.0, 0.0, 1.0]
        );
        // The atlas: inner on the left, outer on the right; row 15 is v near 0.
        let atlas = t.colour_atlas(8, 16);
        assert_eq!(atlas.dimensions(), (16, 16));
        assert_eq!(atlas.get_pixel(0, 15).0, [0, 0, 255, 255]);
        assert_eq!(atlas.get_pixel(8, 15).0, [0, 255, 0, 255]);
        assert_eq!(atlas.get_pixel(15, 15).0, [255, 0, 0, 255]);
        assert_eq!(atlas.get_pixel(8, 0).0, [0, 255, 0, 255]);
    }
}

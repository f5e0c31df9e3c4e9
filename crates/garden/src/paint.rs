//! The growth maps of the default flowers, painted as functions of UV
//! (`u` across with the midrib at 0.5, `v` from the base to the tip) so
//! that the PNGs under `assets/flowers/` can be regenerated from code.
//!
//! Every painted raster is quantised the way the project file stores it
//! (16-bit PNG codes), so a project built here equals the same project saved
//! and loaded again.

use anthesis_maps::{BitDepth, DirectionMap, GrowthMaps, ScalarMap};
use glam::DVec2;

/// The resolution of the painted maps. The maps vary smoothly; 64 pixels
/// resolve a midrib band a tenth of the petal wide.
pub const MAP_SIZE: u32 = 64;

/// Smooth step from 0 at `edge0` to 1 at `edge1` (either order).
pub fn smoothstep(edge0: f64, edge1: f64, x: f64) -> f64 {
    let s = ((x - edge0) / (edge1 - edge0)).clamp(0.0, 1.0);
    s * s * (3.0 - 2.0 * s)
}

/// 1 on the midrib (`u = 0.5`), falling smoothly to 0 at `half_width` in
/// `u` on either side.
pub fn midrib_band(u: f64, half_width: f64) -> f64 {
    1.0 - smoothstep(0.0, half_width, (u - 0.5).abs())
}

/// 1 where the organ grows, 0 in the attachment region (`v <= v_base`),
/// rising over `ramp` in `v` above it.
pub fn above_base(v: f64, v_base: f64, ramp: f64) -> f64 {
    smoothstep(v_base, v_base + ramp, v)
}

/// A scalar map of `value_at(uv)`, clamped to `[0, 1]` and quantised to
/// 16-bit codes; a constant when every pixel has the same code.
pub fn scalar_map(value_at: impl Fn(DVec2) -> f64) -> ScalarMap {
    let map = ScalarMap::from_fn(MAP_SIZE, MAP_SIZE, |uv| {
        quantise_unit(value_at(uv).clamp(0.0, 1.0))
    });
    let first = map.values()[0];
    if map.values().iter().all(|&v| v == first) {
        ScalarMap::constant(first)
    } else {
        map
    }
}

/// A direction map of `direction_at(uv)` (normalised, so every component
/// lies in `[-1, 1]`), quantised to 16-bit signed codes.
pub fn direction_map(direction_at: impl Fn(DVec2) -> DVec2) -> DirectionMap {
    let map = DirectionMap::from_fn(MAP_SIZE, MAP_SIZE, |uv| {
        let d = direction_at(uv).normalize_or(DVec2::Y);
        DVec2::new(
            f64::from(quantise_signed(d.x)),
            f64::from(quantise_signed(d.y)),
        )
    });
    let first = map.values()[0];
    if map.values().iter().all(|&v| v == first) {
        DirectionMap::constant(DVec2::new(f64::from(first[0]), f64::from(first[1])))
    } else {
        map
    }
}

/// The resolution of the painted colour maps: finer than the growth maps,
/// since spots and picotee rims are small.
pub const COLOUR_MAP_SIZE: u32 = 256;

/// A colour mix map of `value_at(uv)` at [`COLOUR_MAP_SIZE`], clamped and
/// quantised like [`scalar_map`]; a constant when uniform.
pub fn colour_map(value_at: impl Fn(DVec2) -> f64) -> ScalarMap {
    let map = ScalarMap::from_fn(COLOUR_MAP_SIZE, COLOUR_MAP_SIZE, |uv| {
        quantise_unit(value_at(uv).clamp(0.0, 1.0))
    });
    let first = map.values()[0];
    if map.values().iter().all(|&v| v == first) {
        ScalarMap::constant(first)
    } else {
        map
    }
}

/// Round spots on the organ (soft-edged discs, 1 inside): `count` of them
/// scattered by a fixed pseudo-random sequence from `seed` over `v` in
/// `v_range`, at most `spread` in `u` from the midrib, `radius_v` tall in
/// `v` and `aspect` times that wide in `u` (an organ `aspect` times longer
/// than wide has round spots then). The same seed paints the same spots.
pub fn spots(
    seed: u64,
    count: usize,
    v_range: (f64, f64),
    spread: f64,
    radius_v: f64,
    aspect: f64,
) -> impl Fn(DVec2) -> f64 {
    // A 64-bit linear congruential generator (Knuth's MMIX constants),
    // its top 53 bits as a number in [0, 1).
    let mut state = seed;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let centres: Vec<(DVec2, f64)> = (0..count)
        .map(|_| {
            // More spots towards the throat: v drawn with a square.
            let v = v_range.0 + (v_range.1 - v_range.0) * next().powf(1.5);
            let u = 0.5 + spread * (2.0 * next() - 1.0);
            let size = 0.6 + 0.8 * next();
            (DVec2::new(u, v), radius_v * size)
        })
        .collect();
    move |uv: DVec2| {
        centres
            .iter()
            .map(|(centre, r)| {
                let d = (uv - *centre) / DVec2::new(r * aspect, *r);
                1.0 - smoothstep(0.7, 1.0, d.length())
            })
            .fold(0.0, f64::max)
    }
}

/// The value a 16-bit scalar PNG gives back for `value` in `[0, 1]`.
fn quantise_unit(value: f64) -> f32 {
    let max = f64::from(BitDepth::Sixteen.max_code());
    ((value * max).round() / max) as f32
}

/// The value a 16-bit direction PNG gives back for `value` in `[-1, 1]`
/// (code `c` means `(c − 32768) / 32767`).
fn quantise_signed(value: f64) -> f32 {
    let (mid, max) = (32768.0, f64::from(BitDepth::Sixteen.max_code()));
    let code = (mid + value.clamp(-1.0, 1.0) * (max - mid))
        .round()
        .clamp(0.0, max);
    ((code - mid) / (max - mid)) as f32
}

/// Growth maps for the base and inner layers from four painting
/// functions plus stiffness and direction; a convenience for the builders.
pub struct Painting<'a> {
    /// The e-growth map's value at a UV point.
    pub e_growth: &'a dyn Fn(DVec2) -> f64,
    /// The w-growth map's value at a UV point.
    pub w_growth: &'a dyn Fn(DVec2) -> f64,
    /// The e-growth-in map's value at a UV point.
    pub e_growth_in: &'a dyn Fn(DVec2) -> f64,
    /// The w-growth-in map's value at a UV point.
    pub w_growth_in: &'a dyn Fn(DVec2) -> f64,
    /// The stretch stiffness multiplier at a UV point.
    pub stretch: &'a dyn Fn(DVec2) -> f64,
    /// The bend stiffness multiplier at a UV point.
    pub bend: &'a dyn Fn(DVec2) -> f64,
    /// The growth direction at a UV point, as a UV vector (`(0, 1)` is
    /// along `v`, base to tip).
    pub direction: &'a dyn Fn(DVec2) -> DVec2,
}

impl Painting<'_> {
    /// The seven maps, each function sampled by [`scalar_map`] or
    /// [`direction_map`] (quantised as a 16-bit PNG holds it).
    pub fn paint(&self) -> GrowthMaps {
        GrowthMaps {
            e_growth: scalar_map(self.e_growth),
            w_growth: scalar_map(self.w_growth),
            e_growth_in: scalar_map(self.e_growth_in),
            w_growth_in: scalar_map(self.w_growth_in),
            stretch: scalar_map(self.stretch),
            bend: scalar_map(self.bend),
            direction: direction_map(self.direction),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn painted_maps_survive_a_16_bit_png_round_trip_exactly() {
        let scalar = scalar_map(|uv| 0.3 + 0.4 * uv.x * uv.y + 0.01 * (uv.x * 37.0).sin());
        let bytes = scalar.to_png_bytes(BitDepth::Sixteen).expect("encodable");
        assert_eq!(
            ScalarMap::from_png_bytes(&bytes).expect("decodable"),
            scalar
        );
        let direction = direction_map(|uv| DVec2::new(0.6 * (uv.x - 0.5) * uv.y, 1.0));
        let bytes = direction
            .to_png_bytes(BitDepth::Sixteen)
            .expect("encodable");
        assert_eq!(
            DirectionMap::from_png_bytes(&bytes).expect("decodable"),
            direction
        );
    }

    #[test]
    fn uniform_paint_becomes_a_constant_and_values_are_clamped() {
        let map = scalar_map(|_| 0.25);
        assert_eq!(map.size(), (1, 1));
        // Quantised like a 16-bit PNG code.
        assert!((map.values()[0] - 0.25).abs() <= 1.0 / 65535.0);
        let clamped = scalar_map(|uv| 2.0 * uv.x - 0.5);
        assert!(clamped.values().iter().all(|v| (0.0..=1.0).contains(v)));
        assert_eq!(direction_map(|_| DVec2::new(0.0, 3.0)).size(), (1, 1));
    }

    #[test]
    fn regions_fall_off_smoothly() {
        assert_eq!(midrib_band(0.5, 0.1), 1.0);
        assert_eq!(midrib_band(0.39, 0.1), 0.0);
        assert!((midrib_band(0.45, 0.1) - 0.5).abs() < 1e-12);
        assert_eq!(above_base(0.04, 0.05, 0.05), 0.0);
        assert_eq!(above_base(0.2, 0.05, 0.05), 1.0);
        assert!((smoothstep(1.0, 0.0, 0.25) - smoothstep(0.0, 1.0, 0.75)).abs() < 1e-12);
    }
}

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
    pub e_growth: &'a dyn Fn(DVec2) -> f64,
    pub w_growth: &'a dyn Fn(DVec2) -> f64,
    pub e_growth_in: &'a dyn Fn(DVec2) -> f64,
    pub w_growth_in: &'a dyn Fn(DVec2) -> f64,
    pub stretch: &'a dyn Fn(DVec2) -> f64,
    pub bend: &'a dyn Fn(DVec2) -> f64,
    pub direction: &'a dyn Fn(DVec2) -> DVec2,
}

impl Painting<'_> {
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

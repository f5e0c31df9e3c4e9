//! Brushes on growth-map rasters, in UV space: set / add / subtract /
//! smooth / reset with radius, strength and hardness, mirrored about the
//! midrib (u = 0.5), and direction painting. Pure functions over the
//! rasters; the desktop app's paint panel and 3D painting call them.

use glam::DVec2;
use serde::{Deserialize, Serialize};

use crate::{DirectionMap, KeyedMaps, MapKind, ScalarMap};

/// Resolution given to a constant (1x1) map when it is first painted and
/// the template has no raster map to match.
pub const DEFAULT_PAINT_SIZE: u32 = 128;

/// What a dab does to the values under the brush.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum BrushMode {
    /// Moves values towards the brush value.
    Set,
    /// Adds the brush value.
    Add,
    /// Subtracts the brush value.
    Subtract,
    /// Moves values towards the mean of their neighbours.
    Smooth,
    /// Moves values towards the map's default (growth 0, stiffness 1,
    /// direction along v).
    Reset,
}

impl BrushMode {
    /// Every mode, in the order the paint panel offers them.
    pub const ALL: [BrushMode; 5] = [
        BrushMode::Set,
        BrushMode::Add,
        BrushMode::Subtract,
        BrushMode::Smooth,
        BrushMode::Reset,
    ];

    /// The mode's name as shown to people, e.g. `subtract`.
    pub fn label(self) -> &'static str {
        match self {
            BrushMode::Set => "set",
            BrushMode::Add => "add",
            BrushMode::Subtract => "subtract",
            BrushMode::Smooth => "smooth",
            BrushMode::Reset => "reset",
        }
    }
}

/// A brush: what it does, its size and falloff in UV space, and the value
/// it paints.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Brush {
    /// What a dab does (set, add, subtract, smooth, reset).
    pub mode: BrushMode,
    /// Radius in UV units (the UV square is 1 wide).
    pub radius_in_uv: f64,
    /// How much one dab moves a value at the centre, in `[0, 1]`.
    pub strength: f32,
    /// Fraction of the radius painted at full strength; the rest falls off
    /// smoothly to 0 at the rim.
    pub hardness: f32,
    /// The value set, added or subtracted.
    pub value: f32,
    /// Also paint the mirror image about the midrib (u = 0.5).
    pub mirror: bool,
}

impl Default for Brush {
    fn default() -> Self {
        Brush {
            mode: BrushMode::Set,
            radius_in_uv: 0.08,
            strength: 0.5,
            hardness: 0.5,
            value: 0.8,
            mirror: true,
        }
    }
}

impl Brush {
    /// Weight of the brush at `distance_in_uv` from its centre, in `[0, 1]`.
    pub fn weight(&self, distance_in_uv: f64) -> f32 {
        let r = self.radius_in_uv.max(1e-9);
        let t = (distance_in_uv / r) as f32;
        if t >= 1.0 {
            return 0.0;
        }
        let hard = self.hardness.clamp(0.0, 1.0);
        let falloff = if t <= hard {
            1.0
        } else {
            let s = (t - hard) / (1.0 - hard).max(1e-6);
            1.0 - s * s * (3.0 - 2.0 * s)
        };
        falloff * self.strength.clamp(0.0, 1.0)
    }

    /// The dab centres: the point and, with mirroring, its mirror image
    /// (once, when the point is on the midrib).
    fn centres(&self, centre_in_uv: DVec2) -> Vec<(DVec2, bool)> {
        let mirrored = DVec2::new(1.0 - centre_in_uv.x, centre_in_uv.y);
        if self.mirror && (mirrored.x - centre_in_uv.x).abs() > 1e-9 {
            vec![(centre_in_uv, false), (mirrored, true)]
        } else {
            vec![(centre_in_uv, false)]
        }
    }
}

/// Calls `visit(index, weight)` for every pixel of a `width x height`
/// raster under one dab, taking the larger weight where mirrored dabs
/// overlap. `mirrored` is true when the stronger dab is the mirrored one.
fn for_pixels_under(
    width: u32,
    height: u32,
    brush: &Brush,
    centre_in_uv: DVec2,
    mut visit: impl FnMut(usize, f32, bool),
) {
    let mut weights = std::collections::BTreeMap::new();
    for (centre, mirrored) in brush.centres(centre_in_uv) {
        let r = brush.radius_in_uv;
        // Pixel centres are at ((x + 0.5) / w, 1 - (y + 0.5) / h).
        let x_range = |lo: f64, hi: f64, n: u32| {
            let a = ((lo * f64::from(n)) - 0.5).floor().max(0.0) as u32;
            let b = ((hi * f64::from(n)) - 0.5)
                .ceil()
                .min(f64::from(n) - 1.0)
                .max(0.0) as u32;
            a..=b
        };
        let ys = x_range(1.0 - (centre.y + r), 1.0 - (centre.y - r), height);
        for y in ys {
            for x in x_range(centre.x - r, centre.x + r, width) {
                let pixel = DVec2::new(
                    (f64::from(x) + 0.5) / f64::from(width),
                    1.0 - (f64::from(y) + 0.5) / f64::from(height),
                );
                let w = brush.weight(pixel.distance(centre));
                if w > 0.0 {
                    let index = (y * width + x) as usize;
                    let entry = weights.entry(index).or_insert((0.0_f32, false));
                    if w > entry.0 {
                        *entry = (w, mirrored);
                    }
                }
            }
        }
    }
    for (index, (w, mirrored)) in weights {
        visit(index, w, mirrored);
    }
}

/// Mean of the 3x3 neighbourhood of pixel `index` (edges clamped).
fn neighbour_mean<T: Copy>(
    values: &[T],
    width: u32,
    height: u32,
    index: usize,
    zero: T,
    add: impl Fn(T, T) -> T,
    scale: impl Fn(T, f32) -> T,
) -> T {
    let (x, y) = ((index as u32) % width, (index as u32) / width);
    let mut sum = zero;
    let mut n = 0.0;
    for dy in -1_i64..=1 {
        for dx in -1_i64..=1 {
            let nx = (i64::from(x) + dx).clamp(0, i64::from(width) - 1) as u32;
            let ny = (i64::from(y) + dy).clamp(0, i64::from(height) - 1) as u32;
            sum = add(sum, values[(ny * width + nx) as usize]);
            n += 1.0;
        }
    }
    scale(sum, 1.0 / n)
}

/// One dab of `brush` on a scalar map at `centre_in_uv`. `default` is the
/// value `Reset` moves towards. Values stay in `[0, 1]`.
pub fn dab_scalar(map: &mut ScalarMap, brush: &Brush, centre_in_uv: DVec2, default: f32) {
    let (width, height) = map.size();
    let before = map.values().to_vec();
    let values = map.values_mut();
    for_pixels_under(width, height, brush, centre_in_uv, |i, w, _| {
        let v = before[i];
        let next = match brush.mode {
            BrushMode::Set => v + (brush.value - v) * w,
            BrushMode::Add => v + brush.value * w,
            BrushMode::Subtract => v - brush.value * w,
            BrushMode::Reset => v + (default - v) * w,
            BrushMode::Smooth => {
                let mean =
                    neighbour_mean(&before, width, height, i, 0.0, |a, b| a + b, |a, s| a * s);
                v + (mean - v) * w
            }
        };
        values[i] = next.clamp(0.0, 1.0);
    });
}

/// One dab on a direction map. `direction_in_uv` (any length, zero for
/// none) is what `Set`/`Add` paint; the mirrored dab paints its mirror image
/// `(-u, v)`. `Reset` moves towards `(0, 1)`; `Subtract` towards zero.
pub fn dab_direction(
    map: &mut DirectionMap,
    brush: &Brush,
    centre_in_uv: DVec2,
    direction_in_uv: DVec2,
) {
    let (width, height) = map.size();
    let before = map.values().to_vec();
    let values = map.values_mut();
    let d = direction_in_uv.normalize_or_zero();
    for_pixels_under(width, height, brush, centre_in_uv, |i, w, mirrored| {
        let v = before[i];
        let painted = if mirrored {
            [-d.x as f32, d.y as f32]
        } else {
            [d.x as f32, d.y as f32]
        };
        let towards =
            |target: [f32; 2]| [v[0] + (target[0] - v[0]) * w, v[1] + (target[1] - v[1]) * w];
        let next = match brush.mode {
            BrushMode::Set | BrushMode::Add => {
                if d == DVec2::ZERO {
                    v
                } else {
                    towards(painted)
                }
            }
            BrushMode::Subtract => towards([0.0, 0.0]),
            BrushMode::Reset => towards([0.0, 1.0]),
            BrushMode::Smooth => {
                let mean = neighbour_mean(
                    &before,
                    width,
                    height,
                    i,
                    [0.0, 0.0],
                    |a, b| [a[0] + b[0], a[1] + b[1]],
                    |a, s| [a[0] * s, a[1] * s],
                );
                towards(mean)
            }
        };
        values[i] = [next[0].clamp(-1.0, 1.0), next[1].clamp(-1.0, 1.0)];
    });
}

/// Makes a constant map paintable: a 1x1 map becomes a raster of `size`
/// with the same value everywhere.
pub fn ensure_scalar_raster(map: &mut ScalarMap, size: (u32, u32)) {
    if map.size() == (1, 1) && size != (1, 1) {
        let value = map.values()[0];
        *map = ScalarMap::from_fn(size.0, size.1, |_| value);
    }
}

/// Like [`ensure_scalar_raster`] for direction maps.
pub fn ensure_direction_raster(map: &mut DirectionMap, size: (u32, u32)) {
    if map.size() == (1, 1) && size != (1, 1) {
        let [u, v] = map.values()[0];
        *map = DirectionMap::from_fn(size.0, size.1, |_| DVec2::new(f64::from(u), f64::from(v)));
    }
}

/// Which map a stroke paints.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum PaintTarget {
    /// One of the six scalar maps (growth or stiffness).
    Scalar(MapKind),
    /// The growth direction map: `Set` and `Add` dabs paint the stroke
    /// direction (see [`dab_direction`]).
    Direction,
    /// A template's colour map: how much of its second colour shows (0 to
    /// 1). It is one map, not one per time key, and it is not simulated, so
    /// [`dab_keyed`] leaves it alone: the template holds it
    /// (`anthesis_flower::Colouring`), painted with [`dab_scalar`].
    Colour,
}

impl PaintTarget {
    /// The target's name as shown to people, e.g. `e-growth` or `direction`.
    pub fn label(self) -> &'static str {
        match self {
            PaintTarget::Scalar(kind) => kind.label(),
            PaintTarget::Direction => "direction",
            PaintTarget::Colour => "colour",
        }
    }
}

/// One dab of `brush` on map `target` of time key `key` of `maps` (a
/// template's keyed maps): constant maps become rasters first, of the size
/// the other maps have, so all maps of a template keep one size.
/// `direction_in_uv` is the stroke direction, used by the direction map. A
/// key that does not exist changes nothing.
pub fn dab_keyed(
    maps: &mut KeyedMaps,
    key: usize,
    target: PaintTarget,
    brush: &Brush,
    centre_in_uv: DVec2,
    direction_in_uv: DVec2,
) {
    let size = maps
        .raster_size()
        .unwrap_or((DEFAULT_PAINT_SIZE, DEFAULT_PAINT_SIZE));
    let Some(map_key) = maps.keys_mut().get_mut(key) else {
        return;
    };
    match target {
        PaintTarget::Scalar(kind) => {
            let map = map_key.maps.scalar_mut(kind);
            ensure_scalar_raster(map, size);
            dab_scalar(map, brush, centre_in_uv, kind.default_value());
        }
        PaintTarget::Direction => {
            let map = &mut map_key.maps.direction;
            ensure_direction_raster(map, size);
            dab_direction(map, brush, centre_in_uv, direction_in_uv);
        }
        PaintTarget::Colour => {}
    }
}

/// Dab spacing as a fraction of the brush radius: dabs along a stroke are
/// at most a quarter of the radius apart, so a hard brush leaves no gaps
/// and a soft one no visible beads.
pub const DAB_SPACING_PER_RADIUS: f64 = 0.25;

/// Where the dabs of a stroke go: points along the pointer's path (a
/// polyline, one vertex per frame) `spacing_in_uv` apart, measured along
/// the path, with the distance travelled since the last dab carried from
/// one segment (frame) to the next, so the dabs are evenly spaced whatever
/// the frame rate. Each dab comes with the direction of the segment it lies
/// on (for direction painting).
#[derive(Debug, Clone, PartialEq)]
pub struct StrokeSpacing {
    spacing_in_uv: f64,
    /// The path's last vertex, `None` before the stroke starts.
    last_in_uv: Option<DVec2>,
    /// Distance travelled along the path since the last dab.
    since_dab_in_uv: f64,
}

/// One dab of a stroke: its centre and the stroke's direction there (unit
/// length, zero for the first dab, which has no direction yet).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StrokeDab {
    /// Where the dab goes, in the UV square.
    pub centre_in_uv: DVec2,
    /// The stroke's direction at the dab, a unit UV vector (zero for the
    /// first dab); what a direction-map dab paints.
    pub direction_in_uv: DVec2,
}

impl StrokeSpacing {
    /// Spacing for `brush`: [`DAB_SPACING_PER_RADIUS`] of its radius.
    pub fn for_brush(brush: &Brush) -> StrokeSpacing {
        StrokeSpacing::new(brush.radius_in_uv * DAB_SPACING_PER_RADIUS)
    }

    /// Dabs `spacing_in_uv` apart (a tiny positive floor keeps a zero
    /// spacing from producing endless dabs).
    pub fn new(spacing_in_uv: f64) -> StrokeSpacing {
        StrokeSpacing {
            spacing_in_uv: spacing_in_uv.max(1e-6),
            last_in_uv: None,
            since_dab_in_uv: 0.0,
        }
    }

    /// Whether a stroke has started.
    pub fn started(&self) -> bool {
        self.last_in_uv.is_some()
    }

    /// Starts a stroke at `point_in_uv`: one dab there.
    pub fn start(&mut self, point_in_uv: DVec2) -> StrokeDab {
        self.last_in_uv = Some(point_in_uv);
        self.since_dab_in_uv = 0.0;
        StrokeDab {
            centre_in_uv: point_in_uv,
            direction_in_uv: DVec2::ZERO,
        }
    }

    /// Extends the path to `point_in_uv` (the pointer's position this
    /// frame): the dabs on the new segment, in order. Starts the stroke
    /// (one dab) if it had not started. Non-finite points are ignored.
    pub fn extend_to(&mut self, point_in_uv: DVec2) -> Vec<StrokeDab> {
        if !point_in_uv.is_finite() {
            return Vec::new();
        }
        let Some(from) = self.last_in_uv else {
            return vec![self.start(point_in_uv)];
        };
        let segment = point_in_uv - from;
        let length = segment.length();
        self.last_in_uv = Some(point_in_uv);
        if length == 0.0 {
            return Vec::new();
        }
        let direction = segment / length;
        let mut dabs = Vec::new();
        // Distance along this segment of the next dab.
        let mut along = self.spacing_in_uv - self.since_dab_in_uv;
        while along <= length {
            dabs.push(StrokeDab {
                centre_in_uv: from + direction * along,
                direction_in_uv: direction,
            });
            along += self.spacing_in_uv;
        }
        self.since_dab_in_uv = length - (along - self.spacing_in_uv);
        dabs
    }

    /// Ends the stroke: the next point starts a new one.
    pub fn end(&mut self) {
        self.last_in_uv = None;
        self.since_dab_in_uv = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(value: f32) -> ScalarMap {
        ScalarMap::from_fn(20, 20, |_| value)
    }

    fn hard(mode: BrushMode, value: f32) -> Brush {
        Brush {
            mode,
            radius_in_uv: 0.15,
            strength: 1.0,
            hardness: 1.0,
            value,
            mirror: false,
        }
    }

    #[test]
    fn weight_is_full_inside_the_hard_core_and_zero_at_the_rim() {
        let brush = Brush {
            radius_in_uv: 0.1,
            hardness: 0.5,
            strength: 0.8,
            ..Brush::default()
        };
        assert_eq!(brush.weight(0.0), 0.8);
        assert_eq!(brush.weight(0.05), 0.8);
        assert!(brush.weight(0.075) < 0.8 && brush.weight(0.075) > 0.0);
        assert_eq!(brush.weight(0.1), 0.0);
    }

    #[test]
    fn set_paints_under_the_brush_only_and_mirror_paints_the_other_side() {
        let mut map = flat(0.0);
        dab_scalar(
            &mut map,
            &hard(BrushMode::Set, 1.0),
            DVec2::new(0.25, 0.5),
            0.0,
        );
        assert_eq!(map.sample(DVec2::new(0.25, 0.5)), 1.0);
        assert_eq!(map.sample(DVec2::new(0.75, 0.5)), 0.0);
        assert_eq!(map.sample(DVec2::new(0.25, 0.9)), 0.0);
        let mut brush = hard(BrushMode::Set, 1.0);
        brush.mirror = true;
        dab_scalar(&mut map, &brush, DVec2::new(0.25, 0.2), 0.0);
        assert_eq!(map.sample(DVec2::new(0.25, 0.2)), 1.0);
        assert_eq!(
            map.sample(DVec2::new(0.75, 0.2)),
            1.0,
            "mirrored about u = 0.5"
        );
    }

    #[test]
    fn add_subtract_clamp_and_reset_restores_the_default() {
        let mut map = flat(0.5);
        let centre = DVec2::new(0.5, 0.5);
        dab_scalar(&mut map, &hard(BrushMode::Add, 0.3), centre, 1.0);
        assert!((map.sample(centre) - 0.8).abs() < 1e-6);
        dab_scalar(&mut map, &hard(BrushMode::Add, 0.3), centre, 1.0);
        assert_eq!(map.sample(centre), 1.0, "clamped to 1");
        dab_scalar(&mut map, &hard(BrushMode::Subtract, 0.25), centre, 1.0);
        assert!((map.sample(centre) - 0.75).abs() < 1e-6);
        dab_scalar(&mut map, &hard(BrushMode::Reset, 0.0), centre, 1.0);
        assert_eq!(map.sample(centre), 1.0, "stiffness default");
    }

    #[test]
    fn smooth_flattens_a_spike() {
        let mut map = flat(0.0);
        let spike = 10 * 20 + 10;
        map.values_mut()[spike] = 1.0;
        dab_scalar(
            &mut map,
            &hard(BrushMode::Smooth, 0.0),
            DVec2::new(0.5, 0.5),
            0.0,
        );
        let after = map.values()[spike];
        assert!(after < 0.2 && after > 0.0, "{after}");
        let total: f32 = map.values().iter().sum();
        assert!(
            total > 0.5,
            "the spike spreads, it does not vanish: {total}"
        );
    }

    #[test]
    fn direction_paints_the_stroke_direction_mirrored_on_the_other_side() {
        let mut map = DirectionMap::from_fn(20, 20, |_| DVec2::Y);
        let mut brush = hard(BrushMode::Set, 0.0);
        brush.mirror = true;
        dab_direction(
            &mut map,
            &brush,
            DVec2::new(0.25, 0.5),
            DVec2::new(3.0, 3.0),
        );
        let left = map.sample(DVec2::new(0.25, 0.5));
        let right = map.sample(DVec2::new(0.75, 0.5));
        let s = std::f64::consts::FRAC_1_SQRT_2;
        assert!((left - DVec2::new(s, s)).length() < 1e-6, "{left}");
        assert!((right - DVec2::new(-s, s)).length() < 1e-6, "{right}");
        dab_direction(
            &mut map,
            &hard(BrushMode::Reset, 0.0),
            DVec2::new(0.25, 0.5),
            DVec2::ZERO,
        );
        assert!((map.sample(DVec2::new(0.25, 0.5)) - DVec2::Y).length() < 1e-6);
    }

    #[test]
    fn painting_a_constant_map_makes_a_raster_of_the_other_maps_size() {
        use crate::{Blend, GrowthMaps, MapKey};
        let mut growth = GrowthMaps::uniform();
        growth.e_growth = ScalarMap::from_fn(32, 24, |uv| uv.y as f32);
        let mut maps = KeyedMaps::new(
            vec![MapKey {
                dg: None,
                step: 0,
                maps: growth,
            }],
            Blend::Linear,
        )
        .expect("one key");
        assert_eq!(maps.keys()[0].maps.stretch.size(), (1, 1));
        let brush = hard(BrushMode::Set, 0.2);
        let stretch = PaintTarget::Scalar(MapKind::Stretch);
        let dab = |maps: &mut KeyedMaps, key| {
            dab_keyed(maps, key, stretch, &brush, DVec2::splat(0.5), DVec2::ZERO);
        };
        dab(&mut maps, 0);
        let painted = &maps.keys()[0].maps.stretch;
        assert_eq!(painted.size(), (32, 24));
        assert!((painted.sample(DVec2::new(0.5, 0.5)) - 0.2).abs() < 1e-6);
        assert_eq!(painted.sample(DVec2::new(0.05, 0.95)), 1.0);
        // A key that does not exist: nothing changes.
        let before = maps.clone();
        dab(&mut maps, 3);
        assert_eq!(maps, before);
    }

    #[test]
    fn the_falloff_is_a_smoothstep_from_the_hard_core_to_the_rim() {
        let brush = Brush {
            radius_in_uv: 0.2,
            hardness: 0.5,
            strength: 0.6,
            ..Brush::default()
        };
        // s = (t - hardness) / (1 - hardness); weight = strength (1 - 3s² + 2s³).
        for (distance, s) in [(0.1, 0.0), (0.125, 0.25), (0.15, 0.5), (0.175, 0.75)] {
            let expected = 0.6 * (1.0 - s * s * (3.0 - 2.0 * s));
            let weight = f64::from(brush.weight(distance));
            assert!(
                (weight - expected).abs() < 1e-6,
                "{distance}: {weight} vs {expected}"
            );
        }
        assert!(
            (f64::from(brush.weight(0.15)) - 0.3).abs() < 1e-6,
            "half way: half strength"
        );
    }

    #[test]
    fn stroke_dabs_are_evenly_spaced_along_the_path_whatever_the_frames() {
        // One long frame and many short ones along the same L-shaped path
        // give the same dabs: the remainder is carried between frames.
        let path = [
            DVec2::new(0.1, 0.1),
            DVec2::new(0.8, 0.1),
            DVec2::new(0.8, 0.6),
        ];
        let spacing = 0.031;
        let mut coarse = StrokeSpacing::new(spacing);
        let mut coarse_dabs: Vec<StrokeDab> = Vec::new();
        for p in path {
            coarse_dabs.extend(coarse.extend_to(p));
        }
        let mut fine = StrokeSpacing::new(spacing);
        let mut fine_dabs = fine.extend_to(path[0]);
        for pair in path.windows(2) {
            for i in 1..=37 {
                let t = f64::from(i) / 37.0;
                fine_dabs.extend(fine.extend_to(pair[0].lerp(pair[1], t)));
            }
        }
        // Path length 1.2: a dab at the start and one every 0.031.
        assert_eq!(coarse_dabs.len(), 39);
        assert_eq!(fine_dabs.len(), coarse_dabs.len());
        for (a, b) in coarse_dabs.iter().zip(&fine_dabs) {
            assert!(a.centre_in_uv.distance(b.centre_in_uv) < 1e-9);
        }
        // Consecutive dabs are never further apart than the spacing (the
        // corner cuts it shorter), and every point of the path is within
        // half a spacing of a dab.
        for pair in coarse_dabs.windows(2) {
            let gap = pair[0].centre_in_uv.distance(pair[1].centre_in_uv);
            assert!(gap <= spacing + 1e-12, "gap {gap}");
        }
        for i in 0..=1200 {
            let s = f64::from(i) / 1000.0;
            let point = if s <= 0.7 {
                DVec2::new(0.1 + s, 0.1)
            } else {
                DVec2::new(0.8, 0.1 + (s - 0.7))
            };
            let nearest = coarse_dabs
                .iter()
                .map(|d| d.centre_in_uv.distance(point))
                .fold(f64::INFINITY, f64::min);
            // The path's end is up to one spacing past the last dab.
            assert!(nearest <= spacing + 1e-9, "{point} is {nearest} from a dab");
        }
        // Directions follow the segments; the first dab has none.
        assert_eq!(coarse_dabs[0].direction_in_uv, DVec2::ZERO);
        assert!((coarse_dabs[5].direction_in_uv - DVec2::X).length() < 1e-12);
        assert!((coarse_dabs[38].direction_in_uv - DVec2::Y).length() < 1e-12);
    }

    #[test]
    fn a_stroke_that_does_not_move_is_one_dab_and_short_moves_add_up() {
        let mut spacing = StrokeSpacing::for_brush(&Brush {
            radius_in_uv: 0.08,
            ..Brush::default()
        });
        assert_eq!(spacing.extend_to(DVec2::new(0.5, 0.5)).len(), 1);
        assert!(spacing.extend_to(DVec2::new(0.5, 0.5)).is_empty());
        // Five moves of 0.005 reach the 0.02 spacing on the fourth.
        let counts: Vec<usize> = (1..=5)
            .map(|i| {
                spacing
                    .extend_to(DVec2::new(0.5 + 0.005 * f64::from(i), 0.5))
                    .len()
            })
            .collect();
        assert_eq!(counts, [0, 0, 0, 1, 0]);
        spacing.end();
        assert!(!spacing.started());
        assert_eq!(spacing.extend_to(DVec2::new(0.1, 0.1)).len(), 1);
        assert!(spacing.extend_to(DVec2::new(f64::NAN, 0.1)).is_empty());
    }
}

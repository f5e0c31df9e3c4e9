//! The coarse map basis the fit works in: per time key, four growth maps
//! (e-growth, w-growth and their inner versions) and the growth direction
//! (an angle from +v), each a sum of bilinear hat functions on a grid of
//! nodes over the UV square.

use anthesis_maps::{Blend, DirectionMap, GrowthMaps, KeyedMaps, MapError, MapKey, ScalarMap};
use glam::DVec2;

/// The fields of one time key, in parameter order.
pub const FIELDS: usize = 5;
/// Field index of the growth direction's angle (the others are
/// e-growth, w-growth, e-growth-in, w-growth-in, in that order).
pub const ANGLE: usize = 4;
/// The growth direction turns at most this far from +v (radians): beyond
/// that the direction map's channels, clamped to [-1, 1], would not hold it
/// and the fit would wander into growth across the organ that the other
/// maps describe better.
pub const MAX_ANGLE: f64 = 1.2;
/// Codes of a 16-bit map: the fit works with values a saved map holds
/// exactly, so that the fitted project simulates to the reported shape.
const CODES: f64 = 65535.0;

/// A grid of hat functions: `nodes_u` columns across, `nodes_v` rows from
/// base to tip (one node along an axis means constant along it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Grid {
    /// Nodes across the organ (u).
    pub nodes_u: usize,
    /// Nodes from base to tip (v).
    pub nodes_v: usize,
}

impl Grid {
    /// The number of nodes.
    pub fn len(&self) -> usize {
        self.nodes_u * self.nodes_v
    }

    /// Whether the grid has no node.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The weight of every node at `uv` (they sum to 1).
    pub fn weights(&self, uv: DVec2) -> Vec<f64> {
        let along = |n: usize, x: f64| -> Vec<f64> {
            if n <= 1 {
                return vec![1.0];
            }
            let s = x.clamp(0.0, 1.0) * (n - 1) as f64;
            (0..n)
                .map(|i| (1.0 - (s - i as f64).abs()).max(0.0))
                .collect()
        };
        let wu = along(self.nodes_u, uv.x);
        let wv = along(self.nodes_v, uv.y);
        let mut weights = Vec::with_capacity(self.len());
        for b in &wv {
            for a in &wu {
                weights.push(a * b);
            }
        }
        weights
    }

    /// The value at `uv` of the field with node values `coefficients`.
    pub fn value(&self, coefficients: &[f64], uv: DVec2) -> f64 {
        self.weights(uv)
            .iter()
            .zip(coefficients)
            .map(|(w, c)| w * c)
            .sum()
    }
}

/// Where the parameters of a fit sit and what they mean.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// The grid of the four growth maps.
    pub growth: Grid,
    /// The grid of the direction's angle (empty: the direction stays +v).
    pub direction: Grid,
    /// The steps of the time keys (sorted, distinct; at least one).
    pub key_steps: Vec<u32>,
}

impl Layout {
    /// Parameters per time key.
    pub fn per_key(&self) -> usize {
        4 * self.growth.len() + self.direction.len()
    }

    /// All parameters.
    pub fn len(&self) -> usize {
        self.per_key() * self.key_steps.len()
    }

    /// Whether there are no parameters.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The range of `field`'s node values: growth maps hold [0, 1], the
    /// angle ±[`MAX_ANGLE`].
    pub fn bounds(field: usize) -> (f64, f64) {
        if field == ANGLE {
            (-MAX_ANGLE, MAX_ANGLE)
        } else {
            (0.0, 1.0)
        }
    }

    /// The field of parameter `index`.
    pub fn field_of(&self, index: usize) -> usize {
        let within = index % self.per_key();
        (within / self.growth.len().max(1)).min(ANGLE)
    }

    /// The parameters of key `key`, field `field` (a range into the vector).
    pub fn range(&self, key: usize, field: usize) -> std::ops::Range<usize> {
        let start = key * self.per_key() + field * self.growth.len();
        let len = if field == ANGLE {
            self.direction.len()
        } else {
            self.growth.len()
        };
        start..start + len
    }

    /// The keyed maps of parameters `p`, rasterised at `size`. Stretch and
    /// bend are material, not growth: each key takes them unchanged from
    /// the key of `template` that weighs most at its step.
    pub fn maps(
        &self,
        p: &[f64],
        size: (u32, u32),
        template: &KeyedMaps,
    ) -> Result<KeyedMaps, MapError> {
        let (width, height) = size;
        let keys = self
            .key_steps
            .iter()
            .enumerate()
            .map(|(k, &step)| {
                let [(a, wa), (b, wb)] = template.weights_at(f64::from(step));
                let stiffness = &template.key_clamped(if wb > wa { b } else { a }).maps;
                let scalar = |field: usize| {
                    let c = &p[self.range(k, field)];
                    ScalarMap::from_fn(width, height, |uv| {
                        quantise(self.growth.value(c, uv).clamp(0.0, 1.0)) as f32
                    })
                };
                let angle = &p[self.range(k, ANGLE)];
                let direction = if self.direction.is_empty() {
                    DirectionMap::constant(DVec2::Y)
                } else {
                    DirectionMap::from_fn(width, height, |uv| {
                        let a = self.direction.value(angle, uv);
                        DVec2::new(quantise_signed(a.sin()), quantise_signed(a.cos()))
                    })
                };
                MapKey {
                    dg: None,
                    step,
                    maps: GrowthMaps {
                        e_growth: scalar(0),
                        w_growth: scalar(1),
                        e_growth_in: scalar(2),
                        w_growth_in: scalar(3),
                        stretch: stiffness.stretch.clone(),
                        bend: stiffness.bend.clone(),
                        direction,
                    },
                }
            })
            .collect();
        KeyedMaps::new(keys, Blend::Linear)
    }
}

/// `value` in [0, 1] as a 16-bit map stores it.
fn quantise(value: f64) -> f64 {
    (value * CODES).round() / CODES
}

/// `value` in [-1, 1] as a 16-bit direction map stores it (mid grey 32768
/// is zero, see `anthesis_maps`).
fn quantise_signed(value: f64) -> f64 {
    let code = (32768.0 + value.clamp(-1.0, 1.0) * 32767.0).round();
    (code - 32768.0) / 32767.0
}

/// The steps of `count` time keys spread evenly over `keyframes`: one key
/// at step 0, or keys at 0 and `keyframes` and evenly between.
pub fn key_steps(count: u32, keyframes: u32) -> Vec<u32> {
    let count = count.max(1);
    if count == 1 {
        return vec![0];
    }
    let mut steps: Vec<u32> = (0..count)
        .map(|k| (f64::from(k) * f64::from(keyframes) / f64::from(count - 1)).round() as u32)
        .collect();
    steps.dedup();
    steps
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hat_weights_sum_to_one_and_interpolate_nodes() {
        let grid = Grid {
            nodes_u: 3,
            nodes_v: 4,
        };
        for uv in [
            DVec2::new(0.1, 0.9),
            DVec2::new(0.5, 0.0),
            DVec2::new(1.0, 0.37),
        ] {
            let sum: f64 = grid.weights(uv).iter().sum();
            assert!((sum - 1.0).abs() < 1e-12);
        }
        let c: Vec<f64> = (0..12).map(|i| i as f64).collect();
        // Node (1, 2): u = 0.5, v = 2/3.
        assert!((grid.value(&c, DVec2::new(0.5, 2.0 / 3.0)) - 7.0).abs() < 1e-12);
    }

    #[test]
    fn keys_spread_over_the_run() {
        assert_eq!(key_steps(1, 100), vec![0]);
        assert_eq!(key_steps(2, 100), vec![0, 100]);
        assert_eq!(key_steps(3, 100), vec![0, 50, 100]);
    }

    #[test]
    fn maps_hold_the_fields() {
        let layout = Layout {
            growth: Grid {
                nodes_u: 1,
                nodes_v: 2,
            },
            direction: Grid {
                nodes_u: 1,
                nodes_v: 1,
            },
            key_steps: vec![0],
        };
        assert_eq!(layout.len(), 9);
        let p = [0.2, 0.4, 0.1, 0.1, 0.3, 0.3, 0.5, 0.5, 0.0];
        let maps = layout
            .maps(&p, (8, 8), &KeyedMaps::single(GrowthMaps::uniform()))
            .expect("valid maps");
        let key = &maps.keys()[0].maps;
        assert!((key.e_growth.sample(DVec2::new(0.5, 0.0)) - 0.2).abs() < 0.02);
        assert!((key.e_growth.sample(DVec2::new(0.5, 1.0)) - 0.4).abs() < 0.02);
        assert!((key.w_growth_in.sample(DVec2::new(0.5, 0.5)) - 0.5).abs() < 1e-4);
        assert!((key.direction.sample(DVec2::new(0.5, 0.5)) - DVec2::Y).length() < 1e-4);
        assert_eq!(layout.field_of(8), ANGLE);
        assert_eq!(layout.field_of(2), 1);
    }
}

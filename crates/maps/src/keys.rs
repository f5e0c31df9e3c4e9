//! Map sets keyed in time and the curves that blend between keys.

use std::iter::Sum;
use std::ops::Mul;

use glam::DVec2;
use serde::{Deserialize, Serialize};

use crate::{GrowthMaps, MapError, MapKind};

/// How the weight of the later key rises from 0 to 1 between two keys.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Blend {
    /// Straight interpolation: weight = s.
    #[default]
    Linear,
    /// The cubic growth function of the sketch-based blossom seed (its §4.1
    /// eq. 2 on the unit interval): weight = 3s² − 2s³. Slow start, slow end.
    Smooth,
    /// The logistic growth function of the same seed (§4.1 eq. 1), centred at
    /// s = ½ and rescaled to pass exactly through 0 at s = 0 and 1 at s = 1:
    /// weight = (σ(k(s − ½)) − σ(−k/2)) / (σ(k/2) − σ(−k/2)) with σ the
    /// logistic function and k the steepness. Small k approaches `Linear`,
    /// large k a step at s = ½; the sign of k does not matter.
    Logistic {
        /// The steepness `k` (any sign; the default is
        /// [`Blend::DEFAULT_STEEPNESS`]).
        #[serde(default = "default_steepness")]
        steepness: f64,
    },
}

fn default_steepness() -> f64 {
    Blend::DEFAULT_STEEPNESS
}

impl Blend {
    /// A steepness that gives a clearly sigmoid but not step-like curve.
    pub const DEFAULT_STEEPNESS: f64 = 10.0;

    /// Below this steepness the logistic curve is taken as linear (they
    /// differ by O(k²)).
    const LINEAR_STEEPNESS: f64 = 1.0e-6;

    /// Above this steepness the logistic curve is a step for all purposes;
    /// the cap keeps infinities out of the arithmetic.
    const MAX_STEEPNESS: f64 = 1.0e6;

    /// `Logistic` with [`Blend::DEFAULT_STEEPNESS`].
    pub fn logistic() -> Self {
        Blend::Logistic {
            steepness: Self::DEFAULT_STEEPNESS,
        }
    }

    /// The weight of the later key at fraction `s` of the way from the
    /// earlier key to the later one. `s` is clamped to `[0, 1]` (NaN counts
    /// as 0); the result is exactly 0 at `s = 0` and exactly 1 at `s = 1`,
    /// and never decreases with `s`.
    pub fn apply(self, s: f64) -> f64 {
        if s.is_nan() || s <= 0.0 {
            return 0.0;
        }
        if s >= 1.0 {
            return 1.0;
        }
        match self {
            Blend::Linear => s,
            Blend::Smooth => s * s * (3.0 - 2.0 * s),
            Blend::Logistic { steepness } => normalised_logistic(s, steepness),
        }
    }
}

/// The rescaled logistic curve of [`Blend::Logistic`], written with tanh
/// (σ(x) = (1 + tanh(x/2)) / 2), which stays accurate for small steepness:
/// weight = ½ + tanh(k(s − ½)/2) / (2 tanh(k/4)).
fn normalised_logistic(s: f64, steepness: f64) -> f64 {
    let k = if steepness.is_nan() {
        0.0
    } else {
        steepness.abs().min(Blend::MAX_STEEPNESS)
    };
    if k < Blend::LINEAR_STEEPNESS {
        return s;
    }
    let half_range = (k / 4.0).tanh();
    (0.5 + (k * (s - 0.5) / 2.0).tanh() / (2.0 * half_range)).clamp(0.0, 1.0)
}

/// The maps that hold at one simulation step.
#[derive(Clone, Debug, PartialEq)]
pub struct MapKey {
    /// The simulation step (keyframe) at which these maps hold exactly.
    pub step: u32,
    /// The maps at that step.
    pub maps: GrowthMaps,
    /// The growth scale at this key, in place of its template's `dg`
    /// (`None`: the template's). A growth value `m` of this key is a rate
    /// `1 + dg · m` per step, blended between keys like the maps: a
    /// negative `dg` makes a late key shrink the organ (a flower that
    /// wilts after it opened).
    pub dg: Option<f64>,
}

impl MapKey {
    /// The key at `step` with `maps` and the template's growth scale.
    pub fn new(step: u32, maps: GrowthMaps) -> MapKey {
        MapKey {
            step,
            maps,
            dg: None,
        }
    }
}

/// Map sets keyed by simulation step, blended between keys.
///
/// Keys are kept sorted by step, with no two at the same step, and there is
/// always at least one.
#[derive(Clone, Debug, PartialEq)]
pub struct KeyedMaps {
    keys: Vec<MapKey>,
    /// How values pass from one key to the next between their steps.
    pub blend: Blend,
}

impl KeyedMaps {
    /// Sorts the keys by step; fails when there are none or two share a step.
    pub fn new(mut keys: Vec<MapKey>, blend: Blend) -> Result<Self, MapError> {
        if keys.is_empty() {
            return Err(MapError::NoKeys);
        }
        keys.sort_by_key(|key| key.step);
        if let Some(pair) = keys.windows(2).find(|pair| pair[0].step == pair[1].step) {
            return Err(MapError::DuplicateStep { step: pair[0].step });
        }
        Ok(Self { keys, blend })
    }

    /// One key at step 0: these maps at every step.
    pub fn single(maps: GrowthMaps) -> Self {
        Self {
            keys: vec![MapKey::new(0, maps)],
            blend: Blend::Linear,
        }
    }

    /// The keys, sorted by step.
    pub fn keys(&self) -> &[MapKey] {
        &self.keys
    }

    /// Key `index`, or the last key when `index` is past the end (as an
    /// index a panel kept while keys were removed can be).
    pub fn key_clamped(&self, index: usize) -> &MapKey {
        &self.keys[self.clamped_index(index)]
    }

    /// `index` if there is such a key, else the index of the last key.
    pub fn clamped_index(&self, index: usize) -> usize {
        // There is always at least one key.
        index.min(self.keys.len().saturating_sub(1))
    }

    /// The one size all raster maps of these keys have (a project keeps one
    /// size per template; 1x1 maps are constants and fit any size), by the
    /// rule the project loader checks ([`common_raster_size`]): `None` when
    /// every map is a constant.
    pub fn raster_size(&self) -> Option<(u32, u32)> {
        common_raster_size(self.keys.iter().flat_map(|key| {
            let maps = &key.maps;
            MapKind::ALL
                .iter()
                .map(|&kind| maps.scalar(kind).size())
                .chain(std::iter::once(maps.direction.size()))
        }))
    }

    /// The keys, for editing their maps. Changing a key's `step` here must
    /// keep the steps sorted and distinct (use [`KeyedMaps::remove`] and
    /// [`KeyedMaps::insert`] to move a key); if it does not, blending picks
    /// wrong keys, though the weights stay finite and sum to 1.
    pub fn keys_mut(&mut self) -> &mut [MapKey] {
        &mut self.keys
    }

    /// Adds a key in step order and returns its index; fails if a key
    /// already sits at that step.
    pub fn insert(&mut self, key: MapKey) -> Result<usize, MapError> {
        match self
            .keys
            .binary_search_by_key(&key.step, |existing| existing.step)
        {
            Ok(_) => Err(MapError::DuplicateStep { step: key.step }),
            Err(index) => {
                self.keys.insert(index, key);
                Ok(index)
            }
        }
    }

    /// Removes and returns key `index`; the last remaining key cannot go.
    pub fn remove(&mut self, index: usize) -> Result<MapKey, MapError> {
        let count = self.keys.len();
        if index >= count {
            return Err(MapError::NoSuchKey { index, count });
        }
        if count == 1 {
            return Err(MapError::LastKey);
        }
        Ok(self.keys.remove(index))
    }

    /// Which keys contribute at `step` and with what weight.
    ///
    /// Before the first key, only the first key counts: `[(0, 1.0), (0, 0.0)]`;
    /// at or after the last key, only the last. Between key `a` at step `sa`
    /// and the next key `b` at `sb` (`sa <= step < sb`) the answer is
    /// `[(a, 1 - w), (b, w)]` with `w = blend.apply((step - sa) / (sb - sa))`,
    /// so exactly at a key's step that key has weight 1. The weights sum to 1;
    /// when one key contributes the second weight is 0.
    pub fn weights_at(&self, step: f64) -> [(usize, f64); 2] {
        blend_weights(&self.keys, |key| key.step, self.blend, step)
    }

    /// The key steps and the blend without the maps: all a simulation needs
    /// once it has sampled each key's maps, so it need not copy them.
    pub fn schedule(&self) -> KeySchedule {
        KeySchedule {
            steps: self.keys.iter().map(|key| key.step).collect(),
            blend: self.blend,
        }
    }

    /// The blended eq. 1 value of one scalar map for a triangle at `step`.
    /// Convenient for single queries; a simulation that asks every step
    /// should evaluate each key once and blend with [`KeyedMaps::weights_at`].
    pub fn scalar_triangle_value_at(
        &self,
        kind: MapKind,
        step: f64,
        corners_in_uv: [DVec2; 3],
    ) -> f64 {
        self.blend_at(step, |maps| maps.scalar(kind).triangle_value(corners_in_uv))
    }

    /// The blended eq. 1 direction (not normalised) for a triangle at `step`.
    pub fn direction_triangle_value_at(&self, step: f64, corners_in_uv: [DVec2; 3]) -> DVec2 {
        self.blend_at(step, |maps| maps.direction.triangle_value(corners_in_uv))
    }

    /// `value_of` the keys around `step`, weighted as [`KeyedMaps::weights_at`]
    /// says (a key of weight zero is not asked).
    fn blend_at<T>(&self, step: f64, value_of: impl Fn(&GrowthMaps) -> T) -> T
    where
        T: Sum,
        f64: Mul<T, Output = T>,
    {
        self.weights_at(step)
            .iter()
            .filter(|(_, weight)| *weight != 0.0)
            .map(|&(index, weight)| weight * value_of(&self.keys[index].maps))
            .sum()
    }
}

/// The steps of a [`KeyedMaps`] and its blend, without the maps.
#[derive(Clone, Debug, PartialEq)]
pub struct KeySchedule {
    steps: Vec<u32>,
    /// How values pass from one key to the next between their steps.
    pub blend: Blend,
}

impl KeySchedule {
    /// The same weights as [`KeyedMaps::weights_at`] of the map set this
    /// schedule came from.
    pub fn weights_at(&self, step: f64) -> [(usize, f64); 2] {
        blend_weights(&self.steps, |&step| step, self.blend, step)
    }
}

/// [`KeyedMaps::weights_at`] over `keys` sorted by `step_of`, at least one.
fn blend_weights<K>(
    keys: &[K],
    step_of: impl Fn(&K) -> u32,
    blend: Blend,
    step: f64,
) -> [(usize, f64); 2] {
    let last = keys.len() - 1;
    // The number of keys at or before `step` (0 for a NaN step).
    let reached = keys.partition_point(|key| f64::from(step_of(key)) <= step);
    if reached == 0 {
        return [(0, 1.0), (0, 0.0)];
    }
    if reached > last {
        return [(last, 1.0), (last, 0.0)];
    }
    let (earlier, later) = (reached - 1, reached);
    let start = f64::from(step_of(&keys[earlier]));
    let end = f64::from(step_of(&keys[later]));
    let weight = blend.apply((step - start) / (end - start));
    [(earlier, 1.0 - weight), (later, weight)]
}

/// The size the raster maps of one template share, from their `sizes` in
/// reading order: the size most maps have (the first one read wins a tie),
/// 1x1 maps left out (they are constants and fit any size); `None` when
/// every map is a constant. The project loader names the maps that differ
/// from it; the app paints and loads maps at it.
pub fn common_raster_size(sizes: impl IntoIterator<Item = (u32, u32)>) -> Option<(u32, u32)> {
    let mut counts: Vec<((u32, u32), usize)> = Vec::new();
    for size in sizes.into_iter().filter(|&size| size != (1, 1)) {
        match counts.iter_mut().find(|(s, _)| *s == size) {
            Some((_, n)) => *n += 1,
            None => counts.push((size, 1)),
        }
    }
    // The first of the most common sizes: `max_by_key` keeps the last of
    // equals, so look from the end.
    counts
        .iter()
        .rev()
        .max_by_key(|(_, n)| *n)
        .map(|(size, _)| *size)
}

//! The seven maps of one organ template at one time key.

use glam::DVec2;
use serde::{Deserialize, Serialize};

use crate::{DirectionMap, ScalarMap};

/// The six scalar maps. The seventh map, the growth direction, has two
/// channels and is a [`DirectionMap`]; its file name is
/// [`DIRECTION_MAP_NAME`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MapKind {
    /// Growth rate of the base (outer) layer along the growth direction.
    EGrowth,
    /// Growth rate of the base layer across the growth direction.
    WGrowth,
    /// Growth rate of the inner layer along the growth direction.
    EGrowthIn,
    /// Growth rate of the inner layer across the growth direction.
    WGrowthIn,
    /// Multiplier of the stretch stiffness.
    Stretch,
    /// Multiplier of the bend stiffness.
    Bend,
}

/// The name of the direction map, as [`MapKind::name`] names the others.
pub const DIRECTION_MAP_NAME: &str = "direction";

impl MapKind {
    /// Every scalar map kind, in the order files and panels list them.
    pub const ALL: [MapKind; 6] = [
        MapKind::EGrowth,
        MapKind::WGrowth,
        MapKind::EGrowthIn,
        MapKind::WGrowthIn,
        MapKind::Stretch,
        MapKind::Bend,
    ];

    /// The identifier used in files and on the command line, e.g. `e_growth`.
    pub fn name(self) -> &'static str {
        match self {
            MapKind::EGrowth => "e_growth",
            MapKind::WGrowth => "w_growth",
            MapKind::EGrowthIn => "e_growth_in",
            MapKind::WGrowthIn => "w_growth_in",
            MapKind::Stretch => "stretch",
            MapKind::Bend => "bend",
        }
    }

    /// The name shown to people, e.g. `e-growth`.
    pub fn label(self) -> &'static str {
        match self {
            MapKind::EGrowth => "e-growth",
            MapKind::WGrowth => "w-growth",
            MapKind::EGrowthIn => "e-growth-in",
            MapKind::WGrowthIn => "w-growth-in",
            MapKind::Stretch => "stretch",
            MapKind::Bend => "bend",
        }
    }

    /// The kind whose [`MapKind::name`] is `name`.
    pub fn from_name(name: &str) -> Option<MapKind> {
        MapKind::ALL.into_iter().find(|kind| kind.name() == name)
    }

    /// The value of an unpainted map: no growth (0) for the growth maps,
    /// the template's own stiffness (1) for stretch and bend.
    pub fn default_value(self) -> f32 {
        match self {
            MapKind::EGrowth | MapKind::WGrowth | MapKind::EGrowthIn | MapKind::WGrowthIn => 0.0,
            MapKind::Stretch | MapKind::Bend => 1.0,
        }
    }
}

/// The seven maps of an organ template at one time key. The maps may have
/// different resolutions; a project loader that wants one resolution per
/// organ checks it with `check_size`.
#[derive(Clone, Debug, PartialEq)]
pub struct GrowthMaps {
    /// [`MapKind::EGrowth`]: growth of the base layer along the growth
    /// direction: 0 = none, 1 = the template's full rate `dg` (a file holds
    /// `[0, 1]`).
    pub e_growth: ScalarMap,
    /// [`MapKind::WGrowth`]: growth of the base layer across the growth
    /// direction, on the same scale.
    pub w_growth: ScalarMap,
    /// [`MapKind::EGrowthIn`]: growth of the inner layer along the growth
    /// direction, on the same scale.
    pub e_growth_in: ScalarMap,
    /// [`MapKind::WGrowthIn`]: growth of the inner layer across the growth
    /// direction, on the same scale.
    pub w_growth_in: ScalarMap,
    /// [`MapKind::Stretch`]: multiplier of the template's stretch
    /// stiffness (1 = unchanged).
    pub stretch: ScalarMap,
    /// [`MapKind::Bend`]: multiplier of the template's bend stiffness
    /// (1 = unchanged).
    pub bend: ScalarMap,
    /// The growth direction at each point, a vector in UV space (`(0, 1)`
    /// is along `v`, from the base towards the tip).
    pub direction: DirectionMap,
}

impl GrowthMaps {
    /// Constant maps: no growth, unit stiffness, and growth along `v` (from
    /// the base towards the tip), direction `(0, 1)`.
    pub fn uniform() -> Self {
        let constant = |kind: MapKind| ScalarMap::constant(kind.default_value());
        Self {
            e_growth: constant(MapKind::EGrowth),
            w_growth: constant(MapKind::WGrowth),
            e_growth_in: constant(MapKind::EGrowthIn),
            w_growth_in: constant(MapKind::WGrowthIn),
            stretch: constant(MapKind::Stretch),
            bend: constant(MapKind::Bend),
            direction: DirectionMap::constant(DVec2::Y),
        }
    }

    /// The scalar map of kind `kind`.
    pub fn scalar(&self, kind: MapKind) -> &ScalarMap {
        match kind {
            MapKind::EGrowth => &self.e_growth,
            MapKind::WGrowth => &self.w_growth,
            MapKind::EGrowthIn => &self.e_growth_in,
            MapKind::WGrowthIn => &self.w_growth_in,
            MapKind::Stretch => &self.stretch,
            MapKind::Bend => &self.bend,
        }
    }

    /// The scalar map of kind `kind`, to paint or replace.
    pub fn scalar_mut(&mut self, kind: MapKind) -> &mut ScalarMap {
        match kind {
            MapKind::EGrowth => &mut self.e_growth,
            MapKind::WGrowth => &mut self.w_growth,
            MapKind::EGrowthIn => &mut self.e_growth_in,
            MapKind::WGrowthIn => &mut self.w_growth_in,
            MapKind::Stretch => &mut self.stretch,
            MapKind::Bend => &mut self.bend,
        }
    }
}

impl Default for GrowthMaps {
    fn default() -> Self {
        Self::uniform()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_are_distinct() {
        for kind in MapKind::ALL {
            assert_eq!(MapKind::from_name(kind.name()), Some(kind));
            assert_eq!(kind.label(), kind.name().replace('_', "-"));
        }
        assert_eq!(MapKind::from_name(DIRECTION_MAP_NAME), None);
        assert_eq!(MapKind::from_name("e-growth"), None);
    }

    #[test]
    fn uniform_maps_hold_the_defaults() {
        let maps = GrowthMaps::uniform();
        let somewhere_in_uv = DVec2::new(0.3, 0.8);
        for kind in MapKind::ALL {
            let expected = f64::from(kind.default_value());
            assert_eq!(maps.scalar(kind).sample(somewhere_in_uv), expected);
        }
        assert_eq!(maps.e_growth.sample(somewhere_in_uv), 0.0);
        assert_eq!(maps.bend.sample(somewhere_in_uv), 1.0);
        assert_eq!(maps.direction.sample(somewhere_in_uv), DVec2::new(0.0, 1.0));
    }

    #[test]
    fn scalar_mut_reaches_the_named_field() {
        let mut maps = GrowthMaps::uniform();
        for (index, kind) in MapKind::ALL.into_iter().enumerate() {
            *maps.scalar_mut(kind) = ScalarMap::constant(index as f32 + 10.0);
        }
        assert_eq!(maps.e_growth.values(), &[10.0]);
        assert_eq!(maps.w_growth.values(), &[11.0]);
        assert_eq!(maps.e_growth_in.values(), &[12.0]);
        assert_eq!(maps.w_growth_in.values(), &[13.0]);
        assert_eq!(maps.stretch.values(), &[14.0]);
        assert_eq!(maps.bend.values(), &[15.0]);
    }
}

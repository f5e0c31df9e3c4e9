//! The lily opened by edge growth (issue 41 item 4, after Liang and
//! Mahadevan, "Growth, geometry, and mechanics of a blooming lily", PNAS
//! 2011): the built-in lily's bud, organs and stretch stiffness, but tepals that
//! grow only in their plane (the inner and the base growth maps are equal,
//! so no hinge is told to bend) and faster at the margins than along the
//! midrib. A tepal that is cup-shaped in the bud (positive Gaussian
//! curvature) and whose margins outgrow its midrib cannot stay a cup: its
//! margins get longer than the cup has room for, so it turns into a saddle
//! (negative Gaussian curvature) and bends out, and the excess length
//! stored at the margin ripples it.
//!
//! Decided here (the paper's measurements, our reading):
//!
//! - the e-growth (along the venation) rises from the midrib to the margins
//!   by a smooth profile across the width ([`LilyEdge::profile_power`]: the
//!   map is `e_midrib + (e_margin − e_midrib)·s^p`, `s` the distance from
//!   the midrib as a fraction of the half width), so that over the 100
//!   steps of the opening the margin lengthens about 40 % more than the
//!   midrib: 1.62 against 1.16 times its bud length ([`LilyEdge::MARGIN`]);
//! - the w-growth (across) is the same everywhere: the excess is along the
//!   margin only;
//! - no joint ramp: the bud opens by its growth alone, not by a turn at the
//!   receptacle (the built-in lily tilts its tepals 23°);
//! - the midrib band is stiffer than the lamina as in the lily, or, in the
//!   variant of the paper's experiment with the midribs cut away
//!   ([`LilyEdge::soft_midrib`]), no stiffer;
//! - half of the margin's excess lies in a narrow layer along the margin
//!   ([`LilyEdge::layer_share`], profile `s^16`), the other half rises as
//!   `s²` across the width: the broad part turns the cup into a saddle and
//!   opens the bud, the layer is what ripples;
//! - the rest state keeps the growth ([`LengthBase::Rest`]: the rest
//!   lengths are the bud's grown by the cumulative growth, not regrown from
//!   the current shape each step, so the margin's excess length is stored
//!   rather than forgotten), and the sheet is thin in bending:
//!   `Kb = Ks / 100` ([`LilyEdge::bend_ratio`], against Table 1's
//!   `Kb = Ks`; the consistent model's sheet is a plate whose bending
//!   thickness is `√(8 Kb/Ks)`, here 0.28 units, a length no mesh
//!   changes), and the stored excess buckles the margin into ripples
//!   (README, "Edge growth"). The buckling makes
//!   the Newton iterations slower to settle, so the solver may take up to
//!   200 per keyframe;
//! - the mesh resolves that sheet: a mean edge of 0.59 (edge scale
//!   [`LILY_EDGE_SCALE`], about two thicknesses), where the ripples'
//!   constant is that of finer meshes. A sheet thinner than the mesh can
//!   resolve (`Kb = Ks / 1000`, 0.089 thick, before) ripples in a constant
//!   that falls with every refinement.

use anthesis_flower::Project;
use anthesis_maps::{KeyedMaps, MapError};
use anthesis_physics::LengthBase;
use glam::DVec2;

use crate::flowers::{GardenError, LILY_BASE_V, LILY_MIDRIB_HALF_WIDTH, keyed, lily_at};
use crate::paint::{Painting, above_base, midrib_band, smoothstep};

/// The built-in name of the edge-growth lily.
pub const LILY_EDGE_NAME: &str = "lily-edge";

/// The edge-growth lily's growth scale: twice the lily's, so that the
/// margin's map value stays below 1 (a map value `m` grows a length by
/// `1 + 0.006·m` per step).
pub const LILY_EDGE_DG: f64 = 0.006;

/// The built-in's mean edge as a fraction of Table 1's (0.59 units; the
/// other flowers: [`EDGE_SCALE`](crate::flowers::EDGE_SCALE), 0.78): fine enough to resolve the sheet
/// ([`LilyEdge::MARGIN`]'s bending thickness 0.28 units), where the ripples'
/// constant `c` is that of the finer meshes (README, "Edge growth").
pub const LILY_EDGE_SCALE: f64 = 0.45;

/// The Newton iterations a keyframe of the edge-growth lily may take (the
/// other flowers: 50): while the margins buckle the iterations settle
/// slowly (at 4 times the particles, 50 were not enough in keyframe 1).
pub const LILY_EDGE_MAX_ITERATIONS: u32 = 200;

/// How an edge-growth lily's tepals grow (map values, scaled by
/// [`LILY_EDGE_DG`] per step).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LilyEdge {
    /// E-growth on the midrib.
    pub e_midrib: f64,
    /// E-growth at the margins.
    pub e_margin: f64,
    /// W-growth, everywhere.
    pub w: f64,
    /// The exponent of the profile across the width (2: a parabola, flat
    /// at the midrib; larger: the excess nearer the margins).
    pub profile_power: f64,
    /// The share of the margin's excess put in a layer along the margin
    /// (`s^layer_power`; 0: none, the whole excess follows `s^profile_power`).
    pub layer_share: f64,
    /// The exponent of that layer's profile (large: a narrow layer).
    pub layer_power: f64,
    /// Stretch and bend stiffness of the lamina, relative to the midrib's
    /// 1 (the lily's 0.3).
    pub lamina_stiffness: f64,
    /// The midrib band is no stiffer than the lamina.
    pub soft_midrib: bool,
    /// Each template's bend stiffness `Kb` over its stretch stiffness `Ks`
    /// (Table 1: 1; small: a sheet thin in bending). A length squared: the
    /// sheet's bending thickness is `√(8 bend_ratio)` project units.
    pub bend_ratio: f64,
}

impl LilyEdge {
    /// The built-in `lily-edge`: over 100 steps the midrib lengthens by
    /// `1.0015^100 ≈ 1.16` and the margin by `1.0049^100 ≈ 1.62`, about
    /// 40 % more (1.62 / 1.16 = 1.40).
    pub const MARGIN: LilyEdge = LilyEdge {
        e_midrib: 0.25,
        e_margin: 0.81,
        w: 0.25,
        profile_power: 2.0,
        layer_share: 0.5,
        layer_power: 16.0,
        lamina_stiffness: 0.3,
        soft_midrib: false,
        bend_ratio: 0.01,
    };

    /// The same growth with the midrib band as soft as the lamina (the
    /// paper's tepals with their midribs cut away still open).
    pub fn soft_midrib(self) -> LilyEdge {
        LilyEdge {
            soft_midrib: true,
            ..self
        }
    }

    /// The e-growth map's value at `uv` (before the base's ramp).
    pub fn e_at(&self, uv: DVec2) -> f64 {
        let s = ((uv.x - 0.5).abs() / 0.5).clamp(0.0, 1.0);
        let profile = (1.0 - self.layer_share) * s.powf(self.profile_power)
            + self.layer_share * s.powf(self.layer_power);
        self.e_midrib + (self.e_margin - self.e_midrib) * profile
    }
}

/// The edge-growth lily's maps: one key (the growth is the same over the
/// whole opening), inner maps equal to the base ones.
pub fn lily_edge_maps(edge: LilyEdge) -> Result<KeyedMaps, MapError> {
    let grows = |uv: DVec2| above_base(uv.y, LILY_BASE_V, 0.04);
    // The claw (v below about 0.15) grows less, as the lily's bottom region.
    let claw = |uv: DVec2| 1.0 - smoothstep(0.1, 0.2, uv.y);
    let e = move |uv: DVec2| grows(uv) * edge.e_at(uv) * (1.0 - 0.5 * claw(uv));
    let w = move |uv: DVec2| grows(uv) * edge.w * (1.0 - 0.5 * claw(uv));
    let lamina = edge.lamina_stiffness;
    let stiffness = move |uv: DVec2| {
        if edge.soft_midrib {
            lamina
        } else {
            lamina + (1.0 - lamina) * midrib_band(uv.x, LILY_MIDRIB_HALF_WIDTH)
        }
    };
    let direction = |uv: DVec2| DVec2::new(0.15 * (uv.x - 0.5) * uv.y, 1.0);
    let maps = Painting {
        e_growth: &e,
        w_growth: &w,
        e_growth_in: &e,
        w_growth_in: &w,
        stretch: &stiffness,
        bend: &stiffness,
        direction: &direction,
    }
    .paint();
    keyed(vec![(0, maps)])
}

/// The built-in `lily-edge` ([`LilyEdge::MARGIN`] at [`LILY_EDGE_SCALE`]).
pub fn lily_edge() -> Result<Project, GardenError> {
    lily_edge_of(LilyEdge::MARGIN, LILY_EDGE_SCALE)
}

/// The lily's bud, organs, colours and parts at `edge_scale` times Table
/// 1's edge, growing by `edge` (see the module documentation).
pub fn lily_edge_of(edge: LilyEdge, edge_scale: f64) -> Result<Project, GardenError> {
    let mut project = lily_at(edge_scale)?;
    project.name = if edge.soft_midrib {
        "Asiatic lily, edge growth, soft midrib".to_string()
    } else {
        "Asiatic lily, edge growth".to_string()
    };
    let organ = "lily edge";
    for template in &mut project.flower.templates {
        template.maps = lily_edge_maps(edge).map_err(|error| GardenError::Maps { organ, error })?;
        template.dg = LILY_EDGE_DG;
        template.joint_schedule.clear();
        template.bend_stiffness = edge.bend_ratio * template.stretch_stiffness;
    }
    project.settings.length_base = LengthBase::Rest;
    project.settings.solver.max_iterations = LILY_EDGE_MAX_ITERATIONS;
    Ok(project)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn maps(edge: LilyEdge) -> anthesis_maps::GrowthMaps {
        let keyed = lily_edge_maps(edge).expect("the maps paint");
        assert_eq!(keyed.keys().len(), 1, "one key: the same growth all along");
        keyed.keys()[0].maps.clone()
    }

    #[test]
    fn the_tepals_grow_only_in_their_plane() {
        let m = maps(LilyEdge::MARGIN);
        assert_eq!(m.e_growth_in, m.e_growth);
        assert_eq!(m.w_growth_in, m.w_growth);
    }

    #[test]
    fn over_the_opening_the_margin_lengthens_about_40_percent_more_than_the_midrib() {
        let m = maps(LilyEdge::MARGIN);
        let stretch = |u: f64| {
            let value = m.e_growth.sample(DVec2::new(u, 0.6));
            (1.0 + LILY_EDGE_DG * value).powi(100)
        };
        // The painted profile: 1.40 at the margin itself.
        let exact =
            |u: f64| (1.0 + LILY_EDGE_DG * LilyEdge::MARGIN.e_at(DVec2::new(u, 0.6))).powi(100);
        assert!((exact(0.0) / exact(0.5) - 1.40).abs() < 0.005);
        // The map: its outermost pixel's centre lies 1/128 inside the
        // margin, where the profile gives 1.340 (the narrow layer falls
        // steeply there: s^16 is 0.78 at s = 63/64).
        let (midrib, margin) = (stretch(0.5), stretch(0.0));
        assert!((midrib - 1.162).abs() < 0.005, "midrib ×{midrib}");
        assert!(
            (1.335..1.345).contains(&(margin / midrib)),
            "margin ×{margin}, midrib ×{midrib}"
        );
        // Half the excess in the layer: at nine tenths of the half width the
        // s² half alone gives 0.405 of the excess, the layer 0.093 more.
        let at = |s: f64| LilyEdge::MARGIN.e_at(DVec2::new(0.5 - 0.5 * s, 0.6));
        let share = (at(0.9) - at(0.0)) / (at(1.0) - at(0.0));
        assert!(
            (share - 0.5 * (0.81 + 0.9f64.powi(16))).abs() < 1e-12,
            "{share}"
        );
        // A smooth profile across: rising monotonically from the midrib.
        let across: Vec<f64> = (0..=10)
            .map(|i| stretch(0.5 - 0.05 * f64::from(i)))
            .collect();
        assert!(across.windows(2).all(|p| p[1] >= p[0]), "{across:?}");
        assert!((stretch(0.25) - midrib) < 0.3 * (margin - midrib));
        // The claw grows less and the attachment not at all.
        assert_eq!(m.e_growth.sample(DVec2::new(0.0, 0.02)), 0.0);
    }

    #[test]
    fn the_soft_midrib_is_no_stiffer_than_the_lamina() {
        let stiff = maps(LilyEdge::MARGIN);
        let soft = maps(LilyEdge::MARGIN.soft_midrib());
        let at = |m: &anthesis_maps::GrowthMaps, u: f64| m.bend.sample(DVec2::new(u, 0.5));
        assert!(at(&stiff, 0.5) > 3.0 * at(&stiff, 0.1));
        assert_eq!(at(&soft, 0.5), at(&soft, 0.1));
        assert_eq!(soft.stretch, soft.bend);
        assert_eq!(soft.e_growth, stiff.e_growth);
    }
}

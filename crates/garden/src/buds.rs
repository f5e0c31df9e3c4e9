//! Bud organs shaped around the flower axis, so that the organs of one bud
//! nest inside each other instead of cutting through each other.
//!
//! A [`RingOrgan`] is described in the flower's *meridional plane* (distance
//! from the axis `ρ`, height `y`): its midrib is a cubic Bézier curve there,
//! and each row across the organ is an arc of the circle of radius `ρ` about
//! the axis, as long as the organ is wide at that height. Organs of an outer
//! whorl use the same profile pushed outwards ([`RingOrgan::offset`]); a
//! contorted corolla tilts each row so that one margin lies further out than
//! the other ([`RingOrgan::contortion`]), which makes neighbours overlap like
//! the blades of a camera shutter.
//!
//! The surface is evaluated in the organ template frame of ARCHITECTURE.md:
//! the organ's base (the midrib at `v = 0`) at the origin, the organ growing
//! along +Y, its inner side facing −Z, `u` running along −X. Placed with
//! [`RingOrgan::placement`] at azimuth `a`, the template's +Z points away from
//! the axis at that azimuth and its +X towards increasing azimuth, so an
//! organ's `u = 0` margin (its *right* side, seen from outside the flower with
//! the tip up) faces the next organ counter-clockwise seen from above.

use anthesis_bud::{BezierCurve, BudError, RemeshOptions, Surface, bernstein3, build_organ};
use anthesis_mesh::Mesh;
use glam::{DVec2, DVec3};

/// A bud organ on a surface of revolution about the flower axis (see the
/// module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RingOrgan {
    /// Bézier control points of the midrib in the meridional plane:
    /// `(distance from the axis, height)`, base first. The base point is
    /// where the organ sits on the receptacle.
    pub midrib: [DVec2; 4],
    /// Bézier control values of the half width along the midrib parameter:
    /// the arc length from the midrib to either margin.
    pub half_width: [f64; 4],
    /// How far the midrib is pushed along the profile's outward normal:
    /// organs of an outer whorl share the inner whorl's profile with a
    /// positive offset, so their surfaces stay apart everywhere.
    pub offset: f64,
    /// How much further from the axis the `u = 1` (left) margin lies than the
    /// `u = 0` (right) margin: positive for a contorted corolla in which each
    /// organ's right side is beneath its right-hand neighbour.
    pub contortion: f64,
    /// Rounds the top: the margins end this fraction of the midrib parameter
    /// before the midrib does (0 for a pointed tip, where the half width
    /// should come to 0).
    pub top_rounding: f64,
}

impl RingOrgan {
    /// The midrib point (ρ, y) and the unit outward normal of the profile at
    /// parameter `t`, offset applied.
    fn profile(&self, t: f64) -> (DVec2, DVec2) {
        let curve = BezierCurve::new(self.midrib.map(|p| p.extend(0.0)));
        let point = curve.at(t).truncate();
        let h = 1e-4;
        let (a, b) = ((t - h).max(0.0), (t + h).min(1.0));
        let tangent = (curve.at(b) - curve.at(a)).truncate();
        // The axis is on the left of the profile as it climbs from the base
        // to the tip: the right-hand normal points away from it.
        let outward = DVec2::new(tangent.y, -tangent.x).normalize_or(DVec2::X);
        (point + self.offset * outward, outward)
    }

    /// The (ρ, y) of the base point: where the organ sits.
    pub fn base_in_meridian(&self) -> DVec2 {
        self.profile(0.0).0
    }

    /// The half width at midrib parameter `t`.
    fn half_width_at(&self, t: f64) -> f64 {
        let b = bernstein3(t);
        (0..4).map(|k| b[k] * self.half_width[k]).sum()
    }

    /// The point at `point_in_uv` in the flower frame for an organ at
    /// azimuth 0 (centred on +Z).
    pub fn point_in_flower(&self, point_in_uv: DVec2) -> DVec3 {
        let across = (0.5 - point_in_uv.x) * 2.0; // +1 at u = 0 (right), −1 at u = 1
        let t = point_in_uv.y * (1.0 - self.top_rounding * across * across);
        let (midrib, _) = self.profile(t);
        let rho_midrib = midrib.x.max(1e-6);
        let angle = across * self.half_width_at(t) / rho_midrib;
        let rho = rho_midrib - 0.5 * self.contortion * across;
        DVec3::new(rho * angle.sin(), midrib.y, rho * angle.cos())
    }

    /// Half the angle about the axis the organ covers at its widest, in
    /// degrees (sampled over the surface).
    pub fn half_span_deg(&self) -> f64 {
        let mut widest: f64 = 0.0;
        for j in 0..=100 {
            for i in 0..=20 {
                let uv = DVec2::new(f64::from(i) / 20.0, f64::from(j) / 100.0);
                let p = self.point_in_flower(uv);
                widest = widest.max(p.x.atan2(p.z).abs());
            }
        }
        widest.to_degrees()
    }

    /// Remeshes the organ at mean edge `target_edge` (template frame).
    pub fn build(&self, target_edge: f64) -> Result<Mesh, BudError> {
        Ok(build_organ(self, &RemeshOptions::new(target_edge))?.mesh)
    }
}

impl Surface for RingOrgan {
    fn point(&self, point_in_uv: DVec2) -> DVec3 {
        let base = self.base_in_meridian();
        self.point_in_flower(point_in_uv) - DVec3::new(0.0, base.y, base.x)
    }
}

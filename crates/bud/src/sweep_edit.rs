//! Editing a PDE sweep petal (the app's PDE petal editor): a starting
//! sweep, and moving one control point of a margin or an across-tangent
//! with its mirror image about the midrib.
//!
//! A sweep is symmetric about the midrib plane `x = 0` when
//! `S(1 − u, v)` is the mirror image of `S(u, v)`: the margins are mirror
//! images (`C1 = M C0`, `M` the mirror `x → −x`) and, because `u` runs the
//! other way on the mirrored side, the across-tangents are mirror images
//! negated (`T1 = −M T0`).

use glam::DVec3;

use crate::net::mirrored;
use crate::surface::{BezierCurve, PdeSweep};

/// One of the four curves of a [`PdeSweep`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SweepCurve {
    /// The margin at `u = 0`.
    Margin0,
    /// The margin at `u = 1`.
    Margin1,
    /// The across-tangent `dS/du` along the margin at `u = 0`.
    Tangent0,
    /// The across-tangent along the margin at `u = 1`.
    Tangent1,
}

impl SweepCurve {
    /// All four, margins first.
    pub const ALL: [SweepCurve; 4] = [
        SweepCurve::Margin0,
        SweepCurve::Margin1,
        SweepCurve::Tangent0,
        SweepCurve::Tangent1,
    ];

    /// The curve on the other side of the midrib.
    pub fn mirror(self) -> SweepCurve {
        match self {
            SweepCurve::Margin0 => SweepCurve::Margin1,
            SweepCurve::Margin1 => SweepCurve::Margin0,
            SweepCurve::Tangent0 => SweepCurve::Tangent1,
            SweepCurve::Tangent1 => SweepCurve::Tangent0,
        }
    }

    /// Whether it holds points (a margin) rather than vectors (a tangent).
    pub fn is_margin(self) -> bool {
        matches!(self, SweepCurve::Margin0 | SweepCurve::Margin1)
    }

    /// The margin a tangent belongs to (a margin: itself).
    pub fn margin(self) -> SweepCurve {
        match self {
            SweepCurve::Margin0 | SweepCurve::Tangent0 => SweepCurve::Margin0,
            SweepCurve::Margin1 | SweepCurve::Tangent1 => SweepCurve::Margin1,
        }
    }
}

impl PdeSweep {
    /// A new petal's sweep in the template frame: 20 long from the base at
    /// the origin along +Y, 2.4 wide at the base, widest (about 10) a
    /// little below the middle, coming to a point at the tip, its margins
    /// cupped towards the inner side (−Z) and the tip bent out a little;
    /// symmetric about the midrib, the cubic generator (`k_s/k_b = 0`).
    pub fn petal() -> PdeSweep {
        crate::examples::pde_petal(
            [0.0, 7.0, 15.0, 20.0],
            [1.2, 6.0, 5.0, 0.0],
            [0.0, 0.3, 0.8, 1.2],
            [0.3, 1.2, 1.2, 0.0],
        )
    }

    /// The curve `which`.
    pub fn curve(&self, which: SweepCurve) -> &BezierCurve {
        match which {
            SweepCurve::Margin0 => &self.curve0,
            SweepCurve::Margin1 => &self.curve1,
            SweepCurve::Tangent0 => &self.tangent0,
            SweepCurve::Tangent1 => &self.tangent1,
        }
    }

    /// The sweep with control point `index` of curve `which` set to
    /// `value` and, when `symmetric`, the mirrored curve's same control
    /// point set to the mirror image (see the module notes). Indices past
    /// 3 leave the sweep as it is.
    pub fn with_point(
        &self,
        which: SweepCurve,
        index: usize,
        value: DVec3,
        symmetric: bool,
    ) -> PdeSweep {
        if index > 3 {
            return *self;
        }
        let mut curves = SweepCurve::ALL.map(|c| *self.curve(c));
        curves[which as usize].control[index] = value;
        if symmetric {
            let image = if which.is_margin() {
                mirrored(value)
            } else {
                -mirrored(value)
            };
            curves[which.mirror() as usize].control[index] = image;
        }
        let [c0, c1, t0, t1] = curves;
        PdeSweep::new(c0, c1, t0, t1, self.stretch_to_bend())
    }

    /// The sweep with another `k_s/k_b` (clamped as [`PdeSweep::new`] does).
    pub fn with_stretch_to_bend(&self, stretch_to_bend: f64) -> PdeSweep {
        PdeSweep::new(
            self.curve0,
            self.curve1,
            self.tangent0,
            self.tangent1,
            stretch_to_bend,
        )
    }

    /// Whether the sweep is symmetric about the midrib plane within
    /// `tolerance` (see the module notes).
    pub fn is_symmetric(&self, tolerance: f64) -> bool {
        (0..4).all(|k| {
            self.curve1.control[k].distance(mirrored(self.curve0.control[k])) <= tolerance
                && self.tangent1.control[k].distance(-mirrored(self.tangent0.control[k]))
                    <= tolerance
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{RemeshOptions, Surface, build_organ};
    use glam::DVec2;

    #[test]
    fn the_new_pde_petal_is_symmetric_pointed_and_meshes_with_its_inner_side_to_minus_z() {
        let sweep = PdeSweep::petal();
        assert!(sweep.is_symmetric(0.0));
        // Mirror symmetry of the surface itself.
        for (u, v) in [(0.1, 0.2), (0.3, 0.7), (0.45, 0.95)] {
            let a = sweep.point(DVec2::new(u, v));
            let b = sweep.point(DVec2::new(1.0 - u, v));
            assert!(a.distance(mirrored(b)) < 1e-12, "{a} {b}");
        }
        assert!(sweep.point(DVec2::new(0.5, 0.0)).length() < 1e-12);
        let tip = sweep.point(DVec2::new(0.5, 1.0));
        assert!(tip.distance(DVec3::new(0.0, 20.0, 1.2)) < 1e-12, "{tip}");
        assert!(sweep.point(DVec2::new(0.0, 1.0)).distance(tip) < 1e-12);
        let bud = build_organ(&sweep, &RemeshOptions::new(1.2)).unwrap();
        assert!(bud.quality.min_angle_deg >= 20.0, "{:?}", bud.quality);
        assert_eq!(crate::inner_side_faces_minus_z(&bud.mesh), Some(true));
    }

    #[test]
    fn a_moved_margin_or_tangent_point_takes_its_mirror_image_along_when_symmetric() {
        let sweep = PdeSweep::petal();
        let moved = sweep.with_point(SweepCurve::Margin0, 2, DVec3::new(6.0, 14.0, -2.0), true);
        assert_eq!(moved.curve0.control[2], DVec3::new(6.0, 14.0, -2.0));
        assert_eq!(moved.curve1.control[2], DVec3::new(-6.0, 14.0, -2.0));
        assert!(moved.is_symmetric(0.0));
        let turned = sweep.with_point(SweepCurve::Tangent1, 1, DVec3::new(-9.0, 1.0, -3.0), true);
        assert_eq!(turned.tangent0.control[1], DVec3::new(-9.0, -1.0, 3.0));
        assert!(turned.is_symmetric(0.0));
        // Alone: only that point, and the k_s/k_b kept.
        let alone = sweep.with_stretch_to_bend(4.0).with_point(
            SweepCurve::Margin1,
            0,
            DVec3::new(-2.0, 0.5, 0.0),
            false,
        );
        assert_eq!(alone.curve0, sweep.curve0);
        assert!(!alone.is_symmetric(1e-9));
        assert_eq!(alone.stretch_to_bend(), 4.0);
        assert_eq!(
            sweep.with_point(SweepCurve::Margin0, 4, DVec3::ONE, true),
            sweep
        );
    }
}

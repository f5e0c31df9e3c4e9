//! Editing a petal's Bézier control net (the app's Bézier petal editor):
//! a starting net, and moving one control point with its mirror image
//! about the midrib.
//!
//! By the UV convention (ARCHITECTURE.md) `u` runs across the organ with
//! the midrib at `u = 0.5`: in a net, column `i` and column `3 - i` are
//! mirror images of each other about the midrib plane `x = 0` (the template
//! frame's symmetry plane: the organ grows along +Y, its inner side faces
//! −Z), and rows run from the base (`j = 0`) to the tip (`j = 3`).

use glam::DVec3;

use crate::BezierPatch;

/// The control point mirrored about the midrib plane `x = 0`.
pub fn mirrored(point: DVec3) -> DVec3 {
    DVec3::new(-point.x, point.y, point.z)
}

impl BezierPatch {
    /// A new petal's net in the template frame: 20 long from the base at
    /// the origin along +Y, 2.4 wide at the base, widest (about 8) a little
    /// above the middle, rounded at the tip, its margins cupped towards the
    /// inner side (−Z); symmetric about the midrib. At the simple petal's
    /// thickness (0.1) it is 200 thicknesses long, like the paper's petals.
    pub fn petal() -> BezierPatch {
        let row = |y: f64, outer: f64, inner: f64, cup: f64, lift: f64| {
            [
                DVec3::new(-outer, y, lift - cup),
                DVec3::new(-inner, y, lift),
                DVec3::new(inner, y, lift),
                DVec3::new(outer, y, lift - cup),
            ]
        };
        BezierPatch::new([
            row(0.0, 1.2, 0.4, 0.3, 0.0),
            row(7.0, 5.0, 1.7, 1.2, 0.3),
            row(15.0, 5.0, 1.7, 1.2, 0.8),
            row(20.0, 1.2, 0.4, 0.3, 1.2),
        ])
    }

    /// The net with control point `(row, column)` moved to `point` and,
    /// when `symmetric`, its mirror image in column `3 - column` moved to
    /// the mirrored point (a point on the midrib plane stays on it only if
    /// it is put there). Rows and columns past 3 leave the net as it is.
    pub fn with_point(&self, row: usize, column: usize, point: DVec3, symmetric: bool) -> Self {
        let mut net = *self;
        if row > 3 || column > 3 {
            return net;
        }
        net.control[row][column] = point;
        if symmetric {
            net.control[row][3 - column] = mirrored(point);
        }
        net
    }

    /// Whether every column is the mirror image of column `3 - column`
    /// within `tolerance`.
    pub fn is_symmetric(&self, tolerance: f64) -> bool {
        self.control
            .iter()
            .all(|row| (0..4).all(|i| row[i].distance(mirrored(row[3 - i])) <= tolerance))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{RemeshOptions, Surface, build_organ};
    use glam::DVec2;

    #[test]
    fn the_new_petal_is_symmetric_and_meshes_with_its_inner_side_to_minus_z() {
        let net = BezierPatch::petal();
        assert!(net.is_symmetric(0.0));
        // The midrib (u = 0.5) lies in the symmetry plane, base at the
        // origin, tip 20 along +Y.
        let base = net.point(DVec2::new(0.5, 0.0));
        assert!(
            base.x.abs() < 1e-12 && base.y == 0.0 && base.z.abs() < 0.1,
            "{base}"
        );
        let tip = net.point(DVec2::new(0.5, 1.0));
        assert!(tip.x.abs() < 1e-12 && (tip.y - 20.0).abs() < 1e-12);
        let bud = build_organ(&net, &RemeshOptions::new(1.2)).unwrap();
        assert!(bud.quality.min_angle_deg >= 20.0);
        assert_eq!(crate::inner_side_faces_minus_z(&bud.mesh), Some(true));
        // UVs by convention: the midrib at u = 0.5 lies at x = 0.
        for (p, uv) in bud.mesh.positions.iter().zip(&bud.mesh.uvs) {
            if (uv.x - 0.5).abs() < 1e-9 {
                assert!(p.x.abs() < 1e-6, "{p} at {uv}");
            }
        }
    }

    #[test]
    fn a_moved_point_takes_its_mirror_image_along_when_symmetric() {
        let net = BezierPatch::petal();
        let moved = net.with_point(2, 3, DVec3::new(6.5, 16.0, -2.0), true);
        assert_eq!(moved.control[2][3], DVec3::new(6.5, 16.0, -2.0));
        assert_eq!(moved.control[2][0], DVec3::new(-6.5, 16.0, -2.0));
        assert!(moved.is_symmetric(0.0));
        // The rest of the net stays.
        for j in 0..4 {
            for i in 0..4 {
                if j != 2 || (i != 0 && i != 3) {
                    assert_eq!(moved.control[j][i], net.control[j][i]);
                }
            }
        }
        // Not symmetric: only that point.
        let alone = net.with_point(1, 1, DVec3::new(-2.0, 7.0, 0.5), false);
        assert_eq!(alone.control[1][1], DVec3::new(-2.0, 7.0, 0.5));
        assert_eq!(alone.control[1][2], net.control[1][2]);
        assert!(!alone.is_symmetric(1e-9));
        // Past the net: unchanged.
        assert_eq!(net.with_point(4, 0, DVec3::ONE, true), net);
    }
}

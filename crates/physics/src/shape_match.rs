//! Shape matching (Müller et al. 2005): the rigid transform that best maps
//! a set of points onto target points in the least-squares sense.
//!
//! The rotation is extracted from the covariance matrix with the iterative
//! method of Müller et al. 2016 ("A robust method to extract the rotational
//! part of deformations"): it needs no SVD, is deterministic, and converges
//! from a warm start in a few iterations. Written here because glam has no
//! SVD and the method is twenty lines.

use glam::{DMat3, DQuat, DVec3};

use crate::elastic::outer;

/// A rigid motion `x -> rotation * (x - from_centre) + to_centre`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidTransform {
    /// The rotation about `from_centre` (unit quaternion).
    pub rotation: DQuat,
    /// The centroid of the points moved (the rotation's pivot).
    pub from_centre: DVec3,
    /// Where `from_centre` goes: the centroid of the target points.
    pub to_centre: DVec3,
}

impl RigidTransform {
    /// The point `x` moved by this transform.
    pub fn apply(&self, x: DVec3) -> DVec3 {
        self.rotation * (x - self.from_centre) + self.to_centre
    }
}

/// The rigid transform that moves `current` points onto `target` points as
/// closely as possible. `warm_start` is a rotation near the answer (the
/// identity when unknown).
pub fn match_shape(current: &[DVec3], target: &[DVec3], warm_start: DQuat) -> RigidTransform {
    let n = current.len().max(1) as f64;
    let from_centre = current.iter().sum::<DVec3>() / n;
    let to_centre = target.iter().sum::<DVec3>() / n;
    // A = sum (q - cq)(p - cp)^T maps the current frame onto the target.
    let mut a = DMat3::ZERO;
    for (p, q) in current.iter().zip(target) {
        a += outer(*q - to_centre, *p - from_centre);
    }
    RigidTransform {
        rotation: extract_rotation(&a, warm_start),
        from_centre,
        to_centre,
    }
}

/// The rotation `R` closest to `a` (maximising `trace(R^T a)`).
pub fn extract_rotation(a: &DMat3, warm_start: DQuat) -> DQuat {
    let mut q = warm_start.normalize();
    for _ in 0..100 {
        let r = DMat3::from_quat(q);
        let numerator =
            r.x_axis.cross(a.x_axis) + r.y_axis.cross(a.y_axis) + r.z_axis.cross(a.z_axis);
        let denominator =
            (r.x_axis.dot(a.x_axis) + r.y_axis.dot(a.y_axis) + r.z_axis.dot(a.z_axis)).abs()
                + 1e-300;
        let omega = numerator / denominator;
        let angle = omega.length();
        if angle < 1e-15 {
            break;
        }
        q = (DQuat::from_axis_angle(omega / angle, angle) * q).normalize();
    }
    q
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_a_known_rigid_motion() {
        let points = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.2, 0.0),
            DVec3::new(0.3, 1.0, 0.1),
            DVec3::new(-0.5, 0.4, 0.7),
        ];
        let rotation = DQuat::from_euler(glam::EulerRot::XYZ, 0.4, -1.2, 2.5);
        let shift = DVec3::new(3.0, -1.0, 0.5);
        let target: Vec<DVec3> = points.iter().map(|p| rotation * *p + shift).collect();
        let t = match_shape(&points, &target, DQuat::IDENTITY);
        for (p, q) in points.iter().zip(&target) {
            assert!((t.apply(*p) - *q).length() < 1e-10);
        }
    }

    #[test]
    fn flat_point_sets_still_give_a_proper_rotation() {
        let points = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)];
        let rotation = DQuat::from_axis_angle(DVec3::new(1.0, 1.0, 0.0).normalize(), 0.8);
        let target: Vec<DVec3> = points.iter().map(|p| rotation * *p).collect();
        let t = match_shape(&points, &target, DQuat::IDENTITY);
        assert!(t.rotation.angle_between(rotation) < 1e-8);
    }
}

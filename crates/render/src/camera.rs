use glam::dcamera::rh::{proj::directx, view};
use glam::{DMat4, DVec2, DVec3, DVec4, Mat4};

use crate::orbit::orbit_directions;

/// A perspective camera looking from `eye` at `target`.
///
/// `fov_y_deg` is the field of view across the *shorter* side of the
/// image, so a framed subject stays in view whatever the aspect ratio.
/// The projection has reversed depth with an infinitely far plane; the near
/// plane is [`Camera::near_clip`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Where the camera is, in world space.
    pub eye: DVec3,
    /// The point it looks at, in world space.
    pub target: DVec3,
    /// Which way is up in the image (need not be perpendicular to the view).
    pub up: DVec3,
    /// Field of view across the image's shorter side, in degrees.
    pub fov_y_deg: f64,
}

/// How much wider than the framed box the view is (1 = touching).
const FRAMING_MARGIN: f64 = 1.08;

impl Camera {
    /// The camera the viewport's `F` frames `points_in_world` with
    /// ([`crate::OrbitCamera::frame_points`]): from `azimuth_deg` and
    /// `elevation_deg`, at the centre of their box, as close as keeps every
    /// point within `fill` of the way from the image's centre to the middle
    /// of its shorter side (0.8: the flower fills most of the picture). The
    /// points themselves are framed, not their box, whose corners lie far
    /// outside a round flower. `None` without points.
    pub fn framing_points(
        points_in_world: &[DVec3],
        azimuth_deg: f64,
        elevation_deg: f64,
        fill: f64,
    ) -> Option<Camera> {
        if points_in_world.is_empty() {
            return None;
        }
        let mut orbit = crate::OrbitCamera {
            azimuth_deg,
            elevation_deg,
            ..crate::OrbitCamera::default()
        };
        orbit.frame_points(points_in_world, fill);
        Some(orbit.camera())
    }

    /// A camera that fits the box `[bounds_min, bounds_max]` with a 30°
    /// field of view, looking at the box centre from `azimuth_deg` around
    /// +Y (0 = from +Z, 90 = from +X) and `elevation_deg` above the XZ plane
    /// (90 = from straight above). All eight box corners end up inside the
    /// image (for any aspect ratio) with a small margin.
    pub fn framing(
        bounds_min: DVec3,
        bounds_max: DVec3,
        azimuth_deg: f64,
        elevation_deg: f64,
    ) -> Camera {
        let fov_y_deg: f64 = 30.0;
        let target = 0.5 * (bounds_min + bounds_max);
        let (towards_eye, up) = orbit_directions(azimuth_deg, elevation_deg);
        let right = up.cross(towards_eye);
        // A corner at height `a` (along towards_eye) and offsets `x`, `y`
        // across the view is inside when max(|x|, |y|) <= tan(fov/2) (d - a),
        // d being the eye-target distance.
        let tan_half = (0.5 * fov_y_deg.to_radians()).tan() / FRAMING_MARGIN;
        let half_extent = 0.5 * (bounds_max - bounds_min).abs();
        let mut distance: f64 = 1e-6;
        for i in 0..8 {
            let sign = |bit: usize| if i & bit == 0 { -1.0 } else { 1.0 };
            let corner = DVec3::new(sign(1), sign(2), sign(4)) * half_extent;
            let across = corner.dot(right).abs().max(corner.dot(up).abs());
            distance = distance.max(corner.dot(towards_eye) + across / tan_half);
        }
        let radius = half_extent.length();
        // Keep the eye outside the box.
        distance = distance.max(1.01 * radius);
        Camera {
            eye: target + distance * towards_eye,
            target,
            up,
            fov_y_deg,
        }
    }

    /// The near clipping distance: a thousandth of the eye–target distance
    /// (reversed depth keeps precision far away).
    pub fn near_clip(&self) -> f64 {
        (1e-3 * self.eye.distance(self.target)).max(1e-9)
    }

    /// The unit vector towards the key light: from near the eye, offset
    /// up and to the left in the image so that curved surfaces show shading
    /// even when seen head-on.
    pub fn key_light_direction(&self) -> DVec3 {
        let towards_eye = (self.eye - self.target).normalize_or(DVec3::Z);
        let right = self.up.cross(towards_eye).normalize_or_zero();
        let up = towards_eye.cross(right);
        (towards_eye + 0.45 * up - 0.3 * right).normalize_or(towards_eye)
    }

    /// The vertical field of view in radians for an image of `aspect`
    /// (width / height).
    pub fn vertical_fov(&self, aspect: f32) -> f64 {
        let shorter_side_fov = self.fov_y_deg.to_radians().clamp(1e-4, 3.1);
        let aspect = f64::from(aspect).max(1e-6);
        if aspect >= 1.0 {
            shorter_side_fov
        } else {
            2.0 * ((0.5 * shorter_side_fov).tan() / aspect).atan()
        }
    }

    /// The matrix from world space to clip space (wgpu/Direct3D conventions:
    /// NDC y up, z in `[0, 1]`, here reversed: 1 at the near plane, 0 at
    /// infinity).
    pub fn view_projection(&self, aspect: f32) -> Mat4 {
        let view = view::look_at_mat4(self.eye, self.target, self.up);
        let projection = directx::perspective_infinite_reverse(
            self.vertical_fov(aspect),
            f64::from(aspect).max(1e-6),
            self.near_clip(),
        );
        (projection * view).as_mat4()
    }

    /// The ray from the eye through the image point `ndc` (x right, y up,
    /// both in `[-1, 1]`) of an image of `aspect` (width / height): its
    /// origin (the eye) and unit direction.
    pub fn ray_through(&self, aspect: f32, ndc: DVec2) -> (DVec3, DVec3) {
        let inverse: DMat4 = self.view_projection(aspect).as_dmat4().inverse();
        let on_near = inverse * DVec4::new(ndc.x, ndc.y, 1.0, 1.0);
        let further = inverse * DVec4::new(ndc.x, ndc.y, 0.5, 1.0);
        let a = on_near.truncate() / on_near.w;
        let b = further.truncate() / further.w;
        (self.eye, (b - a).normalize_or(DVec3::NEG_Z))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn to_ndc(camera: &Camera, aspect: f32, point_in_world: DVec3) -> DVec3 {
        let clip = camera.view_projection(aspect).as_dmat4() * point_in_world.extend(1.0);
        assert!(clip.w > 0.0, "point behind the camera");
        (clip / clip.w).truncate()
    }

    #[test]
    fn framing_keeps_every_box_corner_inside_the_image() {
        let (lo, hi) = (DVec3::new(-1.0, 0.0, -2.0), DVec3::new(3.0, 5.0, 1.0));
        for (az, el) in [(0.0, 0.0), (35.0, 30.0), (200.0, -40.0), (0.0, 90.0)] {
            let camera = Camera::framing(lo, hi, az, el);
            for aspect in [1.0_f32, 2.0, 0.5] {
                for i in 0..8 {
                    let corner = DVec3::new(
                        if i & 1 == 0 { lo.x } else { hi.x },
                        if i & 2 == 0 { lo.y } else { hi.y },
                        if i & 4 == 0 { lo.z } else { hi.z },
                    );
                    let ndc = to_ndc(&camera, aspect, corner);
                    assert!(
                        ndc.x.abs() < 1.0 && ndc.y.abs() < 1.0 && ndc.z > 0.0 && ndc.z < 1.0,
                        "corner {corner} at az {az} el {el} aspect {aspect}: ndc {ndc}"
                    );
                }
            }
        }
    }

    #[test]
    fn target_projects_to_centre_and_depth_is_reversed() {
        let camera = Camera::framing(DVec3::splat(-1.0), DVec3::splat(1.0), 30.0, 20.0);
        let centre = to_ndc(&camera, 1.5, DVec3::ZERO);
        assert!(centre.truncate().length() < 1e-5, "{centre}");
        let towards_eye = (camera.eye - camera.target).normalize();
        let nearer = to_ndc(&camera, 1.5, 0.5 * towards_eye);
        assert!(nearer.z > centre.z, "nearer {nearer} centre {centre}");
        let at_near_plane = camera.eye - camera.near_clip() * towards_eye;
        assert!((to_ndc(&camera, 1.5, at_near_plane).z - 1.0).abs() < 1e-4);
    }

    #[test]
    fn framing_azimuth_zero_looks_from_plus_z_with_plus_y_up() {
        let camera = Camera::framing(DVec3::splat(-1.0), DVec3::splat(1.0), 0.0, 0.0);
        assert!(camera.eye.z > 1.0 && camera.eye.x.abs() < 1e-12);
        // +Y in the world is up in the image, +X is right.
        let above = to_ndc(&camera, 1.0, DVec3::Y * 0.5);
        let right = to_ndc(&camera, 1.0, DVec3::X * 0.5);
        assert!(above.y > 0.1 && above.x.abs() < 1e-6, "{above}");
        assert!(right.x > 0.1 && right.y.abs() < 1e-6, "{right}");
    }

    #[test]
    fn rays_leave_the_eye_towards_the_target_and_the_image_edge_at_half_the_field_of_view() {
        let camera = Camera {
            eye: DVec3::new(0.0, 0.0, 10.0),
            target: DVec3::ZERO,
            up: DVec3::Y,
            fov_y_deg: 30.0,
        };
        let (origin, direction) = camera.ray_through(1.5, DVec2::ZERO);
        assert_eq!(origin, camera.eye);
        assert!((direction - DVec3::NEG_Z).length() < 1e-9, "{direction}");
        // A wide image: the fov is vertical, so the top edge is 15° up.
        let (_, up_edge) = camera.ray_through(1.5, DVec2::new(0.0, 1.0));
        let angle = up_edge.angle_between(DVec3::NEG_Z).to_degrees();
        assert!((angle - 15.0).abs() < 1e-6, "{angle}");
        assert!(up_edge.y > 0.0);
        // Round trip: the ray's points project back onto the same image point.
        let ndc = DVec2::new(0.3, -0.6);
        let (origin, direction) = camera.ray_through(1.5, ndc);
        let back = to_ndc(&camera, 1.5, origin + 7.0 * direction);
        assert!((back.truncate() - ndc).length() < 1e-9, "{back}");
    }
}

//! An orbit camera: a target, a distance and two angles, the camera a
//! viewer turns with the mouse. [`OrbitCamera::camera`] gives the
//! [`Camera`] the renderer draws with.

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

use crate::Camera;

/// Field of view of an orbit camera across the image's shorter side.
pub const ORBIT_FOV_DEG: f64 = 30.0;

/// A camera on a sphere around `target`, looking at it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OrbitCamera {
    /// The point looked at and orbited, in world space.
    pub target: DVec3,
    /// From the target to the eye, in world units.
    pub distance: f64,
    /// Around +Y, 0 = looking from +Z, 90 = from +X.
    pub azimuth_deg: f64,
    /// Above the XZ plane, within ±89°.
    pub elevation_deg: f64,
}

impl Default for OrbitCamera {
    fn default() -> Self {
        OrbitCamera {
            target: DVec3::new(0.0, 15.0, 0.0),
            distance: 90.0,
            azimuth_deg: 30.0,
            elevation_deg: 25.0,
        }
    }
}

/// The unit vector from the target towards the eye and the camera's up
/// vector (the derivative of the first with respect to elevation: always
/// perpendicular to the view, +Y-ish except from the poles) for a view
/// from `azimuth_deg` around +Y and `elevation_deg` above the XZ plane.
pub(crate) fn orbit_directions(azimuth_deg: f64, elevation_deg: f64) -> (DVec3, DVec3) {
    let (az, el) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
    let towards_eye = DVec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
    let up = DVec3::new(-el.sin() * az.sin(), el.cos(), -el.sin() * az.cos());
    (towards_eye, up)
}

impl OrbitCamera {
    /// The camera to render with.
    pub fn camera(&self) -> Camera {
        let (towards_eye, up) = orbit_directions(self.azimuth_deg, self.elevation_deg);
        Camera {
            eye: self.target + self.distance * towards_eye,
            target: self.target,
            up,
            fov_y_deg: ORBIT_FOV_DEG,
        }
    }

    /// Looks at the box `bounds_in_world` (min, max) from the current
    /// direction so that all of it is in view.
    pub fn frame(&mut self, bounds_in_world: (DVec3, DVec3)) {
        let framed = Camera::framing(
            bounds_in_world.0,
            bounds_in_world.1,
            self.azimuth_deg,
            self.elevation_deg,
        );
        self.target = framed.target;
        self.distance = framed.eye.distance(framed.target).max(1e-3);
    }

    /// Looks at `points_in_world` from the current direction, at the
    /// centre of their box, from the distance at which the farthest of
    /// them from the view's axis is at `fill` of the way from the image's
    /// centre to the middle of its shorter side (0.8: the points fill about
    /// 80 % of the shorter side when they are symmetric about the
    /// centre). Points behind the eye cannot happen: the eye stays beyond
    /// every point. Does nothing without points.
    pub fn frame_points(&mut self, points_in_world: &[DVec3], fill: f64) {
        let Some(first) = points_in_world.first() else {
            return;
        };
        let (lo, hi) = points_in_world
            .iter()
            .fold((*first, *first), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        let target = 0.5 * (lo + hi);
        let (towards_eye, up) = orbit_directions(self.azimuth_deg, self.elevation_deg);
        let right = up.cross(towards_eye);
        let tan_half = (0.5 * ORBIT_FOV_DEG.to_radians()).tan() * fill.clamp(0.05, 1.0);
        let radius = 0.5 * (hi - lo).length();
        let mut distance = 1.01 * radius.max(1e-6);
        for p in points_in_world {
            let offset = *p - target;
            let across = offset.dot(right).abs().max(offset.dot(up).abs());
            distance = distance.max(offset.dot(towards_eye) + across / tan_half);
        }
        self.target = target;
        self.distance = distance.clamp(1e-3, 1e6);
    }

    /// How far out the points reach in the image, as a fraction of the way
    /// from its centre to the middle of its shorter side (1 = touching it;
    /// the image's longer side reaches further). Points behind the eye
    /// count as infinitely far out.
    pub fn reach_in_image(&self, points_in_world: &[DVec3]) -> f64 {
        let camera = self.camera();
        let (towards_eye, up) = orbit_directions(self.azimuth_deg, self.elevation_deg);
        let right = up.cross(towards_eye);
        let tan_half = (0.5 * ORBIT_FOV_DEG.to_radians()).tan();
        points_in_world
            .iter()
            .map(|p| {
                let offset = *p - camera.eye;
                let depth = -offset.dot(towards_eye);
                if depth <= 0.0 {
                    return f64::INFINITY;
                }
                offset.dot(right).abs().max(offset.dot(up).abs()) / (depth * tan_half)
            })
            .fold(0.0, f64::max)
    }

    /// Turns the camera by a drag of `drag_in_points` (x right, y down):
    /// 0.4° per point, elevation kept within ±89°.
    pub fn orbit(&mut self, drag_in_points: DVec2) {
        self.azimuth_deg = (self.azimuth_deg - 0.4 * drag_in_points.x) % 360.0;
        self.elevation_deg = (self.elevation_deg + 0.4 * drag_in_points.y).clamp(-89.0, 89.0);
    }

    /// Moves the target with the image: a drag of `drag_in_points` (x
    /// right, y down) over a view `height_in_points` tall moves the point
    /// under the pointer with it (at the target's depth).
    pub fn pan(&mut self, drag_in_points: DVec2, height_in_points: f64) {
        let (towards_eye, up) = orbit_directions(self.azimuth_deg, self.elevation_deg);
        let right = up.cross(towards_eye).normalize_or_zero();
        let world_per_point = 2.0 * self.distance * (0.5 * ORBIT_FOV_DEG.to_radians()).tan()
            / height_in_points.max(1.0);
        self.target += world_per_point * (-drag_in_points.x * right + drag_in_points.y * up);
    }

    /// Moves closer by `factor` (> 1 closer, < 1 further away).
    pub fn zoom(&mut self, factor: f64) {
        self.distance = (self.distance / factor.max(1e-3)).clamp(1e-3, 1e6);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn framing_puts_the_whole_box_in_front_of_the_camera_and_zoom_divides_the_distance() {
        let mut orbit = OrbitCamera::default();
        orbit.frame((DVec3::new(-5.0, 0.0, -5.0), DVec3::new(5.0, 30.0, 5.0)));
        assert!((orbit.target - DVec3::new(0.0, 15.0, 0.0)).length() < 1e-9);
        assert!(orbit.distance > 30.0, "{}", orbit.distance);
        let before = orbit.distance;
        orbit.zoom(2.0);
        assert!((orbit.distance - before / 2.0).abs() < 1e-9);
    }

    #[test]
    fn framing_points_puts_the_farthest_at_the_asked_reach_from_any_direction() {
        // A tall bud-like cloud off the origin, not symmetric.
        let points: Vec<DVec3> = (0..200)
            .map(|i| {
                let t = f64::from(i) / 199.0;
                let angle = 7.0 * t;
                DVec3::new(
                    3.0 + 2.0 * angle.cos() * t,
                    10.0 + 30.0 * t,
                    -1.0 + angle.sin(),
                )
            })
            .collect();
        for (az, el) in [(30.0, 25.0), (0.0, 0.0), (-120.0, 70.0), (200.0, -40.0)] {
            let mut orbit = OrbitCamera {
                azimuth_deg: az,
                elevation_deg: el,
                ..OrbitCamera::default()
            };
            orbit.frame_points(&points, 0.8);
            let reach = orbit.reach_in_image(&points);
            assert!((reach - 0.8).abs() < 1e-9, "from ({az}, {el}): {reach}");
            // The projection agrees: the farthest point's NDC on a square
            // image is at 0.8.
            let clip = orbit.camera().view_projection(1.0);
            let ndc = points
                .iter()
                .map(|p| {
                    let c = clip * p.as_vec3().extend(1.0);
                    f64::from((c.x / c.w).abs().max((c.y / c.w).abs()))
                })
                .fold(0.0, f64::max);
            assert!((ndc - 0.8).abs() < 1e-4, "NDC reach {ndc}");
        }
        let mut orbit = OrbitCamera::default();
        orbit.frame_points(&[], 0.8);
        assert_eq!(orbit, OrbitCamera::default(), "no points, no change");
    }

    #[test]
    fn the_eye_is_on_the_sphere_and_up_is_perpendicular_to_the_view() {
        let orbit = OrbitCamera {
            target: DVec3::new(1.0, 2.0, 3.0),
            distance: 10.0,
            azimuth_deg: 90.0,
            elevation_deg: 0.0,
        };
        let camera = orbit.camera();
        // Azimuth 90°: looking from +X.
        assert!((camera.eye - DVec3::new(11.0, 2.0, 3.0)).length() < 1e-9);
        for (az, el) in [(0.0, 0.0), (30.0, 25.0), (-120.0, 80.0), (200.0, -60.0)] {
            let (towards_eye, up) = orbit_directions(az, el);
            assert!((towards_eye.length() - 1.0).abs() < 1e-12);
            assert!((up.length() - 1.0).abs() < 1e-12);
            assert!(towards_eye.dot(up).abs() < 1e-12);
        }
    }

    #[test]
    fn a_horizontal_drag_turns_about_y_and_elevation_stops_short_of_the_pole() {
        let mut orbit = OrbitCamera::default();
        let (az, el) = (orbit.azimuth_deg, orbit.elevation_deg);
        orbit.orbit(DVec2::new(10.0, 0.0));
        assert!((orbit.azimuth_deg - (az - 4.0)).abs() < 1e-12);
        assert_eq!(orbit.elevation_deg, el);
        orbit.orbit(DVec2::new(0.0, 1000.0));
        assert_eq!(orbit.elevation_deg, 89.0);
    }

    #[test]
    fn panning_by_the_view_height_moves_the_target_by_the_visible_height() {
        let mut orbit = OrbitCamera {
            target: DVec3::ZERO,
            distance: 10.0,
            azimuth_deg: 0.0,
            elevation_deg: 0.0,
        };
        // Looking from +Z with +Y up: dragging down by the whole view
        // height moves the target up by the height seen at its depth.
        orbit.pan(DVec2::new(0.0, 500.0), 500.0);
        let visible = 2.0 * 10.0 * (0.5 * ORBIT_FOV_DEG.to_radians()).tan();
        assert!((orbit.target - DVec3::new(0.0, visible, 0.0)).length() < 1e-9);
        // Dragging right moves the target left (-X), the image follows.
        orbit.target = DVec3::ZERO;
        orbit.pan(DVec2::new(100.0, 0.0), 500.0);
        assert!(orbit.target.x < 0.0 && orbit.target.y.abs() < 1e-12);
    }
}

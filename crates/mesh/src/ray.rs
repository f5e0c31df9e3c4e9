//! Ray casting on triangles (Möller & Trumbore 1997): which triangle a ray
//! meets first, how far along the ray and where in the triangle, for
//! picking organs and painting on them.

use glam::{DVec2, DVec3};

/// Where a ray meets a triangle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayHit {
    /// Index of the triangle in the list searched.
    pub triangle: usize,
    /// Distance along the ray, in units of its direction's length.
    pub distance: f64,
    /// Barycentric weights of the second and third corners (the first has
    /// `1 - u - v`).
    pub barycentric: DVec2,
}

impl RayHit {
    /// The hit point interpolated from per-corner values of its triangle
    /// (positions, UVs).
    pub fn interpolate<T>(&self, corners: [T; 3]) -> T
    where
        T: Copy
            + std::ops::Sub<Output = T>
            + std::ops::Add<Output = T>
            + std::ops::Mul<f64, Output = T>,
    {
        let [a, b, c] = corners;
        a + (b - a) * self.barycentric.x + (c - a) * self.barycentric.y
    }
}

/// Where the ray `origin + t direction` (t > 0) meets the triangle
/// `corners`: `(t, barycentric)`, or `None` when it misses, starts past it
/// or runs parallel to its plane. Both faces count.
pub fn ray_triangle(origin: DVec3, direction: DVec3, corners: [DVec3; 3]) -> Option<(f64, DVec2)> {
    let [p0, p1, p2] = corners;
    let (e1, e2) = (p1 - p0, p2 - p0);
    let h = direction.cross(e2);
    let det = e1.dot(h);
    if det.abs() < 1e-12 {
        return None;
    }
    let s = origin - p0;
    let u = s.dot(h) / det;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = direction.dot(q) / det;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) / det;
    (t > 0.0).then_some((t, DVec2::new(u, v)))
}

/// The first of `triangles` (indices into `positions`) the ray meets.
pub fn nearest_hit(
    origin: DVec3,
    direction: DVec3,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> Option<RayHit> {
    let mut best: Option<RayHit> = None;
    for (triangle, corners) in triangles.iter().enumerate() {
        let corners = corners.map(|i| positions[i as usize]);
        if let Some((distance, barycentric)) = ray_triangle(origin, direction, corners)
            && best.is_none_or(|b| distance < b.distance)
        {
            best = Some(RayHit {
                triangle,
                distance,
                barycentric,
            });
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The triangle (0,0,0), (2,0,0), (0,2,0) in the z = 0 plane.
    const TRIANGLE: [DVec3; 3] = [
        DVec3::ZERO,
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(0.0, 2.0, 0.0),
    ];

    #[test]
    fn a_ray_down_the_z_axis_hits_at_the_known_point_distance_and_weights() {
        // From (0.5, 0.25, 4) straight down: meets z = 0 at distance 4,
        // at x = 2u, y = 2v.
        let hit = ray_triangle(DVec3::new(0.5, 0.25, 4.0), DVec3::NEG_Z, TRIANGLE);
        let (t, weights) = hit.expect("hits");
        assert!((t - 4.0).abs() < 1e-12);
        assert!((weights - DVec2::new(0.25, 0.125)).length() < 1e-12);
        // Distance is in units of the direction's length; the back face hits too.
        let (t, _) = ray_triangle(
            DVec3::new(0.5, 0.25, -3.0),
            DVec3::new(0.0, 0.0, 2.0),
            TRIANGLE,
        )
        .expect("back face");
        assert!((t - 1.5).abs() < 1e-12);
    }

    #[test]
    fn misses_outside_behind_and_parallel() {
        // Beyond the hypotenuse x + y = 2.
        assert!(ray_triangle(DVec3::new(1.5, 1.5, 1.0), DVec3::NEG_Z, TRIANGLE).is_none());
        // Pointing away from the triangle.
        assert!(ray_triangle(DVec3::new(0.5, 0.5, 1.0), DVec3::Z, TRIANGLE).is_none());
        // In a plane parallel to the triangle.
        assert!(ray_triangle(DVec3::new(0.5, 0.5, 1.0), DVec3::X, TRIANGLE).is_none());
    }

    #[test]
    fn the_nearest_of_two_stacked_triangles_wins_and_interpolates_its_corners() {
        let positions: Vec<DVec3> = TRIANGLE
            .iter()
            .map(|p| *p + DVec3::new(0.0, 0.0, -1.0))
            .chain(TRIANGLE.iter().map(|p| *p + DVec3::new(0.0, 0.0, 1.0)))
            .collect();
        let triangles = [[0, 1, 2], [3, 4, 5]];
        let origin = DVec3::new(0.4, 0.6, 5.0);
        let hit = nearest_hit(origin, DVec3::NEG_Z, &positions, &triangles).expect("hits");
        assert_eq!(hit.triangle, 1);
        assert!((hit.distance - 4.0).abs() < 1e-12);
        let point = hit.interpolate([3, 4, 5].map(|i| positions[i]));
        assert!((point - DVec3::new(0.4, 0.6, 1.0)).length() < 1e-12);
        let uv = hit.interpolate([DVec2::ZERO, DVec2::X, DVec2::Y]);
        assert!((uv - DVec2::new(0.2, 0.3)).length() < 1e-12);
    }
}

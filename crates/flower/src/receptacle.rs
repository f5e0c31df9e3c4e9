//! The receptacle as a mesh, for pictures and exports: the organs sit on
//! it but it takes no part in the simulation.

use std::f64::consts::{PI, TAU};

use anthesis_mesh::Mesh;
use glam::{DVec2, DVec3};

use crate::Flower;

/// Segments around the axis.
const SEGMENTS: usize = 32;
/// Rings from the bottom pole to the top pole.
const RINGS: usize = 12;

/// The receptacle's colour in exports (linear RGBA): a stem green.
pub const RECEPTACLE_COLOUR: [f32; 4] = [0.36, 0.55, 0.24, 1.0];

/// The receptacle of `flower` ([`receptacle_mesh`]), sized to the ring its
/// organs sit on: with the organs' bases at most `ring` from the axis
/// (taken as at least 0.5), `1.1 * ring` wide and `0.7 * ring` deep.
pub fn receptacle_for(flower: &Flower) -> Mesh {
    let ring = flower
        .organs
        .iter()
        .map(|o| o.placement.position.x.hypot(o.placement.position.z))
        .fold(0.5, f64::max);
    receptacle_mesh(1.1 * ring, 0.7 * ring)
}

/// A small rounded receptacle in the world frame: a surface of revolution
/// about +Y, widest (`radius`) at `y = 0` where the organs sit, rounding
/// down to a point `height` below it (where a stem would join) and domed a
/// little (a fifth of `height`) above it. Closed, wound counter-clockwise
/// around the outward normal; UVs: `u` around the axis from azimuth 0 (+Z)
/// in the direction of increasing azimuth, `v` from the bottom (0) to the
/// top (1). The seam at `u = 0` / `u = 1` has its vertices twice, so the
/// mesh has a boundary there.
pub fn receptacle_mesh(radius: f64, height: f64) -> Mesh {
    let (radius, height) = (radius.abs(), height.abs());
    let dome = 0.2 * height;
    // The profile: angle from the bottom pole (0) to the top pole (π).
    let profile = |theta: f64| -> DVec2 {
        let r = radius * theta.sin();
        let y = if theta <= 0.5 * PI {
            -height * theta.cos()
        } else {
            -dome * theta.cos()
        };
        DVec2::new(r, y)
    };
    let mut mesh = Mesh::default();
    // The bottom pole, the rings in between (each with its seam vertex
    // twice), the top pole.
    mesh.positions.push(DVec3::new(0.0, -height, 0.0));
    mesh.uvs.push(DVec2::new(0.5, 0.0));
    let columns = SEGMENTS + 1;
    for ring in 1..RINGS {
        let v = ring as f64 / RINGS as f64;
        let p = profile(v * PI);
        for k in 0..columns {
            let u = k as f64 / SEGMENTS as f64;
            let a = u * TAU;
            mesh.positions
                .push(DVec3::new(p.x * a.sin(), p.y, p.x * a.cos()));
            mesh.uvs.push(DVec2::new(u, v));
        }
    }
    let top = mesh.positions.len() as u32;
    mesh.positions.push(DVec3::new(0.0, dome, 0.0));
    mesh.uvs.push(DVec2::new(0.5, 1.0));
    let index = |ring: usize, k: usize| (1 + (ring - 1) * columns + k) as u32;
    // Azimuth grows from +Z towards +X and v upwards, so (along u, along v)
    // is counter-clockwise seen from outside.
    for k in 0..SEGMENTS {
        mesh.triangles.push([0, index(1, k + 1), index(1, k)]);
        mesh.triangles
            .push([top, index(RINGS - 1, k), index(RINGS - 1, k + 1)]);
    }
    for ring in 1..RINGS - 1 {
        for k in 0..SEGMENTS {
            let (a, b) = (index(ring, k), index(ring, k + 1));
            let (c, d) = (index(ring + 1, k), index(ring + 1, k + 1));
            mesh.triangles.push([a, b, c]);
            mesh.triangles.push([b, d, c]);
        }
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn receptacle_is_widest_at_the_origin_plane_and_faces_outwards() {
        let mesh = receptacle_mesh(2.0, 1.5);
        let max_radius = mesh
            .positions
            .iter()
            .map(|p| DVec2::new(p.x, p.z).length())
            .fold(0.0, f64::max);
        assert!((max_radius - 2.0).abs() < 1e-9);
        let lowest = mesh.positions.iter().map(|p| p.y).fold(0.0, f64::min);
        let highest = mesh.positions.iter().map(|p| p.y).fold(0.0, f64::max);
        assert!((lowest + 1.5).abs() < 1e-9 && (highest - 0.3).abs() < 1e-9);
        // Every triangle's normal points away from the centre of the body.
        for t in 0..mesh.triangle_count() {
            let [a, b, c] = mesh.triangle_positions(t);
            let normal = (b - a).cross(c - a);
            let centre = (a + b + c) / 3.0;
            assert!(
                normal.dot(centre - DVec3::new(0.0, -0.5, 0.0)) > 0.0,
                "triangle {t}"
            );
            assert!(normal.length() > 1e-12, "triangle {t} is degenerate");
        }
        // A valid mesh: manifold, no degenerate or unused vertices.
        anthesis_mesh::validate(&mesh).expect("valid receptacle mesh");
    }

    #[test]
    fn the_receptacle_for_a_flower_reaches_just_past_its_organs() {
        let organ_at = |x: f64, z: f64| crate::Organ {
            name: format!("at {x} {z}"),
            template: 0,
            placement: crate::Placement {
                position: DVec3::new(x, 0.2, z),
                azimuth_deg: 0.0,
                joint_angle_deg: 0.0,
                orientation: glam::DQuat::IDENTITY,
            },
        };
        let mut flower = Flower {
            templates: Vec::new(),
            organs: vec![organ_at(1.0, 0.0), organ_at(-3.0, 4.0), organ_at(0.0, -4.5)],
            overlaps: Vec::new(),
            structure: None,
            parts: Vec::new(),
            unit: None,
        };
        // The farthest base is 5 from the axis (its height does not count).
        assert_eq!(
            receptacle_for(&flower),
            receptacle_mesh(1.1 * 5.0, 0.7 * 5.0)
        );
        // Organs on the axis still get a small receptacle.
        flower.organs = vec![organ_at(0.0, 0.0)];
        assert_eq!(
            receptacle_for(&flower),
            receptacle_mesh(1.1 * 0.5, 0.7 * 0.5)
        );
    }
}

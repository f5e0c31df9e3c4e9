//! Helpers shared by the simulation's integration tests.
#![allow(dead_code)]

use anthesis_flower::Project;
use anthesis_flower::parts::{Part, PartShape, Tube};
use anthesis_sim::crossing::{Crossings, OnCrossing};
// Each test crate uses some of the helpers; the two petals driven into
// each other live with the fixtures, since unit tests use them too.
#[allow(unused_imports)]
pub use anthesis_sim::fixtures::{inner_driven_into_outer, inner_driven_into_outer_by};
use anthesis_sim::{Keyframe, Selection, SimError, Simulation, run};
use glam::DVec3;

/// Mean length of the triangle edges (each interior edge counted twice,
/// which does not matter for a near-uniform mesh).
pub fn mean_edge(positions: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    let mut sum = 0.0;
    let mut count = 0.0;
    for t in triangles {
        for k in 0..3 {
            sum += (positions[t[k] as usize] - positions[t[(k + 1) % 3] as usize]).length();
            count += 1.0;
        }
    }
    sum / count
}

/// Where a particle of one organ lies relative to another organ: measured
/// from the nearest point of the other organ's smooth surface (the flat
/// triangles' nearest point lifted onto the Phong surface, as collisions
/// define it), along the normal there (the other organ's inner side is
/// positive).
#[derive(Debug, Clone, Copy)]
pub struct SideSample {
    pub particle: usize,
    /// The triangle of the other organ the nearest point lies on.
    pub nearest_triangle: usize,
    /// Signed distance along the other organ's inner normal.
    pub along_normal: f64,
}

/// The particles of `moving` that lie over `other`: their nearest point on
/// `other`'s triangles is within two mean edges and not on its rim (a
/// particle beside a margin is not over the organ). Brute force over every
/// triangle, independent of the simulator's tracker and its search.
pub fn particles_over(
    moving_in_world: &[DVec3],
    other_in_world: &[DVec3],
    other_triangles: &[[u32; 3]],
) -> Vec<SideSample> {
    use anthesis_mesh::nearest::{closest_point_on_triangle, on_rim, phong_point};
    let normals = anthesis_mesh::vertex_normals(other_in_world, other_triangles);
    let reach = 2.0 * mean_edge(other_in_world, other_triangles);
    // Rim particles: on an edge only one triangle has.
    let mut edge_count = std::collections::HashMap::new();
    for t in other_triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edge_count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let mut rim = vec![false; other_in_world.len()];
    for ((a, b), count) in edge_count {
        if count == 1 {
            rim[a as usize] = true;
            rim[b as usize] = true;
        }
    }
    let mut over = Vec::new();
    for (particle, x) in moving_in_world.iter().enumerate() {
        let Some((triangle, distance, weights)) = other_triangles
            .iter()
            .enumerate()
            .map(|(t, tri)| {
                let [a, b, c] = tri.map(|k| other_in_world[k as usize]);
                let (point, weights) = closest_point_on_triangle(*x, a, b, c);
                (t, point.distance(*x), weights)
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
        else {
            continue;
        };
        let tri = other_triangles[triangle];
        if distance > reach || on_rim(tri, weights, &rim) {
            continue;
        }
        let corners = tri.map(|k| other_in_world[k as usize]);
        let corner_normals = tri.map(|k| normals[k as usize]);
        let point = phong_point(corners, corner_normals, weights);
        let normal = (0..3)
            .map(|k| corner_normals[k] * weights[k])
            .sum::<DVec3>()
            .normalize();
        over.push(SideSample {
            particle,
            nearest_triangle: triangle,
            along_normal: (*x - point).dot(normal),
        });
    }
    over
}

/// Every keyframe of a run (the bud first), or the error that stopped it
/// together with the keyframes computed before it.
pub fn run_all(project: &Project, selection: &Selection) -> (Vec<Keyframe>, Option<SimError>) {
    let mut keyframes = Vec::new();
    let result = run(project, selection, &mut |_, k| keyframes.push(k.clone()));
    (keyframes, result.err())
}

/// [`run_all`] told to go on past crossing keyframes
/// (`OnCrossing::Warn`), with what the crossing check found.
pub fn run_all_warned(
    project: &Project,
    selection: &Selection,
) -> (Vec<Keyframe>, Vec<Crossings>, Option<SimError>) {
    let mut sim = match Simulation::new(project, selection) {
        Ok(sim) => sim,
        Err(error) => return (Vec::new(), Vec::new(), Some(error)),
    };
    sim.on_crossing(OnCrossing::Warn);
    let mut keyframes = vec![sim.bud()];
    while !sim.finished() {
        match sim.step(&|| false, &mut |_| {}) {
            Ok(k) => keyframes.push(k),
            Err(error) => return (keyframes, sim.crossings().to_vec(), Some(error)),
        }
    }
    (keyframes, sim.crossings().to_vec(), None)
}

/// How far an organ's shape is from looking sane, measured against a
/// reference shape of the same mesh (the bud for lengths, the previous
/// keyframe for bends).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeChange {
    /// Largest edge length over its length in the reference.
    pub max_edge_ratio: f64,
    /// Smallest edge length over its length in the reference.
    pub min_edge_ratio: f64,
    /// Smallest triangle area over its area in the reference.
    pub min_area_ratio: f64,
    /// Largest change of a dihedral angle, in degrees.
    pub max_bend_change_deg: f64,
    /// The edge whose dihedral angle changed most.
    pub max_bend_at: [u32; 2],
}

/// Compares `positions` with `reference_positions` (same mesh).
pub fn shape_change(
    positions: &[DVec3],
    reference_positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> ShapeChange {
    let mesh = anthesis_mesh::Mesh {
        positions: reference_positions.to_vec(),
        uvs: vec![glam::DVec2::ZERO; reference_positions.len()],
        triangles: triangles.to_vec(),
    };
    let topology = anthesis_mesh::Topology::build(&mesh).expect("a valid mesh");
    let mut change = ShapeChange {
        max_edge_ratio: 0.0,
        min_edge_ratio: f64::INFINITY,
        min_area_ratio: f64::INFINITY,
        max_bend_change_deg: 0.0,
        max_bend_at: [0, 0],
    };
    for edge in &topology.edges {
        let [a, b] = edge.vertices.map(|v| v as usize);
        let ratio = (positions[a] - positions[b]).length()
            / (reference_positions[a] - reference_positions[b]).length();
        change.max_edge_ratio = change.max_edge_ratio.max(ratio);
        change.min_edge_ratio = change.min_edge_ratio.min(ratio);
        if let Some(hinge) = edge.hinge() {
            let now = anthesis_physics::hinge::dihedral_angle(hinge.map(|v| positions[v as usize]));
            let before = anthesis_physics::hinge::dihedral_angle(
                hinge.map(|v| reference_positions[v as usize]),
            );
            let d = anthesis_physics::elastic::angle_difference(now, before).abs();
            if d.to_degrees() > change.max_bend_change_deg {
                change.max_bend_at = edge.vertices;
            }
            change.max_bend_change_deg = change.max_bend_change_deg.max(d.to_degrees());
        }
    }
    let area = |x: &[DVec3], t: &[u32; 3]| {
        let [a, b, c] = t.map(|v| x[v as usize]);
        0.5 * (b - a).cross(c - a).length()
    };
    for t in triangles {
        change.min_area_ratio = change
            .min_area_ratio
            .min(area(positions, t) / area(reference_positions, t));
    }
    change
}

/// Every number of every keyframe as bits (wall time excluded).
pub fn fingerprint(keyframes: &[Keyframe]) -> Vec<u64> {
    keyframes.iter().flat_map(Keyframe::bits).collect()
}

/// A pistil on the flower axis, without a schedule.
pub fn pistil() -> Part {
    Part {
        name: "pistil".to_string(),
        shape: PartShape::Pistil {
            style: Tube {
                length: 12.0,
                radius: 0.8,
                curvature_deg: 0.0,
            },
            stigma_radius: 1.0,
            stigma_lobes: 3,
            ovary_length: 0.0,
            ovary_radius: 0.0,
        },
        count: 1,
        ring_radius: 0.0,
        height: 0.0,
        offset_deg: 0.0,
        angle_deg: 0.0,
        schedule: Vec::new(),
        colour: [0.5, 0.7, 0.3, 1.0],
        head_colour: [0.5, 0.7, 0.3, 1.0],
    }
}

//! Times the contact search between the whole lily's organs on the
//! positions of one keyframe (normals, grids and every overlap side, as a
//! keyframe's search makes them), many times over, and hashes what it
//! finds: a bench for the collision search alone, which changes to it must
//! leave bit for bit the same.
//!
//! ```text
//! cargo run --release -p anthesis-garden --example contact_search -- [EDGE_SCALE] [KEYFRAME] [REPEATS]
//! ```
use std::hash::{DefaultHasher, Hash, Hasher};
use std::time::Instant;

use anthesis_garden::flowers::flower_at_resolution;
use anthesis_mesh::nearest::TriangleRings;
use anthesis_sim::collide::{Surface, Tracker, Violated, contacts_against};
use anthesis_sim::{Selection, Simulation};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let scale: f64 = args
        .get(1)
        .map_or(0.6, |a| a.parse().expect("an edge scale"));
    let keyframe: u32 = args.get(2).map_or(70, |a| a.parse().expect("a keyframe"));
    let repeats: usize = args.get(3).map_or(200, |a| a.parse().expect("a count"));
    let project = flower_at_resolution("lily", scale)
        .expect("the lily has a builder")
        .expect("the lily builds");
    let mut sim = Simulation::new(&project, &Selection::All).expect("the lily simulates");
    let mut positions = Vec::new();
    while !sim.finished() {
        let k = sim.step(&|| false, &mut |_| {}).expect("converges");
        if k.index == keyframe {
            positions = k.positions_in_world;
            break;
        }
    }
    let organs = positions.len();
    let triangles: Vec<&[[u32; 3]]> = (0..organs).map(|i| sim.triangles(i)).collect();
    let rings: Vec<TriangleRings> = (0..organs)
        .map(|i| TriangleRings::new(triangles[i], positions[i].len()))
        .collect();
    let rims: Vec<Vec<bool>> = (0..organs)
        .map(|i| rim(triangles[i], positions[i].len()))
        .collect();
    let mean_edges: Vec<f64> = (0..organs)
        .map(|i| mean_edge(&positions[i], triangles[i]))
        .collect();
    let sides: Vec<(usize, usize, f64)> = project
        .flower
        .overlaps
        .iter()
        .flat_map(|o| [(o.inner, o.outer, 1.0), (o.outer, o.inner, -1.0)])
        .collect();
    let offset = project.settings.collision_offset;
    let mut hasher = DefaultHasher::new();
    let mut found = 0;
    let started = Instant::now();
    let cpu_started = cpu_seconds();
    for _ in 0..repeats {
        let normals: Vec<Vec<glam::DVec3>> = (0..organs)
            .map(|i| anthesis_mesh::vertex_normals(&positions[i], triangles[i]))
            .collect();
        let trackers: Vec<Tracker> = (0..organs)
            .map(|i| Tracker::new(&positions[i], 2.0 * mean_edges[i]))
            .collect();
        let surfaces: Vec<Surface> = (0..organs)
            .map(|i| Surface {
                positions: &positions[i],
                normals: &normals[i],
                triangles: triangles[i],
                rings: &rings[i],
                rim: &rims[i],
                mean_edge: mean_edges[i],
            })
            .collect();
        for &(moving, other, side) in &sides {
            let mut list = Vec::new();
            contacts_against(
                &surfaces[moving],
                &surfaces[other],
                &trackers[other],
                side,
                offset,
                Violated::MoveHalf,
                &mut list,
            );
            found += list.len();
            for c in &list {
                c.particle.hash(&mut hasher);
                c.point.to_array().map(f64::to_bits).hash(&mut hasher);
                c.normal.to_array().map(f64::to_bits).hash(&mut hasher);
            }
        }
    }
    let seconds = started.elapsed().as_secs_f64();
    let cpu = cpu_seconds().map(|now| now - cpu_started.unwrap_or(now));
    println!(
        "contacts {:016x}  {} per search  {:.3} ms per search, CPU {} ({} sides, {} particles)",
        hasher.finish(),
        found / repeats,
        1e3 * seconds / repeats as f64,
        cpu.map_or("unknown".into(), |cpu| format!(
            "{:.3} ms",
            1e3 * cpu / repeats as f64
        )),
        sides.len(),
        positions.iter().map(Vec::len).sum::<usize>(),
    );
}

/// This thread's CPU time so far (Linux: /proc/thread-self/schedstat), to
/// time the search on a machine that others load too.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let nanoseconds: f64 = stat.split_whitespace().next()?.parse().ok()?;
    Some(nanoseconds * 1e-9)
}

/// Vertices on an edge of one triangle only.
fn rim(triangles: &[[u32; 3]], vertices: usize) -> Vec<bool> {
    let mut edges = std::collections::HashMap::new();
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]));
            *edges.entry((a, b)).or_insert(0) += 1;
        }
    }
    let mut on = vec![false; vertices];
    for ((a, b), n) in edges {
        if n == 1 {
            on[a as usize] = true;
            on[b as usize] = true;
        }
    }
    on
}

fn mean_edge(positions: &[glam::DVec3], triangles: &[[u32; 3]]) -> f64 {
    let (sum, count) = triangles
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .fold((0.0, 0), |(s, n), (a, b)| {
            (
                s + positions[a as usize].distance(positions[b as usize]),
                n + 1,
            )
        });
    sum / count as f64
}

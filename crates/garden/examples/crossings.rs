//! Where touching organs' flat triangles (what the glTF export shows at
//! render level 0) cut each other: runs default flowers whole and prints,
//! per keyframe, the crossing pairs of triangles of different organs, how
//! deep the deepest reaches (`anthesis_bud::crossing_depth`, in mean edges)
//! and what kind they are, then one summary line per flower.
//!
//! ```text
//! cargo run --release -p anthesis-garden --example crossings -- [EDGE_SCALE] [NAME...]
//! ```
//!
//! Without names it runs every default flower. A crossing is
//! vertex-face when a corner of one triangle lies past the other organ's
//! flat surface there (beyond the other triangle's plane, or a neighbour's
//! of it on the same organ, over that triangle), edge-edge when only
//! edges pass through triangles and every corner lies on its side.
//! `DIGEST_TOLERANCE=1e-6` runs with another solver tolerance.
use anthesis_bud::{crossing_depth, quality, self_intersections};
use anthesis_garden::flower_mesh;
use anthesis_garden::flowers::{EDGE_SCALE, FLOWER_NAMES, flower_at_resolution};
use anthesis_mesh::Mesh;
use anthesis_mesh::nearest::{closest_point_on_triangle, triangles_around};
use anthesis_sim::Selection;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let scale: f64 = args
        .get(1)
        .map_or(EDGE_SCALE, |a| a.parse().expect("an edge scale"));
    let names: Vec<String> = if args.len() > 2 {
        args[2..].to_vec()
    } else {
        FLOWER_NAMES.iter().map(|n| n.to_string()).collect()
    };
    let mut summary = Vec::new();
    for name in &names {
        let mut project = flower_at_resolution(name, scale)
            .expect("a default flower's name")
            .expect("the flower builds");
        if let Ok(tolerance) = std::env::var("DIGEST_TOLERANCE") {
            project.settings.solver.relative_tolerance = tolerance.parse().expect("a tolerance");
        }
        let (mut keyframes, mut count, mut deepest) = (Vec::new(), 0, 0.0f64);
        let (mut vertex_face, mut edge_edge) = (0, 0);
        println!("{name}");
        anthesis_sim::run(&project, &Selection::All, &mut |_, keyframe| {
            let (mesh, organ_of) = flower_mesh(&project, &keyframe.positions_in_world);
            let edge = quality(&mesh).mean_edge;
            let around = triangles_around(&mesh.triangles, mesh.positions.len());
            let mut found = Vec::new();
            for pair in self_intersections(&mesh) {
                let [a, b] = pair.map(|t| organ_of[t]);
                if a == b {
                    continue;
                }
                let depth = crossing_depth(&mesh, pair) / edge;
                let kind = if corner_past(&mesh, &around, &organ_of, pair)
                    || corner_past(&mesh, &around, &organ_of, [pair[1], pair[0]])
                {
                    "vertex-face"
                } else {
                    "edge-edge"
                };
                found.push((depth, kind, pair, [a, b]));
            }
            if found.is_empty() {
                return;
            }
            found.sort_by(|x, y| y.0.total_cmp(&x.0));
            let vf = found.iter().filter(|f| f.1 == "vertex-face").count();
            vertex_face += vf;
            edge_edge += found.len() - vf;
            let (depth, kind, pair, organs) = found[0];
            let uv = pair.map(|t| {
                let tri = mesh.triangles[t];
                tri.iter().map(|&v| mesh.uvs[v as usize]).sum::<glam::DVec2>() / 3.0
            });
            println!(
                "  keyframe {:3}: {:2} pairs ({vf} vertex-face), deepest {depth:.4} edges ({kind}) {} uv {:.2},{:.2} / {} uv {:.2},{:.2}",
                keyframe.index,
                found.len(),
                project.flower.organs[organs[0]].name,
                uv[0].x,
                uv[0].y,
                project.flower.organs[organs[1]].name,
                uv[1].x,
                uv[1].y,
            );
            keyframes.push(keyframe.index);
            count += found.len();
            deepest = deepest.max(depth);
        })
        .unwrap_or_else(|error| panic!("{name}: {error}"));
        let line = format!(
            "{name}: {} keyframes with crossings {}, {count} pairs ({vertex_face} vertex-face, {edge_edge} edge-edge), deepest {deepest:.4} edges",
            keyframes.len(),
            ranges(&keyframes),
        );
        println!("{line}");
        summary.push(line);
    }
    println!("summary");
    for line in summary {
        println!("  {line}");
    }
}

/// Whether a corner of triangle `s` lies past the flat surface of `t`'s
/// organ: on the side of `t`'s plane where the fewer of `s`'s corners lie,
/// and over (projecting into) `t` or a triangle of the same organ sharing
/// a corner with `t`, on the same side of that one's plane.
fn corner_past(mesh: &Mesh, around: &[Vec<u32>], organ_of: &[usize], [s, t]: [usize; 2]) -> bool {
    let plane = |b: usize| {
        let [p, q, r] = mesh.triangle_positions(b);
        ((q - p).cross(r - p).normalize_or_zero(), p)
    };
    let (normal, origin) = plane(t);
    let corners = mesh.triangle_positions(s);
    let side: Vec<f64> = corners.iter().map(|c| (*c - origin).dot(normal)).collect();
    let above = side.iter().filter(|d| **d > 0.0).count();
    // The minority side: -1 below, +1 above.
    let sign = if above <= 1 { 1.0 } else { -1.0 };
    let mut nearby: Vec<usize> = mesh.triangles[t]
        .iter()
        .flat_map(|&v| around[v as usize].iter().map(|&u| u as usize))
        .filter(|&u| organ_of[u] == organ_of[t])
        .collect();
    nearby.sort_unstable();
    nearby.dedup();
    corners
        .iter()
        .zip(&side)
        .filter(|(_, d)| **d * sign > 0.0)
        .any(|(c, _)| {
            nearby.iter().any(|&u| {
                let (n, o) = plane(u);
                let [a, b, cc] = mesh.triangle_positions(u);
                let (_, w) = closest_point_on_triangle(*c, a, b, cc);
                let over = w.iter().all(|&w| w > 0.0);
                over && (*c - o).dot(n) * sign > 0.0 && n.dot(normal) > 0.0
            })
        })
}

/// `1-3,7,9-10` for sorted keyframe numbers.
fn ranges(keyframes: &[u32]) -> String {
    let mut out = Vec::new();
    let mut i = 0;
    while i < keyframes.len() {
        let mut j = i;
        while j + 1 < keyframes.len() && keyframes[j + 1] == keyframes[j] + 1 {
            j += 1;
        }
        out.push(if i == j {
            keyframes[i].to_string()
        } else {
            format!("{}-{}", keyframes[i], keyframes[j])
        });
        i = j + 1;
    }
    out.join(",")
}

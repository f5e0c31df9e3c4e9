//! Remeshing template meshes at another edge length through their UVs
//! (`anthesis_bud::remesh_mesh`): known shapes, points on the old surface,
//! UVs consistent with positions, outline and tip kept, stable when
//! repeated, clear refusals.

use anthesis_bud::{BudError, MeshSurface, RemeshOptions, mean_normal, quality, remesh_mesh};
use anthesis_mesh::generate::{flat_sheet, test_petal};
use anthesis_mesh::nearest::closest_point_on_triangle;
use anthesis_mesh::{Mesh, Topology};
use glam::{DVec2, DVec3};

/// A flat disc of radius `radius` in the XY plane from `rings` rings of
/// 6, 12, 18, ... vertices around a centre, UV = position mapped into the
/// unit square: its UV outline comes to a point at the base and at the tip
/// (v = 0 and v = 1 each touch it at one vertex).
fn disc(radius: f64, rings: usize) -> Mesh {
    let mut positions = vec![DVec3::ZERO];
    let mut ring_starts = vec![0usize];
    for k in 1..=rings {
        ring_starts.push(positions.len());
        let r = radius * k as f64 / rings as f64;
        for i in 0..6 * k {
            // Start at -90 degrees so that the base and tip are vertices.
            let angle =
                -std::f64::consts::FRAC_PI_2 + std::f64::consts::TAU * i as f64 / (6 * k) as f64;
            positions.push(DVec3::new(r * angle.cos(), r * angle.sin(), 0.0));
        }
    }
    let mut triangles = Vec::new();
    for k in 1..=rings {
        let outer: Vec<u32> = (0..6 * k).map(|i| (ring_starts[k] + i) as u32).collect();
        let inner: Vec<u32> = if k == 1 {
            vec![0]
        } else {
            (0..6 * (k - 1))
                .map(|i| (ring_starts[k - 1] + i) as u32)
                .collect()
        };
        // Walk both rings by angle (fraction of the turn), counter-clockwise.
        let (mut i, mut j) = (0usize, 0usize);
        while i < outer.len() || (k > 1 && j < inner.len()) {
            let next_outer = (i + 1) as f64 / outer.len() as f64;
            let next_inner = (j + 1) as f64 / inner.len() as f64;
            if k == 1 || (i < outer.len() && next_outer <= next_inner) {
                triangles.push([
                    outer[i],
                    outer[(i + 1) % outer.len()],
                    inner[j % inner.len()],
                ]);
                i += 1;
            } else {
                triangles.push([
                    inner[j],
                    outer[i % outer.len()],
                    inner[(j + 1) % inner.len()],
                ]);
                j += 1;
            }
        }
    }
    let uvs = positions
        .iter()
        .map(|p| DVec2::new(0.5 + 0.5 * p.x / radius, 0.5 + 0.5 * p.y / radius))
        .collect();
    Mesh {
        positions,
        uvs,
        triangles,
    }
}

/// Drops the vertices no triangle uses.
fn without_unused_vertices(mesh: &Mesh) -> Mesh {
    let mut new_index = vec![u32::MAX; mesh.vertex_count()];
    let mut kept = Mesh::default();
    for t in &mesh.triangles {
        let mut tri = [0; 3];
        for (k, &i) in t.iter().enumerate() {
            if new_index[i as usize] == u32::MAX {
                new_index[i as usize] = kept.positions.len() as u32;
                kept.positions.push(mesh.positions[i as usize]);
                kept.uvs.push(mesh.uvs[i as usize]);
            }
            tri[k] = new_index[i as usize];
        }
        kept.triangles.push(tri);
    }
    kept
}

/// The distance from `p` to the nearest point of `mesh` (brute force).
fn distance_to(mesh: &Mesh, p: DVec3) -> f64 {
    (0..mesh.triangle_count())
        .map(|t| {
            let [a, b, c] = mesh.triangle_positions(t);
            closest_point_on_triangle(p, a, b, c).0.distance(p)
        })
        .fold(f64::INFINITY, f64::min)
}

/// The distance from `p` to the outline (boundary edges) of `mesh`.
fn distance_to_outline(mesh: &Mesh, p: DVec3) -> f64 {
    let topology = Topology::build(mesh).expect("valid mesh");
    topology
        .boundary_edges()
        .map(|[i, j]| {
            let (a, b) = (mesh.positions[i as usize], mesh.positions[j as usize]);
            let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            (a + t * (b - a)).distance(p)
        })
        .fold(f64::INFINITY, f64::min)
}

fn boundary_vertices(mesh: &Mesh) -> Vec<usize> {
    let topology = Topology::build(mesh).expect("valid mesh");
    let on = topology.boundary_vertices(mesh.vertex_count());
    (0..mesh.vertex_count()).filter(|&i| on[i]).collect()
}

#[test]
fn a_flat_rectangle_gets_the_edge_asked_for_and_keeps_its_area() {
    let old = flat_sheet(4.0, 10.0, 9, 21);
    let old_area = old.area();
    for h in [0.8, 0.4, 0.2] {
        let bud = remesh_mesh(&old, &RemeshOptions::new(h)).expect("remeshes");
        let q = bud.quality;
        assert!(
            (q.mean_edge - h).abs() < 0.1 * h,
            "edge {h}: mean edge {:.4}",
            q.mean_edge
        );
        assert!(q.min_angle_deg >= 30.0, "edge {h}: {q:?}");
        // The corners are kept, so a flat rectangle keeps its area exactly.
        let area = bud.mesh.area();
        assert!(
            (area - old_area).abs() < 1e-9 * old_area,
            "{area} vs {old_area}"
        );
        assert!(anthesis_mesh::validate(&bud.mesh).is_ok());
        // Same side as the old winding (+Z).
        assert!(mean_normal(&bud.mesh).z > 0.0);
    }
}

#[test]
fn a_disc_keeps_its_area_better_as_the_edge_shrinks() {
    let radius = 5.0;
    let old = disc(radius, 40);
    let exact = std::f64::consts::PI * radius * radius;
    let old_error = (old.area() - exact).abs() / exact;
    let mut errors = Vec::new();
    for h in [1.0, 0.5, 0.25] {
        let bud = remesh_mesh(&old, &RemeshOptions::new(h)).expect("remeshes");
        let q = bud.quality;
        assert!(
            (q.mean_edge - h).abs() < 0.1 * h,
            "edge {h}: mean edge {:.4}",
            q.mean_edge
        );
        // The inscribed polygon of edge h loses about h^2 / (12 r^2) of a
        // circle's area (measured against the old mesh, itself a polygon).
        let error = (bud.mesh.area() - old.area()).abs() / exact;
        assert!(
            error < h * h / (radius * radius) + old_error,
            "edge {h}: area off by {error:.5}"
        );
        errors.push(error);
        // The pointed base and tip (v = 0 and v = 1 of the outline) stay.
        let lowest = bud
            .mesh
            .uvs
            .iter()
            .zip(&bud.mesh.positions)
            .min_by(|a, b| a.0.y.total_cmp(&b.0.y))
            .expect("vertices");
        assert!(lowest.1.distance(DVec3::new(0.0, -radius, 0.0)) < 1e-9);
        let highest = bud
            .mesh
            .uvs
            .iter()
            .zip(&bud.mesh.positions)
            .max_by(|a, b| a.0.y.total_cmp(&b.0.y))
            .expect("vertices");
        assert!(highest.1.distance(DVec3::new(0.0, radius, 0.0)) < 1e-9);
    }
    assert!(
        errors[2] < errors[0],
        "area error does not shrink: {errors:?}"
    );
}

#[test]
fn new_vertices_lie_on_the_old_surface_with_its_uvs() {
    let old = test_petal(10.0, 5.0, 9, 17);
    let surface = MeshSurface::new(&old).expect("a petal's UVs");
    let bud = remesh_mesh(&old, &RemeshOptions::new(0.45)).expect("remeshes");
    let scale = 10.0;
    for (p, uv) in bud.mesh.positions.iter().zip(&bud.mesh.uvs) {
        assert!(
            distance_to(&old, *p) < 1e-9 * scale,
            "{p} is off the old surface"
        );
        // The UV is where the old surface has this point.
        assert!(surface.point_at_uv(*uv).distance(*p) < 1e-9 * scale);
        assert!(uv.x >= -1e-12 && uv.x <= 1.0 + 1e-12 && uv.y >= -1e-12 && uv.y <= 1.0 + 1e-12);
    }
    // The outline stays: every new boundary vertex is on the old outline,
    // and the old outline's corners and tip are new vertices.
    for i in boundary_vertices(&bud.mesh) {
        let p = bud.mesh.positions[i];
        assert!(
            distance_to_outline(&old, p) < 1e-9 * scale,
            "{p} is off the outline"
        );
    }
    for corner in [
        DVec2::new(0.0, 0.0),
        DVec2::new(1.0, 0.0),
        DVec2::new(0.0, 1.0),
        DVec2::new(1.0, 1.0),
    ] {
        let old_corner = old.uvs.iter().position(|uv| *uv == corner).expect("corner");
        let at = old.positions[old_corner];
        assert!(
            bud.mesh
                .positions
                .iter()
                .any(|p| p.distance(at) < 1e-9 * scale),
            "corner {corner} moved"
        );
    }
    // The inner side stays the inner side (-Z for the test petal).
    assert!(mean_normal(&old).z < 0.0);
    assert!(mean_normal(&bud.mesh).z < 0.0);
}

#[test]
fn remeshing_twice_at_the_same_edge_is_stable() {
    let old = test_petal(10.0, 5.0, 13, 25);
    let once = remesh_mesh(&old, &RemeshOptions::new(0.6)).expect("remeshes");
    let twice = remesh_mesh(&once.mesh, &RemeshOptions::new(0.6)).expect("remeshes again");
    let (a, b) = (once.quality, twice.quality);
    let vertices = a.vertices as f64;
    assert!(
        (b.vertices as f64 - vertices).abs() < 0.05 * vertices,
        "{a:?}\n{b:?}"
    );
    assert!((b.mean_edge - a.mean_edge).abs() < 0.03 * a.mean_edge);
    assert!((twice.mesh.area() - once.mesh.area()).abs() < 0.01 * once.mesh.area());
    assert!(b.min_angle_deg > 25.0);
}

#[test]
fn coarser_and_finer_than_the_original() {
    // The shipped meshes are remeshed both ways: coarser than they were
    // built and finer.
    let old = test_petal(10.0, 5.0, 9, 17);
    let built = quality(&old).mean_edge;
    for factor in [2.0, 0.5, 0.25] {
        let h = built * factor;
        let bud = remesh_mesh(&old, &RemeshOptions::new(h)).expect("remeshes");
        assert!((bud.quality.mean_edge - h).abs() < 0.1 * h, "{factor}");
    }
}

#[test]
fn a_layout_that_turns_back_is_refused_with_where() {
    // A U-shaped UV layout: lines of constant v above the bottom of the U
    // cross it four times.
    let mut mesh = flat_sheet(3.0, 3.0, 13, 13);
    let keep: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .copied()
        .filter(|t| {
            let c = t.map(|i| mesh.uvs[i as usize]).iter().sum::<DVec2>() / 3.0;
            !(c.x > 0.35 && c.x < 0.65 && c.y > 0.4)
        })
        .collect();
    mesh.triangles = keep;
    let mesh = without_unused_vertices(&mesh);
    match remesh_mesh(&mesh, &RemeshOptions::new(0.3)) {
        Err(BudError::UvNotMonotone { v, crossings }) => {
            assert!(v > 0.4, "{v}");
            assert_eq!(crossings, 4);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_folded_layout_is_refused() {
    // Both halves of a sheet on the same UVs: a fold.
    let mut mesh = flat_sheet(4.0, 2.0, 9, 5);
    for uv in &mut mesh.uvs {
        if uv.x > 0.5 {
            uv.x = 1.0 - uv.x;
        }
    }
    let error = remesh_mesh(&mesh, &RemeshOptions::new(0.3)).expect_err("folded");
    assert!(
        matches!(
            error,
            BudError::UvOverlap { .. }
                | BudError::InvalidMesh(anthesis_mesh::MeshError::FlippedUv { .. })
        ),
        "{error}"
    );
}

#[test]
fn a_tiny_edge_is_refused_before_anything_is_built() {
    let old = test_petal(10.0, 5.0, 9, 17);
    let error = remesh_mesh(&old, &RemeshOptions::new(1e-4)).expect_err("too fine");
    assert!(
        matches!(error, BudError::TooManyVertices { estimated, .. } if estimated > 1_000_000),
        "{error}"
    );
}

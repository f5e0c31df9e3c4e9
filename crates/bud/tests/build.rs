//! Remeshing surfaces into organs: quality, conventions and refusals.

use std::f64::consts::PI;

use anthesis_bud::{
    BudError, InnerSide, RemeshOptions, Surface, build_organ, eustoma_petal_surface,
    lily_petal_surface, mean_normal, quality,
};
use anthesis_mesh::validate::validate;
use glam::{DVec2, DVec3};

/// A flat 20 x 20 square in the XY plane; `u` runs along −X, so the surface
/// normal `dS/du × dS/dv` is −Z (the inner side).
fn square(uv: DVec2) -> DVec3 {
    DVec3::new((0.5 - uv.x) * 20.0, uv.y * 20.0, 0.0)
}

/// A lily-petal-like test shape: 40 long, 12 wide at most, tapering to
/// 3 at the base and the (blunt) top, cupped towards −Z and curving in.
fn cupped_petal(uv: DVec2) -> DVec3 {
    let (length, width) = (40.0, 12.0);
    let half_width = 0.5 * width * (0.25 + 0.75 * (PI * uv.y).sin().powf(0.7));
    let x = -(uv.x - 0.5) * 2.0 * half_width;
    let z = -0.35 * x * x / width - 0.08 * length * uv.y * uv.y;
    DVec3::new(x, uv.y * length, z)
}

fn options(target_edge: f64) -> RemeshOptions {
    RemeshOptions::new(target_edge)
}

fn within(value: f64, expected: f64, fraction: f64) -> bool {
    (value - expected).abs() <= fraction * expected
}

#[test]
fn planar_square_remeshes_to_near_equilateral_triangles() {
    let bud = build_organ(&square, &options(1.0)).expect("a square meshes");
    validate(&bud.mesh).expect("valid mesh");
    let q = bud.quality;
    assert_eq!(q, quality(&bud.mesh));
    assert!(within(q.mean_edge, 1.0, 0.10), "mean edge {}", q.mean_edge);
    assert!(q.min_angle_deg >= 30.0, "min angle {}", q.min_angle_deg);
    assert!(q.max_angle_deg <= 110.0, "max angle {}", q.max_angle_deg);
    assert!(q.edge_spread <= 0.15, "spread {}", q.edge_spread);
    assert!(
        q.near_equilateral >= 0.8,
        "equilateral {}",
        q.near_equilateral
    );
    // An equilateral lattice of edge 1 covers 400 with about 462 vertices.
    assert!((400..=560).contains(&q.vertices), "{} vertices", q.vertices);
    // Boundary vertices stay on the square's sides, so the area is exact.
    assert!(
        (bud.mesh.area() - 400.0).abs() < 1e-9,
        "area {}",
        bud.mesh.area()
    );
    // UVs are the surface parameters of each vertex.
    for (p, uv) in bud.mesh.positions.iter().zip(&bud.mesh.uvs) {
        assert!((*p - square(*uv)).length() < 1e-9);
        assert!(uv.x >= 0.0 && uv.x <= 1.0 && uv.y >= 0.0 && uv.y <= 1.0);
    }
}

#[test]
fn cupped_petal_meshes_well() {
    let bud = build_organ(&cupped_petal, &options(1.3)).expect("a petal meshes");
    validate(&bud.mesh).expect("valid mesh");
    let q = bud.quality;
    assert!(q.min_angle_deg >= 30.0, "min angle {}", q.min_angle_deg);
    assert!(q.edge_spread <= 0.15, "spread {}", q.edge_spread);
    assert!(within(q.mean_edge, 1.3, 0.10), "mean edge {}", q.mean_edge);
    assert!(
        q.near_equilateral >= 0.7,
        "equilateral {}",
        q.near_equilateral
    );
    // The paper's lily petal: 388 particles, 685 triangles at edge 1.3;
    // this smaller shape (area about 390) lands in the same range.
    assert!((230..=450).contains(&q.vertices), "{} vertices", q.vertices);
    // Mesh vertices lie on the surface.
    for (p, uv) in bud.mesh.positions.iter().zip(&bud.mesh.uvs) {
        assert!((*p - cupped_petal(*uv)).length() < 1e-9);
    }
}

#[test]
fn lily_example_has_about_the_papers_counts() {
    let bud = build_organ(&lily_petal_surface(), &options(1.3)).expect("lily petal");
    validate(&bud.mesh).expect("valid mesh");
    let q = bud.quality;
    // Paper: 388 particles / 685 triangles / 1082 edges at mean edge 1.3.
    assert!(
        within(q.vertices as f64, 388.0, 0.10),
        "{} vertices",
        q.vertices
    );
    assert!(
        within(q.triangles as f64, 685.0, 0.10),
        "{} triangles",
        q.triangles
    );
    assert!(within(q.edges as f64, 1082.0, 0.10), "{} edges", q.edges);
    assert!(within(q.mean_edge, 1.3, 0.10), "mean edge {}", q.mean_edge);
    assert!(q.min_angle_deg >= 30.0, "min angle {}", q.min_angle_deg);
    assert!(q.edge_spread <= 0.15, "spread {}", q.edge_spread);
}

#[test]
fn eustoma_example_has_about_the_papers_counts() {
    let bud = build_organ(&eustoma_petal_surface(), &options(2.0)).expect("Eustoma petal");
    validate(&bud.mesh).expect("valid mesh");
    let q = bud.quality;
    // Paper: 261 particles / 458 triangles / 718 edges at mean edge 2.0.
    assert!(
        within(q.vertices as f64, 261.0, 0.10),
        "{} vertices",
        q.vertices
    );
    assert!(
        within(q.triangles as f64, 458.0, 0.10),
        "{} triangles",
        q.triangles
    );
    assert!(within(q.mean_edge, 2.0, 0.10), "mean edge {}", q.mean_edge);
    assert!(q.min_angle_deg >= 30.0, "min angle {}", q.min_angle_deg);
    assert!(q.edge_spread <= 0.15, "spread {}", q.edge_spread);
}

#[test]
fn quality_holds_across_target_edges() {
    // The layout changes discretely with the target; no target may produce
    // slivers. (A few sizes of each example, coarse to fine.)
    for (name, surface) in [
        ("lily", &lily_petal_surface() as &dyn Surface),
        ("eustoma", &eustoma_petal_surface() as &dyn Surface),
        ("cupped", &cupped_petal as &dyn Surface),
    ] {
        for target in [0.7, 1.0, 1.3, 1.6, 2.0] {
            let bud = build_organ(surface, &options(target)).expect("meshes");
            let q = bud.quality;
            assert!(q.min_angle_deg >= 25.0, "{name} at {target}: {q:?}");
            assert!(q.edge_spread <= 0.15, "{name} at {target}: {q:?}");
            assert!(
                within(q.mean_edge, target, 0.10),
                "{name} at {target}: {q:?}"
            );
        }
    }
}

#[test]
fn normals_face_minus_z_in_the_template_frame() {
    for (name, surface) in [
        ("lily", &lily_petal_surface() as &dyn Surface),
        ("eustoma", &eustoma_petal_surface() as &dyn Surface),
        ("cupped", &cupped_petal as &dyn Surface),
    ] {
        let bud = build_organ(surface, &options(1.5)).expect("meshes");
        let n = mean_normal(&bud.mesh).normalize();
        assert!(n.z < -0.5, "{name}: mean normal {n}");
        // Near the base the petal rises along +Y, so the inner normal there
        // is close to −Z.
        let near_base: DVec3 = bud
            .mesh
            .vertex_normals()
            .iter()
            .zip(&bud.mesh.uvs)
            .filter(|(_, uv)| uv.y < 0.2)
            .map(|(n, _)| *n)
            .sum();
        assert!(near_base.normalize().z < -0.8, "{name}: {near_base}");
    }
}

#[test]
fn winding_follows_the_inner_side_option() {
    // u along +X: the surface normal du x dv is +Z.
    let mirrored = |uv: DVec2| DVec3::new((uv.x - 0.5) * 10.0, uv.y * 10.0, 0.0);
    let mut o = options(1.0);
    let auto = build_organ(&mirrored, &o).expect("meshes");
    assert!(mean_normal(&auto.mesh).z < 0.0, "auto picks -Z");
    validate(&auto.mesh).expect("valid with clockwise UVs");
    o.inner_side = InnerSide::AlongSurfaceNormal;
    let along = build_organ(&mirrored, &o).expect("meshes");
    assert!(mean_normal(&along.mesh).z > 0.0);
    o.inner_side = InnerSide::AgainstSurfaceNormal;
    let against = build_organ(&mirrored, &o).expect("meshes");
    assert!(mean_normal(&against.mesh).z < 0.0);
    // The same triangles, wound the other way.
    assert_eq!(along.mesh.positions, against.mesh.positions);
    for (a, b) in along.mesh.triangles.iter().zip(&against.mesh.triangles) {
        assert_eq!([a[0], a[2], a[1]], *b);
    }
}

#[test]
fn uvs_follow_the_organ_convention() {
    let surface = lily_petal_surface();
    let bud = build_organ(&surface, &options(1.3)).expect("lily petal");
    let mesh = &bud.mesh;
    let topology = validate(mesh).expect("valid");
    // The base row sits at v = 0, at the organ's base (y = 0), from u = 0
    // to u = 1.
    let base: Vec<usize> = (0..mesh.uvs.len())
        .filter(|&i| mesh.uvs[i].y == 0.0)
        .collect();
    assert!(base.len() >= 2);
    assert!(base.iter().all(|&i| mesh.positions[i].y.abs() < 1e-9));
    assert!(base.iter().any(|&i| mesh.uvs[i].x == 0.0));
    assert!(base.iter().any(|&i| mesh.uvs[i].x == 1.0));
    // The pointed tip is one vertex at uv (0.5, 1), the highest point.
    let tip: Vec<usize> = (0..mesh.uvs.len())
        .filter(|&i| mesh.uvs[i].y == 1.0)
        .collect();
    assert_eq!(tip.len(), 1);
    assert_eq!(mesh.uvs[tip[0]], DVec2::new(0.5, 1.0));
    let top = mesh.positions.iter().map(|p| p.y).fold(f64::MIN, f64::max);
    assert_eq!(mesh.positions[tip[0]].y, top);
    // The petal is symmetric about x = 0: the midrib u = 0.5 is at x = 0,
    // u < 0.5 on +X and u > 0.5 on -X (u runs along -X).
    for (p, uv) in mesh.positions.iter().zip(&mesh.uvs) {
        assert!((p.x - surface.point(DVec2::new(uv.x, uv.y)).x).abs() < 1e-9);
        if (uv.x - 0.5).abs() > 1e-6 {
            assert_eq!(p.x > 0.0, uv.x < 0.5, "uv {uv} at {p}");
        } else {
            assert!(p.x.abs() < 1e-9);
        }
    }
    // v increases from base to tip: along the midrib, y grows with v.
    let mut midrib: Vec<(f64, f64)> = (0..=20)
        .map(|k| {
            let v = k as f64 / 20.0;
            (v, surface.point(DVec2::new(0.5, v)).y)
        })
        .collect();
    midrib.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert!(midrib.windows(2).all(|w| w[1].1 > w[0].1));
    // Every boundary vertex lies on the boundary of the UV square (or is
    // the tip).
    let on_boundary = topology.boundary_vertices(mesh.uvs.len());
    for (i, uv) in mesh.uvs.iter().enumerate() {
        let at_edge = uv.x == 0.0 || uv.x == 1.0 || uv.y == 0.0 || uv.y == 1.0;
        assert_eq!(on_boundary[i], at_edge, "vertex {i} at {uv}");
    }
}

#[test]
fn invalid_target_edges_are_refused() {
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let err = build_organ(&square, &options(bad)).expect_err("bad target");
        assert!(matches!(err, BudError::InvalidTargetEdge(_)), "{err}");
    }
}

#[test]
fn target_edge_too_large_or_too_small_is_refused() {
    let err = build_organ(&square, &options(25.0)).expect_err("too coarse");
    assert!(matches!(err, BudError::TooFewRows { rows: 2, .. }), "{err}");
    assert!(err.to_string().contains("at least 3"), "{err}");
    let err = build_organ(&square, &options(0.04)).expect_err("too fine");
    match err {
        BudError::TooManyVertices {
            estimated, limit, ..
        } => {
            assert!(estimated > limit);
            assert_eq!(limit, 200_000);
        }
        other => panic!("expected TooManyVertices, got {other}"),
    }
    let mut o = options(1.0);
    o.max_vertices = 100;
    assert!(matches!(
        build_organ(&square, &o),
        Err(BudError::TooManyVertices { .. })
    ));
}

#[test]
fn zero_width_is_refused_except_at_the_tip() {
    // Pinched in the middle.
    let pinched = |uv: DVec2| {
        let w = 8.0 * (uv.y - 0.5).abs();
        DVec3::new((0.5 - uv.x) * w, uv.y * 20.0, 0.0)
    };
    match build_organ(&pinched, &options(1.0)) {
        Err(BudError::ZeroWidth { v }) => assert!((v - 0.5).abs() < 0.01, "v {v}"),
        other => panic!("expected ZeroWidth, got {other:?}"),
    }
    // Pointed at the base.
    let pointed_base = |uv: DVec2| DVec3::new((0.5 - uv.x) * 6.0 * uv.y, uv.y * 20.0, 0.0);
    match build_organ(&pointed_base, &options(1.0)) {
        Err(BudError::ZeroWidth { v }) => assert_eq!(v, 0.0),
        other => panic!("expected ZeroWidth, got {other:?}"),
    }
    // Pointed at the tip is fine (a blunt 60° tip).
    let pointed_tip = |uv: DVec2| DVec3::new((0.5 - uv.x) * 12.0 * (1.0 - uv.y), uv.y * 10.4, 0.0);
    let bud = build_organ(&pointed_tip, &options(1.0)).expect("pointed tip meshes");
    validate(&bud.mesh).expect("valid");
    assert!(bud.quality.min_angle_deg >= 30.0, "{:?}", bud.quality);
    // No length at all.
    let line = |uv: DVec2| DVec3::new(uv.x * 10.0, 0.0, 0.0);
    assert!(matches!(
        build_organ(&line, &options(1.0)),
        Err(BudError::ZeroLength)
    ));
}

#[test]
fn non_finite_points_are_refused() {
    let broken = |uv: DVec2| {
        if uv.y > 0.7 {
            DVec3::new(f64::NAN, 0.0, 0.0)
        } else {
            square(uv)
        }
    };
    match build_organ(&broken, &options(1.0)) {
        Err(BudError::NonFinitePoint { v, .. }) => assert!(v > 0.7),
        other => panic!("expected NonFinitePoint, got {other:?}"),
    }
}

#[test]
fn sharp_tip_below_the_quality_floor_is_refused_with_the_angle() {
    // A 17° tip: the tip triangle cannot be better than the tip.
    let sharp = |uv: DVec2| DVec3::new((0.5 - uv.x) * 6.0 * (1.0 - uv.y), uv.y * 20.0, 0.0);
    let err = build_organ(&sharp, &options(1.0)).expect_err("too sharp");
    match &err {
        BudError::PoorQuality {
            angle_deg,
            floor_deg,
            ..
        } => {
            assert!(*angle_deg < 20.0 && *angle_deg > 14.0, "{err}");
            assert_eq!(*floor_deg, 20.0);
        }
        other => panic!("expected PoorQuality, got {other}"),
    }
    assert!(err.to_string().contains('°'), "{err}");
    // With a lower floor it is accepted.
    let mut o = options(1.0);
    o.min_angle_floor_deg = 10.0;
    let bud = build_organ(&sharp, &o).expect("accepted with a lower floor");
    validate(&bud.mesh).expect("valid");
}

#[test]
fn self_intersecting_surface_is_refused() {
    // A strip along a planar loop (x, y) = 10 (t² − 1, t³ − t), t in
    // [−1.5, 1.5], which crosses itself at t = ±1; the strip is 3 wide in Z.
    let loop_strip = |uv: DVec2| {
        let t = -1.5 + 3.0 * uv.y;
        DVec3::new(
            10.0 * (t * t - 1.0),
            10.0 * (t * t * t - t),
            (uv.x - 0.5) * 3.0,
        )
    };
    let err = build_organ(&loop_strip, &options(0.8)).expect_err("crosses itself");
    match err {
        BudError::SelfIntersection {
            first,
            second,
            near_in_template,
        } => {
            assert!(first < second);
            // The crossing is at the origin's Z line.
            assert!(
                near_in_template.truncate().length() < 2.0,
                "{near_in_template}"
            );
        }
        other => panic!("expected SelfIntersection, got {other}"),
    }
    let mut o = options(0.8);
    o.check_self_intersection = false;
    assert!(build_organ(&loop_strip, &o).is_ok());
}

#[test]
fn examples_sit_in_the_template_frame() {
    for (name, surface) in [
        ("lily", &lily_petal_surface() as &dyn Surface),
        ("eustoma", &eustoma_petal_surface() as &dyn Surface),
    ] {
        // The base's middle is at the origin and the organ grows along +Y.
        let base = surface.point(DVec2::new(0.5, 0.0));
        assert!(base.length() < 1e-12, "{name}: base at {base}");
        let heights: Vec<f64> = (0..=10)
            .map(|k| surface.point(DVec2::new(0.5, k as f64 / 10.0)).y)
            .collect();
        assert!(
            heights.windows(2).all(|w| w[1] > w[0]),
            "{name}: {heights:?}"
        );
        // The organ leans out (+Z) and its top bends back in towards the
        // flower axis (−Z), so the bud closes.
        let z = |v: f64| surface.point(DVec2::new(0.5, v)).z;
        assert!(
            z(0.4) > 1.0 && z(1.0) < 0.0,
            "{name}: {} {}",
            z(0.4),
            z(1.0)
        );
        // Symmetric about the YZ plane: u and 1 - u mirror in X.
        for (u, v) in [(0.1, 0.3), (0.3, 0.7), (0.45, 0.95)] {
            let a = surface.point(DVec2::new(u, v));
            let b = surface.point(DVec2::new(1.0 - u, v));
            assert!((a - DVec3::new(-b.x, b.y, b.z)).length() < 1e-12, "{name}");
        }
    }
}

#[test]
fn flipping_the_inner_side_winds_every_triangle_the_other_way_and_back() {
    let bud = anthesis_bud::build_organ(
        &anthesis_bud::lily_petal_surface(),
        &anthesis_bud::RemeshOptions::new(1.3),
    )
    .unwrap();
    // Built with the inner side chosen automatically: it faces −Z.
    assert_eq!(
        anthesis_bud::inner_side_faces_minus_z(&bud.mesh),
        Some(true)
    );
    let flipped = anthesis_bud::with_inner_side_flipped(&bud.mesh);
    assert_eq!(
        anthesis_bud::inner_side_faces_minus_z(&flipped),
        Some(false)
    );
    assert_eq!(flipped.positions, bud.mesh.positions);
    assert_eq!(flipped.uvs, bud.mesh.uvs);
    assert_eq!(
        anthesis_bud::mean_normal(&flipped),
        -anthesis_bud::mean_normal(&bud.mesh)
    );
    assert_eq!(anthesis_bud::with_inner_side_flipped(&flipped), bud.mesh);
}

use super::*;
use crate::{BezierPatch, RemeshOptions, build_organ};

/// A flat petal in the template frame's `x`–`y` plane, 20 long.
fn flat_petal() -> Mesh {
    let row = |y: f64, outer: f64, inner: f64| {
        [
            DVec3::new(-outer, y, 0.0),
            DVec3::new(-inner, y, 0.0),
            DVec3::new(inner, y, 0.0),
            DVec3::new(outer, y, 0.0),
        ]
    };
    let net = BezierPatch::new([
        row(0.0, 1.2, 0.4),
        row(7.0, 5.0, 1.7),
        row(15.0, 5.0, 1.7),
        row(20.0, 1.2, 0.4),
    ]);
    build_organ(&net, &RemeshOptions::new(1.2)).unwrap().mesh
}

fn edge_lengths(mesh: &Mesh) -> Vec<f64> {
    mesh.triangles
        .iter()
        .flat_map(|t| {
            (0..3).map(move |k| {
                mesh.positions[t[k] as usize].distance(mesh.positions[t[(k + 1) % 3] as usize])
            })
        })
        .collect()
}

fn straight(length: f64) -> Vein {
    Vein::new(&[DVec2::ZERO, DVec2::new(length, 0.0)], 0.1).unwrap()
}

#[test]
fn a_straight_vein_as_long_as_a_flat_petal_leaves_it_where_it_is() {
    let mesh = flat_petal();
    // The midrib of the flat petal runs from (0, 0, 0) to (0, 20, 0); the
    // mesh's own midrib zig-zags by a few thousandths across.
    let bent = bend_along_vein(&mesh, &straight(20.0)).unwrap();
    for (a, b) in mesh.positions.iter().zip(&bent.positions) {
        assert!(a.distance(*b) < 0.01, "{a} moved to {b}");
    }
    assert_eq!(bent.uvs, mesh.uvs);
    assert_eq!(bent.triangles, mesh.triangles);
}

#[test]
fn a_vein_twice_as_long_scales_the_petal_twice() {
    let mesh = flat_petal();
    let bent = bend_along_vein(&mesh, &straight(40.0)).unwrap();
    for (a, b) in mesh.positions.iter().zip(&bent.positions) {
        assert!((2.0 * *a).distance(*b) < 0.02, "{a} went to {b}");
    }
}

#[test]
fn a_flat_petal_bent_along_a_circle_keeps_its_edge_lengths_and_its_midrib_lies_on_the_circle() {
    let mesh = flat_petal();
    // A quarter circle of length 20 in the y–z plane, curving to +z
    // (outwards): centre (y, z) = (0, radius).
    let radius = 40.0 / std::f64::consts::PI;
    let arc: Vec<DVec2> = (0..=200)
        .map(|k| {
            let a = std::f64::consts::FRAC_PI_2 * k as f64 / 200.0;
            DVec2::new(radius * a.sin(), radius * (1.0 - a.cos()))
        })
        .collect();
    let vein = Vein::new(&arc, 0.1).unwrap();
    // Smoothing the stroke pulls it in a little.
    assert!((vein.length() - 20.0).abs() < 0.02, "{}", vein.length());
    let bent = bend_along_vein(&mesh, &vein).unwrap();
    // A flat sheet bent about its across direction is not stretched.
    for (before, after) in edge_lengths(&mesh).iter().zip(edge_lengths(&bent)) {
        assert!(
            (after / before - 1.0).abs() < 0.01,
            "edge {before} became {after}"
        );
    }
    let centre = DVec3::new(0.0, 0.0, radius);
    for (p, uv) in bent.positions.iter().zip(&bent.uvs) {
        // Every point keeps its distance across (x) and lies on the
        // cylinder the circle sweeps.
        let q = DVec3::new(0.0, p.y, p.z);
        assert!(
            ((q - centre).length() - radius).abs() < 0.02 * radius,
            "{p} (uv {uv}) is off the circle"
        );
    }
    for (a, b) in mesh.positions.iter().zip(&bent.positions) {
        assert!((a.x - b.x).abs() < 0.01, "across moved: {a} -> {b}");
    }
    // The tip ends at the quarter circle's end, (y, z) = (R, R).
    let tip = bent
        .positions
        .iter()
        .copied()
        .max_by(|a, b| a.z.total_cmp(&b.z))
        .unwrap();
    assert!(
        (tip.y - radius).abs() < 0.05 && (tip.z - radius).abs() < 0.05,
        "{tip}"
    );
}

#[test]
fn a_cupped_petal_keeps_its_cup_across_when_its_midrib_is_straightened() {
    let mesh = build_organ(&BezierPatch::petal(), &RemeshOptions::new(1.2))
        .unwrap()
        .mesh;
    let bent = bend_along_vein(&mesh, &straight(21.0)).unwrap();
    // Margins stay on the inner side (−z) of the midrib, as in the cup.
    let depth = |m: &Mesh| {
        let (mut margin, mut midrib) = (0.0, 0.0);
        for (p, uv) in m.positions.iter().zip(&m.uvs) {
            if (uv.y - 0.5).abs() < 0.1 {
                if uv.x < 0.05 || uv.x > 0.95 {
                    margin += p.z;
                } else if (uv.x - 0.5).abs() < 0.05 {
                    midrib += p.z;
                }
            }
        }
        (margin, midrib)
    };
    let (margin, _) = depth(&bent);
    assert!(margin < 0.0, "the margins went to the outer side: {margin}");
    for p in &bent.positions {
        assert!(p.y > -1.0 && p.y < 22.0, "{p}");
    }
}

#[test]
fn a_side_stroke_drawn_from_the_tip_down_or_left_of_the_axis_gives_the_same_vein() {
    let stroke: Vec<DVec2> = (0..=30)
        .map(|k| {
            let t = k as f64 / 30.0;
            DVec2::new(2.0 + 6.0 * (std::f64::consts::PI * t).sin(), 15.0 * t)
        })
        .collect();
    let up = SideStroke::new(&stroke, 1.0).unwrap();
    assert_eq!(up.base, DVec2::new(2.0, 0.0));
    let reversed: Vec<DVec2> = stroke.iter().rev().copied().collect();
    let down = SideStroke::new(&reversed, 1.0).unwrap();
    let mirrored: Vec<DVec2> = stroke.iter().map(|p| DVec2::new(-p.x, p.y)).collect();
    let left = SideStroke::new(&mirrored, 1.0).unwrap();
    for other in [&down, &left] {
        assert_eq!(other.base, up.base);
        for (a, b) in up.vein.points().iter().zip(other.vein.points()) {
            assert!(
                a.distance(*b) < 0.05 * up.vein.length() / STROKE_SAMPLES as f64,
                "{a} vs {b}"
            );
        }
    }
    // In the template frame y is the height and z the distance outwards.
    let top = up.vein.points().last().unwrap();
    assert!((top.x - 15.0).abs() < 1e-9 && top.y.abs() < 1e-9, "{top}");
    let middle = up.vein.points()[STROKE_SAMPLES / 2];
    assert!(middle.y > 4.0, "bulges outwards: {middle}");
    assert!(up.side_points()[0].distance(up.base) < 1e-12);
}

#[test]
fn bad_side_strokes_are_refused_saying_why() {
    let loop_stroke = [
        DVec2::new(1.0, 0.0),
        DVec2::new(5.0, 5.0),
        DVec2::new(5.0, 8.0),
        DVec2::new(3.0, 8.0),
        DVec2::new(3.0, 2.0),
        DVec2::new(7.0, 2.0),
    ];
    let error = SideStroke::new(&loop_stroke, 1.0).unwrap_err();
    assert!(
        matches!(error, VeinError::SelfIntersecting { .. }),
        "{error:?}"
    );
    assert!(error.to_string().contains("crosses itself"), "{error}");
    let across = [DVec2::new(-3.0, 0.0), DVec2::new(3.0, 6.0)];
    let error = SideStroke::new(&across, 1.0).unwrap_err();
    assert_eq!(error, VeinError::CrossesAxis { h: 3.0 });
    // Through a point on the axis.
    let through = [
        DVec2::new(-1.0, 0.0),
        DVec2::new(0.0, 1.0),
        DVec2::new(1.0, 2.0),
    ];
    let error = SideStroke::new(&through, 1.0).unwrap_err();
    assert_eq!(error, VeinError::CrossesAxis { h: 1.0 });
    // Starting on the axis is not crossing it.
    assert!(SideStroke::new(&through[1..], 1.0).is_ok());
    let short = [DVec2::new(1.0, 0.0), DVec2::new(1.0, 0.5)];
    let error = SideStroke::new(&short, 1.0).unwrap_err();
    assert!(error.to_string().contains("too short"), "{error}");
    assert_eq!(
        SideStroke::new(&[DVec2::new(1.0, 1.0)], 1.0).unwrap_err(),
        VeinError::TooShort {
            length: 0.0,
            minimum: 1.0
        }
    );
    assert_eq!(
        SideStroke::new(&[DVec2::new(f64::NAN, 1.0), DVec2::ONE], 1.0).unwrap_err(),
        VeinError::NotFinite
    );
}

use super::*;
use crate::{RemeshOptions, Surface, build_organ};
use glam::DVec2;

/// `count` points evenly along a function of t in [0, 1].
fn stroke(count: usize, f: impl Fn(f64) -> DVec2) -> Vec<DVec2> {
    (0..count)
        .map(|k| f(k as f64 / (count - 1) as f64))
        .collect()
}

/// A straight-sided petal: margins at x = ∓2, the vein at x = 0, 14 long.
fn strip() -> PetalSketch {
    PetalSketch {
        left: stroke(30, |t| DVec2::new(-2.0, 14.0 * t)),
        right: stroke(30, |t| DVec2::new(2.0, 14.0 * t)),
        vein: stroke(30, |t| DVec2::new(0.0, 14.0 * t)),
        sections: Vec::new(),
    }
}

/// A petal outline: margins `left` and `right` wide at their widest,
/// meeting at the base and the tip, `length` long, the vein bowed by
/// `bow` to the right.
fn petal(left: f64, right: f64, length: f64, bow: f64) -> PetalSketch {
    let w = |t: f64| (std::f64::consts::PI * t).sin().powf(0.8) * (1.0 - 0.25 * t);
    PetalSketch {
        left: stroke(80, |t| DVec2::new(-left * w(t), length * t)),
        right: stroke(80, |t| DVec2::new(right * w(t), length * t)),
        vein: stroke(60, |t| {
            DVec2::new(bow * (std::f64::consts::PI * t).sin(), length * t)
        }),
        sections: Vec::new(),
    }
}

/// A "U" across the petal at height `y`, from `x0` to `x1`, sagging by
/// `depth` towards the base in the middle.
fn cup(y: f64, x0: f64, x1: f64, depth: f64) -> Vec<DVec2> {
    stroke(50, |t| {
        let x = x0 + (x1 - x0) * t;
        DVec2::new(x, y - depth * 4.0 * t * (1.0 - t))
    })
}

#[test]
fn a_straight_sided_outline_gives_control_points_spread_evenly() {
    let built = strip().build().unwrap();
    let control = &built.surface.control;
    assert_eq!(control.len(), SKETCH_ROWS);
    // Row j at y = 14 j / 7, the seven points from x = -2 to 2 in thirds
    // of each half, all in the base plane.
    for (j, row) in control.iter().enumerate() {
        assert_eq!(row.len(), SKETCH_COLUMNS);
        for (i, p) in row.iter().enumerate() {
            let expected = DVec3::new(-2.0 + 2.0 * i as f64 / 3.0, 2.0 * j as f64, 0.0);
            assert!((*p - expected).length() < 1e-9, "row {j} column {i}: {p}");
        }
    }
    assert_eq!(built.frame.origin, DVec2::ZERO);
    assert!((built.frame.axis - DVec2::Y).length() < 1e-12);
    // The surface reaches the outline's corners and the vein's ends.
    let s = &built.surface;
    assert!((s.point(DVec2::new(0.0, 0.0)) - DVec3::new(-2.0, 0.0, 0.0)).length() < 1e-9);
    assert!((s.point(DVec2::new(1.0, 1.0)) - DVec3::new(2.0, 14.0, 0.0)).length() < 1e-9);
    assert!((s.point(DVec2::new(0.5, 0.5)) - DVec3::new(0.0, 7.0, 0.0)).length() < 1e-9);
}

#[test]
fn the_strokes_may_come_in_any_order_and_direction_and_anywhere() {
    let expected = strip().build().unwrap().surface;
    let s = strip();
    let reversed = |v: &Vec<DVec2>| v.iter().rev().copied().collect::<Vec<_>>();
    // Vein first, the right margin drawn tip to base, the left base to tip.
    let shuffled = PetalSketch {
        left: s.vein.clone(),
        right: s.left.clone(),
        vein: reversed(&s.right),
        sections: Vec::new(),
    };
    let built = shuffled.build().unwrap().surface;
    for (a, b) in built
        .control
        .iter()
        .flatten()
        .zip(expected.control.iter().flatten())
    {
        assert!((*a - *b).length() < 1e-9, "{a} {b}");
    }
    assert_eq!(
        shuffled.sorted(),
        PetalSketch {
            left: s.left.clone(),
            right: reversed(&s.right),
            vein: s.vein.clone(),
            sections: Vec::new(),
        }
    );
    // Turned by 30° and moved: the same petal in the template frame.
    let turn = DVec2::from_angle(std::f64::consts::FRAC_PI_6);
    let moved = |v: &Vec<DVec2>| {
        v.iter()
            .map(|p| turn.rotate(*p) + DVec2::new(5.0, -3.0))
            .collect::<Vec<_>>()
    };
    let turned = PetalSketch {
        left: moved(&s.right),
        right: moved(&s.vein),
        vein: moved(&s.left),
        sections: Vec::new(),
    }
    .build()
    .unwrap();
    for (a, b) in turned
        .surface
        .control
        .iter()
        .flatten()
        .zip(expected.control.iter().flatten())
    {
        assert!((*a - *b).length() < 1e-9, "{a} {b}");
    }
    // Lying down (turned by 100°), the base is where the strokes meet:
    // here the margins meet the vein only at the base.
    let fan = PetalSketch {
        left: stroke(20, |t| DVec2::new(-3.0 * t, 14.0 * t)),
        right: stroke(20, |t| DVec2::new(3.0 * t, 14.0 * t)),
        vein: stroke(20, |t| DVec2::new(0.0, 14.0 * t)),
        sections: Vec::new(),
    };
    let lying = DVec2::from_angle(100f64.to_radians());
    let turn_all = |v: &Vec<DVec2>| v.iter().rev().map(|p| lying.rotate(*p)).collect::<Vec<_>>();
    let built = PetalSketch {
        left: turn_all(&fan.left),
        right: turn_all(&fan.right),
        vein: turn_all(&fan.vein),
        sections: Vec::new(),
    }
    .build()
    .unwrap();
    assert!(built.frame.origin.length() < 1e-9, "{:?}", built.frame);
    let upright = fan.build().unwrap();
    for (a, b) in built
        .surface
        .control
        .iter()
        .flatten()
        .zip(upright.surface.control.iter().flatten())
    {
        assert!((*a - *b).length() < 1e-9, "{a} {b}");
    }
    // And back in the sketch plane where it was drawn.
    let corner = turned.control_in_sketch()[0][0];
    assert!(
        (corner - (turn.rotate(DVec2::new(-2.0, 0.0)) + DVec2::new(5.0, -3.0))).length() < 1e-9
    );
}

#[test]
fn a_cross_section_bends_exactly_its_row_and_the_columns_follow_a_natural_spline() {
    let depth = 1.5;
    // Drawn right to left over row 4 (y = 8), a parabola sagging `depth`
    // towards the base, from margin to margin.
    let mut section = cup(8.0, -2.0, 2.0, depth);
    section.reverse();
    let mut sketch = strip();
    sketch.sections.push(section);
    let built = sketch.build().unwrap();
    assert_eq!(built.section_rows, vec![4]);
    let flat = strip().build().unwrap().surface;
    let control = &built.surface.control;
    // Seen from above nothing moved.
    for (a, b) in control.iter().flatten().zip(flat.control.iter().flatten()) {
        assert!((a.truncate() - b.truncate()).length() < 1e-12);
    }
    // Row 4: the parabola h(s) = -4 depth s (1 - s) relative to its margins
    // and to the vein, negated: z = -depth (2 s - 1)^2 at s = i / 6.
    for (i, p) in control[4].iter().enumerate() {
        let s = i as f64 / 6.0;
        let expected = -depth * (2.0 * s - 1.0).powi(2);
        assert!(
            (p.z - expected).abs() < 0.01 * depth,
            "column {i}: {} vs {expected}",
            p.z
        );
    }
    assert_eq!(control[4][3].z, 0.0);
    // Base and tip rows stay flat.
    assert!(control[0].iter().chain(&control[7]).all(|p| p.z == 0.0));
    // The other rows: per column the natural cubic spline through
    // (0, 0), (v4, z4), (1, 0), by its closed form (v4 = 0.6, the
    // Greville abscissa of row 4 of 8 clamped uniform cubic knots).
    let v = [0.0, 1.0 / 15.0, 0.2, 0.4, 0.6, 0.8, 14.0 / 15.0, 1.0];
    let (h0, h1) = (0.6, 0.4);
    for i in 0..SKETCH_COLUMNS {
        let z4 = control[4][i].z;
        let m = 6.0 * ((0.0 - z4) / h1 - (z4 - 0.0) / h0) / (2.0 * (h0 + h1));
        let spline = |t: f64| {
            if t <= 0.6 {
                m * t.powi(3) / (6.0 * h0) + (z4 / h0 - m * h0 / 6.0) * t
            } else {
                let r = 1.0 - t;
                m * r.powi(3) / (6.0 * h1) + (z4 / h1 - m * h1 / 6.0) * r
            }
        };
        for (j, vj) in v.iter().enumerate() {
            let z = control[j][i].z;
            assert!(
                (z - spline(*vj)).abs() < 1e-9,
                "row {j} column {i}: {z} vs {}",
                spline(*vj)
            );
        }
    }
    // The margins rise to the inner side (-Z): the petal is cupped.
    let bud = build_organ(&built.surface, &RemeshOptions::new(0.5)).unwrap();
    assert_eq!(crate::inner_side_faces_minus_z(&bud.mesh), Some(true));
    let mid = built.surface.point(DVec2::new(0.5, 0.6));
    let margin = built.surface.point(DVec2::new(0.0, 0.6));
    assert!(margin.z < mid.z - 0.5 * depth, "{margin} {mid}");
}

#[test]
fn a_straight_or_tilted_section_leaves_the_row_flat_and_a_new_one_on_its_row_replaces_it() {
    let mut sketch = strip();
    // A straight line across row 2 (y = 4), tilted by half a unit.
    sketch
        .sections
        .push(stroke(10, |t| DVec2::new(-2.1 + 4.2 * t, 4.0 + 0.5 * t)));
    let built = sketch.build().unwrap();
    assert_eq!(built.section_rows, vec![2]);
    assert!(
        built
            .surface
            .control
            .iter()
            .flatten()
            .all(|p| p.z.abs() < 1e-9)
    );
    // Drawn with the tool: a cup on the same row replaces the line.
    let cupped = sketch.with_stroke(SketchTool::CrossSection, cup(4.2, -2.0, 2.0, 1.0));
    assert_eq!(cupped.sections.len(), 1);
    assert!(cupped.build().unwrap().surface.control[2][0].z < -0.9);
    // One on another row is added.
    let two = cupped.with_stroke(SketchTool::CrossSection, cup(10.0, -2.0, 2.0, 0.5));
    assert_eq!(two.sections.len(), 2);
    assert_eq!(two.build().unwrap().section_rows, vec![2, 5]);
}

#[test]
fn automatic_roles_sort_the_outline_and_tell_sections_from_redrawn_strokes() {
    let s = strip();
    let mut sketch = PetalSketch::default();
    for drawn in [s.vein.clone(), s.right.clone(), s.left.clone()] {
        sketch = sketch.with_stroke(SketchTool::Auto, drawn);
    }
    assert_eq!(sketch, s);
    // Across: a cross-section.
    let with_section = sketch.with_stroke(SketchTool::Auto, cup(6.0, -2.0, 2.0, 0.8));
    assert_eq!(with_section.sections.len(), 1);
    // Along, near the right margin: replaces it.
    let wider = stroke(20, |t| {
        DVec2::new(2.5 + (std::f64::consts::PI * t).sin(), 14.0 * t)
    });
    let redrawn = with_section.with_stroke(SketchTool::Auto, wider.clone());
    assert_eq!(redrawn.right, wider);
    assert_eq!(redrawn.left, s.left);
    assert_eq!(redrawn.sections.len(), 1);
    // A role chosen by hand replaces that stroke.
    let vein = stroke(20, |t| DVec2::new(0.3 * t, 14.0 * t));
    assert_eq!(
        redrawn.with_stroke(SketchTool::Vein, vein.clone()).vein,
        vein
    );
}

#[test]
fn bad_strokes_are_refused_naming_the_stroke_and_why() {
    // Missing.
    let mut sketch = strip();
    sketch.vein.clear();
    let e = sketch.build().unwrap_err();
    assert_eq!(e, SketchError::Missing(StrokeRole::Vein));
    assert!(
        e.to_string().contains("vein stroke has not been drawn"),
        "{e}"
    );
    // A click, not a stroke.
    let mut sketch = strip();
    sketch.left = vec![DVec2::new(-2.0, 3.0); 3];
    let e = sketch.build().unwrap_err();
    assert!(
        matches!(
            e,
            SketchError::TooShort {
                stroke: StrokeRole::LeftOutline,
                ..
            }
        ),
        "{e}"
    );
    // Too short against the others.
    let mut sketch = strip();
    sketch.right = stroke(5, |t| DVec2::new(2.0, 2.0 * t));
    let e = sketch.build().unwrap_err();
    assert_eq!(
        e.to_string(),
        "the right outline stroke is too short: 2.000 long, at least 3.500 is needed (a quarter \
         of the longest outline stroke)"
    );
    // A loop in the vein.
    let mut sketch = strip();
    sketch.vein = stroke(120, |t| {
        let a = 2.0 * std::f64::consts::PI * ((t - 0.4) / 0.2).clamp(0.0, 1.0);
        DVec2::new(0.8 * a.sin(), 14.0 * t - 0.8 * (1.0 - a.cos()) * 3.0)
    });
    let e = sketch.build().unwrap_err();
    assert!(
        matches!(
            e,
            SketchError::SelfIntersecting {
                stroke: StrokeRole::Vein,
                ..
            }
        ),
        "{e}"
    );
    assert!(
        e.to_string()
            .starts_with("the vein stroke crosses itself near ("),
        "{e}"
    );
    // A margin that swings over the vein.
    let mut sketch = strip();
    sketch.left = stroke(40, |t| {
        DVec2::new(
            -2.0 + 3.5 * (std::f64::consts::PI * t).sin().powi(8),
            14.0 * t,
        )
    });
    let e = sketch.build().unwrap_err();
    assert!(matches!(e, SketchError::Crossing { .. }), "{e}");
    assert!(
        e.to_string()
            .contains("the left outline stroke and the vein stroke cross near"),
        "{e}"
    );
    // Margins that meet at the base and the tip (and overshoot there) are fine.
    let mut sketch = petal(3.0, 3.0, 16.0, 0.0);
    sketch.left.push(DVec2::new(0.3, 16.4));
    sketch.right.push(DVec2::new(-0.3, 16.4));
    sketch.build().unwrap();
    // A section over half the petal.
    let mut sketch = strip();
    sketch.sections.push(cup(8.0, -2.0, 0.5, 0.5));
    let e = sketch.build().unwrap_err();
    assert_eq!(
        e.to_string(),
        "the cross-section stroke 1 does not span the petal: it covers 0 % to 62 % of the width \
         of row 5 (draw it from one margin to the other)"
    );
    // One that goes back.
    let mut sketch = strip();
    sketch.sections.push(stroke(40, |t| {
        let x = if t < 0.7 {
            -2.0 + 6.0 * t
        } else {
            2.2 - 3.0 * (t - 0.7)
        };
        DVec2::new(x, 8.0 + 2.0 * t)
    }));
    let e = sketch.build().unwrap_err();
    assert!(
        matches!(
            e,
            SketchError::SectionTurnsBack {
                stroke: StrokeRole::CrossSection(0),
                ..
            }
        ),
        "{e}"
    );
    // Over a pointed tip.
    let mut sketch = petal(3.0, 3.0, 16.0, 0.0);
    sketch.sections.push(cup(16.2, -1.0, 1.0, 0.5));
    let e = sketch.build().unwrap_err();
    assert!(
        matches!(e, SketchError::SectionAtPoint { row: 7, .. }),
        "{e}"
    );
    // Not finite.
    let mut sketch = strip();
    sketch.left[3].x = f64::NAN;
    assert_eq!(
        sketch.build().unwrap_err(),
        SketchError::NotFinite(StrokeRole::LeftOutline)
    );
}

#[test]
fn a_pointed_base_is_widened_to_a_tenth_of_the_widest_row() {
    let built = petal(3.0, 3.0, 16.0, 0.0).build().unwrap();
    let base = &built.surface.control[0];
    let widest = built
        .surface
        .control
        .iter()
        .map(|r| r[0].distance(r[SKETCH_COLUMNS - 1]))
        .fold(0.0, f64::max);
    assert!((base[0].distance(base[SKETCH_COLUMNS - 1]) - 0.1 * widest).abs() < 1e-9);
    assert!(base[3].length() < 1e-12);
    assert!(base[0].x < 0.0 && base[6].x > 0.0);
}

#[test]
fn sketched_petals_of_several_shapes_mesh_within_the_quality_bounds() {
    let shapes = [
        (
            "narrow",
            petal(1.5, 1.5, 20.0, 0.0),
            vec![cup(10.0, -1.6, 1.6, 0.6)],
            [0.3, 0.5],
            22.0,
        ),
        (
            "wide",
            petal(8.0, 8.0, 14.0, 0.0),
            vec![cup(6.0, -8.5, 8.5, 3.0), cup(10.0, -7.0, 7.0, 2.0)],
            [0.8, 1.5],
            30.0,
        ),
        (
            "asymmetric",
            petal(3.0, 6.0, 18.0, 0.8),
            vec![cup(9.0, -3.2, 6.6, 1.5)],
            [0.6, 1.0],
            30.0,
        ),
    ];
    // Edges from a sixth to a tenth of the widest row or finer: coarser
    // than that, the base (a tenth of the widest row) gets one triangle.
    // The smallest angle is the remesher's usual 30° but for the narrow
    // petal, whose drawn tip is itself sharper (its tip triangle).
    for (name, mut sketch, sections, edges, floor) in shapes {
        sketch.sections = sections;
        let built = sketch.build().unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(built.section_rows.len(), sketch.sections.len(), "{name}");
        for edge in edges {
            let bud = build_organ(&built.surface, &RemeshOptions::new(edge))
                .unwrap_or_else(|e| panic!("{name} at {edge}: {e}"));
            let q = bud.quality;
            println!(
                "{name} at {edge}: {} particles, mean edge {:.3}, smallest angle {:.1}°, spread {:.1} %",
                q.vertices,
                q.mean_edge,
                q.min_angle_deg,
                100.0 * q.edge_spread
            );
            assert!(q.min_angle_deg >= floor, "{name} at {edge}: {q:?}");
            assert!(q.edge_spread <= 0.15, "{name} at {edge}: {q:?}");
            assert!(
                (q.mean_edge - edge).abs() < 0.15 * edge,
                "{name} at {edge}: {q:?}"
            );
            assert_eq!(
                crate::inner_side_faces_minus_z(&bud.mesh),
                Some(true),
                "{name}"
            );
            // UVs by convention: the base at v = 0 near the origin.
            for (p, uv) in bud.mesh.positions.iter().zip(&bud.mesh.uvs) {
                if uv.y == 0.0 {
                    assert!(p.y.abs() < 0.2 * edge + 1.0, "{name}: {p} at {uv}");
                }
            }
        }
    }
}

#[test]
fn the_new_petal_sketch_is_symmetric_cupped_and_meshes_at_the_simple_petals_edge() {
    let built = PetalSketch::petal().build().unwrap();
    assert_eq!(built.section_rows.len(), 1);
    let row = built.section_rows[0];
    let control = &built.surface.control;
    for row in control {
        for i in 0..SKETCH_COLUMNS {
            let (p, q) = (row[i], row[SKETCH_COLUMNS - 1 - i]);
            assert!(
                (p.x + q.x).abs() < 1e-9 && (p.y - q.y).abs() < 1e-9 && (p.z - q.z).abs() < 1e-9
            );
        }
    }
    let base = built.surface.point(DVec2::new(0.5, 0.0));
    assert!(base.length() < 1e-9, "{base}");
    let tip = built.surface.point(DVec2::new(0.5, 1.0));
    assert!((tip - DVec3::new(0.0, 20.0, 0.0)).length() < 1e-9, "{tip}");
    let width = built
        .surface
        .point(DVec2::new(0.0, 0.0))
        .distance(built.surface.point(DVec2::new(1.0, 0.0)));
    assert!((width - 2.4).abs() < 1e-9, "{width}");
    // Cupped: the margins over the middle lie towards -Z.
    assert!(control[row][0].z < -0.9, "{}", control[row][0]);
    let bud = build_organ(&built.surface, &RemeshOptions::new(1.2)).unwrap();
    println!("{:?}", bud.quality);
    assert!(bud.quality.min_angle_deg >= 30.0, "{:?}", bud.quality);
    assert!(bud.quality.edge_spread <= 0.15, "{:?}", bud.quality);
    assert_eq!(crate::inner_side_faces_minus_z(&bud.mesh), Some(true));
}

#[test]
fn a_vein_drawn_short_of_or_past_the_margins_ends_leaves_the_base_and_tip_straight() {
    let mut sketch = petal(3.0, 3.0, 16.0, 0.0);
    // The vein starts 1.5 above where the margins start and ends 1 past
    // their meeting point at the tip.
    sketch.vein = stroke(30, |t| DVec2::new(0.0, 1.5 + 15.5 * t));
    let built = sketch.build().unwrap();
    let control = &built.surface.control;
    // Base row on one line through the base, the middle at the origin.
    for p in &control[0] {
        assert!(p.y.abs() < 1e-9, "{p}");
    }
    assert!(control[0][3].length() < 1e-9);
    // The tip row collapses to the margins' meeting point.
    for p in &control[SKETCH_ROWS - 1] {
        assert!((*p - DVec3::new(0.0, 16.0, 0.0)).length() < 1e-9, "{p}");
    }
    // It meshes as well as the same petal with the vein from base to tip
    // (its smallest angle is the sharp tip's).
    let bud = build_organ(&built.surface, &RemeshOptions::new(0.6)).unwrap();
    let exact = petal(3.0, 3.0, 16.0, 0.0).build().unwrap();
    let reference = build_organ(&exact.surface, &RemeshOptions::new(0.6)).unwrap();
    assert!(
        bud.quality.min_angle_deg >= reference.quality.min_angle_deg - 2.0,
        "{:?} vs {:?}",
        bud.quality,
        reference.quality
    );
}

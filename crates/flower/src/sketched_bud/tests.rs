use glam::DVec2;

use super::*;
use crate::Template;
use crate::structure::Whorl;
use anthesis_mesh::generate::test_petal;

fn template(name: &str, width: f64) -> Template {
    Template {
        thickness: 0.1,
        ..crate::test_template(name, test_petal(8.0, width, 9, 17))
    }
}

/// Five petals in one whorl, 2 from the axis, tilted out by 10°.
fn five_petals(width: f64) -> Flower {
    let whorl = Whorl {
        name: "petal".to_string(),
        template: 0,
        count: 5,
        offset_deg: 0.0,
        radius: 2.0,
        height: 0.0,
        joint_angle_deg: 10.0,
        half_span_deg: 40.0,
    };
    Flower {
        templates: vec![template("petal", width)],
        organs: Vec::new(),
        overlaps: Vec::new(),
        structure: None,
        parts: Vec::new(),
        unit: None,
    }
    .arranged_by(Structure::Whorls {
        whorls: vec![whorl],
        contorted: false,
    })
    .unwrap()
}

/// A bud outline in the side view, `(r, h)`: out from `r0` and back in
/// towards the axis, 10 high.
fn bud_stroke(r0: f64, bulge: f64, top: f64) -> SideStroke {
    let points: Vec<DVec2> = (0..=40)
        .map(|k| {
            let t = k as f64 / 40.0;
            DVec2::new(
                r0 + (top - r0) * t + bulge * (std::f64::consts::PI * t).sin(),
                10.0 * t,
            )
        })
        .collect();
    SideStroke::new(&points, 1.0).unwrap()
}

/// Distance of `p` (side view) from the polyline.
fn distance_to(polyline: &[DVec2], p: DVec2) -> f64 {
    polyline
        .windows(2)
        .map(|w| {
            let d = w[1] - w[0];
            let t = ((p - w[0]).dot(d) / d.length_squared()).clamp(0.0, 1.0);
            p.distance(w[0] + t * d)
        })
        .fold(f64::INFINITY, f64::min)
}

/// The side-view points `(r, h)` of organ `i`'s midrib (u = 0.5).
fn midrib_in_side_view(flower: &Flower, i: usize) -> Vec<DVec2> {
    let organ = &flower.organs[i];
    let mesh = &flower.templates[organ.template].mesh;
    mesh.positions
        .iter()
        .zip(&mesh.uvs)
        .filter(|(_, uv)| (uv.x - 0.5).abs() < 1e-9)
        .map(|(p, _)| {
            let w = organ.placement.world_from_template(*p, 0.0);
            DVec2::new(w.x.hypot(w.z), w.y)
        })
        .collect()
}

#[test]
fn a_golden_spiral_puts_every_midrib_on_a_copy_of_the_stroke_137_5_degrees_apart() {
    let flower = five_petals(2.0);
    let stroke = bud_stroke(1.5, 1.5, 0.8);
    let bud = flower
        .with_sketched_bud(0, &stroke, BudPlacement::GoldenSpiral { count: 6 })
        .unwrap();
    assert_eq!(bud.crossing, None);
    assert_eq!(bud.flower.organs.len(), 6);
    assert_eq!(first_crossing(&bud.flower), None);
    let side = stroke.side_points();
    for (k, organ) in bud.flower.organs.iter().enumerate() {
        let azimuth = (GOLDEN_ANGLE_DEG * k as f64).rem_euclid(360.0);
        assert!((organ.placement.azimuth_deg - azimuth).abs() < 1e-9, "{k}");
        assert_eq!(organ.placement.joint_angle_deg, 0.0);
        // The midrib follows the stroke, moved in and down by k steps.
        let shift = DVec2::splat(bud.radius_step * k as f64);
        let copy: Vec<DVec2> = side.iter().map(|p| *p - shift).collect();
        let midrib = midrib_in_side_view(&bud.flower, k);
        assert!(midrib.len() >= 10);
        for p in midrib {
            assert!(
                distance_to(&copy, p) < 0.02,
                "organ {k}: {p} is off the stroke"
            );
        }
    }
    // The tip is where the stroke ends, the base where it starts.
    let template = &bud.flower.templates[0];
    assert_eq!(template.vein.as_ref(), Some(&stroke.vein));
    let top = template
        .mesh
        .positions
        .iter()
        .map(|p| p.y)
        .fold(f64::MIN, f64::max);
    assert!((top - 10.0).abs() < 0.3, "{top}");
    let midrib_length = stroke.vein.length();
    assert!(midrib_length > 10.0);
}

#[test]
fn the_arrangement_keeps_its_azimuths_and_moves_the_bases_to_the_stroke() {
    let flower = five_petals(2.0);
    let stroke = bud_stroke(3.0, 1.0, 1.0);
    let bud = flower
        .with_sketched_bud(0, &stroke, BudPlacement::Arrangement)
        .unwrap();
    assert_eq!(bud.flower.organs.len(), 5);
    for (before, after) in flower.organs.iter().zip(&bud.flower.organs) {
        assert_eq!(before.name, after.name);
        assert_eq!(before.placement.azimuth_deg, after.placement.azimuth_deg);
        assert_eq!(after.placement.joint_angle_deg, 0.0);
        let p = after.placement.position;
        assert!(
            (p.x.hypot(p.z) - 3.0).abs() < 1e-9 && p.y.abs() < 1e-9,
            "{p}"
        );
    }
    assert_eq!(bud.crossing, None);
    let side = stroke.side_points();
    for k in 0..5 {
        for p in midrib_in_side_view(&bud.flower, k) {
            assert!(distance_to(&side, p) < 0.02, "{p}");
        }
    }
}

#[test]
fn wide_petals_cross_and_the_bud_says_which() {
    // Five petals 6 wide at 1 from the axis overlap their neighbours.
    let flower = five_petals(6.0);
    let stroke = bud_stroke(1.0, 0.5, 0.5);
    let bud = flower
        .with_sketched_bud(0, &stroke, BudPlacement::Arrangement)
        .unwrap();
    let (a, b) = bud.crossing.expect("neighbours cross");
    assert!(
        a.starts_with("petal-") && b.starts_with("petal-"),
        "{a} {b}"
    );
    // Nor does nesting a spiral's later petals (nearer the axis and lower)
    // part petals this wide: the bud still says which cross, having tried
    // the steps up to the largest that keeps the innermost base off the axis.
    let spiral = flower
        .with_sketched_bud(0, &stroke, BudPlacement::GoldenSpiral { count: 3 })
        .unwrap();
    assert!(spiral.crossing.is_some());
    assert!(
        spiral.radius_step > 0.0 && 1.0 - 2.0 * spiral.radius_step > 0.0,
        "{}",
        spiral.radius_step
    );
}

#[test]
fn a_spiral_is_refused_when_other_templates_have_organs() {
    let mut flower = five_petals(2.0);
    flower = flower.with_template(template("sepal", 2.0));
    let organ = flower.new_organ(1).unwrap();
    let flower = flower.with_organ(organ).unwrap();
    let error = flower
        .with_sketched_bud(
            0,
            &bud_stroke(2.0, 1.0, 1.0),
            BudPlacement::GoldenSpiral { count: 5 },
        )
        .unwrap_err();
    assert!(matches!(error, EditError::OtherOrgans(_)), "{error}");
    assert!(error.to_string().contains("sepal"), "{error}");
}

#[test]
fn the_vein_is_saved_and_read_back() {
    let flower = five_petals(2.0);
    let bud = flower
        .with_sketched_bud(
            0,
            &bud_stroke(2.0, 1.0, 1.0),
            BudPlacement::GoldenSpiral { count: 5 },
        )
        .unwrap();
    let project = crate::Project {
        name: "bud".to_string(),
        flower: bud.flower.clone(),
        settings: crate::SimulationSettings::default(),
    };
    let folder = tempfile::tempdir().unwrap();
    let path = folder.path().join("bud.anthesis.toml");
    crate::project::save_project(&project, &path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("version = 8\n"), "{text}");
    assert!(text.contains("[templates.vein]"), "{text}");
    let loaded = crate::project::load_project(&path).unwrap();
    assert_eq!(
        loaded.flower.templates[0].vein,
        bud.flower.templates[0].vein
    );
}

#[test]
fn a_new_shape_for_a_template_with_a_vein_is_bent_along_it() {
    let flower = five_petals(2.0);
    let bud = flower
        .with_sketched_bud(0, &bud_stroke(2.0, 1.0, 1.0), BudPlacement::Arrangement)
        .unwrap();
    let bent = &bud.flower.templates[0];
    // A wider petal made for the bent template follows the same vein.
    let wider = test_petal(8.0, 3.0, 9, 17);
    let reshaped = bent.shaped(wider.clone()).unwrap();
    let organ = &bud.flower.organs[0];
    let side = bud_stroke(2.0, 1.0, 1.0).side_points();
    for (p, uv) in reshaped.positions.iter().zip(&reshaped.uvs) {
        if (uv.x - 0.5).abs() < 1e-9 {
            let w = organ.placement.world_from_template(*p, 0.0);
            assert!(distance_to(&side, DVec2::new(w.x.hypot(w.z), w.y)) < 0.02);
        }
    }
    // Without a vein the shape is used as it is.
    assert_eq!(flower.templates[0].shaped(wider.clone()).unwrap(), wider);
}

#[test]
fn an_opened_flower_stroke_makes_the_template_open_to_the_petal_bent_along_it() {
    let flower = five_petals(2.0);
    let bud = flower
        .with_sketched_bud(0, &bud_stroke(2.0, 1.0, 1.0), BudPlacement::Arrangement)
        .unwrap()
        .flower;
    // Out and down: an open flower's petal.
    let open_stroke: Vec<DVec2> = (0..=30)
        .map(|k| {
            let t = k as f64 / 30.0;
            DVec2::new(2.0 + 9.0 * t, 4.0 * (std::f64::consts::PI * t).sin())
        })
        .collect();
    let open = SideStroke::new(&open_stroke, 1.0).unwrap();
    let (opened, crossing) = bud.with_sketched_opening(0, &open.vein, 60).unwrap();
    assert_eq!(crossing, None);
    let template = &opened.templates[0];
    assert_eq!(template.mesh, bud.templates[0].mesh, "the bud stays");
    let animation = template.two_state.as_ref().expect("two-state");
    assert_eq!(animation.growth.duration, 60.0);
    assert_eq!(animation.open.len(), template.mesh.positions.len());
    // The open shape's midrib follows the open stroke from the organ's base.
    let organ = &opened.organs[0];
    let side = open.side_points();
    let shift = side[0]
        - DVec2::new(
            organ.placement.position.x.hypot(organ.placement.position.z),
            organ.placement.position.y,
        );
    for (p, uv) in animation.open.iter().zip(&template.mesh.uvs) {
        if (uv.x - 0.5).abs() < 1e-9 {
            let w = organ.placement.world_from_template(*p, 0.0);
            let q = DVec2::new(w.x.hypot(w.z), w.y) + shift;
            assert!(distance_to(&side, q) < 0.02, "{q}");
        }
    }
    // It passes the project's checks and is saved.
    let project = crate::Project {
        name: "opening".to_string(),
        flower: opened,
        settings: crate::SimulationSettings::default(),
    };
    let folder = tempfile::tempdir().unwrap();
    let path = folder.path().join("o.anthesis.toml");
    crate::project::save_project(&project, &path).unwrap();
    let loaded = crate::project::load_project(&path).unwrap();
    assert_eq!(
        loaded.flower.templates[0].two_state,
        project.flower.templates[0].two_state
    );
}

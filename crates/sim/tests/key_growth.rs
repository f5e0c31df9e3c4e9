//! A time key's own growth scale (`MapKey::dg`): growth values of that key
//! are rates `1 + dg · m`, blended between keys like the maps, so a late
//! key with a negative `dg` shrinks an organ that grew before it.

mod common;

use anthesis_flower::{Flower, Organ, Placement, Project, SimulationSettings};
use anthesis_maps::{Blend, GrowthMaps, KeyedMaps, MapKey, ScalarMap};
use anthesis_sim::Selection;
use anthesis_sim::fixtures::petal_template;
use common::run_all;

/// A flat petal growing evenly everywhere (all four growth maps 1, so it
/// stays flat), template `dg` 0.02; a second key at step 4 with
/// `key_dg`; 10 keyframes.
fn flat_petal(key_dg: Option<f64>) -> Project {
    let mut template = petal_template("petal", 6, 14);
    template.dg = 0.02;
    template.joint_schedule.clear();
    let maps = GrowthMaps {
        e_growth: ScalarMap::constant(1.0),
        w_growth: ScalarMap::constant(1.0),
        e_growth_in: ScalarMap::constant(1.0),
        w_growth_in: ScalarMap::constant(1.0),
        ..GrowthMaps::uniform()
    };
    let mut late = MapKey::new(4, maps.clone());
    late.dg = key_dg;
    template.maps =
        KeyedMaps::new(vec![MapKey::new(0, maps), late], Blend::Linear).expect("two keys");
    Project {
        name: "flat".into(),
        flower: Flower {
            templates: vec![template],
            organs: vec![Organ {
                name: "petal".into(),
                template: 0,
                placement: Placement {
                    position: glam::DVec3::ZERO,
                    azimuth_deg: 0.0,
                    joint_angle_deg: 0.0,
                    orientation: glam::DQuat::IDENTITY,
                },
            }],
            overlaps: Vec::new(),
            structure: None,
            parts: Vec::new(),
            unit: None,
        },
        settings: SimulationSettings {
            keyframes: 10,
            ..SimulationSettings::default()
        },
    }
}

/// How much the upper half of the midrib (from the middle particle to the
/// tip) lengthened over the run.
fn upper_midrib_growth(project: &Project) -> f64 {
    let (keyframes, error) = run_all(project, &Selection::All);
    assert!(error.is_none(), "{error:?}");
    let mesh = &project.flower.templates[0].mesh;
    let nearest = |u: f64, v: f64| {
        (0..mesh.uvs.len())
            .min_by(|&a, &b| {
                let d = |i: usize| (mesh.uvs[i] - glam::DVec2::new(u, v)).length();
                d(a).total_cmp(&d(b))
            })
            .expect("particles")
    };
    let (middle, tip) = (nearest(0.5, 0.5), nearest(0.5, 1.0));
    let length = |k: usize| {
        let p = &keyframes[k].positions_in_world[0];
        p[middle].distance(p[tip])
    };
    length(keyframes.len() - 1) / length(0)
}

#[test]
fn a_key_with_a_negative_growth_scale_shrinks_what_grew_before_it() {
    // Step s grows by 1 + (blended dg) per step along the midrib: steps 1–3
    // blend 0.02 into the key's dg, steps 4–10 are the key's alone.
    let expected = |key_dg: f64| -> f64 {
        (1..=10)
            .map(|s: i32| {
                let w = (f64::from(s) / 4.0).min(1.0);
                1.0 + (1.0 - w) * 0.02 + w * key_dg
            })
            .product()
    };
    for key_dg in [None, Some(-0.02), Some(0.0)] {
        let measured = upper_midrib_growth(&flat_petal(key_dg));
        let want = expected(key_dg.unwrap_or(0.02));
        assert!(
            (measured / want - 1.0).abs() < 0.01,
            "key dg {key_dg:?}: grew {measured:.4}, expected {want:.4}"
        );
    }
    // Shrinking for real: the negative key ends shorter than the bud.
    assert!(expected(-0.02) < 0.9);
}

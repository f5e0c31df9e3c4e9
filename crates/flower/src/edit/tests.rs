use glam::DVec3;

use super::*;
use crate::Placement;
use crate::structure::lsystem::LSystemError;
use anthesis_mesh::generate::test_petal;

fn template(name: &str) -> Template {
    crate::test_template(name, test_petal(4.0, 2.0, 4, 6))
}

fn whorl(name: &str, template: usize, count: usize, offset_deg: f64, radius: f64) -> Whorl {
    Whorl {
        name: name.to_string(),
        template,
        count,
        offset_deg,
        radius,
        height: 0.1 * radius,
        joint_angle_deg: 5.0,
        half_span_deg: 40.0,
    }
}

/// A lily-like flower: three petals inside three sepals (whorls), and one
/// listed organ, a bract, with a listed rule.
fn flower() -> Flower {
    let whorls = vec![
        whorl("petal", 0, 3, 0.0, 1.0),
        whorl("sepal", 1, 3, 60.0, 1.5),
    ];
    let made = Structure::Whorls {
        whorls: whorls.clone(),
        contorted: false,
    }
    .arrange(&[template("petal"), template("sepal")])
    .unwrap();
    let mut organs = made.organs;
    organs.push(Organ {
        name: "bract".to_string(),
        template: 1,
        placement: placement(0.0, 3.0, -1.0, 10.0),
    });
    let mut overlaps = made.overlaps;
    overlaps.push(Overlap { inner: 3, outer: 6 });
    Flower {
        templates: vec![template("petal"), template("sepal")],
        organs,
        overlaps,
        structure: Some(Structure::Whorls {
            whorls,
            contorted: false,
        }),
        parts: Vec::new(),
        unit: None,
    }
}

fn names(flower: &Flower) -> Vec<&str> {
    flower.organs.iter().map(|o| o.name.as_str()).collect()
}

fn rule_names(flower: &Flower) -> Vec<(String, String)> {
    flower
        .overlaps
        .iter()
        .map(|o| {
            (
                flower.organs[o.inner].name.clone(),
                flower.organs[o.outer].name.clone(),
            )
        })
        .collect()
}

fn whorls_of(flower: &Flower) -> Vec<Whorl> {
    match &flower.structure {
        Some(Structure::Whorls { whorls, .. }) => whorls.clone(),
        other => panic!("whorls expected: {other:?}"),
    }
}

#[test]
fn a_new_whorl_count_remakes_the_made_organs_and_keeps_the_listed_ones() {
    let flower = flower();
    assert_eq!(flower.made_organ_count(), 6);
    let mut whorls = whorls_of(&flower);
    whorls[0].count = 5;
    let edited = flower
        .with_structure(Some(Structure::Whorls {
            whorls,
            contorted: false,
        }))
        .unwrap();
    assert_eq!(
        names(&edited),
        [
            "petal-1", "petal-2", "petal-3", "petal-4", "petal-5", "sepal-1", "sepal-2", "sepal-3",
            "bract"
        ]
    );
    assert_eq!(edited.made_organ_count(), 8);
    // The listed rule follows its organs' names to their new indices.
    assert!(rule_names(&edited).contains(&("sepal-1".into(), "bract".into())));
    let origins = edited.rule_origins();
    assert_eq!(
        origins.iter().filter(|o| **o == RuleOrigin::Listed).count(),
        1
    );
    // Every other rule is a petal inside a sepal.
    for (rule, origin) in edited.overlaps.iter().zip(&origins) {
        if *origin == RuleOrigin::Made {
            assert!(rule.inner < 5 && (5..8).contains(&rule.outer), "{rule:?}");
        }
    }
    // The listed organ keeps its place.
    assert_eq!(edited.organs[8], flower.organs[6]);
}

#[test]
fn a_bad_l_system_is_refused_with_its_line_and_column_and_the_flower_stays() {
    let flower = flower();
    let bad = Structure::LSystem {
        text: "axiom: A\nA -> [/(0 B".to_string(),
        steps: 1,
        surfaces: BTreeMap::from([('a', 0)]),
        units: 1.0,
    };
    let err = flower.with_structure(Some(bad)).unwrap_err();
    assert!(
        matches!(
            err,
            EditError::Structure(StructureError::LSystem(LSystemError::Syntax {
                line: 2,
                column: 11,
                ..
            }))
        ),
        "{err:?}"
    );
    // A surface no template is given for.
    let unknown = Structure::LSystem {
        text: "axiom: ~q".to_string(),
        steps: 0,
        surfaces: BTreeMap::from([('a', 0)]),
        units: 1.0,
    };
    assert_eq!(
        flower.arranged_by(unknown).unwrap_err(),
        EditError::Structure(StructureError::UnknownSurface('q'))
    );
}

#[test]
fn the_l_system_like_the_whorls_places_the_same_organs_in_the_same_order_of_layers() {
    let flower = flower();
    let whorls = whorls_of(&flower);
    let (text, steps, surfaces) = lsystem_like(&whorls);
    let by_lsystem = flower
        .arranged_by(Structure::LSystem {
            text: text.clone(),
            steps,
            surfaces,
            units: 1.0,
        })
        .unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(by_lsystem.organs.len(), 6, "the listed bract is dropped");
    // Outermost first: the sepals, then the petals; each organ's points
    // land where the whorl puts them.
    let points = [
        DVec3::ZERO,
        DVec3::new(0.5, 3.0, 0.0),
        DVec3::new(-0.3, 1.0, 0.2),
    ];
    let sepals_then_petals = [3, 4, 5, 0, 1, 2];
    for (organ, &whorl_organ) in by_lsystem.organs.iter().zip(&sepals_then_petals) {
        let expected = &flower.organs[whorl_organ];
        assert_eq!(organ.template, expected.template);
        for p in points {
            let (a, b) = (
                organ.placement.world_from_template(p, 0.0),
                expected.placement.world_from_template(p, 0.0),
            );
            assert!(
                a.distance(b) < 1e-9,
                "{} vs {}: {a} {b}\n{text}",
                organ.name,
                expected.name
            );
        }
    }
    // Petals inside sepals, as the whorls have it (the L-system pairs
    // every petal with the sepals facing its way).
    for rule in &by_lsystem.overlaps {
        assert_eq!(by_lsystem.organs[rule.inner].template, 0);
        assert_eq!(by_lsystem.organs[rule.outer].template, 1);
    }
    assert!(!by_lsystem.overlaps.is_empty());
}

#[test]
fn swapping_a_rule_overrides_it_and_swapping_back_restores_the_made_one() {
    let flower = flower();
    let made = flower
        .rule_origins()
        .iter()
        .position(|o| *o == RuleOrigin::Made)
        .unwrap();
    let swapped = flower.with_rule_swapped(made).unwrap();
    let rule = flower.overlaps[made];
    let reversed = Overlap {
        inner: rule.outer,
        outer: rule.inner,
    };
    assert!(!swapped.overlaps.contains(&rule));
    let at = swapped
        .overlaps
        .iter()
        .position(|o| *o == reversed)
        .expect("the swapped rule");
    assert_eq!(swapped.rule_origins()[at], RuleOrigin::Overridden);
    assert_eq!(swapped.overlaps.len(), flower.overlaps.len());
    // As loading would make it from the structure and the listed rules.
    assert_eq!(
        swapped.with_structure(swapped.structure.clone()).unwrap(),
        swapped
    );
    // The override survives remaking the organs (a new whorl offset).
    let mut whorls = whorls_of(&swapped);
    whorls[1].offset_deg = 61.0;
    let remade = swapped
        .with_structure(Some(Structure::Whorls {
            whorls,
            contorted: false,
        }))
        .unwrap();
    let inner = &flower.organs[flower.overlaps[made].outer].name;
    let outer = &flower.organs[flower.overlaps[made].inner].name;
    assert!(rule_names(&remade).contains(&(inner.clone(), outer.clone())));
    let back = swapped.with_rule_swapped(at).unwrap();
    assert_eq!(back, flower);
    assert!(flower.with_rule_swapped(99).is_err());
}

#[test]
fn templates_and_organs_are_added_and_removed_with_their_whorls_and_rules() {
    let flower = flower();
    // A third template, its name made unique; an organ of it, listed.
    let added = flower.with_template(template("petal"));
    assert_eq!(added.templates[2].name, "petal 2");
    let organ = added.new_organ(2).unwrap();
    assert_eq!(organ.name, "petal 2-1");
    let with_organ = added.with_organ(organ).unwrap();
    assert_eq!(with_organ.organs.len(), 8);
    // Removing the sepal template removes its whorl and the bract (and
    // the bract's rule), and the third template becomes the second.
    let without = with_organ.without_template(1).unwrap();
    assert_eq!(
        names(&without),
        ["petal-1", "petal-2", "petal-3", "petal 2-1"]
    );
    assert_eq!(without.organs[3].template, 1);
    assert!(without.overlaps.is_empty());
    assert_eq!(whorls_of(&without).len(), 1);
    // A made organ cannot be removed on its own; a listed one can.
    assert_eq!(
        without.without_organ(0).unwrap_err(),
        EditError::MadeByStructure("petal-1".into())
    );
    let fewer = without.without_organ(3).unwrap();
    assert_eq!(names(&fewer), ["petal-1", "petal-2", "petal-3"]);
    // The template of the last organs, or the last template, cannot go.
    assert_eq!(fewer.without_template(0).unwrap_err(), EditError::NoOrgans);
    let one = fewer.without_template(1).unwrap();
    assert_eq!(one.templates.len(), 1);
    assert_eq!(one.organs, fewer.organs);
    assert_eq!(one.without_template(0).unwrap_err(), EditError::NoTemplates);
    let only_bract = flower.with_structure(None).unwrap();
    assert_eq!(only_bract.made_organ_count(), 0);
    assert_eq!(only_bract.organs, flower.organs, "all organs kept, listed");
    assert_eq!(only_bract.overlaps, flower.overlaps);
    // Two organs of one name are refused.
    let mut whorls = whorls_of(&flower);
    whorls[1].name = "petal".into();
    assert!(matches!(
        flower.with_structure(Some(Structure::Whorls {
            whorls,
            contorted: false
        })),
        Err(EditError::DuplicateOrgan(_))
    ));
}

#[test]
fn a_listed_organ_moved_keeps_its_rules() {
    let flower = flower();
    let mut bract = flower.organs[6].clone();
    bract.placement = Placement {
        joint_angle_deg: 30.0,
        ..bract.placement
    };
    bract.name = "bract A".into();
    let moved = flower.with_organ_changed(6, bract.clone()).unwrap();
    assert_eq!(moved.organs[6], bract);
    assert!(rule_names(&moved).contains(&("sepal-1".into(), "bract A".into())));
    assert!(flower.with_organ_changed(0, bract).is_err());
}

#[test]
fn a_spiral_like_the_whorls_holds_all_their_organs() {
    let flower = flower();
    let spiral = spiral_like(&whorls_of(&flower)).unwrap();
    let arranged = flower.arranged_by(Structure::Spiral(spiral)).unwrap();
    assert_eq!(arranged.organs.len(), 6);
    assert!(arranged.organs.iter().all(|o| o.template == 1));
}

#[test]
fn an_edited_flower_saves_and_loads_as_it_is() {
    // Swapped rules, a new whorl count and a listed organ: the file holds
    // the structure, the listed organ and the listed rules, and loading it
    // makes the same flower (organs and rules in the same order).
    let flower = flower();
    let made = flower
        .rule_origins()
        .iter()
        .position(|o| *o == RuleOrigin::Made)
        .unwrap();
    let mut whorls = whorls_of(&flower);
    whorls[0].count = 4;
    let edited = flower
        .with_rule_swapped(made)
        .unwrap()
        .with_structure(Some(Structure::Whorls {
            whorls,
            contorted: false,
        }))
        .unwrap();
    let project = crate::Project {
        name: "edited".to_string(),
        flower: edited,
        settings: crate::SimulationSettings::default(),
    };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("edited.anthesis.toml");
    crate::project::save_project(&project, &path).unwrap();
    let loaded = crate::project::load_project(&path).unwrap();
    assert_eq!(loaded.flower.organs, project.flower.organs);
    assert_eq!(loaded.flower.overlaps, project.flower.overlaps);
    assert_eq!(loaded.flower.structure, project.flower.structure);
}

#[test]
fn a_renamed_template_keeps_its_organs_and_an_l_system_s_organs_follow_the_name() {
    let flower = flower();
    let renamed = flower.with_template_renamed(1, "tepal").unwrap();
    assert_eq!(renamed.templates[1].name, "tepal");
    assert_eq!(
        renamed.organs, flower.organs,
        "whorl organs keep their names"
    );
    assert!(matches!(
        flower.with_template_renamed(1, "petal"),
        Err(EditError::TemplateName(_))
    ));
    assert!(flower.with_template_renamed(0, "  ").is_err());
    // An L-system names organs after their templates: `sepal-1` becomes
    // `tepal-1`, and a rule listed for it follows.
    let (text, steps, surfaces) = lsystem_like(&whorls_of(&flower));
    let by_lsystem = flower
        .arranged_by(Structure::LSystem {
            text,
            steps,
            surfaces,
            units: 1.0,
        })
        .unwrap();
    let sepal = by_lsystem.organ_index("sepal-1").unwrap();
    let petal = by_lsystem.organ_index("petal-1").unwrap();
    let rule = by_lsystem
        .overlaps
        .iter()
        .position(|o| o.inner == petal && o.outer == sepal)
        .expect("petal-1 inside sepal-1");
    let swapped = by_lsystem.with_rule_swapped(rule).unwrap();
    let renamed = swapped.with_template_renamed(1, "tepal").unwrap();
    let tepal = renamed.organ_index("tepal-1").unwrap();
    let petal = renamed.organ_index("petal-1").unwrap();
    assert!(renamed.overlaps.contains(&Overlap {
        inner: tepal,
        outer: petal
    }));
    assert!(!renamed.overlaps.contains(&Overlap {
        inner: petal,
        outer: tepal
    }));
}

#[test]
fn a_template_made_in_the_app_comes_with_one_organ_unless_its_mesh_is_in_another_unit() {
    let flower = flower();
    // 4 long on a thickness of 0.2: 20 thicknesses, a plausible organ.
    let added = flower.with_template_and_organ(template("petal")).unwrap();
    assert_eq!(added.templates.len(), 3);
    assert_eq!(added.templates[2].name, "petal 2");
    assert_eq!(added.organs.len(), flower.organs.len() + 1);
    let organ = added.organs.last().unwrap();
    assert_eq!(organ.template, 2);
    assert_eq!(organ.name, "petal 2-1");
    // Placed as new_organ places the first organ of a template: at the
    // distance of the farthest organ from the axis, facing +Z.
    let expected = added.new_organ(2).map(|o| o.placement);
    assert!(expected.is_some());
    let farthest = flower
        .organs
        .iter()
        .map(|o| o.placement.position.x.hypot(o.placement.position.z))
        .fold(0.0, f64::max);
    let p = organ.placement.position;
    assert!((p.x.hypot(p.z) - farthest).abs() < 1e-9);

    // The same mesh made in millimetres for a project in centimetres.
    let mut big = template("big");
    for p in &mut big.mesh.positions {
        *p *= 1000.0;
    }
    match flower.with_template_and_organ(big) {
        Err(EditError::Scale(mismatch)) => {
            assert_eq!(mismatch.template, "big");
            assert!(mismatch.to_string().contains("\"big\""), "{mismatch}");
        }
        other => panic!("expected a unit mismatch, got {other:?}"),
    }
}

#[test]
fn a_new_shape_keeps_the_maps_a_flipped_inner_side_and_the_vein_and_records_its_source() {
    let base = flower();
    let net = anthesis_bud::BezierPatch::petal();
    let made = anthesis_bud::build_organ(&net, &anthesis_bud::RemeshOptions::new(1.5))
        .unwrap()
        .mesh;
    let source = crate::TemplateSource::Bezier { net, edge: 1.5 };
    let reshaped = base.with_shape(0, made.clone(), source.clone()).unwrap();
    let template = &reshaped.templates[0];
    assert_eq!(template.mesh, made);
    assert_eq!(template.source, Some(source.clone()));
    assert_eq!(template.maps, base.templates[0].maps);
    assert_eq!(reshaped.templates[1], base.templates[1]);

    // A template whose inner side was flipped gets the new shape flipped.
    let mut flipped = base.clone();
    flipped.templates[0].mesh = anthesis_bud::with_inner_side_flipped(&base.templates[0].mesh);
    let reshaped = flipped.with_shape(0, made.clone(), source.clone()).unwrap();
    assert_eq!(
        reshaped.templates[0].mesh,
        anthesis_bud::with_inner_side_flipped(&made)
    );

    // A template with a vein gets the new shape bent along it.
    let mut veined = base.clone();
    let vein = anthesis_bud::Vein::new(
        &[
            glam::DVec2::ZERO,
            glam::DVec2::new(10.0, 3.0),
            glam::DVec2::new(18.0, 8.0),
        ],
        1.0,
    )
    .unwrap();
    veined.templates[0].vein = Some(vein.clone());
    let reshaped = veined.with_shape(0, made.clone(), source.clone()).unwrap();
    assert_eq!(
        reshaped.templates[0].mesh,
        anthesis_bud::bend_along_vein(&made, &vein).unwrap()
    );

    assert_eq!(
        base.with_shape(7, made, source).unwrap_err(),
        EditError::Missing {
            what: "template",
            index: 7
        }
    );
}

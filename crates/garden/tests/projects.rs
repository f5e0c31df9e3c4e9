//! The default projects: the committed files equal the builders, the
//! embedded copies equal the files, and the buds are what the paper used
//! and can be simulated (organs apart, overlap rules where they touch).

use std::path::PathBuf;

use anthesis_bud::{find_self_intersection, quality};
use anthesis_flower::Project;
use anthesis_flower::project::load_project;
use anthesis_garden::{
    FLOWER_NAMES, builtin, builtin_lily, builtin_names, flower_mesh, flowers, project_file_name,
};
use glam::DVec3;

fn committed(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets/flowers")
        .join(name)
        .join(project_file_name(name))
}

/// The folder names of the three Eustoma cultivars.
fn eustomas() -> Vec<&'static str> {
    anthesis_garden::Cultivar::ALL
        .iter()
        .map(|c| c.folder_name())
        .collect()
}

fn built(name: &str) -> Project {
    match flowers::flower(name) {
        Some(Ok(project)) => project,
        Some(Err(error)) => panic!("{name}: {error}"),
        None => panic!("no builder for {name}"),
    }
}

/// Each organ's bud positions in the world frame.
fn bud_positions(project: &Project) -> Vec<Vec<DVec3>> {
    project
        .flower
        .organs
        .iter()
        .enumerate()
        .map(|(i, organ)| {
            project
                .flower
                .template_of(i)
                .mesh
                .positions
                .iter()
                .map(|p| organ.placement.world_from_template(*p, 0.0))
                .collect()
        })
        .collect()
}

#[test]
fn committed_assets_equal_the_builders() {
    for name in FLOWER_NAMES {
        let path = committed(name);
        let loaded = load_project(&path).unwrap_or_else(|e| panic!("{e}"));
        assert!(
            loaded == built(name),
            "{} differs from what anthesis_garden::flowers builds; regenerate it with \
             `cargo run -p anthesis-garden --bin make-flowers`",
            path.display()
        );
    }
}

#[test]
fn embedded_flowers_equal_the_committed_files() {
    let mut names = builtin_names();
    names.sort_unstable();
    let mut expected = FLOWER_NAMES.to_vec();
    expected.sort_unstable();
    assert_eq!(names, expected);
    for name in FLOWER_NAMES {
        let embedded = builtin(name)
            .expect("built in")
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let loaded = load_project(&committed(name)).unwrap_or_else(|e| panic!("{e}"));
        assert!(embedded == loaded, "embedded {name} differs from its files");
    }
    let lily = builtin_lily().expect("the lily is built in");
    assert_eq!(lily.name, "Asiatic lily");
    assert_eq!(lily.flower.organs.len(), 6);
    assert!(builtin("rose").is_none());
}

/// The default flower `name` meshed at `edge_scale` times Table 1's edge.
fn built_at(name: &str, edge_scale: f64) -> Project {
    match flowers::flower_at_resolution(name, edge_scale) {
        Some(Ok(project)) => project,
        Some(Err(error)) => panic!("{name}: {error}"),
        None => panic!("no builder for {name}"),
    }
}

#[test]
fn buds_meshed_at_the_papers_edge_have_about_its_particle_counts() {
    let near = |found: usize, paper: usize| {
        let (found, paper) = (found as f64, paper as f64);
        (found - paper).abs() <= 0.05 * paper
    };
    // Paper §6.3: lily petal 388 particles / 685 triangles / 1082 edges,
    // sepal 323 / 567 / 889; Eustoma petal 261 / 458 / 718.
    let lily = built_at("lily", 1.0);
    for (template, counts, edge) in [(0, [388, 685, 1082], 1.3), (1, [323, 567, 889], 1.4)] {
        let q = quality(&lily.flower.templates[template].mesh);
        assert!(
            near(q.vertices, counts[0]),
            "lily template {template}: {q:?}"
        );
        assert!(
            near(q.triangles, counts[1]),
            "lily template {template}: {q:?}"
        );
        assert!(near(q.edges, counts[2]), "lily template {template}: {q:?}");
        assert!((q.mean_edge - edge).abs() < 0.05 * edge, "{q:?}");
        assert!(q.min_angle_deg > 30.0, "{q:?}");
    }
    for name in eustomas() {
        let q = quality(&built_at(name, 1.0).flower.templates[0].mesh);
        assert!(near(q.vertices, 261), "{name}: {q:?}");
        assert!(near(q.triangles, 458), "{name}: {q:?}");
        assert!(near(q.edges, 718), "{name}: {q:?}");
        assert!((q.mean_edge - 2.0).abs() < 0.1, "{q:?}");
    }
}

#[test]
fn the_default_flowers_are_meshed_finer_than_the_paper_for_converged_shapes() {
    // EDGE_SCALE of Table 1's edge (see its documentation for the
    // refinement study behind it), same bud surfaces; lily-edge finer, to
    // resolve its thin sheet (LILY_EDGE_SCALE).
    for name in FLOWER_NAMES {
        let scale = if name == anthesis_garden::edge::LILY_EDGE_NAME {
            anthesis_garden::edge::LILY_EDGE_SCALE
        } else {
            flowers::EDGE_SCALE
        };
        let default = built(name);
        let paper = built_at(name, 1.0);
        for (mine, theirs) in default.flower.templates.iter().zip(&paper.flower.templates) {
            let (mine, theirs) = (quality(&mine.mesh), quality(&theirs.mesh));
            let ratio = mine.mean_edge / theirs.mean_edge;
            assert!(
                (ratio - scale).abs() < 0.05,
                "{name}: edge {:.3} vs the paper's {:.3}",
                mine.mean_edge,
                theirs.mean_edge
            );
            // Well shaped: no sliver (the Eustoma petal's worst is about 24°).
            assert!(mine.min_angle_deg > 20.0, "{name}: {mine:?}");
        }
    }
}

#[test]
fn the_three_cultivars_share_one_bud_and_differ_in_their_maps() {
    let projects: Vec<Project> = eustomas().iter().map(|n| built(n)).collect();
    for other in &projects[1..] {
        assert_eq!(
            other.flower.templates[0].mesh,
            projects[0].flower.templates[0].mesh
        );
        assert_eq!(other.flower.organs, projects[0].flower.organs);
        assert_eq!(other.flower.overlaps, projects[0].flower.overlaps);
        assert_ne!(
            other.flower.templates[0].maps,
            projects[0].flower.templates[0].maps
        );
    }
    assert_ne!(
        projects[1].flower.templates[0].maps,
        projects[2].flower.templates[0].maps
    );
}

#[test]
fn bud_organs_do_not_cut_through_each_other() {
    for name in FLOWER_NAMES {
        let project = built(name);
        assert_eq!(
            find_self_intersection(&flower_mesh(&project, &bud_positions(&project)).0),
            None,
            "{name}: organs intersect in the bud"
        );
    }
}

/// How many particles of organ `a` lie over or under organ `b`, the way the
/// collision handling sees it: the nearest particle of `b` is within two
/// mean edges and the offset to it runs along `b`'s normal (at most one
/// mean edge sideways).
fn particles_over(a: &[DVec3], b: &[DVec3], b_triangles: &[[u32; 3]], mean_edge: f64) -> usize {
    let normals = anthesis_mesh::vertex_normals(b, b_triangles);
    a.iter()
        .filter(|p| {
            let Some((q, n)) = b
                .iter()
                .zip(&normals)
                .min_by(|x, y| x.0.distance(**p).total_cmp(&y.0.distance(**p)))
            else {
                return false;
            };
            let d = **p - *q;
            let lateral = (d - *n * d.dot(*n)).length();
            d.length() <= 2.0 * mean_edge && lateral <= mean_edge
        })
        .count()
}

#[test]
fn overlap_rules_pair_exactly_the_organs_whose_margins_overlap() {
    for name in FLOWER_NAMES {
        let project = built(name);
        let positions = bud_positions(&project);
        let n = positions.len();
        for a in 0..n {
            for b in a + 1..n {
                let paired = project
                    .flower
                    .overlaps
                    .iter()
                    .any(|o| (o.inner, o.outer) == (a, b) || (o.inner, o.outer) == (b, a));
                let mesh_b = &project.flower.template_of(b).mesh;
                let mean_edge = quality(mesh_b).mean_edge;
                let over =
                    particles_over(&positions[a], &positions[b], &mesh_b.triangles, mean_edge);
                // An L-system pairs every organ with the earlier layers'
                // organs facing within 90° of it (pairs that never meet
                // cost nothing); whorls pair exactly the overlapping ones.
                let made_by_lsystem = matches!(
                    project.flower.structure,
                    Some(anthesis_flower::structure::Structure::LSystem { .. })
                );
                if paired && !made_by_lsystem {
                    assert!(
                        over >= 20,
                        "{name}: organs {a} and {b} are paired but only {over} particles overlap"
                    );
                } else if !paired {
                    // Organs side by side in one whorl may meet at the very tip.
                    assert!(
                        over <= 3,
                        "{name}: organs {a} and {b} are not paired but {over} particles overlap"
                    );
                }
            }
        }
        let inner_outer: Vec<(usize, usize)> = project
            .flower
            .overlaps
            .iter()
            .map(|o| (o.inner, o.outer))
            .collect();
        if name == "apple" {
            // Calyx c and petal p of segment k are organs 2k and 2k + 1:
            // each petal lies inside the lobe of its own segment, which
            // covers it.
            for k in 0..6 {
                assert!(inner_outer.contains(&(2 * k + 1, 2 * k)), "{inner_outer:?}");
                let mesh = &project.flower.template_of(2 * k).mesh;
                let over = particles_over(
                    &positions[2 * k + 1],
                    &positions[2 * k],
                    &mesh.triangles,
                    quality(mesh).mean_edge,
                );
                assert!(
                    over >= 20,
                    "apple segment {k}: only {over} particles overlap"
                );
            }
            assert!(inner_outer.iter().all(|&(i, o)| i % 2 == 1 && o % 2 == 0));
        } else if name == "lily" {
            // Petals (0–2) inside sepals (3–5), each petal under two sepals.
            assert_eq!(inner_outer.len(), 6);
            assert!(inner_outer.iter().all(|&(i, o)| i < 3 && o >= 3));
        } else if eustomas().contains(&name) {
            assert_eq!(inner_outer, [(0, 1), (1, 2), (2, 3), (3, 4), (4, 0)]);
        } else if name == anthesis_garden::five_petal::FIVE_PETAL_NAME {
            // Five petals side by side: none lies over another.
            assert!(inner_outer.is_empty(), "{inner_outer:?}");
        }
    }
}

#[test]
fn inner_organs_lie_inside_outer_ones_where_they_overlap() {
    // Where a paired organ's particle is near the other organ, it is on the
    // side the rule asks for, so the simulation starts without contacts.
    for name in FLOWER_NAMES {
        let project = built(name);
        let positions = bud_positions(&project);
        for overlap in &project.flower.overlaps {
            let outer_mesh = &project.flower.template_of(overlap.outer).mesh;
            let outer = &positions[overlap.outer];
            let normals = anthesis_mesh::vertex_normals(outer, &outer_mesh.triangles);
            let mut checked = 0;
            for p in &positions[overlap.inner] {
                let Some((q, normal)) = outer
                    .iter()
                    .zip(&normals)
                    .filter(|(q, _)| q.distance(*p) < 3.0)
                    .min_by(|x, y| x.0.distance(*p).total_cmp(&y.0.distance(*p)))
                else {
                    continue;
                };
                checked += 1;
                assert!(
                    (*p - *q).dot(*normal) > 0.0,
                    "{name}: a particle of organ {} is outside organ {} at {p}",
                    overlap.inner,
                    overlap.outer
                );
            }
            assert!(checked > 0, "{name}: {overlap:?} never meet");
        }
    }
}

#[test]
fn the_five_petal_start_is_one_whorl_of_five_petals_as_structure() {
    use anthesis_flower::structure::Structure;
    let project = built(anthesis_garden::five_petal::FIVE_PETAL_NAME);
    assert_eq!(project.flower.templates.len(), 1);
    assert_eq!(project.flower.organs.len(), 5);
    let Some(Structure::Whorls { whorls, contorted }) = &project.flower.structure else {
        panic!("made by a whorl: {:?}", project.flower.structure);
    };
    assert!(!contorted);
    assert_eq!(whorls.len(), 1);
    assert_eq!(whorls[0].count, 5);
    // Narrower than the gap between neighbours: no overlap rules needed.
    assert!(
        whorls[0].half_span_deg < 36.0,
        "{}",
        whorls[0].half_span_deg
    );
    // Uniform maps: one key of constant maps.
    let maps = &project.flower.templates[0].maps;
    assert_eq!(maps.keys().len(), 1);
    assert_eq!(maps.raster_size(), None);
    let q = quality(&project.flower.templates[0].mesh);
    assert!(
        (100..=600).contains(&q.vertices),
        "a petal of a few hundred particles: {q:?}"
    );
    assert!(q.min_angle_deg > 20.0, "{q:?}");
}

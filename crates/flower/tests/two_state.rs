//! `[templates.two_state]` (format version 7): a template animated from
//! its bud to an open shape saved beside its mesh, read back equal, and
//! refused with a message naming the template and the file when the open
//! shape is not the template mesh moved.

use std::fs;

use anthesis_flower::project::{FORMAT_VERSION, ProjectError, load_project, save_project};
use anthesis_flower::{
    BaseRegion, Flower, Organ, Placement, Project, SimulationSettings, Template, TwoStateAnimation,
};
use anthesis_maps::{Blend, GrowthMaps, KeyedMaps, MapKey};
use anthesis_mesh::generate::test_petal;
use anthesis_twostate::{GrowthFunction, VelocityCurve};
use glam::DVec3;

fn template(name: &str) -> Template {
    Template {
        name: name.to_string(),
        mesh: test_petal(4.0, 1.5, 4, 6),
        maps: KeyedMaps::new(vec![MapKey::new(0, GrowthMaps::uniform())], Blend::Linear)
            .expect("one key"),
        dg: 0.002,
        thickness: 0.3,
        stretch_stiffness: 20.0,
        bend_stiffness: 20.0,
        base_region: BaseRegion {
            v_max: 0.25,
            ..BaseRegion::default()
        },
        joint_schedule: Vec::new(),
        colour: [0.9, 0.5, 0.6, 1.0],
        colouring: None,
        source: None,
        vein: None,
        two_state: None,
    }
}

/// A petal that opens by two states and a sepal that grows.
fn project(velocity: VelocityCurve) -> Project {
    let mut petal = template("petal");
    let open = petal
        .mesh
        .positions
        .iter()
        .zip(&petal.mesh.uvs)
        .map(|(p, uv)| *p + DVec3::new(0.0, 0.0, 0.7 * uv.y * uv.y) + 0.1 * DVec3::X * uv.x)
        .collect();
    petal.two_state = Some(TwoStateAnimation {
        open,
        growth: GrowthFunction {
            g: 5.5,
            duration: 40.0,
        },
        velocity,
    });
    let organ = |name: &str, template: usize, azimuth_deg: f64| Organ {
        name: name.to_string(),
        template,
        placement: Placement {
            position: DVec3::ZERO,
            azimuth_deg,
            joint_angle_deg: 5.0,
            orientation: glam::DQuat::IDENTITY,
        },
    };
    Project {
        name: "two states".to_string(),
        flower: Flower {
            templates: vec![petal, template("sepal")],
            organs: vec![organ("petal-1", 0, 0.0), organ("sepal-1", 1, 180.0)],
            overlaps: Vec::new(),
            structure: None,
            parts: Vec::new(),
            unit: None,
        },
        settings: SimulationSettings {
            keyframes: 50,
            ..SimulationSettings::default()
        },
    }
}

#[test]
fn a_two_state_template_saves_its_open_shape_beside_its_mesh_and_loads_equal() {
    for velocity in [
        VelocityCurve::FollowGrowth,
        VelocityCurve::Points(vec![[0.0, 0.0], [0.3, 0.6], [1.0, 1.0]]),
    ] {
        let folder = tempfile::tempdir().expect("temp dir");
        let path = folder.path().join("p.anthesis.toml");
        let project = project(velocity);
        save_project(&project, &path).expect("saves");
        let text = fs::read_to_string(&path).expect("read");
        // The oldest version that has the table.
        assert!(text.contains("version = 7\n"), "{text}");
        assert!(text.contains("[templates.two_state]"), "{text}");
        assert!(
            text.contains("open_mesh = \"meshes/petal.open.obj\""),
            "{text}"
        );
        assert!(folder.path().join("meshes/petal.open.obj").is_file());
        assert!(!folder.path().join("meshes/sepal.open.obj").exists());
        let loaded = load_project(&path).expect("loads");
        assert_eq!(loaded, project);
    }
}

#[test]
fn a_project_without_two_states_still_writes_an_older_version() {
    let mut project = project(VelocityCurve::FollowGrowth);
    project.flower.templates[0].two_state = None;
    let folder = tempfile::tempdir().expect("temp dir");
    let path = folder.path().join("p.anthesis.toml");
    save_project(&project, &path).expect("saves");
    let text = fs::read_to_string(&path).expect("read");
    assert!(!text.contains("two_state"), "{text}");
    assert!(text.contains("version = 2"), "{text}");
}

fn saved() -> (tempfile::TempDir, std::path::PathBuf) {
    let folder = tempfile::tempdir().expect("temp dir");
    let path = folder.path().join("p.anthesis.toml");
    save_project(&project(VelocityCurve::FollowGrowth), &path).expect("saves");
    (folder, path)
}

fn invalid_message(path: &std::path::Path) -> String {
    match load_project(path) {
        Err(ProjectError::Invalid { message, .. }) => message,
        other => panic!("expected an invalid project, got {other:?}"),
    }
}

#[test]
fn an_open_shape_of_another_mesh_is_refused_naming_the_template_and_the_file() {
    // Another vertex count.
    let (folder, path) = saved();
    let other = test_petal(4.0, 1.5, 5, 6);
    fs::write(
        folder.path().join("meshes/petal.open.obj"),
        anthesis_mesh::obj_string(&other),
    )
    .expect("write");
    let message = invalid_message(&path);
    assert!(message.contains("template \"petal\""), "{message}");
    assert!(message.contains("petal.open.obj"), "{message}");
    assert!(message.contains("vertices"), "{message}");

    // Same vertices, other triangles.
    let (folder, path) = saved();
    let mut flipped = test_petal(4.0, 1.5, 4, 6);
    flipped.triangles[3].rotate_left(1);
    fs::write(
        folder.path().join("meshes/petal.open.obj"),
        anthesis_mesh::obj_string(&flipped),
    )
    .expect("write");
    let message = invalid_message(&path);
    assert!(message.contains("template \"petal\""), "{message}");
    assert!(message.contains("triangle 4"), "{message}");
}

#[test]
fn bad_timing_numbers_are_refused_and_say_which() {
    for (from, to, says) in [
        ("g = 5.5", "g = -1.0", "g must be a positive number"),
        (
            "duration = 40.0",
            "duration = 0.0",
            "duration (T, in keyframes)",
        ),
        (
            "duration = 40.0",
            "duration = 40.0\nvelocity = [[0.5, 0.0], [0.2, 1.0]]",
            "point 2 of the velocity curve",
        ),
    ] {
        let (_folder, path) = saved();
        let text = fs::read_to_string(&path).expect("read");
        assert!(text.contains(from), "{text}");
        fs::write(&path, text.replacen(from, to, 1)).expect("write");
        let message = invalid_message(&path);
        assert!(message.contains("template \"petal\""), "{message}");
        assert!(message.contains(says), "{to}: {message}");
    }
}

#[test]
fn a_version_6_reader_would_refuse_the_table_so_the_version_is_7() {
    // The table in a file that says version 6 is still read (a newer build
    // reads older versions), but a version 6 build refuses an unknown
    // field: a file with the table must say 7, which such a build refuses
    // as newer rather than as broken.
    let (_folder, path) = saved();
    let text = fs::read_to_string(&path).expect("read");
    let newer = FORMAT_VERSION + 1;
    fs::write(
        &path,
        text.replacen("version = 7", &format!("version = {newer}"), 1),
    )
    .expect("write");
    assert!(matches!(
        load_project(&path),
        Err(ProjectError::NewerVersion { found, .. }) if found == i64::from(newer)
    ));
}

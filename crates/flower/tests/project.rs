//! The project file format: saving and loading real files, and the errors
//! for broken ones.

use std::collections::HashMap;
use std::fs;
use std::io;
use std::path::{Path, PathBuf};

use anthesis_flower::project::{
    FORMAT_VERSION, ProjectError, UNNAMED_PROJECT, load_project, parse_project, project_to_toml,
    save_project,
};
use anthesis_flower::structure::{Spiral, Structure, Whorl};
use anthesis_flower::{
    BaseRegion, ColourLayer, Colouring, Flower, JointRamp, Organ, Overlap, Placement, Project,
    Resolution, SimulationSettings, Template,
};
use anthesis_maps::{
    BitDepth, Blend, DirectionMap, GrowthMaps, KeyedMaps, MapError, MapKey, MapKind, ScalarMap,
};
use anthesis_mesh::MeshError;
use anthesis_mesh::generate::test_petal;
use anthesis_physics::{Model, SolverSettings};
use glam::{DVec2, DVec3};

/// A value a 16-bit greyscale PNG holds exactly, as the map loader reads it.
fn grey16(value: f64) -> f32 {
    let code = (value.clamp(0.0, 1.0) * 65535.0).round() as u16;
    f32::from(code) / 65535.0
}

/// A direction component a 16-bit PNG holds exactly, as the loader reads it.
fn signed16(value: f64) -> f32 {
    let code = (32768.0 + value.clamp(-1.0, 1.0) * 32767.0).round() as u16;
    (f32::from(code) - 32768.0) / 32767.0
}

/// A scalar raster whose values survive a 16-bit PNG exactly.
fn exact_raster(width: u32, height: u32, value_at: impl Fn(DVec2) -> f64) -> ScalarMap {
    ScalarMap::from_fn(width, height, |uv| grey16(value_at(uv)))
}

fn petal_template() -> Template {
    let early = GrowthMaps {
        e_growth: exact_raster(8, 6, |uv| 0.2 + 0.7 * uv.y),
        w_growth: ScalarMap::constant(0.2),
        e_growth_in: exact_raster(8, 6, |uv| (uv.x - 0.5).abs() + 0.3 * uv.y),
        w_growth_in: ScalarMap::constant(0.35),
        stretch: ScalarMap::constant(1.0),
        bend: exact_raster(8, 6, |uv| 1.0 - 0.5 * uv.y),
        direction: DirectionMap::from_fn(8, 6, |uv| {
            let direction = DVec2::new(0.4 * (uv.x - 0.5), 0.9);
            DVec2::new(
                f64::from(signed16(direction.x)),
                f64::from(signed16(direction.y)),
            )
        }),
    };
    let late = GrowthMaps {
        e_growth: ScalarMap::constant(0.05),
        w_growth: ScalarMap::constant(0.0),
        e_growth_in: exact_raster(8, 6, |uv| 0.1 * uv.x),
        w_growth_in: ScalarMap::constant(0.0),
        stretch: ScalarMap::constant(1.5),
        bend: ScalarMap::constant(2.0),
        direction: DirectionMap::constant(DVec2::new(0.25, 0.75)),
    };
    let maps = KeyedMaps::new(
        vec![
            MapKey {
                dg: None,
                step: 50,
                maps: late,
            },
            MapKey {
                dg: None,
                step: 0,
                maps: early,
            },
        ],
        Blend::Smooth,
    )
    .expect("two keys at distinct steps");
    Template {
        name: "Petal".to_string(),
        mesh: test_petal(10.0, 4.0, 6, 9),
        maps,
        dg: 0.003,
        thickness: 0.2,
        stretch_stiffness: 20.0,
        bend_stiffness: 18.5,
        base_region: BaseRegion {
            v_max: 0.06,
            u_min: 0.1,
            u_max: 0.9,
        },
        joint_schedule: vec![
            JointRamp {
                from_step: 0,
                to_step: 60,
                angle_deg: 23.0,
            },
            JointRamp {
                from_step: 70,
                to_step: 90,
                angle_deg: -4.5,
            },
        ],
        colour: [0.98, 0.62, 0.32, 1.0],
        colouring: None,
        two_state: None,
        source: None,
        vein: None,
    }
}

fn sepal_template() -> Template {
    let mut maps = GrowthMaps::uniform();
    maps.e_growth = ScalarMap::constant(0.4);
    maps.direction = DirectionMap::constant(DVec2::new(-0.1, 1.0));
    Template {
        name: "Outer sepal".to_string(),
        mesh: test_petal(12.0, 3.0, 5, 7),
        maps: KeyedMaps::new(
            vec![MapKey {
                dg: None,
                step: 10,
                maps,
            }],
            Blend::Logistic { steepness: 7.5 },
        )
        .expect("one key"),
        dg: -0.001,
        thickness: 0.35,
        stretch_stiffness: 30.0,
        bend_stiffness: 25.0,
        base_region: BaseRegion::default(),
        joint_schedule: Vec::new(),
        colour: [0.3, 0.55, 0.2, 0.9],
        colouring: None,
        two_state: None,
        source: None,
        vein: None,
    }
}

fn lily() -> Project {
    let organ = |name: &str, template, azimuth_deg: f64, joint_angle_deg| Organ {
        name: name.to_string(),
        template,
        placement: Placement {
            position: DVec3::new(
                0.8 * azimuth_deg.to_radians().sin(),
                0.1,
                0.8 * azimuth_deg.to_radians().cos(),
            ),
            azimuth_deg,
            joint_angle_deg,
            orientation: glam::DQuat::IDENTITY,
        },
    };
    Project {
        name: "Asiatic lily \"test\"".to_string(),
        flower: Flower {
            templates: vec![petal_template(), sepal_template()],
            organs: vec![
                organ("petal-1", 0, 0.0, 10.0),
                organ("petal-2", 0, 120.0, 10.0),
                organ("sepal-1", 1, 60.0, 12.5),
            ],
            overlaps: vec![Overlap { inner: 0, outer: 2 }],
            structure: None,
            parts: Vec::new(),
            unit: None,
        },
        settings: SimulationSettings {
            keyframes: 80,
            solver: SolverSettings {
                relative_tolerance: 1e-7,
                max_iterations: 40,
            },
            collision_offset: 0.02,
            ..SimulationSettings::default()
        },
    }
}

/// The lily saved in a fresh folder: the folder (kept alive) and the file.
fn saved_lily() -> (tempfile::TempDir, PathBuf) {
    let folder = tempfile::tempdir().expect("temp dir");
    let path = folder.path().join("lily").join("lily.anthesis.toml");
    save_project(&lily(), &path).expect("the lily saves");
    (folder, path)
}

/// Rewrites the project file with `edit` applied to its text.
fn edit(path: &Path, edit: impl Fn(String) -> String) {
    let text = fs::read_to_string(path).expect("read project");
    let edited = edit(text.clone());
    assert_ne!(edited, text, "the edit changed nothing");
    fs::write(path, edited).expect("write project");
}

fn replace_once(text: String, from: &str, to: &str) -> String {
    assert!(text.contains(from), "`{from}` not in\n{text}");
    text.replacen(from, to, 1)
}

/// All files under `folder`, by path relative to it, with their bytes.
fn files_under(folder: &Path) -> HashMap<PathBuf, Vec<u8>> {
    let mut files = HashMap::new();
    let mut pending = vec![folder.to_path_buf()];
    while let Some(current) = pending.pop() {
        for entry in fs::read_dir(&current).expect("list folder") {
            let path = entry.expect("entry").path();
            if path.is_dir() {
                pending.push(path);
            } else {
                let relative = path.strip_prefix(folder).expect("inside").to_path_buf();
                files.insert(relative, fs::read(&path).expect("read file"));
            }
        }
    }
    files
}

#[test]
fn a_project_states_its_unit_or_keeps_the_old_meaning() {
    let (_folder, path) = saved_lily();
    let loaded = anthesis_flower::project::load_project_with_warnings(&path).expect("loads");
    assert_eq!(loaded.project.flower.unit, None);
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    // A unit is saved (as version 9) and read back as written.
    let mut project = lily();
    project.flower.unit = anthesis_flower::Unit::millimetres(1.8);
    save_project(&project, &path).expect("saves");
    let text = fs::read_to_string(&path).expect("read");
    assert!(
        text.contains("version = 9\nname = 'Asiatic lily \"test\"'\nunit = \"1.8 mm\"\n"),
        "{text}"
    );
    let loaded = anthesis_flower::project::load_project_with_warnings(&path).expect("loads");
    assert_eq!(loaded.project, project);
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    // A colour layer on one side is saved with its side.
    let mut colouring = project.flower.templates[0].colouring_to_paint().clone();
    colouring.layers.push(ColourLayer {
        colour: [0.5, 0.0, 0.1, 1.0],
        mix: exact_raster(4, 4, |uv| uv.y),
        side: anthesis_flower::Side::Inner,
    });
    project.flower.templates[0].colouring = Some(colouring);
    save_project(&project, &path).expect("saves");
    let text = fs::read_to_string(&path).expect("read");
    assert!(text.contains("side = \"inner\""), "{text}");
    assert_eq!(load_project(&path).expect("loads"), project);
    // What is not a length is refused, naming the field.
    edit(&path, |t| {
        replace_once(t, "unit = \"1.8 mm\"", "unit = \"1.8 furlongs\"")
    });
    let error = load_project(&path).expect_err("not a unit").to_string();
    assert!(
        error.contains("unit: `1.8 furlongs` is not a length"),
        "{error}"
    );
}

#[test]
fn saving_then_loading_gives_an_equal_project() {
    let (_folder, path) = saved_lily();
    let loaded = load_project(&path).expect("the saved lily loads");
    assert_eq!(loaded, lily());
}

#[test]
fn saved_files_have_stable_names_and_constants_stay_numbers() {
    let (_folder, path) = saved_lily();
    let project_folder = path.parent().expect("folder");
    let mut names: Vec<String> = files_under(project_folder)
        .keys()
        .map(|p| p.to_string_lossy().replace('\\', "/"))
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "lily.anthesis.toml",
            "maps/petal-step0-bend.png",
            "maps/petal-step0-direction.png",
            "maps/petal-step0-e_growth.png",
            "maps/petal-step0-e_growth_in.png",
            "maps/petal-step50-e_growth_in.png",
            "meshes/outer_sepal.obj",
            "meshes/petal.obj",
        ]
    );
    let text = fs::read_to_string(&path).expect("read");
    for line in [
        "format = \"anthesis-project\"",
        "version = 2",
        "w_growth = 0.2",
        "direction = [0.25, 0.75]",
        "e_growth = \"maps/petal-step0-e_growth.png\"",
        "mesh = \"meshes/outer_sepal.obj\"",
        "blend = \"smooth\"",
    ] {
        assert!(
            text.lines().any(|l| l.trim() == line),
            "no line `{line}` in\n{text}"
        );
    }
    // Keys come out in step order.
    let first = text.find("step = 0").expect("key at step 0");
    let second = text.find("step = 50").expect("key at step 50");
    assert!(first < second);
    // The saved maps are 16-bit PNGs.
    let bytes = fs::read(project_folder.join("maps/petal-step0-e_growth.png")).expect("read");
    assert_eq!(bytes[24], 16, "bit depth byte of the IHDR chunk");
    assert_eq!(
        project_to_toml(&lily(), &path).expect("same text"),
        text,
        "project_to_toml gives the text save_project writes"
    );
}

#[test]
fn arbitrary_map_values_are_quantised_once_and_saves_are_stable() {
    let mut project = lily();
    let key_maps = &mut project.flower.templates[0].maps.keys_mut()[0].maps;
    key_maps.e_growth = ScalarMap::from_fn(8, 6, |uv| (0.123_456_7 + 0.5 * uv.x * uv.y) as f32);
    key_maps.direction = DirectionMap::from_fn(8, 6, |uv| DVec2::new(0.333 * uv.x, -0.777));
    let original_e_growth = key_maps.e_growth.clone();

    let folder = tempfile::tempdir().expect("temp dir");
    let first_path = folder.path().join("a").join("p.anthesis.toml");
    save_project(&project, &first_path).expect("save");
    let loaded = load_project(&first_path).expect("load");
    let loaded_e_growth = &loaded.flower.templates[0].maps.keys()[0].maps.e_growth;
    for (saved, read) in original_e_growth
        .values()
        .iter()
        .zip(loaded_e_growth.values())
    {
        assert!(
            (saved - read).abs() <= 0.5 / 65535.0 + 1e-7,
            "{saved} vs {read}"
        );
    }

    let second_path = folder.path().join("b").join("p.anthesis.toml");
    save_project(&loaded, &second_path).expect("save again");
    assert_eq!(
        files_under(first_path.parent().expect("a")),
        files_under(second_path.parent().expect("b")),
        "saving what was loaded writes the same bytes"
    );
    assert_eq!(load_project(&second_path).expect("load again"), loaded);
}

#[test]
fn saving_over_a_project_replaces_it() {
    let (_folder, path) = saved_lily();
    let mut project = lily();
    project.name = "Renamed".to_string();
    project.flower.templates[0].thickness = 0.25;
    save_project(&project, &path).expect("save over");
    assert_eq!(load_project(&path).expect("load"), project);
    let leftovers: Vec<_> = fs::read_dir(path.parent().expect("folder"))
        .expect("list")
        .map(|entry| {
            entry
                .expect("entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .filter(|name| name.ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn saving_over_a_project_can_keep_the_previous_version_as_a_backup() {
    let (_folder, path) = saved_lily();
    let before = load_project(&path).expect("load");
    let mut project = lily();
    project.name = "Renamed".to_string();
    project.flower.templates[0].thickness = 0.25;
    let backup = anthesis_flower::project::keep_backup(&path)
        .expect("backup")
        .expect("there was a project");
    save_project(&project, &path).expect("save over");
    assert_eq!(
        backup,
        path.parent()
            .expect("folder")
            .join("backup/lily.anthesis.toml")
    );
    assert_eq!(load_project(&backup).expect("the backup loads"), before);
    assert_eq!(load_project(&path).expect("load"), project);

    // The next save keeps the version just replaced, not the first.
    let mut third = project.clone();
    third.name = "Third".to_string();
    anthesis_flower::project::keep_backup(&path).expect("backup");
    save_project(&third, &path).expect("save over");
    assert_eq!(load_project(&backup).expect("load").name, "Renamed");

    // A file that no longer loads is kept as it is.
    fs::write(&path, "format = \"anthesis-project\"\nversion = ").expect("write");
    anthesis_flower::project::keep_backup(&path).expect("backup");
    assert_eq!(
        fs::read_to_string(&backup).expect("read"),
        "format = \"anthesis-project\"\nversion = "
    );
    // Nothing to keep for a new file.
    assert_eq!(
        anthesis_flower::project::keep_backup(&path.with_file_name("new.anthesis.toml")),
        Ok(None)
    );
}

#[test]
fn a_truncated_file_is_a_syntax_error_naming_the_file() {
    let (_folder, path) = saved_lily();
    edit(&path, |text| {
        let mut half = text.len() / 2;
        while !text.is_char_boundary(half) {
            half -= 1;
        }
        text[..half].to_string()
    });
    let error = load_project(&path).expect_err("truncated");
    assert!(matches!(error, ProjectError::Syntax { .. }), "{error:?}");
    let message = error.to_string();
    assert!(message.contains("lily.anthesis.toml"), "{message}");
    assert!(message.contains("line"), "{message}");
}

#[test]
fn a_file_cut_inside_a_string_is_a_syntax_error() {
    let (_folder, path) = saved_lily();
    edit(&path, |text| {
        let cut = text.find("meshes/petal").expect("mesh path");
        text[..cut].to_string()
    });
    let error = load_project(&path).expect_err("truncated");
    assert!(matches!(error, ProjectError::Syntax { .. }), "{error:?}");
}

#[test]
fn an_unknown_field_is_named_with_its_line() {
    let (_folder, path) = saved_lily();
    edit(&path, |text| {
        replace_once(text, "dg = ", "colour = [1, 0, 0]\ndg = ")
    });
    let error = load_project(&path).expect_err("unknown field");
    assert!(matches!(error, ProjectError::Syntax { .. }), "{error:?}");
    let message = error.to_string();
    assert!(message.contains("unknown field `colour`"), "{message}");
    assert!(message.contains("lily.anthesis.toml"), "{message}");
    assert!(message.contains("line"), "{message}");
}

#[test]
fn an_unknown_field_in_a_key_or_blend_is_refused() {
    let (_folder, path) = saved_lily();
    edit(&path, |text| {
        replace_once(text, "step = 50", "step = 50\nbend_in = 0.5")
    });
    let message = load_project(&path).expect_err("unknown").to_string();
    assert!(message.contains("bend_in"), "{message}");

    let (_folder, path) = saved_lily();
    edit(&path, |text| {
        replace_once(text, "steepness = 7.5", "steepness = 7.5, slope = 2")
    });
    let message = load_project(&path).expect_err("unknown").to_string();
    assert!(message.contains("slope"), "{message}");
}

#[test]
fn a_newer_version_says_so() {
    let (_folder, path) = saved_lily();
    // A newer version may have fields this build does not know: the version
    // error must win over the unknown field.
    edit(&path, |text| {
        replace_once(
            text,
            "version = 2",
            &format!("version = {}\nwind = \"strong\"", FORMAT_VERSION + 1),
        )
    });
    let error = load_project(&path).expect_err("newer");
    assert_eq!(
        error,
        ProjectError::NewerVersion {
            path: path.clone(),
            found: i64::from(FORMAT_VERSION) + 1,
            supported: FORMAT_VERSION,
        }
    );
    assert_eq!(
        error.to_string(),
        format!(
            "{} was written by a newer Anthesis (format version {}; this build reads up to {})",
            path.display(),
            FORMAT_VERSION + 1,
            FORMAT_VERSION
        )
    );
}

#[test]
fn version_zero_or_text_is_invalid() {
    for version in ["0", "\"1\""] {
        let (_folder, path) = saved_lily();
        edit(&path, |text| {
            replace_once(text, "version = 2", &format!("version = {version}"))
        });
        let error = load_project(&path).expect_err("bad version");
        assert!(matches!(error, ProjectError::Invalid { .. }), "{error:?}");
        assert!(error.to_string().contains("version"), "{error}");
    }
}

#[test]
fn a_file_of_another_format_is_refused() {
    let (_folder, path) = saved_lily();
    edit(&path, |text| {
        replace_once(text, "\"anthesis-project\"", "\"anthesis-brush\"")
    });
    let error = load_project(&path).expect_err("wrong format");
    assert_eq!(
        error,
        ProjectError::WrongFormat {
            path: path.clone(),
            found: "\"anthesis-brush\"".to_string(),
        }
    );

    fs::write(&path, "[package]\nname = \"anthesis\"\n").expect("write");
    let error = load_project(&path).expect_err("no format");
    assert!(
        matches!(&error, ProjectError::WrongFormat { found, .. } if found == "missing"),
        "{error:?}"
    );
}

#[test]
fn a_missing_png_is_an_io_error_naming_it() {
    let (_folder, path) = saved_lily();
    let png = path
        .parent()
        .expect("folder")
        .join("maps/petal-step0-bend.png");
    fs::remove_file(&png).expect("remove");
    let error = load_project(&path).expect_err("missing png");
    assert!(
        matches!(&error, ProjectError::Io { path, .. } if *path == png),
        "{error:?}"
    );
    assert!(
        error.to_string().contains("petal-step0-bend.png"),
        "{error}"
    );
}

#[test]
fn a_corrupt_png_is_a_map_error_naming_it() {
    let (_folder, path) = saved_lily();
    let png = path
        .parent()
        .expect("folder")
        .join("maps/petal-step0-e_growth.png");
    let mut bytes = fs::read(&png).expect("read");
    bytes.truncate(bytes.len() / 2);
    fs::write(&png, bytes).expect("write");
    let error = load_project(&path).expect_err("corrupt png");
    match &error {
        ProjectError::Map { path, error } => {
            assert_eq!(*path, png);
            assert!(matches!(error, MapError::Decode { .. }), "{error:?}");
        }
        other => panic!("expected a map error, got {other:?}"),
    }
    assert!(
        error.to_string().contains("petal-step0-e_growth.png"),
        "{error}"
    );
}

#[test]
fn maps_of_different_sizes_are_refused() {
    let (_folder, path) = saved_lily();
    let png = path
        .parent()
        .expect("folder")
        .join("maps/petal-step0-bend.png");
    let bytes = ScalarMap::from_fn(5, 5, |uv| uv.x as f32)
        .to_png_bytes(BitDepth::Eight)
        .expect("encode");
    fs::write(&png, bytes).expect("write");
    let error = load_project(&path).expect_err("wrong size");
    assert_eq!(
        error,
        ProjectError::MapSize {
            path: png,
            expected: (8, 6),
            found: (5, 5),
        }
    );
    assert!(error.to_string().contains("5x5"), "{error}");
}

#[test]
fn saving_maps_of_different_sizes_is_refused_before_writing() {
    let mut project = lily();
    project.flower.templates[0].maps.keys_mut()[1]
        .maps
        .e_growth_in = ScalarMap::from_fn(4, 4, |_| 0.5);
    let folder = tempfile::tempdir().expect("temp dir");
    let path = folder.path().join("lily.anthesis.toml");
    let error = save_project(&project, &path).expect_err("sizes differ");
    assert!(
        matches!(&error, ProjectError::MapSize { path, expected: (8, 6), found: (4, 4) }
            if path.ends_with("maps/petal-step50-e_growth_in.png")),
        "{error:?}"
    );
    assert!(files_under(folder.path()).is_empty(), "nothing written");
}

#[test]
fn saving_a_raster_outside_what_png_holds_is_refused() {
    let mut project = lily();
    project.flower.templates[0].maps.keys_mut()[0].maps.bend =
        ScalarMap::from_fn(8, 6, |uv| 2.0 * uv.y as f32);
    let folder = tempfile::tempdir().expect("temp dir");
    let path = folder.path().join("lily.anthesis.toml");
    let error = save_project(&project, &path).expect_err("values above 1");
    assert!(matches!(error, ProjectError::Invalid { .. }), "{error:?}");
    assert!(error.to_string().contains("bend"), "{error}");
    assert!(files_under(folder.path()).is_empty(), "nothing written");
}

#[test]
fn an_organ_with_a_missing_template_is_refused() {
    let (_folder, path) = saved_lily();
    edit(&path, |text| {
        replace_once(
            text,
            "template = \"Outer sepal\"",
            "template = \"Inner sepal\"",
        )
    });
    let error = load_project(&path).expect_err("unknown template");
    assert_eq!(
        error,
        ProjectError::UnknownTemplate {
            path: path.clone(),
            organ: "sepal-1".to_string(),
            template: "Inner sepal".to_string(),
        }
    );
}

#[test]
fn an_overlap_with_a_missing_organ_is_refused() {
    let (_folder, path) = saved_lily();
    edit(&path, |text| {
        replace_once(text, "outer = \"sepal-1\"", "outer = \"sepal-9\"")
    });
    let error = load_project(&path).expect_err("unknown organ");
    assert_eq!(
        error,
        ProjectError::UnknownOrgan {
            path: path.clone(),
            name: "sepal-9".to_string(),
        }
    );
}

#[test]
fn duplicate_names_are_refused() {
    let (_folder, path) = saved_lily();
    edit(&path, |text| {
        replace_once(text, "name = \"petal-2\"", "name = \"petal-1\"")
    });
    let error = load_project(&path).expect_err("duplicate organ");
    assert_eq!(
        error,
        ProjectError::DuplicateName {
            path: path.clone(),
            what: "organ",
            name: "petal-1".to_string(),
        }
    );

    let mut project = lily();
    project.flower.templates[1].name = "Petal".to_string();
    let folder = tempfile::tempdir().expect("temp dir");
    let error = save_project(&project, &folder.path().join("p.toml")).expect_err("duplicate");
    assert!(
        matches!(&error, ProjectError::DuplicateName { what: "template", name, .. } if name == "Petal"),
        "{error:?}"
    );
}

#[test]
fn a_mesh_without_uvs_is_a_mesh_error_naming_the_obj() {
    let (_folder, path) = saved_lily();
    let obj = path.parent().expect("folder").join("meshes/petal.obj");
    let without_uvs: String = fs::read_to_string(&obj)
        .expect("read")
        .lines()
        .filter(|line| !line.starts_with("vt "))
        .map(|line| {
            if let Some(corners) = line.strip_prefix("f ") {
                let corners: Vec<String> = corners
                    .split_whitespace()
                    .map(|corner| corner.split('/').next().unwrap_or("").to_string())
                    .collect();
                format!("f {}\n", corners.join(" "))
            } else {
                format!("{line}\n")
            }
        })
        .collect();
    fs::write(&obj, without_uvs).expect("write");
    let error = load_project(&path).expect_err("no uvs");
    assert_eq!(
        error,
        ProjectError::Mesh {
            path: obj,
            error: MeshError::MissingUvs,
        }
    );
    assert!(error.to_string().contains("meshes/petal.obj"), "{error}");
}

#[test]
fn out_of_range_values_are_invalid_and_say_which() {
    let cases: [(&str, &str, &str); 7] = [
        ("thickness = 0.2", "thickness = 0.0", "thickness"),
        ("keyframes = 80", "keyframes = 0", "keyframes"),
        (
            "bend_stiffness = 18.5",
            "bend_stiffness = -1.0",
            "bend_stiffness",
        ),
        (
            "stretch_stiffness = 20.0",
            "stretch_stiffness = 0",
            "stretch_stiffness",
        ),
        ("v_max = 0.06", "v_max = 1.5", "v_max"),
        ("step = 50", "step = 0", "two map keys at step 0"),
        ("w_growth = 0.2", "w_growth = nan", "w_growth"),
    ];
    for (from, to, expected) in cases {
        let (_folder, path) = saved_lily();
        edit(&path, |text| replace_once(text, from, to));
        let error = load_project(&path).expect_err(to);
        assert!(
            matches!(error, ProjectError::Invalid { .. }),
            "{to}: {error:?}"
        );
        let message = error.to_string();
        assert!(message.contains(expected), "{to}: {message}");
        assert!(message.contains("lily.anthesis.toml"), "{to}: {message}");
    }
}

#[test]
fn a_template_without_keys_is_invalid() {
    let text = r#"
format = "anthesis-project"
version = 1
name = "bare"

[[templates]]
name = "petal"
mesh = "petal.obj"
dg = 0.003
thickness = 0.2
stretch_stiffness = 20
bend_stiffness = 20
keys = []
"#;
    let files = |_: &str| -> Result<Vec<u8>, io::Error> { panic!("no file should be read") };
    let error = parse_project(text, &files).expect_err("no keys");
    assert!(matches!(error, ProjectError::Invalid { .. }), "{error:?}");
    assert!(error.to_string().contains("no map keys"), "{error}");
}

#[test]
fn saving_an_invalid_project_writes_nothing() {
    let mut project = lily();
    project.flower.templates[1].thickness = 0.0;
    let folder = tempfile::tempdir().expect("temp dir");
    let path = folder.path().join("lily.anthesis.toml");
    let error = save_project(&project, &path).expect_err("thickness 0");
    assert!(
        error
            .to_string()
            .contains("template \"Outer sepal\": thickness"),
        "{error}"
    );
    assert!(files_under(folder.path()).is_empty(), "nothing written");
}

#[test]
fn parse_project_reads_files_through_the_resolver() {
    let mesh = test_petal(8.0, 3.0, 5, 6);
    let e_growth = exact_raster(4, 3, |uv| uv.y);
    let direction = DirectionMap::from_fn(4, 3, |_| {
        DVec2::new(f64::from(signed16(0.5)), f64::from(signed16(-0.25)))
    });
    let files: HashMap<String, Vec<u8>> = HashMap::from([
        (
            "shapes/petal.obj".to_string(),
            anthesis_mesh::obj_string(&mesh).into_bytes(),
        ),
        (
            "paint/e.png".to_string(),
            e_growth.to_png_bytes(BitDepth::Sixteen).expect("encode"),
        ),
        (
            "paint/dir.png".to_string(),
            direction.to_png_bytes(BitDepth::Sixteen).expect("encode"),
        ),
    ]);
    // A hand-written file: integers for floats, omitted optional fields,
    // omitted maps, a logistic blend with its default steepness.
    let text = r#"
format = "anthesis-project"
version = 1
name = "embedded"

[[templates]]
name = "petal"
mesh = "shapes/petal.obj"
dg = 0.003
thickness = 1
stretch_stiffness = 20
bend_stiffness = 20
base_region = { v_max = 0.1 }
blend = { logistic = {} }
joint_schedule = [{ from_step = 0, to_step = 60, degrees = 23 }]

[[templates.keys]]
step = 0
e_growth = "paint/e.png"
stretch = 2

[[templates.keys]]
step = 30
direction = "paint/dir.png"

[[organs]]
name = "petal-1"
template = "petal"
"#;
    let resolver = |relative: &str| {
        files
            .get(relative)
            .cloned()
            .ok_or_else(|| io::Error::new(io::ErrorKind::NotFound, "not embedded"))
    };
    let project = parse_project(text, &resolver).expect("parses");

    assert_eq!(project.name, "embedded");
    // A version 1 file names no model: it was made with the paper's.
    assert_eq!(
        project.settings,
        SimulationSettings {
            model: Model::Paper,
            ..SimulationSettings::default()
        }
    );
    let template = &project.flower.templates[0];
    assert_eq!(template.mesh, mesh);
    assert_eq!(template.thickness, 1.0);
    assert_eq!(template.colour, [1.0; 4]);
    assert_eq!(
        template.base_region,
        BaseRegion {
            v_max: 0.1,
            ..BaseRegion::default()
        }
    );
    assert_eq!(template.maps.blend, Blend::logistic());
    assert_eq!(template.joint_schedule[0].angle_deg, 23.0);
    let keys = template.maps.keys();
    assert_eq!(keys.len(), 2);
    assert_eq!(keys[0].maps.e_growth, e_growth);
    assert_eq!(keys[0].maps.stretch, ScalarMap::constant(2.0));
    for kind in [MapKind::WGrowth, MapKind::EGrowthIn, MapKind::Bend] {
        assert_eq!(
            *keys[0].maps.scalar(kind),
            ScalarMap::constant(kind.default_value()),
            "{kind:?} defaults"
        );
    }
    assert_eq!(keys[0].maps.direction, DirectionMap::constant(DVec2::Y));
    assert_eq!(keys[1].maps.direction, direction);
    assert_eq!(keys[1].maps.e_growth, ScalarMap::constant(0.0));
    assert_eq!(
        project.flower.organs[0].placement,
        Placement {
            position: DVec3::ZERO,
            azimuth_deg: 0.0,
            joint_angle_deg: 0.0,
            orientation: glam::DQuat::IDENTITY,
        }
    );

    // A file the resolver lacks is named as written.
    let missing = text.replace("paint/dir.png", "paint/missing.png");
    let error = parse_project(&missing, &resolver).expect_err("missing");
    assert!(
        matches!(&error, ProjectError::Io { path, message }
            if path == Path::new("paint/missing.png") && message.contains("not embedded")),
        "{error:?}"
    );
    // Syntax errors name the project text.
    let error = parse_project("format = ", &resolver).expect_err("syntax");
    assert!(error.to_string().starts_with(UNNAMED_PROJECT), "{error}");
}

#[test]
fn a_direction_needs_two_components() {
    let (_folder, path) = saved_lily();
    edit(&path, |text| {
        replace_once(
            text,
            "direction = [0.25, 0.75]",
            "direction = [0.25, 0.75, 0.0]",
        )
    });
    let error = load_project(&path).expect_err("three components");
    assert!(matches!(error, ProjectError::Syntax { .. }), "{error:?}");
    assert!(error.to_string().contains("[u, v]"), "{error}");
}

#[test]
fn a_missing_project_file_is_an_io_error() {
    let folder = tempfile::tempdir().expect("temp dir");
    let path = folder.path().join("nothing.anthesis.toml");
    let error = load_project(&path).expect_err("missing");
    assert!(
        matches!(&error, ProjectError::Io { path: p, .. } if *p == path),
        "{error:?}"
    );
}

/// The project's message when loading `path` fails.
fn load_message(path: &Path) -> String {
    match load_project(path) {
        Ok(_) => panic!("{} loaded but must fail", path.display()),
        Err(error) => error.to_string(),
    }
}

#[test]
fn paths_outside_the_project_folder_are_refused_without_reading_them() {
    let (folder, path) = saved_lily();
    let project_folder = path.parent().expect("folder").to_path_buf();
    // A secret beside the project folder and links that lead to it.
    fs::write(folder.path().join("secret.txt"), "root:x:0:0:secret\n").expect("write");
    std::os::unix::fs::symlink("../../secret.txt", project_folder.join("meshes/link.obj"))
        .expect("symlink");
    std::os::unix::fs::symlink(folder.path(), project_folder.join("outside")).expect("symlink");
    let cases = [
        (
            "../../../../etc/passwd",
            "template \"Petal\": mesh = \"../../../../etc/passwd\" is refused: the path leaves \
             the project's folder through `..`",
        ),
        (
            "/etc/hostname",
            "template \"Petal\": mesh = \"/etc/hostname\" is refused: the path is absolute; \
             files named in a project must be given relative to the project's folder",
        ),
        (
            "meshes/link.obj",
            "template \"Petal\": mesh = \"meshes/link.obj\" is refused: the path leads outside \
             the project's folder through a symbolic link; files named in a project must lie \
             inside its folder",
        ),
        (
            "outside/secret.txt",
            "template \"Petal\": mesh = \"outside/secret.txt\" is refused: the path leads \
             outside the project's folder through a symbolic link",
        ),
        (
            "",
            "template \"Petal\": mesh = \"\" is refused: the path is empty",
        ),
    ];
    for (mesh, expected) in cases {
        let text = fs::read_to_string(&path).expect("read");
        let edited = replace_once(
            text.clone(),
            "mesh = \"meshes/petal.obj\"",
            &format!("mesh = \"{mesh}\""),
        );
        fs::write(&path, edited).expect("write");
        let message = load_message(&path);
        assert!(message.contains(expected), "{mesh}: {message}");
        assert!(!message.contains("root:x"), "{message}");
        fs::write(&path, text).expect("restore");
    }
    // A map path climbing out is refused the same way, naming its key.
    edit(&path, |text| {
        replace_once(
            text,
            "e_growth = \"maps/petal-step0-e_growth.png\"",
            "e_growth = \"maps/../../secret.txt\"",
        )
    });
    assert!(
        load_message(&path).contains(
            "template \"Petal\", key 0: e_growth = \"maps/../../secret.txt\" is refused: the path \
             leaves the project's folder through `..`"
        ),
        "{}",
        load_message(&path)
    );
}

#[test]
fn paths_that_stay_inside_are_fine_through_dot_dot_and_links() {
    let (_folder, path) = saved_lily();
    let project_folder = path.parent().expect("folder");
    std::os::unix::fs::symlink("petal.obj", project_folder.join("meshes/alias.obj"))
        .expect("symlink");
    edit(&path, |text| {
        replace_once(
            text,
            "mesh = \"meshes/petal.obj\"",
            "mesh = \"maps/../meshes/alias.obj\"",
        )
    });
    assert_eq!(load_project(&path).expect("inside"), lily());
}

#[test]
fn parse_project_refuses_paths_that_climb_out_too() {
    let (_folder, path) = saved_lily();
    let folder = path.parent().expect("folder").to_path_buf();
    let text =
        fs::read_to_string(&path)
            .expect("read")
            .replacen("meshes/petal.obj", "../petal.obj", 1);
    let files = |relative: &str| fs::read(folder.join(relative));
    let error = parse_project(&text, &files).expect_err("climbs out");
    assert!(
        error
            .to_string()
            .contains("mesh = \"../petal.obj\" is refused: the path leaves the project's folder"),
        "{error}"
    );
}

#[test]
fn special_files_named_by_a_project_are_not_read() {
    let (_folder, path) = saved_lily();
    let folder = path.parent().expect("folder").to_path_buf();
    let fifo = folder.join("meshes/pipe.obj");
    let status = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo");
    assert!(status.success());
    std::os::unix::fs::symlink("/dev/zero", folder.join("maps/zero.png")).expect("symlink");
    edit(&path, |text| {
        replace_once(
            text,
            "mesh = \"meshes/petal.obj\"",
            "mesh = \"meshes/pipe.obj\"",
        )
    });
    let message = load_message(&path);
    assert!(
        message.ends_with("meshes/pipe.obj: it is a named pipe (FIFO), not a regular file; only regular files are read"),
        "{message}"
    );
    // A link to /dev/zero leads outside the folder: refused as such, unread.
    edit(&path, |text| {
        replace_once(
            text,
            "mesh = \"meshes/pipe.obj\"",
            "mesh = \"meshes/petal.obj\"",
        )
    });
    edit(&path, |text| {
        replace_once(
            text,
            "bend = \"maps/petal-step0-bend.png\"",
            "bend = \"maps/zero.png\"",
        )
    });
    assert!(
        load_message(&path).contains("bend = \"maps/zero.png\" is refused: the path leads outside"),
        "{}",
        load_message(&path)
    );
}

#[test]
fn a_project_file_that_is_not_a_regular_file_is_not_read() {
    let folder = tempfile::tempdir().expect("temp dir");
    let fifo = folder.path().join("pipe.anthesis.toml");
    assert!(
        std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .expect("mkfifo")
            .success()
    );
    assert_eq!(
        load_message(&fifo),
        format!(
            "{}: it is a named pipe (FIFO), not a regular file; only regular files are read",
            fifo.display()
        )
    );
    assert!(load_message(Path::new("/dev/zero")).contains("character device"));
}

#[test]
fn a_project_cut_after_its_header_or_without_organs_is_an_error() {
    let (_folder, path) = saved_lily();
    let full = fs::read_to_string(&path).expect("read");
    let header_end = full.find("[simulation]").expect("a simulation table");
    fs::write(&path, &full[..header_end]).expect("write");
    assert_eq!(
        load_message(&path),
        format!(
            "{}: the project defines no templates ([[templates]]); is the file cut short?",
            path.display()
        )
    );
    let organs_start = full.find("[[organs]]").expect("organs");
    fs::write(&path, &full[..organs_start]).expect("write");
    assert_eq!(
        load_message(&path),
        format!(
            "{}: the project has no organs ([[organs]]); is the file cut short?",
            path.display()
        )
    );
}

#[test]
fn negative_map_values_and_dg_of_minus_one_are_refused() {
    let (_folder, path) = saved_lily();
    edit(&path, |text| {
        replace_once(text, "w_growth = 0.2", "w_growth = -5")
    });
    assert!(
        load_message(&path).contains(
            "template \"Petal\": map key at step 0: the w_growth map holds -5; map values must be \
             0 or more (for shrinkage, give the template a negative dg)"
        ),
        "{}",
        load_message(&path)
    );
    let (_folder, path) = saved_lily();
    edit(&path, |text| replace_once(text, "dg = 0.003", "dg = -1"));
    assert!(
        load_message(&path).contains(
            "dg must be a number greater than -1 (a growth rate 1 + dg × map value must stay \
             positive), found -1"
        ),
        "{}",
        load_message(&path)
    );
    // Shrinkage itself is allowed.
    let (_folder, path) = saved_lily();
    edit(&path, |text| {
        replace_once(text, "dg = 0.003", "dg = -0.002")
    });
    assert!(load_project(&path).is_ok());
}

#[test]
fn a_base_region_without_three_particles_is_refused_at_save_and_load() {
    // The lily petal's base row has particles at u = 0, 0.2, ..., 1.
    let mut project = lily();
    project.flower.templates[0].base_region.u_min = 0.45;
    project.flower.templates[0].base_region.u_max = 0.55;
    let folder = tempfile::tempdir().expect("temp dir");
    let error = save_project(&project, &folder.path().join("lily.anthesis.toml"))
        .expect_err("no base particle");
    assert!(
        error.to_string().contains(
            "template \"Petal\": the base region (v <= 0.06, u from 0.45 to 0.55) holds 0 \
             particle(s) of the mesh; at least 3 are needed to attach the organ"
        ),
        "{error}"
    );
}

#[test]
fn the_map_of_the_wrong_size_is_the_one_named() {
    // The first map read (e_growth) is the odd one out: the others are 8x6.
    let (_folder, path) = saved_lily();
    let png = path
        .parent()
        .expect("folder")
        .join("maps/petal-step0-e_growth.png");
    let bytes = ScalarMap::from_fn(5, 5, |uv| uv.x as f32)
        .to_png_bytes(BitDepth::Eight)
        .expect("encode");
    fs::write(&png, bytes).expect("write");
    assert_eq!(
        load_project(&path).expect_err("wrong size"),
        ProjectError::MapSize {
            path: png,
            expected: (8, 6),
            found: (5, 5),
        }
    );
}

#[test]
fn long_names_and_control_characters_are_not_echoed() {
    let (_folder, path) = saved_lily();
    let long = "x".repeat(5000);
    edit(&path, |text| {
        text.replace("\"petal-1\"", &format!("\"{long}\""))
    });
    let message = load_message(&path);
    assert!(message.len() < 300, "{message}");
    assert!(
        message.contains("is longer than 100 characters"),
        "{message}"
    );
    let (_folder, path) = saved_lily();
    edit(&path, |text| {
        text.replace("\"petal-1\"", "\"petal\\u001b[2J\"")
    });
    let message = load_message(&path);
    assert!(message.contains("holds a control character"), "{message}");
    assert!(!message.contains('\u{1b}'), "{message:?}");
}

#[test]
fn a_huge_line_is_not_echoed_whole() {
    let (_folder, path) = saved_lily();
    let junk = "y".repeat(100_000);
    edit(&path, |text| format!("{text}\n{junk} = 1 2\n"));
    let message = load_message(&path);
    assert!(message.len() < 1000, "{} characters", message.len());
}

#[test]
fn obj_warnings_reach_the_caller_naming_the_file() {
    let (_folder, path) = saved_lily();
    let obj = path.parent().expect("folder").join("meshes/petal.obj");
    let mut text = fs::read_to_string(&obj).expect("read");
    text.push_str("l 1 2\nl 2 3\n");
    fs::write(&obj, text).expect("write");
    let loaded = anthesis_flower::project::load_project_with_warnings(&path).expect("loads");
    assert_eq!(loaded.project, lily());
    assert_eq!(loaded.warnings.len(), 1, "{:?}", loaded.warnings);
    assert!(
        loaded.warnings[0].contains("meshes/petal.obj: OBJ line")
            && loaded.warnings[0].contains("2 line (`l`) statements ignored"),
        "{:?}",
        loaded.warnings
    );
}

#[test]
fn a_mesh_wound_with_its_inner_side_outwards_loads_with_a_warning() {
    // Another tool's export wound the other way round: the organs would
    // bend inwards instead of opening, and nothing else says why.
    let (_folder, path) = saved_lily();
    let obj = path.parent().expect("folder").join("meshes/petal.obj");
    let text = fs::read_to_string(&obj).expect("read");
    let reversed: Vec<String> = text
        .lines()
        .map(|line| match line.strip_prefix("f ") {
            Some(corners) => {
                let corners: Vec<&str> = corners.split_whitespace().rev().collect();
                format!("f {}", corners.join(" "))
            }
            None => line.to_string(),
        })
        .collect();
    fs::write(&obj, reversed.join("\n")).expect("write");
    let loaded = anthesis_flower::project::load_project_with_warnings(&path).expect("loads");
    assert_eq!(loaded.warnings.len(), 1, "{:?}", loaded.warnings);
    let warning = &loaded.warnings[0];
    assert!(
        warning.contains("meshes/petal.obj: template \"Petal\": the triangles wind so that the inner side faces +Z"),
        "{warning}"
    );
    assert!(warning.contains("reverse the faces' winding"), "{warning}");
}

/// The saved lily with every `vt` of its petal mesh changed by `change`.
fn lily_with_petal_uvs(change: impl Fn(f64, f64) -> (f64, f64)) -> (tempfile::TempDir, PathBuf) {
    let (folder, path) = saved_lily();
    let obj = path.parent().expect("folder").join("meshes/petal.obj");
    let text = fs::read_to_string(&obj).expect("read");
    let changed: Vec<String> = text
        .lines()
        .map(|line| match line.strip_prefix("vt ") {
            Some(uv) => {
                let uv: Vec<f64> = uv
                    .split_whitespace()
                    .map(|n| n.parse().expect("a number"))
                    .collect();
                let (u, v) = change(uv[0], uv[1]);
                format!("vt {u} {v}")
            }
            None => line.to_string(),
        })
        .collect();
    fs::write(&obj, changed.join("\n")).expect("write");
    (folder, path)
}

#[test]
fn a_uv_layout_outside_the_unit_square_is_named_where_it_misses_the_base() {
    // A UDIM tile other than 1001: u from 1 to 2. The base region, over
    // the unit square, then holds only the particles at u = 1, and the
    // message said nothing of why.
    let (_folder, path) = lily_with_petal_uvs(|u, v| (u + 1.0, v));
    let message = load_message(&path);
    assert!(message.contains("the base region"), "{message}");
    assert!(
        message.contains("(the mesh's UVs span u 1 to 2, v 0 to 1; the maps and the base region are read over the unit square"),
        "{message}"
    );
    // Scaled past 1 but still holding the base: it loads, with the note.
    let (_folder, path) = lily_with_petal_uvs(|u, v| (u, 1.5 * v));
    let loaded = anthesis_flower::project::load_project_with_warnings(&path).expect("loads");
    assert_eq!(loaded.warnings.len(), 1, "{:?}", loaded.warnings);
    assert!(
        loaded.warnings[0].contains("the mesh's UVs span u 0 to 1, v 0 to 1.5"),
        "{:?}",
        loaded.warnings
    );
}

#[test]
fn a_uv_layout_with_v_across_the_organ_loads_with_a_warning() {
    // u along the petal and v across: the base region (v <= 0.06) is a
    // margin, which then held the petal along its side, silently.
    let (_folder, path) = lily_with_petal_uvs(|u, v| (v, u));
    let loaded = anthesis_flower::project::load_project_with_warnings(&path).expect("loads");
    let notes: Vec<&String> = loaded
        .warnings
        .iter()
        .filter(|w| {
            w.contains("the UV layout's v seems not to run from the base (0) to the tip (1)")
        })
        .collect();
    assert_eq!(notes.len(), 1, "{:?}", loaded.warnings);
    assert!(
        notes[0].starts_with("template \"Petal\": the base region's particles (v <= 0.06) reach"),
        "{}",
        notes[0]
    );
}

#[test]
fn the_model_is_read_from_the_file_and_version_1_files_keep_the_papers() {
    use anthesis_physics::BendBase;
    let (_folder, path) = saved_lily();
    let text = fs::read_to_string(&path).expect("saved");
    assert!(text.contains("version = 2"), "{text}");
    assert!(text.contains("model = \"consistent\""), "{text}");
    assert!(text.contains("bend_from = \"dihedral\""), "{text}");
    let settings = |path: &Path| load_project(path).expect("loads").settings;
    assert_eq!(settings(&path).model, Model::Consistent);

    // Without a model, version 2 means the default and version 1 the
    // paper's, which is what a version 1 file was made with.
    edit(&path, |t| replace_once(t, "model = \"consistent\"\n", ""));
    assert_eq!(settings(&path).model, Model::Consistent);
    edit(&path, |t| replace_once(t, "version = 2", "version = 1"));
    assert_eq!(settings(&path).model, Model::Paper);

    edit(&path, |t| {
        replace_once(
            t,
            "bend_from = \"dihedral\"",
            "model = \"paper\"\nbend_from = \"rest_angle\"",
        )
    });
    let read = settings(&path);
    assert_eq!(
        (read.model, read.bend_base),
        (Model::Paper, BendBase::RestAngle)
    );

    edit(&path, |t| {
        replace_once(t, "model = \"paper\"", "model = \"exact\"")
    });
    let error = load_project(&path).expect_err("unknown model");
    assert!(matches!(error, ProjectError::Syntax { .. }), "{error:?}");
    assert!(error.to_string().contains("exact"), "{error}");
}

#[test]
fn accumulated_rest_lengths_are_saved_as_version_10_and_absent_means_the_shape() {
    use anthesis_physics::LengthBase;
    let (_folder, path) = saved_lily();
    // The default is not written: the file is the version 2 file it was.
    let text = fs::read_to_string(&path).expect("saved");
    assert!(text.contains("version = 2\n"), "{text}");
    assert!(!text.contains("lengths_from"), "{text}");
    assert_eq!(
        load_project(&path).expect("loads").settings.length_base,
        LengthBase::Shape
    );
    let mut project = lily();
    project.settings.length_base = LengthBase::Rest;
    save_project(&project, &path).expect("saves");
    let text = fs::read_to_string(&path).expect("read");
    assert!(text.contains("version = 10\n"), "{text}");
    assert!(text.contains("lengths_from = \"rest\""), "{text}");
    assert_eq!(load_project(&path).expect("loads"), project);
    edit(&path, |t| {
        replace_once(t, "lengths_from = \"rest\"", "lengths_from = \"target\"")
    });
    let error = load_project(&path).expect_err("unknown rule");
    assert!(error.to_string().contains("target"), "{error}");
}

/// A project saved by the release that wrote format version 1 (the
/// Pinocchio asset as it was then, kept byte for byte) still opens, with the
/// paper's model it was made with.
#[test]
fn a_version_1_project_from_the_previous_release_opens() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/version-1-pinocchio/eustoma-pinocchio.anthesis.toml");
    assert!(
        fs::read_to_string(&path)
            .expect("fixture")
            .contains("version = 1"),
        "the fixture must stay a version 1 file"
    );
    let project = load_project(&path).expect("a version 1 project opens");
    assert_eq!(project.name, "Eustoma 'Pinocchio'");
    assert_eq!(project.flower.organs.len(), 5);
    assert_eq!(project.flower.templates.len(), 1);
    assert_eq!(project.settings.model, Model::Paper);
    assert_eq!(
        project.settings.bend_base,
        anthesis_physics::BendBase::Dihedral
    );
}

#[test]
fn the_resolution_is_saved_and_read_and_the_mesh_as_built_is_kept() {
    let (_folder, path) = saved_lily();
    let as_built = fs::read_to_string(&path).expect("read");
    // No setting: the file is the version 2 file it always was.
    assert!(as_built.contains("version = 2\n"), "{as_built}");
    assert!(!as_built.contains("mean_edge"));
    let loaded = load_project(&path).expect("loads");
    assert_eq!(loaded.settings.resolution, Resolution::AsBuilt);

    let mut fine = loaded.clone();
    fine.settings.resolution = Resolution::MeanEdge(0.75);
    let folder = tempfile::tempdir().expect("temp dir");
    let fine_path = folder.path().join("fine").join("lily.anthesis.toml");
    save_project(&fine, &fine_path).expect("saves");
    let text = fs::read_to_string(&fine_path).expect("read");
    assert!(text.contains("version = 3\n"), "{text}");
    assert!(text.contains("mean_edge = 0.75\n"), "{text}");
    let read = load_project(&fine_path).expect("loads");
    assert_eq!(read.settings.resolution, Resolution::MeanEdge(0.75));
    // The mesh saved is the one built, not the remeshed one.
    assert_eq!(
        read.flower.templates[0].mesh,
        loaded.flower.templates[0].mesh
    );
    let mesh_file = |p: &Path| fs::read(p.parent().expect("folder").join("meshes/petal.obj"));
    assert_eq!(
        mesh_file(&fine_path).expect("mesh"),
        mesh_file(&path).expect("mesh")
    );
    // Back to as built: the same bytes as the first save.
    let mut back = read;
    back.settings.resolution = Resolution::AsBuilt;
    let back_path = folder.path().join("back").join("lily.anthesis.toml");
    save_project(&back, &back_path).expect("saves");
    assert_eq!(fs::read_to_string(&back_path).expect("read"), as_built);
}

#[test]
fn a_mean_edge_that_is_not_a_length_is_refused() {
    for bad in ["0.0", "-1.0", "nan"] {
        let (_folder, path) = saved_lily();
        edit(&path, |text| {
            replace_once(
                text,
                "[simulation]\n",
                &format!("[simulation]\nmean_edge = {bad}\n"),
            )
        });
        let message = load_project(&path).expect_err("bad").to_string();
        assert!(
            message.contains("mean_edge must be a positive length"),
            "{bad}: {message}"
        );
    }
}

#[test]
fn a_project_folder_opens_its_one_project_file() {
    let lily = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/flowers/lily");
    let from_folder = load_project(&lily).expect("the folder opens");
    let from_file = load_project(&lily.join("lily.anthesis.toml")).expect("the file opens");
    assert_eq!(from_folder, from_file);
    assert_eq!(
        anthesis_flower::project::project_file(&lily).expect("found"),
        lily.join("lily.anthesis.toml")
    );

    let dir = tempfile::tempdir().expect("tempdir");
    let err = load_project(dir.path()).unwrap_err().to_string();
    assert!(err.contains("holds no project file"), "{err}");
    fs::write(dir.path().join("a.anthesis.toml"), "").expect("write");
    fs::write(dir.path().join("notes.toml"), "").expect("write");
    // One project file among other files: that one (here empty, so its
    // own error shows, naming it).
    let err = load_project(dir.path()).unwrap_err().to_string();
    assert!(err.contains("a.anthesis.toml"), "{err}");
    fs::write(dir.path().join("b.anthesis.toml"), "").expect("write");
    let err = load_project(dir.path()).unwrap_err().to_string();
    assert!(
        err.contains("several project files (a.anthesis.toml, b.anthesis.toml)"),
        "{err}"
    );
}

/// The test lily with its organs given by a structure instead.
fn lily_by(structure: Structure) -> Project {
    let mut project = lily();
    let derived = structure
        .arrange(&project.flower.templates)
        .expect("arranges");
    project.flower.organs = derived.organs;
    project.flower.overlaps = derived.overlaps;
    project.flower.structure = Some(structure);
    project
}

fn lily_whorls() -> Structure {
    let petals = Whorl {
        name: "petal".into(),
        template: 0,
        count: 3,
        offset_deg: 0.0,
        radius: 0.8,
        height: 0.1,
        joint_angle_deg: 10.0,
        half_span_deg: 50.0,
    };
    let sepals = Whorl {
        name: "sepal".into(),
        template: 1,
        offset_deg: 60.0,
        radius: 1.0,
        half_span_deg: 45.0,
        ..petals.clone()
    };
    Structure::Whorls {
        whorls: vec![petals, sepals],
        contorted: false,
    }
}

#[test]
fn organs_placed_by_a_structure_are_saved_as_the_structure() {
    let folder = tempfile::tempdir().expect("temp dir");
    for (name, structure) in [
        ("whorls", lily_whorls()),
        (
            "spiral",
            Structure::Spiral(Spiral {
                name: "tepal".into(),
                template: 0,
                count: 8,
                divergence_deg: anthesis_flower::structure::GOLDEN_ANGLE_DEG,
                first_radius: 1.2,
                first_height: 0.0,
                radius_step: 0.05,
                height_step: 0.02,
                joint_angle_deg: 5.0,
                half_span_deg: 40.0,
            }),
        ),
        (
            "lsystem",
            Structure::LSystem {
                text: "axiom: f(0.1) B\nB -> D/(120)D/(120)D\nD -> [&(5)~s][~p]".into(),
                steps: 2,
                surfaces: [('p', 0), ('s', 1)].into_iter().collect(),
                // Not the default, so the round trip shows it is kept.
                units: 2.0,
            },
        ),
    ] {
        let project = lily_by(structure);
        let path = folder.path().join(name).join("flower.anthesis.toml");
        save_project(&project, &path).expect("saves");
        let text = fs::read_to_string(&path).expect("read");
        assert!(text.contains("version = 4"), "{text}");
        assert!(text.contains(&format!("kind = \"{name}\"")), "{text}");
        assert!(
            !text.contains("[[organs]]"),
            "made organs are not listed:\n{text}"
        );
        assert!(
            !text.contains("[[overlaps]]"),
            "made rules are not listed:\n{text}"
        );
        let loaded = load_project(&path).expect("loads");
        assert_eq!(loaded, project, "{name}");
        assert!(!loaded.flower.organs.is_empty());
    }
}

#[test]
fn an_lsystem_places_organs_in_the_turtle_frame_and_layers_templates_in_order() {
    let project = lily_by(Structure::LSystem {
        text: "axiom: f(0.1) B\nB -> D/(120)D/(120)D\nD -> [&(5)~s][~p]".into(),
        steps: 2,
        surfaces: [('p', 0), ('s', 1)].into_iter().collect(),
        units: 1.0,
    });
    let flower = &project.flower;
    let names: Vec<&str> = flower.organs.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "Outer sepal-1",
            "Petal-1",
            "Outer sepal-2",
            "Petal-2",
            "Outer sepal-3",
            "Petal-3",
        ]
    );
    // Every organ at the end of f(0.1); petals upright but turned 120°
    // about the axis (the heading), so their tips stay on the axis.
    for organ in &flower.organs {
        assert!((organ.placement.position - DVec3::new(0.0, 0.1, 0.0)).length() < 1e-12);
    }
    let tip = |i: usize| {
        flower.organs[i]
            .placement
            .world_from_template(DVec3::Y, 0.0)
    };
    assert!((tip(1) - DVec3::new(0.0, 1.1, 0.0)).length() < 1e-12);
    // A sepal is pitched by & (5°): its tip leaves the axis.
    assert!(tip(0).x.hypot(tip(0).z) > 0.05);
    // Sepals came first in the word, so each petal lies inside the sepal
    // of its own segment (same place, facing the same way), and only that.
    let mut overlaps = flower.overlaps.clone();
    overlaps.sort_by_key(|o| (o.inner, o.outer));
    assert_eq!(
        overlaps,
        [
            Overlap { inner: 1, outer: 0 },
            Overlap { inner: 3, outer: 2 },
            Overlap { inner: 5, outer: 4 },
        ]
    );
}

#[test]
fn lsystem_units_scale_every_position_and_line_width_but_not_the_organs() {
    let text = "width = 4\naxiom: F(10) [ +(90) F(5) ] ~p";
    let at = |units: f64| {
        lily_by(Structure::LSystem {
            text: text.into(),
            steps: 0,
            surfaces: [('p', 0)].into_iter().collect(),
            units,
        })
    };
    let (one, tenth) = (at(1.0), at(0.1));
    let organ = |p: &anthesis_flower::Project| p.flower.organs[0].placement;
    assert!((organ(&one).position - DVec3::new(0.0, 10.0, 0.0)).length() < 1e-12);
    assert!((organ(&tenth).position - DVec3::new(0.0, 1.0, 0.0)).length() < 1e-12);
    assert_eq!(organ(&one).orientation, organ(&tenth).orientation);
    let segments = |p: &anthesis_flower::Project| p.flower.structure.as_ref().unwrap().segments();
    let (s1, s10) = (segments(&one), segments(&tenth));
    assert_eq!(s1.len(), 2);
    for (a, b) in s1.iter().zip(&s10) {
        assert!((a.start * 0.1 - b.start).length() < 1e-12);
        assert!((a.end * 0.1 - b.end).length() < 1e-12);
        assert!(
            (a.width * 0.1 - b.width).abs() < 1e-12,
            "{} {}",
            a.width,
            b.width
        );
    }
    // The branch ends 5 units to the side of the stem's top, in either unit.
    assert!(((s10[1].end - DVec3::new(0.0, 1.0, 0.0)).length() - 0.5).abs() < 1e-12);
    // Organ meshes are the template's, unscaled.
    assert_eq!(one.flower.templates[0].mesh, tenth.flower.templates[0].mesh);
}

#[test]
fn lsystem_units_that_are_not_a_positive_number_are_refused() {
    let folder = tempfile::tempdir().expect("temp dir");
    let path = folder.path().join("flower.anthesis.toml");
    let mut project = lily_by(Structure::LSystem {
        text: "axiom: ~p".into(),
        steps: 0,
        surfaces: [('p', 0)].into_iter().collect(),
        units: 0.5,
    });
    project.name = "units".into();
    save_project(&project, &path).expect("saves");
    edit(&path, |text| {
        replace_once(text, "units = 0.5", "units = -2.0")
    });
    let err = load_project(&path).expect_err("negative units");
    assert!(
        err.to_string()
            .contains("units must be a positive number, got -2"),
        "{err}"
    );
}

#[test]
fn a_listed_rule_overrides_the_made_one_for_its_pair_and_survives_saving() {
    let (_folder, path) = saved_lily();
    edit(&path, |text| {
        let text = replace_once(text, "version = 2", "version = 4");
        // Drop the listed organs and rule; whorls make them instead.
        let start = text.find("[[organs]]").expect("organs");
        let mut text = text[..start].to_string();
        text.push_str(
            "[structure]\nkind = \"whorls\"\n\n\
             [[structure.whorls]]\nname = \"petal\"\ntemplate = \"Petal\"\ncount = 3\n\
             radius = 0.8\nheight = 0.1\njoint_angle_deg = 10.0\nhalf_span_deg = 50.0\n\n\
             [[structure.whorls]]\nname = \"sepal\"\ntemplate = \"Outer sepal\"\ncount = 3\n\
             offset_deg = 60.0\nradius = 1.0\nheight = 0.1\njoint_angle_deg = 10.0\n\
             half_span_deg = 45.0\n\n\
             [[overlaps]]\ninner = \"sepal-1\"\nouter = \"petal-1\"\n",
        );
        text
    });
    let project = load_project(&path).expect("loads");
    let index = |name: &str| project.flower.organ_index(name).expect("organ");
    let (petal, sepal) = (index("petal-1"), index("sepal-1"));
    assert!(project.flower.overlaps.contains(&Overlap {
        inner: sepal,
        outer: petal
    }));
    assert!(!project.flower.overlaps.contains(&Overlap {
        inner: petal,
        outer: sepal
    }));
    // The other made rules stay.
    assert!(project.flower.overlaps.len() > 1);
    save_project(&project, &path).expect("saves");
    let text = fs::read_to_string(&path).expect("read");
    assert_eq!(text.matches("[[overlaps]]").count(), 1, "{text}");
    assert_eq!(load_project(&path).expect("reloads"), project);
}

#[test]
fn a_broken_structure_is_refused_naming_what_is_wrong() {
    let (_folder, path) = saved_lily();
    let with = |structure: &str| {
        let (_f, path) = saved_lily();
        edit(&path, |text| {
            let text = replace_once(text, "version = 2", "version = 4");
            format!("{text}\n{structure}")
        });
        load_project(&path).expect_err("refused").to_string()
    };
    let _ = path;
    let err = with(
        "[structure]\nkind = \"lsystem\"\n[structure.lsystem]\nsteps = 1\n\
                    text = \"axiom: ~p\\nA -> F(1\"\nsurfaces = { p = \"Petal\" }\n",
    );
    assert!(err.contains("line 2, column 9"), "{err}");
    let err = with(
        "[structure]\nkind = \"lsystem\"\n[structure.lsystem]\nsteps = 1\n\
                    text = \"axiom: ~q\"\nsurfaces = { p = \"Petal\" }\n",
    );
    assert!(err.contains("surface `q`"), "{err}");
    let err = with("[structure]\nkind = \"spiral\"\n");
    assert!(err.contains("needs a [structure.spiral] table"), "{err}");
    let err = with(
        "[structure]\nkind = \"lsystem\"\n[structure.lsystem]\nsteps = 1\n\
                    text = \"axiom: ~p\"\nsurfaces = { p = \"stamen\" }\n",
    );
    assert!(err.contains("template \"stamen\""), "{err}");
    // Made organs whose names clash with listed ones.
    let err = with(
        "[structure]\nkind = \"whorls\"\n[[structure.whorls]]\nname = \"petal\"\n\
                    template = \"Petal\"\ncount = 2\nradius = 1.0\nhalf_span_deg = 40.0\n",
    );
    assert!(err.contains("petal-1"), "{err}");
}

/// Stamens that spread, a three-lobed pistil with an ovary, a stem and a
/// receptacle of its own.
fn lily_parts() -> Vec<anthesis_flower::parts::Part> {
    use anthesis_flower::parts::{Part, PartShape, Tube};
    let part = |name: &str, shape: PartShape, count: u32| Part {
        name: name.to_string(),
        shape,
        count,
        ring_radius: 0.0,
        height: 0.0,
        offset_deg: 0.0,
        angle_deg: 0.0,
        schedule: Vec::new(),
        colour: [0.3, 0.5, 0.2, 1.0],
        head_colour: [0.3, 0.5, 0.2, 1.0],
    };
    let mut stamen = part(
        "stamen",
        PartShape::Stamen {
            filament: Tube {
                length: 8.0,
                radius: 0.12,
                curvature_deg: 20.0,
            },
            anther_length: 1.5,
            anther_radius: 0.3,
            anther_tilt_deg: 90.0,
        },
        6,
    );
    stamen.ring_radius = 0.6;
    stamen.offset_deg = 30.0;
    stamen.angle_deg = 5.0;
    stamen.head_colour = [0.6, 0.2, 0.05, 1.0];
    stamen.schedule = vec![JointRamp {
        from_step: 20,
        to_step: 80,
        angle_deg: 30.0,
    }];
    let mut pedicel = part(
        "pedicel",
        PartShape::Pedicel {
            stalk: Tube {
                length: 12.0,
                radius: 0.4,
                curvature_deg: -10.0,
            },
        },
        1,
    );
    pedicel.height = -1.2;
    vec![
        part(
            "receptacle",
            PartShape::Receptacle {
                radius: 2.2,
                depth: 1.4,
            },
            1,
        ),
        stamen,
        part(
            "pistil",
            PartShape::Pistil {
                style: Tube {
                    length: 9.0,
                    radius: 0.15,
                    curvature_deg: 0.0,
                },
                stigma_radius: 0.45,
                stigma_lobes: 3,
                ovary_length: 2.0,
                ovary_radius: 0.5,
            },
            1,
        ),
        pedicel,
    ]
}

#[test]
fn parts_are_saved_as_readable_tables_and_load_back_equal() {
    let mut project = lily();
    project.flower.parts = lily_parts();
    let folder = tempfile::tempdir().expect("temp dir");
    let path = folder.path().join("lily.anthesis.toml");
    save_project(&project, &path).expect("saves");
    let text = fs::read_to_string(&path).expect("read");
    assert!(text.contains("version = 5"), "{text}");
    assert_eq!(text.matches("[[parts]]").count(), 4, "{text}");
    assert!(text.contains("kind = \"stamen\"") && text.contains("anther_tilt_deg = 90.0"));
    assert!(text.contains("[[parts.schedule]]"), "{text}");
    // Keys of other kinds are not written.
    let pedicel = &text[text.find("name = \"pedicel\"").expect("pedicel")..];
    assert!(
        !pedicel.contains("anther") && !pedicel.contains("depth"),
        "{pedicel}"
    );
    assert_eq!(load_project(&path).expect("loads"), project);
    // Without parts the lily stays at its old version.
    let (_f, plain) = saved_lily();
    assert!(
        fs::read_to_string(plain)
            .expect("read")
            .contains("version = 2")
    );
}

#[test]
fn broken_parts_are_refused_naming_the_part_and_the_key() {
    let with = |part: &str| {
        let (_f, path) = saved_lily();
        edit(&path, |text| {
            let text = replace_once(text, "version = 2", "version = 5");
            format!("{text}\n[[parts]]\n{part}")
        });
        load_project(&path).expect_err("refused").to_string()
    };
    let err = with("name = \"s\"\nkind = \"stamen\"\nlength = 5.0\nradius = 0.1\n");
    assert!(
        err.contains("stamen \"s\": `anther_length` is missing"),
        "{err}"
    );
    let err = with("name = \"s\"\nkind = \"petal\"\n");
    assert!(
        err.contains("kind must be one of stamen, pistil, pedicel, receptacle"),
        "{err}"
    );
    let err = with("name = \"p\"\nkind = \"pedicel\"\nlength = 5.0\nradius = 0.1\ndepth = 1.0\n");
    assert!(
        err.contains("`depth` is not a setting of a pedicel"),
        "{err}"
    );
    let err = with(
        "name = \"s\"\nkind = \"pistil\"\nlength = 5.0\nradius = 0.1\nstigma_radius = 0.3\n\
         stigma_lobes = 12\n",
    );
    assert!(err.contains("stigma_lobes must be 1 to 8, not 12"), "{err}");
    let err = with(
        "name = \"s\"\nkind = \"pistil\"\nlength = 5.0\nradius = 0.1\nstigma_radius = 0.3\nwidth = 2\n",
    );
    assert!(err.contains("width"), "{err}");
    // An instance named like an organ.
    let err = with(
        "name = \"petal\"\nkind = \"stamen\"\ncount = 3\nlength = 5.0\nradius = 0.1\n\
         anther_length = 1.0\nanther_radius = 0.2\n",
    );
    assert!(err.contains("petal-1"), "{err}");
}

/// The lily with a crimson blush painted from the petal's base (a colour map
/// of its own size, 16x16 against the growth maps' 8x6).
fn coloured_lily() -> Project {
    let mut project = lily();
    project.flower.templates[0].colouring = Some(Colouring {
        second_colour: [0.6, 0.02, 0.08, 1.0],
        mix: exact_raster(16, 16, |uv| 1.0 - uv.y),
        layers: Vec::new(),
    });
    project
}

#[test]
fn a_colour_map_survives_saving_and_loading() {
    let folder = tempfile::tempdir().expect("temp dir");
    let path = folder.path().join("lily.anthesis.toml");
    let project = coloured_lily();
    save_project(&project, &path).expect("save");
    let text = fs::read_to_string(&path).expect("read");
    assert!(
        text.contains("second_color = [0.6, 0.02, 0.08, 1.0]")
            && text.contains("colour_map = \"maps/petal-colour.png\""),
        "{text}"
    );
    assert!(text.contains("version = 5"), "{text}");
    // Only the template that has one names a colour map.
    assert_eq!(text.matches("colour_map").count(), 1, "{text}");
    assert!(folder.path().join("maps/petal-colour.png").is_file());
    let loaded = load_project(&path).expect("load");
    assert_eq!(loaded, project);
    let base = loaded.flower.templates[0].colour_at(DVec2::new(0.5, 0.0));
    let tip = loaded.flower.templates[0].colour_at(DVec2::new(0.5, 1.0));
    assert!(
        base[0] < 0.7 && base[1] < 0.1,
        "crimson at the base: {base:?}"
    );
    let colour = loaded.flower.templates[0].colour;
    assert!(
        (0..4).all(|i| (tip[i] - colour[i]).abs() < 0.05),
        "nearly the base colour at the tip: {tip:?}"
    );
}

#[test]
fn a_project_without_colour_maps_saves_as_before() {
    let (_folder, path) = saved_lily();
    let text = fs::read_to_string(&path).expect("read");
    assert!(!text.contains("second_color") && !text.contains("colour_map"));
    assert!(text.contains("version = 2"), "{text}");
    assert_eq!(
        load_project(&path).expect("load").flower.templates[0].colouring,
        None
    );
}

#[test]
fn a_constant_colour_map_is_a_number_and_layers_are_saved() {
    let folder = tempfile::tempdir().expect("temp dir");
    let path = folder.path().join("lily.anthesis.toml");
    let mut project = lily();
    project.flower.templates[1].colouring = Some(Colouring {
        second_colour: [0.1, 0.2, 0.3, 1.0],
        mix: ScalarMap::constant(0.5),
        layers: vec![ColourLayer {
            colour: [0.9, 0.9, 0.1, 1.0],
            mix: exact_raster(4, 4, |uv| uv.x),
            side: anthesis_flower::Side::Both,
        }],
    });
    save_project(&project, &path).expect("save");
    let text = fs::read_to_string(&path).expect("read");
    assert!(text.contains("colour_map = 0.5"), "{text}");
    assert!(
        text.contains("map = \"maps/outer_sepal-colour-2.png\""),
        "{text}"
    );
    assert_eq!(load_project(&path).expect("load"), project);
}

#[test]
fn a_bad_colour_map_png_is_a_map_error_naming_it() {
    let folder = tempfile::tempdir().expect("temp dir");
    let path = folder.path().join("lily.anthesis.toml");
    save_project(&coloured_lily(), &path).expect("save");
    let png = folder.path().join("maps/petal-colour.png");
    fs::write(&png, b"not a png at all").expect("write");
    let error = load_project(&path).expect_err("bad png");
    match &error {
        ProjectError::Map { path, error } => {
            assert_eq!(*path, png);
            assert!(matches!(error, MapError::NotPng { .. }), "{error:?}");
        }
        other => panic!("expected a map error, got {other:?}"),
    }
    assert!(error.to_string().contains("petal-colour.png"), "{error}");
    fs::remove_file(&png).expect("remove");
    let error = load_project(&path).expect_err("missing png");
    assert!(
        matches!(&error, ProjectError::Io { path, .. } if *path == png),
        "{error:?}"
    );
}

#[test]
fn half_a_colour_map_or_colours_out_of_range_are_refused() {
    let folder = tempfile::tempdir().expect("temp dir");
    let path = folder.path().join("lily.anthesis.toml");
    save_project(&coloured_lily(), &path).expect("save");
    edit(&path, |text| {
        replace_once(text, "second_color = [0.6, 0.02, 0.08, 1.0]\n", "")
    });
    let error = load_project(&path).expect_err("colour map without its colour");
    assert!(
        matches!(&error, ProjectError::Invalid { message, .. }
            if message.contains("second_color") && message.contains("\"Petal\"")),
        "{error:?}"
    );
    let mut project = coloured_lily();
    if let Some(colouring) = &mut project.flower.templates[0].colouring {
        colouring.second_colour = [1.5, 0.0, 0.0, 1.0];
    }
    let error = save_project(&project, &path).expect_err("second colour out of range");
    assert!(error.to_string().contains("second_color"), "{error}");
}

#[test]
fn a_keys_own_growth_scale_is_saved_as_version_6_and_a_bad_one_is_refused() {
    let mut project = lily();
    project.flower.templates[0].maps.keys_mut()[0].dg = Some(-0.004);
    let folder = tempfile::tempdir().expect("temp dir");
    let path = folder.path().join("lily.anthesis.toml");
    save_project(&project, &path).expect("saves");
    let text = fs::read_to_string(&path).expect("read");
    assert!(text.contains("version = 6"), "{text}");
    assert_eq!(text.matches("dg = -0.004").count(), 1, "{text}");
    assert_eq!(load_project(&path).expect("loads"), project);
    // Without one, the file stays at the version it needed before.
    save_project(&lily(), &path).expect("saves");
    let text = fs::read_to_string(&path).expect("read");
    assert!(!text.contains("version = 6"), "{text}");
    // A rate 1 + dg × value must stay positive.
    save_project(&project, &path).expect("saves");
    edit(&path, |text| replace_once(text, "dg = -0.004", "dg = -1.5"));
    let err = load_project(&path).expect_err("dg -1.5");
    let message = err.to_string();
    assert!(
        message.contains("map key at step")
            && message.contains("dg must be a number greater than -1"),
        "{message}"
    );
}

#[test]
fn a_bezier_template_keeps_its_control_net_through_a_save_as_version_7() {
    let folder = tempfile::tempdir().expect("temp dir");
    let path = folder.path().join("bezier.anthesis.toml");
    let mut project = lily();
    let net = anthesis_bud::BezierPatch::petal().with_point(3, 2, DVec3::new(0.9, 21.0, 1.5), true);
    project.flower.templates[0].source =
        Some(anthesis_flower::TemplateSource::Bezier { net, edge: 1.25 });
    save_project(&project, &path).expect("saves");
    let text = fs::read_to_string(&path).expect("read");
    assert!(text.contains("version = 7"), "{text}");
    assert!(text.contains("[templates.source]"), "{text}");
    assert!(text.contains("kind = \"bezier\""), "{text}");
    assert!(text.contains("edge = 1.25"), "{text}");
    let loaded = load_project(&path).expect("loads");
    assert_eq!(loaded, project);
    match &loaded.flower.templates[0].source {
        Some(anthesis_flower::TemplateSource::Bezier { net: read, edge }) => {
            assert_eq!(*read, net);
            assert_eq!(*edge, 1.25);
        }
        other => panic!("the source is lost: {other:?}"),
    }
    // A broken source is refused with what is wrong.
    edit(&path, |t| replace_once(t, "edge = 1.25", "edge = -1.0"));
    let error = load_project(&path).expect_err("a negative edge");
    assert!(
        error.to_string().contains("edge must be a positive"),
        "{error}"
    );
    // Without a source the file stays at the version it needed before.
    save_project(&lily(), &path).expect("saves");
    let text = fs::read_to_string(&path).expect("read");
    assert!(text.contains("version = 2"), "{text}");
}

/// A sketched petal's strokes: margins meeting at the base and tip, a
/// vein, a cross-section cupping the middle.
fn petal_sketch() -> anthesis_bud::PetalSketch {
    let along = |f: &dyn Fn(f64) -> glam::DVec2| (0..=24).map(|k| f(f64::from(k) / 24.0)).collect();
    let width = |t: f64| 4.0 * (std::f64::consts::PI * t).sin();
    anthesis_bud::PetalSketch {
        left: along(&|t| glam::DVec2::new(-width(t), 18.0 * t)),
        right: along(&|t| glam::DVec2::new(width(t), 18.0 * t)),
        vein: along(&|t| glam::DVec2::new(0.0, 18.0 * t)),
        sections: vec![along(&|t| {
            glam::DVec2::new(-4.2 + 8.4 * t, 9.0 - 4.0 * t * (1.0 - t))
        })],
    }
}

#[test]
fn a_sketched_template_keeps_its_strokes_through_a_save_as_version_8() {
    let folder = tempfile::tempdir().expect("temp dir");
    let path = folder.path().join("sketch.anthesis.toml");
    let mut project = lily();
    let sketch = petal_sketch();
    sketch.build().expect("the strokes make a petal");
    project.flower.templates[0].source = Some(anthesis_flower::TemplateSource::Sketch {
        sketch: sketch.clone(),
        edge: 1.25,
    });
    save_project(&project, &path).expect("saves");
    let text = fs::read_to_string(&path).expect("read");
    assert!(text.contains("version = 8"), "{text}");
    assert!(text.contains("kind = \"sketch\""), "{text}");
    let loaded = load_project(&path).expect("loads");
    assert_eq!(loaded, project);
    match &loaded.flower.templates[0].source {
        Some(anthesis_flower::TemplateSource::Sketch { sketch: read, edge }) => {
            assert_eq!(*read, sketch);
            assert_eq!(*edge, 1.25);
        }
        other => panic!("the strokes are lost: {other:?}"),
    }
    // Broken sources are refused naming the template and what is wrong.
    let name = &project.flower.templates[0].name;
    let refused = |from: &str, to: &str| {
        save_project(&project, &path).expect("saves");
        edit(&path, |t| replace_once(t, from, to));
        load_project(&path).expect_err(to).to_string()
    };
    let message = refused("edge = 1.25", "edge = 0.0");
    assert!(
        message.contains(&format!(
            "template \"{name}\": a sketch source's edge must be a positive number"
        )),
        "{message}"
    );
    let message = refused("vein = [[", "vein = [[0.0, 0.0]]\nunused = [[");
    assert!(message.contains("unused"), "{message}");
    let message = refused("sections = [[[", "sections = [[[1.0, 1.0]], [[");
    assert!(
        message.contains(&format!(
            "template \"{name}\": a sketch source's cross-section 1 needs at least two finite points"
        )),
        "{message}"
    );
    // Strokes that make no petal: the right margin moved over the vein.
    let mut crossing = project.clone();
    if let Some(anthesis_flower::TemplateSource::Sketch { sketch, .. }) =
        &mut crossing.flower.templates[0].source
    {
        for p in &mut sketch.right[8..16] {
            p.x = -3.0;
        }
    }
    save_project(&crossing, &path).expect("saves");
    let message = load_project(&path).expect_err("crossing").to_string();
    assert!(
        message.contains(&format!(
            "template \"{name}\": its sketch makes no petal: the"
        )) && message.contains("cross near"),
        "{message}"
    );
}

#[test]
fn a_pde_template_keeps_its_curves_through_a_save_as_version_8_and_a_broken_one_is_named() {
    let folder = tempfile::tempdir().expect("temp dir");
    let path = folder.path().join("pde.anthesis.toml");
    let mut project = lily();
    let sweep = anthesis_bud::PdeSweep::petal()
        .with_point(
            anthesis_bud::SweepCurve::Margin0,
            1,
            DVec3::new(5.5, 7.5, -1.0),
            true,
        )
        .with_stretch_to_bend(2.5);
    project.flower.templates[0].source =
        Some(anthesis_flower::TemplateSource::Pde { sweep, edge: 1.1 });
    save_project(&project, &path).expect("saves");
    let text = fs::read_to_string(&path).expect("read");
    assert!(text.contains("version = 8"), "{text}");
    assert!(text.contains("kind = \"pde\""), "{text}");
    assert!(text.contains("stretch_to_bend = 2.5"), "{text}");
    let loaded = load_project(&path).expect("loads");
    assert_eq!(loaded, project);
    match &loaded.flower.templates[0].source {
        Some(anthesis_flower::TemplateSource::Pde { sweep: read, edge }) => {
            assert_eq!(*read, sweep);
            assert_eq!(*edge, 1.1);
        }
        other => panic!("the source is lost: {other:?}"),
    }
    // Broken sources are refused naming the template and the field.
    let name = &project.flower.templates[0].name;
    for (from, to, says) in [
        (
            "edge = 1.1",
            "edge = 0.0",
            "a PDE source's edge must be a positive number",
        ),
        (
            "stretch_to_bend = 2.5",
            "stretch_to_bend = -1.0",
            "stretch_to_bend (k_s/k_b) must be from 0 to 100",
        ),
        (
            "margin1 = [",
            "margin1 = [[0.0, 0.0, 0.0], ",
            "a PDE source's margin1 needs 4 points",
        ),
    ] {
        save_project(&project, &path).expect("saves");
        edit(&path, |t| replace_once(t, from, to));
        let error = load_project(&path).expect_err(to).to_string();
        assert!(
            error.contains(&format!("template \"{name}\"")) && error.contains(says),
            "{error}"
        );
    }
}

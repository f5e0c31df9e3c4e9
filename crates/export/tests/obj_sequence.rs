//! One OBJ file per keyframe, read back by a minimal independent parser.

mod common;

use anthesis_files::WriteError;
use std::collections::BTreeMap;

use anthesis_export::{ExportError, write_obj_sequence};
use common::*;
use glam::{DVec2, DVec3};

struct Object {
    positions: Vec<DVec3>,
    uvs: Vec<DVec2>,
    normals: usize,
    /// Corners as 1-based global (v, vt, vn) indices.
    faces: Vec<[(usize, usize, usize); 3]>,
}

fn parse(text: &str) -> (Vec<String>, BTreeMap<String, Object>) {
    let mut order = Vec::new();
    let mut objects: BTreeMap<String, Object> = BTreeMap::new();
    let mut current = String::new();
    for line in text.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        let numbers = || {
            words[1..]
                .iter()
                .map(|w| w.parse::<f64>().expect("number"))
                .collect::<Vec<_>>()
        };
        match words.first().copied() {
            Some("o") => {
                current = words[1].to_owned();
                order.push(current.clone());
                objects.insert(
                    current.clone(),
                    Object {
                        positions: vec![],
                        uvs: vec![],
                        normals: 0,
                        faces: vec![],
                    },
                );
            }
            Some("v") => {
                let n = numbers();
                objects
                    .get_mut(&current)
                    .expect("o first")
                    .positions
                    .push(DVec3::new(n[0], n[1], n[2]));
            }
            Some("vt") => {
                let n = numbers();
                objects
                    .get_mut(&current)
                    .expect("o first")
                    .uvs
                    .push(DVec2::new(n[0], n[1]));
            }
            Some("vn") => objects.get_mut(&current).expect("o first").normals += 1,
            Some("f") => {
                let corners: Vec<(usize, usize, usize)> = words[1..]
                    .iter()
                    .map(|c| {
                        let i: Vec<usize> =
                            c.split('/').map(|x| x.parse().expect("index")).collect();
                        (i[0], i[1], i[2])
                    })
                    .collect();
                objects
                    .get_mut(&current)
                    .expect("o first")
                    .faces
                    .push([corners[0], corners[1], corners[2]]);
            }
            Some(w) if w.starts_with('#') => {}
            other => panic!("unexpected OBJ statement {other:?}"),
        }
    }
    (order, objects)
}

#[test]
fn one_obj_per_keyframe_with_every_track_as_an_object() {
    let tracks = fixture(6);
    let dir = tempfile::tempdir().expect("tempdir");
    let paths = write_obj_sequence(dir.path(), &tracks).expect("write");
    let names: Vec<String> = paths
        .iter()
        .map(|p| p.file_name().expect("name").to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        (0..6)
            .map(|k| format!("keyframe_{k:04}.obj"))
            .collect::<Vec<_>>()
    );
    for (k, path) in paths.iter().enumerate() {
        let (order, objects) = parse(&std::fs::read_to_string(path).expect("read"));
        assert_eq!(order, ["petal", "sepal", "receptacle"]);
        let mut offset = 1;
        for (name, track) in order.iter().zip(&tracks) {
            let object = &objects[name];
            let expected = &track.keyframes[k.min(track.keyframes.len() - 1)];
            // Positions read back exactly (shortest round-trip decimals).
            assert_eq!(&object.positions, expected, "{name} keyframe {k}");
            assert_eq!(object.uvs, track.uvs, "{name}: OBJ keeps v = 0 at the base");
            assert_eq!(object.normals, expected.len());
            let triangles: Vec<[u32; 3]> = object
                .faces
                .iter()
                .map(|f| {
                    f.map(|(v, vt, vn)| {
                        assert!(v == vt && vt == vn);
                        (v - offset) as u32
                    })
                })
                .collect();
            assert_eq!(triangles, track.triangles, "{name}");
            offset += expected.len();
        }
    }
    assert_eq!(
        std::fs::read_dir(dir.path()).expect("dir").count(),
        6,
        "no temporary files left"
    );
}

#[test]
fn obj_sequence_into_a_missing_folder_is_a_clear_error() {
    let dir = tempfile::tempdir().expect("tempdir");
    let missing = dir.path().join("frames");
    let error = write_obj_sequence(&missing, &fixture(3)).expect_err("missing folder");
    match &error {
        ExportError::Write(WriteError::MissingFolder { folder, .. }) => {
            assert_eq!(folder, &missing)
        }
        other => panic!("expected MissingFolder, got {other:?}"),
    }
    assert!(error.to_string().contains("does not exist"), "{error}");
}

#[test]
fn obj_sequence_rejects_invalid_tracks() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut tracks = fixture(3);
    tracks[2].uvs.pop();
    let error = write_obj_sequence(dir.path(), &tracks).expect_err("uv count");
    assert!(
        matches!(error, ExportError::InvalidTrack { track: 2, .. }),
        "{error:?}"
    );
    assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 0);
}

/// The unit goes into a comment (OBJ has no field for it); the lengths stay
/// in project units, the unit Anthesis reads meshes and fit targets in.
#[test]
fn the_unit_is_stated_and_lengths_stay_in_project_units() {
    let unit = anthesis_flower::Unit::parse("1.8 mm").expect("unit");
    let mut tracks = fixture(2);
    for track in &mut tracks {
        track.unit = unit;
    }
    let dir = tempfile::tempdir().expect("tempdir");
    let paths = write_obj_sequence(dir.path(), &tracks).expect("written");
    let text = std::fs::read_to_string(&paths[1]).expect("read");
    assert!(
        text.lines()
            .take(3)
            .any(|l| l == "# Lengths in project units: one unit is 1.8 mm (0.0018 m)"),
        "{}",
        &text[..200]
    );
    let (_, objects) = parse(&text);
    assert_eq!(objects["petal"].positions[0], tracks[0].keyframes[1][0]);
}

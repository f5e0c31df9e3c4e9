//! Parts turned by a schedule are exported as rigid nodes: the .glb keeps
//! their mesh once and animates the node's translation and rotation, which
//! reproduce every keyframe; the Khronos validator accepts every encoding.

mod common;

use anthesis_export::{Encoding, GlbOptions, Track, glb_bytes, part_track};
use anthesis_flower::JointRamp;
use anthesis_flower::parts::{Part, PartShape, Tube, part_pieces};
use anthesis_flower::{Flower, Placement};
use common::*;
use glam::{DQuat, DVec3, Quat, Vec3};

const KEYFRAMES: usize = 21;

/// Six stamens spreading from step 5 to 15, with the fixture's organs.
fn tracks() -> Vec<Track> {
    let stamens = Part {
        name: "stamen".to_string(),
        shape: PartShape::Stamen {
            filament: Tube {
                length: 4.0,
                radius: 0.1,
                curvature_deg: 20.0,
            },
            anther_length: 0.8,
            anther_radius: 0.15,
            anther_tilt_deg: 90.0,
        },
        count: 6,
        ring_radius: 0.4,
        height: 0.1,
        offset_deg: 30.0,
        angle_deg: 5.0,
        schedule: vec![JointRamp {
            from_step: 5,
            to_step: 15,
            angle_deg: 30.0,
        }],
        colour: [0.8, 0.8, 0.6, 1.0],
        head_colour: [0.6, 0.2, 0.05, 1.0],
    };
    let flower = Flower {
        templates: Vec::new(),
        organs: vec![anthesis_flower::Organ {
            name: "petal".to_string(),
            template: 0,
            placement: Placement {
                position: DVec3::new(0.0, 0.0, 1.0),
                azimuth_deg: 0.0,
                joint_angle_deg: 0.0,
                orientation: DQuat::IDENTITY,
            },
        }],
        overlaps: Vec::new(),
        structure: None,
        parts: vec![stamens],
        unit: None,
    };
    let mut tracks = fixture(KEYFRAMES);
    // The fixture's receptacle is replaced by the flower's pieces.
    tracks.pop();
    tracks.extend(
        part_pieces(&flower)
            .iter()
            .map(|piece| part_track(piece, KEYFRAMES)),
    );
    tracks
}

#[test]
fn scheduled_parts_are_rigid_and_still_ones_are_still() {
    let tracks = tracks();
    let names: Vec<&str> = tracks.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(names[2..5], ["receptacle", "stamen-1", "stamen-1-anther"]);
    assert_eq!(tracks[2].keyframes.len(), 1, "the receptacle does not move");
    let stamen = &tracks[3];
    let rigid = stamen.rigid.as_ref().expect("a scheduled part is rigid");
    assert_eq!(stamen.keyframes.len(), KEYFRAMES);
    for (k, positions) in stamen.keyframes.iter().enumerate() {
        let pose = rigid.poses[k];
        for (p, local) in positions.iter().zip(&rigid.local) {
            assert!((*p - (pose.translation + pose.rotation * *local)).length() < 1e-12);
        }
    }
    // Still before the ramp, moving during it.
    assert_eq!(stamen.keyframes[0], stamen.keyframes[5]);
    assert_ne!(stamen.keyframes[5], stamen.keyframes[10]);
}

#[test]
fn rigid_parts_pass_the_validator_in_every_encoding() {
    let tracks = tracks();
    for encoding in Encoding::ALL {
        let options = GlbOptions {
            encoding,
            ..GlbOptions::default()
        };
        let bytes = glb_bytes(&tracks, &options, &mut |_| {}).expect("export");
        let report = assert_valid_glb(&bytes, &format!("parts-{encoding}"));
        assert_eq!(report["info"]["animationCount"], 1, "{encoding}");
        assert_eq!(
            report["info"]["drawCallCount"],
            tracks.len(),
            "{encoding}: one mesh per track"
        );
    }
}

#[test]
fn the_node_animation_reproduces_every_keyframe() {
    let tracks = tracks();
    let options = GlbOptions {
        encoding: Encoding::Dense,
        ..GlbOptions::default()
    };
    let bytes = glb_bytes(&tracks, &options, &mut |_| {}).expect("export");
    let gltf = gltf::Gltf::from_slice(&bytes).expect("parse");
    let blob = gltf.blob.clone().expect("blob");
    let scene = gltf.scenes().next().expect("scene");
    let top: Vec<String> = scene
        .nodes()
        .map(|n| n.name().unwrap_or_default().to_string())
        .collect();
    let expected: Vec<String> = tracks.iter().map(|t| t.name.clone()).collect();
    assert_eq!(top, expected, "one top node per track, in order");
    let animation = gltf.animations().next().expect("animation");
    for (track_index, track) in tracks.iter().enumerate() {
        let Some(_) = &track.rigid else { continue };
        let node = scene.nodes().nth(track_index).expect("node");
        let child = node.children().next().expect("the mesh hangs below");
        let mesh = child.mesh().expect("mesh");
        let primitive = mesh.primitives().next().expect("primitive");
        let reader = primitive.reader(|_| Some(&blob[..]));
        let local: Vec<Vec3> = reader
            .read_positions()
            .expect("positions")
            .map(Vec3::from)
            .collect();
        let mut translations = Vec::new();
        let mut rotations = Vec::new();
        for channel in animation.channels() {
            if channel.target().node().index() != node.index() {
                continue;
            }
            let outputs = channel
                .reader(|_| Some(&blob[..]))
                .read_outputs()
                .expect("outputs");
            match outputs {
                gltf::animation::util::ReadOutputs::Translations(t) => {
                    translations = t.map(Vec3::from).collect()
                }
                gltf::animation::util::ReadOutputs::Rotations(r) => {
                    rotations = r.into_f32().map(Quat::from_array).collect()
                }
                _ => panic!("a rigid node animates only translation and rotation"),
            }
        }
        assert_eq!(translations.len(), KEYFRAMES, "{}", track.name);
        assert_eq!(rotations.len(), KEYFRAMES, "{}", track.name);
        for (k, expected) in track.keyframes.iter().enumerate() {
            for (p, e) in local.iter().zip(expected) {
                let placed = translations[k] + rotations[k] * *p;
                assert!(
                    (placed.as_dvec3() - *e).length() < 1e-5,
                    "{} keyframe {k}: {placed} vs {e}",
                    track.name
                );
            }
        }
    }
}

/// An L-system's tubes reach every export under the names of what drew
/// them: glTF node names as they are, USD prims as valid identifiers.
#[test]
fn lsystem_tubes_are_exported_under_the_names_of_what_drew_them() {
    let flower = Flower {
        templates: Vec::new(),
        organs: Vec::new(),
        overlaps: Vec::new(),
        structure: Some(anthesis_flower::structure::Structure::LSystem {
            text: "name A = stem\nname S = stamen\naxiom: A [S] [S]\nA -> F(3)\nS -> F(1)[+F(1)]"
                .to_string(),
            steps: 1,
            surfaces: Default::default(),
            units: 1.0,
        }),
        parts: Vec::new(),
        unit: None,
    };
    let keyframes: Vec<Vec<Vec<DVec3>>> = vec![Vec::new(); 2];
    let tracks =
        anthesis_export::flower_tracks(&flower, &[], keyframes.iter().map(Vec::as_slice), 0)
            .expect("tracks");
    let names: Vec<&str> = tracks.iter().map(|t| t.name.as_str()).collect();
    let expected = [
        "receptacle",
        "stem",
        "stamen-1",
        "stamen-2",
        "stamen-3",
        "stamen-4",
    ];
    assert_eq!(names, expected);
    let bytes = glb_bytes(&tracks, &GlbOptions::default(), &mut |_| {}).expect("glb");
    let gltf = gltf::Gltf::from_slice(&bytes).expect("parse");
    let nodes: Vec<&str> = gltf.nodes().filter_map(|n| n.name()).collect();
    for name in expected {
        assert!(nodes.contains(&name), "{name} in {nodes:?}");
    }
    let usda = String::from_utf8(
        anthesis_export::usd_bytes(&tracks, &Default::default(), &mut |_| {}).expect("usd"),
    )
    .expect("text");
    for prim in ["stem", "stamen_1", "stamen_4"] {
        assert!(usda.contains(&format!("\"{prim}\"")), "{prim}");
    }
    assert!(!usda.contains("segment"), "no segment-N left");
}

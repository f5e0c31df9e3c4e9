//! A template's colour map in the exports: `flower_tracks` bakes it into
//! the track's base-colour texture (white base colour), the .glb carries it
//! as `baseColorTexture` and passes the Khronos validator, and the texture
//! shows the template's colours where its mix map says.

mod common;

use anthesis_export::{Encoding, GlbOptions, flower_tracks, glb_bytes};
use anthesis_flower::{BaseRegion, Colouring, Flower, Organ, Placement, Template, srgb8_to_linear};
use anthesis_maps::{GrowthMaps, KeyedMaps, ScalarMap};
use anthesis_mesh::generate::test_petal;
use common::*;
use glam::{DQuat, DVec3};

const RED: [f32; 4] = [0.8, 0.05, 0.05, 1.0];
const BLUE: [f32; 4] = [0.05, 0.1, 0.9, 1.0];
const GREEN: [f32; 4] = [0.2, 0.6, 0.1, 1.0];

fn template(name: &str, colour: [f32; 4], colouring: Option<Colouring>) -> Template {
    Template {
        name: name.to_owned(),
        mesh: test_petal(4.0, 2.0, 6, 9),
        maps: KeyedMaps::single(GrowthMaps::uniform()),
        dg: 0.0,
        thickness: 0.2,
        stretch_stiffness: 20.0,
        bend_stiffness: 20.0,
        base_region: BaseRegion::default(),
        joint_schedule: Vec::new(),
        colour,
        colouring,
        two_state: None,
        source: None,
        vein: None,
    }
}

/// A red petal painted blue on its right half (`u > 0.5`), and a plain
/// green sepal.
fn flower() -> Flower {
    let organ = |name: &str, template, azimuth_deg| Organ {
        name: name.to_owned(),
        template,
        placement: Placement {
            position: DVec3::new(0.0, 0.0, 0.5),
            azimuth_deg,
            joint_angle_deg: 0.0,
            orientation: DQuat::IDENTITY,
        },
    };
    Flower {
        templates: vec![
            template(
                "petal",
                RED,
                Some(Colouring {
                    second_colour: BLUE,
                    mix: ScalarMap::from_fn(16, 8, |uv| if uv.x > 0.5 { 1.0 } else { 0.0 }),
                    layers: Vec::new(),
                }),
            ),
            template("sepal", GREEN, None),
        ],
        organs: vec![organ("petal-1", 0, 0.0), organ("sepal-1", 1, 180.0)],
        overlaps: Vec::new(),
        structure: None,
        parts: Vec::new(),
        unit: None,
    }
}

fn tracks() -> Vec<anthesis_export::Track> {
    let flower = flower();
    let keyframe: Vec<Vec<DVec3>> = flower
        .organs
        .iter()
        .map(|o| flower.templates[o.template].mesh.positions.clone())
        .collect();
    flower_tracks(
        &flower,
        &[0, 1],
        [keyframe.as_slice(), keyframe.as_slice()],
        0,
    )
    .expect("tracks")
}

fn close(a: [f32; 4], b: [f32; 4], tolerance: f32) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tolerance)
}

#[test]
fn a_colour_map_becomes_the_tracks_texture_with_a_white_base_colour() {
    let tracks = tracks();
    assert_eq!(tracks.len(), 3, "two organs and the receptacle");
    let petal = &tracks[0];
    assert_eq!(petal.base_colour, [1.0; 4]);
    let png = petal.base_colour_png.as_ref().expect("a texture");
    let image = image::load_from_memory(png).expect("a PNG").into_rgba8();
    assert_eq!(image.dimensions(), (16, 8));
    let linear = |x: u32, y: u32| {
        let p = image.get_pixel(x, y).0;
        [
            srgb8_to_linear(p[0]),
            srgb8_to_linear(p[1]),
            srgb8_to_linear(p[2]),
            f32::from(p[3]) / 255.0,
        ]
    };
    assert!(close(linear(2, 4), RED, 0.01), "{:?}", linear(2, 4));
    assert!(close(linear(13, 4), BLUE, 0.01), "{:?}", linear(13, 4));
    // The plain sepal keeps its colour, without a texture.
    assert_eq!(tracks[1].base_colour, GREEN);
    assert_eq!(tracks[1].base_colour_png, None);
    assert_eq!(tracks[2].base_colour_png, None);
    // Render meshes keep the texture.
    let flower = flower();
    let keyframe: Vec<Vec<DVec3>> = flower
        .organs
        .iter()
        .map(|o| flower.templates[o.template].mesh.positions.clone())
        .collect();
    let fine = flower_tracks(&flower, &[0, 1], [keyframe.as_slice()], 1).expect("subdivided");
    assert_eq!(fine[0].base_colour_png, petal.base_colour_png);
}

#[test]
fn a_coloured_flower_passes_the_validator_with_a_base_colour_texture() {
    let tracks = tracks();
    for encoding in Encoding::ALL {
        let options = GlbOptions {
            encoding,
            ..GlbOptions::default()
        };
        let bytes = glb_bytes(&tracks, &options, &mut |_| {}).expect("export");
        assert_valid_glb(&bytes, &format!("coloured-{encoding}"));
        let glb = parse_glb(&bytes);
        let materials = glb.json["materials"].as_array().expect("materials");
        let petal = &materials[0]["pbrMetallicRoughness"];
        assert_eq!(
            petal["baseColorFactor"],
            serde_json::json!([1.0, 1.0, 1.0, 1.0])
        );
        assert_eq!(petal["baseColorTexture"]["index"], 0, "{encoding}");
        let sepal = &materials[1]["pbrMetallicRoughness"];
        assert!(sepal.get("baseColorTexture").is_none(), "{encoding}");
        assert_eq!(glb.json["images"].as_array().map(Vec::len), Some(1));
    }
    // Organs of one template share its image.
    let mut tracks = tracks;
    tracks.insert(1, tracks[0].clone());
    tracks[1].name = "petal-2".into();
    let bytes = glb_bytes(&tracks, &GlbOptions::default(), &mut |_| {}).expect("export");
    assert_valid_glb(&bytes, "coloured-shared");
    let glb = parse_glb(&bytes);
    assert_eq!(glb.json["images"].as_array().map(Vec::len), Some(1));
    for material in 0..2 {
        assert_eq!(
            glb.json["materials"][material]["pbrMetallicRoughness"]["baseColorTexture"]["index"],
            0
        );
    }
}

//! Renders on whatever adapter the machine has (lavapipe in CI). These
//! tests fail, never skip, when no adapter is available.

use anthesis_render::{Background, Camera, OffscreenRenderer, OrganMesh, RenderError};
use std::sync::Arc;

use glam::DVec3;
use image::{Rgba, RgbaImage};

const SIZE: u32 = 96;

fn renderer() -> OffscreenRenderer {
    let renderer = match OffscreenRenderer::new() {
        Ok(r) => r,
        Err(e) => panic!("{e}"),
    };
    eprintln!(
        "adapter: {:?}, sample count {}",
        renderer.adapter_info(),
        renderer.format().sample_count
    );
    renderer
}

/// A square `[-h, h]^2` in the plane z = `z`, wound counter-clockwise seen
/// from +Z, so its normal (the front side) faces +Z.
fn square(half: f64, z: f64, colour_linear: [f32; 4]) -> OrganMesh {
    let positions = [
        DVec3::new(-half, -half, z),
        DVec3::new(half, -half, z),
        DVec3::new(half, half, z),
        DVec3::new(-half, half, z),
    ];
    OrganMesh::from_positions(&positions, &[[0, 1, 2], [0, 2, 3]], colour_linear)
}

/// Looks at the origin from +Z (`from_front`) or -Z, 5 units away, with a
/// 40° field of view: a 2x2 square at z = 0 covers the middle ~55% of the
/// image width, a 1x1 square at z = 0.6 seen from +Z the middle ~31%.
fn camera(from_front: bool) -> Camera {
    Camera {
        eye: DVec3::new(0.0, 0.0, if from_front { 5.0 } else { -5.0 }),
        target: DVec3::ZERO,
        up: DVec3::Y,
        fov_y_deg: 40.0,
    }
}

/// Linear colours (sRGB 0.9, 0.1, 0.1 and 0.1, 0.8, 0.1).
const RED: [f32; 4] = [0.79, 0.01, 0.01, 1.0];
const GREEN: [f32; 4] = [0.01, 0.6, 0.01, 1.0];

fn centre(image: &RgbaImage) -> Rgba<u8> {
    *image.get_pixel(image.width() / 2, image.height() / 2)
}

fn is_reddish(p: Rgba<u8>) -> bool {
    p[0] > 150 && u16::from(p[0]) > 2 * u16::from(p[1].max(p[2]))
}

fn is_greenish(p: Rgba<u8>) -> bool {
    p[1] > 130 && p[1] > p[0] + 60 && p[1] > p[2] + 60
}

/// Relative luminance of an sRGB-encoded pixel, linear in `[0, 1]`.
fn luminance(p: Rgba<u8>) -> f64 {
    let linear = |c: u8| {
        let c = f64::from(c) / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    0.2126 * linear(p[0]) + 0.7152 * linear(p[1]) + 0.0722 * linear(p[2])
}

fn assert_background(image: &RgbaImage, x: u32, y: u32) {
    let down = (y as f32 + 0.5) / image.height() as f32;
    let expected = Background::default().srgb_at(down).map(|c| c * 255.0);
    let got = image.get_pixel(x, y);
    for channel in 0..3 {
        assert!(
            (f32::from(got[channel]) - expected[channel]).abs() <= 3.0,
            "pixel ({x}, {y}) = {got:?}, background there is {expected:?}"
        );
    }
    assert_eq!(got[3], 255);
}

#[test]
fn square_facing_the_camera_is_lit_in_its_colour_on_the_background() {
    let mut renderer = renderer();
    let image = renderer
        .render(&[square(1.0, 0.0, RED)], &camera(true), SIZE, SIZE)
        .expect("render");
    let centre = centre(&image);
    assert!(
        is_reddish(centre),
        "centre pixel {centre:?} is not the lit red"
    );
    assert_eq!(centre[3], 255);
    assert_background(&image, 0, 0);
    assert_background(&image, SIZE - 1, SIZE - 1);
    assert_background(&image, 0, SIZE - 1);
    // The gradient is lighter at the top than at the bottom.
    assert!(luminance(*image.get_pixel(0, 0)) > luminance(*image.get_pixel(0, SIZE - 1)) + 0.2);
}

#[test]
fn nearer_square_occludes_farther_whatever_the_draw_order() {
    let mut renderer = renderer();
    let far_red = square(1.0, 0.0, RED);
    let near_green = square(0.5, 0.6, GREEN);
    // A point on the red square outside the green one (see `camera`).
    let red_only = (SIZE * 2 / 7, SIZE / 2);
    for organs in [
        [far_red.clone(), near_green.clone()],
        [near_green.clone(), far_red.clone()],
    ] {
        let image = renderer
            .render(&organs, &camera(true), SIZE, SIZE)
            .expect("render");
        let centre = centre(&image);
        assert!(
            is_greenish(centre),
            "centre {centre:?} should be the near green square"
        );
        let side = *image.get_pixel(red_only.0, red_only.1);
        assert!(
            is_reddish(side),
            "pixel {red_only:?} = {side:?} should be the far red square"
        );
    }
    // Seen from behind, the red square is the nearer one.
    let image = renderer
        .render(&[far_red, near_green], &camera(false), SIZE, SIZE)
        .expect("render");
    assert!(
        is_reddish(centre(&image)),
        "from behind: {:?}",
        centre(&image)
    );
}

#[test]
fn back_side_is_drawn_a_little_darker_than_the_front_not_muddy() {
    let mut renderer = renderer();
    let organs = [square(1.0, 0.0, RED)];
    let front = centre(
        &renderer
            .render(&organs, &camera(true), SIZE, SIZE)
            .expect("front"),
    );
    let back_image = renderer
        .render(&organs, &camera(false), SIZE, SIZE)
        .expect("back");
    let back = centre(&back_image);
    assert!(is_reddish(front), "front {front:?}");
    assert!(
        is_reddish(back),
        "back side not drawn in the organ colour: {back:?}"
    );
    // The sides read apart, but the outer side of a bud is not a dark,
    // muddy version of the inner one.
    let ratio = luminance(back) / luminance(front);
    assert!(
        (0.8..0.97).contains(&ratio),
        "back {back:?} / front {front:?} = {ratio}"
    );
    assert_background(&back_image, 0, 0);
}

/// The pixel `point` is drawn at by `camera` in a `SIZE` x `SIZE` image.
fn pixel_of(camera: &Camera, point: DVec3) -> (u32, u32) {
    let clip = camera.view_projection(1.0) * point.as_vec3().extend(1.0);
    let ndc = clip.truncate() / clip.w;
    let x = (0.5 + 0.5 * ndc.x) * SIZE as f32;
    let y = (0.5 - 0.5 * ndc.y) * SIZE as f32;
    (x as u32, y as u32)
}

#[test]
fn the_flower_casts_a_soft_shadow_on_the_ground_under_it() {
    let mut renderer = renderer();
    // An upright 2 x 2 square (1 across around the axis), seen from above
    // the ground in front of it.
    let organs = [square(1.0, 0.0, RED)];
    let camera = Camera {
        eye: DVec3::new(0.0, 2.0, 6.0),
        target: DVec3::new(0.0, -0.5, 0.0),
        up: DVec3::Y,
        fov_y_deg: 40.0,
    };
    let image = renderer
        .render(&organs, &camera, SIZE, SIZE)
        .expect("render");
    // The ground (just below the square's lowest point, y = -1) half a
    // radius in front of it, and a point on the same image row far off to
    // the side.
    let (x, y) = pixel_of(&camera, DVec3::new(0.0, -1.02, 0.5));
    let (x_far, y_far) = (2, y);
    assert!(x > 10 && x < SIZE - 10 && y < SIZE - 2, "in view: {x}, {y}");
    let under = *image.get_pixel(x, y);
    let far = *image.get_pixel(x_far, y_far);
    let ratio = luminance(under) / luminance(far);
    assert!(
        (0.4..0.8).contains(&ratio),
        "shadow {under:?} against open ground {far:?}: {ratio}"
    );
    assert_background(&image, x_far, y_far);
    // Nothing on the ground: no shadow.
    let empty = renderer.render(&[], &camera, SIZE, SIZE).expect("render");
    assert_background(&empty, x, y);
}

#[test]
fn overlay_replaces_the_organ_colour_with_the_ramp() {
    let mut renderer = renderer();
    let low = square(1.0, 0.0, GREEN).with_overlay(vec![0.0; 4]);
    let high = square(1.0, 0.0, GREEN).with_overlay(vec![1.0; 4]);
    let low = centre(
        &renderer
            .render(&[low], &camera(true), SIZE, SIZE)
            .expect("low"),
    );
    let high = centre(
        &renderer
            .render(&[high], &camera(true), SIZE, SIZE)
            .expect("high"),
    );
    assert!(
        low[2] > low[0] + 60 && low[2] > low[1] + 40,
        "low end should be blue: {low:?}"
    );
    assert!(is_reddish(high), "high end should be red: {high:?}");
}

/// The square's UVs: `u` along +X, `v` along +Y (0 at the bottom edge).
const SQUARE_UVS: [[f32; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];

#[test]
fn a_texture_paints_the_organ_by_its_uvs() {
    let mut renderer = renderer();
    // 2 x 2 pixels, row 0 the top (v = 1): red bottom-left, green
    // bottom-right and top-right, red top-left. sRGB codes.
    let (red, green) = ([230, 25, 25, 255], [25, 204, 25, 255]);
    let painted = image::RgbaImage::from_fn(2, 2, |x, _| Rgba(if x == 0 { red } else { green }));
    let organ = square(1.0, 0.0, [1.0; 4]).with_texture(SQUARE_UVS.to_vec(), Arc::new(painted));
    let image = renderer
        .render(std::slice::from_ref(&organ), &camera(true), SIZE, SIZE)
        .expect("render");
    let left = pixel_of(&camera(true), DVec3::new(-0.6, 0.0, 0.0));
    let right = pixel_of(&camera(true), DVec3::new(0.6, 0.0, 0.0));
    let left = *image.get_pixel(left.0, left.1);
    let right = *image.get_pixel(right.0, right.1);
    assert!(is_reddish(left), "u < 0.5 is red: {left:?}");
    assert!(is_greenish(right), "u > 0.5 is green: {right:?}");
    // The texture is multiplied with the organ's colour: white over red
    // is the flat red of an untextured square.
    let white = image::RgbaImage::from_pixel(1, 1, Rgba([255; 4]));
    let textured = square(1.0, 0.0, RED).with_texture(SQUARE_UVS.to_vec(), Arc::new(white));
    let flat = centre(
        &renderer
            .render(&[square(1.0, 0.0, RED)], &camera(true), SIZE, SIZE)
            .expect("flat"),
    );
    let through_white = centre(
        &renderer
            .render(&[textured], &camera(true), SIZE, SIZE)
            .expect("white texture"),
    );
    assert_eq!(flat, through_white);
    // Drawn again with the same image (kept uploaded) and then another.
    let again = renderer
        .render(std::slice::from_ref(&organ), &camera(true), SIZE, SIZE)
        .expect("again");
    assert_eq!(again, image);
    // A texture with the wrong number of coordinates is refused.
    let mut broken = organ.clone();
    if let Some(texture) = &mut broken.texture {
        texture.uvs.pop();
    }
    assert!(
        renderer
            .render(&[broken], &camera(true), SIZE, SIZE)
            .is_err()
    );
}

#[test]
fn malformed_meshes_and_sizes_are_errors() {
    let mut renderer = renderer();
    let mut broken = square(1.0, 0.0, RED);
    broken.triangles.push([0, 2, 7]);
    match renderer.render(
        &[square(1.0, 0.0, GREEN), broken],
        &camera(true),
        SIZE,
        SIZE,
    ) {
        Err(RenderError::InvalidMesh { organ: 1, reason }) => {
            assert!(reason.contains("vertex 7"), "{reason}")
        }
        other => panic!("expected InvalidMesh for organ 1, got {other:?}"),
    }
    assert!(matches!(
        renderer.render(&[], &camera(true), 0, SIZE),
        Err(RenderError::InvalidSize { .. })
    ));
    // The renderer still works afterwards, and with no organs draws only
    // the background.
    let image = renderer
        .render(&[], &camera(true), 40, 30)
        .expect("empty scene");
    assert_eq!(image.dimensions(), (40, 30));
    assert_background(&image, 20, 15);
}

//! `anthesis render` end to end on the software renderer (Mesa's lavapipe
//! here and in CI): a project in, PNG pictures of chosen keyframes out; bad
//! input gives one line and a non-zero exit. Without a graphics adapter the
//! rendering test fails: it is not skipped.

use std::path::{Path, PathBuf};

use image::RgbaImage;

mod common;

use common::{anthesis, one_line_error, text};

fn utf8(path: &Path) -> &str {
    path.to_str().expect("utf-8 path")
}

fn saved_whorl(dir: &Path) -> PathBuf {
    let project = anthesis_sim::fixtures::whorl(3, 8, 14, 4);
    let path = dir.join("whorl.anthesis.toml");
    anthesis_flower::project::save_project(&project, &path).expect("save");
    path
}

fn load_png(path: &Path) -> RgbaImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgba8()
}

fn differs(a: &image::Rgba<u8>, b: &image::Rgba<u8>) -> bool {
    a.0.iter().zip(b.0.iter()).any(|(x, y)| x.abs_diff(*y) > 8)
}

/// Pixels that differ from the background. The background is a vertical
/// gradient and the framing keeps a margin, so the left column of each row
/// is background.
fn organ_pixels(picture: &RgbaImage) -> Vec<(u32, u32)> {
    picture
        .enumerate_pixels()
        .filter(|(_, y, p)| differs(p, picture.get_pixel(0, *y)))
        .map(|(x, y, _)| (x, y))
        .collect()
}

#[test]
fn render_writes_the_requested_frames_and_a_tile() {
    let dir = tempfile::tempdir().expect("tempdir");
    let project = saved_whorl(dir.path());
    let pictures = dir.path().join("pictures");
    std::fs::create_dir(&pictures).expect("mkdir");
    let out = anthesis(&[
        "render",
        utf8(&project),
        "--frames",
        "4,0,2",
        "--out",
        utf8(&pictures),
        "--size",
        "160x120",
        "--tile",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));

    let mut names: Vec<String> = std::fs::read_dir(&pictures)
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "camera.json",
            "frame-000.png",
            "frame-002.png",
            "frame-004.png",
            "tiled.png"
        ],
        "only the pictures and their camera, no temporary files"
    );
    let frames: Vec<RgbaImage> = ["frame-000.png", "frame-002.png", "frame-004.png"]
        .iter()
        .map(|name| load_png(&pictures.join(name)))
        .collect();
    for (frame, picture) in [0, 2, 4].iter().zip(&frames) {
        assert_eq!(picture.dimensions(), (160, 120), "frame {frame}");
        let organ = organ_pixels(picture);
        let share = organ.len() as f64 / (160.0 * 120.0);
        assert!(
            (0.03..0.9).contains(&share),
            "frame {frame}: {:.1} % of the picture is flower",
            100.0 * share
        );
        // The petal template is orange, the sepal template green; the
        // background is blue-grey.
        let orange = picture
            .pixels()
            .filter(|p| p[0] > p[2].saturating_add(60) && p[0] > p[1].saturating_add(20))
            .count();
        let green = picture
            .pixels()
            .filter(|p| p[1] > p[0].saturating_add(5) && p[1] > p[2].saturating_add(40))
            .count();
        assert!(
            orange > 50 && green > 50,
            "frame {frame}: {orange} orange and {green} green pixels"
        );
    }
    // The flower moves between keyframes, in one camera.
    for (a, b) in [(0, 1), (1, 2), (0, 2)] {
        let changed = frames[a]
            .pixels()
            .zip(frames[b].pixels())
            .filter(|(p, q)| differs(p, q))
            .count();
        assert!(
            changed > 100,
            "frames {a} and {b} differ in {changed} pixels"
        );
    }
    let tiled = load_png(&pictures.join("tiled.png"));
    assert_eq!(tiled.dimensions(), (480, 120));
    for (i, frame) in frames.iter().enumerate() {
        let x0 = 160 * i as u32;
        let tile = image::imageops::crop_imm(&tiled, x0, 0, 160, 120).to_image();
        assert!(tile == *frame, "tile {i} is frame {i}");
    }
}

#[test]
fn render_animation_writes_a_looping_gif_and_numbered_png_frames() {
    use image::AnimationDecoder;
    use image::codecs::gif::GifDecoder;

    let dir = tempfile::tempdir().expect("tempdir");
    let project = saved_whorl(dir.path());
    let gif = dir.path().join("opening.gif");
    let out = anthesis(&[
        "render",
        utf8(&project),
        "--animation",
        utf8(&gif),
        "--step",
        "3",
        "--size",
        "96x64",
        "--fps",
        "10",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let file = std::io::BufReader::new(std::fs::File::open(&gif).expect("gif written"));
    let frames = GifDecoder::new(file)
        .expect("a GIF")
        .into_frames()
        .collect_frames()
        .expect("frames decode");
    // Keyframes 0, 3 and the last (4).
    assert_eq!(frames.len(), 3);
    let delays: Vec<(u32, u32)> = frames.iter().map(|f| f.delay().numer_denom_ms()).collect();
    let ms = |(n, d): (u32, u32)| f64::from(n) / f64::from(d);
    assert!((ms(delays[0]) - 100.0).abs() < 1e-9, "{delays:?}");
    // The open flower is held for a second before the loop starts again.
    assert!((ms(delays[2]) - 1100.0).abs() < 1e-9, "{delays:?}");
    let pictures: Vec<RgbaImage> = frames.into_iter().map(|f| f.into_buffer()).collect();
    for picture in &pictures {
        assert_eq!(picture.dimensions(), (96, 64));
        assert!(organ_pixels(picture).len() > 100, "the flower shows");
    }
    let changed = pictures[0]
        .pixels()
        .zip(pictures[2].pixels())
        .filter(|(p, q)| differs(p, q))
        .count();
    assert!(
        changed > 50,
        "bud and open flower differ in {changed} pixels"
    );

    // A folder (created) of PNG frames, the camera turning once around.
    let folder = dir.path().join("frames");
    let out = anthesis(&[
        "render",
        utf8(&project),
        "--animation",
        utf8(&folder),
        "--turn",
        "360",
        "--size",
        "64x48",
        "--background",
        "ffffff",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let mut names: Vec<String> = std::fs::read_dir(&folder)
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let expected: Vec<String> = (0..5).map(|i| format!("frame-{i:04}.png")).collect();
    assert_eq!(names, expected);
    let first = load_png(&folder.join("frame-0000.png"));
    assert_eq!(first.dimensions(), (64, 48));
    assert_eq!(
        first.get_pixel(0, 0).0,
        [255, 255, 255, 255],
        "white background"
    );

    // Impossible requests fail before simulating and write nothing.
    let too_wide = dir.path().join("wide.gif");
    for (args, expected) in [
        (
            vec!["--animation", utf8(&too_wide), "--size", "70000x10"],
            "65535",
        ),
        (
            vec!["--animation", utf8(&too_wide), "--fps", "60"],
            "frames per second",
        ),
        (
            vec!["--animation", utf8(&too_wide), "--step", "0"],
            "--step",
        ),
        (
            vec!["--animation", utf8(&too_wide), "--background", "white"],
            "RRGGBB",
        ),
    ] {
        let args: Vec<&str> = ["render", utf8(&project)].into_iter().chain(args).collect();
        let out = one_line_error(&args);
        let stderr = text(&out.stderr);
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
    }
    assert!(!too_wide.exists());
}

#[test]
fn render_refuses_bad_input_with_one_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let project = saved_whorl(dir.path());
    let p = utf8(&project);
    let folder = dir.path().join("pictures");
    std::fs::create_dir(&folder).expect("mkdir");
    let out_dir = utf8(&folder);
    // A missing folder is created only when its parent exists.
    let missing_folder = dir.path().join("missing/pictures").display().to_string();
    let a_file = project.display().to_string();
    let missing_project = dir.path().join("nope.anthesis.toml").display().to_string();
    let mut cases: Vec<(Vec<&str>, &str)> = vec![
        (vec![p, "--frames", "1,x", "--out", out_dir], "`x`"),
        (vec![p, "--frames", "", "--out", out_dir], "--frames"),
        (vec![p, "--frames", "0,-1", "--out", out_dir], "`-1`"),
        (vec![p, "--frames", "5", "--out", out_dir], "keyframe 5"),
        (
            vec![p, "--frames", "5", "--keyframes", "3", "--out", out_dir],
            "3 keyframes",
        ),
        (vec![p, "--out", &missing_folder], "does not exist"),
        (vec![p, "--out", &a_file], "not a folder"),
        (vec![p, "--out", out_dir, "--size", "0x10"], "--size"),
        (vec![p, "--out", out_dir, "--size", "big"], "--size"),
        (vec![p, "--out", out_dir, "--organ", "nobody"], "nobody"),
        (
            vec![p, "--out", out_dir, "--elevation", "120"],
            "--elevation",
        ),
        (
            vec![&missing_project, "--out", out_dir],
            "nope.anthesis.toml",
        ),
    ];
    // Not writable even for root.
    if cfg!(target_os = "linux") {
        cases.push((vec![p, "--out", "/proc"], "cannot write"));
    }
    for (args, expected) in cases {
        let args: Vec<&str> = std::iter::once("render").chain(args).collect();
        let out = one_line_error(&args);
        let stderr = text(&out.stderr);
        assert!(
            stderr.contains(expected),
            "{args:?}: `{expected}` missing from {stderr}"
        );
    }
    assert_eq!(
        std::fs::read_dir(&folder).expect("list").count(),
        0,
        "nothing written"
    );
}

#[test]
fn render_without_a_graphics_adapter_says_so_in_one_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let project = saved_whorl(dir.path());
    // Direct3D 12 does not exist on this platform: no adapter.
    let out = common::command()
        .args(["render", utf8(&project), "--out", utf8(dir.path())])
        .env("WGPU_BACKEND", if cfg!(windows) { "metal" } else { "dx12" })
        .output()
        .expect("the binary runs");
    assert!(!out.status.success());
    let stderr = text(&out.stderr);
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert!(stderr.contains("no graphics adapter"), "{stderr}");
}

#[test]
fn render_subdivide_draws_the_smooth_render_meshes_in_the_same_place() {
    let dir = tempfile::tempdir().expect("tempdir");
    let project = saved_whorl(dir.path());
    let picture_at = |level: &str| {
        let pictures = dir.path().join(format!("level-{level}"));
        let out = anthesis(&[
            "render",
            utf8(&project),
            "--frames",
            "4",
            "--out",
            utf8(&pictures),
            "--size",
            "200x150",
            "--subdivide",
            level,
        ]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        load_png(&pictures.join("frame-004.png"))
    };
    let (coarse, smooth) = (picture_at("0"), picture_at("2"));
    // The smooth surface follows the simulated one: nearly the same
    // silhouette (it rounds off the simulated mesh's facets and rim
    // corners), but not the same picture (its shading is smoother).
    let inside = |picture: &RgbaImage| -> std::collections::HashSet<(u32, u32)> {
        organ_pixels(picture).into_iter().collect()
    };
    let (a, b) = (inside(&coarse), inside(&smooth));
    let overlap = a.intersection(&b).count() as f64 / a.union(&b).count() as f64;
    assert!(overlap > 0.9, "silhouettes overlap by {overlap:.3}");
    let changed = coarse
        .pixels()
        .zip(smooth.pixels())
        .filter(|(p, q)| differs(p, q))
        .count();
    assert!(changed > 20, "only {changed} pixels changed");
}

/// The colour of `picture` around `(x, y)`: the mean of the 3x3 pixels.
fn colour_around(picture: &RgbaImage, x: f64, y: f64) -> [f64; 3] {
    let (x, y) = (x.round() as i64, y.round() as i64);
    let mut sum = [0.0; 3];
    for dy in -1..=1 {
        for dx in -1..=1 {
            let p = picture.get_pixel((x + dx) as u32, (y + dy) as u32);
            for (s, c) in sum.iter_mut().zip(p.0) {
                *s += f64::from(c) / 9.0;
            }
        }
    }
    sum
}

#[test]
fn render_shows_a_two_colour_template_in_both_colours_where_its_mix_map_says() {
    use anthesis_flower::Colouring;
    use glam::DVec2;
    // A red organ painted blue over its right half (u > 0.5).
    let mut project = anthesis_sim::fixtures::whorl(1, 8, 14, 2);
    let template = &mut project.flower.templates[0];
    template.colour = [0.8, 0.05, 0.03, 1.0];
    template.colouring = Some(Colouring {
        second_colour: [0.03, 0.08, 0.8, 1.0],
        mix: anthesis_maps::ScalarMap::from_fn(32, 32, |uv| if uv.x > 0.5 { 1.0 } else { 0.0 }),
        layers: Vec::new(),
    });
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("two-colour.anthesis.toml");
    anthesis_flower::project::save_project(&project, &path).expect("save");
    let (azimuth_deg, elevation_deg) = (project.flower.organs[0].placement.azimuth_deg, 10.0);
    let out = anthesis(&[
        "render",
        utf8(&path),
        "--frames",
        "0",
        "--out",
        utf8(dir.path()),
        "--size",
        "320x240",
        "--azimuth",
        &azimuth_deg.to_string(),
        "--elevation",
        &elevation_deg.to_string(),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let picture = load_png(&dir.path().join("frame-000.png"));

    // Where the organ's points at u = 0.25 and u = 0.75 (half way up) land.
    let bud = anthesis_sim::Simulation::new(&project, &anthesis_sim::Selection::All)
        .expect("simulation")
        .bud();
    let positions = &bud.positions_in_world[0];
    let (low, high) = positions
        .iter()
        .fold((positions[0], positions[0]), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    let camera = anthesis_render::Camera::framing(low, high, azimuth_deg, elevation_deg);
    let mesh = &project.flower.templates[0].mesh;
    let at_uv = |uv: DVec2| {
        let nearest = (0..mesh.vertex_count())
            .min_by(|&a, &b| {
                mesh.uvs[a]
                    .distance(uv)
                    .total_cmp(&mesh.uvs[b].distance(uv))
            })
            .expect("vertices");
        let clip = camera.view_projection(320.0 / 240.0) * positions[nearest].as_vec3().extend(1.0);
        let ndc = clip.truncate() / clip.w;
        colour_around(
            &picture,
            (f64::from(ndc.x) + 1.0) * 0.5 * 320.0,
            (1.0 - f64::from(ndc.y)) * 0.5 * 240.0,
        )
    };
    let base_side = at_uv(DVec2::new(0.25, 0.5));
    let second_side = at_uv(DVec2::new(0.75, 0.5));
    assert!(
        base_side[0] > base_side[2] + 80.0,
        "u = 0.25 shows the red base colour: {base_side:?}"
    );
    assert!(
        second_side[2] > second_side[0] + 80.0,
        "u = 0.75 shows the blue second colour: {second_side:?}"
    );
}

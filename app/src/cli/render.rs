//! `anthesis render`: pictures of chosen keyframes, rendered offscreen with
//! one camera for the whole run, or the opening as an animation (GIF or PNG
//! frames, see [`crate::animation`]).

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use anthesis_flower::Project;
use anthesis_mesh::Subdivision;
use anthesis_render::{Background, Camera, OffscreenRenderer, OrganMesh, organs_bounds_in_world};
use anthesis_sim::batch::step_through;
use anthesis_sim::memory::KeyframeCost;
use anthesis_sim::{Selection, Simulation};
use anyhow::{Context, Result, bail};
use clap::Args;
use image::RgbaImage;

use super::simulate::{Progress, set_keyframes};
use super::stream::{say, say_part};
use super::{at_resolution, load, selection};
use crate::animation::{self, AnimationOptions, AnimationTarget, write_png};

#[derive(Debug, Args)]
pub struct RenderArgs {
    /// A project file (*.anthesis.toml), its folder, or builtin:NAME.
    pub project: PathBuf,
    /// Keyframes to render, comma-separated; 0 is the bud (default: the bud
    /// and every quarter of the run).
    #[arg(long, value_name = "N,N,...")]
    pub frames: Option<String>,
    /// An existing folder; receives frame-NNN.png per keyframe (NNN the
    /// keyframe number).
    #[arg(long, value_name = "DIR", required_unless_present = "animation")]
    pub out: Option<PathBuf>,
    /// Render the opening as an animation instead: OUT.gif (loops, holds the
    /// open flower for a second) or a folder (created if missing) of
    /// frame-0000.png, frame-0001.png, … in playback order.
    #[arg(long, value_name = "OUT.gif|FOLDER", conflicts_with_all = ["out", "frames", "tile"])]
    pub animation: Option<PathBuf>,
    /// With --animation: show every N-th keyframe (the last is always shown).
    #[arg(long, value_name = "N", default_value_t = 1, requires = "animation")]
    pub step: u32,
    /// With --animation: turn the camera this many degrees around the flower
    /// axis over the animation (360 = once around).
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_negative_numbers = true,
        requires = "animation"
    )]
    pub turn: f64,
    /// With --animation to a GIF: frames per second, from 0.0016 to 50.
    #[arg(long, value_name = "F", default_value_t = crate::animation::DEFAULT_GIF_FRAMES_PER_SECOND, requires = "animation")]
    pub fps: f64,
    /// Simulate and show only this organ (no collisions).
    #[arg(long, value_name = "NAME")]
    pub organ: Option<String>,
    /// Image size in pixels.
    #[arg(long, value_name = "WxH", default_value = "640x480")]
    pub size: String,
    /// Camera direction around the flower axis in degrees (0 = from +Z,
    /// 90 = from +X).
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 30.0,
        allow_negative_numbers = true
    )]
    pub azimuth: f64,
    /// Camera height in degrees above the horizontal (90 = from straight
    /// above, negative = from below).
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 20.0,
        allow_negative_numbers = true
    )]
    pub elevation: f64,
    /// Number of keyframes of the run (default: the project's).
    #[arg(long, value_name = "N")]
    pub keyframes: Option<i64>,
    /// Simulate every template remeshed at this mean edge length (see
    /// `simulate --edge`).
    #[arg(long, value_name = "LENGTH|as-built", value_parser = super::parse_edge)]
    pub edge: Option<anthesis_flower::Resolution>,
    /// Also write DIR/tiled.png: the frames side by side, in keyframe order.
    #[arg(long)]
    pub tile: bool,
    /// A plain background colour as hexadecimal sRGB, such as ffffff for
    /// white (default: a soft blue-grey gradient).
    #[arg(long, value_name = "RRGGBB")]
    pub background: Option<String>,
    /// Draw each organ as a smooth render mesh: N levels of Loop
    /// subdivision of the simulated mesh, about 4^N times the vertices
    /// (0 = the simulated mesh), as `simulate --subdivide` exports it.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub subdivide: u32,
}

pub fn render(args: &RenderArgs) -> Result<()> {
    let mut project = load(&args.project)?;
    let keyframes = args
        .keyframes
        .map(|n| super::check_count("--keyframes", n, 1, anthesis_flower::MAX_KEYFRAMES as usize))
        .transpose()?
        .map(|n| n as u32);
    set_keyframes(&mut project, keyframes)?;
    let selection = selection(&project, args.organ.as_deref())?;
    let project = at_resolution(project, args.edge, Some((&selection, KeyframeCost::Kept)))?;
    let last_keyframe = project.settings.keyframes;
    let (width, height) = parse_size(&args.size)?;
    if !args.azimuth.is_finite() {
        bail!(
            "--azimuth must be a number of degrees, got {}",
            args.azimuth
        );
    }
    if !(-90.0..=90.0).contains(&args.elevation) {
        bail!(
            "--elevation must be between -90 and 90 degrees, got {}",
            args.elevation
        );
    }
    let animation = match &args.animation {
        Some(path) => {
            if args.step == 0 {
                bail!("--step must be at least 1");
            }
            let target = AnimationTarget::of(path);
            // A GIF frame lasts 1/100 s to 655.35 s (whole hundredths).
            let slowest = 100.0 / f64::from(u16::MAX);
            let fastest = crate::animation::MAX_GIF_FRAMES_PER_SECOND;
            if matches!(target, AnimationTarget::Gif(_))
                && !(args.fps >= slowest && args.fps <= fastest)
            {
                bail!(
                    "--fps must be from {:.4} to {fastest} frames per second for a GIF (a frame \
                     lasts a whole number of hundredths of a second up to 655.35 s; browsers show \
                     faster GIFs at 10), got {}",
                    (slowest * 1e4).ceil() / 1e4,
                    args.fps
                );
            }
            let options = AnimationOptions {
                width,
                height,
                azimuth_deg: args.azimuth,
                elevation_deg: args.elevation,
                turn_deg: args.turn,
                frames_per_second: args.fps,
            };
            animation::check_request(&target, &options)?;
            Some((target, options))
        }
        None => None,
    };
    let frames = match (&animation, &args.frames) {
        (Some(_), _) => animation::keyframes_every(args.step, last_keyframe),
        (None, Some(list)) => parse_frames(list, last_keyframe)?,
        (None, None) => default_frames(last_keyframe),
    };
    let out = match (&animation, &args.out) {
        (None, Some(out)) => {
            check_folder(out)?;
            Some(out)
        }
        _ => None,
    };
    let background = args.background.as_deref().map(parse_colour).transpose()?;
    anthesis_export::check_render_level(
        &project.flower,
        &selection.organs(project.flower.organs.len()),
        frames.len(),
        args.subdivide,
    )?;
    // Before the simulation, so that a machine without a GPU driver fails
    // at once.
    let mut renderer = OffscreenRenderer::new().context("cannot render")?;
    if let Some(srgb) = background {
        renderer.set_background(Background::plain(srgb));
    }
    let max_side = renderer.device().limits().max_texture_dimension_2d;
    if width > max_side || height > max_side {
        bail!(
            "--size {width}x{height} is too large: this GPU renders at most {max_side} pixels a side"
        );
    }

    let scenes = simulate_scenes(&project, &selection, &frames, args.subdivide)?;
    if let Some((target, options)) = &animation {
        let count = scenes.len();
        let organs: Vec<Vec<OrganMesh>> = scenes.into_iter().map(|(_, organs)| organs).collect();
        let show_progress = std::io::stderr().is_terminal();
        animation::write_animation(&mut renderer, &organs, options, target, &mut |done| {
            if show_progress {
                say_part!("\rrendered frame {done}/{count}   ");
            }
        })?;
        if show_progress {
            say!();
        }
        say!(
            "wrote {count} frame(s) of {width}x{height} to {}",
            target.path().display()
        );
        return Ok(());
    }
    let Some(out) = out else {
        bail!("--out DIR or --animation OUT.gif|FOLDER says where the pictures go");
    };

    write_stills(args, &mut renderer, &scenes, out, (width, height))
}

/// Renders each scene as `out/frame-NNN.png` with one camera framing them
/// all, writes `camera.json` and, with `--tile`, the pictures side by side.
fn write_stills(
    args: &RenderArgs,
    renderer: &mut OffscreenRenderer,
    scenes: &[(u32, Vec<OrganMesh>)],
    out: &Path,
    (width, height): (u32, u32),
) -> Result<()> {
    // One camera for all pictures, so the flower does not jump between them.
    let bounds = scenes
        .iter()
        .filter_map(|(_, organs)| organs_bounds_in_world(organs))
        .reduce(|(lo_a, hi_a), (lo_b, hi_b)| (lo_a.min(lo_b), hi_a.max(hi_b)));
    let Some((lo, hi)) = bounds else {
        bail!("there is nothing to render: the organs have no vertices");
    };
    let camera = Camera::framing(lo, hi, args.azimuth, args.elevation);
    let mut pictures = Vec::with_capacity(scenes.len());
    for (index, organs) in scenes {
        let picture = renderer
            .render(organs, &camera, width, height)
            .with_context(|| format!("cannot render keyframe {index}"))?;
        let path = out.join(format!("frame-{index:03}.png"));
        write_png(&path, &picture)?;
        pictures.push(picture);
    }
    write_camera(&out.join("camera.json"), &camera, width, height)?;
    let mut written = scenes.len();
    if args.tile {
        write_png(&out.join("tiled.png"), &side_by_side(&pictures))?;
        written += 1;
    }
    say!(
        "wrote {written} picture(s) of {width}x{height} and camera.json to {}",
        out.display()
    );
    Ok(())
}

/// The camera of the pictures, for matching them in another renderer: eye,
/// target and up in the world frame, the vertical field of view of these
/// pictures in degrees (what three.js and Blender call the field of view
/// for a landscape picture), the near clipping distance, and the size.
#[derive(serde::Serialize)]
struct CameraFile {
    eye: [f64; 3],
    target: [f64; 3],
    up: [f64; 3],
    vertical_fov_deg: f64,
    near: f64,
    width: u32,
    height: u32,
}

fn write_camera(path: &Path, camera: &Camera, width: u32, height: u32) -> Result<()> {
    let aspect = width as f32 / height as f32;
    let file = CameraFile {
        eye: camera.eye.to_array(),
        target: camera.target.to_array(),
        up: camera.up.to_array(),
        vertical_fov_deg: camera.vertical_fov(aspect).to_degrees(),
        near: camera.near_clip(),
        width,
        height,
    };
    let json = serde_json::to_string_pretty(&file)?;
    Ok(anthesis_files::write_atomic(path, json.as_bytes())?)
}

/// `RRGGBB` hexadecimal sRGB (a leading `#` allowed) as components in
/// `[0, 1]`.
fn parse_colour(hex: &str) -> Result<[f32; 3]> {
    let digits = hex.trim().trim_start_matches('#');
    let channel = |i: usize| {
        digits
            .get(2 * i..2 * i + 2)
            .and_then(|d| u8::from_str_radix(d, 16).ok())
    };
    match (digits.len(), channel(0), channel(1), channel(2)) {
        (6, Some(r), Some(g), Some(b)) => Ok([r, g, b].map(|c| f32::from(c) / 255.0)),
        _ => bail!(
            "--background takes a colour as RRGGBB hexadecimal, such as ffffff for white, not `{hex}`"
        ),
    }
}

/// Simulates through the last of `frames` (sorted keyframe numbers, 0 the
/// bud) and returns each of those keyframes' organs, ready to draw, as
/// render meshes of `render_level` levels of subdivision (0: as simulated).
fn simulate_scenes(
    project: &Project,
    selection: &Selection,
    frames: &[u32],
    render_level: u32,
) -> Result<Vec<(u32, Vec<OrganMesh>)>> {
    anthesis_sim::memory::check_run(project, selection, KeyframeCost::Kept)?;
    let mut sim = Simulation::new(project, selection)?;
    // Each organ's colour, or its template's colour map (white times the
    // baked image), as the viewport draws it.
    let looks: Vec<_> = selection
        .organs(project.flower.organs.len())
        .iter()
        .map(|&organ| crate::look::template_look(project.flower.template_of(organ)))
        .collect();
    // The same render meshes as `simulate --subdivide` exports
    // (`anthesis_export::Track::subdivided`): each organ's subdivision built
    // once, its corners found in the bud.
    let bud = sim.bud();
    let subdivisions: Vec<Subdivision> = selection
        .organs(project.flower.organs.len())
        .iter()
        .zip(&bud.positions_in_world)
        .map(|(&organ, positions)| {
            let template = &project.flower.template_of(organ).mesh;
            let in_bud = anthesis_mesh::Mesh {
                positions: positions.clone(),
                ..template.clone()
            };
            Subdivision::new(&in_bud, render_level).with_context(|| {
                format!(
                    "cannot subdivide organ `{}`",
                    project.flower.organs[organ].name
                )
            })
        })
        .collect::<Result<_>>()?;
    let organs_at = |positions: &[Vec<glam::DVec3>]| -> Vec<OrganMesh> {
        positions
            .iter()
            .zip(&subdivisions)
            .zip(&looks)
            .map(|((p, s), (colour, texture))| {
                let mesh = OrganMesh::from_positions(&s.apply(p), s.triangles(), *colour);
                crate::look::with_texture(mesh, s.uvs(), texture.as_ref())
            })
            .collect()
    };
    let organs_at = |positions: &[Vec<glam::DVec3>], keyframe: u32| -> Vec<OrganMesh> {
        let mut meshes = organs_at(positions);
        meshes.extend(crate::parts::part_meshes(
            &project.flower,
            f64::from(keyframe),
        ));
        meshes
    };
    let mut scenes: Vec<(u32, Vec<OrganMesh>)> = Vec::with_capacity(frames.len());
    if frames.first() == Some(&0) {
        scenes.push((0, organs_at(&bud.positions_in_world, 0)));
    }
    let last_wanted = frames.last().copied().unwrap_or(0);
    let last = last_wanted.min(sim.keyframe_count());
    let mut progress = Progress::new();
    let stepped = step_through(&mut sim, last, &|| false, &mut |sim, keyframe| {
        progress.show(sim, keyframe.index, last);
        if frames.binary_search(&keyframe.index).is_ok() {
            scenes.push((
                keyframe.index,
                organs_at(&keyframe.positions_in_world, keyframe.index),
            ));
        }
    });
    progress.finish(&sim, stepped.failure)?;
    Ok(scenes)
}

/// The bud, the last keyframe and the quarters in between (without
/// repeats on short runs).
fn default_frames(last_keyframe: u32) -> Vec<u32> {
    let mut frames: Vec<u32> = (0..=4).map(|q| q * last_keyframe / 4).collect();
    frames.dedup();
    frames
}

/// A comma-separated list of keyframe numbers, each at most
/// `last_keyframe`; sorted, repeats dropped.
fn parse_frames(list: &str, last_keyframe: u32) -> Result<Vec<u32>> {
    let mut frames = Vec::new();
    for item in list.split(',').map(str::trim) {
        let Ok(frame) = item.parse::<u32>() else {
            bail!(
                "--frames takes keyframe numbers separated by commas (0 is the bud), `{item}` is not one"
            );
        };
        if frame > last_keyframe {
            bail!(
                "--frames: keyframe {frame} is past the end of the run ({last_keyframe} keyframes; --keyframes sets how many)"
            );
        }
        frames.push(frame);
    }
    frames.sort_unstable();
    frames.dedup();
    Ok(frames)
}

/// `WxH` in pixels, each side at least 1.
fn parse_size(size: &str) -> Result<(u32, u32)> {
    let parsed = size
        .split_once(['x', 'X'])
        .and_then(|(w, h)| Some((w.trim().parse::<u32>().ok()?, h.trim().parse::<u32>().ok()?)));
    match parsed {
        Some((w, h)) if w > 0 && h > 0 => Ok((w, h)),
        _ => bail!("--size takes WIDTHxHEIGHT in pixels, such as 640x480, not `{size}`"),
    }
}

/// Fails before the simulation when `folder` is not writable; creates it
/// when it is missing but its parent exists.
fn check_folder(folder: &Path) -> Result<()> {
    if !folder.is_dir() {
        if folder.exists() {
            bail!("--out {} is not a folder", folder.display());
        }
        let parent = anthesis_files::folder_of(folder);
        if !parent.is_dir() {
            bail!(
                "--out {}: cannot create the folder, {} does not exist",
                folder.display(),
                parent.display()
            );
        }
        std::fs::create_dir(folder)
            .with_context(|| format!("cannot create the --out folder {}", folder.display()))?;
    }
    let probe = folder.join(format!(".anthesis-write-test-{}", std::process::id()));
    std::fs::write(&probe, b"")
        .with_context(|| format!("cannot write to the --out folder {}", folder.display()))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// The pictures (all of one size) in a row, left to right.
fn side_by_side(pictures: &[RgbaImage]) -> RgbaImage {
    let (width, height) = pictures.first().map_or((0, 0), RgbaImage::dimensions);
    let count = u32::try_from(pictures.len()).unwrap_or(u32::MAX);
    let mut tiled = RgbaImage::new(width.saturating_mul(count), height);
    for (i, picture) in (0..count).zip(pictures) {
        image::imageops::replace(&mut tiled, picture, i64::from(i * width), 0);
    }
    tiled
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_lists_are_sorted_checked_and_defaulted() {
        assert_eq!(
            parse_frames("50, 0,25,25", 100).expect("valid"),
            [0, 25, 50]
        );
        assert!(parse_frames("1,,2", 100).is_err());
        assert!(parse_frames("1,-2", 100).is_err());
        assert!(parse_frames("101", 100).is_err());
        assert_eq!(default_frames(100), [0, 25, 50, 75, 100]);
        assert_eq!(default_frames(2), [0, 1, 2]);
        assert_eq!(default_frames(1), [0, 1]);
    }

    #[test]
    fn background_colours_parse_as_hexadecimal_srgb() {
        assert_eq!(
            parse_colour("ff0080").expect("valid"),
            [1.0, 0.0, 128.0 / 255.0]
        );
        assert_eq!(parse_colour("#FFFFFF").expect("valid"), [1.0; 3]);
        for bad in ["fff", "white", "ff00zz", "ff00ff00", "é00000"] {
            assert!(parse_colour(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn sizes_parse_as_width_by_height() {
        assert_eq!(parse_size("640x480").expect("valid"), (640, 480));
        for bad in ["640", "0x10", "10x", "axb", "-1x5"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn tiles_put_pictures_left_to_right() {
        let red = RgbaImage::from_pixel(3, 2, image::Rgba([255, 0, 0, 255]));
        let blue = RgbaImage::from_pixel(3, 2, image::Rgba([0, 0, 255, 255]));
        let tiled = side_by_side(&[red, blue]);
        assert_eq!(tiled.dimensions(), (6, 2));
        assert_eq!(tiled.get_pixel(2, 1).0, [255, 0, 0, 255]);
        assert_eq!(tiled.get_pixel(3, 0).0, [0, 0, 255, 255]);
    }
}

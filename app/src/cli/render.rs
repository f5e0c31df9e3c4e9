//! `anthesis render`: pictures of chosen keyframes, rendered offscreen with
//! one camera for the whole run.

use std::io::Cursor;
use std::path::{Path, PathBuf};

use anthesis_render::{Camera, OffscreenRenderer, OrganMesh, organs_bounds_in_world};
use anthesis_sim::Simulation;
use anyhow::{Context, Result, bail};
use clap::Args;
use image::RgbaImage;

use super::simulate::run_keyframes;
use super::{load, selection};

#[derive(Debug, Args)]
pub struct RenderArgs {
    /// A project file (*.anthesis.toml).
    pub project: PathBuf,
    /// Keyframes to render, comma-separated; 0 is the bud (default: the bud
    /// and every quarter of the run).
    #[arg(long, value_name = "N,N,...")]
    pub frames: Option<String>,
    /// An existing folder; receives frame-NNN.png per keyframe (NNN the
    /// keyframe number).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
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
    pub keyframes: Option<u32>,
    /// Also write DIR/tiled.png: the frames side by side, in keyframe order.
    #[arg(long)]
    pub tile: bool,
}

pub fn render(args: &RenderArgs) -> Result<()> {
    let mut project = load(&args.project)?;
    if let Some(n) = args.keyframes {
        if n == 0 {
            bail!("--keyframes must be at least 1");
        }
        project.settings.keyframes = n;
    }
    let selection = selection(&project, args.organ.as_deref())?;
    let last_keyframe = project.settings.keyframes;
    let frames = match &args.frames {
        Some(list) => parse_frames(list, last_keyframe)?,
        None => default_frames(last_keyframe),
    };
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
    check_folder(&args.out)?;
    // Before the simulation, so that a machine without a GPU driver fails
    // at once.
    let mut renderer = OffscreenRenderer::new().context("cannot render")?;
    let max_side = renderer.device().limits().max_texture_dimension_2d;
    if width > max_side || height > max_side {
        bail!(
            "--size {width}x{height} is too large: this GPU renders at most {max_side} pixels a side"
        );
    }

    let mut sim = Simulation::new(&project, &selection)?;
    let colors: Vec<[f32; 4]> = (0..sim.organs().len()).map(|i| sim.color(i)).collect();
    let triangles: Vec<Vec<[u32; 3]>> = (0..colors.len())
        .map(|i| sim.triangles(i).to_vec())
        .collect();
    let organs_at = |positions: &[Vec<glam::DVec3>]| -> Vec<OrganMesh> {
        positions
            .iter()
            .zip(&triangles)
            .zip(&colors)
            .map(|((p, t), c)| OrganMesh::from_positions(p, t, *c))
            .collect()
    };
    let mut scenes: Vec<(u32, Vec<OrganMesh>)> = Vec::with_capacity(frames.len());
    if frames.first() == Some(&0) {
        scenes.push((0, organs_at(&sim.bud().positions_in_world)));
    }
    let last_wanted = frames.last().copied().unwrap_or(0);
    run_keyframes(&mut sim, last_wanted, &mut |keyframe| {
        if frames.binary_search(&keyframe.index).is_ok() {
            scenes.push((keyframe.index, organs_at(&keyframe.positions_in_world)));
        }
    })?;

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
    for (index, organs) in &scenes {
        let picture = renderer
            .render(organs, &camera, width, height)
            .with_context(|| format!("cannot render keyframe {index}"))?;
        let path = args.out.join(format!("frame-{index:03}.png"));
        write_png(&path, &picture)?;
        pictures.push(picture);
    }
    let mut written = scenes.len();
    if args.tile {
        write_png(&args.out.join("tiled.png"), &side_by_side(&pictures))?;
        written += 1;
    }
    eprintln!(
        "wrote {written} picture(s) of {width}x{height} to {}",
        args.out.display()
    );
    Ok(())
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

/// Fails before the simulation when `folder` is missing or not writable.
fn check_folder(folder: &Path) -> Result<()> {
    if !folder.is_dir() {
        if folder.exists() {
            bail!("--out {} is not a folder", folder.display());
        }
        bail!("--out folder {} does not exist", folder.display());
    }
    let probe = folder.join(format!(".anthesis-write-test-{}", std::process::id()));
    std::fs::write(&probe, b"")
        .with_context(|| format!("cannot write to the --out folder {}", folder.display()))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

fn write_png(path: &Path, picture: &RgbaImage) -> Result<()> {
    let mut bytes = Vec::new();
    picture
        .write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Png)
        .with_context(|| format!("cannot encode {}", path.display()))?;
    // Export errors name the file.
    Ok(anthesis_files::write_atomic(path, &bytes)?)
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

//! An opening rendered as an animation for slides and papers: an animated
//! GIF or a folder of numbered PNG frames, seen by one camera that may turn
//! around the flower. Shared by `anthesis render --animation` and the
//! desktop's File menu.

use std::io::Cursor;
use std::path::{Path, PathBuf};

use anthesis_render::{Camera, OffscreenRenderer, OrganMesh, organs_bounds_in_world};
use anthesis_sim::batch::Format;
use anyhow::{Context, Result, bail};
use glam::DVec3;
use image::RgbaImage;
use image::codecs::gif::{GifEncoder, Repeat};

/// Where the animation goes, told by the path: a `.gif` file, or else a
/// folder of `frame-0000.png`, `frame-0001.png`, … in playback order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum AnimationTarget {
    Gif(PathBuf),
    PngFolder(PathBuf),
}

impl AnimationTarget {
    pub fn of(path: &Path) -> AnimationTarget {
        if Format::from_path(path) == Some(Format::Gif) {
            AnimationTarget::Gif(path.to_path_buf())
        } else {
            AnimationTarget::PngFolder(path.to_path_buf())
        }
    }

    pub fn path(&self) -> &Path {
        match self {
            AnimationTarget::Gif(path) | AnimationTarget::PngFolder(path) => path,
        }
    }
}

/// How the animation looks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnimationOptions {
    pub width: u32,
    pub height: u32,
    /// Camera direction around the flower axis at the first frame (0 = from
    /// +Z, 90 = from +X).
    pub azimuth_deg: f64,
    /// Camera height above the horizontal, in `[-90, 90]`.
    pub elevation_deg: f64,
    /// How far the camera turns around the flower axis over the whole
    /// animation (0 = still, 360 = once around).
    pub turn_deg: f64,
    /// Playback speed of a GIF in frames per second.
    pub frames_per_second: f64,
}

impl Default for AnimationOptions {
    fn default() -> Self {
        Self {
            width: 640,
            height: 480,
            azimuth_deg: 30.0,
            elevation_deg: 20.0,
            turn_deg: 0.0,
            frames_per_second: DEFAULT_GIF_FRAMES_PER_SECOND,
        }
    }
}

/// Default GIF speed: 25 frames per second is what GIF stores exactly (a
/// frame lasts a whole number of hundredths of a second).
pub const DEFAULT_GIF_FRAMES_PER_SECOND: f64 = 25.0;

/// Browsers show GIF frames shorter than 2/100 s at 10 frames per second,
/// so faster GIFs play slower, not faster.
pub const MAX_GIF_FRAMES_PER_SECOND: f64 = 50.0;

/// How long a GIF holds its last frame (the open flower) before it starts
/// again from the bud, in hundredths of a second.
const GIF_FINAL_HOLD_CENTISECONDS: u16 = 100;

/// The keyframes an animation shows: `0, step, 2 step, …` and always the
/// last one.
pub fn keyframes_every(step: u32, last_keyframe: u32) -> Vec<u32> {
    let step = step.max(1);
    let mut keyframes: Vec<u32> = (0..=last_keyframe).step_by(step as usize).collect();
    if keyframes.last() != Some(&last_keyframe) {
        keyframes.push(last_keyframe);
    }
    keyframes
}

/// Checks `options` and `target` before any work (a long simulation), so
/// that a typo or an impossible request is reported at once: the size, the
/// angles, the GIF speed and frame size, and that the file's folder (or the
/// frame folder's parent) exists.
pub fn check_request(target: &AnimationTarget, options: &AnimationOptions) -> Result<()> {
    let AnimationOptions {
        width,
        height,
        azimuth_deg,
        elevation_deg,
        turn_deg,
        frames_per_second,
    } = *options;
    if width == 0 || height == 0 {
        bail!("the animation needs a size of at least 1x1 pixels, not {width}x{height}");
    }
    if !azimuth_deg.is_finite() || !turn_deg.is_finite() {
        bail!("the camera angles must be numbers of degrees");
    }
    if !(-90.0..=90.0).contains(&elevation_deg) {
        bail!("the camera elevation must be between -90 and 90 degrees, not {elevation_deg}");
    }
    let parent_of = |path: &Path| {
        path.parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."))
            .to_path_buf()
    };
    match target {
        AnimationTarget::Gif(path) => {
            if u16::try_from(width).is_err() || u16::try_from(height).is_err() {
                bail!(
                    "a GIF is at most 65535 pixels a side, {width}x{height} is too large (write PNG frames to a folder instead)"
                );
            }
            gif_frame_centiseconds(frames_per_second)?;
            let folder = parent_of(path);
            if !folder.is_dir() {
                bail!(
                    "cannot write {}: the folder {} does not exist",
                    path.display(),
                    folder.display()
                );
            }
            if path.is_dir() {
                bail!(
                    "cannot write {}: a folder of that name exists",
                    path.display()
                );
            }
        }
        AnimationTarget::PngFolder(folder) => {
            if folder.exists() && !folder.is_dir() {
                bail!(
                    "{} is a file: the animation goes to a .gif file or a folder for PNG frames",
                    folder.display()
                );
            }
            let parent = parent_of(folder);
            if !folder.exists() && !parent.is_dir() {
                bail!(
                    "cannot create the frame folder {}: {} does not exist",
                    folder.display(),
                    parent.display()
                );
            }
        }
    }
    Ok(())
}

/// The length of one GIF frame in hundredths of a second (what GIF
/// stores) for `frames_per_second`.
fn gif_frame_centiseconds(frames_per_second: f64) -> Result<u16> {
    if !(frames_per_second.is_finite()
        && frames_per_second > 0.0
        && frames_per_second <= MAX_GIF_FRAMES_PER_SECOND)
    {
        bail!(
            "a GIF plays at most {MAX_GIF_FRAMES_PER_SECOND} frames per second (browsers slow faster GIFs down to 10), not {frames_per_second}"
        );
    }
    let centiseconds = (100.0 / frames_per_second).round();
    if centiseconds > f64::from(u16::MAX) {
        bail!(
            "a GIF frame lasts at most 655 seconds: {frames_per_second} frames per second is too slow"
        );
    }
    Ok(centiseconds.max(2.0) as u16)
}

/// One camera per frame, all at the same distance from the centre of the
/// bounds of every frame (so the flower does not jump or zoom), turning
/// evenly from `azimuth_deg` to `azimuth_deg + turn_deg`. Returns `None`
/// when there is nothing to see.
pub fn cameras(scenes: &[Vec<OrganMesh>], options: &AnimationOptions) -> Option<Vec<Camera>> {
    let (lo, hi) = scenes
        .iter()
        .filter_map(|organs| organs_bounds_in_world(organs))
        .reduce(|(lo_a, hi_a), (lo_b, hi_b)| (lo_a.min(lo_b), hi_a.max(hi_b)))?;
    let count = scenes.len();
    let azimuth_at = |i: usize| {
        let fraction = if count > 1 {
            i as f64 / (count - 1) as f64
        } else {
            0.0
        };
        options.azimuth_deg + options.turn_deg * fraction
    };
    // Framed as the viewport's F frames: the points, 80 % of the way out.
    let points: Vec<DVec3> = scenes
        .iter()
        .flatten()
        .flat_map(|o| &o.positions_in_world)
        .map(|p| DVec3::from_array(p.map(f64::from)))
        .collect();
    let cameras: Vec<Camera> = (0..count)
        .map(|i| Camera::framing_points(&points, azimuth_at(i), options.elevation_deg, 0.8))
        .collect::<Option<_>>()
        .unwrap_or_else(|| {
            (0..count)
                .map(|i| Camera::framing(lo, hi, azimuth_at(i), options.elevation_deg))
                .collect()
        });
    // Framing depends on the direction; the farthest fits every direction.
    let distance = cameras
        .iter()
        .map(|c| c.eye.distance(c.target))
        .fold(0.0, f64::max);
    Some(
        cameras
            .into_iter()
            .map(|c| {
                let towards_eye = (c.eye - c.target).normalize_or(DVec3::Z);
                Camera {
                    eye: c.target + distance * towards_eye,
                    ..c
                }
            })
            .collect(),
    )
}

/// Renders `scenes` (one per frame, in playback order) and writes them to
/// `target` (checked with [`check_request`] first). A GIF loops forever and
/// holds its last frame for a second; it is written atomically, so an
/// existing file is replaced only by a complete new one. `progress` gets
/// the number of frames done. Returns the number of frames written.
pub fn write_animation(
    renderer: &mut OffscreenRenderer,
    scenes: &[Vec<OrganMesh>],
    options: &AnimationOptions,
    target: &AnimationTarget,
    progress: &mut dyn FnMut(usize),
) -> Result<usize> {
    check_request(target, options)?;
    let max_side = renderer.device().limits().max_texture_dimension_2d;
    if options.width > max_side || options.height > max_side {
        bail!(
            "{}x{} is too large: this GPU renders at most {max_side} pixels a side",
            options.width,
            options.height
        );
    }
    let Some(cameras) = cameras(scenes, options) else {
        bail!("there is nothing to render: the organs have no vertices");
    };
    let mut render = |index: usize| -> Result<RgbaImage> {
        let picture = renderer
            .render(
                &scenes[index],
                &cameras[index],
                options.width,
                options.height,
            )
            .with_context(|| format!("cannot render frame {index}"))?;
        progress(index + 1);
        Ok(picture)
    };
    match target {
        AnimationTarget::Gif(path) => {
            let centiseconds = gif_frame_centiseconds(options.frames_per_second)?;
            let mut bytes = Vec::new();
            {
                // Speed 10: NeuQuant samples a tenth of the pixels to pick
                // each frame's 256 colours (the encoder's suggested default).
                let mut encoder = GifEncoder::new_with_speed(&mut bytes, 10);
                encoder.set_repeat(Repeat::Infinite)?;
                for index in 0..scenes.len() {
                    let mut picture = render(index)?;
                    // Floyd-Steinberg onto the frame's own palette: no bands
                    // (the encoder keeps a frame of 256 colours as it is).
                    let palette = color_quant::NeuQuant::new(10, 256, picture.as_raw());
                    image::imageops::dither(&mut picture, &palette);
                    let hold = if index + 1 == scenes.len() {
                        GIF_FINAL_HOLD_CENTISECONDS
                    } else {
                        0
                    };
                    let delay_ms = 10 * u32::from(centiseconds.saturating_add(hold));
                    let frame = image::Frame::from_parts(
                        picture,
                        0,
                        0,
                        image::Delay::from_numer_denom_ms(delay_ms, 1),
                    );
                    encoder
                        .encode_frame(frame)
                        .with_context(|| format!("cannot encode {}", path.display()))?;
                }
            }
            anthesis_files::write_atomic(path, &bytes)?;
        }
        AnimationTarget::PngFolder(folder) => {
            if !folder.is_dir() {
                std::fs::create_dir(folder)
                    .with_context(|| format!("cannot create the folder {}", folder.display()))?;
            }
            for index in 0..scenes.len() {
                let picture = render(index)?;
                write_png(&folder.join(frame_file_name(index)), &picture)?;
            }
        }
    }
    Ok(scenes.len())
}

/// The file name of frame `index` in a PNG folder.
pub fn frame_file_name(index: usize) -> String {
    format!("frame-{index:04}.png")
}

/// Encodes `picture` as PNG and writes it atomically.
pub fn write_png(path: &Path, picture: &RgbaImage) -> Result<()> {
    let mut bytes = Vec::new();
    picture
        .write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Png)
        .with_context(|| format!("cannot encode {}", path.display()))?;
    // File errors name the file.
    Ok(anthesis_files::write_atomic(path, &bytes)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keyframes_step_through_the_run_and_end_on_the_last() {
        assert_eq!(keyframes_every(1, 4), [0, 1, 2, 3, 4]);
        assert_eq!(keyframes_every(2, 4), [0, 2, 4]);
        assert_eq!(keyframes_every(3, 4), [0, 3, 4]);
        assert_eq!(keyframes_every(10, 4), [0, 4]);
        assert_eq!(keyframes_every(0, 2), [0, 1, 2]);
        assert_eq!(keyframes_every(5, 0), [0]);
    }

    #[test]
    fn the_target_follows_the_extension() {
        assert!(matches!(
            AnimationTarget::of(Path::new("a/opening.GIF")),
            AnimationTarget::Gif(_)
        ));
        assert!(matches!(
            AnimationTarget::of(Path::new("a/frames")),
            AnimationTarget::PngFolder(_)
        ));
    }

    #[test]
    fn gif_speeds_are_whole_hundredths_within_what_browsers_play() {
        assert_eq!(gif_frame_centiseconds(25.0).expect("fine"), 4);
        assert_eq!(gif_frame_centiseconds(24.0).expect("fine"), 4);
        assert_eq!(gif_frame_centiseconds(50.0).expect("fine"), 2);
        assert_eq!(gif_frame_centiseconds(1.0).expect("fine"), 100);
        for bad in [0.0, -3.0, 51.0, f64::NAN, 1e-4] {
            assert!(gif_frame_centiseconds(bad).is_err(), "{bad}");
        }
    }

    fn square(offset: DVec3) -> Vec<OrganMesh> {
        let positions: Vec<DVec3> = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y]
            .iter()
            .map(|p| *p + offset)
            .collect();
        vec![OrganMesh::from_positions(
            &positions,
            &[[0, 1, 2], [0, 2, 3]],
            [1.0, 0.5, 0.5, 1.0],
        )]
    }

    #[test]
    fn a_turning_camera_keeps_its_distance_and_turns_evenly() {
        let scenes = vec![
            square(DVec3::ZERO),
            square(DVec3::new(2.0, 0.0, 0.0)),
            square(DVec3::new(0.0, 0.0, 3.0)),
        ];
        let options = AnimationOptions {
            azimuth_deg: 10.0,
            elevation_deg: 0.0,
            turn_deg: 180.0,
            ..AnimationOptions::default()
        };
        let cameras = cameras(&scenes, &options).expect("something to see");
        assert_eq!(cameras.len(), 3);
        let target = cameras[0].target;
        let distance = cameras[0].eye.distance(target);
        for (i, camera) in cameras.iter().enumerate() {
            assert!(camera.target.distance(target) < 1e-12);
            assert!((camera.eye.distance(target) - distance).abs() < 1e-9);
            let towards_eye = camera.eye - target;
            let azimuth = towards_eye.x.atan2(towards_eye.z).to_degrees();
            let expected = 10.0 + 90.0 * i as f64;
            let off_deg = ((azimuth - expected + 180.0).rem_euclid(360.0) - 180.0).abs();
            assert!(off_deg < 1e-6, "frame {i}: {azimuth}");
        }
        // Every frame's flower is framed from every direction.
        for az in [10.0, 100.0, 190.0] {
            let fitted = Camera::framing(DVec3::ZERO, DVec3::new(3.0, 1.0, 3.0), az, 0.0);
            assert!(fitted.eye.distance(fitted.target) <= distance + 1e-9);
        }
        assert!(super::cameras(&[vec![]], &options).is_none());
    }

    #[test]
    fn impossible_requests_are_refused_before_any_work() {
        let dir = tempfile::tempdir().expect("tempdir");
        let gif = AnimationTarget::Gif(dir.path().join("a.gif"));
        let fine = AnimationOptions::default();
        check_request(&gif, &fine).expect("fine");
        let too_wide = AnimationOptions {
            width: 70_000,
            ..fine
        };
        let error = check_request(&gif, &too_wide).expect_err("GIF side limit");
        assert!(error.to_string().contains("65535"), "{error}");
        let too_fast = AnimationOptions {
            frames_per_second: 60.0,
            ..fine
        };
        assert!(check_request(&gif, &too_fast).is_err());
        let missing = AnimationTarget::Gif(dir.path().join("no/a.gif"));
        assert!(check_request(&missing, &fine).is_err());
        let nested = AnimationTarget::PngFolder(dir.path().join("no/frames"));
        assert!(check_request(&nested, &fine).is_err());
        std::fs::write(dir.path().join("file"), b"x").expect("write");
        let file = AnimationTarget::PngFolder(dir.path().join("file"));
        assert!(check_request(&file, &fine).is_err());
        let tilted = AnimationOptions {
            elevation_deg: 95.0,
            ..fine
        };
        assert!(check_request(&gif, &tilted).is_err());
    }
}

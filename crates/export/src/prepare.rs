//! Input validation, keyframe resampling, animation times and normals shared
//! by the exporters.

use glam::DVec3;

use crate::error::{ExportError, TrackProblem};
use crate::{GlbOptions, KeyframeBlend, Timing, Track};

const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a];

fn fits_f32(x: f64) -> bool {
    (x as f32).is_finite()
}

fn check_track(track: &Track) -> Result<(), TrackProblem> {
    let Some(first) = track.keyframes.first() else {
        return Err(TrackProblem::NoKeyframes);
    };
    let vertex_count = first.len();
    if vertex_count == 0 {
        return Err(TrackProblem::NoVertices);
    }
    if track.triangles.is_empty() {
        return Err(TrackProblem::NoTriangles);
    }
    if track.uvs.len() != vertex_count {
        return Err(TrackProblem::UvCount {
            expected: vertex_count,
            found: track.uvs.len(),
        });
    }
    for (keyframe, positions) in track.keyframes.iter().enumerate() {
        if positions.len() != vertex_count {
            return Err(TrackProblem::KeyframeVertexCount {
                keyframe,
                expected: vertex_count,
                found: positions.len(),
            });
        }
        if let Some(vertex) = positions
            .iter()
            .position(|p| !(fits_f32(p.x) && fits_f32(p.y) && fits_f32(p.z)))
        {
            return Err(TrackProblem::NonFinitePosition { keyframe, vertex });
        }
    }
    for (triangle, corners) in track.triangles.iter().enumerate() {
        if let Some(&index) = corners.iter().find(|&&i| i as usize >= vertex_count) {
            return Err(TrackProblem::IndexOutOfRange {
                triangle,
                index,
                vertex_count,
            });
        }
    }
    if let Some(vertex) = track
        .uvs
        .iter()
        .position(|uv| !(fits_f32(uv.x) && fits_f32(uv.y)))
    {
        return Err(TrackProblem::NonFiniteUv { vertex });
    }
    if !track
        .base_colour
        .iter()
        .all(|c| c.is_finite() && (0.0..=1.0).contains(c))
    {
        return Err(TrackProblem::BaseColour {
            colour: track.base_colour,
        });
    }
    if let Some(png) = &track.base_colour_png
        && !png.starts_with(&PNG_SIGNATURE)
    {
        return Err(TrackProblem::TextureNotPng);
    }
    if let Some(png) = &track.outer_colour_png
        && !png.starts_with(&PNG_SIGNATURE)
    {
        return Err(TrackProblem::TextureNotPng);
    }
    if let Some(rigid) = &track.rigid {
        let finite = rigid.poses.iter().all(|p| {
            p.translation.is_finite() && p.rotation.is_finite() && p.rotation.length() > 0.5
        }) && rigid.local.iter().all(|p| p.is_finite());
        if rigid.local.len() != vertex_count
            || rigid.poses.len() != track.keyframes.len()
            || !finite
        {
            return Err(TrackProblem::RigidMotion {
                local: rigid.local.len(),
                vertices: vertex_count,
                poses: rigid.poses.len(),
                keyframes: track.keyframes.len(),
            });
        }
    }
    Ok(())
}

/// Validates every track and returns the keyframe count shared by the
/// animated tracks (1 if every track is static).
pub(crate) fn validate_tracks(tracks: &[Track]) -> Result<usize, ExportError> {
    if tracks.is_empty() {
        return Err(ExportError::NoTracks);
    }
    let mut animated: Option<usize> = None;
    for (index, track) in tracks.iter().enumerate() {
        check_track(track).map_err(|problem| ExportError::InvalidTrack {
            track: index,
            name: track.name.clone(),
            problem,
        })?;
        let count = track.keyframes.len();
        if count > 1 {
            match animated {
                None => animated = Some(count),
                Some(expected) if expected != count => {
                    return Err(ExportError::KeyframeCountMismatch {
                        track: index,
                        name: track.name.clone(),
                        expected,
                        found: count,
                    });
                }
                Some(_) => {}
            }
        }
    }
    Ok(animated.unwrap_or(1))
}

pub(crate) fn validate_options(
    options: &GlbOptions,
    keyframe_count: usize,
) -> Result<(), ExportError> {
    validate_timing(options.timing)?;
    if keyframe_count > 1 && options.max_morph_targets == 0 {
        return Err(ExportError::InvalidOptions(
            "an animation needs at least one morph target per mesh".to_owned(),
        ));
    }
    Ok(())
}

/// A frame rate or duration must be a positive, finite number.
pub(crate) fn validate_timing(timing: Timing) -> Result<(), ExportError> {
    match timing {
        Timing::FramesPerSecond(fps) if !(fps.is_finite() && fps > 0.0) => {
            Err(ExportError::InvalidOptions(format!(
                "the frame rate must be a positive number of keyframes per second, not {fps}"
            )))
        }
        Timing::Duration(seconds) if !(seconds.is_finite() && seconds > 0.0) => {
            Err(ExportError::InvalidOptions(format!(
                "the duration must be a positive number of seconds, not {seconds}"
            )))
        }
        _ => Ok(()),
    }
}

/// Where the exported keyframes sit in the original sequence, in keyframe
/// units: `0, 1, …, K-1` when `K - 1 <= max_targets`, else `max_targets + 1`
/// uniformly spaced positions from `0` to `K - 1` (both exact).
pub(crate) fn sample_positions(keyframe_count: usize, max_targets: usize) -> Vec<f64> {
    if keyframe_count <= 1 {
        return vec![0.0];
    }
    let intervals = keyframe_count - 1;
    if intervals <= max_targets {
        return (0..keyframe_count).map(|k| k as f64).collect();
    }
    let samples = max_targets + 1;
    (0..samples)
        // The integer product keeps the last sample exactly at K - 1.
        .map(|j| (j * intervals) as f64 / max_targets as f64)
        .collect()
}

/// Positions at keyframe position `x` (in keyframe units), linearly
/// interpolated between the neighbouring keyframes ([`KeyframeBlend`]).
/// `keyframes` is not empty (the tracks are validated first).
pub(crate) fn sample_keyframes(keyframes: &[Vec<DVec3>], x: f64) -> Vec<DVec3> {
    match KeyframeBlend::at(keyframes.len(), x) {
        Some(blend) => blend.positions(&keyframes[blend.below], &keyframes[blend.above]),
        None => Vec::new(),
    }
}

/// Name of the morph target holding keyframe position `x`.
pub(crate) fn target_name(x: f64) -> String {
    if x.fract() == 0.0 {
        format!("keyframe {}", x as u64)
    } else {
        format!("keyframe {x:.2}")
    }
}

/// Animation times in seconds of the exported keyframes at `positions`
/// (keyframe units) of a `keyframe_count` sequence. Fails when `f32` cannot
/// keep the times strictly increasing (absurd frame rates).
pub(crate) fn animation_times(
    timing: Timing,
    keyframe_count: usize,
    positions: &[f64],
) -> Result<Vec<f32>, ExportError> {
    let seconds_per_keyframe = match timing {
        Timing::FramesPerSecond(fps) => 1.0 / fps,
        Timing::Duration(seconds) => seconds / (keyframe_count.max(2) - 1) as f64,
    };
    let times: Vec<f32> = positions
        .iter()
        .map(|&x| (x * seconds_per_keyframe) as f32)
        .collect();
    if times.iter().any(|t| !t.is_finite()) || times.windows(2).any(|w| w[0] >= w[1]) {
        let timing = match timing {
            Timing::FramesPerSecond(fps) => format!("a frame rate of {fps:?} keyframes per second"),
            Timing::Duration(seconds) => format!("a duration of {seconds:?} seconds"),
        };
        return Err(ExportError::InvalidOptions(format!(
            "{timing} puts the keyframes too close together or too far apart in time to store \
             (glTF keeps times as 32-bit numbers)"
        )));
    }
    Ok(times)
}

/// Area-weighted unit vertex normals; a vertex without a usable normal
/// (unused, or only in degenerate triangles) gets +Y so that every stored
/// normal has unit length as glTF requires.
pub(crate) fn unit_normals(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let mut normals = anthesis_mesh::vertex_normals(positions, triangles);
    for n in &mut normals {
        if !n.is_normalized() {
            *n = DVec3::Y;
        }
    }
    normals
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    fn triangle_track(keyframes: Vec<Vec<DVec3>>) -> Track {
        Track {
            name: "t".to_owned(),
            triangles: vec![[0, 1, 2]],
            uvs: vec![DVec2::ZERO, DVec2::X, DVec2::Y],
            base_colour: [1.0, 1.0, 1.0, 1.0],
            keyframes,
            base_colour_png: None,
            rigid: None,
            unit: anthesis_flower::Unit::METRE,
            outer_colour_png: None,
        }
    }

    fn frame(offset: f64) -> Vec<DVec3> {
        vec![
            DVec3::new(offset, 0.0, 0.0),
            DVec3::new(offset + 1.0, 0.0, 0.0),
            DVec3::new(offset, 1.0, 0.0),
        ]
    }

    fn problem(tracks: &[Track]) -> TrackProblem {
        match validate_tracks(tracks) {
            Err(ExportError::InvalidTrack { problem, .. }) => problem,
            other => panic!("expected InvalidTrack, got {other:?}"),
        }
    }

    #[test]
    fn invalid_tracks_are_typed_errors() {
        assert!(matches!(validate_tracks(&[]), Err(ExportError::NoTracks)));
        assert_eq!(
            problem(&[triangle_track(vec![])]),
            TrackProblem::NoKeyframes
        );
        assert_eq!(
            problem(&[triangle_track(vec![vec![]])]),
            TrackProblem::NoVertices
        );
        let mut t = triangle_track(vec![frame(0.0)]);
        t.triangles.clear();
        assert_eq!(problem(&[t]), TrackProblem::NoTriangles);
        let mut t = triangle_track(vec![frame(0.0)]);
        t.uvs.pop();
        assert_eq!(
            problem(&[t]),
            TrackProblem::UvCount {
                expected: 3,
                found: 2
            }
        );
        let mut short = frame(1.0);
        short.pop();
        assert_eq!(
            problem(&[triangle_track(vec![frame(0.0), short])]),
            TrackProblem::KeyframeVertexCount {
                keyframe: 1,
                expected: 3,
                found: 2
            }
        );
        let mut t = triangle_track(vec![frame(0.0)]);
        t.triangles[0][2] = 3;
        assert_eq!(
            problem(&[t]),
            TrackProblem::IndexOutOfRange {
                triangle: 0,
                index: 3,
                vertex_count: 3
            }
        );
        let mut nan = frame(1.0);
        nan[2].y = f64::NAN;
        assert_eq!(
            problem(&[triangle_track(vec![frame(0.0), nan])]),
            TrackProblem::NonFinitePosition {
                keyframe: 1,
                vertex: 2
            }
        );
        let mut huge = frame(0.0);
        huge[1].z = 1e300;
        assert_eq!(
            problem(&[triangle_track(vec![huge])]),
            TrackProblem::NonFinitePosition {
                keyframe: 0,
                vertex: 1
            }
        );
        let mut t = triangle_track(vec![frame(0.0)]);
        t.uvs[1].x = f64::INFINITY;
        assert_eq!(problem(&[t]), TrackProblem::NonFiniteUv { vertex: 1 });
        let mut t = triangle_track(vec![frame(0.0)]);
        t.base_colour = [1.2, 0.0, 0.0, 1.0];
        assert!(matches!(problem(&[t]), TrackProblem::BaseColour { .. }));
        let mut t = triangle_track(vec![frame(0.0)]);
        t.base_colour_png = Some(b"GIF89a".to_vec());
        assert_eq!(problem(&[t]), TrackProblem::TextureNotPng);
    }

    #[test]
    fn animated_tracks_must_share_their_keyframe_count() {
        let receptacle = triangle_track(vec![frame(0.0)]);
        let a = triangle_track(vec![frame(0.0), frame(1.0), frame(2.0)]);
        let b = triangle_track(vec![frame(0.0), frame(1.0)]);
        assert_eq!(
            validate_tracks(&[receptacle.clone(), a.clone()]).expect("valid"),
            3
        );
        assert_eq!(
            validate_tracks(std::slice::from_ref(&receptacle)).expect("valid"),
            1
        );
        assert!(matches!(
            validate_tracks(&[receptacle, a, b]),
            Err(ExportError::KeyframeCountMismatch {
                track: 2,
                expected: 3,
                found: 2,
                ..
            })
        ));
    }

    #[test]
    fn options_are_checked() {
        let bad_fps = GlbOptions {
            timing: Timing::FramesPerSecond(0.0),
            ..GlbOptions::default()
        };
        assert!(validate_options(&bad_fps, 10).is_err());
        let bad_duration = GlbOptions {
            timing: Timing::Duration(f64::NAN),
            ..GlbOptions::default()
        };
        assert!(validate_options(&bad_duration, 10).is_err());
        let no_targets = GlbOptions {
            max_morph_targets: 0,
            ..GlbOptions::default()
        };
        assert!(validate_options(&no_targets, 10).is_err());
        assert!(validate_options(&no_targets, 1).is_ok());
        assert!(validate_options(&GlbOptions::default(), 10).is_ok());
    }

    #[test]
    fn options_are_checked_without_data_as_the_export_would() {
        let fps = |fps| GlbOptions {
            timing: Timing::FramesPerSecond(fps),
            ..GlbOptions::default()
        };
        assert!(GlbOptions::default().check(101).is_ok());
        assert!(fps(1e-30).check(101).is_ok(), "far apart but storable");
        let error = fps(1e-300).check(101).expect_err("1e300 s is no f32");
        assert_eq!(
            error.to_string(),
            "invalid export option: a frame rate of 1e-300 keyframes per second puts the \
             keyframes too close together or too far apart in time to store (glTF keeps times \
             as 32-bit numbers)"
        );
        assert!(fps(1e300).check(101).is_err(), "all at time 0");
        let no_targets = GlbOptions {
            max_morph_targets: 0,
            ..GlbOptions::default()
        };
        assert!(no_targets.check(101).is_err());
        assert!(no_targets.check(1).is_ok(), "a still needs no targets");
    }

    #[test]
    fn sampling_keeps_keyframes_or_spreads_them_uniformly() {
        assert_eq!(sample_positions(1, 250), vec![0.0]);
        assert_eq!(sample_positions(4, 3), vec![0.0, 1.0, 2.0, 3.0]);
        let resampled = sample_positions(101, 4);
        assert_eq!(resampled, vec![0.0, 25.0, 50.0, 75.0, 100.0]);
        let odd = sample_positions(10, 4);
        assert_eq!(odd.len(), 5);
        assert_eq!(odd[0], 0.0);
        assert_eq!(odd[4], 9.0);
        assert!((odd[1] - 2.25).abs() < 1e-15);
    }

    #[test]
    fn sampling_interpolates_linearly() {
        let keyframes = vec![frame(0.0), frame(2.0), frame(10.0)];
        assert_eq!(sample_keyframes(&keyframes, 1.0), frame(2.0));
        assert_eq!(sample_keyframes(&keyframes, 2.0), frame(10.0));
        let between = sample_keyframes(&keyframes, 1.25);
        assert!((between[0].x - 4.0).abs() < 1e-12);
        assert_eq!(target_name(7.0), "keyframe 7");
        assert_eq!(target_name(6.925), "keyframe 6.92");
    }

    #[test]
    fn times_follow_the_timing() {
        let positions = sample_positions(5, 250);
        assert_eq!(
            animation_times(Timing::FramesPerSecond(2.0), 5, &positions).expect("times"),
            vec![0.0, 0.5, 1.0, 1.5, 2.0]
        );
        assert_eq!(
            animation_times(Timing::Duration(8.0), 5, &positions).expect("times"),
            vec![0.0, 2.0, 4.0, 6.0, 8.0]
        );
        // Resampled: the duration stays (K - 1) / fps.
        let resampled = sample_positions(101, 4);
        assert_eq!(
            animation_times(Timing::FramesPerSecond(10.0), 101, &resampled).expect("times"),
            vec![0.0, 2.5, 5.0, 7.5, 10.0]
        );
        assert!(animation_times(Timing::FramesPerSecond(1e300), 5, &positions).is_err());
    }

    #[test]
    fn normals_are_unit_even_for_unused_vertices() {
        let mut positions = frame(0.0);
        positions.push(DVec3::new(5.0, 5.0, 5.0));
        let normals = unit_normals(&positions, &[[0, 1, 2]]);
        assert!((normals[0] - DVec3::Z).length() < 1e-12);
        assert_eq!(normals[3], DVec3::Y);
    }
}

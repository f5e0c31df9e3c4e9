//! One Wavefront OBJ file per keyframe, every track an object (`o name`).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::prepare::{unit_normals, validate_tracks};
use crate::{ExportError, Track};
use anthesis_files::{check_destination, write_atomic};

/// File name of keyframe `keyframe` in a sequence of `keyframe_count`:
/// `keyframe_0007.obj`, zero-padded to at least four digits so the files sort
/// in playback order.
pub fn obj_file_name(keyframe: usize, keyframe_count: usize) -> String {
    let digits = keyframe_count.saturating_sub(1).max(1).ilog10() as usize + 1;
    format!("keyframe_{keyframe:0width$}.obj", width = digits.max(4))
}

/// Writes one OBJ file per keyframe into the existing folder `dir` (see
/// [`obj_file_name`]) and returns their paths in keyframe order. Each file
/// holds every track as an object (`o name`) with positions, UVs (`vt`, in
/// the Anthesis convention, which is also OBJ's: `v = 0` at the bottom of an
/// image), area-weighted normals and `v/vt/vn` triangles; a static track
/// (one keyframe) appears unchanged in every file. Lengths are in the
/// tracks' unit ([`Track::unit`], the project's: the unit Anthesis reads
/// meshes and fit targets in), which a comment near the top states
/// (`# Lengths in project units: one unit is 1.8 mm (0.0018 m)`). Each file
/// is written atomically.
///
/// Anthesis's own OBJ reader (`anthesis_mesh::obj`) reads these files back
/// (as one mesh with all objects merged).
pub fn write_obj_sequence(dir: &Path, tracks: &[Track]) -> Result<Vec<PathBuf>, ExportError> {
    let keyframe_count = validate_tracks(tracks)?;
    check_destination(&dir.join(obj_file_name(0, keyframe_count)))?;
    let names = object_names(tracks);
    let mut paths = Vec::with_capacity(keyframe_count);
    for keyframe in 0..keyframe_count {
        let text = keyframe_obj(tracks, &names, keyframe, keyframe_count);
        let path = dir.join(obj_file_name(keyframe, keyframe_count));
        write_atomic(&path, text.as_bytes())?;
        paths.push(path);
    }
    Ok(paths)
}

/// Track names usable on an `o` line: no whitespace or control characters,
/// never empty.
fn object_names(tracks: &[Track]) -> Vec<String> {
    tracks
        .iter()
        .enumerate()
        .map(|(index, track)| {
            let name: String = track
                .name
                .chars()
                .map(|c| {
                    if c.is_whitespace() || c.is_control() {
                        '_'
                    } else {
                        c
                    }
                })
                .collect();
            if name.is_empty() {
                format!("track_{index}")
            } else {
                name
            }
        })
        .collect()
}

fn keyframe_obj(
    tracks: &[Track],
    names: &[String],
    keyframe: usize,
    keyframe_count: usize,
) -> String {
    // Writing to a String cannot fail, so the fmt::Results are ignored.
    let mut text = String::new();
    let _ = writeln!(
        text,
        "# Anthesis keyframe {keyframe} of {keyframe_count} (keyframes 0 to {})",
        keyframe_count - 1
    );
    // OBJ has no unit: say it where people and importers' notes look.
    let unit_line = |unit: anthesis_flower::Unit| {
        format!(
            "# Lengths in project units: one unit is {unit} ({:?} m)",
            unit.metres()
        )
    };
    let first_unit = tracks.first().map(|t| t.unit).unwrap_or_default();
    let _ = writeln!(text, "{}", unit_line(first_unit));
    let mut offset = 1usize; // OBJ indices start at 1 and run across objects
    for (track, name) in tracks.iter().zip(names) {
        let positions = &track.keyframes[keyframe.min(track.keyframes.len() - 1)];
        if track.unit != first_unit {
            let _ = writeln!(text, "{}", unit_line(track.unit));
        }
        let _ = writeln!(text, "o {name}");
        // `{:?}` prints the shortest decimal that reads back as the same f64.
        for p in positions {
            let _ = writeln!(text, "v {:?} {:?} {:?}", p.x, p.y, p.z);
        }
        for uv in &track.uvs {
            let _ = writeln!(text, "vt {:?} {:?}", uv.x, uv.y);
        }
        for n in unit_normals(positions, &track.triangles) {
            let _ = writeln!(text, "vn {:?} {:?} {:?}", n.x, n.y, n.z);
        }
        for tri in &track.triangles {
            let [a, b, c] = tri.map(|i| i as usize + offset);
            let _ = writeln!(text, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}");
        }
        offset += positions.len();
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_names_sort_in_keyframe_order() {
        assert_eq!(obj_file_name(7, 100), "keyframe_0007.obj");
        assert_eq!(obj_file_name(0, 1), "keyframe_0000.obj");
        assert_eq!(obj_file_name(12345, 20000), "keyframe_12345.obj");
        assert_eq!(obj_file_name(5, 20000), "keyframe_00005.obj");
    }

    #[test]
    fn names_are_safe_on_an_o_line() {
        let tracks = vec![
            Track {
                name: "inner petal\n2".to_owned(),
                ..Track::default()
            },
            Track::default(),
        ];
        assert_eq!(object_names(&tracks), vec!["inner_petal_2", "track_1"]);
    }
}

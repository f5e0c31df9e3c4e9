//! Wavefront OBJ import and export.
//!
//! Import reads `v`, `vt` and `f` statements (`vn` is read past: normals
//! are recomputed from the triangles). Face corners may be `v/vt` or
//! `v/vt/vn`, indices may be negative (relative to the end of the list so
//! far), and polygons with more than three corners are fan-triangulated.
//! `o`, `g`, `s`, `usemtl` and `mtllib` statements and `#` comments are
//! ignored; any other statement is a syntax error.
//!
//! An organ needs exactly one UV per vertex, so every OBJ position takes the
//! UV of the face corners that use it; a position used with two different
//! UVs is a UV seam and is rejected. Positions used by no face are dropped.

use std::io::{self, Write};
use std::path::Path;

use glam::{DVec2, DVec3};

use crate::{Mesh, MeshError, validate, vertex_normals};

/// Reads and validates the OBJ file at `path`.
pub fn load_obj(path: &Path) -> Result<Mesh, MeshError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| MeshError::Io(format!("{}: {e}", path.display())))?;
    parse_obj(&text)
}

/// Parses OBJ text into a mesh and validates it (see
/// [`validate::validate`]). Errors found by validation name vertices of the
/// returned mesh, i.e. after unused OBJ positions have been dropped.
pub fn parse_obj(text: &str) -> Result<Mesh, MeshError> {
    let mesh = parse_obj_unvalidated(text)?;
    validate::validate(&mesh)?;
    Ok(mesh)
}

/// One corner of an OBJ face: 0-based position and texture coordinate
/// indices.
#[derive(Debug, Clone, Copy)]
struct Corner {
    position: usize,
    texcoord: Option<usize>,
}

/// Parses OBJ text into a mesh without geometric validation. It still fails
/// on syntax errors, missing UVs and UV seams, because those make a mesh
/// with one UV per vertex impossible to build. [`MeshError::UvSeam`] names
/// the 0-based index of the position among the file's `v` statements.
pub fn parse_obj_unvalidated(text: &str) -> Result<Mesh, MeshError> {
    let mut positions: Vec<DVec3> = Vec::new();
    let mut texcoords: Vec<DVec2> = Vec::new();
    let mut triangles: Vec<[Corner; 3]> = Vec::new();
    let mut first_face_without_uv: Option<usize> = None;

    for (line_index, raw_line) in text.lines().enumerate() {
        let line = line_index + 1;
        let content = raw_line.split('#').next().unwrap_or("");
        let mut words = content.split_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        let syntax = |message: String| MeshError::ObjSyntax { line, message };
        match keyword {
            "v" => {
                let [x, y, z] = parse_numbers::<3>(&mut words, "v", "x y z").map_err(syntax)?;
                positions.push(DVec3::new(x, y, z));
            }
            "vt" => {
                let [u, v] = parse_numbers::<2>(&mut words, "vt", "u v").map_err(syntax)?;
                texcoords.push(DVec2::new(u, v));
            }
            "f" => {
                let mut corners = Vec::new();
                for word in words {
                    let corner =
                        parse_corner(word, positions.len(), texcoords.len()).map_err(syntax)?;
                    if corner.texcoord.is_none() && first_face_without_uv.is_none() {
                        first_face_without_uv = Some(line);
                    }
                    corners.push(corner);
                }
                if corners.len() < 3 {
                    return Err(syntax(format!(
                        "a face needs at least 3 corners, found {}",
                        corners.len()
                    )));
                }
                for k in 1..corners.len() - 1 {
                    triangles.push([corners[0], corners[k], corners[k + 1]]);
                }
            }
            "vn" | "o" | "g" | "s" | "usemtl" | "mtllib" => {}
            other => return Err(syntax(format!("unsupported statement `{other}`"))),
        }
    }

    if texcoords.is_empty() {
        return Err(MeshError::MissingUvs);
    }
    if let Some(line) = first_face_without_uv {
        return Err(MeshError::MissingUvOnFace { line });
    }

    // One texture coordinate per position; a second, different one is a seam.
    let mut texcoord_of_position: Vec<Option<usize>> = vec![None; positions.len()];
    for corner in triangles.iter().flatten() {
        let Some(texcoord) = corner.texcoord else {
            continue;
        };
        match texcoord_of_position[corner.position] {
            None => texcoord_of_position[corner.position] = Some(texcoord),
            Some(previous) if texcoords[previous] != texcoords[texcoord] => {
                return Err(MeshError::UvSeam {
                    vertex: corner.position,
                });
            }
            Some(_) => {}
        }
    }

    // Keep the used positions in file order.
    let mut mesh = Mesh::default();
    let mut new_index: Vec<u32> = vec![u32::MAX; positions.len()];
    for (position_index, texcoord) in texcoord_of_position.iter().enumerate() {
        if let Some(texcoord) = texcoord {
            new_index[position_index] = mesh.positions.len() as u32;
            mesh.positions.push(positions[position_index]);
            mesh.uvs.push(texcoords[*texcoord]);
        }
    }
    mesh.triangles = triangles
        .iter()
        .map(|corners| corners.map(|c| new_index[c.position]))
        .collect();
    Ok(mesh)
}

/// Parses the first `N` numbers after a keyword; further numbers (such as
/// `w` or vertex colours) are ignored.
fn parse_numbers<'a, const N: usize>(
    words: &mut impl Iterator<Item = &'a str>,
    keyword: &str,
    expected: &str,
) -> Result<[f64; N], String> {
    let mut numbers = [0.0; N];
    for number in &mut numbers {
        let word = words
            .next()
            .ok_or_else(|| format!("`{keyword}` needs {expected}"))?;
        *number = word
            .parse()
            .map_err(|_| format!("`{word}` is not a number"))?;
    }
    Ok(numbers)
}

/// Parses a face corner `v`, `v/vt`, `v//vn` or `v/vt/vn`, resolving the
/// indices against the `position_count` positions and `texcoord_count`
/// texture coordinates defined so far.
fn parse_corner(
    word: &str,
    position_count: usize,
    texcoord_count: usize,
) -> Result<Corner, String> {
    let parts: Vec<&str> = word.split('/').collect();
    if parts.len() > 3 {
        return Err(format!("face corner `{word}` has too many `/`"));
    }
    let position = resolve_index(parts[0], position_count, "vertex")?;
    let texcoord = match parts.get(1) {
        Some(part) if !part.is_empty() => {
            Some(resolve_index(part, texcoord_count, "texture coordinate")?)
        }
        _ => None,
    };
    Ok(Corner { position, texcoord })
}

/// Turns a 1-based or negative (relative) OBJ index into a 0-based one.
fn resolve_index(word: &str, count: usize, what: &str) -> Result<usize, String> {
    let index: i64 = word
        .parse()
        .map_err(|_| format!("`{word}` is not a {what} index"))?;
    let resolved = if index > 0 {
        index - 1
    } else if index < 0 {
        count as i64 + index
    } else {
        return Err(format!(
            "{what} index 0 is invalid (OBJ indices start at 1)"
        ));
    };
    if resolved < 0 || resolved >= count as i64 {
        return Err(format!(
            "{what} index {index} is out of range ({count} defined so far)"
        ));
    }
    Ok(resolved as usize)
}

/// Writes a triangle mesh as OBJ text: positions, UVs (if `uvs` is not
/// empty), area-weighted vertex normals and `v/vt/vn` faces. Numbers are
/// printed with enough digits to read back exactly.
///
/// Fails with [`io::ErrorKind::InvalidInput`] if `uvs` is neither empty nor
/// one per position, or a triangle refers to a missing position.
pub fn write_obj(
    w: &mut impl Write,
    positions: &[DVec3],
    uvs: &[DVec2],
    triangles: &[[u32; 3]],
) -> io::Result<()> {
    if !uvs.is_empty() && uvs.len() != positions.len() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} UVs for {} positions", uvs.len(), positions.len()),
        ));
    }
    if let Some(t) = triangles
        .iter()
        .position(|tri| tri.iter().any(|&i| i as usize >= positions.len()))
    {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("triangle {t} refers to a missing position"),
        ));
    }
    w.write_all(obj_text(positions, uvs, triangles).as_bytes())
}

/// The OBJ text of `mesh` (see [`write_obj`]). The mesh's triangles must
/// refer to existing vertices, as in every validated mesh; UVs are left out
/// if there is not exactly one per vertex.
pub fn obj_string(mesh: &Mesh) -> String {
    let uvs: &[DVec2] = if mesh.uvs.len() == mesh.positions.len() {
        &mesh.uvs
    } else {
        &[]
    };
    obj_text(&mesh.positions, uvs, &mesh.triangles)
}

fn obj_text(positions: &[DVec3], uvs: &[DVec2], triangles: &[[u32; 3]]) -> String {
    use std::fmt::Write as _;

    let normals = vertex_normals(positions, triangles);
    let mut text = String::from("# Anthesis mesh\n");
    // `{:?}` prints the shortest decimal that parses back to the same f64.
    // Writing to a String cannot fail, so the fmt::Results are ignored.
    for p in positions {
        let _ = writeln!(text, "v {:?} {:?} {:?}", p.x, p.y, p.z);
    }
    for uv in uvs {
        let _ = writeln!(text, "vt {:?} {:?}", uv.x, uv.y);
    }
    for n in &normals {
        let _ = writeln!(text, "vn {:?} {:?} {:?}", n.x, n.y, n.z);
    }
    for tri in triangles {
        let [a, b, c] = tri.map(|i| i + 1);
        if uvs.is_empty() {
            let _ = writeln!(text, "f {a}//{a} {b}//{b} {c}//{c}");
        } else {
            let _ = writeln!(text, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}");
        }
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate;
    use crate::generate::unit_square;

    const QUAD: &str = "\
# a unit square as one polygon
mtllib petal.mtl
o petal
g front
s 1
usemtl petal
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
f 1/1/1 2/2/1 3/3/1 4/4/1
";

    #[test]
    fn polygon_is_fan_triangulated_and_ignored_statements_are_skipped() {
        let mesh = parse_obj(QUAD).expect("valid quad");
        assert_eq!(mesh, unit_square());
    }

    #[test]
    fn negative_indices_and_v_vt_corners() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n\
                    f -3/-3 -2/-2 -1/-1\n\
                    v 0 1 0\nvt 0 1\nf 1/1 3/3 -1/-1\n";
        let mesh = parse_obj(text).expect("valid");
        assert_eq!(mesh, unit_square());
    }

    #[test]
    fn duplicate_vt_with_equal_value_is_not_a_seam() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
                    vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0 0\nvt 1 1\n\
                    f 1/1 2/2 3/3\nf 1/5 3/6 4/4\n";
        assert_eq!(parse_obj(text).expect("no seam"), unit_square());
    }

    #[test]
    fn unused_positions_are_dropped_and_faces_renumbered() {
        let text = "v 9 9 9\nv 0 0 0\nv 1 0 0\nv 8 8 8\nv 1 1 0\nv 0 1 0\nv 7 7 7\n\
                    vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
                    f 2/1 3/2 5/3 6/4\n";
        assert_eq!(parse_obj(text).expect("valid"), unit_square());
    }

    #[test]
    fn position_with_two_uvs_is_a_seam_naming_the_vertex() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
                    vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\n\
                    f 1/1 2/2 3/3\nf 1/1 3/5 4/4\n";
        assert_eq!(parse_obj(text), Err(MeshError::UvSeam { vertex: 2 }));
    }

    #[test]
    fn face_without_vt_names_its_line() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n\
                    f 1/1 2/2 3/3\nf 1/1 3/3 4//1\n";
        assert_eq!(parse_obj(text), Err(MeshError::MissingUvOnFace { line: 9 }));
    }

    #[test]
    fn file_without_any_vt_is_missing_uvs() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n";
        assert_eq!(parse_obj(text), Err(MeshError::MissingUvs));
    }

    #[test]
    fn syntax_errors_name_their_line() {
        let cases = [
            ("v 0 0 0\nv 1 zero 0\n", 2, "`zero` is not a number"),
            ("v 0 0\n", 1, "`v` needs x y z"),
            ("vt 0\n", 1, "`vt` needs u v"),
            (
                "v 0 0 0\nv 1 0 0\nvt 0 0\n\nf 1/1 2/1\n",
                5,
                "at least 3 corners",
            ),
            ("v 0 0 0\nvt 0 0\nf 0/1 1/1 1/1\n", 3, "index 0 is invalid"),
            (
                "v 0 0 0\nvt 0 0\nf 1/1 2/1 1/1\n",
                3,
                "vertex index 2 is out of range",
            ),
            (
                "v 0 0 0\nvt 0 0\nf 1/1 1/-2 1/1\n",
                3,
                "texture coordinate index -2",
            ),
            ("v 0 0 0\nvt 0 0\nf 1/1/1/1 1/1 1/1\n", 3, "too many `/`"),
            (
                "v 0 0 0\nvt 0 0\nf a/1 1/1 1/1\n",
                3,
                "`a` is not a vertex index",
            ),
            ("# fine\nl 1 2\n", 2, "unsupported statement `l`"),
        ];
        for (text, expected_line, expected_message) in cases {
            match parse_obj(text) {
                Err(MeshError::ObjSyntax { line, message }) => {
                    assert_eq!(line, expected_line, "{text:?}");
                    assert!(
                        message.contains(expected_message),
                        "{text:?}: message {message:?} lacks {expected_message:?}"
                    );
                }
                other => panic!("{text:?}: expected a syntax error, got {other:?}"),
            }
        }
    }

    #[test]
    fn import_validates_non_finite_coordinates() {
        let text = QUAD.replace("v 1 1 0", "v 1 nan 0");
        assert_eq!(
            parse_obj(&text),
            Err(MeshError::NonFinitePosition { vertex: 2 })
        );
        let text = QUAD.replace("v 1 0 0", "v inf 0 0");
        assert_eq!(
            parse_obj(&text),
            Err(MeshError::NonFinitePosition { vertex: 1 })
        );
        // The unvalidated parser hands the mesh over as it is.
        let mesh = parse_obj_unvalidated(&text).expect("parses");
        assert!(mesh.positions[1].x.is_infinite());
    }

    #[test]
    fn import_validates_topology() {
        // Second face walks the shared edge 1-3 in the same direction.
        let text = QUAD.replace("f 1/1/1 2/2/1 3/3/1 4/4/1", "f 1/1 2/2 3/3\nf 1/1 4/4 3/3");
        assert_eq!(
            parse_obj(&text),
            Err(MeshError::InconsistentOrientation {
                a: 2,
                b: 0,
                first: 0,
                second: 1
            })
        );
    }

    #[test]
    fn generated_petal_round_trips_exactly() {
        let petal = generate::test_petal(10.0, 4.0, 9, 17);
        let text = obj_string(&petal);
        assert_eq!(parse_obj(&text).expect("valid petal"), petal);
    }

    #[test]
    fn write_obj_writes_unit_normals() {
        let sheet = generate::flat_sheet(2.0, 1.0, 3, 2);
        let mut bytes = Vec::new();
        write_obj(&mut bytes, &sheet.positions, &sheet.uvs, &sheet.triangles).expect("writes");
        let text = String::from_utf8(bytes).expect("utf-8");
        let normals: Vec<&str> = text.lines().filter(|l| l.starts_with("vn ")).collect();
        assert_eq!(normals.len(), sheet.vertex_count());
        assert!(
            normals.iter().all(|&l| l == "vn 0.0 0.0 1.0"),
            "{normals:?}"
        );
        assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), 4);
        assert_eq!(text, obj_string(&sheet));
    }

    #[test]
    fn write_obj_rejects_inconsistent_arrays() {
        let sheet = generate::flat_sheet(1.0, 1.0, 2, 2);
        let mut bytes = Vec::new();
        let err = write_obj(
            &mut bytes,
            &sheet.positions,
            &sheet.uvs[..3],
            &sheet.triangles,
        )
        .expect_err("3 UVs for 4 positions");
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        let err = write_obj(&mut bytes, &sheet.positions, &sheet.uvs, &[[0, 1, 4]])
            .expect_err("index 4 of 4");
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        assert!(bytes.is_empty());
    }

    #[test]
    fn load_obj_reads_a_file_and_names_a_missing_path() {
        let dir = std::env::temp_dir().join(format!("anthesis-mesh-obj-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let path = dir.join("square.obj");
        std::fs::write(&path, QUAD).expect("write");
        assert_eq!(load_obj(&path).expect("loads"), unit_square());
        std::fs::remove_dir_all(&dir).expect("clean up");

        let missing = dir.join("missing.obj");
        match load_obj(&missing) {
            Err(MeshError::Io(message)) => {
                assert!(message.contains("missing.obj"), "{message}");
            }
            other => panic!("expected an Io error, got {other:?}"),
        }
    }
}

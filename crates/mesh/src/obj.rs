//! Wavefront OBJ import and export.
//!
//! Import reads `v`, `vt` and `f` statements (`vn` is read past: normals
//! are recomputed from the triangles). Face corners may be `v/vt` or
//! `v/vt/vn`, indices may be negative (relative to the end of the list so
//! far), and polygons with more than three corners are fan-triangulated
//! from their first corner, or cut by ear clipping where that fan would
//! leave a triangle without area or folded over (see `triangulate`).
//! `o`, `g`, `s`, `usemtl` and `mtllib` statements and `#` comments are
//! ignored; `l` (loose edges, which Blender writes) and `p` (points) are
//! ignored with an [`ObjWarning`]; any other statement is a syntax error.
//! A UTF-8 byte-order mark at the start is skipped; lines end in LF, CRLF or
//! (classic Mac OS) a lone CR.
//!
//! An organ needs exactly one UV per vertex, so every OBJ position takes the
//! UV of the face corners that use it; a position used with two different
//! UVs is a UV seam and is rejected. Positions used by no face are dropped.
//!
//! Files from elsewhere are read with limits: only regular files of at most
//! [`MAX_OBJ_BYTES`], at most [`MAX_VERTICES`] vertices,
//! [`MAX_TEXCOORDS`] texture coordinates and [`MAX_TRIANGLES`] triangles,
//! coordinates within [`validate::MAX_COORDINATE`]. Errors name the OBJ
//! line and count vertices and faces as the OBJ does, from 1.

use std::fmt;
use std::io::{self, Write};
use std::path::Path;

use glam::{DVec2, DVec3};

use crate::{Mesh, MeshError, validate, vertex_normals};

/// The largest OBJ file read, in bytes. A 2-million-triangle mesh with
/// normals is about 150 MB.
pub const MAX_OBJ_BYTES: u64 = 256 << 20;
/// The most vertices (`v` statements) an OBJ may have.
pub const MAX_VERTICES: usize = 1_000_000;
/// The most texture coordinates (`vt` statements) an OBJ may have.
pub const MAX_TEXCOORDS: usize = 4 * MAX_VERTICES;
/// The most triangles an OBJ may have (polygons count as their triangles).
pub const MAX_TRIANGLES: usize = 2 * MAX_VERTICES;

/// How much of a word from the file an error message quotes.
const QUOTED_CHARS: usize = 32;

/// Statements that were read past, one warning per kind.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ObjWarning {
    /// The statement, e.g. `l`.
    pub keyword: &'static str,
    /// How many there were.
    pub count: usize,
    /// The line of the first one.
    pub first_line: usize,
}

impl fmt::Display for ObjWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.keyword == "v" {
            let plural = if self.count == 1 { "" } else { "s" };
            let (what, verb) = if plural.is_empty() {
                ("vertex", "was")
            } else {
                ("vertices", "were")
            };
            return write!(
                f,
                "OBJ line {}: {} {what} at the same place as an earlier one {verb} joined to \
                 it (a mesh exported with its vertices split per face)",
                self.first_line, self.count
            );
        }
        let what = match self.keyword {
            "l" => "line (`l`)",
            _ => "point (`p`)",
        };
        let plural = if self.count == 1 { "" } else { "s" };
        write!(
            f,
            "OBJ line {}: {} {what} statement{plural} ignored; an organ is made of faces only",
            self.first_line, self.count
        )
    }
}

/// A mesh read from an OBJ file, and what was read past.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjFile {
    /// The mesh, validated (see [`validate()`](fn@crate::validate)).
    pub mesh: Mesh,
    /// Statements that were ignored (lines, points), to show the user.
    pub warnings: Vec<ObjWarning>,
}

/// Reads and validates the OBJ file at `path` (warnings dropped; see
/// [`load_obj_file`]).
pub fn load_obj(path: &Path) -> Result<Mesh, MeshError> {
    load_obj_file(path).map(|file| file.mesh)
}

/// Reads and validates the OBJ file at `path`: a regular file of at most
/// [`MAX_OBJ_BYTES`] bytes of UTF-8 text.
pub fn load_obj_file(path: &Path) -> Result<ObjFile, MeshError> {
    let text = anthesis_files::read_regular_text(path, MAX_OBJ_BYTES, "an OBJ mesh")
        .map_err(|e| MeshError::Io(format!("{}: {e}", path.display())))?;
    parse_obj_file(&text)
}

/// Parses OBJ text into a mesh and validates it (warnings dropped; see
/// [`parse_obj_file`]).
pub fn parse_obj(text: &str) -> Result<Mesh, MeshError> {
    parse_obj_file(text).map(|file| file.mesh)
}

/// Parses OBJ text into a mesh and validates it (see
/// [`validate::validate`]). Errors come wrapped in [`MeshError::InObj`]
/// with the OBJ line and the OBJ's own numbers (from 1) where one element
/// is at fault.
pub fn parse_obj_file(text: &str) -> Result<ObjFile, MeshError> {
    let parsed = parse(text, true)?;
    if let Err(error) = validate::validate(&parsed.mesh) {
        return Err(parsed.locate(error));
    }
    Ok(ObjFile {
        mesh: parsed.mesh,
        warnings: parsed.warnings,
    })
}

/// Parses OBJ text into a mesh without geometric validation. It still fails
/// on syntax errors, an empty file, missing UVs and UV seams, because those
/// make a mesh with one UV per vertex impossible to build.
pub fn parse_obj_unvalidated(text: &str) -> Result<Mesh, MeshError> {
    parse(text, true).map(|parsed| parsed.mesh)
}

/// Reads the OBJ file at `path` as a bare shape: like [`load_obj_file`],
/// but texture coordinates are not needed and, where there are any, not
/// read (a scanned or CAD petal without a UV layout; the mesh's UVs are
/// all zero). Positions, faces and topology are validated as for
/// [`load_obj_file`] ([`validate::validate_shape`]), errors naming the OBJ
/// line and element.
pub fn load_obj_shape(path: &Path) -> Result<ObjFile, MeshError> {
    let text = anthesis_files::read_regular_text(path, MAX_OBJ_BYTES, "an OBJ mesh")
        .map_err(|e| MeshError::Io(format!("{}: {e}", path.display())))?;
    parse_obj_shape(&text)
}

/// Parses OBJ text as a bare shape (see [`load_obj_shape`]). Vertices at
/// exactly the same place are joined into one (exports that split every
/// vertex per face, or along normal or texture seams, would otherwise read
/// as loose triangles), with a warning saying how many.
pub fn parse_obj_shape(text: &str) -> Result<ObjFile, MeshError> {
    let parsed = parse(text, false)?.welded();
    if let Err(error) = validate::validate_shape(&parsed.mesh) {
        return Err(parsed.locate(error));
    }
    Ok(ObjFile {
        mesh: parsed.mesh,
        warnings: parsed.warnings,
    })
}

/// Parses OBJ text as triangles to measure against, not to simulate: like
/// [`parse_obj_shape`] (no UVs needed, vertices at one place joined, syntax
/// and index errors naming the line) but without its checks of the
/// surface (several pieces, non-manifold edges or vertices, mixed winding,
/// degenerate triangles are all kept): a scan as it comes.
pub fn parse_obj_triangles(text: &str) -> Result<ObjFile, MeshError> {
    let parsed = parse(text, false)?.welded();
    Ok(ObjFile {
        mesh: parsed.mesh,
        warnings: parsed.warnings,
    })
}

/// The OBJ text of one object of `text` alone (its `v`, `vt` and `f`
/// statements, face indices renumbered from 1), for files that hold several
/// organs such as `anthesis simulate --out FOLDER/` writes: the object
/// called `name`, or with no name the only object. A file without `o`
/// statements is one object. Needs each object's `v` and `vt` statements
/// after its `o` statement (as Anthesis and most tools write them) and
/// positive face indices.
pub fn object_text(text: &str, name: Option<&str>) -> Result<String, MeshError> {
    // Object name and its lines; lines before the first `o` go to "".
    let mut objects: Vec<(String, Vec<&str>)> = vec![(String::new(), Vec::new())];
    for line in text.lines() {
        match line.trim_start().strip_prefix("o ") {
            Some(rest) => objects.push((rest.trim().to_owned(), Vec::new())),
            None => {
                if let Some((_, lines)) = objects.last_mut() {
                    lines.push(line);
                }
            }
        }
    }
    let is_face = |l: &&str| l.trim_start().starts_with("f ");
    if objects.len() > 1 && !objects[0].1.iter().any(is_face) {
        objects.remove(0);
    }
    let names: Vec<&str> = objects.iter().map(|(n, _)| n.as_str()).collect();
    let chosen = match name {
        Some(name) => names.iter().position(|n| *n == name).ok_or_else(|| {
            MeshError::Object(format!(
                "the OBJ has no object `{name}` (it has: {})",
                names.join(", ")
            ))
        })?,
        None if objects.len() == 1 => 0,
        None => {
            return Err(MeshError::Object(format!(
                "the OBJ holds {} objects ({}); say which one",
                objects.len(),
                names.join(", ")
            )));
        }
    };
    let count = |lines: &[&str], keyword: &str| {
        lines
            .iter()
            .filter(|l| {
                l.trim_start()
                    .strip_prefix(keyword)
                    .is_some_and(|r| r.starts_with(' '))
            })
            .count()
    };
    let (v_before, vt_before) = objects[..chosen]
        .iter()
        .fold((0, 0), |(v, vt), (_, lines)| {
            (v + count(lines, "v"), vt + count(lines, "vt"))
        });
    let mut out = String::new();
    for line in &objects[chosen].1 {
        let Some(corners) = line.trim_start().strip_prefix("f ") else {
            out.push_str(line);
            out.push('\n');
            continue;
        };
        out.push('f');
        for corner in corners.split_whitespace() {
            let mut parts = corner.split('/');
            let mut renumber = |before: usize| -> Result<String, MeshError> {
                match parts.next() {
                    None | Some("") => Ok(String::new()),
                    Some(index) => match index.parse::<usize>() {
                        Ok(i) if i > before => Ok((i - before).to_string()),
                        _ => Err(MeshError::Object(format!(
                            "face corner `{corner}` of object `{}` does not index the object's own vertices",
                            names[chosen]
                        ))),
                    },
                }
            };
            let v = renumber(v_before)?;
            let vt = renumber(vt_before)?;
            out.push(' ');
            out.push_str(&v);
            if !vt.is_empty() {
                out.push('/');
                out.push_str(&vt);
            }
        }
        out.push('\n');
    }
    Ok(out)
}

/// One corner of an OBJ face: 0-based position and texture coordinate
/// indices.
#[derive(Debug, Clone, Copy)]
struct Corner {
    position: usize,
    texcoord: Option<usize>,
}

/// A parsed OBJ and where each element of its mesh came from.
struct Parsed {
    mesh: Mesh,
    warnings: Vec<ObjWarning>,
    /// Per mesh vertex: its number among the `v` statements (from 1), the
    /// line of that statement and the line of its `vt`.
    vertex_number: Vec<usize>,
    vertex_line: Vec<usize>,
    texcoord_line: Vec<usize>,
    /// Per triangle: the number of its `f` statement (from 1) and its line.
    face_number: Vec<usize>,
    face_line: Vec<usize>,
}

impl Parsed {
    /// The mesh with vertices at exactly the same position joined (the
    /// first one kept, with its `v` statement's number and line for error
    /// messages), and a warning when any were.
    fn welded(mut self) -> Parsed {
        let key = |p: glam::DVec3| {
            // +0 and -0 are the same place.
            p.to_array()
                .map(|c| if c == 0.0 { 0u64 } else { c.to_bits() })
        };
        let mut first: std::collections::HashMap<[u64; 3], u32> = std::collections::HashMap::new();
        let mut kept: Vec<usize> = Vec::new();
        let mut new_index: Vec<u32> = Vec::with_capacity(self.mesh.positions.len());
        let mut joined = 0;
        let mut first_joined_line = None;
        for (v, p) in self.mesh.positions.iter().enumerate() {
            let index = *first.entry(key(*p)).or_insert_with(|| {
                kept.push(v);
                (kept.len() - 1) as u32
            });
            if kept.last() != Some(&v) {
                joined += 1;
                first_joined_line.get_or_insert(self.vertex_line[v]);
            }
            new_index.push(index);
        }
        if joined == 0 {
            return self;
        }
        let pick = |values: &[usize]| kept.iter().map(|&v| values[v]).collect::<Vec<_>>();
        self.vertex_number = pick(&self.vertex_number);
        self.vertex_line = pick(&self.vertex_line);
        self.texcoord_line = pick(&self.texcoord_line);
        self.mesh.positions = kept.iter().map(|&v| self.mesh.positions[v]).collect();
        self.mesh.uvs = kept.iter().map(|&v| self.mesh.uvs[v]).collect();
        for t in &mut self.mesh.triangles {
            *t = t.map(|v| new_index[v as usize]);
        }
        self.warnings.push(ObjWarning {
            keyword: "v",
            count: joined,
            first_line: first_joined_line.unwrap_or(0),
        });
        self
    }

    /// `error`, found by validating the mesh, in the OBJ's numbers and with
    /// the line of the statement at fault.
    fn locate(&self, error: MeshError) -> MeshError {
        use MeshError::*;
        let vertex = |v: usize| self.vertex_number[v];
        let vertex_u32 = |v: u32| u32::try_from(self.vertex_number[v as usize]).unwrap_or(u32::MAX);
        let face = |t: usize| self.face_number[t];
        let (line, error) = match error {
            RepeatedVertex {
                triangle,
                vertex: v,
            } => (
                Some(self.face_line[triangle]),
                RepeatedVertex {
                    triangle: face(triangle),
                    vertex: vertex_u32(v),
                },
            ),
            NonFinitePosition { vertex: v } => (
                Some(self.vertex_line[v]),
                NonFinitePosition { vertex: vertex(v) },
            ),
            CoordinateOutOfRange { vertex: v, value } => (
                Some(self.vertex_line[v]),
                CoordinateOutOfRange {
                    vertex: vertex(v),
                    value,
                },
            ),
            NonFiniteUv { vertex: v } => (
                Some(self.texcoord_line[v]),
                NonFiniteUv { vertex: vertex(v) },
            ),
            UvOutOfRange { vertex: v, value } => (
                Some(self.texcoord_line[v]),
                UvOutOfRange {
                    vertex: vertex(v),
                    value,
                },
            ),
            DegenerateTriangle {
                triangle,
                space,
                area,
            } => (
                Some(self.face_line[triangle]),
                DegenerateTriangle {
                    triangle: face(triangle),
                    space,
                    area,
                },
            ),
            NonManifoldEdge { a, b, faces } => (
                None,
                NonManifoldEdge {
                    a: vertex_u32(a),
                    b: vertex_u32(b),
                    faces,
                },
            ),
            NonManifoldVertex { vertex: v, fans } => (
                Some(self.vertex_line[v as usize]),
                NonManifoldVertex {
                    vertex: vertex_u32(v),
                    fans,
                },
            ),
            InconsistentOrientation {
                a,
                b,
                first,
                second,
            } => (
                Some(self.face_line[second]),
                InconsistentOrientation {
                    a: vertex_u32(a),
                    b: vertex_u32(b),
                    first: face(first),
                    second: face(second),
                },
            ),
            FlippedUv { triangle } => (
                Some(self.face_line[triangle]),
                FlippedUv {
                    triangle: face(triangle),
                },
            ),
            // Nothing to renumber: the whole mesh is at fault.
            other => return other,
        };
        InObj {
            line,
            error: Box::new(error),
        }
    }
}

/// With `uvs` false the texture coordinates are read past: every vertex
/// gets UV zero, and faces need none.
///
/// The phases: the statements read line by line ([`Statements::read`]),
/// checked for a surface ([`Statements::check`]), one texture coordinate
/// found per position ([`Statements::texcoord_per_position`]), then the
/// used positions kept in file order ([`Statements::into_parsed`]).
fn parse(text: &str, uvs: bool) -> Result<Parsed, MeshError> {
    let statements = Statements::read(text, uvs)?;
    statements.check(uvs)?;
    let (texcoord_of_position, used_position) = statements.texcoord_per_position()?;
    Ok(statements.into_parsed(&texcoord_of_position, &used_position))
}

/// An OBJ file's statements as read, with the lines they are on.
#[derive(Default)]
struct Statements {
    positions: Vec<DVec3>,
    position_lines: Vec<usize>,
    texcoords: Vec<DVec2>,
    texcoord_lines: Vec<usize>,
    /// The faces, triangulated.
    triangles: Vec<[Corner; 3]>,
    /// Each triangle's face number (from 1) and line.
    face_of_triangle: Vec<(usize, usize)>,
    face_count: usize,
    first_face_without_uv: Option<usize>,
    warnings: Vec<ObjWarning>,
}

impl Statements {
    /// Reads every line of `text` (LF, CRLF or classic Mac CR line ends, a
    /// byte-order mark skipped); an error names the line.
    fn read(text: &str, uvs: bool) -> Result<Statements, MeshError> {
        // Notepad and some exporters start UTF-8 files with a byte-order mark.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut read = Statements::default();
        // Classic Mac OS ended lines with a lone CR; such a file has no LF,
        // and read by LF it was one comment line, "empty".
        let lines: Box<dyn Iterator<Item = &str>> = if text.contains('\n') {
            Box::new(text.lines())
        } else {
            Box::new(text.split('\r'))
        };
        for (line_index, raw_line) in lines.enumerate() {
            read.line(line_index + 1, raw_line, uvs)?;
        }
        Ok(read)
    }

    /// One line, numbered `line` from 1.
    fn line(&mut self, line: usize, raw_line: &str, uvs: bool) -> Result<(), MeshError> {
        let content = raw_line.split('#').next().unwrap_or("");
        let mut words = content.split_whitespace();
        let Some(keyword) = words.next() else {
            return Ok(());
        };
        let syntax = |message: String| MeshError::ObjSyntax { line, message };
        let too_many =
            |what: &'static str, limit: usize| MeshError::TooManyElements { line, what, limit };
        match keyword {
            "v" => {
                if self.positions.len() == MAX_VERTICES {
                    return Err(too_many("vertices", MAX_VERTICES));
                }
                let [x, y, z] = parse_numbers::<3>(&mut words, "v", "x y z").map_err(syntax)?;
                self.positions.push(DVec3::new(x, y, z));
                self.position_lines.push(line);
            }
            "vt" => {
                if self.texcoords.len() == MAX_TEXCOORDS {
                    return Err(too_many("texture coordinates", MAX_TEXCOORDS));
                }
                let [u, v] = parse_numbers::<2>(&mut words, "vt", "u v").map_err(syntax)?;
                self.texcoords.push(DVec2::new(u, v));
                self.texcoord_lines.push(line);
            }
            "f" => self.face(line, words, uvs)?,
            // Blender writes loose edges as `l`; points are as loose. Neither
            // is part of a surface.
            "l" | "p" => match self.warnings.iter_mut().find(|w| w.keyword == keyword) {
                Some(warning) => warning.count += 1,
                None => self.warnings.push(ObjWarning {
                    keyword: if keyword == "l" { "l" } else { "p" },
                    count: 1,
                    first_line: line,
                }),
            },
            "vn" | "o" | "g" | "s" | "usemtl" | "mtllib" => {}
            other => {
                return Err(syntax(format!(
                    "unsupported statement `{}`",
                    anthesis_files::excerpt(other, QUOTED_CHARS)
                )));
            }
        }
        Ok(())
    }

    /// An `f` statement on `line`: its corners, triangulated.
    fn face<'a>(
        &mut self,
        line: usize,
        words: impl Iterator<Item = &'a str>,
        uvs: bool,
    ) -> Result<(), MeshError> {
        let syntax = |message: String| MeshError::ObjSyntax { line, message };
        let mut corners = Vec::new();
        for word in words {
            let mut corner =
                parse_corner(word, self.positions.len(), self.texcoords.len()).map_err(syntax)?;
            if !uvs {
                corner.texcoord = None;
            }
            if corner.texcoord.is_none() && self.first_face_without_uv.is_none() {
                self.first_face_without_uv = Some(line);
            }
            corners.push(corner);
        }
        if corners.len() < 3 {
            return Err(syntax(format!(
                "a face needs at least 3 corners, found {}",
                corners.len()
            )));
        }
        if self.triangles.len() + corners.len() - 2 > MAX_TRIANGLES {
            return Err(MeshError::TooManyElements {
                line,
                what: "triangles",
                limit: MAX_TRIANGLES,
            });
        }
        self.face_count += 1;
        let points = polygon_points(&corners, &self.positions, &self.texcoords);
        for [a, b, c] in triangulate(corners.len(), &points) {
            self.triangles.push([corners[a], corners[b], corners[c]]);
            self.face_of_triangle.push((self.face_count, line));
        }
        Ok(())
    }

    /// A file with no surface (or, when `uvs`, without texture
    /// coordinates on every face) is refused.
    fn check(&self, uvs: bool) -> Result<(), MeshError> {
        if self.positions.is_empty() && self.triangles.is_empty() {
            return Err(MeshError::EmptyObj);
        }
        if self.triangles.is_empty() {
            return Err(MeshError::NoFaces);
        }
        if uvs && self.texcoords.is_empty() {
            return Err(MeshError::MissingUvs);
        }
        if let Some(line) = self.first_face_without_uv.filter(|_| uvs) {
            return Err(MeshError::MissingUvOnFace { line });
        }
        Ok(())
    }

    /// One texture coordinate per position; a second, different one is a
    /// seam. Returns each position's texture coordinate and whether a face
    /// uses it.
    fn texcoord_per_position(&self) -> Result<(Vec<Option<usize>>, Vec<bool>), MeshError> {
        let mut texcoord_of_position: Vec<Option<usize>> = vec![None; self.positions.len()];
        let mut used_position = vec![false; self.positions.len()];
        for (triangle, corners) in self.triangles.iter().enumerate() {
            for corner in corners {
                used_position[corner.position] = true;
            }
            for corner in corners {
                let Some(texcoord) = corner.texcoord else {
                    continue;
                };
                match texcoord_of_position[corner.position] {
                    None => texcoord_of_position[corner.position] = Some(texcoord),
                    Some(previous) if self.texcoords[previous] != self.texcoords[texcoord] => {
                        return Err(MeshError::InObj {
                            line: Some(self.face_of_triangle[triangle].1),
                            error: Box::new(MeshError::UvSeam {
                                vertex: corner.position + 1,
                            }),
                        });
                    }
                    Some(_) => {}
                }
            }
        }
        Ok((texcoord_of_position, used_position))
    }

    /// The mesh of the used positions in file order, with the numbers and
    /// lines its errors are reported at.
    fn into_parsed(self, texcoord_of_position: &[Option<usize>], used_position: &[bool]) -> Parsed {
        let Statements {
            positions,
            position_lines,
            texcoords,
            texcoord_lines,
            triangles,
            face_of_triangle,
            warnings,
            ..
        } = self;
        // Keep the used positions in file order.
        let mut parsed = Parsed {
            mesh: Mesh::default(),
            warnings,
            vertex_number: Vec::new(),
            vertex_line: Vec::new(),
            texcoord_line: Vec::new(),
            face_number: face_of_triangle.iter().map(|&(face, _)| face).collect(),
            face_line: face_of_triangle.iter().map(|&(_, line)| line).collect(),
        };
        let mesh = &mut parsed.mesh;
        let mut new_index: Vec<u32> = vec![u32::MAX; positions.len()];
        for (position_index, texcoord) in texcoord_of_position.iter().enumerate() {
            if !used_position[position_index] {
                continue;
            }
            new_index[position_index] = mesh.positions.len() as u32;
            mesh.positions.push(positions[position_index]);
            parsed.vertex_number.push(position_index + 1);
            parsed.vertex_line.push(position_lines[position_index]);
            match *texcoord {
                Some(texcoord) => {
                    mesh.uvs.push(texcoords[texcoord]);
                    parsed.texcoord_line.push(texcoord_lines[texcoord]);
                }
                // Only when UVs are not read (otherwise every corner has one).
                None => {
                    mesh.uvs.push(DVec2::ZERO);
                    parsed.texcoord_line.push(position_lines[position_index]);
                }
            }
        }
        mesh.triangles = triangles
            .iter()
            .map(|corners| corners.map(|c| new_index[c.position]))
            .collect();
        parsed
    }
}

/// Polygons with more corners than this are always fanned: ear clipping
/// takes time cubic in the corners in the worst case.
const MAX_EAR_CLIPPED_CORNERS: usize = 256;

/// A face's corners as points in a plane, to triangulate it in: their UVs
/// when every corner has one and the UV polygon has an area (a petal's
/// layout is flat, and its triangles must not fold there), otherwise the
/// positions projected onto the plane across the polygon's (Newell)
/// normal. Empty when neither gives an area.
fn polygon_points(corners: &[Corner], positions: &[DVec3], texcoords: &[DVec2]) -> Vec<DVec2> {
    if corners.len() <= 3 {
        return Vec::new();
    }
    let uvs: Option<Vec<DVec2>> = corners
        .iter()
        .map(|c| c.texcoord.map(|t| texcoords[t]))
        .collect();
    if let Some(uvs) = uvs
        && doubled_signed_area(&uvs) != 0.0
    {
        return uvs;
    }
    let points: Vec<DVec3> = corners.iter().map(|c| positions[c.position]).collect();
    let mut normal = DVec3::ZERO;
    for (k, p) in points.iter().enumerate() {
        let q = points[(k + 1) % points.len()];
        normal += p.cross(q);
    }
    let Some(normal) = normal.try_normalize() else {
        return Vec::new();
    };
    let across = normal.any_orthonormal_vector();
    let up = normal.cross(across);
    points
        .iter()
        .map(|p| DVec2::new(p.dot(across), p.dot(up)))
        .collect()
}

/// Twice the signed area of a polygon (positive counter-clockwise).
fn doubled_signed_area(points: &[DVec2]) -> f64 {
    (0..points.len())
        .map(|k| points[k].perp_dot(points[(k + 1) % points.len()]))
        .sum()
}

/// The triangles of a polygon of `count` corners at `points` (see
/// [`polygon_points`]), as indices into its corners, each wound as the
/// polygon: a fan from the first corner, as most readers make, unless a
/// fan triangle would have no area or turn the other way. Then the polygon
/// is cut by ear clipping, skipping ears without area: a corner on a
/// straight side (two quads merged into one face leave one) or a concave
/// corner otherwise leaves a degenerate or folded triangle. Without
/// points, or when no ear is left, the rest is fanned.
fn triangulate(count: usize, points: &[DVec2]) -> Vec<[usize; 3]> {
    let fan = |corners: &[usize]| -> Vec<[usize; 3]> {
        (1..corners.len().saturating_sub(1))
            .map(|k| [corners[0], corners[k], corners[k + 1]])
            .collect()
    };
    let all: Vec<usize> = (0..count).collect();
    let n = points.len();
    if n != count || n <= 3 || n > MAX_EAR_CLIPPED_CORNERS {
        return fan(&all);
    }
    let sense = doubled_signed_area(points).signum();
    let perimeter: f64 = (0..n)
        .map(|k| points[k].distance(points[(k + 1) % n]))
        .sum();
    let side = perimeter / n as f64;
    let smallest = 2.0 * crate::validate::DEGENERATE_AREA_RATIO * side * side;
    // Twice the area of a triangle, positive when wound as the polygon.
    let area = |a: usize, b: usize, c: usize| {
        sense * (points[b] - points[a]).perp_dot(points[c] - points[a])
    };
    if (1..n - 1).all(|k| area(0, k, k + 1) > smallest) {
        return fan(&all);
    }
    let mut left = all;
    let mut triangles = Vec::with_capacity(n - 2);
    while left.len() > 3 {
        let m = left.len();
        let ear = (0..m).find(|&k| {
            let (a, b, c) = (left[(k + m - 1) % m], left[k], left[(k + 1) % m]);
            area(a, b, c) > smallest
                && left.iter().all(|&p| {
                    p == a
                        || p == b
                        || p == c
                        || points[p] == points[a]
                        || points[p] == points[b]
                        || points[p] == points[c]
                        || area(a, b, p) < 0.0
                        || area(b, c, p) < 0.0
                        || area(c, a, p) < 0.0
                })
        });
        let Some(k) = ear else {
            break;
        };
        triangles.push([left[(k + m - 1) % m], left[k], left[(k + 1) % m]]);
        left.remove(k);
    }
    triangles.extend(fan(&left));
    triangles
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
        *number = word.parse().map_err(|_| {
            format!(
                "`{}` is not a number",
                anthesis_files::excerpt(word, QUOTED_CHARS)
            )
        })?;
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
        return Err(format!(
            "face corner `{}` has too many `/`",
            anthesis_files::excerpt(word, QUOTED_CHARS)
        ));
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
    let index: i64 = word.parse().map_err(|_| {
        format!(
            "`{}` is not a {what} index",
            anthesis_files::excerpt(word, QUOTED_CHARS)
        )
    })?;
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
    fn one_object_is_read_alone_from_a_file_of_several() {
        let square = generate::flat_sheet(1.0, 2.0, 2, 3);
        let other = generate::test_petal(4.0, 1.0, 3, 4);
        let first = obj_string(&other);
        let second = obj_string(&square);
        // Two objects, the second's indices counted after the first's.
        let offset = other.vertex_count();
        let shifted: String = second
            .lines()
            .filter(|l| !l.starts_with('#'))
            .map(|l| match l.strip_prefix("f ") {
                Some(corners) => {
                    let moved: Vec<String> = corners
                        .split_whitespace()
                        .map(|c| {
                            c.split('/')
                                .map(|i| (i.parse::<usize>().unwrap() + offset).to_string())
                                .collect::<Vec<_>>()
                                .join("/")
                        })
                        .collect();
                    format!("f {}\n", moved.join(" "))
                }
                None => format!("{l}\n"),
            })
            .collect();
        let text = format!("o leaf\n{first}o petal-1\n{shifted}");
        let alone = parse_obj(&object_text(&text, Some("petal-1")).unwrap()).unwrap();
        assert_eq!(alone, square);
        let leaf = parse_obj(&object_text(&text, Some("leaf")).unwrap()).unwrap();
        assert_eq!(leaf, other);
        let err = object_text(&text, None).unwrap_err().to_string();
        assert!(err.contains("2 objects (leaf, petal-1)"), "{err}");
        let err = object_text(&text, Some("sepal")).unwrap_err().to_string();
        assert!(err.contains("no object `sepal`"), "{err}");
        // A file without objects is its own only object.
        assert_eq!(
            parse_obj(&object_text(&second, None).unwrap()).unwrap(),
            square
        );
    }

    #[test]
    fn a_shape_exported_with_split_vertices_is_joined_into_one_surface() {
        // Two triangles sharing the edge (1, 0, 0)-(0, 1, 0), each with its
        // own three vertices (as STL-like exports write them), one of them
        // at -0.
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 0 0\nv 1 1 0\nv -0 1 -0\nf 1 2 3\nf 4 5 6\n";
        let file = parse_obj_shape(text).expect("a shape");
        assert_eq!(file.mesh.positions.len(), 4);
        assert_eq!(file.mesh.triangles, vec![[0, 1, 2], [1, 3, 2]]);
        assert_eq!(
            file.warnings,
            vec![ObjWarning {
                keyword: "v",
                count: 2,
                first_line: 4
            }]
        );
        assert!(
            file.warnings[0].to_string().starts_with(
                "OBJ line 4: 2 vertices at the same place as an earlier one were joined"
            ),
            "{}",
            file.warnings[0]
        );
        // An error still names the file's own vertex numbers: a NaN in the
        // fifth `v` statement.
        let bad = text.replace("v 1 1 0", "v nan 1 0");
        let error = parse_obj_shape(&bad).unwrap_err().to_string();
        assert!(error.contains("line 5"), "{error}");
    }

    #[test]
    fn polygon_is_fan_triangulated_and_ignored_statements_are_skipped() {
        let mesh = parse_obj(QUAD).expect("valid quad");
        assert_eq!(mesh, unit_square());
    }

    /// The triangles' areas in 3D and in UV, each wound as the mesh's
    /// first triangle (positive when the same way round in UV).
    fn areas(mesh: &Mesh) -> Vec<(f64, f64)> {
        (0..mesh.triangle_count())
            .map(|t| {
                let [a, b, c] = mesh.triangle_uvs(t);
                (mesh.triangle_area(t), 0.5 * (b - a).perp_dot(c - a))
            })
            .collect()
    }

    #[test]
    fn a_polygon_with_a_corner_on_a_straight_side_is_cut_into_proper_triangles() {
        // Two unit squares merged into one face (as Blender's dissolve or
        // a CAD export leaves them): the corner (1, 0) lies on the straight
        // bottom side, so a fan from the first corner would make the
        // triangle (0,0)-(1,0)-(2,0) of no area.
        let text = "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 0 1 0\n\
                    vt 0 0\nvt 0.5 0\nvt 1 0\nvt 1 1\nvt 0.5 1\nvt 0 1\n\
                    f 1/1 2/2 3/3 4/4 5/5 6/6\n";
        let mesh = parse_obj(text).expect("a proper hexagon");
        assert_eq!(mesh.triangle_count(), 4);
        let areas = areas(&mesh);
        assert!(
            areas.iter().all(|&(world, uv)| world > 0.1 && uv > 0.05),
            "{areas:?}"
        );
        let total: f64 = areas.iter().map(|(world, _)| world).sum();
        assert!((total - 2.0).abs() < 1e-12, "{total}");
        // The same face without UVs, read as a shape: cut in its plane.
        let shape = parse_obj_shape(text).expect("a proper shape").mesh;
        let total: f64 = (0..4).map(|t| shape.triangle_area(t)).sum();
        assert!((total - 2.0).abs() < 1e-12, "{total}");
    }

    #[test]
    fn a_concave_polygon_is_cut_without_folding() {
        // An L whose first corner sees the reflex corner (1, 1) from
        // outside: the fan's second triangle would turn the other way.
        let text = "v 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nv 0 0 0\n\
                    vt 1 0\nvt 1 0.5\nvt 0.5 0.5\nvt 0.5 1\nvt 0 1\nvt 0 0\n\
                    f 1/1 2/2 3/3 4/4 5/5 6/6\n";
        let mesh = parse_obj(text).expect("a proper L");
        let areas = areas(&mesh);
        assert_eq!(areas.len(), 4);
        assert!(areas.iter().all(|&(_, uv)| uv > 0.0), "{areas:?}");
        let total: f64 = areas.iter().map(|(world, _)| world).sum();
        assert!((total - 3.0).abs() < 1e-12, "{total}");
    }

    #[test]
    fn lines_ended_by_a_lone_cr_are_lines() {
        let text = "# classic Mac OS\rv 0 0 0\rv 1 0 0\rv 1 1 0\rv 0 1 0\r\
                    vt 0 0\rvt 1 0\rvt 1 1\rvt 0 1\rf 1/1 2/2 3/3 4/4\r";
        assert_eq!(parse_obj(text).expect("a square"), unit_square());
        // Its errors count those lines.
        let bad = text.replace("v 1 1 0", "v one 1 0");
        let error = parse_obj(&bad).expect_err("not a number").to_string();
        assert!(error.contains("line 4"), "{error}");
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
        // Position 3 (the OBJ's third `v`) meets a second UV on line 11.
        let error = parse_obj(text).expect_err("a seam");
        assert_eq!(
            error,
            MeshError::InObj {
                line: Some(11),
                error: Box::new(MeshError::UvSeam { vertex: 3 })
            }
        );
        assert!(
            error
                .to_string()
                .starts_with("OBJ line 11: vertex 3 has two")
        );
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
    fn a_shape_needs_no_uvs_and_its_errors_still_name_the_obj_element() {
        // No vt at all, an unused vertex dropped, a quad fanned.
        let text = "v 0 0 0\nv 1 0 0\nv 9 9 9\nv 1 1 0\nv 0 1 0\nf 1 2 4 5\n";
        let shape = parse_obj_shape(text).unwrap().mesh;
        assert_eq!(shape.positions.len(), 4);
        assert_eq!(shape.uvs, vec![DVec2::ZERO; 4]);
        assert_eq!(shape.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        // Faces with and without vt, UVs that would be a seam or flipped:
        // all read past.
        let mixed = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 1\n\
                     f 1/1 2/2 3\nf 1/2 3 4\n";
        assert_eq!(parse_obj_shape(mixed).unwrap().mesh.triangles.len(), 2);
        // A degenerate triangle is still refused, naming its OBJ line.
        let flat = "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 4\nf 2 3 4\nf 1 2 3\n";
        let error = parse_obj_shape(flat).unwrap_err().to_string();
        assert!(
            error.starts_with("OBJ line 7:") && error.contains("zero area"),
            "{error}"
        );
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
            ("# fine\nvp 1 2\n", 2, "unsupported statement `vp`"),
            (
                "v 0 0 0\nv 1 x2345678901234567890123456789012345678901 0\n",
                2,
                "`x2345678901234567890123456789012…` is not a number",
            ),
            ("v 0 0 \u{1b}[2J\n", 1, "`\\u{1b}[2J` is not a number"),
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

    /// `error` wrapped with an OBJ line.
    fn at_line(line: usize, error: MeshError) -> MeshError {
        MeshError::InObj {
            line: Some(line),
            error: Box::new(error),
        }
    }

    #[test]
    fn import_validates_non_finite_coordinates() {
        // QUAD's `v` statements are on lines 7 to 10.
        let text = QUAD.replace("v 1 1 0", "v 1 nan 0");
        assert_eq!(
            parse_obj(&text),
            Err(at_line(9, MeshError::NonFinitePosition { vertex: 3 }))
        );
        let text = QUAD.replace("v 1 0 0", "v inf 0 0");
        let error = parse_obj(&text).expect_err("infinite");
        assert_eq!(
            error,
            at_line(8, MeshError::NonFinitePosition { vertex: 2 })
        );
        assert_eq!(
            error.to_string(),
            "OBJ line 8: vertex 2 has a non-finite coordinate (NaN or infinite)"
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
            Err(at_line(
                17,
                MeshError::InconsistentOrientation {
                    a: 3,
                    b: 1,
                    first: 1,
                    second: 2
                }
            ))
        );
    }

    #[test]
    fn validation_errors_count_as_the_obj_does() {
        // Position 1 is unused (dropped from the mesh) and the quad is the
        // second face: the errors still name OBJ vertex 4 and face 2.
        // The square v2..v5 as a quad, and a fin v4-v2-v6 on its diagonal.
        let text = "v 9 9 9\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\n\
                    vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.2 0.8\n\
                    f 2/1 3/2 4/3 5/4\n\
                    f 4/3 2/1 6/5\n";
        let error = parse_obj(text).expect_err("non-manifold");
        assert_eq!(
            error.to_string(),
            "edge 2-4 is shared by 3 triangles (non-manifold; at most 2 allowed)"
        );
        let text = "v 9 9 9\nv 0 0 0\nv 1 0 0\nv 2 2 0\nv 0 1 0\n\
                    vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
                    f 2/1 3/2 4/3\n\
                    f 2/1 4/3 4/3\n";
        assert_eq!(
            parse_obj(text),
            Err(at_line(
                11,
                MeshError::RepeatedVertex {
                    triangle: 2,
                    vertex: 4
                }
            ))
        );
        let text = "v 0 0 0\nv 1 0 0\nv 2 0 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n";
        match parse_obj(text) {
            Err(MeshError::InObj {
                line: Some(7),
                error,
            }) => assert!(
                matches!(
                    *error,
                    MeshError::DegenerateTriangle {
                        triangle: 1,
                        space: crate::Space::World,
                        ..
                    }
                ),
                "{error:?}"
            ),
            other => panic!("expected a degenerate face 1 on line 7, got {other:?}"),
        }
    }

    #[test]
    fn a_huge_coordinate_is_out_of_range_at_its_line() {
        let text = QUAD.replace("v 1 1 0", "v 1 1e30 0");
        let error = parse_obj(&text).expect_err("out of range");
        assert_eq!(
            error,
            at_line(
                9,
                MeshError::CoordinateOutOfRange {
                    vertex: 3,
                    value: 1e30
                }
            )
        );
        assert_eq!(
            error.to_string(),
            "OBJ line 9: vertex 3 has a coordinate of 1e30, out of range: coordinates must \
             lie within ±1e6"
        );
        let text = QUAD.replace("vt 1 0", "vt 1e9 0");
        assert_eq!(
            parse_obj(&text),
            Err(at_line(
                12,
                MeshError::UvOutOfRange {
                    vertex: 2,
                    value: 1e9
                }
            ))
        );
    }

    #[test]
    fn empty_files_say_they_are_empty() {
        for text in [
            "",
            "\n\n",
            "# only a comment\n",
            "\u{feff}",
            "o petal\ng front\n",
        ] {
            assert_eq!(parse_obj(text), Err(MeshError::EmptyObj), "{text:?}");
        }
        assert_eq!(
            MeshError::EmptyObj.to_string(),
            "the OBJ file is empty: it has no vertices (v) and no faces (f)"
        );
        let points_only = "v 0 0 0\nv 1 0 0\nvt 0 0\n";
        assert_eq!(parse_obj(points_only), Err(MeshError::NoFaces));
    }

    #[test]
    fn a_byte_order_mark_is_skipped() {
        let with_bom = format!("\u{feff}{QUAD}");
        assert_eq!(parse_obj(&with_bom).expect("valid"), unit_square());
        let bom_before_v = "\u{feff}v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
                            vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\r\n";
        assert_eq!(parse_obj(bom_before_v).expect("valid"), unit_square());
    }

    #[test]
    fn loose_edges_and_points_are_ignored_with_a_warning() {
        let text = format!("{QUAD}l 1 2\nl 2 3 4\np 1\n");
        let file = parse_obj_file(&text).expect("valid");
        assert_eq!(file.mesh, unit_square());
        assert_eq!(
            file.warnings,
            [
                ObjWarning {
                    keyword: "l",
                    count: 2,
                    first_line: 17
                },
                ObjWarning {
                    keyword: "p",
                    count: 1,
                    first_line: 19
                }
            ]
        );
        assert_eq!(
            file.warnings[0].to_string(),
            "OBJ line 17: 2 line (`l`) statements ignored; an organ is made of faces only"
        );
        assert!(parse_obj_file(QUAD).expect("valid").warnings.is_empty());
    }

    #[test]
    fn too_many_triangles_stop_reading_at_the_line() {
        // One polygon with MAX_TRIANGLES + 1 triangles: the limit is met
        // while reading, before a mesh is built.
        let corners = MAX_TRIANGLES + 3;
        let mut text = String::from("v 0 0 0\nvt 0 0\nf");
        for _ in 0..corners {
            text.push_str(" 1/1");
        }
        text.push('\n');
        assert_eq!(
            parse_obj(&text),
            Err(MeshError::TooManyElements {
                line: 3,
                what: "triangles",
                limit: MAX_TRIANGLES
            })
        );
        let error = MeshError::TooManyElements {
            line: 3,
            what: "vertices",
            limit: MAX_VERTICES,
        };
        assert_eq!(
            error.to_string(),
            "OBJ line 3: more than 1000000 vertices, the most an organ mesh may have"
        );
    }

    #[test]
    fn too_many_vertices_stop_reading_at_the_line() {
        let text = "v 0 0 0\n".repeat(MAX_VERTICES + 1);
        assert_eq!(
            parse_obj(&text),
            Err(MeshError::TooManyElements {
                line: MAX_VERTICES + 1,
                what: "vertices",
                limit: MAX_VERTICES
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
                assert!(message.contains("does not exist"), "{message}");
            }
            other => panic!("expected an Io error, got {other:?}"),
        }
    }

    #[test]
    fn load_obj_reads_only_regular_files() {
        match load_obj(Path::new("/dev/zero")) {
            Err(MeshError::Io(message)) => assert_eq!(
                message,
                "/dev/zero: it is a character device (like /dev/zero), not a regular file; \
                 only regular files are read"
            ),
            other => panic!("expected an Io error, got {other:?}"),
        }
    }
}

use thiserror::Error;

use crate::validate::MAX_COORDINATE;

/// Which space a geometric check failed in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Space {
    /// 3D positions.
    World,
    /// The UV layout.
    Uv,
}

impl std::fmt::Display for Space {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Space::World => f.write_str("3D"),
            Space::Uv => f.write_str("UV"),
        }
    }
}

/// Everything that can be wrong with a mesh. Each variant names the
/// offending element so the user can find it. Indices of a mesh in memory
/// are 0-based; an error found in an OBJ file comes wrapped in
/// [`MeshError::InObj`] with the line and, inside it, the numbers the OBJ
/// uses, from 1: vertex `n` is the `n`-th `v` statement, triangle `n` the
/// `n`-th `f` statement (a polygon's triangles share its number).
#[derive(Debug, Error, Clone, PartialEq)]
pub enum MeshError {
    #[error("the mesh has no triangles")]
    Empty,
    #[error(
        "triangle {triangle} refers to vertex {index}, but there are only {vertex_count} vertices"
    )]
    IndexOutOfRange {
        triangle: usize,
        index: u32,
        vertex_count: usize,
    },
    #[error("triangle {triangle} uses vertex {vertex} twice")]
    RepeatedVertex { triangle: usize, vertex: u32 },
    #[error("the mesh has {uvs} UVs for {vertices} vertices: every vertex needs exactly one UV")]
    UvCountMismatch { vertices: usize, uvs: usize },
    #[error("vertex {vertex} has a non-finite coordinate (NaN or infinite)")]
    NonFinitePosition { vertex: usize },
    #[error("vertex {vertex} has a non-finite UV (NaN or infinite)")]
    NonFiniteUv { vertex: usize },
    #[error(
        "vertex {vertex} has a coordinate of {value:e}, out of range: coordinates must lie \
         within ±{MAX_COORDINATE:e}"
    )]
    CoordinateOutOfRange { vertex: usize, value: f64 },
    #[error(
        "vertex {vertex} has a UV component of {value:e}, out of range: UVs must lie within \
         ±{MAX_COORDINATE:e}"
    )]
    UvOutOfRange { vertex: usize, value: f64 },
    #[error("triangle {triangle} has zero area in {space} (area {area:.3e})")]
    DegenerateTriangle {
        triangle: usize,
        space: Space,
        area: f64,
    },
    #[error("edge {a}-{b} is shared by {faces} triangles (non-manifold; at most 2 allowed)")]
    NonManifoldEdge { a: u32, b: u32, faces: usize },
    #[error("vertex {vertex} is non-manifold: its triangles form {fans} separate fans")]
    NonManifoldVertex { vertex: u32, fans: usize },
    #[error("triangles {first} and {second} have opposite orientations across edge {a}-{b}")]
    InconsistentOrientation {
        a: u32,
        b: u32,
        first: usize,
        second: usize,
    },
    #[error(
        "triangle {triangle} is flipped in the UV layout (its UV winding disagrees with the rest of the mesh)"
    )]
    FlippedUv { triangle: usize },
    #[error("the mesh has {pieces} separate pieces; an organ must be one connected surface")]
    MultiplePieces { pieces: usize },
    #[error("vertex {vertex} belongs to no triangle")]
    UnusedVertex { vertex: usize },
    #[error("OBJ line {line}: {message}")]
    ObjSyntax { line: usize, message: String },
    #[error("the OBJ file is empty: it has no vertices (v) and no faces (f)")]
    EmptyObj,
    #[error("the OBJ file has no faces (f): an organ is a surface of triangles")]
    NoFaces,
    #[error("OBJ line {line}: more than {limit} {what}, the most an organ mesh may have")]
    TooManyElements {
        line: usize,
        /// "vertices", "texture coordinates" or "triangles".
        what: &'static str,
        limit: usize,
    },
    #[error("OBJ has no texture coordinates (vt): an organ needs a UV layout")]
    MissingUvs,
    #[error("OBJ line {line}: face corner has no texture coordinate")]
    MissingUvOnFace { line: usize },
    #[error("vertex {vertex} has two different UVs (a UV seam); an organ needs one UV per vertex")]
    UvSeam { vertex: usize },
    #[error("{}{error}", line_prefix(*line))]
    InObj {
        /// The OBJ line of the statement at fault, when one line is.
        line: Option<usize>,
        /// The error with the OBJ's numbers (from 1).
        error: Box<MeshError>,
    },
    #[error(
        "subdividing {level} times would make {vertices} vertices, more than the limit of {limit}: \
         choose a lower level"
    )]
    SubdivisionTooLarge {
        level: u32,
        vertices: u64,
        limit: u64,
    },
    #[error("cannot read mesh: {0}")]
    Io(String),
}

fn line_prefix(line: Option<usize>) -> String {
    line.map_or_else(String::new, |line| format!("OBJ line {line}: "))
}

impl MeshError {
    /// The error itself, without the [`MeshError::InObj`] wrapper.
    pub fn root(&self) -> &MeshError {
        match self {
            MeshError::InObj { error, .. } => error.root(),
            other => other,
        }
    }
}

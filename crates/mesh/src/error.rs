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
    /// The mesh has no triangles at all.
    #[error("the mesh has no triangles")]
    Empty,
    /// A triangle names a vertex index past the last vertex.
    #[error(
        "triangle {triangle} refers to vertex {index}, but there are only {vertex_count} vertices"
    )]
    IndexOutOfRange {
        /// The triangle's index.
        triangle: usize,
        /// The vertex index it names.
        index: u32,
        /// How many vertices the mesh has.
        vertex_count: usize,
    },
    /// A triangle uses one vertex at two of its corners (it has no area).
    #[error("triangle {triangle} uses vertex {vertex} twice")]
    RepeatedVertex {
        /// The triangle's index.
        triangle: usize,
        /// The vertex it uses twice.
        vertex: u32,
    },
    /// The mesh has not one UV per vertex.
    #[error("the mesh has {uvs} UVs for {vertices} vertices: every vertex needs exactly one UV")]
    UvCountMismatch {
        /// How many vertices it has.
        vertices: usize,
        /// How many UVs it has.
        uvs: usize,
    },
    /// A vertex position has a NaN or infinite coordinate.
    #[error("vertex {vertex} has a non-finite coordinate (NaN or infinite)")]
    NonFinitePosition {
        /// The vertex's index.
        vertex: usize,
    },
    /// A vertex UV has a NaN or infinite component.
    #[error("vertex {vertex} has a non-finite UV (NaN or infinite)")]
    NonFiniteUv {
        /// The vertex's index.
        vertex: usize,
    },
    /// A vertex coordinate lies beyond ±[`MAX_COORDINATE`] (a broken
    /// exporter or a hand edit).
    #[error(
        "vertex {vertex} has a coordinate of {value:e}, out of range: coordinates must lie \
         within ±{MAX_COORDINATE:e}"
    )]
    CoordinateOutOfRange {
        /// The vertex's index.
        vertex: usize,
        /// The coordinate out of range, in the mesh's units.
        value: f64,
    },
    /// A UV component lies beyond ±[`MAX_COORDINATE`].
    #[error(
        "vertex {vertex} has a UV component of {value:e}, out of range: UVs must lie within \
         ±{MAX_COORDINATE:e}"
    )]
    UvOutOfRange {
        /// The vertex's index.
        vertex: usize,
        /// The component out of range.
        value: f64,
    },
    /// A triangle has (next to) no area in 3D or in the UV layout, so its
    /// growth and stiffness cannot be computed.
    #[error("triangle {triangle} has zero area in {space} (area {area:.3e})")]
    DegenerateTriangle {
        /// The triangle's index.
        triangle: usize,
        /// Whether the area is zero in 3D or in UV.
        space: Space,
        /// Its area there (squared mesh units in 3D, UV units² in UV).
        area: f64,
    },
    /// More than two triangles share one edge; an organ is a surface.
    #[error("edge {a}-{b} is shared by {faces} triangles (non-manifold; at most 2 allowed)")]
    NonManifoldEdge {
        /// One end of the edge (vertex index).
        a: u32,
        /// The other end of the edge (vertex index).
        b: u32,
        /// How many triangles share it.
        faces: usize,
    },
    /// The triangles around a vertex do not form one fan (two surfaces
    /// touch at a point).
    #[error("vertex {vertex} is non-manifold: its triangles form {fans} separate fans")]
    NonManifoldVertex {
        /// The vertex's index.
        vertex: u32,
        /// How many separate fans of triangles meet at it.
        fans: usize,
    },
    /// Two neighbouring triangles wind opposite ways, so the surface has no
    /// consistent inner side.
    #[error("triangles {first} and {second} have opposite orientations across edge {a}-{b}")]
    InconsistentOrientation {
        /// One end of the shared edge (vertex index).
        a: u32,
        /// The other end of the shared edge (vertex index).
        b: u32,
        /// The first triangle's index.
        first: usize,
        /// The second triangle's index.
        second: usize,
    },
    /// A triangle is mirrored in the UV layout relative to the others
    /// (a folded UV map).
    #[error(
        "triangle {triangle} is flipped in the UV layout (its UV winding disagrees with the rest of the mesh)"
    )]
    FlippedUv {
        /// The triangle's index.
        triangle: usize,
    },
    /// The mesh is several disconnected surfaces; an organ is one.
    #[error("the mesh has {pieces} separate pieces; an organ must be one connected surface")]
    MultiplePieces {
        /// How many connected pieces it has.
        pieces: usize,
    },
    /// A vertex is in no triangle (it would be a free particle).
    #[error("vertex {vertex} belongs to no triangle")]
    UnusedVertex {
        /// The vertex's index.
        vertex: usize,
    },
    /// An OBJ statement cannot be read (bad number, unknown index form, ...).
    #[error("OBJ line {line}: {message}")]
    ObjSyntax {
        /// The OBJ line (from 1).
        line: usize,
        /// What is wrong on it.
        message: String,
    },
    /// The OBJ file holds no vertices and no faces.
    #[error("the OBJ file is empty: it has no vertices (v) and no faces (f)")]
    EmptyObj,
    /// The OBJ file has vertices but no faces (e.g. a point cloud).
    #[error("the OBJ file has no faces (f): an organ is a surface of triangles")]
    NoFaces,
    /// The OBJ file has more vertices, UVs or triangles than an organ mesh
    /// may have; reading stops at that line.
    #[error("OBJ line {line}: more than {limit} {what}, the most an organ mesh may have")]
    TooManyElements {
        /// The OBJ line where the limit was passed (from 1).
        line: usize,
        /// "vertices", "texture coordinates" or "triangles".
        what: &'static str,
        /// The most of them a mesh may have.
        limit: usize,
    },
    /// The OBJ file has no `vt` statements, so no UV layout to paint on.
    #[error("OBJ has no texture coordinates (vt): an organ needs a UV layout")]
    MissingUvs,
    /// A face corner has no texture coordinate while the file has some.
    #[error("OBJ line {line}: face corner has no texture coordinate")]
    MissingUvOnFace {
        /// The OBJ line of the face (from 1).
        line: usize,
    },
    /// One vertex is used with two different UVs (a UV seam); Anthesis
    /// needs one UV per vertex.
    #[error("vertex {vertex} has two different UVs (a UV seam); an organ needs one UV per vertex")]
    UvSeam {
        /// The vertex's index.
        vertex: usize,
    },
    /// Another mesh error found in an OBJ file, with the OBJ's numbering.
    #[error("{}{error}", line_prefix(*line))]
    InObj {
        /// The OBJ line of the statement at fault, when one line is.
        line: Option<usize>,
        /// The error with the OBJ's numbers (from 1).
        error: Box<MeshError>,
    },
    /// Subdividing this often would make more vertices than a render mesh
    /// may have.
    #[error(
        "subdividing {level} times would make {vertices} vertices, more than the limit of {limit}: \
         choose a lower level"
    )]
    SubdivisionTooLarge {
        /// The subdivision level asked for.
        level: u32,
        /// How many vertices it would make.
        vertices: u64,
        /// The most vertices a subdivided mesh may have.
        limit: u64,
    },
    /// The mesh file could not be read; the message names the file and why.
    #[error("cannot read mesh: {0}")]
    Io(String),
    /// An OBJ has no object (`o` statement) of the name asked for, or has
    /// several objects and none was named.
    #[error("{0}")]
    Object(String),
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

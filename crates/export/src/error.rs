use thiserror::Error;

/// Everything that can go wrong while exporting. File errors
/// ([`anthesis_files::WriteError`]) name the path and say what went wrong in
/// words a user can act on; input errors name the track and the offending
/// keyframe, vertex or triangle (0-based).
#[derive(Debug, Error)]
pub enum ExportError {
    /// The file could not be written; the error names it and says why.
    #[error(transparent)]
    Write(#[from] anthesis_files::WriteError),
    #[error("cannot encode the glTF JSON: {0}")]
    Json(#[from] serde_json::Error),
    #[error("nothing to export: there are no tracks")]
    NoTracks,
    #[error("track {track} ({name:?}): {problem}")]
    InvalidTrack {
        track: usize,
        name: String,
        problem: TrackProblem,
    },
    #[error(
        "track {track} ({name:?}) has {found} keyframes but the animated tracks before it have {expected}: all animated tracks need the same keyframes"
    )]
    KeyframeCountMismatch {
        track: usize,
        name: String,
        expected: usize,
        found: usize,
    },
    #[error("invalid export option: {0}")]
    InvalidOptions(String),
    #[error("the .glb would be {bytes} bytes, more than the 4 GiB the format allows")]
    TooLarge { bytes: u64 },
    #[error("cannot build the USD layer: {0}")]
    Usd(String),
}

/// What is wrong with one track's data.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TrackProblem {
    #[error("it has no keyframes")]
    NoKeyframes,
    #[error("it has no vertices")]
    NoVertices,
    #[error("it has no triangles")]
    NoTriangles,
    #[error("it has {found} UVs for {expected} vertices: every vertex needs one UV")]
    UvCount { expected: usize, found: usize },
    #[error("keyframe {keyframe} has {found} vertices but keyframe 0 has {expected}")]
    KeyframeVertexCount {
        keyframe: usize,
        expected: usize,
        found: usize,
    },
    #[error("triangle {triangle} refers to vertex {index}, but there are only {vertex_count}")]
    IndexOutOfRange {
        triangle: usize,
        index: u32,
        vertex_count: usize,
    },
    #[error(
        "vertex {vertex} at keyframe {keyframe} has a non-finite or huge coordinate (NaN, infinite or beyond f32)"
    )]
    NonFinitePosition { keyframe: usize, vertex: usize },
    #[error("the UV of vertex {vertex} is not finite")]
    NonFiniteUv { vertex: usize },
    #[error("its base colour {color:?} is not four numbers in [0, 1]")]
    BaseColor { color: [f32; 4] },
    #[error("its base-colour texture is not a PNG file")]
    TextureNotPng,
}

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
    /// The glTF JSON could not be encoded.
    #[error("cannot encode the glTF JSON: {0}")]
    Json(#[from] serde_json::Error),
    #[error("nothing to export: there are no tracks")]
    /// No tracks were given.
    NoTracks,
    #[error("track {track} ({name:?}): {problem}")]
    /// One track's data is wrong.
    InvalidTrack {
        /// Its index among the tracks given.
        track: usize,
        /// Its name.
        name: String,
        /// What is wrong.
        problem: TrackProblem,
    },
    #[error(
        "track {track} ({name:?}) has {found} keyframes but the animated tracks before it have {expected}: all animated tracks need the same keyframes"
    )]
    /// Animated tracks have different keyframe counts.
    KeyframeCountMismatch {
        /// The first track that differs.
        track: usize,
        /// Its name.
        name: String,
        /// The count of the animated tracks before it.
        expected: usize,
        /// Its count.
        found: usize,
    },
    #[error("invalid export option: {0}")]
    /// An option is out of range.
    InvalidOptions(String),
    #[error("the .glb would be {bytes} bytes, more than the 4 GiB the format allows")]
    /// The file would exceed the .glb format's 4 GiB.
    TooLarge {
        /// The size it would have.
        bytes: u64,
    },
    #[error(
        "render subdivision level {level} would make {vertices} render vertices per keyframe, \
         {positions} positions over {keyframes} keyframes, more than the {limit} an export may \
         hold{}",
        finest_hint(*finest)
    )]
    /// The render subdivision level asks for more vertices than an export
    /// may hold (see [`crate::MAX_RENDER_POSITIONS`]).
    TooFine {
        /// The level asked for.
        level: u32,
        /// Render vertices per keyframe over every subdivided organ.
        vertices: u64,
        /// `vertices` times the keyframes.
        positions: u64,
        /// The keyframes (the bud included).
        keyframes: usize,
        /// [`crate::MAX_RENDER_POSITIONS`].
        limit: u64,
        /// The finest level that fits, if any above 0 does.
        finest: Option<u32>,
    },
    #[error("cannot subdivide organ {organ:?}: {error}")]
    /// An organ's mesh cannot be subdivided.
    Subdivision {
        /// The organ's name.
        organ: String,
        /// What is wrong with its mesh.
        error: anthesis_mesh::MeshError,
    },
    #[error("cannot build the USD layer: {0}")]
    /// The USD layer could not be built.
    Usd(String),
    #[error("cannot encode the colour map of template {template:?} as a PNG: {message}")]
    /// A template's baked colour map could not be encoded.
    Texture {
        /// The template's name.
        template: String,
        /// The encoder's message.
        message: String,
    },
}

fn finest_hint(finest: Option<u32>) -> String {
    match finest {
        Some(level) => format!("; level {level} is the finest that fits"),
        None => "; export without subdivision (level 0)".to_string(),
    }
}

/// What is wrong with one track's data.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TrackProblem {
    #[error("it has no keyframes")]
    /// The track has no keyframes.
    NoKeyframes,
    #[error("it has no vertices")]
    /// The mesh has no vertices.
    NoVertices,
    #[error("it has no triangles")]
    /// The mesh has no triangles.
    NoTriangles,
    #[error("it has {found} UVs for {expected} vertices: every vertex needs one UV")]
    /// Not one UV per vertex.
    UvCount {
        /// The vertex count.
        expected: usize,
        /// The UV count.
        found: usize,
    },
    #[error("keyframe {keyframe} has {found} vertices but keyframe 0 has {expected}")]
    /// A keyframe has another vertex count than keyframe 0.
    KeyframeVertexCount {
        /// The keyframe.
        keyframe: usize,
        /// Keyframe 0's vertex count.
        expected: usize,
        /// Its vertex count.
        found: usize,
    },
    #[error("triangle {triangle} refers to vertex {index}, but there are only {vertex_count}")]
    /// A triangle names a vertex that does not exist.
    IndexOutOfRange {
        /// The triangle.
        triangle: usize,
        /// The vertex index it names.
        index: u32,
        /// How many vertices there are.
        vertex_count: usize,
    },
    #[error(
        "vertex {vertex} at keyframe {keyframe} has a non-finite or huge coordinate (NaN, infinite or beyond f32)"
    )]
    /// A position is NaN, infinite or beyond `f32`.
    NonFinitePosition {
        /// The keyframe.
        keyframe: usize,
        /// The vertex.
        vertex: usize,
    },
    #[error("the UV of vertex {vertex} is not finite")]
    /// A UV is NaN or infinite.
    NonFiniteUv {
        /// The vertex.
        vertex: usize,
    },
    #[error("its base colour {colour:?} is not four numbers in [0, 1]")]
    /// The base colour is outside `[0, 1]`.
    BaseColour {
        /// The colour given.
        colour: [f32; 4],
    },
    #[error(
        "its rigid motion does not match its keyframes ({local} local positions for {vertices} \
         vertices, {poses} poses for {keyframes} keyframes, or a pose that is not finite)"
    )]
    /// A rigid track's local mesh or poses do not fit its keyframes.
    RigidMotion {
        /// Positions in the track's own frame.
        local: usize,
        /// Vertices of the keyframes.
        vertices: usize,
        /// Poses given.
        poses: usize,
        /// Keyframes given.
        keyframes: usize,
    },
    #[error("its base-colour texture is not a PNG file")]
    /// The base-colour texture is not a PNG.
    TextureNotPng,
    #[error("its base-colour texture cannot be read: {message}")]
    /// The base-colour texture starts like a PNG but does not decode (USD
    /// samples it for the vertex colours).
    TextureUnreadable {
        /// The decoder's message.
        message: String,
    },
}

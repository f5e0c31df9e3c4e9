use std::path::{Path, PathBuf};

/// Everything that can go wrong when building, loading, saving or keying maps.
///
/// Errors from [`crate::ScalarMap::from_png_bytes`] and friends do not know a
/// file name; the `load_png` functions wrap them in [`MapError::InFile`], and
/// a loader that reads bytes itself can do the same with [`MapError::in_file`].
/// [`MapError::root`] looks through that wrapper.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MapError {
    #[error("not a PNG image: the data is {found}; maps must be saved as PNG")]
    NotPng {
        /// What the data looks like instead, e.g. "a JPEG image" or "text".
        found: &'static str,
    },
    #[error("corrupt or truncated PNG: {message}")]
    Decode { message: String },
    #[error("could not encode the map as PNG: {message}")]
    Encode { message: String },
    #[error(
        "map is {}x{} pixels but {}x{} pixels were expected",
        found.0, found.1, expected.0, expected.1
    )]
    WrongSize {
        expected: (u32, u32),
        found: (u32, u32),
    },
    #[error("unsupported PNG pixel format {found}: {expected}")]
    UnsupportedFormat {
        /// The format found, e.g. "grey 8-bit" or "RGB 16-bit".
        found: String,
        /// What this kind of map needs, in words.
        expected: &'static str,
    },
    #[error(
        "scalar maps must be greyscale, but this {format} PNG has a coloured pixel at \
         column {x}, row {y} (counted from the top) with R, G, B = {}, {}, {}; \
         save the map as greyscale",
        rgb[0], rgb[1], rgb[2]
    )]
    NotGrey {
        format: String,
        x: u32,
        y: u32,
        rgb: [u16; 3],
    },
    #[error(
        "the map is {width}x{height} pixels, more than the limit of {limit}x{limit}; scale it \
         down in a paint program (a map is sampled once per triangle, so detail beyond that \
         is lost anyway)",
        limit = crate::png_io::MAX_MAP_SIDE
    )]
    TooManyPixels { width: u32, height: u32 },
    #[error("map file {}: {message}", path.display())]
    Io { path: PathBuf, message: String },
    #[error("{}: {error}", path.display())]
    InFile { path: PathBuf, error: Box<MapError> },
    #[error("a map needs at least one pixel, but the size given is {width}x{height}")]
    EmptyRaster { width: u32, height: u32 },
    #[error("a {width}x{height} map needs {expected} values, but {found} were given")]
    ValueCountMismatch {
        width: u32,
        height: u32,
        expected: usize,
        found: usize,
    },
    #[error("a keyed map set needs at least one key")]
    NoKeys,
    #[error("two map keys are at step {step}; each key needs its own step")]
    DuplicateStep { step: u32 },
    #[error("there is no map key {index}; there are {count} keys")]
    NoSuchKey { index: usize, count: usize },
    #[error("cannot remove the only map key; a keyed map set needs at least one key")]
    LastKey,
}

impl MapError {
    /// Attaches the file this error came from (once: an error that already
    /// names a file is returned unchanged).
    pub fn in_file(self, path: impl AsRef<Path>) -> MapError {
        match self {
            MapError::InFile { .. } | MapError::Io { .. } => self,
            other => MapError::InFile {
                path: path.as_ref().to_path_buf(),
                error: Box::new(other),
            },
        }
    }

    /// The error itself, without the [`MapError::InFile`] wrapper.
    pub fn root(&self) -> &MapError {
        match self {
            MapError::InFile { error, .. } => error.root(),
            other => other,
        }
    }
}

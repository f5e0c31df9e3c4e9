use std::path::{Path, PathBuf};

/// Everything that can go wrong when building, loading, saving or keying maps.
///
/// Errors from [`crate::ScalarMap::from_png_bytes`] and friends do not know a
/// file name; the `load_png` functions wrap them in [`MapError::InFile`], and
/// a loader that reads bytes itself can do the same with [`MapError::in_file`].
/// [`MapError::root`] looks through that wrapper.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MapError {
    /// The bytes are not a PNG image (another image format, text, ...).
    #[error("not a PNG image: the data is {found}; maps must be saved as PNG")]
    NotPng {
        /// What the data looks like instead, e.g. "a JPEG image" or "text".
        found: &'static str,
    },
    /// The data starts like a PNG but cannot be decoded.
    #[error("corrupt or truncated PNG: {message}")]
    Decode {
        /// The PNG decoder's message.
        message: String,
    },
    /// Saving: the map's pixels could not be written as a PNG.
    #[error("could not encode the map as PNG: {message}")]
    Encode {
        /// The PNG encoder's message.
        message: String,
    },
    /// The image's size differs from the size the map must have (e.g. the
    /// other maps of its template).
    #[error(
        "map is {}x{} pixels but {}x{} pixels were expected",
        found.0, found.1, expected.0, expected.1
    )]
    WrongSize {
        /// Width and height in pixels that were expected.
        expected: (u32, u32),
        /// Width and height in pixels of the image.
        found: (u32, u32),
    },
    /// The PNG's pixel format cannot hold this kind of map (e.g. a 1-bit or
    /// 32-bit float image, or greyscale where a direction map needs RGB).
    #[error("unsupported PNG pixel format {found}: {expected}")]
    UnsupportedFormat {
        /// The format found, e.g. "grey 8-bit" or "RGB 16-bit".
        found: String,
        /// What this kind of map needs, in words.
        expected: &'static str,
    },
    /// A scalar map saved as RGB(A) has a pixel whose red,
    /// green and blue differ, so its value is ambiguous.
    #[error(
        "scalar maps must be greyscale, but this {format} PNG has a coloured pixel at \
         column {x}, row {y} (counted from the top) with R, G, B = {}, {}, {}; \
         save the map as greyscale",
        rgb[0], rgb[1], rgb[2]
    )]
    NotGrey {
        /// The PNG's pixel format in words, e.g. "RGB 8-bit".
        format: String,
        /// Column of the first coloured pixel, from the left (0-based).
        x: u32,
        /// Row of the first coloured pixel, from the top (0-based).
        y: u32,
        /// That pixel's red, green and blue as stored (0–255 or 0–65535).
        rgb: [u16; 3],
    },
    /// The image is wider or taller than [`MAX_MAP_SIDE`](crate::MAX_MAP_SIDE)
    /// pixels; it is refused before its pixels are decoded.
    #[error(
        "the map is {width}x{height} pixels, more than the limit of {limit}x{limit}; scale it \
         down in a paint program (a map is sampled once per triangle, so detail beyond that \
         is lost anyway)",
        limit = crate::png_io::MAX_MAP_SIDE
    )]
    TooManyPixels {
        /// The image's width in pixels.
        width: u32,
        /// The image's height in pixels.
        height: u32,
    },
    /// A map file could not be read or written.
    #[error("map file {}: {message}", path.display())]
    Io {
        /// The map file.
        path: PathBuf,
        /// Why, from the operating system or the file checks.
        message: String,
    },
    /// Another map error, with the file it came from (see
    /// [`MapError::in_file`] and [`MapError::root`]).
    #[error("{}: {error}", path.display())]
    InFile {
        /// The map file.
        path: PathBuf,
        /// What is wrong with it.
        error: Box<MapError>,
    },
    /// A map was asked for with a width or height of zero.
    #[error("a map needs at least one pixel, but the size given is {width}x{height}")]
    EmptyRaster {
        /// The requested width in pixels.
        width: u32,
        /// The requested height in pixels.
        height: u32,
    },
    /// A map was built from a list of values whose length is not
    /// width × height.
    #[error("a {width}x{height} map needs {expected} values, but {found} were given")]
    ValueCountMismatch {
        /// The map's width in pixels.
        width: u32,
        /// The map's height in pixels.
        height: u32,
        /// width × height.
        expected: usize,
        /// The number of values given.
        found: usize,
    },
    /// A keyed map set (maps at key steps) was built with no key.
    #[error("a keyed map set needs at least one key")]
    NoKeys,
    /// Two keys of one keyed map set are at the same step.
    #[error("two map keys are at step {step}; each key needs its own step")]
    DuplicateStep {
        /// The step both keys are at.
        step: u32,
    },
    /// A key was addressed by an index past the last key.
    #[error("there is no map key {index}; there are {count} keys")]
    NoSuchKey {
        /// The index asked for (0-based).
        index: usize,
        /// How many keys there are.
        count: usize,
    },
    /// Removing the only key was asked for; a keyed map set keeps at least
    /// one.
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

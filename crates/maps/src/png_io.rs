//! PNG decoding into integer codes and encoding from them, shared by the
//! scalar and direction maps. Pixel rows are in image order (top row first),
//! which is also the storage order of the rasters.

use std::io::Cursor;

use image::codecs::png::{PngDecoder, PngEncoder};
use image::{ColorType, ExtendedColorType, ImageDecoder, ImageEncoder, Limits};

use crate::MapError;

const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n'];

/// The largest PNG file read, in bytes (a 4096x4096 16-bit RGBA map that
/// does not compress at all is 128 MiB).
pub const MAX_PNG_BYTES: u64 = 256 << 20;

/// The widest and tallest map read, in pixels. A map is sampled at the
/// organ's triangles (a lily petal has 685), so 4096 is far past what
/// sampling can tell apart; a 16k x 16k map took 8 GB to load.
pub const MAX_MAP_SIDE: u32 = 4096;

/// The most the PNG decoder may allocate: the pixels of the largest map,
/// 16-bit RGBA, and room for its chunks.
const MAX_DECODE_ALLOCATION: u64 = 2 * (MAX_MAP_SIDE as u64).pow(2) * 8;

/// Bits per channel of a written PNG.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum BitDepth {
    /// 256 levels per channel; what most paint programs write.
    #[default]
    Eight,
    /// 65536 levels per channel; lossless for slowly varying maps.
    Sixteen,
}

impl BitDepth {
    /// The largest code of one channel: 255 or 65535.
    pub fn max_code(self) -> u16 {
        match self {
            BitDepth::Eight => u8::MAX as u16,
            BitDepth::Sixteen => u16::MAX,
        }
    }
}

/// A decoded PNG: every channel of every pixel as an integer code in
/// `0..=depth.max_code()`, rows from the top.
pub(crate) struct DecodedPng {
    pub width: u32,
    pub height: u32,
    /// 1 (grey), 2 (grey + alpha), 3 (RGB) or 4 (RGBA).
    pub channels: usize,
    pub depth: BitDepth,
    pub codes: Vec<u16>,
}

impl DecodedPng {
    /// The pixel format in words, e.g. "grey 8-bit" or "RGBA 16-bit".
    pub fn format_name(&self) -> String {
        let layout = match self.channels {
            1 => "grey",
            2 => "grey+alpha",
            3 => "RGB",
            _ => "RGBA",
        };
        let bits = match self.depth {
            BitDepth::Eight => 8,
            BitDepth::Sixteen => 16,
        };
        format!("{layout} {bits}-bit")
    }
}

pub(crate) fn decode(bytes: &[u8]) -> Result<DecodedPng, MapError> {
    if !bytes.is_empty() && bytes.len() < PNG_SIGNATURE.len() && PNG_SIGNATURE.starts_with(bytes) {
        return Err(MapError::Decode {
            message: format!(
                "the data ends after {} bytes of the PNG signature",
                bytes.len()
            ),
        });
    }
    if !bytes.starts_with(&PNG_SIGNATURE) {
        return Err(MapError::NotPng {
            found: describe_non_png(bytes),
        });
    }
    let decode_error = |error: image::ImageError| MapError::Decode {
        message: error.to_string(),
    };
    // The allocation limit also bounds what the decoder unpacks from
    // compressed text chunks before the pixels. The size is checked here,
    // with a message of our own, before any pixel is decoded.
    let mut limits = Limits::no_limits();
    limits.max_alloc = Some(MAX_DECODE_ALLOCATION);
    let decoder = PngDecoder::with_limits(Cursor::new(bytes), limits).map_err(decode_error)?;
    let (width, height) = decoder.dimensions();
    if width > MAX_MAP_SIDE || height > MAX_MAP_SIDE {
        return Err(MapError::TooManyPixels { width, height });
    }
    let colour_type = decoder.color_type();
    let (channels, depth) = match colour_type {
        ColorType::L8 => (1, BitDepth::Eight),
        ColorType::La8 => (2, BitDepth::Eight),
        ColorType::Rgb8 => (3, BitDepth::Eight),
        ColorType::Rgba8 => (4, BitDepth::Eight),
        ColorType::L16 => (1, BitDepth::Sixteen),
        ColorType::La16 => (2, BitDepth::Sixteen),
        ColorType::Rgb16 => (3, BitDepth::Sixteen),
        ColorType::Rgba16 => (4, BitDepth::Sixteen),
        other => {
            return Err(MapError::UnsupportedFormat {
                found: format!("{other:?}"),
                expected: "maps must be 8-bit or 16-bit PNGs",
            });
        }
    };
    let total_bytes = decoder.total_bytes();
    if width == 0 || height == 0 {
        return Err(MapError::EmptyRaster { width, height });
    }
    let mut raw = vec![0_u8; total_bytes as usize];
    decoder.read_image(&mut raw).map_err(decode_error)?;
    let codes = match depth {
        BitDepth::Eight => raw.iter().map(|&byte| u16::from(byte)).collect(),
        // The decoder hands out 16-bit samples in native byte order.
        BitDepth::Sixteen => raw
            .chunks_exact(2)
            .map(|pair| u16::from_ne_bytes([pair[0], pair[1]]))
            .collect(),
    };
    Ok(DecodedPng {
        width,
        height,
        channels,
        depth,
        codes,
    })
}

/// Encodes grey (`channels == 1`) or RGB (`channels == 3`) codes, rows from
/// the top.
pub(crate) fn encode(
    width: u32,
    height: u32,
    channels: usize,
    depth: BitDepth,
    codes: &[u16],
) -> Result<Vec<u8>, MapError> {
    let colour_type = match (channels, depth) {
        (1, BitDepth::Eight) => ExtendedColorType::L8,
        (1, BitDepth::Sixteen) => ExtendedColorType::L16,
        (3, BitDepth::Eight) => ExtendedColorType::Rgb8,
        (3, BitDepth::Sixteen) => ExtendedColorType::Rgb16,
        _ => {
            return Err(MapError::Encode {
                message: format!("no PNG layout for {channels} channels"),
            });
        }
    };
    let raw: Vec<u8> = match depth {
        // Codes never exceed the depth's maximum, so the narrowing is exact.
        BitDepth::Eight => codes.iter().map(|&code| code.min(255) as u8).collect(),
        // The encoder expects 16-bit samples in native byte order.
        BitDepth::Sixteen => codes.iter().flat_map(|code| code.to_ne_bytes()).collect(),
    };
    let mut png = Vec::new();
    PngEncoder::new(&mut png)
        .write_image(&raw, width, height, colour_type)
        .map_err(|error| MapError::Encode {
            message: error.to_string(),
        })?;
    Ok(png)
}

/// A guess at what non-PNG data is, for the error message.
fn describe_non_png(bytes: &[u8]) -> &'static str {
    if bytes.is_empty() {
        "empty"
    } else if bytes.starts_with(&[0xff, 0xd8, 0xff]) {
        "a JPEG image"
    } else if bytes.starts_with(b"GIF8") {
        "a GIF image"
    } else if bytes.starts_with(b"BM") {
        "a BMP image"
    } else if bytes.starts_with(b"II*\0") || bytes.starts_with(b"MM\0*") {
        "a TIFF image"
    } else if bytes.starts_with(b"RIFF") && bytes.get(8..12) == Some(b"WEBP".as_slice()) {
        "a WebP image"
    } else if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        "an OpenEXR image"
    } else if looks_like_text(bytes) {
        "text"
    } else {
        "of an unrecognised kind"
    }
}

fn looks_like_text(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(512)];
    let text = match std::str::from_utf8(head) {
        Ok(text) => text,
        // The cut at 512 bytes may split a character; the part before it counts.
        Err(error) if error.error_len().is_none() => {
            std::str::from_utf8(&head[..error.valid_up_to()]).unwrap_or_default()
        }
        Err(_) => return false,
    };
    text.chars().all(|c| !c.is_control() || c.is_whitespace())
}

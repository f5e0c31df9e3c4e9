//! Scalar and direction rasters with bilinear sampling, the per-triangle value
//! of paper eq. 1, and their PNG form.

use std::ops::{Add, Mul};
use std::path::Path;

use glam::DVec2;

use crate::MapError;
use crate::png_io::{self, BitDepth, DecodedPng};

/// Values of type `T` over the UV square, one per pixel: [`ScalarMap`]
/// holds `f32`s and [`DirectionMap`] `[u, v]` pairs.
///
/// Values are stored row by row in image order: the first row is the top of
/// the image (`v = 1`), the last row the bottom (`v = 0`); see the crate
/// documentation for the UV convention.
#[derive(Clone, Debug, PartialEq)]
pub struct Raster<T> {
    width: u32,
    height: u32,
    values: Vec<T>,
}

/// A raster of scalar values over the UV square.
pub type ScalarMap = Raster<f32>;

/// A raster of 2D growth directions in UV space, each channel in `[-1, 1]`.
///
/// Stored like [`ScalarMap`] (first row = top of the image = `v = 1`). The
/// vectors need not be unit length; normalising (and deciding what a zero
/// vector means) is left to the consumer.
pub type DirectionMap = Raster<[f32; 2]>;

impl<T> Raster<T> {
    /// A raster from values in image order (first row = top = `v = 1`).
    pub fn new(width: u32, height: u32, values: Vec<T>) -> Result<Self, MapError> {
        check_value_count(width, height, values.len())?;
        Ok(Self {
            width,
            height,
            values,
        })
    }

    /// A 1x1 raster: the same value everywhere.
    fn single(value: T) -> Self {
        Self {
            width: 1,
            height: 1,
            values: vec![value],
        }
    }

    /// A raster whose pixel values are `value_at(uv of the pixel centre)`.
    /// A zero width or height is taken as 1.
    fn at_pixel_centres(width: u32, height: u32, value_at: impl Fn(DVec2) -> T) -> Self {
        let (width, height) = (width.max(1), height.max(1));
        let values = pixel_centres_in_uv(width, height).map(value_at).collect();
        Self {
            width,
            height,
            values,
        }
    }

    /// Width in pixels (across `u`).
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels (along `v`).
    pub fn height(&self) -> u32 {
        self.height
    }

    /// `(width, height)` in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// All values in image order (first row = top = `v = 1`).
    pub fn values(&self) -> &[T] {
        &self.values
    }

    /// All values in image order (first row = top = `v = 1`), to change
    /// in place; the size stays.
    pub fn values_mut(&mut self) -> &mut [T] {
        &mut self.values
    }

    /// The UV position of the centre of pixel `(x, y)`, `y` counted from the
    /// top row.
    pub fn pixel_centre_in_uv(&self, x: u32, y: u32) -> DVec2 {
        pixel_centre_in_uv(self.width, self.height, x, y)
    }

    /// `Ok` when the raster is `expected` = `(width, height)` pixels.
    pub fn check_size(&self, expected: (u32, u32)) -> Result<(), MapError> {
        check_size(self.size(), expected)
    }
}

impl ScalarMap {
    /// A 1x1 raster: the same value everywhere.
    pub fn constant(value: f32) -> Self {
        Self::single(value)
    }

    /// A raster whose pixel values are `value_at(uv of the pixel centre)`.
    /// A zero width or height is taken as 1.
    pub fn from_fn(width: u32, height: u32, value_at: impl Fn(DVec2) -> f32) -> Self {
        Self::at_pixel_centres(width, height, value_at)
    }

    /// Bilinear interpolation between pixel centres; points beyond the outer
    /// pixel centres (including outside the UV square) take the edge values.
    pub fn sample(&self, point_in_uv: DVec2) -> f64 {
        Footprint::new(self.width, self.height, point_in_uv)
            .interpolate(|index| f64::from(self.values[index]))
    }

    /// The map value of a triangle with corners at these UVs (paper eq. 1):
    /// `(m(uv0) + m(uv1) + m(uv2) + 3 m(centroid)) / 6`.
    pub fn triangle_value(&self, corners_in_uv: [DVec2; 3]) -> f64 {
        triangle_rule(corners_in_uv, |point_in_uv| self.sample(point_in_uv))
    }

    /// Reads a greyscale PNG, 8-bit (value = code / 255) or 16-bit
    /// (value = code / 65535); an alpha channel is ignored.
    ///
    /// RGB and RGBA PNGs are accepted only when every pixel is neutral grey
    /// (R = G = B), because many paint programs save grey paintings in colour
    /// formats; a PNG with a coloured pixel is refused with
    /// [`MapError::NotGrey`], naming the pixel.
    pub fn from_png_bytes(bytes: &[u8]) -> Result<Self, MapError> {
        let png = png_io::decode(bytes)?;
        let max = f32::from(png.depth.max_code());
        let mut values = Vec::with_capacity(png.codes.len() / png.channels);
        for (index, pixel) in png.codes.chunks_exact(png.channels).enumerate() {
            if png.channels >= 3 && (pixel[0] != pixel[1] || pixel[0] != pixel[2]) {
                return Err(not_grey(&png, index, pixel));
            }
            values.push(f32::from(pixel[0]) / max);
        }
        Self::new(png.width, png.height, values)
    }

    /// [`ScalarMap::from_png_bytes`] on a file; errors name the file.
    pub fn load_png(path: &Path) -> Result<Self, MapError> {
        let bytes = read_file(path)?;
        Self::from_png_bytes(&bytes).map_err(|error| error.in_file(path))
    }

    /// A greyscale PNG of this map. Values are clamped to `[0, 1]` and
    /// rounded to the nearest code of the bit depth.
    pub fn to_png_bytes(&self, depth: BitDepth) -> Result<Vec<u8>, MapError> {
        let max = f32::from(depth.max_code());
        let codes: Vec<u16> = self
            .values
            .iter()
            .map(|&value| (value.clamp(0.0, 1.0) * max).round() as u16)
            .collect();
        png_io::encode(self.width, self.height, 1, depth, &codes)
    }

    /// Writes [`ScalarMap::to_png_bytes`] to a file (not atomically).
    pub fn save_png(&self, path: &Path, depth: BitDepth) -> Result<(), MapError> {
        let bytes = self.to_png_bytes(depth)?;
        write_file(path, &bytes)
    }
}

impl DirectionMap {
    /// A 1x1 raster: the same direction everywhere.
    pub fn constant(direction_in_uv: DVec2) -> Self {
        Self::single(to_pair(direction_in_uv))
    }

    /// A raster whose pixel values are `direction_at(uv of the pixel centre)`.
    /// A zero width or height is taken as 1.
    pub fn from_fn(width: u32, height: u32, direction_at: impl Fn(DVec2) -> DVec2) -> Self {
        Self::at_pixel_centres(width, height, |point_in_uv| {
            to_pair(direction_at(point_in_uv))
        })
    }

    /// Bilinear interpolation of the signed components (not normalised), with
    /// edge values beyond the outer pixel centres.
    pub fn sample(&self, point_in_uv: DVec2) -> DVec2 {
        Footprint::new(self.width, self.height, point_in_uv).interpolate(|index| {
            let [u, v] = self.values[index];
            DVec2::new(f64::from(u), f64::from(v))
        })
    }

    /// Paper eq. 1 on each component (not normalised).
    pub fn triangle_value(&self, corners_in_uv: [DVec2; 3]) -> DVec2 {
        triangle_rule(corners_in_uv, |point_in_uv| self.sample(point_in_uv))
    }

    /// Reads an RGB or RGBA PNG, 8 or 16 bit: red is the `u` component, green
    /// the `v` component, blue and alpha are ignored. A channel code `c` maps
    /// to `(c - mid) / (max - mid)` clamped to `[-1, 1]`, with `mid` = 128
    /// (8-bit) or 32768 (16-bit) and `max` = 255 or 65535: the mid grey that
    /// paint programs call 50 % is exactly zero and `max` is exactly 1.
    pub fn from_png_bytes(bytes: &[u8]) -> Result<Self, MapError> {
        let png = png_io::decode(bytes)?;
        if png.channels < 3 {
            return Err(MapError::UnsupportedFormat {
                found: png.format_name(),
                expected: "direction maps must be RGB or RGBA, with the u component in red \
                           and the v component in green",
            });
        }
        let values = png
            .codes
            .chunks_exact(png.channels)
            .map(|pixel| {
                [
                    signed_from_code(pixel[0], png.depth),
                    signed_from_code(pixel[1], png.depth),
                ]
            })
            .collect();
        Self::new(png.width, png.height, values)
    }

    /// [`DirectionMap::from_png_bytes`] on a file; errors name the file.
    pub fn load_png(path: &Path) -> Result<Self, MapError> {
        let bytes = read_file(path)?;
        Self::from_png_bytes(&bytes).map_err(|error| error.in_file(path))
    }

    /// An RGB PNG of this map: red = `u`, green = `v`, blue = zero (mid
    /// grey), each component clamped to `[-1, 1]` and coded as in
    /// [`DirectionMap::from_png_bytes`].
    pub fn to_png_bytes(&self, depth: BitDepth) -> Result<Vec<u8>, MapError> {
        let codes: Vec<u16> = self
            .values
            .iter()
            .flat_map(|&[u, v]| {
                [
                    code_from_signed(u, depth),
                    code_from_signed(v, depth),
                    code_from_signed(0.0, depth),
                ]
            })
            .collect();
        png_io::encode(self.width, self.height, 3, depth, &codes)
    }

    /// Writes [`DirectionMap::to_png_bytes`] to a file (not atomically).
    pub fn save_png(&self, path: &Path, depth: BitDepth) -> Result<(), MapError> {
        let bytes = self.to_png_bytes(depth)?;
        write_file(path, &bytes)
    }
}

/// The code that stands for zero in a signed channel: 128 or 32768.
fn mid_code(depth: BitDepth) -> f32 {
    f32::from(depth.max_code() / 2 + 1)
}

fn signed_from_code(code: u16, depth: BitDepth) -> f32 {
    let mid = mid_code(depth);
    ((f32::from(code) - mid) / (f32::from(depth.max_code()) - mid)).clamp(-1.0, 1.0)
}

fn code_from_signed(value: f32, depth: BitDepth) -> u16 {
    let mid = mid_code(depth);
    let code = mid + value.clamp(-1.0, 1.0) * (f32::from(depth.max_code()) - mid);
    code.round() as u16
}

fn to_pair(direction: DVec2) -> [f32; 2] {
    [direction.x as f32, direction.y as f32]
}

/// The four pixels around a UV point and the fractions between them.
struct Footprint {
    /// Indices of the pixels at (x0, y0), (x1, y0), (x0, y1), (x1, y1).
    indices: [usize; 4],
    fraction_x: f64,
    fraction_y: f64,
}

impl Footprint {
    /// `width` and `height` are at least 1 (every raster has a pixel).
    fn new(width: u32, height: u32, point_in_uv: DVec2) -> Self {
        // Continuous pixel coordinates in which pixel (x, y) has its centre at
        // (x, y); y counts rows from the top, so it runs against v.
        let last_x = f64::from(width - 1);
        let last_y = f64::from(height - 1);
        let x = (point_in_uv.x * f64::from(width) - 0.5).clamp(0.0, last_x);
        let y = ((1.0 - point_in_uv.y) * f64::from(height) - 0.5).clamp(0.0, last_y);
        let (x0, y0) = (x.floor(), y.floor());
        // A NaN coordinate becomes pixel 0 here and a NaN fraction below.
        let (column0, row0) = (x0 as usize, y0 as usize);
        let column1 = (column0 + 1).min(width as usize - 1);
        let row1 = (row0 + 1).min(height as usize - 1);
        let row_start0 = row0 * width as usize;
        let row_start1 = row1 * width as usize;
        Self {
            indices: [
                row_start0 + column0,
                row_start0 + column1,
                row_start1 + column0,
                row_start1 + column1,
            ],
            fraction_x: x - x0,
            fraction_y: y - y0,
        }
    }

    fn interpolate<T>(&self, value_at: impl Fn(usize) -> T) -> T
    where
        T: Copy + Add<Output = T> + Mul<f64, Output = T>,
    {
        let [i00, i10, i01, i11] = self.indices;
        let (fx, fy) = (self.fraction_x, self.fraction_y);
        let row0 = value_at(i00) * (1.0 - fx) + value_at(i10) * fx;
        let row1 = value_at(i01) * (1.0 - fx) + value_at(i11) * fx;
        row0 * (1.0 - fy) + row1 * fy
    }
}

/// Paper eq. 1: corners weigh 1 each, the UV centroid 3, over 6.
fn triangle_rule<T>(corners_in_uv: [DVec2; 3], sample: impl Fn(DVec2) -> T) -> T
where
    T: Add<Output = T> + Mul<f64, Output = T>,
{
    let [a, b, c] = corners_in_uv;
    let centroid_in_uv = (a + b + c) / 3.0;
    (sample(a) + sample(b) + sample(c) + sample(centroid_in_uv) * 3.0) * (1.0 / 6.0)
}

fn pixel_centre_in_uv(width: u32, height: u32, x: u32, y: u32) -> DVec2 {
    DVec2::new(
        (f64::from(x) + 0.5) / f64::from(width),
        1.0 - (f64::from(y) + 0.5) / f64::from(height),
    )
}

/// Pixel centres in storage order (rows from the top).
fn pixel_centres_in_uv(width: u32, height: u32) -> impl Iterator<Item = DVec2> {
    (0..height).flat_map(move |y| (0..width).map(move |x| pixel_centre_in_uv(width, height, x, y)))
}

fn check_value_count(width: u32, height: u32, found: usize) -> Result<(), MapError> {
    if width == 0 || height == 0 {
        return Err(MapError::EmptyRaster { width, height });
    }
    let expected = usize::try_from(u64::from(width) * u64::from(height)).unwrap_or(usize::MAX);
    if found != expected {
        return Err(MapError::ValueCountMismatch {
            width,
            height,
            expected,
            found,
        });
    }
    Ok(())
}

fn check_size(found: (u32, u32), expected: (u32, u32)) -> Result<(), MapError> {
    if found == expected {
        Ok(())
    } else {
        Err(MapError::WrongSize { expected, found })
    }
}

fn not_grey(png: &DecodedPng, pixel_index: usize, pixel: &[u16]) -> MapError {
    let width = png.width as usize;
    MapError::NotGrey {
        format: png.format_name(),
        x: (pixel_index % width) as u32,
        y: (pixel_index / width) as u32,
        rgb: [pixel[0], pixel[1], pixel[2]],
    }
}

/// The bytes of the map file at `path`: a regular file of at most
/// [`png_io::MAX_PNG_BYTES`].
fn read_file(path: &Path) -> Result<Vec<u8>, MapError> {
    anthesis_files::read_regular(path, png_io::MAX_PNG_BYTES, "a PNG map").map_err(|error| {
        MapError::Io {
            path: path.to_path_buf(),
            message: error.to_string(),
        }
    })
}

fn write_file(path: &Path, bytes: &[u8]) -> Result<(), MapError> {
    std::fs::write(path, bytes).map_err(|error| MapError::Io {
        path: path.to_path_buf(),
        message: format!("cannot write: {error}"),
    })
}

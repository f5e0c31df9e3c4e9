//! Growth maps: rasters painted on an organ's UV layout that drive regional
//! growth (Ijiri et al. 2008, §4).
//!
//! There are seven maps per organ template: six scalar maps ([`MapKind`]:
//! e-growth, w-growth, e-growth-in, w-growth-in, stretch, bend) and the
//! growth direction ([`DirectionMap`]), collected in [`GrowthMaps`]. Several
//! map sets can be keyed in time ([`KeyedMaps`]) and blended between keys
//! ([`Blend`]).
//!
//! # Conventions
//!
//! - **UV and image rows.** UV `(0, 0)` is the bottom-left corner of the
//!   image and `(1, 1)` the top-right: `u` runs along a row from the left
//!   column to the right, `v` runs from the *bottom* row (`v = 0`, the organ's
//!   base) to the *top* row (`v = 1`, its tip). Rasters store their values in
//!   image order, first row = top of the image, so the PNG rows map straight
//!   onto storage. Pixel `(x, y)` (`y` counted from the top) has its centre at
//!   `u = (x + ½) / width`, `v = 1 − (y + ½) / height`.
//! - **Sampling** is bilinear between pixel centres. Beyond the outermost
//!   pixel centres, including outside the UV square, the edge values hold
//!   (clamp to edge). A 1x1 raster is a constant.
//! - **Triangle value** (paper eq. 1): `(m(uv0) + m(uv1) + m(uv2) + 3 m(uvc)) / 6`
//!   with `uvc` the UV centroid of the triangle.
//! - **Scalar PNGs** are greyscale, 8-bit (value = code / 255) or 16-bit
//!   (value = code / 65535); an alpha channel is ignored. RGB(A) PNGs are
//!   accepted when every pixel is neutral grey (R = G = B), since paint
//!   programs often save grey paintings as colour; a coloured pixel is an
//!   error. Values are clamped to `[0, 1]` on saving.
//! - **Direction PNGs** are RGB or RGBA, 8 or 16 bit: red holds `u`, green
//!   `v`, blue and alpha are ignored (blue is written as zero). A channel is
//!   signed with mid grey as zero: code `c` means `(c − mid) / (max − mid)`,
//!   `mid` = 128 or 32768, `max` = 255 or 65535, clamped to `[−1, 1]`. So
//!   value ≈ 2·(c / max) − 1, but with the 50 % grey of paint programs (128)
//!   exactly zero, and zero survives a save and load exactly.

#![warn(missing_docs)]

pub mod brush;
mod error;
mod growth;
mod keys;
mod png_io;
mod raster;

pub use error::MapError;
pub use growth::{DIRECTION_MAP_NAME, GrowthMaps, MapKind};
pub use keys::{Blend, KeySchedule, KeyedMaps, MapKey, common_raster_size};
pub use png_io::{BitDepth, MAX_MAP_SIDE, MAX_PNG_BYTES};
pub use raster::{DirectionMap, Raster, ScalarMap};

#[cfg(test)]
mod tests;

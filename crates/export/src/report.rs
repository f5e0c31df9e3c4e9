//! File sizes of the .glb in every storage mode, for documentation and for
//! choosing a mode.

use std::fmt;

use crate::{Encoding, ExportError, GlbOptions, Track, glb_bytes};

/// Size of one .glb variant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GlbSize {
    /// How the animation is stored.
    pub encoding: Encoding,
    /// Whether normals are stored.
    pub normals: bool,
    /// The file's size.
    pub bytes: usize,
}

/// Sizes of the same export in every [`Encoding`], with and without
/// normals. `Display` prints a Markdown table.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GlbSizeReport {
    /// Tracks exported.
    pub tracks: usize,
    /// Vertices over all tracks.
    pub vertices: usize,
    /// Keyframes of the run.
    pub keyframes: usize,
    /// Morph targets per mesh after resampling.
    pub morph_targets: usize,
    /// One entry per variant.
    pub sizes: Vec<GlbSize>,
}

impl GlbSizeReport {
    /// The size of one variant.
    pub fn bytes(&self, encoding: Encoding, normals: bool) -> Option<usize> {
        self.sizes
            .iter()
            .find(|s| s.encoding == encoding && s.normals == normals)
            .map(|s| s.bytes)
    }
}

/// Exports `tracks` with `options` in each encoding, with and without
/// normals, and reports the file sizes.
pub fn glb_size_report(
    tracks: &[Track],
    options: &GlbOptions,
) -> Result<GlbSizeReport, ExportError> {
    let mut sizes = Vec::new();
    for encoding in Encoding::ALL {
        for normals in [true, false] {
            let variant = GlbOptions {
                encoding,
                normals,
                ..*options
            };
            let bytes = glb_bytes(tracks, &variant, &mut |_| {})?.len();
            sizes.push(GlbSize {
                encoding,
                normals,
                bytes,
            });
        }
    }
    let keyframes = tracks.iter().map(|t| t.keyframes.len()).max().unwrap_or(0);
    Ok(GlbSizeReport {
        tracks: tracks.len(),
        vertices: tracks
            .iter()
            .map(|t| t.keyframes.first().map_or(0, Vec::len))
            .sum(),
        keyframes,
        morph_targets: keyframes.saturating_sub(1).min(options.max_morph_targets),
        sizes,
    })
}

impl fmt::Display for GlbSizeReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{} meshes, {} vertices, {} keyframes, {} morph targets per animated mesh",
            self.tracks, self.vertices, self.keyframes, self.morph_targets
        )?;
        writeln!(f)?;
        writeln!(f, "| encoding | normals | size |")?;
        writeln!(f, "|---|---|---:|")?;
        for size in &self.sizes {
            writeln!(
                f,
                "| {} | {} | {:.2} MB ({} bytes) |",
                size.encoding,
                if size.normals { "yes" } else { "no" },
                size.bytes as f64 / 1e6,
                size.bytes
            )?;
        }
        Ok(())
    }
}

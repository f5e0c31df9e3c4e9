//! Stage 1 of the remeshing: the vertices, in rows of constant `v` and
//! along the two margins.

use glam::{DVec2, DVec3};

use super::{
    Layout, NEAR_BOUNDARY, Pin, SAMPLES_ACROSS, SAMPLES_ALONG_V, SurfaceKind, Work, ZERO_WIDTH,
    cumulative_length, invert_length, point,
};
use crate::{BudError, RemeshOptions, Surface};

impl Work<'_> {
    /// Step 1: places the vertices. Returns the rows (each in increasing
    /// `u`): the full base row (or, for a template mesh, a single base
    /// vertex where the base has no width) first, then the interior points of each inner
    /// row (rows without any are left out), then the full top row or the
    /// single tip vertex; and the two margins (`u = 0` and `u = 1`, each from
    /// its base corner to its top corner or the tip).
    ///
    /// The phases: the surface measured and checked ([`Lengths::measure`]),
    /// candidate points per row ([`row_candidates`]), points along the
    /// margins ([`margin_points`]), inner-row points too near those left
    /// out ([`drop_near_boundary`]), then the vertices made.
    pub(super) fn lay_out(
        &mut self,
        options: &RemeshOptions,
        kind: SurfaceKind,
    ) -> Result<Layout, BudError> {
        let h = options.target_edge;
        let surface = self.surface;
        let lengths = Lengths::measure(surface, options, kind)?;
        let mut rows = row_candidates(surface, &lengths, h, kind)?;
        let margin_points = margin_points(surface, &lengths.line_lengths, h)?;
        drop_near_boundary(surface, &mut rows, &margin_points, h)?;

        // Create the vertices.
        let mut row_indices = Vec::with_capacity(rows.len());
        for row in &rows {
            let mut indices = Vec::with_capacity(row.len());
            for &(uv, pin) in row {
                indices.push(self.add_vertex(uv, pin)?);
            }
            row_indices.push(indices);
        }
        let rows = row_indices;
        let base = &rows[0];
        let top = &rows[rows.len() - 1];
        let mut margins = [Vec::new(), Vec::new()];
        for (side, margin) in margins.iter_mut().enumerate() {
            margin.push(if side == 0 {
                base[0]
            } else {
                base[base.len() - 1]
            });
            for &(uv, _) in &margin_points[side] {
                margin.push(self.add_vertex(uv, Pin::SlideV)?);
            }
            margin.push(if side == 0 {
                top[0]
            } else {
                top[top.len() - 1]
            });
        }
        Ok(Layout { rows, margins })
    }
}

/// The lines of constant `u` the length along `v` is the mean of.
const LINES: [f64; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];

/// A candidate vertex: where, and how it may move.
type Candidate = (DVec2, Pin);

/// The surface's lengths along `v`, and the number of row gaps.
struct Lengths {
    /// The cumulative length along each of [`LINES`].
    line_lengths: Vec<Vec<f64>>,
    /// Their mean, per sample along `v`.
    along_v: Vec<f64>,
    /// The mean length from base to tip.
    length: f64,
    /// Rows from base to tip, less one.
    gaps: usize,
}

impl Lengths {
    /// The surface measured: the length along `v` (the mean of five lines
    /// of constant `u`), widths and area on a coarse grid; an error for a
    /// surface without length or width (a pointed tip, and a pointed base
    /// where allowed, are fine), too few rows or too many vertices.
    fn measure(
        surface: &dyn Surface,
        options: &RemeshOptions,
        kind: SurfaceKind,
    ) -> Result<Lengths, BudError> {
        let h = options.target_edge;
        // Length along v: the mean of five lines of constant u.
        let lines = LINES;
        let line_lengths = lines
            .iter()
            .map(|&u| cumulative_length(SAMPLES_ALONG_V, |v| point(surface, DVec2::new(u, v))))
            .collect::<Result<Vec<_>, _>>()?;
        let along_v: Vec<f64> = (0..=SAMPLES_ALONG_V)
            .map(|k| line_lengths.iter().map(|c| c[k]).sum::<f64>() / lines.len() as f64)
            .collect();
        let length = along_v[SAMPLES_ALONG_V];
        // Widths and area on a coarse grid: zero-width check and size estimate.
        let widths: Vec<f64> = (0..=SAMPLES_ALONG_V)
            .map(|k| {
                let v = k as f64 / SAMPLES_ALONG_V as f64;
                row_width(surface, v, SAMPLES_ACROSS).map(|c| c[SAMPLES_ACROSS])
            })
            .collect::<Result<_, _>>()?;
        let widest = widths.iter().copied().fold(0.0, f64::max);
        let area: f64 = (1..=SAMPLES_ALONG_V)
            .map(|k| 0.5 * (widths[k] + widths[k - 1]) * (along_v[k] - along_v[k - 1]))
            .sum();
        let size = length.max(widest);
        if length <= ZERO_WIDTH * size {
            return Err(BudError::ZeroLength);
        }
        // Everything but the last sample (the tip), and the first (the
        // base) where a pointed base is allowed, must have a width.
        let first = match kind {
            SurfaceKind::Bud => 0,
            SurfaceKind::TemplateMesh => 1,
        };
        if let Some(k) = widths[first..SAMPLES_ALONG_V]
            .iter()
            .position(|&w| w <= ZERO_WIDTH * size)
        {
            return Err(BudError::ZeroWidth {
                v: (k + first) as f64 / SAMPLES_ALONG_V as f64,
            });
        }
        let spacing = h * 3f64.sqrt() / 2.0;
        let gaps = (length / spacing).round() as usize;
        if gaps < 2 {
            return Err(BudError::TooFewRows {
                target_edge: h,
                length,
                rows: gaps + 1,
            });
        }
        // An equilateral lattice has one vertex per sqrt(3)/2 h^2 of area.
        let estimated =
            ((area / (spacing * h)).round() as usize).saturating_add(gaps.saturating_mul(2));
        if estimated > options.max_vertices {
            return Err(BudError::TooManyVertices {
                target_edge: h,
                area,
                estimated,
                limit: options.max_vertices,
            });
        }
        Ok(Lengths {
            line_lengths,
            along_v,
            length,
            gaps,
        })
    }
}

/// The cumulative length across the row at `v`, in `n` samples.
fn row_width(surface: &dyn Surface, v: f64, n: usize) -> Result<Vec<f64>, BudError> {
    cumulative_length(n, |u| point(surface, DVec2::new(u, v)))
}

/// Candidate points per row, as (uv, pin), at rows evenly spaced along
/// the length.
fn row_candidates(
    surface: &dyn Surface,
    lengths: &Lengths,
    h: f64,
    kind: SurfaceKind,
) -> Result<Vec<Vec<Candidate>>, BudError> {
    let Lengths {
        along_v,
        length,
        gaps,
        ..
    } = lengths;
    let (length, gaps) = (*length, *gaps);
    let mut rows: Vec<Vec<Candidate>> = Vec::with_capacity(gaps + 1);
    for j in 0..=gaps {
        let (v, boundary) = match j {
            0 => (0.0, true),
            _ if j == gaps => (1.0, true),
            _ => (
                invert_length(along_v, j as f64 * length / gaps as f64),
                false,
            ),
        };
        let coarse = row_width(surface, v, SAMPLES_ACROSS)?;
        if j == gaps && coarse[SAMPLES_ACROSS] < 0.5 * h {
            // A pointed (or nearly pointed) tip: one vertex.
            rows.push(vec![(DVec2::new(0.5, 1.0), Pin::Fixed)]);
            continue;
        }
        if j == 0 && kind == SurfaceKind::TemplateMesh && coarse[SAMPLES_ACROSS] < 0.5 * h {
            // A pointed base, where allowed: one vertex, as the tip.
            rows.push(vec![(DVec2::new(0.5, 0.0), Pin::Fixed)]);
            continue;
        }
        rows.push(row_points(surface, v, j, boundary, coarse, h)?);
    }
    Ok(rows)
}

/// The candidate points of row `j` at `v` (`coarse` its cumulative width
/// at [`SAMPLES_ACROSS`] samples), spaced evenly by arc length.
fn row_points(
    surface: &dyn Surface,
    v: f64,
    j: usize,
    boundary: bool,
    coarse: Vec<f64>,
    h: f64,
) -> Result<Vec<Candidate>, BudError> {
    let segments = ((coarse[SAMPLES_ACROSS] / h).round() as usize).max(1);
    let samples = SAMPLES_ACROSS.max(8 * segments + 16);
    let cumulative = if samples == SAMPLES_ACROSS {
        coarse
    } else {
        row_width(surface, v, samples)?
    };
    let width = cumulative[samples];
    // Arc-length fractions: boundary rows from corner to corner,
    // inner rows without their ends (the margins have their own
    // vertices), odd inner rows staggered by half a segment.
    let fractions: Vec<f64> = if boundary {
        (0..=segments).map(|k| k as f64 / segments as f64).collect()
    } else if j % 2 == 1 {
        (0..segments)
            .map(|k| (k as f64 + 0.5) / segments as f64)
            .collect()
    } else {
        (1..segments).map(|k| k as f64 / segments as f64).collect()
    };
    Ok(fractions
        .iter()
        .enumerate()
        .map(|(k, f)| {
            let corner = boundary && (k == 0 || k == segments);
            let u = match (corner, k) {
                (true, 0) => 0.0,
                (true, _) => 1.0,
                _ => invert_length(&cumulative, f * width),
            };
            let pin = match (boundary, corner) {
                (true, true) => Pin::Fixed,
                (true, false) => Pin::SlideU,
                _ => Pin::Free,
            };
            (DVec2::new(u, v), pin)
        })
        .collect())
}

/// Margins: points spaced evenly in 3D along u = 0 and u = 1, between
/// the corners (or the tip) of the boundary rows, with their positions.
fn margin_points(
    surface: &dyn Surface,
    line_lengths: &[Vec<f64>],
    h: f64,
) -> Result<[Vec<(DVec2, DVec3)>; 2], BudError> {
    let mut margin_points = [Vec::new(), Vec::new()];
    for (side, points) in margin_points.iter_mut().enumerate() {
        let cumulative = &line_lengths[if side == 0 { 0 } else { LINES.len() - 1 }];
        let total = cumulative[SAMPLES_ALONG_V];
        let segments = ((total / h).round() as usize).max(2);
        for k in 1..segments {
            let v = invert_length(cumulative, k as f64 * total / segments as f64);
            let uv = DVec2::new(side as f64, v);
            points.push((uv, point(surface, uv)?));
        }
    }
    Ok(margin_points)
}

/// Inner-row points too close to a margin point, the tip or a pointed
/// base are left out (only the two outermost points of a row on each
/// side can be); rows left empty go.
fn drop_near_boundary(
    surface: &dyn Surface,
    rows: &mut Vec<Vec<Candidate>>,
    margin_points: &[Vec<(DVec2, DVec3)>; 2],
    h: f64,
) -> Result<(), BudError> {
    let tip = point(surface, DVec2::new(0.5, 1.0))?;
    let pointed_base = match rows[0].as_slice() {
        [(uv, _)] => Some(point(surface, *uv)?),
        _ => None,
    };
    let too_close = |p: DVec3| {
        margin_points
            .iter()
            .flatten()
            .map(|(_, m)| m)
            .chain(std::iter::once(&tip))
            .chain(pointed_base.as_ref())
            .any(|m| m.distance(p) < NEAR_BOUNDARY * h)
    };
    let last = rows.len() - 1;
    for row in &mut rows[1..last] {
        let n = row.len();
        let mut keep = Vec::with_capacity(n);
        for (k, &(uv, pin)) in row.iter().enumerate() {
            let outer = k < 2 || k + 2 >= n;
            if !(outer && too_close(point(surface, uv)?)) {
                keep.push((uv, pin));
            }
        }
        *row = keep;
    }
    rows.retain(|r| !r.is_empty());
    Ok(())
}

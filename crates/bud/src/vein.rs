//! A petal's primary vein drawn as one stroke in a side view, and a
//! template bent so its midrib follows it (the floral blossom paper
//! §3.2: "the user first draws a curved stroke indicating the outline of a
//! flower bud ... the initial form of the primary vein of one petal";
//! copies of the curve around the axis then carry the bud's petals).
//!
//! The side view looks at the flower across its axis: a stroke point is
//! `(r, h)`, its distance from the axis and its height. An organ placed at
//! azimuth 0 (ARCHITECTURE.md: base at `(0, h, r)`, inner side towards the
//! axis) has the template frame's `y` along the height and `z` along `r`,
//! so the vein is kept in the template frame as `(y, z) = (h - h0, r - r0)`
//! from the stroke's base `(r0, h0)`.
//!
//! Bending: each template vertex is written in the frame of its midrib
//! point (the point of the UV line `u = mid` at the vertex's `v`): along the
//! midrib, towards the inner side, across. The frame is carried to the
//! vein's point at the same fraction of the length, and the petal is scaled
//! so its midrib is as long as the vein. Across stays the template's `x`
//! (the vein lies in the `y`–`z` plane), so a flat petal is bent without
//! stretching (a developable bend), and a cupped one keeps its cup.

use anthesis_mesh::Mesh;
use glam::{DVec2, DVec3};
use thiserror::Error;

use crate::{BudError, MeshSurface};

/// Points a stroke is resampled to.
const STROKE_SAMPLES: usize = 64;
/// Smoothing passes over the resampled stroke (a `[1, 2, 1] / 4` filter
/// with the ends held).
const SMOOTHING_PASSES: usize = 4;
/// Samples along the template's midrib.
const MIDRIB_SAMPLES: usize = 96;
/// Smoothing passes across the template's midrib.
const MIDRIB_SMOOTHING_PASSES: usize = 16;
/// Samples either side over which the midrib's tangent is taken.
const TANGENT_REACH: usize = 8;

/// Why a stroke cannot be a petal's vein.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum VeinError {
    /// Fewer than two distinct points, or no length.
    #[error("the vein stroke is too short: {length:.3} long, at least {minimum:.3} is needed")]
    TooShort {
        /// The stroke's length.
        length: f64,
        /// The shortest accepted.
        minimum: f64,
    },
    /// A point is NaN or infinite.
    #[error("the vein stroke has a point that is not a number")]
    NotFinite,
    /// The stroke crosses itself.
    #[error(
        "the vein stroke crosses itself (near r = {r:.2}, height {h:.2}); draw it as one curve from the base to the tip"
    )]
    SelfIntersecting {
        /// Distance from the axis where it crosses.
        r: f64,
        /// Height where it crosses.
        h: f64,
    },
    /// The stroke goes from one side of the axis to the other.
    #[error(
        "the vein stroke crosses the flower's axis (at height {h:.2}); draw it on one side of the axis"
    )]
    CrossesAxis {
        /// Height where it crosses.
        h: f64,
    },
}

/// A petal's primary vein in the template frame's `y`–`z` plane, from the
/// base (the origin) to the tip, at even arc-length steps.
#[derive(Debug, Clone, PartialEq)]
pub struct Vein {
    /// `(y, z)` points, the first `(0, 0)`.
    points: Vec<DVec2>,
}

/// A side-view stroke read as a vein: where its base sits and the vein.
#[derive(Debug, Clone, PartialEq)]
pub struct SideStroke {
    /// The base: distance from the axis and height.
    pub base: DVec2,
    /// The vein from that base.
    pub vein: Vein,
}

impl Vein {
    /// A vein through `points` (`(y, z)` in the template frame, from the
    /// base): moved so it starts at the origin, resampled evenly and
    /// smoothed. Refuses a stroke shorter than `minimum_length`, one that
    /// crosses itself, and NaN.
    pub fn new(points: &[DVec2], minimum_length: f64) -> Result<Vein, VeinError> {
        if points.iter().any(|p| !p.is_finite()) {
            return Err(VeinError::NotFinite);
        }
        let length = polyline_length(points);
        if points.len() < 2 || length < minimum_length || length <= 0.0 {
            return Err(VeinError::TooShort {
                length,
                minimum: minimum_length,
            });
        }
        let mut resampled = resample(points, STROKE_SAMPLES);
        for _ in 0..SMOOTHING_PASSES {
            let previous = resampled.clone();
            for i in 1..previous.len() - 1 {
                resampled[i] = 0.25 * (previous[i - 1] + 2.0 * previous[i] + previous[i + 1]);
            }
        }
        let resampled = resample(&resampled, STROKE_SAMPLES);
        if let Some(at) = self_crossing(&resampled) {
            // Report in the side view's (r, h): z is r, y is h.
            return Err(VeinError::SelfIntersecting { r: at.y, h: at.x });
        }
        let origin = resampled[0];
        Ok(Vein {
            points: resampled.into_iter().map(|p| p - origin).collect(),
        })
    }

    /// A vein through exactly these points (`(y, z)`, base first; moved
    /// so it starts at the origin), as [`Vein::points`] gave them: for
    /// reading one back from a file. Refuses fewer than two points, no
    /// length, NaN and a self-crossing.
    pub fn from_points(points: &[DVec2]) -> Result<Vein, VeinError> {
        if points.iter().any(|p| !p.is_finite()) {
            return Err(VeinError::NotFinite);
        }
        let length = polyline_length(points);
        if points.len() < 2 || length <= 0.0 {
            return Err(VeinError::TooShort {
                length,
                minimum: 0.0,
            });
        }
        if let Some(at) = self_crossing(points) {
            return Err(VeinError::SelfIntersecting { r: at.y, h: at.x });
        }
        let origin = points[0];
        Ok(Vein {
            points: points.iter().map(|p| *p - origin).collect(),
        })
    }

    /// The points `(y, z)`, base first.
    pub fn points(&self) -> &[DVec2] {
        &self.points
    }

    /// Its length.
    pub fn length(&self) -> f64 {
        polyline_length(&self.points)
    }

    /// The point and unit tangent at arc length `s` (clamped to the vein),
    /// in the template frame (`x = 0`).
    fn at(&self, s: f64) -> (DVec3, DVec3) {
        let (i, f) = locate(&self.points, s);
        let a = self.points[i];
        let b = self.points[(i + 1).min(self.points.len() - 1)];
        let p = a.lerp(b, f);
        let d = (b - a).normalize_or_zero();
        (DVec3::new(0.0, p.x, p.y), DVec3::new(0.0, d.x, d.y))
    }
}

impl SideStroke {
    /// A stroke drawn in the side view, `(r, h)` points in any direction:
    /// the base is its lower end (the one nearer the axis when both are at
    /// the same height). A stroke drawn left of the axis (`r < 0`
    /// throughout) is mirrored to the right; one that crosses the axis is
    /// refused, as are those [`Vein::new`] refuses.
    pub fn new(points: &[DVec2], minimum_length: f64) -> Result<SideStroke, VeinError> {
        if points.iter().any(|p| !p.is_finite()) {
            return Err(VeinError::NotFinite);
        }
        let mut points = points.to_vec();
        if points.iter().all(|p| p.x <= 0.0) {
            points.iter_mut().for_each(|p| p.x = -p.x);
        }
        if let Some(h) = axis_crossing(&points) {
            return Err(VeinError::CrossesAxis { h });
        }
        if let (Some(first), Some(last)) = (points.first(), points.last())
            && (last.y, last.x) < (first.y, first.x)
        {
            points.reverse();
        }
        let base = points.first().copied().unwrap_or(DVec2::ZERO);
        let in_template: Vec<DVec2> = points
            .iter()
            .map(|p| DVec2::new(p.y - base.y, p.x - base.x))
            .collect();
        let vein = Vein::new(&in_template, minimum_length)?;
        Ok(SideStroke { base, vein })
    }

    /// The vein's points in the side view, `(r, h)`.
    pub fn side_points(&self) -> Vec<DVec2> {
        self.vein
            .points
            .iter()
            .map(|p| self.base + DVec2::new(p.y, p.x))
            .collect()
    }
}

/// `mesh` (a template: UVs by the convention, `v` from base to tip) bent so
/// its midrib follows `vein` and scaled so the midrib is as long as the
/// vein (see the module documentation). The UVs and triangles are kept, so
/// painted maps stay valid.
pub fn bend_along_vein(mesh: &Mesh, vein: &Vein) -> Result<Mesh, BudError> {
    let surface = MeshSurface::new(mesh)?;
    let (v_min, v_max) = mesh
        .uvs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), uv| {
            (lo.min(uv.y), hi.max(uv.y))
        });
    // The midrib: the line u = 0.5, with its arc length
    // and frame (along, inner, across).
    let midrib: Vec<DVec3> = (0..=MIDRIB_SAMPLES)
        .map(|k| {
            // u = 0.5 where the row reaches it (the convention's midrib),
            // else the row's middle.
            let row = surface.uv_at(DVec2::new(0.0, k as f64 / MIDRIB_SAMPLES as f64));
            let end = surface.uv_at(DVec2::new(1.0, k as f64 / MIDRIB_SAMPLES as f64));
            let u = if (row.x..=end.x).contains(&0.5) {
                0.5
            } else {
                0.5 * (row.x + end.x)
            };
            surface.point_at_uv(DVec2::new(u, row.y))
        })
        .collect();
    // The mesh's midrib zig-zags across its triangles by a little; it is
    // smoothed across (not along, which would move it along the petal).
    let mut midrib = midrib;
    for _ in 0..MIDRIB_SMOOTHING_PASSES {
        let previous = midrib.clone();
        for k in 1..MIDRIB_SAMPLES {
            let chord = (previous[k + 1] - previous[k - 1]).normalize_or_zero();
            let shift = 0.25 * (previous[k - 1] + previous[k + 1]) - 0.5 * previous[k];
            midrib[k] = previous[k] + shift - shift.dot(chord) * chord;
        }
    }
    let mut arc = vec![0.0; midrib.len()];
    for k in 1..midrib.len() {
        arc[k] = arc[k - 1] + midrib[k].distance(midrib[k - 1]);
    }
    let midrib_length = arc[MIDRIB_SAMPLES];
    if midrib_length.is_nan() || midrib_length <= 0.0 {
        return Err(BudError::ZeroLength);
    }
    let frames: Vec<[DVec3; 3]> = (0..midrib.len())
        .map(|k| {
            // Over a few samples: the mesh's midrib zig-zags across its
            // triangles.
            let (a, b) = (
                midrib[k.saturating_sub(TANGENT_REACH)],
                midrib[(k + TANGENT_REACH).min(MIDRIB_SAMPLES)],
            );
            frame((b - a).normalize_or(DVec3::Y))
        })
        .collect();
    let scale = vein.length() / midrib_length;
    let positions = mesh
        .positions
        .iter()
        .zip(&mesh.uvs)
        .map(|(p, uv)| {
            let t = if v_max > v_min {
                ((uv.y - v_min) / (v_max - v_min)).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let x = t * MIDRIB_SAMPLES as f64;
            let k = (x.floor() as usize).min(MIDRIB_SAMPLES - 1);
            let f = x - k as f64;
            let on_midrib = midrib[k].lerp(midrib[k + 1], f);
            let s = arc[k] + f * (arc[k + 1] - arc[k]);
            let [along, inner, across] = frame(frames[k][0].lerp(frames[k + 1][0], f));
            let d = *p - on_midrib;
            let (da, di, dx) = (d.dot(along), d.dot(inner), d.dot(across));
            let (point, tangent) = vein.at(s * scale);
            let [v_along, v_inner, v_across] = frame(tangent.normalize_or(DVec3::Y));
            point + scale * (da * v_along + di * v_inner + dx * v_across)
        })
        .collect();
    Ok(Mesh {
        positions,
        ..mesh.clone()
    })
}

/// The frame at a midrib point with unit tangent `along`: across is the
/// template's `x` made perpendicular to it, inner is `along × across`
/// (`−z` for a midrib along `+y`).
fn frame(along: DVec3) -> [DVec3; 3] {
    let along = along.normalize_or(DVec3::Y);
    let across = (DVec3::X - DVec3::X.dot(along) * along).normalize_or(DVec3::X);
    [along, along.cross(across), across]
}

fn polyline_length(points: &[DVec2]) -> f64 {
    points.windows(2).map(|w| w[0].distance(w[1])).sum()
}

/// The segment holding arc length `s` and the fraction along it.
fn locate(points: &[DVec2], s: f64) -> (usize, f64) {
    let mut walked = 0.0;
    for i in 0..points.len().saturating_sub(1) {
        let step = points[i].distance(points[i + 1]);
        if walked + step >= s && step > 0.0 {
            return (i, ((s - walked) / step).clamp(0.0, 1.0));
        }
        walked += step;
    }
    (points.len().saturating_sub(2), 1.0)
}

/// `count` points evenly spaced along the polyline, its ends included.
fn resample(points: &[DVec2], count: usize) -> Vec<DVec2> {
    let length = polyline_length(points);
    (0..count)
        .map(|k| {
            let (i, f) = locate(points, length * k as f64 / (count - 1) as f64);
            points[i].lerp(points[(i + 1).min(points.len() - 1)], f)
        })
        .collect()
}

/// Where two non-adjacent segments of the polyline cross, if they do.
fn self_crossing(points: &[DVec2]) -> Option<DVec2> {
    let n = points.len();
    for i in 0..n.saturating_sub(1) {
        for j in i + 2..n - 1 {
            if let Some(at) = segments_cross(points[i], points[i + 1], points[j], points[j + 1]) {
                return Some(at);
            }
        }
    }
    None
}

fn segments_cross(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> Option<DVec2> {
    let r = b - a;
    let s = d - c;
    let denominator = r.perp_dot(s);
    if denominator == 0.0 {
        return None;
    }
    let t = (c - a).perp_dot(s) / denominator;
    let u = (c - a).perp_dot(r) / denominator;
    ((0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u)).then(|| a + t * r)
}

/// The height where the stroke passes from one side of the axis (`r`) to
/// the other, if it does (touching it is not passing).
fn axis_crossing(points: &[DVec2]) -> Option<f64> {
    let mut last_off_axis: Option<DVec2> = None;
    for &b in points.iter().filter(|p| p.x != 0.0) {
        if let Some(a) = last_off_axis
            && (a.x < 0.0) != (b.x < 0.0)
        {
            return Some(a.y + (b.y - a.y) * (a.x / (a.x - b.x)));
        }
        last_off_axis = Some(b);
    }
    None
}

#[cfg(test)]
mod tests;

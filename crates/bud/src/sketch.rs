//! The sketched petal (the floral blossom paper §3.1): three
//! strokes on the base plane (the two margins and the primary vein) give a
//! flat bicubic B-spline surface whose control points are spread evenly
//! across and along the petal; a cross-section stroke drawn over a row of
//! control points bends that row onto it, and every column of control
//! points is re-interpolated through the bent rows with a cubic B-spline.
//!
//! **Strokes.** They are drawn in the sketch plane (the base plane, the
//! template frame's x, y: +Y up on the canvas), in any order and any
//! direction. Each is resampled evenly by arc length and smoothed (its ends
//! stay). The vein is the one between the other two; all three are
//! oriented from the base to the tip. The base is the lower end when the
//! petal is drawn upright (within 45° of the canvas's vertical, as the
//! template frame has it: base down, growing up); a petal drawn lying down
//! has its base at the end where the strokes come closer together (where
//! strokes meet is no rule for an upright petal: a pointed tip is where
//! they meet best). The petal is then put in the template frame: the
//! middle of its base at the origin and its midrib's chord (base to tip)
//! along +Y.
//!
//! **The flat surface.** [`SKETCH_ROWS`] rows of [`SKETCH_COLUMNS`] control
//! points. Row `j` runs straight from the left margin to the right one at
//! the arc-length fraction `j / (rows - 1)` of each; its middle point is
//! where the vein crosses that line, and its points are spaced evenly from
//! the left margin to the middle and from the middle to the right margin
//! (the vein is the middle column, so the midrib is at `u = 0.5` by the UV
//! convention; the left margin at `u = 0` is on the −X side). Where the
//! vein does not cross a row (drawn a little short of the margins' ends or
//! past them) the vein's point at that fraction is put on the row: a
//! vein's ends make no notch in the base or the tip. A petal attaches by a
//! base, not a point:
//! when the margins start closer together than a tenth of the petal's
//! widest row, the base row is widened to that about the vein's start.
//!
//! **Cross-sections.** A cross-section picks the row of control points
//! nearest to its first point. Its points are put in the plane through
//! that row's ends perpendicular to the base plane: the position across is
//! the point's position along the row's chord, and its distance from the
//! chord on the canvas (towards the tip positive) becomes the height, as if
//! the stroke were drawn on a sheet folded up along the row. Heights are
//! taken relative to the straight line between the stroke's heights at the
//! two margins and to the height at the vein, so a straight stroke is flat,
//! a tilted one too, and the vein stays in the base plane (bending the
//! vein is the sketched bud's business). The stroke is approximated by a
//! cubic B-spline curve, and each control point of the row is moved to the
//! curve above it along Z, with the sign chosen so that a stroke that sags
//! towards the base in its middle ("U") raises the margins towards the inner
//! side, −Z: a cupped petal. The row's points keep their order across and
//! their place seen from above (the outline drawn stays the outline).
//! Then every column is re-interpolated along `v`: a cubic B-spline with
//! natural ends (two edge conditions) through the column's points at the
//! fixed rows (the base row, the tip row and every bent row, at their
//! Greville `v`) gives the heights of the other rows.

use std::fmt;

use glam::{DVec2, DVec3};
use thiserror::Error;

use crate::bspline::{BSplineCurve, BSplineSurface, clamped_uniform_knots, greville};

/// Control points across a sketched petal (the middle one on the vein).
pub const SKETCH_COLUMNS: usize = 7;
/// Rows of control points from the base to the tip.
pub const SKETCH_ROWS: usize = 8;
/// Points every stroke is resampled to.
const RESAMPLED: usize = 64;
/// Smoothing passes (each point moves halfway to its neighbours' mean).
const SMOOTHING_PASSES: usize = 4;
/// An outline stroke shorter than this fraction of the longest is refused.
const MIN_OUTLINE_FRACTION: f64 = 0.25;
/// Where strokes may meet or cross: the first and last tenth of each.
const END_ZONE: f64 = 0.1;
/// A cross-section must reach within this fraction of the row's width of
/// both margins.
const SPAN_SLACK: f64 = 0.1;
/// A cross-section may go back across by this fraction of the row's width
/// (a hand's tremor) before it counts as turning back.
const TURN_BACK_SLACK: f64 = 0.02;
/// The base row is at least this fraction of the widest row wide.
const MIN_BASE_WIDTH: f64 = 0.1;
/// Control points of the B-spline curve a cross-section is approximated by.
const SECTION_CONTROL_POINTS: usize = 8;

/// Which stroke of a sketch (errors name it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StrokeRole {
    /// The margin on the −X side (`u = 0`).
    LeftOutline,
    /// The margin on the +X side (`u = 1`).
    RightOutline,
    /// The primary vein (the midrib, `u = 0.5`).
    Vein,
    /// Cross-section stroke number `n` (from 0, in drawing order).
    CrossSection(usize),
}

impl fmt::Display for StrokeRole {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StrokeRole::LeftOutline => write!(f, "left outline stroke"),
            StrokeRole::RightOutline => write!(f, "right outline stroke"),
            StrokeRole::Vein => write!(f, "vein stroke"),
            StrokeRole::CrossSection(n) => write!(f, "cross-section stroke {}", n + 1),
        }
    }
}

/// What a new stroke is drawn as (the canvas's tool).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SketchTool {
    /// Decided from the stroke: the first three are the outline and the
    /// vein (sorted by where they lie); after that a stroke drawn more
    /// across the petal than along it is a cross-section, and one drawn
    /// along it replaces the outline stroke or vein nearest to it.
    #[default]
    Auto,
    /// Replaces the left outline stroke.
    LeftOutline,
    /// Replaces the right outline stroke.
    RightOutline,
    /// Replaces the vein.
    Vein,
    /// A cross-section; it replaces one on the same row.
    CrossSection,
}

/// A petal's strokes as drawn, in the sketch plane (an empty stroke has not
/// been drawn). The slots name the roles the strokes were last sorted into;
/// [`PetalSketch::build`] sorts them again by where they lie.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PetalSketch {
    /// The left margin.
    pub left: Vec<DVec2>,
    /// The right margin.
    pub right: Vec<DVec2>,
    /// The primary vein.
    pub vein: Vec<DVec2>,
    /// Cross-sections, in drawing order.
    pub sections: Vec<Vec<DVec2>>,
}

/// Why a sketch makes no petal; each names the stroke and says why.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SketchError {
    /// An outline stroke or the vein has not been drawn.
    #[error(
        "the {0} has not been drawn yet (a sketched petal needs two outline strokes and a vein)"
    )]
    Missing(StrokeRole),
    /// A stroke has a point that is not a finite number.
    #[error("the {0} has a point that is not a finite number")]
    NotFinite(StrokeRole),
    /// A stroke is too short to use.
    #[error(
        "the {stroke} is too short: {length:.3} long, at least {min:.3} is needed{why}",
        why = if *min > 0.0 { " (a quarter of the longest outline stroke)" } else { " (draw it with a drag, not a click)" }
    )]
    TooShort {
        /// Which stroke.
        stroke: StrokeRole,
        /// Its length after smoothing.
        length: f64,
        /// The shortest allowed (0 when it has no length at all).
        min: f64,
    },
    /// A stroke crosses itself.
    #[error(
        "the {stroke} crosses itself near ({x:.2}, {y:.2}); draw it without a loop",
        x = at.x,
        y = at.y
    )]
    SelfIntersecting {
        /// Which stroke.
        stroke: StrokeRole,
        /// Where, in the sketch plane.
        at: DVec2,
    },
    /// Two of the outline strokes and the vein cross away from the base and
    /// the tip.
    #[error(
        "the {first} and the {second} cross near ({x:.2}, {y:.2}): the outline strokes must \
         stay on either side of the vein and meet it only at the base and the tip",
        x = at.x,
        y = at.y
    )]
    Crossing {
        /// One stroke.
        first: StrokeRole,
        /// The other.
        second: StrokeRole,
        /// Where, in the sketch plane.
        at: DVec2,
    },
    /// A cross-section does not reach from one margin to the other.
    #[error(
        "the {stroke} does not span the petal: it covers {from:.0} % to {to:.0} % of the width \
         of row {row_number} (draw it from one margin to the other)",
        row_number = row + 1
    )]
    SectionDoesNotSpan {
        /// Which stroke.
        stroke: StrokeRole,
        /// The row it picked (from 0 at the base).
        row: usize,
        /// Where it starts across the row, in percent of its width.
        from: f64,
        /// Where it ends.
        to: f64,
    },
    /// A cross-section goes back across the petal.
    #[error(
        "the {stroke} turns back across the petal (over row {row_number}); a cross-section goes \
         once from one margin to the other",
        row_number = row + 1
    )]
    SectionTurnsBack {
        /// Which stroke.
        stroke: StrokeRole,
        /// The row it picked.
        row: usize,
    },
    /// A cross-section is nearest a row that has no width (a pointed tip).
    #[error(
        "the {stroke} starts nearest row {row_number}, the tip, which comes to a point and has \
         nothing to bend; draw it lower down",
        row_number = row + 1
    )]
    SectionAtPoint {
        /// Which stroke.
        stroke: StrokeRole,
        /// The row it picked.
        row: usize,
    },
}

/// The rigid map between the sketch plane and the template frame's base
/// plane: the middle of the petal's base goes to the origin, the midrib's
/// chord along +Y.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SketchFrame {
    /// The middle of the petal's base, in the sketch plane.
    pub origin: DVec2,
    /// The unit direction from the base's middle to the tip's, in the
    /// sketch plane.
    pub axis: DVec2,
}

impl SketchFrame {
    /// The template frame's `+X` in the sketch plane.
    fn right(&self) -> DVec2 {
        DVec2::new(self.axis.y, -self.axis.x)
    }

    /// A sketch-plane point in the template frame (its x, y).
    pub fn to_template(&self, p: DVec2) -> DVec2 {
        let d = p - self.origin;
        DVec2::new(d.dot(self.right()), d.dot(self.axis))
    }

    /// A template-frame point's x, y back in the sketch plane.
    pub fn to_sketch(&self, q: DVec2) -> DVec2 {
        self.origin + self.right() * q.x + self.axis * q.y
    }
}

/// A sketch made into a petal surface.
#[derive(Debug, Clone, PartialEq)]
pub struct SketchedPetal {
    /// The bicubic B-spline surface, in the template frame; its control
    /// grid is [`SKETCH_ROWS`] × [`SKETCH_COLUMNS`].
    pub surface: BSplineSurface,
    /// Where the template frame lies in the sketch plane.
    pub frame: SketchFrame,
    /// The strokes as used: resampled, smoothed, oriented base to tip, in
    /// the sketch plane: left margin, right margin, vein.
    pub outline: [Vec<DVec2>; 3],
    /// The row each cross-section bent (by index into
    /// [`PetalSketch::sections`]).
    pub section_rows: Vec<usize>,
}

impl SketchedPetal {
    /// The control points seen from above, in the sketch plane.
    pub fn control_in_sketch(&self) -> Vec<Vec<DVec2>> {
        self.surface
            .control
            .iter()
            .map(|row| {
                row.iter()
                    .map(|p| self.frame.to_sketch(p.truncate()))
                    .collect()
            })
            .collect()
    }
}

/// The strokes sorted, oriented and made into a flat control grid.
struct Outline {
    frame: SketchFrame,
    /// Left, right, vein, in the sketch plane.
    strokes: [Vec<DVec2>; 3],
    /// The flat grid, template frame (x, y).
    grid: Vec<Vec<DVec2>>,
    /// The longest outline stroke.
    longest: f64,
}

impl PetalSketch {
    /// A new petal's strokes (the app's "New sketched petal"): 20 long from
    /// the base at the origin along +Y, 2.4 wide at the base, widest (about
    /// 8) a little above the middle, pointed at the tip, a straight vein,
    /// and one cross-section over the middle that cups the margins about 1
    /// towards the inner side.
    pub fn petal() -> PetalSketch {
        let half_width = |t: f64| {
            1.2 * (1.0 - t) * (1.0 - t)
                + 4.2 * (std::f64::consts::PI * t.powf(0.85)).sin() * (1.0 - 0.3 * t)
        };
        let along = |f: &dyn Fn(f64) -> DVec2| -> Vec<DVec2> {
            (0..=24).map(|k| f(f64::from(k) / 24.0)).collect()
        };
        let reach = half_width(0.57) + 0.3;
        PetalSketch {
            left: along(&|t| DVec2::new(-half_width(t), 20.0 * t)),
            right: along(&|t| DVec2::new(half_width(t), 20.0 * t)),
            vein: along(&|t| DVec2::new(0.0, 20.0 * t)),
            sections: vec![along(&|t| {
                DVec2::new(-reach + 2.0 * reach * t, 11.4 - 4.8 * t * (1.0 - t))
            })],
        }
    }

    /// The strokes of `role` (an empty slice when not drawn or past the
    /// cross-sections).
    pub fn stroke(&self, role: StrokeRole) -> &[DVec2] {
        match role {
            StrokeRole::LeftOutline => &self.left,
            StrokeRole::RightOutline => &self.right,
            StrokeRole::Vein => &self.vein,
            StrokeRole::CrossSection(n) => self.sections.get(n).map_or(&[], Vec::as_slice),
        }
    }

    /// The sketch with `points` drawn with `tool` (see [`SketchTool`]):
    /// an outline stroke or the vein replaces the one of its role, a
    /// cross-section one on the same row. The outline slots are sorted
    /// again by where the strokes lie once all three are there.
    pub fn with_stroke(&self, tool: SketchTool, points: Vec<DVec2>) -> PetalSketch {
        let mut sketch = self.clone();
        match tool {
            SketchTool::LeftOutline => sketch.left = points,
            SketchTool::RightOutline => sketch.right = points,
            SketchTool::Vein => sketch.vein = points,
            SketchTool::CrossSection => sketch.add_section(points),
            SketchTool::Auto => {
                if sketch.left.is_empty() {
                    sketch.left = points;
                } else if sketch.right.is_empty() {
                    sketch.right = points;
                } else if sketch.vein.is_empty() {
                    sketch.vein = points;
                } else {
                    match sketch.outline() {
                        Ok(outline) if outline.is_across(&points) => sketch.add_section(points),
                        _ => {
                            let slot = sketch.nearest_outline_slot(&points);
                            *slot = points;
                        }
                    }
                }
            }
        }
        sketch.sorted()
    }

    /// The sketch with the outline slots holding the strokes in the roles
    /// their places give them (unchanged when the outline is incomplete or
    /// cannot be sorted).
    pub fn sorted(&self) -> PetalSketch {
        let Ok(order) = self.outline_order() else {
            return self.clone();
        };
        let raw = [self.left.clone(), self.right.clone(), self.vein.clone()];
        PetalSketch {
            left: raw[order[0]].clone(),
            right: raw[order[1]].clone(),
            vein: raw[order[2]].clone(),
            sections: self.sections.clone(),
        }
    }

    /// Adds a cross-section, dropping any earlier one on the same row.
    fn add_section(&mut self, points: Vec<DVec2>) {
        if let Ok(outline) = self.outline()
            && let Some(prepared) = prepare(&points)
        {
            let row = outline.nearest_row(outline.frame.to_template(prepared[0]));
            let keep: Vec<Vec<DVec2>> = std::mem::take(&mut self.sections)
                .into_iter()
                .filter(|s| {
                    prepare(s)
                        .is_none_or(|p| outline.nearest_row(outline.frame.to_template(p[0])) != row)
                })
                .collect();
            self.sections = keep;
        }
        self.sections.push(points);
    }

    /// The outline slot whose stroke is nearest to `points` (mean distance
    /// of their resampled points).
    fn nearest_outline_slot(&mut self, points: &[DVec2]) -> &mut Vec<DVec2> {
        let distance = |stroke: &[DVec2]| match (prepare(stroke), prepare(points)) {
            (Some(a), Some(b)) => {
                // Either direction: the closer.
                let along: f64 = a.iter().zip(&b).map(|(p, q)| p.distance(*q)).sum();
                let back: f64 = a
                    .iter()
                    .zip(b.iter().rev())
                    .map(|(p, q)| p.distance(*q))
                    .sum();
                along.min(back)
            }
            _ => f64::INFINITY,
        };
        let d = [
            distance(&self.left),
            distance(&self.right),
            distance(&self.vein),
        ];
        let best = (0..3).min_by(|a, b| d[*a].total_cmp(&d[*b])).unwrap_or(0);
        match best {
            0 => &mut self.left,
            1 => &mut self.right,
            _ => &mut self.vein,
        }
    }

    /// The indices into `[left, right, vein]` of the strokes that lie on
    /// the left, on the right and between them.
    fn outline_order(&self) -> Result<[usize; 3], SketchError> {
        let prepared = self.prepared_outline()?;
        Ok(sort_and_orient(prepared).0)
    }

    /// The three outline strokes checked, resampled and smoothed (in slot
    /// order).
    fn prepared_outline(&self) -> Result<[Vec<DVec2>; 3], SketchError> {
        let roles = [
            StrokeRole::LeftOutline,
            StrokeRole::RightOutline,
            StrokeRole::Vein,
        ];
        let mut prepared: [Vec<DVec2>; 3] = Default::default();
        for (k, role) in roles.iter().enumerate() {
            let raw = self.stroke(*role);
            if raw.is_empty() {
                return Err(SketchError::Missing(*role));
            }
            if raw.iter().any(|p| !p.is_finite()) {
                return Err(SketchError::NotFinite(*role));
            }
            prepared[k] = prepare(raw).ok_or(SketchError::TooShort {
                stroke: *role,
                length: 0.0,
                min: 0.0,
            })?;
        }
        let lengths = prepared.clone().map(|s| length(&s));
        let longest = lengths.iter().copied().fold(0.0, f64::max);
        for (k, role) in roles.iter().enumerate() {
            let min = MIN_OUTLINE_FRACTION * longest;
            if lengths[k] < min {
                return Err(SketchError::TooShort {
                    stroke: *role,
                    length: lengths[k],
                    min,
                });
            }
            if let Some(at) = self_intersection(&prepared[k]) {
                return Err(SketchError::SelfIntersecting { stroke: *role, at });
            }
        }
        Ok(prepared)
    }

    /// The outline sorted, oriented, checked and made into the flat grid.
    fn outline(&self) -> Result<Outline, SketchError> {
        let prepared = self.prepared_outline()?;
        let longest = prepared.iter().map(|s| length(s)).fold(0.0, f64::max);
        let (_, strokes) = sort_and_orient(prepared);
        let roles = [
            StrokeRole::LeftOutline,
            StrokeRole::RightOutline,
            StrokeRole::Vein,
        ];
        for (a, b) in [(0, 2), (1, 2), (0, 1)] {
            if let Some(at) = crossing(&strokes[a], &strokes[b]) {
                return Err(SketchError::Crossing {
                    first: roles[a],
                    second: roles[b],
                    at,
                });
            }
        }
        // The rows, in the sketch plane: straight from the left margin to
        // the right one at each arc-length fraction, their middle point
        // where the vein crosses that line (or, where it does not, as a
        // vein drawn a little short of or past the margins' ends: the
        // point of the vein at that fraction, put on the line).
        let rows: Vec<[DVec2; 3]> = (0..SKETCH_ROWS)
            .map(|j| {
                let f = j as f64 / (SKETCH_ROWS - 1) as f64;
                let (l, r) = (at_fraction(&strokes[0], f), at_fraction(&strokes[1], f));
                let d = r - l;
                let crossing = strokes[2]
                    .windows(2)
                    .find_map(|w| segment_crossing(l, r, w[0], w[1]))
                    .map(|(t, _)| t.clamp(0.1, 0.9));
                let along = crossing.unwrap_or_else(|| {
                    if d.length_squared() > 0.0 {
                        ((at_fraction(&strokes[2], f) - l).dot(d) / d.length_squared())
                            .clamp(0.25, 0.75)
                    } else {
                        0.5
                    }
                });
                [l, l + d * along, r]
            })
            .collect();
        let last = rows.len() - 1;
        let chord = rows[last][1] - rows[0][1];
        let axis = if chord.length() > 1e-12 * longest.max(1e-300) {
            chord.normalize()
        } else {
            DVec2::Y
        };
        let frame = SketchFrame {
            origin: rows[0][1],
            axis,
        };
        let widest = rows
            .iter()
            .map(|[l, _, r]| l.distance(*r))
            .fold(0.0, f64::max);
        let mut rows = rows;
        let [l0, v0, r0] = rows[0];
        let min_base = MIN_BASE_WIDTH * widest;
        if l0.distance(r0) < min_base {
            let across = if l0.distance(r0) > 1e-9 * widest {
                (r0 - l0).normalize()
            } else {
                frame.right()
            };
            rows[0] = [
                v0 - across * min_base * 0.5,
                v0,
                v0 + across * min_base * 0.5,
            ];
        }
        let half = SKETCH_COLUMNS / 2;
        let grid = rows
            .iter()
            .map(|[l, v, r]| {
                (0..SKETCH_COLUMNS)
                    .map(|i| {
                        let p = if i <= half {
                            *l + (*v - *l) * (i as f64 / half as f64)
                        } else {
                            *v + (*r - *v) * ((i - half) as f64 / half as f64)
                        };
                        frame.to_template(p)
                    })
                    .collect()
            })
            .collect();
        Ok(Outline {
            frame,
            strokes,
            grid,
            longest,
        })
    }

    /// The petal surface of this sketch, or which stroke is wrong and why.
    pub fn build(&self) -> Result<SketchedPetal, SketchError> {
        let outline = self.outline()?;
        let rows = SKETCH_ROWS;
        // Heights of the bent rows, later sections replacing earlier ones
        // on the same row.
        let mut bent: Vec<Option<Vec<f64>>> = vec![None; rows];
        let mut section_rows = Vec::with_capacity(self.sections.len());
        for (k, raw) in self.sections.iter().enumerate() {
            let role = StrokeRole::CrossSection(k);
            let (row, heights) = outline.section(raw, role)?;
            bent[row] = Some(heights);
            section_rows.push(row);
        }
        // Every column through its fixed rows: base, tip, bent rows.
        let v = greville(&clamped_uniform_knots(rows, 3), 3, rows);
        let fixed: Vec<usize> = (0..rows)
            .filter(|j| *j == 0 || *j == rows - 1 || bent[*j].is_some())
            .collect();
        let params: Vec<f64> = fixed.iter().map(|j| v[*j]).collect();
        let mut z = vec![vec![0.0; SKETCH_COLUMNS]; rows];
        for i in 0..SKETCH_COLUMNS {
            let values: Vec<f64> = fixed
                .iter()
                .map(|j| bent[*j].as_ref().map_or(0.0, |h| h[i]))
                .collect();
            let column = BSplineCurve::interpolate(&params, &values);
            for j in 0..rows {
                z[j][i] = match (&bent[j], &column) {
                    (Some(h), _) => h[i],
                    (None, _) if fixed.contains(&j) => 0.0,
                    (None, Some(c)) => c.at(v[j]),
                    (None, None) => 0.0,
                };
            }
        }
        let control: Vec<Vec<DVec3>> = outline
            .grid
            .iter()
            .zip(&z)
            .map(|(row, zs)| {
                row.iter()
                    .zip(zs)
                    .map(|(p, z)| DVec3::new(p.x, p.y, *z))
                    .collect()
            })
            .collect();
        let surface =
            BSplineSurface::clamped_cubic(control).ok_or(SketchError::Missing(StrokeRole::Vein))?;
        Ok(SketchedPetal {
            surface,
            frame: outline.frame,
            outline: outline.strokes,
            section_rows,
        })
    }
}

impl Outline {
    /// The row of control points nearest to `point` (template frame).
    fn nearest_row(&self, point: DVec2) -> usize {
        let distance = |row: &Vec<DVec2>| {
            row.windows(2)
                .map(|w| distance_to_segment(point, w[0], w[1]))
                .fold(f64::INFINITY, f64::min)
        };
        (0..self.grid.len())
            .min_by(|a, b| distance(&self.grid[*a]).total_cmp(&distance(&self.grid[*b])))
            .unwrap_or(0)
    }

    /// Whether a stroke (sketch plane) runs more across the petal than
    /// along it.
    fn is_across(&self, points: &[DVec2]) -> bool {
        match (points.first(), points.last()) {
            (Some(a), Some(b)) => {
                let chord = self.frame.to_template(*b) - self.frame.to_template(*a);
                chord.x.abs() > chord.y.abs()
            }
            _ => false,
        }
    }

    /// The row a cross-section bends and the heights (Z) of its control
    /// points.
    fn section(&self, raw: &[DVec2], role: StrokeRole) -> Result<(usize, Vec<f64>), SketchError> {
        if raw.iter().any(|p| !p.is_finite()) {
            return Err(SketchError::NotFinite(role));
        }
        let prepared = prepare(raw).ok_or(SketchError::TooShort {
            stroke: role,
            length: 0.0,
            min: 0.0,
        })?;
        if let Some(at) = self_intersection(&prepared) {
            return Err(SketchError::SelfIntersecting { stroke: role, at });
        }
        let points: Vec<DVec2> = prepared
            .iter()
            .map(|p| self.frame.to_template(*p))
            .collect();
        let row = self.nearest_row(points[0]);
        let grid = &self.grid[row];
        let (a, b) = (grid[0], grid[SKETCH_COLUMNS - 1]);
        let width = a.distance(b);
        if width <= 1e-6 * self.longest {
            return Err(SketchError::SectionAtPoint { stroke: role, row });
        }
        let e = (b - a) / width;
        let mut n = DVec2::new(-e.y, e.x);
        if n.y < 0.0 {
            n = -n;
        }
        // (across as a fraction of the row, height on the canvas)
        let mut sh: Vec<DVec2> = points
            .iter()
            .map(|p| DVec2::new((*p - a).dot(e) / width, (*p - a).dot(n)))
            .collect();
        if sh[sh.len() - 1].x < sh[0].x {
            sh.reverse();
        }
        let mut furthest = f64::NEG_INFINITY;
        for p in &sh {
            if p.x < furthest - TURN_BACK_SLACK {
                return Err(SketchError::SectionTurnsBack { stroke: role, row });
            }
            furthest = furthest.max(p.x);
        }
        let (from, to) = sh
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.x), hi.max(p.x))
            });
        if from > SPAN_SLACK || to < 1.0 - SPAN_SLACK {
            return Err(SketchError::SectionDoesNotSpan {
                stroke: role,
                row,
                from: 100.0 * from,
                to: 100.0 * to,
            });
        }
        // The height across as a cubic B-spline of the position across
        // (least squares; the stroke goes once across, so it is a
        // function of it).
        let params: Vec<f64> = sh
            .iter()
            .map(|p| ((p.x - from) / (to - from)).clamp(0.0, 1.0))
            .collect();
        let values: Vec<f64> = sh.iter().map(|p| p.y).collect();
        let curve = BSplineCurve::approximate(&params, &values, SECTION_CONTROL_POINTS);
        let height = |s: f64| {
            let t = ((s - from) / (to - from)).clamp(0.0, 1.0);
            match &curve {
                Some(c) => c.at(t),
                None => height_at(&sh, s),
            }
        };
        let (h0, h1) = (height(0.0), height(1.0));
        let relative = |s: f64| height(s) - (h0 + (h1 - h0) * s);
        let across = |p: DVec2| (p - a).dot(e) / width;
        let at_vein = relative(across(grid[SKETCH_COLUMNS / 2]));
        let heights = grid
            .iter()
            .map(|p| -(relative(across(*p)) - at_vein))
            .collect();
        Ok((row, heights))
    }
}

/// Sorts `[left, right, vein]` slots by where the strokes lie and orients
/// them from base to tip: the slot indices of the left, right and middle
/// stroke, and those strokes.
fn sort_and_orient(mut strokes: [Vec<DVec2>; 3]) -> ([usize; 3], [Vec<DVec2>; 3]) {
    let chord = |s: &[DVec2]| s[s.len() - 1] - s[0];
    // One direction for all: along the longest chord.
    let reference = strokes
        .iter()
        .map(|s| chord(s))
        .max_by(|a, b| a.length().total_cmp(&b.length()))
        .unwrap_or(DVec2::Y);
    for s in &mut strokes {
        if chord(s).dot(reference) < 0.0 {
            s.reverse();
        }
    }
    // The base is the lower end on the canvas (where the template frame
    // has it) when the petal is drawn upright; drawn lying down, it is the
    // end where the strokes come closer together.
    let spread = |ends: [DVec2; 3]| {
        ends[0].distance(ends[1]) + ends[1].distance(ends[2]) + ends[0].distance(ends[2])
    };
    let starts = [strokes[0][0], strokes[1][0], strokes[2][0]];
    let ends = strokes.clone().map(|s| s[s.len() - 1]);
    let along = ends.iter().sum::<DVec2>() - starts.iter().sum::<DVec2>();
    let reverse = if along.y.abs() >= along.x.abs() {
        along.y < 0.0
    } else {
        spread(starts) > spread(ends)
    };
    if reverse {
        for s in &mut strokes {
            s.reverse();
        }
    }
    // Left, middle, right by their mean offset to the left of the axis.
    let base = strokes.iter().map(|s| s[0]).sum::<DVec2>() / 3.0;
    let tip = strokes.iter().map(|s| s[s.len() - 1]).sum::<DVec2>() / 3.0;
    let axis = (tip - base).try_normalize().unwrap_or(DVec2::Y);
    let left_normal = DVec2::new(-axis.y, axis.x);
    let offset =
        |s: &[DVec2]| s.iter().map(|p| (*p - base).dot(left_normal)).sum::<f64>() / s.len() as f64;
    let mut order = [0, 1, 2];
    order.sort_by(|a, b| offset(&strokes[*b]).total_cmp(&offset(&strokes[*a])));
    let [l, m, r] = order;
    let sorted = [strokes[l].clone(), strokes[r].clone(), strokes[m].clone()];
    ([l, r, m], sorted)
}

/// A stroke without repeated points, resampled evenly to [`RESAMPLED`]
/// points, smoothed and resampled again; `None` without any length.
fn prepare(raw: &[DVec2]) -> Option<Vec<DVec2>> {
    let mut clean: Vec<DVec2> = Vec::with_capacity(raw.len());
    for p in raw {
        if !p.is_finite() {
            return None;
        }
        if clean.last().is_none_or(|q| q.distance(*p) > 1e-12) {
            clean.push(*p);
        }
    }
    if clean.len() < 2 || length(&clean) <= 0.0 {
        return None;
    }
    let mut points = resample(&clean, RESAMPLED);
    for _ in 0..SMOOTHING_PASSES {
        let previous = points.clone();
        for k in 1..points.len() - 1 {
            points[k] = previous[k] * 0.5 + (previous[k - 1] + previous[k + 1]) * 0.25;
        }
    }
    Some(resample(&points, RESAMPLED))
}

/// The polyline's length.
fn length(points: &[DVec2]) -> f64 {
    points.windows(2).map(|w| w[0].distance(w[1])).sum()
}

/// `count` points evenly spaced by arc length along the polyline.
fn resample(points: &[DVec2], count: usize) -> Vec<DVec2> {
    (0..count)
        .map(|k| at_fraction(points, k as f64 / (count - 1) as f64))
        .collect()
}

/// The point at arc-length fraction `f` of the polyline.
fn at_fraction(points: &[DVec2], f: f64) -> DVec2 {
    let total = length(points);
    let mut left = f.clamp(0.0, 1.0) * total;
    for w in points.windows(2) {
        let d = w[0].distance(w[1]);
        if left <= d && d > 0.0 {
            return w[0] + (w[1] - w[0]) * (left / d);
        }
        left -= d;
    }
    points[points.len() - 1]
}

/// Cumulative chord length, scaled to `[0, 1]`.
fn chord_parameters(points: &[DVec2]) -> Vec<f64> {
    let mut params = Vec::with_capacity(points.len());
    let mut total = 0.0;
    params.push(0.0);
    for w in points.windows(2) {
        total += w[0].distance(w[1]);
        params.push(total);
    }
    if total > 0.0 {
        for p in &mut params {
            *p /= total;
        }
    }
    params
}

/// The height (y) of the sampled curve at across position `s` (x), the
/// first piece that spans it; the nearest end's height beyond the curve.
fn height_at(samples: &[DVec2], s: f64) -> f64 {
    let first = samples[0];
    let last = samples[samples.len() - 1];
    if s <= first.x.min(last.x) {
        return if first.x <= last.x { first.y } else { last.y };
    }
    if s >= first.x.max(last.x) {
        return if first.x >= last.x { first.y } else { last.y };
    }
    for w in samples.windows(2) {
        let (lo, hi) = (w[0].x.min(w[1].x), w[0].x.max(w[1].x));
        if (lo..=hi).contains(&s) {
            let d = w[1].x - w[0].x;
            if d.abs() < 1e-300 {
                return w[0].y;
            }
            return w[0].y + (w[1].y - w[0].y) * (s - w[0].x) / d;
        }
    }
    last.y
}

/// The distance from `p` to the segment `a`–`b`.
fn distance_to_segment(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let d = b - a;
    let t = if d.length_squared() > 0.0 {
        ((p - a).dot(d) / d.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + d * t)
}

/// Where segments `a`–`b` and `c`–`d` cross: the fractions along each.
fn segment_crossing(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> Option<(f64, f64)> {
    let r = b - a;
    let s = d - c;
    let denominator = r.perp_dot(s);
    // Parallel (or collinear: strokes that run along each other touch,
    // they do not cross).
    if denominator.abs() <= 1e-9 * r.length() * s.length() {
        return None;
    }
    let t = (c - a).perp_dot(s) / denominator;
    let u = (c - a).perp_dot(r) / denominator;
    ((0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u)).then_some((t, u))
}

/// Where a polyline crosses itself (segments that do not share a point).
fn self_intersection(points: &[DVec2]) -> Option<DVec2> {
    let n = points.len();
    for i in 0..n.saturating_sub(1) {
        for j in i + 2..n - 1 {
            if let Some((t, _)) =
                segment_crossing(points[i], points[i + 1], points[j], points[j + 1])
            {
                return Some(points[i] + (points[i + 1] - points[i]) * t);
            }
        }
    }
    None
}

/// Where two strokes cross, away from where strokes meet: a crossing in
/// the end zones (first and last tenth) of both is allowed.
fn crossing(p: &[DVec2], q: &[DVec2]) -> Option<DVec2> {
    let fractions = |s: &[DVec2]| chord_parameters(s);
    let (fp, fq) = (fractions(p), fractions(q));
    let in_end_zone = |f: f64| !(END_ZONE..=1.0 - END_ZONE).contains(&f);
    for i in 0..p.len() - 1 {
        for j in 0..q.len() - 1 {
            if let Some((t, u)) = segment_crossing(p[i], p[i + 1], q[j], q[j + 1]) {
                let a = fp[i] + (fp[i + 1] - fp[i]) * t;
                let b = fq[j] + (fq[j + 1] - fq[j]) * u;
                if !(in_end_zone(a) && in_end_zone(b)) {
                    return Some(p[i] + (p[i + 1] - p[i]) * t);
                }
            }
        }
    }
    None
}

#[cfg(test)]
mod tests;

//! B-spline curves and tensor-product B-spline surfaces (the sketched
//! petal of the floral blossom paper §3.1 is one).
//!
//! A curve of degree `p` with `n` control points has `n + p + 1`
//! non-decreasing knots. The knot vectors made here are *clamped*: the
//! first and last knots are repeated `p + 1` times, so the curve starts at
//! its first control point and ends at its last (a surface reaches its
//! boundary control points). [`clamped_uniform_knots`] spaces the inner
//! knots evenly over `[0, 1]`; [`BSplineCurve::interpolate`] puts them at
//! the data's parameters.
//!
//! Basis functions are evaluated with the Cox–de Boor recurrence in its
//! triangular form (only the `p + 1` functions that are not zero at `t`);
//! derivatives are B-splines of one degree less, whose control points are
//! the scaled differences of the original ones.

use std::ops::{Add, Mul};

use glam::{DVec2, DVec3};

use crate::Surface;

/// What a B-spline's control points can be: points or vectors in any
/// dimension, or plain numbers.
pub trait ControlValue: Copy + Default + Add<Output = Self> + Mul<f64, Output = Self> {}
impl<T: Copy + Default + Add<Output = T> + Mul<f64, Output = T>> ControlValue for T {}

/// The clamped knot vector of `count` control points of degree `degree`
/// over `[0, 1]`: `degree + 1` zeros, `count - degree - 1` evenly spaced
/// inner knots, `degree + 1` ones. `count` must exceed `degree`.
pub fn clamped_uniform_knots(count: usize, degree: usize) -> Vec<f64> {
    let spans = count.saturating_sub(degree).max(1);
    let mut knots = vec![0.0; degree + 1];
    knots.extend((1..spans).map(|i| i as f64 / spans as f64));
    knots.extend(std::iter::repeat_n(1.0, degree + 1));
    knots
}

/// The knot span of `t`: the index `s` with `knots[s] <= t < knots[s + 1]`
/// among the spans of `count` control points of degree `degree` (`t` is
/// clamped to the curve's domain; its end belongs to the last span).
fn span(knots: &[f64], degree: usize, count: usize, t: f64) -> usize {
    let (first, last) = (degree, count - 1);
    if t >= knots[last + 1] {
        return last;
    }
    if t <= knots[first] {
        // The first non-empty span.
        let mut s = first;
        while s < last && knots[s + 1] <= knots[first] {
            s += 1;
        }
        return s;
    }
    let (mut low, mut high) = (first, last + 1);
    while high - low > 1 {
        let middle = (low + high) / 2;
        if t < knots[middle] {
            high = middle;
        } else {
            low = middle;
        }
    }
    low
}

/// The `degree + 1` basis functions that may be non-zero in span `s` at
/// `t`: `N[s - degree + k]` for `k` in `0..=degree`.
fn basis_in_span(knots: &[f64], degree: usize, s: usize, t: f64) -> Vec<f64> {
    let mut n = vec![0.0; degree + 1];
    let mut left = vec![0.0; degree + 1];
    let mut right = vec![0.0; degree + 1];
    n[0] = 1.0;
    for j in 1..=degree {
        left[j] = t - knots[s + 1 - j];
        right[j] = knots[s + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            let denominator = right[r + 1] + left[j - r];
            let temp = if denominator == 0.0 {
                0.0
            } else {
                n[r] / denominator
            };
            n[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        n[j] = saved;
    }
    n
}

/// All `count` basis functions of degree `degree` at `t` (zero where they
/// have no support); they add up to one inside the domain.
pub fn basis(knots: &[f64], degree: usize, count: usize, t: f64) -> Vec<f64> {
    let s = span(knots, degree, count, t);
    let mut all = vec![0.0; count];
    for (k, value) in basis_in_span(knots, degree, s, t).into_iter().enumerate() {
        all[s - degree + k] = value;
    }
    all
}

/// A B-spline curve: `C(t) = sum_i N_i,p(t) P_i` over its knots' domain.
#[derive(Debug, Clone, PartialEq)]
pub struct BSplineCurve<T> {
    /// The degree `p` (3: cubic).
    pub degree: usize,
    /// `control.len() + degree + 1` non-decreasing knots.
    pub knots: Vec<f64>,
    /// The control points.
    pub control: Vec<T>,
}

impl<T: ControlValue> BSplineCurve<T> {
    /// A clamped cubic curve over `[0, 1]` with evenly spaced inner knots
    /// through these control points (at least four).
    pub fn clamped_cubic(control: Vec<T>) -> Self {
        BSplineCurve {
            degree: 3,
            knots: clamped_uniform_knots(control.len(), 3),
            control,
        }
    }

    /// The curve's domain: `[t_p, t_n]`.
    pub fn domain(&self) -> (f64, f64) {
        (self.knots[self.degree], self.knots[self.control.len()])
    }

    /// The curve at `t` (clamped to its domain).
    pub fn at(&self, t: f64) -> T {
        let count = self.control.len();
        let s = span(&self.knots, self.degree, count, t);
        let n = basis_in_span(&self.knots, self.degree, s, t);
        let mut value = T::default();
        for (k, weight) in n.into_iter().enumerate() {
            value = value + self.control[s - self.degree + k] * weight;
        }
        value
    }

    /// The derivative curve `dC/dt`: degree one less, control points
    /// `p (P_i+1 - P_i) / (t_i+p+1 - t_i+1)`. A curve of degree 0 has the
    /// zero derivative.
    pub fn derivative(&self) -> BSplineCurve<T> {
        let p = self.degree;
        if p == 0 || self.control.len() < 2 {
            return BSplineCurve {
                degree: 0,
                knots: vec![self.domain().0, self.domain().1],
                control: vec![T::default()],
            };
        }
        let control = (0..self.control.len() - 1)
            .map(|i| {
                let gap = self.knots[i + p + 1] - self.knots[i + 1];
                if gap == 0.0 {
                    T::default()
                } else {
                    (self.control[i + 1] + self.control[i] * -1.0) * (p as f64 / gap)
                }
            })
            .collect();
        BSplineCurve {
            degree: p - 1,
            knots: self.knots[1..self.knots.len() - 1].to_vec(),
            control,
        }
    }

    /// The cubic curve through `values[k]` at parameter `params[k]`
    /// (strictly increasing, at least two): inner knots at the inner
    /// parameters, clamped at both ends, with the two end conditions of a
    /// natural spline (no second derivative at the first and last
    /// parameter). Two points give the straight line between them.
    pub fn interpolate(params: &[f64], values: &[T]) -> Option<Self> {
        let m = params.len();
        if m < 2
            || values.len() != m
            || params
                .windows(2)
                .any(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
        {
            return None;
        }
        if m == 2 {
            // Degree 3 needs four control points: the line's thirds.
            let (a, b) = (values[0], values[1]);
            let third = |f: f64| a * (1.0 - f) + b * f;
            return Some(BSplineCurve {
                degree: 3,
                knots: [[params[0]; 4], [params[1]; 4]].concat(),
                control: vec![a, third(1.0 / 3.0), third(2.0 / 3.0), b],
            });
        }
        let mut knots = vec![params[0]; 4];
        knots.extend_from_slice(&params[1..m - 1]);
        knots.extend(std::iter::repeat_n(params[m - 1], 4));
        let count = m + 2;
        // Rows: the interpolation at every parameter, then C'' = 0 at both
        // ends (the second derivative of the basis, from unit curves).
        let mut matrix = Vec::with_capacity(count);
        let mut right = Vec::with_capacity(count);
        for (t, value) in params.iter().zip(values) {
            matrix.push(basis(&knots, 3, count, *t));
            right.push(*value);
        }
        for t in [params[0], params[m - 1]] {
            let row = (0..count)
                .map(|i| {
                    let mut unit = vec![0.0; count];
                    unit[i] = 1.0;
                    let curve = BSplineCurve {
                        degree: 3,
                        knots: knots.clone(),
                        control: unit,
                    };
                    curve.derivative().derivative().at(t)
                })
                .collect();
            matrix.push(row);
            right.push(T::default());
        }
        let control = solve(matrix, right)?;
        Some(BSplineCurve {
            degree: 3,
            knots,
            control,
        })
    }

    /// The clamped cubic curve with `count` control points (at least four,
    /// evenly spaced inner knots over `[0, 1]`) closest in least squares to
    /// `values[k]` at parameter `params[k]` (in `[0, 1]`); its ends are
    /// the first and last value.
    pub fn approximate(params: &[f64], values: &[T], count: usize) -> Option<Self> {
        let m = values.len();
        if count < 4 || params.len() != m || m < count {
            return None;
        }
        let knots = clamped_uniform_knots(count, 3);
        let rows: Vec<Vec<f64>> = params.iter().map(|t| basis(&knots, 3, count, *t)).collect();
        // The ends are fixed: solve for the inner control points only.
        let (first, last) = (values[0], values[m - 1]);
        let inner = count - 2;
        let mut normal = vec![vec![0.0; inner]; inner];
        let mut right = vec![T::default(); inner];
        for (row, value) in rows.iter().zip(values) {
            let residual = *value + first * -row[0] + last * -row[count - 1];
            for a in 0..inner {
                right[a] = right[a] + residual * row[a + 1];
                for b in 0..inner {
                    normal[a][b] += row[a + 1] * row[b + 1];
                }
            }
        }
        let solved = solve(normal, right)?;
        let mut control = Vec::with_capacity(count);
        control.push(first);
        control.extend(solved);
        control.push(last);
        Some(BSplineCurve {
            degree: 3,
            knots,
            control,
        })
    }
}

/// Solves the small dense system `matrix · x = right` by Gaussian
/// elimination with partial pivoting; `None` when it is singular.
fn solve<T: ControlValue>(mut matrix: Vec<Vec<f64>>, mut right: Vec<T>) -> Option<Vec<T>> {
    let n = right.len();
    let scale = matrix
        .iter()
        .flatten()
        .fold(0.0_f64, |m, v| m.max(v.abs()))
        .max(f64::MIN_POSITIVE);
    for column in 0..n {
        let pivot = (column..n)
            .max_by(|&a, &b| matrix[a][column].abs().total_cmp(&matrix[b][column].abs()))?;
        if matrix[pivot][column].abs() <= 1e-13 * scale {
            return None;
        }
        matrix.swap(column, pivot);
        right.swap(column, pivot);
        for row in column + 1..n {
            let factor = matrix[row][column] / matrix[column][column];
            if factor == 0.0 {
                continue;
            }
            for k in column..n {
                matrix[row][k] -= factor * matrix[column][k];
            }
            right[row] = right[row] + right[column] * -factor;
        }
    }
    let mut x = vec![T::default(); n];
    for row in (0..n).rev() {
        let mut sum = right[row];
        for k in row + 1..n {
            sum = sum + x[k] * -matrix[row][k];
        }
        x[row] = sum * (1.0 / matrix[row][row]);
    }
    Some(x)
}

/// A tensor-product B-spline surface,
/// `S(u, v) = sum_j sum_i N_i,p(u) N_j,q(v) P_ji`.
///
/// `control[j][i]` is the control point in row `j` (along `v`, the base row
/// first) and column `i` (along `u`, across): the same layout as
/// [`crate::BezierPatch`]. With clamped knots the surface's edges are the
/// B-spline curves of its outer rows and columns, and its corners are the
/// corner control points.
#[derive(Debug, Clone, PartialEq)]
pub struct BSplineSurface {
    /// The degree across (`p`).
    pub degree_u: usize,
    /// The degree from base to tip (`q`).
    pub degree_v: usize,
    /// The knots across: columns + `p` + 1.
    pub knots_u: Vec<f64>,
    /// The knots from base to tip: rows + `q` + 1.
    pub knots_v: Vec<f64>,
    /// `control[j][i]`: row `j` (base to tip), column `i` (across).
    pub control: Vec<Vec<DVec3>>,
}

impl BSplineSurface {
    /// The bicubic surface of this control grid (at least 4×4, every row
    /// the same length) with clamped, evenly spaced knots over `[0, 1]²`;
    /// `None` for a smaller or ragged grid.
    pub fn clamped_cubic(control: Vec<Vec<DVec3>>) -> Option<Self> {
        let columns = control.first().map_or(0, Vec::len);
        if control.len() < 4 || columns < 4 || control.iter().any(|r| r.len() != columns) {
            return None;
        }
        Some(BSplineSurface {
            degree_u: 3,
            degree_v: 3,
            knots_u: clamped_uniform_knots(columns, 3),
            knots_v: clamped_uniform_knots(control.len(), 3),
            control,
        })
    }

    /// The number of columns (control points across).
    pub fn columns(&self) -> usize {
        self.control.first().map_or(0, Vec::len)
    }

    /// The number of rows (control points from base to tip).
    pub fn rows(&self) -> usize {
        self.control.len()
    }

    /// `dS/du` as a surface (degree one less across).
    pub fn derivative_u(&self) -> BSplineSurface {
        let rows: Vec<BSplineCurve<DVec3>> = self
            .control
            .iter()
            .map(|row| {
                BSplineCurve {
                    degree: self.degree_u,
                    knots: self.knots_u.clone(),
                    control: row.clone(),
                }
                .derivative()
            })
            .collect();
        let knots_u = rows.first().map_or_else(Vec::new, |r| r.knots.clone());
        BSplineSurface {
            degree_u: self.degree_u.saturating_sub(1),
            degree_v: self.degree_v,
            knots_u,
            knots_v: self.knots_v.clone(),
            control: rows.into_iter().map(|r| r.control).collect(),
        }
    }

    /// `dS/dv` as a surface (degree one less from base to tip).
    pub fn derivative_v(&self) -> BSplineSurface {
        let transposed = self.transposed().derivative_u();
        transposed.transposed()
    }

    /// The surface with `u` and `v` swapped.
    fn transposed(&self) -> BSplineSurface {
        let columns = self.columns();
        BSplineSurface {
            degree_u: self.degree_v,
            degree_v: self.degree_u,
            knots_u: self.knots_v.clone(),
            knots_v: self.knots_u.clone(),
            control: (0..columns)
                .map(|i| self.control.iter().map(|row| row[i]).collect())
                .collect(),
        }
    }

    /// The `v` at which each row's control point has the most weight (the
    /// Greville abscissae of the knots along `v`: the mean of each control
    /// point's `q` inner knots).
    pub fn row_parameters(&self) -> Vec<f64> {
        greville(&self.knots_v, self.degree_v, self.rows())
    }
}

/// The Greville abscissae of `count` control points of degree `degree`.
pub fn greville(knots: &[f64], degree: usize, count: usize) -> Vec<f64> {
    (0..count)
        .map(|i| {
            if degree == 0 {
                knots[i]
            } else {
                knots[i + 1..=i + degree].iter().sum::<f64>() / degree as f64
            }
        })
        .collect()
}

impl Surface for BSplineSurface {
    fn point(&self, point_in_uv: DVec2) -> DVec3 {
        let (columns, rows) = (self.columns(), self.rows());
        let su = span(&self.knots_u, self.degree_u, columns, point_in_uv.x);
        let sv = span(&self.knots_v, self.degree_v, rows, point_in_uv.y);
        let nu = basis_in_span(&self.knots_u, self.degree_u, su, point_in_uv.x);
        let nv = basis_in_span(&self.knots_v, self.degree_v, sv, point_in_uv.y);
        let mut p = DVec3::ZERO;
        for (l, wv) in nv.iter().enumerate() {
            let row = &self.control[sv - self.degree_v + l];
            for (k, wu) in nu.iter().enumerate() {
                p += *wu * *wv * row[su - self.degree_u + k];
            }
        }
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_basis_adds_up_to_one_and_is_never_negative() {
        for count in [4, 5, 8, 11] {
            let knots = clamped_uniform_knots(count, 3);
            assert_eq!(knots.len(), count + 4);
            for k in 0..=100 {
                let t = k as f64 / 100.0;
                let n = basis(&knots, 3, count, t);
                let sum: f64 = n.iter().sum();
                assert!((sum - 1.0).abs() < 1e-12, "count {count} t {t}: {sum}");
                assert!(n.iter().all(|v| *v >= 0.0));
            }
        }
    }

    #[test]
    fn a_clamped_cubic_with_four_points_is_the_bezier_curve() {
        // Four control points, no inner knots: the basis is Bernstein's.
        let knots = clamped_uniform_knots(4, 3);
        assert_eq!(knots, vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0]);
        for t in [0.0, 0.2, 0.5, 0.9, 1.0] {
            let n = basis(&knots, 3, 4, t);
            let b = crate::bernstein3(t);
            for i in 0..4 {
                assert!((n[i] - b[i]).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn the_hand_computed_basis_of_five_points_at_the_middle() {
        // Knots 0,0,0,0,1/2,1,1,1,1 at t = 1/2: only N1, N2, N3 are not zero,
        // N1 = 1/4, N2 = 1/2, N3 = 1/4 (by the recurrence, by hand).
        let knots = clamped_uniform_knots(5, 3);
        assert_eq!(knots, vec![0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0]);
        let n = basis(&knots, 3, 5, 0.5);
        let expected = [0.0, 0.25, 0.5, 0.25, 0.0];
        for i in 0..5 {
            assert!((n[i] - expected[i]).abs() < 1e-14, "{n:?}");
        }
    }

    #[test]
    fn a_clamped_curve_starts_and_ends_at_its_end_points_along_its_end_legs() {
        let control = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 2.0),
            DVec2::new(3.0, 3.0),
            DVec2::new(4.0, 1.0),
            DVec2::new(6.0, 0.0),
            DVec2::new(7.0, 2.0),
        ];
        let curve = BSplineCurve::clamped_cubic(control.clone());
        assert_eq!(curve.at(0.0), control[0]);
        assert!((curve.at(1.0) - control[5]).length() < 1e-14);
        // The end tangent: p / (t_4 - t_1) (P1 - P0), t_4 = 1/3 here.
        let d = curve.derivative();
        let start = d.at(0.0);
        assert!(
            (start - 9.0 * (control[1] - control[0])).length() < 1e-12,
            "{start}"
        );
        let end = d.at(1.0);
        assert!(
            (end - 9.0 * (control[5] - control[4])).length() < 1e-12,
            "{end}"
        );
        // The derivative agrees with central differences inside.
        for t in [0.1, 0.37, 0.5, 0.81] {
            let h = 1e-6;
            let fd = (curve.at(t + h) - curve.at(t - h)) / (2.0 * h);
            assert!((fd - d.at(t)).length() < 1e-6, "{t}: {fd} {}", d.at(t));
            let fd2 = (d.at(t + h) - d.at(t - h)) / (2.0 * h);
            assert!((fd2 - d.derivative().at(t)).length() < 1e-5);
        }
    }

    #[test]
    fn linear_control_points_at_the_greville_abscissae_give_a_straight_line() {
        let count = 7;
        let knots = clamped_uniform_knots(count, 3);
        let g = greville(&knots, 3, count);
        let curve = BSplineCurve {
            degree: 3,
            knots,
            control: g.iter().map(|t| 2.0 * t + 1.0).collect::<Vec<f64>>(),
        };
        for k in 0..=20 {
            let t = k as f64 / 20.0;
            assert!((curve.at(t) - (2.0 * t + 1.0)).abs() < 1e-12);
        }
    }

    #[test]
    fn interpolation_passes_through_its_points_with_natural_ends() {
        // Three points and two end conditions: z = 0 at the base and tip,
        // -1 at the middle row.
        let params = [0.0, 0.4, 1.0];
        let values = [0.0, -1.0, 0.0];
        let curve = BSplineCurve::interpolate(&params, &values).unwrap();
        assert_eq!(curve.control.len(), 5);
        for (t, v) in params.iter().zip(values) {
            assert!((curve.at(*t) - v).abs() < 1e-12);
        }
        let second = curve.derivative().derivative();
        assert!(second.at(0.0).abs() < 1e-10 && second.at(1.0).abs() < 1e-10);
        // The natural cubic spline through these points, by hand: its
        // second derivative at 0.4 solves h0 M0 + 2 (h0 + h1) M1 + h1 M2 =
        // 6 ((y2 - y1) / h1 - (y1 - y0) / h0) with M0 = M2 = 0, h0 = 0.4,
        // h1 = 0.6 (M1 = 12.5), and on [0, 0.4] it is
        // M1 t^3 / (6 h0) + (y1 / h0 - M1 h0 / 6) t.
        let m: f64 = 6.0 * ((0.0 - -1.0) / 0.6 - (-1.0 - 0.0) / 0.4) / (2.0 * (0.4 + 0.6));
        assert!((m - 12.5).abs() < 1e-12);
        let s = |t: f64| m * t.powi(3) / (6.0 * 0.4) + (-1.0 / 0.4 - m * 0.4 / 6.0) * t;
        for t in [0.1, 0.2, 0.3] {
            assert!(
                (curve.at(t) - s(t)).abs() < 1e-12,
                "{t}: {} {}",
                curve.at(t),
                s(t)
            );
        }
        // Two points: the line.
        let line = BSplineCurve::interpolate(&[0.0, 1.0], &[2.0, 4.0]).unwrap();
        assert!((line.at(0.25) - 2.5).abs() < 1e-12);
        // Out of order: refused.
        assert!(BSplineCurve::interpolate(&[0.0, 0.0, 1.0], &[0.0, 1.0, 2.0]).is_none());
    }

    #[test]
    fn least_squares_recovers_a_curve_it_can_represent() {
        let curve = BSplineCurve::clamped_cubic(vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(2.0, -1.0),
            DVec2::new(3.0, 0.5),
            DVec2::new(4.0, 0.0),
        ]);
        let params: Vec<f64> = (0..=40).map(|k| k as f64 / 40.0).collect();
        let values: Vec<DVec2> = params.iter().map(|t| curve.at(*t)).collect();
        let fitted = BSplineCurve::approximate(&params, &values, 5).unwrap();
        for (a, b) in fitted.control.iter().zip(&curve.control) {
            assert!((*a - *b).length() < 1e-9);
        }
    }

    #[test]
    fn a_surface_reaches_its_corner_points_and_its_derivatives_agree_with_differences() {
        let control: Vec<Vec<DVec3>> = (0..6)
            .map(|j| {
                (0..5)
                    .map(|i| DVec3::new(i as f64, j as f64 * 2.0, ((i * j) as f64 * 0.7).sin()))
                    .collect()
            })
            .collect();
        let s = BSplineSurface::clamped_cubic(control.clone()).unwrap();
        assert_eq!(s.point(DVec2::new(0.0, 0.0)), control[0][0]);
        assert!((s.point(DVec2::new(1.0, 1.0)) - control[5][4]).length() < 1e-12);
        assert!((s.point(DVec2::new(1.0, 0.0)) - control[0][4]).length() < 1e-12);
        let (du, dv) = (s.derivative_u(), s.derivative_v());
        for uv in [
            DVec2::new(0.3, 0.6),
            DVec2::new(0.71, 0.2),
            DVec2::new(0.5, 0.5),
        ] {
            let h = 1e-6;
            let fu = (s.point(uv + DVec2::X * h) - s.point(uv - DVec2::X * h)) / (2.0 * h);
            let fv = (s.point(uv + DVec2::Y * h) - s.point(uv - DVec2::Y * h)) / (2.0 * h);
            assert!((fu - du.point(uv)).length() < 1e-6);
            assert!((fv - dv.point(uv)).length() < 1e-6);
        }
        // The v edge is the curve of the first column.
        let column = BSplineCurve::clamped_cubic(control.iter().map(|r| r[0]).collect());
        for t in [0.2, 0.5, 0.9] {
            assert!((s.point(DVec2::new(0.0, t)) - column.at(t)).length() < 1e-12);
        }
        assert!(BSplineSurface::clamped_cubic(vec![vec![DVec3::ZERO; 3]; 4]).is_none());
    }
}

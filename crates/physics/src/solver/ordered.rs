//! The Hessian in a fill-reducing order, as faer's factorisation reads it.

use super::*;

/// The Hessian's sparsity in a fill-reducing order, as the lower triangle
/// in compressed columns (the layout faer's supernodal factorisation works
/// in), with where each entry comes from in the [`BlockPattern`]'s values.
/// Handing faer the matrix already ordered saves it permuting (and
/// transposing) the matrix at every factorisation, for one gather: a
/// factorisation of a lily petal's Hessian took 4 % less time at 4k
/// particles and 9 % less at 1k (best of 30); the factor is the same, bit
/// for bit, as when faer permutes.
pub(super) struct Ordered {
    /// `order[new] = old`: the scalar unknown at each new position.
    pub(super) order: Vec<usize>,
    /// The lower triangle's structure, checked once here (faer checks a
    /// structure when it is made, which was 0.5 % of a 4k run when every
    /// factorisation made its own).
    pub(super) structure: SymbolicSparseColMat<usize>,
    /// For each stored entry, its index in the pattern's values.
    pub(super) source: Vec<usize>,
}

impl Ordered {
    pub(super) fn new(pattern: &BlockPattern, order: Vec<usize>) -> Ordered {
        let n = pattern.dimension();
        let mut new_of_old = vec![0; n];
        for (new, &old) in order.iter().enumerate() {
            new_of_old[old] = new;
        }
        // (row, source) of each entry, per new column.
        let mut columns: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n];
        for col in 0..n {
            for idx in pattern.col_ptr()[col]..pattern.col_ptr()[col + 1] {
                let (a, b) = (new_of_old[pattern.row_idx()[idx]], new_of_old[col]);
                columns[a.min(b)].push((a.max(b), idx));
            }
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::with_capacity(pattern.nonzeros());
        let mut source = Vec::with_capacity(pattern.nonzeros());
        col_ptr.push(0);
        for column in &mut columns {
            column.sort_unstable();
            for &(row, idx) in column.iter() {
                row_idx.push(row);
                source.push(idx);
            }
            col_ptr.push(row_idx.len());
        }
        // Every particle has its diagonal block, so each lower column
        // starts with its diagonal entry (factorize and multiply use that).
        debug_assert!((0..n).all(|col| row_idx[col_ptr[col]] == col));
        Ordered {
            structure: SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx),
            order,
            source,
        }
    }

    /// The upper triangle's structure (the symbolic analysis reads the
    /// upper triangle).
    pub(super) fn upper_structure(&self) -> (Vec<usize>, Vec<usize>) {
        let n = self.order.len();
        let (col_ptr, row_idx) = (self.structure.col_ptr(), self.structure.row_idx());
        let mut counts = vec![0; n + 1];
        for &row in row_idx {
            counts[row + 1] += 1;
        }
        for i in 0..n {
            counts[i + 1] += counts[i];
        }
        let upper_col_ptr = counts.clone();
        let mut upper_row_idx = vec![0; row_idx.len()];
        for col in 0..n {
            for &row in &row_idx[col_ptr[col]..col_ptr[col + 1]] {
                upper_row_idx[counts[row]] = col;
                counts[row] += 1;
            }
        }
        (upper_col_ptr, upper_row_idx)
    }

    /// `y = A x` for the symmetric matrix whose lower triangle, in this
    /// layout, is `values`.
    pub(super) fn multiply(&self, values: &[f64], x: &[f64], y: &mut [f64]) {
        let (col_ptr, row_idx) = (self.structure.col_ptr(), self.structure.row_idx());
        y.fill(0.0);
        for (col, &x_col) in x.iter().enumerate() {
            // The diagonal entry comes first in each lower column.
            let (diagonal, below) = (col_ptr[col], col_ptr[col] + 1..col_ptr[col + 1]);
            y[col] += values[diagonal] * x_col;
            let mut column_sum = 0.0;
            for (&row, &value) in row_idx[below.clone()].iter().zip(&values[below]) {
                y[row] += value * x_col;
                column_sum += value * x[row];
            }
            y[col] += column_sum;
        }
    }

    /// `-gradient` (per particle) as a vector in this order.
    pub(super) fn negated(&self, gradient: &[DVec3], ordered: &mut [f64]) {
        for (v, &old) in ordered.iter_mut().zip(&self.order) {
            *v = -gradient[old / 3][old % 3];
        }
    }

    /// A vector in this order back in the particles' order (three
    /// components per particle).
    pub(super) fn scatter(&self, ordered: &[f64], out: &mut [f64]) {
        for (&v, &old) in ordered.iter().zip(&self.order) {
            out[old] = v;
        }
    }

    /// Lays the pattern's `values` out in this order, in `ordered` and in
    /// single precision in `single`.
    pub(super) fn gather(&self, values: &[f64], ordered: &mut [f64], single: &mut [f32]) {
        for ((v, s), &idx) in ordered.iter_mut().zip(single).zip(&self.source) {
            *v = values[idx];
            *s = *v as f32;
        }
    }
}

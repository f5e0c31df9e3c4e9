//! The sparsity pattern of the Hessian: 3x3 blocks between particles that
//! share an edge or a hinge, stored as the upper triangle of a scalar
//! compressed-sparse-column matrix (the layout faer's Cholesky takes).

use glam::DMat3;

/// Upper-triangular CSC pattern over `3 * n` scalar unknowns.
#[derive(Debug, Clone)]
pub struct BlockPattern {
    particles: usize,
    /// For each particle block `b`, the sorted blocks `a < b` it couples to.
    upper_neighbours: Vec<Vec<u32>>,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
}

impl BlockPattern {
    /// Builds the pattern from the coupled particle pairs (any order,
    /// duplicates allowed). Every particle gets its diagonal block.
    pub fn new(particles: usize, pairs: impl IntoIterator<Item = (u32, u32)>) -> Self {
        let mut upper_neighbours = vec![Vec::new(); particles];
        for (a, b) in pairs {
            if a != b {
                let (lo, hi) = (a.min(b), a.max(b));
                upper_neighbours[hi as usize].push(lo);
            }
        }
        for list in &mut upper_neighbours {
            list.sort_unstable();
            list.dedup();
        }
        let mut col_ptr = Vec::with_capacity(3 * particles + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for (b, list) in upper_neighbours.iter().enumerate() {
            for c in 0..3 {
                for &a in list {
                    row_idx.extend((0..3).map(|r| 3 * a as usize + r));
                }
                row_idx.extend((0..=c).map(|r| 3 * b + r));
                col_ptr.push(row_idx.len());
            }
        }
        BlockPattern {
            particles,
            upper_neighbours,
            col_ptr,
            row_idx,
        }
    }

    /// The number of scalar unknowns, three per particle.
    pub fn dimension(&self) -> usize {
        3 * self.particles
    }

    /// The number of stored entries (upper triangle, diagonal included).
    pub fn nonzeros(&self) -> usize {
        self.row_idx.len()
    }

    /// CSC column pointers: column `c`'s entries are
    /// `row_idx()[col_ptr()[c]..col_ptr()[c + 1]]` (`dimension() + 1` values).
    pub fn col_ptr(&self) -> &[usize] {
        &self.col_ptr
    }

    /// CSC row indices of the stored entries, sorted within each column.
    pub fn row_idx(&self) -> &[usize] {
        &self.row_idx
    }

    /// Adds the block `m` at block row `a`, block column `b` (and, by
    /// symmetry, its transpose at `(b, a)`) into `values`.
    pub fn add_block(&self, values: &mut [f64], a: u32, b: u32, m: &DMat3) {
        use std::cmp::Ordering;
        match a.cmp(&b) {
            Ordering::Equal => {
                let b = b as usize;
                let diag_offset = 3 * self.upper_neighbours[b].len();
                for c in 0..3 {
                    let start = self.col_ptr[3 * b + c] + diag_offset;
                    for r in 0..=c {
                        values[start + r] += m.col(c)[r];
                    }
                }
            }
            Ordering::Less => self.add_off_diagonal(values, a, b, m, false),
            Ordering::Greater => self.add_off_diagonal(values, b, a, m, true),
        }
    }

    fn add_off_diagonal(&self, values: &mut [f64], a: u32, b: u32, m: &DMat3, transpose: bool) {
        let b = b as usize;
        let slot = self.upper_neighbours[b]
            .binary_search(&a)
            .unwrap_or_else(|_| panic!("particles {a} and {b} are not coupled in the pattern"));
        for c in 0..3 {
            let start = self.col_ptr[3 * b + c] + 3 * slot;
            for r in 0..3 {
                values[start + r] += if transpose { m.col(r)[c] } else { m.col(c)[r] };
            }
        }
    }

    /// Adds `value` to every diagonal entry.
    pub fn add_to_diagonal(&self, values: &mut [f64], value: f64) {
        for col in 0..self.dimension() {
            // The diagonal entry is the last one of each upper column.
            values[self.col_ptr[col + 1] - 1] += value;
        }
    }

    /// The diagonal entries.
    pub fn diagonal<'a>(&'a self, values: &'a [f64]) -> impl Iterator<Item = f64> + 'a {
        (0..self.dimension()).map(move |col| values[self.col_ptr[col + 1] - 1])
    }

    /// `y = A x` for the symmetric matrix whose upper triangle is `values`.
    pub fn multiply(&self, values: &[f64], x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        for col in 0..self.dimension() {
            for idx in self.col_ptr[col]..self.col_ptr[col + 1] {
                let row = self.row_idx[idx];
                y[row] += values[idx] * x[col];
                if row != col {
                    y[col] += values[idx] * x[row];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn blocks_land_where_a_dense_matrix_puts_them() {
        let pattern = BlockPattern::new(3, [(0, 2), (2, 1)]);
        let mut values = vec![0.0; pattern.nonzeros()];
        let m = DMat3::from_cols(
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(4.0, 5.0, 6.0),
            DVec3::new(7.0, 8.0, 9.0),
        );
        let sym = m + m.transpose();
        pattern.add_block(&mut values, 2, 0, &m);
        pattern.add_block(&mut values, 1, 1, &sym);
        // Dense reference.
        let mut dense = vec![vec![0.0; 9]; 9];
        for c in 0..3 {
            for r in 0..3 {
                dense[6 + r][c] += m.col(c)[r];
                dense[c][6 + r] += m.col(c)[r];
                dense[3 + r][3 + c] += sym.col(c)[r];
            }
        }
        let x: Vec<f64> = (0..9).map(|i| (i as f64) * 0.5 - 1.0).collect();
        let mut y = vec![0.0; 9];
        pattern.multiply(&values, &x, &mut y);
        for r in 0..9 {
            let expect: f64 = (0..9).map(|c| dense[r][c] * x[c]).sum();
            assert!(
                (y[r] - expect).abs() < 1e-12,
                "row {r}: {} vs {expect}",
                y[r]
            );
        }
    }
}

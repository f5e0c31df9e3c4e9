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
    /// Where the blocks of each registered stencil live (see
    /// [`BlockPattern::with_stencils`]).
    stencils: Vec<StencilSlots>,
}

/// Where one 3x3 block between two particles lives in the values array:
/// its first column starts at `start`, the next two follow at `stride` and
/// `2 * stride + 1` (an upper column of block column `b` holds the blocks
/// above the diagonal, then its diagonal entries, one more per column).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct BlockSlot {
    start: usize,
    stride: usize,
    kind: SlotKind,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
enum SlotKind {
    /// A diagonal block: only its upper triangle is stored.
    #[default]
    Diagonal,
    /// Block row below block column: stored as it is.
    Upper,
    /// Block row above block column: its transpose is stored.
    Transposed,
}

/// The slots of every block between the (up to four) particles of a
/// stencil, e.g. an edge with its two opposite particles: `slots[p][q]` for
/// local particles `p <= q` holds the block of rows `p`, columns `q`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StencilSlots {
    /// The stencil's particles; `u32::MAX` where it has fewer than four.
    pub particles: [u32; 4],
    slots: [[BlockSlot; 4]; 4],
}

impl StencilSlots {
    /// The slot of local block `(p, q)`, `p <= q`.
    #[inline]
    pub fn slot(&self, p: usize, q: usize) -> &BlockSlot {
        &self.slots[p][q]
    }
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
            stencils: Vec::new(),
        }
    }

    /// Registers stencils (up to four particles each, `u32::MAX` for the
    /// missing ones; every pair of a stencil must be coupled) whose blocks
    /// are looked up once here, so that assembly adds them with
    /// [`BlockPattern::add_at`] without searching the pattern per block.
    pub fn with_stencils(mut self, stencils: impl IntoIterator<Item = [u32; 4]>) -> Self {
        self.stencils = stencils
            .into_iter()
            .map(|ids| self.stencil_slots(ids))
            .collect();
        self
    }

    /// The slots of the stencil `ids`: the `index`-th registered stencil if
    /// it starts with the same particles (it may have more), otherwise
    /// looked up now.
    pub fn stencil(&self, index: usize, ids: [u32; 4]) -> std::borrow::Cow<'_, StencilSlots> {
        let starts_with =
            |s: &StencilSlots| (0..4).all(|p| ids[p] == u32::MAX || ids[p] == s.particles[p]);
        match self.stencils.get(index) {
            Some(s) if starts_with(s) => std::borrow::Cow::Borrowed(s),
            _ => std::borrow::Cow::Owned(self.stencil_slots(ids)),
        }
    }

    fn stencil_slots(&self, particles: [u32; 4]) -> StencilSlots {
        let mut slots = [[BlockSlot::default(); 4]; 4];
        let count = particles.iter().take_while(|&&p| p != u32::MAX).count();
        for p in 0..count {
            for q in p..count {
                slots[p][q] = self.slot(particles[p], particles[q]);
            }
        }
        StencilSlots { particles, slots }
    }

    /// The slot of the block at block row `a`, block column `b`.
    pub fn slot(&self, a: u32, b: u32) -> BlockSlot {
        let (low, high) = (a.min(b) as usize, a.max(b) as usize);
        let neighbours = &self.upper_neighbours[high];
        let stride = 3 * neighbours.len() + 1;
        let (position, kind) = match a.cmp(&b) {
            std::cmp::Ordering::Equal => (neighbours.len(), SlotKind::Diagonal),
            ordering => {
                let position = neighbours.binary_search(&(low as u32)).unwrap_or_else(|_| {
                    panic!("particles {a} and {b} are not coupled in the pattern")
                });
                let kind = if ordering == std::cmp::Ordering::Less {
                    SlotKind::Upper
                } else {
                    SlotKind::Transposed
                };
                (position, kind)
            }
        };
        BlockSlot {
            start: self.col_ptr[3 * high] + 3 * position,
            stride,
            kind,
        }
    }

    /// Adds the block `m` at `slot` (and, by symmetry, its transpose at
    /// the mirrored block) into `values`. For a diagonal block only the
    /// upper triangle of `m` is read.
    #[inline(always)]
    pub fn add_at(values: &mut [f64], slot: &BlockSlot, m: &DMat3) {
        let starts = [
            slot.start,
            slot.start + slot.stride,
            slot.start + 2 * slot.stride + 1,
        ];
        let m = m.to_cols_array_2d();
        match slot.kind {
            SlotKind::Diagonal => {
                for c in 0..3 {
                    for r in 0..=c {
                        values[starts[c] + r] += m[c][r];
                    }
                }
            }
            SlotKind::Upper => {
                for c in 0..3 {
                    let column = &mut values[starts[c]..starts[c] + 3];
                    for r in 0..3 {
                        column[r] += m[c][r];
                    }
                }
            }
            SlotKind::Transposed => {
                for c in 0..3 {
                    let column = &mut values[starts[c]..starts[c] + 3];
                    for r in 0..3 {
                        column[r] += m[r][c];
                    }
                }
            }
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
        Self::add_at(values, &self.slot(a, b), m);
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

    #[test]
    fn stencil_slots_add_where_add_block_does() {
        // Two triangles sharing the edge (1, 3), numbered so that the
        // stencil's local order differs from the particle order.
        let stencil = [3, 1, 0, 2];
        let pairs = [(3, 1), (1, 0), (0, 3), (3, 2), (2, 1), (0, 2)];
        let pattern = BlockPattern::new(4, pairs).with_stencils([stencil]);
        let slots = pattern.stencil(0, stencil);
        let mut by_slot = vec![0.0; pattern.nonzeros()];
        let mut by_block = vec![0.0; pattern.nonzeros()];
        for p in 0..4 {
            for q in p..4 {
                let m = DMat3::from_cols_array(&std::array::from_fn(|k| {
                    (10 * p + q) as f64 + 0.1 * k as f64
                }));
                let m = if p == q { m + m.transpose() } else { m };
                BlockPattern::add_at(&mut by_slot, slots.slot(p, q), &m);
                pattern.add_block(&mut by_block, stencil[p], stencil[q], &m);
            }
        }
        assert_eq!(by_slot, by_block);
        // A stencil that is not the registered one is looked up.
        let other = pattern.stencil(0, [2, 0, u32::MAX, u32::MAX]);
        assert_eq!(*other.slot(0, 1), pattern.slot(2, 0));
    }
}

//! Stage 2 of the remeshing: triangle strips between the rows and along the
//! margins.

use super::{Layout, Work};

impl Work<'_> {
    /// Step 2: triangulates the layout: strips between consecutive rows and
    /// between each margin and the row ends next to it.
    pub(super) fn triangulate(&mut self, layout: &Layout) {
        for pair in layout.rows.windows(2) {
            // Rows run along +u, the next row is above (+v): on the left.
            self.zip(&pair[0], &pair[1], false);
        }
        let firsts: Vec<u32> = layout.rows.iter().map(|r| r[0]).collect();
        let lasts: Vec<u32> = layout.rows.iter().map(|r| r[r.len() - 1]).collect();
        // Margins run along +v; the row ends are on the right of u = 0 and on
        // the left of u = 1.
        self.zip(&layout.margins[0], &firsts, true);
        self.zip(&layout.margins[1], &lasts, false);
        // The boundary: base row, margins, top row.
        let mut neighbours = vec![Vec::new(); self.uvs.len()];
        let top = &layout.rows[layout.rows.len() - 1];
        for line in [&layout.rows[0], top, &layout.margins[0], &layout.margins[1]] {
            for pair in line.windows(2) {
                neighbours[pair[0] as usize].push(pair[1]);
                neighbours[pair[1] as usize].push(pair[0]);
            }
        }
        self.boundary_neighbours = neighbours;
    }

    /// Triangulates the strip between two polylines that run side by side in
    /// the same direction, always adding the triangle whose new diagonal is
    /// shorter. Triangles that would repeat a vertex (where the polylines
    /// share an end) are left out. The triangles are `(a, a, b)` and
    /// `(a, b, b)` in the polylines' direction, which is counter-clockwise in
    /// UV when `b` lies to the left of `a`; `b_on_right` reverses them.
    fn zip(&mut self, a: &[u32], b: &[u32], b_on_right: bool) {
        let (mut i, mut k) = (0, 0);
        while i + 1 < a.len() || k + 1 < b.len() {
            let p = |v: u32| self.positions[v as usize];
            let advance_a = if i + 1 == a.len() {
                false
            } else if k + 1 == b.len() {
                true
            } else {
                p(a[i + 1]).distance(p(b[k])) <= p(a[i]).distance(p(b[k + 1]))
            };
            let mut tri = if advance_a {
                i += 1;
                [a[i - 1], a[i], b[k]]
            } else {
                k += 1;
                [a[i], b[k], b[k - 1]]
            };
            if tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0] {
                continue;
            }
            if b_on_right {
                tri.swap(1, 2);
            }
            self.triangles.push(tri);
        }
    }
}

//! Stage 3 of the remeshing: edge flips and tangential smoothing.

use std::collections::HashSet;

use glam::{DVec2, DVec3};

use super::{Pin, Work};

/// The cosine of 20° (the default quality floor): guarded smoothing may
/// lower an angle to this.
const GUARD_COS: f64 = 0.939_692_620_785_908_4;

/// The directed edges leaving each vertex, with their triangles: a compact
/// adjacency rebuilt before each pass.
struct Adjacency {
    /// Directed edges `a -> b` of triangle `t`, as `(b, t)`, grouped by `a`.
    items: Vec<(u32, u32)>,
    offsets: Vec<usize>,
}

impl Adjacency {
    fn new(vertex_count: usize, triangles: &[[u32; 3]]) -> Self {
        let mut offsets = vec![0; vertex_count + 1];
        for &a in triangles.iter().flatten() {
            offsets[a as usize + 1] += 1;
        }
        for i in 0..vertex_count {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets.clone();
        let mut items = vec![(0, 0); offsets[vertex_count]];
        for (t, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                let a = tri[k] as usize;
                items[fill[a]] = (tri[(k + 1) % 3], t as u32);
                fill[a] += 1;
            }
        }
        Adjacency { items, offsets }
    }

    /// `(b, t)` for the edges `a -> b` leaving `a`; their triangles `t` are
    /// exactly the triangles around `a`.
    fn leaving(&self, a: u32) -> &[(u32, u32)] {
        &self.items[self.offsets[a as usize]..self.offsets[a as usize + 1]]
    }

    /// The triangle that has the directed edge `a -> b`.
    fn triangle_of(&self, a: u32, b: u32) -> Option<usize> {
        self.leaving(a)
            .iter()
            .find(|&&(x, _)| x == b)
            .map(|&(_, t)| t as usize)
    }

    fn has_edge(&self, a: u32, b: u32) -> bool {
        self.triangle_of(a, b).is_some() || self.triangle_of(b, a).is_some()
    }
}

impl Work<'_> {
    /// Signed area of a triangle in the parameters (positive when
    /// counter-clockwise).
    fn uv_area(&self, t: [u32; 3]) -> f64 {
        let [a, b, c] = t.map(|i| self.uvs[i as usize]);
        0.5 * (b - a).perp_dot(c - a)
    }

    /// Signed area of a triangle in the layout's UVs
    /// ([`crate::Surface::layout_uv`]).
    fn layout_area(&self, t: [u32; 3]) -> f64 {
        let [a, b, c] = t.map(|i| self.surface.layout_uv(self.uvs[i as usize]));
        0.5 * (b - a).perp_dot(c - a)
    }

    /// Whether a triangle is acceptable: counter-clockwise in the parameters
    /// and in the layout's UVs, with a 3D area that is not negligible.
    fn is_valid(&self, t: [u32; 3]) -> bool {
        let [a, b, c] = t.map(|i| self.positions[i as usize]);
        let area = 0.5 * (b - a).cross(c - a).length();
        let longest = (b - a)
            .length_squared()
            .max((c - b).length_squared())
            .max((a - c).length_squared());
        self.uv_area(t) > 1e-12 && area > 1e-9 * longest && self.layout_area(t) > 0.0
    }

    /// The cosine of the smallest interior angle of a triangle in 3D (the
    /// largest of the three cosines; no `acos` needed to compare angles).
    fn min_angle_cos(&self, t: [u32; 3]) -> f64 {
        let p = t.map(|i| self.positions[i as usize]);
        (0..3)
            .map(|k| {
                let (a, b, c) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
                let (e, f) = (b - a, c - a);
                e.dot(f) / (e.length_squared() * f.length_squared()).sqrt()
            })
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// One pass of edge flips over the interior edges: an edge is flipped
    /// when that raises the smallest angle of its two triangles (in the plane
    /// this is the Delaunay flip), or when one of them is folded and the
    /// flip unfolds both. Returns the number of flips.
    pub(super) fn flip_pass(&mut self) -> usize {
        let adjacency = Adjacency::new(self.uvs.len(), &self.triangles);
        // A triangle changed in this pass is not looked at again until the
        // next pass (the adjacency is stale there); edges made in this pass
        // are remembered so that no edge is made twice.
        let mut touched = vec![false; self.triangles.len()];
        let mut made: HashSet<(u32, u32)> = HashSet::new();
        let mut flips = 0;
        for t1 in 0..self.triangles.len() {
            for k in 0..3 {
                if touched[t1] {
                    break;
                }
                // t1 = (a, b, c) and t2 = (b, a, d) become (a, d, c), (d, b, c).
                let tri = self.triangles[t1];
                let (a, b, c) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
                let Some(t2) = adjacency.triangle_of(b, a) else {
                    continue;
                };
                if touched[t2] || a > b {
                    continue;
                }
                let other = self.triangles[t2];
                let Some(d) = other.iter().copied().find(|&x| x != a && x != b) else {
                    continue;
                };
                if adjacency.has_edge(c, d) || made.contains(&(c.min(d), c.max(d))) {
                    continue;
                }
                let (n1, n2) = ([a, d, c], [d, b, c]);
                if !self.is_valid(n1) || !self.is_valid(n2) {
                    continue;
                }
                // A pair with a folded triangle (the strips can fold one in
                // the layout's UVs near a pointed end) is flipped whenever
                // that unfolds it.
                let repairs = !self.is_valid(tri) || !self.is_valid(other);
                let before = self.min_angle_cos(tri).max(self.min_angle_cos(other));
                let after = self.min_angle_cos(n1).max(self.min_angle_cos(n2));
                if repairs || after < before - 1e-9 {
                    self.triangles[t1] = n1;
                    self.triangles[t2] = n2;
                    touched[t1] = true;
                    touched[t2] = true;
                    made.insert((c.min(d), c.max(d)));
                    flips += 1;
                }
            }
        }
        flips
    }

    /// The surface's partial derivatives at `uv` (central differences,
    /// one-sided at the domain's edges).
    fn jacobian(&self, uv: DVec2) -> (DVec3, DVec3) {
        const STEP: f64 = 1e-6;
        let derivative = |axis: DVec2, x: f64| {
            let lo = (x - STEP).max(0.0);
            let hi = (x + STEP).min(1.0);
            let at = |s: f64| self.surface.point(uv + axis * (s - x));
            (at(hi) - at(lo)) / (hi - lo)
        };
        (derivative(DVec2::X, uv.x), derivative(DVec2::Y, uv.y))
    }

    /// The area-weighted mean of the circumcentres of `triangles` (the
    /// optimal-Delaunay position of the vertex they surround).
    fn circumcentre_mean(&self, triangles: &[usize]) -> Option<DVec3> {
        let mut sum = DVec3::ZERO;
        let mut weight = 0.0;
        for &t in triangles {
            let [a, b, c] = self.triangles[t].map(|v| self.positions[v as usize]);
            let (ab, ac) = (b - a, c - a);
            let n = ab.cross(ac);
            let nn = n.length_squared();
            if nn == 0.0 {
                continue;
            }
            let centre = a
                + (ac.length_squared() * n.cross(ab) + ab.length_squared() * ac.cross(n))
                    / (2.0 * nn);
            let area = 0.5 * nn.sqrt();
            sum += area * centre;
            weight += area;
        }
        (weight > 0.0).then(|| sum / weight)
    }

    /// One Gauss–Seidel sweep of tangential smoothing. With
    /// `guard_angles`, a move that makes the smallest angle around the
    /// vertex worse, and below 20°, is not taken.
    pub(super) fn smooth_pass(&mut self, guard_angles: bool) {
        let n = self.uvs.len();
        let adjacency = Adjacency::new(n, &self.triangles);
        let mut around = Vec::new();
        for i in 0..n {
            let pin = self.pins[i];
            if pin == Pin::Fixed {
                continue;
            }
            around.clear();
            around.extend(adjacency.leaving(i as u32).iter().map(|&(_, t)| t as usize));
            let Some(centre) = self.circumcentre_mean(&around) else {
                continue;
            };
            let target = match (pin, self.boundary_neighbours[i].as_slice()) {
                (Pin::Free, _) => centre,
                (_, &[a, b]) => {
                    let midpoint = 0.5 * (self.positions[a as usize] + self.positions[b as usize]);
                    0.5 * (centre + midpoint)
                }
                _ => continue,
            };
            let uv = self.uvs[i];
            let residual = target - self.positions[i];
            let (su, sv) = self.jacobian(uv);
            let step = match pin {
                Pin::SlideU if su.length_squared() > 0.0 => {
                    DVec2::new(su.dot(residual) / su.length_squared(), 0.0)
                }
                Pin::SlideV if sv.length_squared() > 0.0 => {
                    DVec2::new(0.0, sv.dot(residual) / sv.length_squared())
                }
                Pin::Free => {
                    // Normal equations of the Gauss–Newton step.
                    let (a, b, c) = (su.dot(su), su.dot(sv), sv.dot(sv));
                    let det = a * c - b * b;
                    if det <= 1e-12 * (a + c) * (a + c) {
                        continue;
                    }
                    let (ru, rv) = (su.dot(residual), sv.dot(residual));
                    DVec2::new((c * ru - b * rv) / det, (a * rv - b * ru) / det)
                }
                _ => continue,
            };
            if !step.is_finite() {
                continue;
            }
            // Take the step, or half of it, ... as long as no triangle folds
            // (and, guarded, the worst angle around does not get worse).
            let worst_cos = |work: &Self| {
                around
                    .iter()
                    .map(|&t| work.min_angle_cos(work.triangles[t]))
                    .fold(f64::NEG_INFINITY, f64::max)
            };
            let allowed_cos = if guard_angles {
                worst_cos(self).max(GUARD_COS)
            } else {
                f64::INFINITY
            };
            let (old_uv, old_position) = (uv, self.positions[i]);
            let mut scale = 1.0;
            for _ in 0..4 {
                let new_uv = (old_uv + step * scale).clamp(DVec2::ZERO, DVec2::ONE);
                let p = self.surface.point(new_uv);
                if p.is_finite() {
                    self.uvs[i] = new_uv;
                    self.positions[i] = p;
                    if around.iter().all(|&t| self.is_valid(self.triangles[t]))
                        && worst_cos(self) <= allowed_cos
                    {
                        break;
                    }
                }
                self.uvs[i] = old_uv;
                self.positions[i] = old_position;
                scale *= 0.5;
            }
        }
    }
}

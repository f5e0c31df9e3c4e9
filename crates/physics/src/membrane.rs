//! The edge-smoothed membrane: the stretching energy of the consistent model.
//!
//! The paper's edge springs are the membrane of a flat-faceted surface. On a
//! curved bud they lock: the facets can hardly bend without stretching an
//! edge, so a coarse mesh resists bending that a fine one (and the smooth
//! surface) allows. Measured on the lily petal, the springs put the tip 15 %
//! of the midrib length away from the same petal at 4× the particles, and an
//! Eustoma petal 28 % (README, refinement table). Here, as in the
//! edge-based smoothed finite element method (ES-FEM, Liu et al. 2009), the
//! strain of each edge's smoothing domain (a third of each triangle next to
//! it) is the area-weighted mean of those triangles' Green strains. The
//! oscillating strains by which facets follow a bend partly cancel in the
//! mean, so the membrane locks much less (8 % and 4 % at the same meshes),
//! and the energy is that of a continuum membrane: isotropic, with Lamé
//! parameters `λ = μ` (the springs' Poisson ratio of 1/3 on equilateral
//! triangles), the same for any triangulation.
//!
//! Each triangle's Green strain `E` is fixed by its edges: an edge with rest
//! vector `D` (in the flat rest triangle) and current length `l` has
//! `Dᵀ E D = s` with `s = (l² − L²) / 2`. So the domain's mean strain, and its
//! energy `a (½ λ tr(E)² + μ E:E)`, are a quadratic form `½ sᵀ Q s` in the
//! strains of the domain's (three or five) edges, with `Q` fixed by the rest
//! lengths: rebuilt after each growth step, it makes the energy, its gradient
//! and a positive semi-definite Hessian (Gauss–Newton plus the edges'
//! own curvature where they are in tension) cheap to evaluate.

use glam::{DMat3, DVec2, DVec3};

use anthesis_mesh::Topology;

use crate::elastic::outer;
use crate::pattern::BlockPattern;

/// One smoothing domain: an edge with its one or two triangles.
#[derive(Debug, Clone, PartialEq)]
struct Domain {
    /// Endpoints of the domain's edges: the edge `i -> j` itself, then the
    /// left triangle's `j -> k`, `k -> i`, then the right triangle's
    /// `i -> l`, `l -> j`.
    pairs: [[u32; 2]; 5],
    /// Their indices in the topology's edge list.
    edges: [u32; 5],
    /// 3 for a boundary edge, 5 for an interior one.
    count: usize,
    /// The energy as a quadratic form in the edge strains.
    q: [[f64; 5]; 5],
}

/// The membrane energy of one organ (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeSmoothedMembrane {
    domains: Vec<Domain>,
}

/// Where the directed edge `a -> b` sits in triangle `tri` (0, 1 or 2 for
/// its sides `(t0,t1)`, `(t1,t2)`, `(t2,t0)`).
fn side_of(tri: [u32; 3], a: u32, b: u32) -> usize {
    (0..3)
        .find(|&m| tri[m] == a && tri[(m + 1) % 3] == b)
        .unwrap_or(0)
}

/// The strain coefficients of a flat rest triangle with corners `p`: for
/// each of its sides `(p0,p1)`, `(p1,p2)`, `(p2,p0)`, the Green strain
/// tensor `(E_xx, E_xy, E_yy)` made by a unit strain `s` of that side alone.
/// `None` for a degenerate triangle.
fn strain_coefficients(p: [DVec2; 3]) -> Option<[[f64; 3]; 3]> {
    let d = [p[1] - p[0], p[2] - p[1], p[0] - p[2]];
    // Row k: d_kᵀ E d_k = s_k, i.e. [dx², 2 dx dy, dy²] · (E_xx, E_xy, E_yy).
    let rows = DMat3::from_cols(
        DVec3::new(d[0].x * d[0].x, d[1].x * d[1].x, d[2].x * d[2].x),
        DVec3::new(
            2.0 * d[0].x * d[0].y,
            2.0 * d[1].x * d[1].y,
            2.0 * d[2].x * d[2].y,
        ),
        DVec3::new(d[0].y * d[0].y, d[1].y * d[1].y, d[2].y * d[2].y),
    );
    let scale = d.iter().map(|v| v.length_squared()).sum::<f64>();
    if rows.determinant().abs() <= 1e-12 * scale * scale * scale {
        return None;
    }
    let inverse = rows.inverse();
    Some([0, 1, 2].map(|k| inverse.col(k).to_array()))
}

/// The corner of a triangle over the base from `(−b/2, 0)` to `(b/2, 0)` at
/// distance `to_start` from the first end and `to_end` from the second, on
/// the side of `side` (±1). Lengths that violate the triangle inequality
/// give the nearest flat triangle.
fn apex(base: f64, to_start: f64, to_end: f64, side: f64) -> DVec2 {
    let x = (to_start * to_start - to_end * to_end) / (2.0 * base);
    let y = (to_start * to_start - (x + 0.5 * base).powi(2))
        .max(0.0)
        .sqrt();
    DVec2::new(x, side * y)
}

impl EdgeSmoothedMembrane {
    /// The domains of a mesh's edges; call [`EdgeSmoothedMembrane::update`]
    /// before evaluating the energy.
    pub fn new(triangles: &[[u32; 3]], topology: &Topology) -> EdgeSmoothedMembrane {
        let domains = topology
            .edges
            .iter()
            .enumerate()
            .map(|(e, edge)| {
                let [i, j] = edge.vertices;
                let k = edge.left.opposite;
                let left = edge.left.triangle as usize;
                let m = side_of(triangles[left], i, j);
                let sides = topology.triangle_edges[left];
                let mut pairs = [[i, j], [j, k], [k, i], [i, j], [i, j]];
                let mut edges = [e as u32, sides[(m + 1) % 3], sides[(m + 2) % 3], 0, 0];
                let mut count = 3;
                if let Some(right) = edge.right {
                    let l = right.opposite;
                    let r = right.triangle as usize;
                    let m = side_of(triangles[r], j, i);
                    let sides = topology.triangle_edges[r];
                    pairs[3] = [i, l];
                    pairs[4] = [l, j];
                    edges[3] = sides[(m + 1) % 3];
                    edges[4] = sides[(m + 2) % 3];
                    count = 5;
                }
                Domain {
                    pairs,
                    edges,
                    count,
                    q: [[0.0; 5]; 5],
                }
            })
            .collect();
        EdgeSmoothedMembrane { domains }
    }

    /// Rebuilds each domain's energy from the rest lengths and the Lamé
    /// parameter `μ = λ` of each edge's domain (both indexed like the
    /// topology's edges).
    pub fn update(&mut self, rest_lengths: &[f64], modulus: &[f64]) {
        for d in &mut self.domains {
            let [e0, e1, e2, e3, e4] = d.edges.map(|e| e as usize);
            let base = rest_lengths[e0];
            let (pi, pj) = (DVec2::new(-0.5 * base, 0.0), DVec2::new(0.5 * base, 0.0));
            let area = |p: [DVec2; 3]| 0.5 * (p[1] - p[0]).perp_dot(p[2] - p[0]).abs();
            // The rest triangles unfolded flat about the edge: the left one
            // (i, j, k) above it, the right one (i, l, j) below. Each is
            // (side slots of its edges, corners, area).
            let corners = [pi, pj, apex(base, rest_lengths[e2], rest_lengths[e1], 1.0)];
            let left = ([0, 1, 2], corners, area(corners));
            let right = (d.count == 5).then(|| {
                let corners = [pi, apex(base, rest_lengths[e3], rest_lengths[e4], -1.0), pj];
                ([3, 4, 0], corners, area(corners))
            });
            let total = left.2 + right.map_or(0.0, |r| r.2);
            // The mean strain as (E_xx, E_xy, E_yy) per unit strain of each
            // edge slot.
            let mut per_slot = [[0.0; 3]; 5];
            for (slots, corners, area) in std::iter::once(left).chain(right) {
                let Some(coefficients) = strain_coefficients(corners) else {
                    continue;
                };
                let weight = area / total.max(f64::MIN_POSITIVE);
                for (side, &slot) in slots.iter().enumerate() {
                    for c in 0..3 {
                        per_slot[slot][c] += weight * coefficients[side][c];
                    }
                }
            }
            let domain_area = total / 3.0;
            let mu = modulus[e0];
            let lambda = mu;
            // Q is symmetric: each pair once.
            for a in 0..d.count {
                for b in a..d.count {
                    let (x, y) = (per_slot[a], per_slot[b]);
                    let traces = (x[0] + x[2]) * (y[0] + y[2]);
                    let contraction = x[0] * y[0] + 2.0 * x[1] * y[1] + x[2] * y[2];
                    d.q[a][b] = domain_area * (lambda * traces + 2.0 * mu * contraction);
                    d.q[b][a] = d.q[a][b];
                }
            }
        }
    }

    /// The edge strains `s` of a domain and the edge vectors `xa − xb`.
    fn strains(d: &Domain, x: &[DVec3], rest_lengths: &[f64]) -> ([f64; 5], [DVec3; 5]) {
        let mut s = [0.0; 5];
        let mut v = [DVec3::ZERO; 5];
        for k in 0..d.count {
            let [a, b] = d.pairs[k];
            v[k] = x[a as usize] - x[b as usize];
            let rest = rest_lengths[d.edges[k] as usize];
            s[k] = 0.5 * (v[k].length_squared() - rest * rest);
        }
        (s, v)
    }

    /// `Q s`: the energy's derivative by each edge strain.
    fn stresses(d: &Domain, s: &[f64; 5]) -> [f64; 5] {
        let mut r = [0.0; 5];
        for a in 0..d.count {
            r[a] = (0..d.count).map(|b| d.q[a][b] * s[b]).sum();
        }
        r
    }

    /// The membrane energy at `x`; adds its gradient to `gradient` if given.
    pub fn energy(
        &self,
        x: &[DVec3],
        rest_lengths: &[f64],
        mut gradient: Option<&mut [DVec3]>,
    ) -> f64 {
        let mut energy = 0.0;
        for d in &self.domains {
            let (s, v) = Self::strains(d, x, rest_lengths);
            let r = Self::stresses(d, &s);
            energy += 0.5 * (0..d.count).map(|k| s[k] * r[k]).sum::<f64>();
            if let Some(g) = gradient.as_deref_mut() {
                for k in 0..d.count {
                    let [a, b] = d.pairs[k];
                    g[a as usize] += v[k] * r[k];
                    g[b as usize] -= v[k] * r[k];
                }
            }
        }
        energy
    }

    /// Adds the PSD Hessian approximation into `values` (see
    /// [`crate::Elastic::hessian`]): `Σ Q_ab ∇s_a ∇s_bᵀ` (exact where the
    /// strains vanish) plus each edge's `r_k ∇²s_k` where its stress `r_k`
    /// is a tension.
    pub fn hessian(
        &self,
        x: &[DVec3],
        rest_lengths: &[f64],
        pattern: &BlockPattern,
        values: &mut [f64],
    ) {
        for (e, d) in self.domains.iter().enumerate() {
            let (s, v) = Self::strains(d, x, rest_lengths);
            let r = Self::stresses(d, &s);
            Self::add_domain_hessian(e, d, &v, &r, pattern, values);
        }
    }

    /// [`EdgeSmoothedMembrane::energy`] with its gradient added to
    /// `gradient` and [`EdgeSmoothedMembrane::hessian`] added to `values`,
    /// in one pass: each domain's strains and stresses computed once for
    /// all three, the same bits as the two calls.
    pub fn energy_gradient_and_hessian(
        &self,
        x: &[DVec3],
        rest_lengths: &[f64],
        gradient: &mut [DVec3],
        pattern: &BlockPattern,
        values: &mut [f64],
    ) -> f64 {
        let mut energy = 0.0;
        for (e, d) in self.domains.iter().enumerate() {
            let (s, v) = Self::strains(d, x, rest_lengths);
            let r = Self::stresses(d, &s);
            energy += 0.5 * (0..d.count).map(|k| s[k] * r[k]).sum::<f64>();
            for k in 0..d.count {
                let [a, b] = d.pairs[k];
                gradient[a as usize] += v[k] * r[k];
                gradient[b as usize] -= v[k] * r[k];
            }
            Self::add_domain_hessian(e, d, &v, &r, pattern, values);
        }
        energy
    }

    /// Adds domain `e`'s Hessian blocks for edge vectors `v` and stresses
    /// `r` into `values`.
    #[inline(always)]
    fn add_domain_hessian(
        e: usize,
        d: &Domain,
        v: &[DVec3; 5],
        r: &[f64; 5],
        pattern: &BlockPattern,
        values: &mut [f64],
    ) {
        // Summed per pair of the domain's (three or four) particles
        // first, then added to the sparse matrix once per pair.
        let particles = d.count.div_ceil(2) + 1;
        // Only the blocks p <= q are added to the (symmetric) matrix.
        let mut local = [[DMat3::ZERO; 4]; 4];
        let mut add = |p: usize, q: usize, block: &DMat3, minus: bool| {
            if p <= q {
                if minus {
                    local[p][q] -= *block;
                } else {
                    local[p][q] += *block;
                }
            }
        };
        for a in 0..d.count {
            let [la, lb] = SLOT_PARTICLES[a];
            if r[a] > 0.0 {
                let block = DMat3::IDENTITY * r[a];
                add(la, la, &block, false);
                add(lb, lb, &block, false);
                add(la, lb, &block, true);
                add(lb, la, &block, true);
            }
            for b in 0..d.count {
                let [qa, qb] = SLOT_PARTICLES[b];
                // ∇s_a is +v_a at la and −v_a at lb.
                let block = outer(v[a], v[b]) * d.q[a][b];
                add(la, qa, &block, false);
                add(la, qb, &block, true);
                add(lb, qa, &block, true);
                add(lb, qb, &block, false);
            }
        }
        let stencil = pattern.stencil(e, Self::stencil(d));
        for p in 0..particles {
            for q in p..particles {
                // The slot mirrors (p, q) to (q, p); for p == q only
                // the upper triangle of the (symmetric) block is used.
                BlockPattern::add_at(values, stencil.slot(p, q), &local[p][q]);
            }
        }
    }

    /// The particles `[i, j, k, l]` of each domain (`l` is `u32::MAX` at a
    /// boundary edge), in the topology's edge order: the stencils the
    /// Hessian adds blocks to.
    pub fn stencils(&self) -> impl Iterator<Item = [u32; 4]> + '_ {
        self.domains.iter().map(Self::stencil)
    }

    fn stencil(d: &Domain) -> [u32; 4] {
        let l = if d.count == 5 {
            d.pairs[3][1]
        } else {
            u32::MAX
        };
        [d.pairs[0][0], d.pairs[0][1], d.pairs[1][1], l]
    }
}

/// The domain's particles `i, j, k, l` (local 0–3) at the ends of each edge
/// slot: `i -> j`, `j -> k`, `k -> i`, `i -> l`, `l -> j`.
const SLOT_PARTICLES: [[usize; 2]; 5] = [[0, 1], [1, 2], [2, 0], [0, 3], [3, 1]];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::TestRng;
    use anthesis_mesh::generate;

    fn irregular_sheet(rng: &mut TestRng) -> (anthesis_mesh::Mesh, Topology) {
        let mut mesh = generate::flat_sheet(3.0, 4.0, 5, 6);
        for p in &mut mesh.positions {
            *p += DVec3::new(rng.centred(), rng.centred(), 0.0) * 0.3;
        }
        let topology = Topology::build(&mesh).expect("manifold");
        (mesh, topology)
    }

    fn lengths(x: &[DVec3], topology: &Topology) -> Vec<f64> {
        topology
            .edges
            .iter()
            .map(|e| (x[e.vertices[0] as usize] - x[e.vertices[1] as usize]).length())
            .collect()
    }

    #[test]
    fn a_uniform_strain_costs_the_continuum_energy_over_the_area() {
        // Stretch an irregular flat sheet by the affine map F: every
        // triangle has the Green strain E = (FᵀF − I)/2, so every domain's
        // mean strain is E too and the energy is area · (λ/2 tr² + μ E:E).
        let mut rng = TestRng(3);
        let (mesh, topology) = irregular_sheet(&mut rng);
        let rest = lengths(&mesh.positions, &topology);
        let mu = 2.5;
        let mut membrane = EdgeSmoothedMembrane::new(&mesh.triangles, &topology);
        membrane.update(&rest, &vec![mu; rest.len()]);
        let f = glam::DMat2::from_cols(DVec2::new(1.1, 0.05), DVec2::new(-0.02, 0.93));
        let x: Vec<DVec3> = mesh
            .positions
            .iter()
            .map(|p| (f * p.truncate()).extend(0.0))
            .collect();
        let c = f.transpose() * f;
        let (exx, exy, eyy) = (
            0.5 * (c.x_axis.x - 1.0),
            0.5 * c.y_axis.x,
            0.5 * (c.y_axis.y - 1.0),
        );
        let density =
            0.5 * mu * (exx + eyy).powi(2) + mu * (exx * exx + 2.0 * exy * exy + eyy * eyy);
        let area: f64 = (0..mesh.triangles.len())
            .map(|t| {
                let [a, b, c] = mesh.triangles[t].map(|i| mesh.positions[i as usize]);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum();
        let energy = membrane.energy(&x, &rest, None);
        assert!(
            (energy - area * density).abs() < 1e-10 * energy,
            "{energy} vs {}",
            area * density
        );
        // A rigid motion costs nothing.
        let turned: Vec<DVec3> = mesh
            .positions
            .iter()
            .map(|p| glam::DQuat::from_rotation_x(0.7) * *p + DVec3::new(1.0, 2.0, 3.0))
            .collect();
        assert!(membrane.energy(&turned, &rest, None) < 1e-20);
    }

    #[test]
    fn gradient_and_hessian_match_finite_differences() {
        let mut rng = TestRng(11);
        let (mesh, topology) = irregular_sheet(&mut rng);
        let rest: Vec<f64> = lengths(&mesh.positions, &topology)
            .iter()
            .map(|l| l * (1.0 + 0.2 * rng.centred()))
            .collect();
        let modulus: Vec<f64> = rest.iter().map(|_| 1.0 + rng.centred()).collect();
        let mut membrane = EdgeSmoothedMembrane::new(&mesh.triangles, &topology);
        membrane.update(&rest, &modulus);
        let x: Vec<DVec3> = mesh
            .positions
            .iter()
            .map(|p| *p + DVec3::new(rng.centred(), rng.centred(), rng.centred()) * 0.3)
            .collect();
        let mut g = vec![DVec3::ZERO; x.len()];
        membrane.energy(&x, &rest, Some(&mut g));
        let h = 1e-6;
        for p in 0..x.len() {
            for c in 0..3 {
                let (mut plus, mut minus) = (x.clone(), x.clone());
                plus[p][c] += h;
                minus[p][c] -= h;
                let fd = (membrane.energy(&plus, &rest, None)
                    - membrane.energy(&minus, &rest, None))
                    / (2.0 * h);
                assert!(
                    (fd - g[p][c]).abs() < 1e-6 * (1.0 + fd.abs()),
                    "particle {p} axis {c}: {fd} vs {}",
                    g[p][c]
                );
            }
        }

        // At rest (no strain) the Gauss–Newton Hessian is exact: compare
        // H·v with the difference of gradients along v.
        let pairs = topology
            .edges
            .iter()
            .map(|e| (e.vertices[0], e.vertices[1]))
            .chain(
                topology
                    .edges
                    .iter()
                    .filter_map(|e| e.right.map(|r| (e.left.opposite, r.opposite))),
            );
        let pattern = BlockPattern::new(x.len(), pairs);
        let at_rest: Vec<DVec3> = mesh
            .positions
            .iter()
            .map(|p| glam::DQuat::from_rotation_y(0.3) * *p)
            .collect();
        let rest = lengths(&mesh.positions, &topology);
        membrane.update(&rest, &modulus);
        let mut values = vec![0.0; pattern.nonzeros()];
        membrane.hessian(&at_rest, &rest, &pattern, &mut values);
        let v: Vec<f64> = (0..3 * x.len()).map(|_| rng.centred()).collect();
        let mut hv = vec![0.0; v.len()];
        pattern.multiply(&values, &v, &mut hv);
        let shifted = |t: f64| -> Vec<DVec3> {
            at_rest
                .iter()
                .enumerate()
                .map(|(i, p)| *p + DVec3::from_slice(&v[3 * i..3 * i + 3]) * t)
                .collect()
        };
        let (mut gp, mut gm) = (vec![DVec3::ZERO; x.len()], vec![DVec3::ZERO; x.len()]);
        membrane.energy(&shifted(h), &rest, Some(&mut gp));
        membrane.energy(&shifted(-h), &rest, Some(&mut gm));
        for i in 0..x.len() {
            let fd = (gp[i] - gm[i]) / (2.0 * h);
            let analytic = DVec3::from_slice(&hv[3 * i..3 * i + 3]);
            assert!(
                (fd - analytic).length() < 1e-5 * (1.0 + fd.length()),
                "particle {i}: {fd} vs {analytic}"
            );
        }
    }
}

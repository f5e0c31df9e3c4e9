//! The elastic energy of one organ (paper §5.1) and its derivatives:
//!
//! `E = sum_edges 1/2 ks (|xi - xj| - L0)^2 + sum_hinges 1/2 kb (theta - theta0)^2`
//!
//! plus, while organs touch, a one-sided contact penalty
//! `1/2 kc min(0, (x - p) . n - offset)^2` that keeps a particle on the right
//! side of its tracking point `p` on a neighbouring organ (see `Contact`).
//!
//! The Hessian is made positive semi-definite element by element: a spring
//! keeps its transverse term only while stretched (`|d| > L0`), and a hinge
//! uses the Gauss–Newton term `kb grad(theta) grad(theta)^T`, which is exact
//! where `theta = theta0` and never indefinite.

use glam::{DMat3, DVec3};

use anthesis_mesh::Topology;

use crate::hinge::{dihedral_angle, dihedral_gradient, hinge_is_degenerate};
use crate::membrane::EdgeSmoothedMembrane;
use crate::pattern::BlockPattern;

/// A particle held on one side of a neighbouring organ: the particle should
/// satisfy `(x - point) . normal >= offset`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// The held particle's index in this organ.
    pub particle: u32,
    /// The tracking point on the neighbouring organ's surface, in the same
    /// frame as the particle positions (world, in the simulation).
    pub point: DVec3,
    /// Unit normal at `point`, pointing to the side the particle must stay on.
    pub normal: DVec3,
    /// How far past `point` along `normal` the particle must stay, in
    /// lengths of the positions (the project's collision offset).
    pub offset: f64,
    /// The share of the contact stiffness this contact carries: 1 for a
    /// particle held off a neighbour; a two-sided contact's reaction spreads
    /// the stiffness over the neighbour triangle's corners by the contact
    /// point's barycentric weights, so its forces sum to the contact's,
    /// opposite.
    pub weight: f64,
}

impl Contact {
    /// How far the particle is short of its allowed side (positive when it
    /// must move), for particle position `x`.
    pub fn violation(&self, x: DVec3) -> f64 {
        self.offset - (x - self.point).dot(self.normal)
    }
}

/// Rest state and stiffness of one organ's springs and hinges.
#[derive(Debug, Clone, PartialEq)]
pub struct Elastic {
    /// Particle pairs of every edge (topology order).
    pub edges: Vec<[u32; 2]>,
    /// Rest length `L0` per edge, in the units of the positions; growth
    /// changes them each step.
    pub rest_lengths: Vec<f64>,
    /// Spring stiffness `ks` per edge (energy per length squared).
    pub stretch_stiffness: Vec<f64>,
    /// Interior edges as hinges `[i, j, k, l]` with their edge index.
    pub hinges: Vec<([u32; 4], u32)>,
    /// Rest dihedral angle per edge (boundary edges hold 0 and are unused).
    pub rest_angles: Vec<f64>,
    /// Bend stiffness per edge (boundary edges unused).
    pub bend_stiffness: Vec<f64>,
    /// Stiffness of the contact penalty.
    pub contact_stiffness: f64,
    /// Particles held at a point by zero-length springs of
    /// `anchor_stiffness` (the simulation holds an organ's base particles
    /// where the receptacle and the joint schedule put them).
    pub anchors: Vec<(u32, DVec3)>,
    /// Stiffness of the anchor springs (0 = no anchoring).
    pub anchor_stiffness: f64,
    /// The consistent model's membrane; `None` for the paper's springs
    /// (`stretch_stiffness` then holds their stiffness; either way it sets
    /// the force and contact scales).
    pub membrane: Option<EdgeSmoothedMembrane>,
}

impl Elastic {
    /// An organ at rest in its current shape: rest lengths and rest angles
    /// measured from `positions`, unit stiffness, no contact stiffness.
    pub fn at_rest(positions: &[DVec3], topology: &Topology) -> Elastic {
        let edges: Vec<[u32; 2]> = topology.edges.iter().map(|e| e.vertices).collect();
        let hinges: Vec<([u32; 4], u32)> = topology
            .edges
            .iter()
            .enumerate()
            .filter_map(|(i, e)| e.hinge().map(|h| (h, i as u32)))
            .collect();
        let rest_lengths = edges
            .iter()
            .map(|&[a, b]| (positions[a as usize] - positions[b as usize]).length())
            .collect();
        let mut rest_angles = vec![0.0; edges.len()];
        for &(stencil, edge) in &hinges {
            rest_angles[edge as usize] = dihedral_angle(stencil.map(|p| positions[p as usize]));
        }
        Elastic {
            stretch_stiffness: vec![1.0; edges.len()],
            bend_stiffness: vec![1.0; edges.len()],
            edges,
            rest_lengths,
            hinges,
            rest_angles,
            contact_stiffness: 0.0,
            anchors: Vec::new(),
            anchor_stiffness: 0.0,
            membrane: None,
        }
    }

    /// The springs that carry the stretching energy: every edge, or none
    /// when the edge-smoothed membrane does.
    fn springs(&self) -> impl Iterator<Item = (usize, &[u32; 2])> + '_ {
        let count = if self.membrane.is_some() {
            0
        } else {
            self.edges.len()
        };
        self.edges.iter().enumerate().take(count)
    }

    /// Particle pairs coupled by the Hessian (edges and hinge wings).
    pub fn coupled_pairs(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        let edge_pairs = self.edges.iter().map(|&[a, b]| (a, b));
        let wing_pairs = self.hinges.iter().map(|&([_, _, k, l], _)| (k, l));
        edge_pairs.chain(wing_pairs)
    }

    /// The Hessian's sparsity pattern over `particles` particles (the
    /// blocks of [`Elastic::coupled_pairs`]), with the blocks of every
    /// edge's stencil `[i, j, k, l]` looked up once for assembly.
    pub fn pattern(&self, particles: usize) -> BlockPattern {
        BlockPattern::new(particles, self.coupled_pairs()).with_stencils(self.edge_stencils())
    }

    /// Per edge, the particles its membrane domain, spring or hinge couples:
    /// the edge's ends, then the opposite particles the domain or hinge
    /// has (`u32::MAX` for none).
    fn edge_stencils(&self) -> Vec<[u32; 4]> {
        let mut stencils: Vec<[u32; 4]> = match &self.membrane {
            Some(m) => m.stencils().collect(),
            None => self
                .edges
                .iter()
                .map(|&[a, b]| [a, b, u32::MAX, u32::MAX])
                .collect(),
        };
        for &(stencil, edge) in &self.hinges {
            if let Some(s) = stencils.get_mut(edge as usize) {
                *s = stencil;
            }
        }
        stencils
    }

    /// A force that sets the scale of the convergence test: the mean over
    /// edges of `ks * L0`, the force an edge exerts at 100 % strain.
    pub fn force_scale(&self) -> f64 {
        let n = self.edges.len().max(1) as f64;
        let sum: f64 = self
            .stretch_stiffness
            .iter()
            .zip(&self.rest_lengths)
            .map(|(k, l)| k * l)
            .sum();
        (sum / n).max(f64::MIN_POSITIVE)
    }

    /// A length of the organ's own size, whatever its mesh: the root of the
    /// sum of the squared rest lengths (about the square root of three times
    /// its area).
    pub fn size(&self) -> f64 {
        self.rest_lengths.iter().map(|l| l * l).sum::<f64>().sqrt()
    }

    /// The total energy `E` (springs or membrane, hinges, anchors and the
    /// `contacts`' penalties) at particle positions `x`.
    pub fn energy(&self, x: &[DVec3], contacts: &[Contact]) -> f64 {
        let e = self.elastic_energy(x);
        if e == f64::INFINITY {
            return e;
        }
        self.add_penalty_energy(x, contacts, e)
    }

    /// The energy of the membrane or springs and the hinges alone (no
    /// contacts, no anchors): the first part of [`Elastic::energy`], and
    /// the energy [`Elastic::elastic_energy_and_gradient`] computes, bit
    /// for bit.
    pub fn elastic_energy(&self, x: &[DVec3]) -> f64 {
        let mut e = 0.0;
        if let Some(m) = &self.membrane {
            e += m.energy(x, &self.rest_lengths, None);
        }
        for (idx, &[a, b]) in self.springs() {
            let stretch = (x[a as usize] - x[b as usize]).length() - self.rest_lengths[idx];
            e += 0.5 * self.stretch_stiffness[idx] * stretch * stretch;
        }
        for &(stencil, edge) in &self.hinges {
            let xs = stencil.map(|p| x[p as usize]);
            if hinge_is_degenerate(xs) {
                // A collapsed triangle has no normal and no angle: refuse the
                // shape, so a line search backs off instead of stepping here.
                return f64::INFINITY;
            }
            let d = angle_difference(dihedral_angle(xs), self.rest_angles[edge as usize]);
            e += 0.5 * self.bend_stiffness[edge as usize] * d * d;
        }
        e
    }

    /// Adds the `contacts`' penalties and the anchors to `energy` at `x`
    /// (the rest of [`Elastic::energy`]).
    pub fn add_penalty_energy(&self, x: &[DVec3], contacts: &[Contact], energy: f64) -> f64 {
        let mut e = energy;
        for c in contacts {
            let v = c.violation(x[c.particle as usize]);
            if v > 0.0 {
                e += 0.5 * (self.contact_stiffness * c.weight) * v * v;
            }
        }
        for &(p, target) in &self.anchors {
            e += 0.5 * self.anchor_stiffness * (x[p as usize] - target).length_squared();
        }
        e
    }

    /// Writes the gradient into `g` (one vector per particle).
    pub fn gradient(&self, x: &[DVec3], contacts: &[Contact], g: &mut [DVec3]) {
        self.energy_and_gradient(x, contacts, g);
    }

    /// The energy at `x`, with the gradient written into `g`, in one pass
    /// over the elements (the springs' lengths and the hinges' angles are
    /// computed once for both). The energy is infinite, as in
    /// [`Elastic::energy`], when a triangle has collapsed; `g` is then
    /// meaningless.
    pub fn energy_and_gradient(&self, x: &[DVec3], contacts: &[Contact], g: &mut [DVec3]) -> f64 {
        let elastic = self.elastic_energy_and_gradient(x, g);
        self.add_penalties(x, contacts, elastic, g)
    }

    /// The first part of [`Elastic::energy_and_gradient`]: the energy of
    /// the membrane or springs and the hinges alone (no contacts, no
    /// anchors), with its gradient written into `g`; infinite when a
    /// triangle has collapsed. [`Elastic::add_penalties`] completes it, to
    /// the same bits as one call of [`Elastic::energy_and_gradient`].
    pub fn elastic_energy_and_gradient(&self, x: &[DVec3], g: &mut [DVec3]) -> f64 {
        g.iter_mut().for_each(|v| *v = DVec3::ZERO);
        let mut e = 0.0;
        if let Some(m) = &self.membrane {
            e += m.energy(x, &self.rest_lengths, Some(g));
        }
        self.add_spring_energy_and_gradient(x, &mut e, g);
        let mut degenerate = false;
        for &(stencil, edge) in &self.hinges {
            self.add_hinge_energy_and_gradient(x, stencil, edge, &mut e, g, &mut degenerate);
        }
        if degenerate { f64::INFINITY } else { e }
    }

    /// Adds one hinge's bending energy to `e` and its gradient to `g`
    /// (`degenerate` set if either triangle has collapsed); returns the
    /// angle's gradient for the Hessian.
    fn add_hinge_energy_and_gradient(
        &self,
        x: &[DVec3],
        stencil: [u32; 4],
        edge: u32,
        e: &mut f64,
        g: &mut [DVec3],
        degenerate: &mut bool,
    ) -> [DVec3; 4] {
        let xs = stencil.map(|p| x[p as usize]);
        *degenerate |= hinge_is_degenerate(xs);
        let k = self.bend_stiffness[edge as usize];
        let d = angle_difference(dihedral_angle(xs), self.rest_angles[edge as usize]);
        *e += 0.5 * k * d * d;
        let dtheta = dihedral_gradient(xs);
        for (p, grad) in stencil.iter().zip(dtheta) {
            g[*p as usize] += grad * (k * d);
        }
        dtheta
    }

    /// Adds the `contacts`' penalties and the anchors to `energy` and to
    /// the gradient `g` at `x`, in the order [`Elastic::energy_and_gradient`]
    /// adds them after [`Elastic::elastic_energy_and_gradient`].
    pub fn add_penalties(
        &self,
        x: &[DVec3],
        contacts: &[Contact],
        energy: f64,
        g: &mut [DVec3],
    ) -> f64 {
        let mut e = energy;
        for c in contacts {
            let v = c.violation(x[c.particle as usize]);
            if v > 0.0 {
                let k = self.contact_stiffness * c.weight;
                e += 0.5 * k * v * v;
                g[c.particle as usize] -= c.normal * (k * v);
            }
        }
        for &(p, target) in &self.anchors {
            let offset = x[p as usize] - target;
            e += 0.5 * self.anchor_stiffness * offset.length_squared();
            g[p as usize] += offset * self.anchor_stiffness;
        }
        // A collapsed triangle's infinity stays (a NaN penalty must not hide it).
        if energy == f64::INFINITY { energy } else { e }
    }

    /// Writes the PSD Hessian approximation into `values` (upper CSC layout
    /// of `pattern`, which must come from [`Elastic::coupled_pairs`]).
    pub fn hessian(
        &self,
        x: &[DVec3],
        contacts: &[Contact],
        pattern: &BlockPattern,
        values: &mut [f64],
    ) {
        values.iter_mut().for_each(|v| *v = 0.0);
        if let Some(m) = &self.membrane {
            m.hessian(x, &self.rest_lengths, pattern, values);
        }
        self.add_spring_hessian(x, pattern, values);
        for &(stencil, edge) in &self.hinges {
            let dtheta = dihedral_gradient(stencil.map(|p| x[p as usize]));
            self.add_hinge_hessian(stencil, edge, &dtheta, pattern, values);
        }
        self.add_penalty_hessian(x, contacts, pattern, values);
    }

    /// [`Elastic::elastic_energy_and_gradient`] and the elastic part of
    /// [`Elastic::hessian`] (no contacts, no anchors; `values` overwritten)
    /// in one pass: the membrane's strains and stresses and the hinges'
    /// angle gradients computed once for both, the same bits as the
    /// separate calls. [`Elastic::add_penalties`] and
    /// [`Elastic::add_penalty_hessian`] complete them.
    pub fn elastic_energy_gradient_and_hessian(
        &self,
        x: &[DVec3],
        g: &mut [DVec3],
        pattern: &BlockPattern,
        values: &mut [f64],
    ) -> f64 {
        g.iter_mut().for_each(|v| *v = DVec3::ZERO);
        values.iter_mut().for_each(|v| *v = 0.0);
        let mut e = 0.0;
        if let Some(m) = &self.membrane {
            e += m.energy_gradient_and_hessian(x, &self.rest_lengths, g, pattern, values);
        }
        self.add_spring_energy_and_gradient(x, &mut e, g);
        self.add_spring_hessian(x, pattern, values);
        let mut degenerate = false;
        for &(stencil, edge) in &self.hinges {
            let dtheta =
                self.add_hinge_energy_and_gradient(x, stencil, edge, &mut e, g, &mut degenerate);
            self.add_hinge_hessian(stencil, edge, &dtheta, pattern, values);
        }
        if degenerate { f64::INFINITY } else { e }
    }

    /// Adds the springs' energy to `e` (one spring at a time) and their
    /// gradient to `g` (none with the membrane).
    #[inline(always)]
    fn add_spring_energy_and_gradient(&self, x: &[DVec3], e: &mut f64, g: &mut [DVec3]) {
        for (idx, &[a, b]) in self.springs() {
            let d = x[a as usize] - x[b as usize];
            let len = d.length();
            let stretch = len - self.rest_lengths[idx];
            let k = self.stretch_stiffness[idx];
            *e += 0.5 * k * stretch * stretch;
            let f = d * (k * stretch / len);
            g[a as usize] += f;
            g[b as usize] -= f;
        }
    }

    /// The springs' Hessian blocks (none with the membrane).
    fn add_spring_hessian(&self, x: &[DVec3], pattern: &BlockPattern, values: &mut [f64]) {
        for (idx, &[a, b]) in self.springs() {
            let d = x[a as usize] - x[b as usize];
            let len = d.length();
            let n = d / len;
            let nn = outer(n, n);
            let transverse = (1.0 - self.rest_lengths[idx] / len).max(0.0);
            let block = (nn + (DMat3::IDENTITY - nn) * transverse) * self.stretch_stiffness[idx];
            let slots = pattern.stencil(idx, [a, b, u32::MAX, u32::MAX]);
            BlockPattern::add_at(values, slots.slot(0, 0), &block);
            BlockPattern::add_at(values, slots.slot(1, 1), &block);
            BlockPattern::add_at(values, slots.slot(0, 1), &(-block));
        }
    }

    /// The Gauss–Newton blocks `kb ∇θ ∇θᵀ` of the hinge `stencil` of edge
    /// `edge`, with its angle's gradient `dtheta`.
    #[inline(always)]
    fn add_hinge_hessian(
        &self,
        stencil: [u32; 4],
        edge: u32,
        dtheta: &[DVec3; 4],
        pattern: &BlockPattern,
        values: &mut [f64],
    ) {
        let k = self.bend_stiffness[edge as usize];
        let slots = pattern.stencil(edge as usize, stencil);
        for r in 0..4 {
            for c in r..4 {
                let block = outer(dtheta[r], dtheta[c]) * k;
                BlockPattern::add_at(values, slots.slot(r, c), &block);
            }
        }
    }

    /// Adds the Hessian blocks of the violated `contacts`' penalties and
    /// of the anchors (the rest of [`Elastic::hessian`]).
    pub fn add_penalty_hessian(
        &self,
        x: &[DVec3],
        contacts: &[Contact],
        pattern: &BlockPattern,
        values: &mut [f64],
    ) {
        for c in contacts {
            if c.violation(x[c.particle as usize]) > 0.0 {
                let block = outer(c.normal, c.normal) * (self.contact_stiffness * c.weight);
                pattern.add_block(values, c.particle, c.particle, &block);
            }
        }
        let anchor = DMat3::IDENTITY * self.anchor_stiffness;
        for &(p, _) in &self.anchors {
            pattern.add_block(values, p, p, &anchor);
        }
    }
}

/// `theta - rest`, wrapped into `[-pi, pi)`: a hinge folding through a
/// half-turn must not make the energy jump.
pub fn angle_difference(theta: f64, rest: f64) -> f64 {
    use std::f64::consts::PI;
    (theta - rest + PI).rem_euclid(2.0 * PI) - PI
}

/// The outer product `u v^T`.
pub(crate) fn outer(u: DVec3, v: DVec3) -> DMat3 {
    DMat3::from_cols(u * v.x, u * v.y, u * v.z)
}

/// The area associated with each edge: the mean area of its (one or two)
/// triangles. Stiffness is this area times the user's K times the map value
/// (paper §5.1).
pub fn edge_areas(positions: &[DVec3], triangles: &[[u32; 3]], topology: &Topology) -> Vec<f64> {
    let mut areas = Vec::new();
    edge_areas_into(positions, triangles, topology, &mut Vec::new(), &mut areas);
    areas
}

/// [`edge_areas`] into `areas`, with each triangle's area computed once into
/// `triangle_areas` (both buffers reused from call to call).
pub fn edge_areas_into(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    topology: &Topology,
    triangle_areas: &mut Vec<f64>,
    areas: &mut Vec<f64>,
) {
    triangle_areas.clear();
    triangle_areas.extend(triangles.iter().map(|&[a, b, c]| {
        let (a, b, c) = (
            positions[a as usize],
            positions[b as usize],
            positions[c as usize],
        );
        0.5 * (b - a).cross(c - a).length()
    }));
    areas.clear();
    areas.extend(topology.edges.iter().map(|e| {
        let left = triangle_areas[e.left.triangle as usize];
        match e.right {
            Some(r) => 0.5 * (left + triangle_areas[r.triangle as usize]),
            None => left,
        }
    }));
}

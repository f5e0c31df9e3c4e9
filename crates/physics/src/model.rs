//! Which discretisation of the petal's growth and mechanics a simulation
//! uses, and the stiffness of each element under it.
//!
//! Both models minimise stretching plus bending energy (paper §5.1); they
//! differ in how the pieces are discretised:
//!
//! | | [`Model::Consistent`] (default) | [`Model::Paper`] |
//! |---|---|---|
//! | rest angles | [`BendRule::Curvature`] | [`BendRule::InnerTriangle`] (eq. 4) |
//! | stretching | edge-smoothed membrane ([`crate::membrane`]) | edge springs, `ks = area · Ks · map` |
//! | bending weight | `kb = (3/16) Kb h² · |e|² / A_e · map` | `kb = A_e · Kb · map` |
//!
//! `A_e` is the mean area of an edge's triangles, `|e|` its rest length and
//! `h` the organ's mean edge in the bud. The consistent bending weight is
//! the discretisation of `∫ Kb h² κ²` whose hinge angle `θ ≈ κ · (distance
//! across the hinge) ∝ κ · A_e / |e|` gives every hinge the same energy
//! per curvature, whatever the triangles' shape (the paper's area weight
//! over-weights hinges whose triangles are long across the edge). The
//! constant `3/16` makes both weights equal on equilateral triangles of edge
//! `h`, and the membrane's Lamé parameter `μ = λ = (3/16) Ks h²` gives the
//! springs' energy under isotropic strain there, so Table 1's `Ks` and `Kb`
//! mean the same in both models on the paper's meshes. `h` is the organ's
//! own, so the ratio of bending to stretching, which alone sets the shape,
//! does not change when the mesh is refined.

use crate::growth::BendRule;

/// The discretisation of the growth and mechanics (see the module
/// documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Model {
    /// Converges under mesh refinement; the default.
    #[default]
    Consistent,
    /// The paper's rules, kept for comparison.
    Paper,
}

impl Model {
    /// How inner growth becomes rest angles.
    pub fn bend_rule(self) -> BendRule {
        match self {
            Model::Consistent => BendRule::Curvature,
            Model::Paper => BendRule::InnerTriangle,
        }
    }

    /// Whether stretching is the edge-smoothed membrane (else springs).
    pub fn smoothed_membrane(self) -> bool {
        self == Model::Consistent
    }

    /// The bend stiffness of a hinge: `bend` is the template's `Kb` times
    /// the bend map value, `rest_length` the edge's rest length, `edge_area`
    /// the mean area of its two triangles and `mesh_edge` the organ's mean
    /// edge in the bud.
    pub fn hinge_stiffness(
        self,
        bend: f64,
        rest_length: f64,
        edge_area: f64,
        mesh_edge: f64,
    ) -> f64 {
        match self {
            Model::Paper => edge_area * bend,
            Model::Consistent => {
                REFERENCE * bend * mesh_edge * mesh_edge * rest_length * rest_length
                    / edge_area.max(f64::MIN_POSITIVE)
            }
        }
    }

    /// The edge-smoothed membrane's Lamé parameter `μ = λ` of an edge's
    /// domain: `stretch` is the template's `Ks` times the stretch map value.
    pub fn membrane_modulus(stretch: f64, mesh_edge: f64) -> f64 {
        REFERENCE * stretch * mesh_edge * mesh_edge
    }
}

/// `3/16`: equates the consistent weights with the paper's on equilateral
/// triangles (see the module documentation).
const REFERENCE: f64 = 3.0 / 16.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_models_agree_on_equilateral_triangles_of_the_mesh_edge() {
        let h = 1.3;
        let area = 3f64.sqrt() / 4.0 * h * h;
        let paper = Model::Paper.hinge_stiffness(20.0, h, area, h);
        let consistent = Model::Consistent.hinge_stiffness(20.0, h, area, h);
        assert!((paper - consistent).abs() < 1e-12 * paper);
        // Springs ks = area Ks on three half-shared edges per triangle give
        // ks L² / 2 per edge under unit isotropic strain; the membrane gives
        // 4 μ ε² over a domain of two thirds of that area per edge.
        let ks = area * 20.0;
        let mu = Model::membrane_modulus(20.0, h);
        assert!((0.5 * ks * h * h - 4.0 * mu * (2.0 / 3.0) * area).abs() < 1e-12 * ks);
    }

    #[test]
    fn the_consistent_hinges_are_a_plate_of_bending_stiffness_three_eighths_kb_h_squared() {
        // Equilateral triangles of edge h wrapped on a cylinder of
        // curvature k: the hinges hold (3/16) Kb h² k² per area, the
        // ½ D k² of a plate with D = (3/8) Kb h² (so, with the membrane's
        // Y = Ks h² / 2 and ν = 1/3, a bending thickness √(8 Kb/Ks)).
        use crate::hinge::dihedral_angle;
        use glam::DVec3;
        let (h, k, kb, n) = (0.5, 0.05, 3.0, 40usize);
        let lattice = |i: usize, j: usize| {
            let x = (i as f64 + 0.5 * (j % 2) as f64) * h;
            let y = j as f64 * h * 3f64.sqrt() / 2.0;
            DVec3::new((k * x).sin() / k, y, (1.0 - (k * x).cos()) / k)
        };
        let area = 3f64.sqrt() / 4.0 * h * h;
        let mut energy = 0.0;
        let mut hinges = 0usize;
        // Each interior hinge of the lattice once: the edge (p, q) with its
        // opposite corners (left, right).
        for j in 1..n - 1 {
            for i in 1..n - 1 {
                let o = j % 2;
                let p = lattice(i, j);
                let stencils = [
                    // along x: the corners above and below
                    [
                        p,
                        lattice(i + 1, j),
                        lattice(i + o, j + 1),
                        lattice(i + o, j - 1),
                    ],
                    // up to the right, and up to the left
                    [
                        p,
                        lattice(i + o, j + 1),
                        lattice(i + 1, j),
                        lattice(i + o - 1, j + 1),
                    ],
                    [
                        p,
                        lattice(i + o - 1, j + 1),
                        lattice(i + o, j + 1),
                        lattice(i - 1, j),
                    ],
                ];
                for x in stencils {
                    let theta = dihedral_angle(x);
                    let stiffness = Model::Consistent.hinge_stiffness(kb, h, area, h);
                    energy += 0.5 * stiffness * theta * theta;
                    hinges += 1;
                }
            }
        }
        // Three hinges per two triangles.
        let per_area = energy / (hinges as f64 * 2.0 / 3.0 * area);
        let plate = 0.5 * (3.0 / 8.0) * kb * h * h * k * k;
        assert!((per_area / plate - 1.0).abs() < 0.01, "{per_area} {plate}");
    }

    #[test]
    fn the_consistent_weight_depends_on_the_hinge_shape_as_the_curvature_does() {
        // A hinge twice as long with the same area has triangles half as
        // deep: the same curvature makes half the angle, so it needs four
        // times the weight to hold the same energy.
        let a = Model::Consistent.hinge_stiffness(1.0, 1.0, 0.5, 1.0);
        let b = Model::Consistent.hinge_stiffness(1.0, 2.0, 0.5, 1.0);
        assert!((b / a - 4.0).abs() < 1e-12);
    }
}

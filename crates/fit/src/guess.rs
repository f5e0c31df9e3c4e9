//! The closed-form first guess: growth maps read off the target's
//! stretches and curvatures relative to the bud, as if every step's growth
//! were realised exactly (no elastic frustration, no collisions).
//!
//! Growth at map value `m` multiplies lengths by `1 + dg m` per step, from
//! the shape the organ has, so a stretch `λ` after `N` steps asks for
//! `m = (λ^(1/N) − 1) / dg`. The curvature rule adds
//! `dg (m_in − m) / thickness` to the curvature along (and across) the
//! growth direction per step and carries the curvature the organ has, so a
//! change of curvature `Δκ` asks for `m_in − m = Δκ thickness / (N dg)`.
//! Stretches are measured per triangle along and across the growth
//! direction (+v), curvature changes per interior edge (the change of its
//! dihedral angle over the distance between its triangles' centroids),
//! and both are projected onto the hat basis by least squares.

use anthesis_mesh::{Mesh, Topology};
use anthesis_physics::growth::growth_direction;
use anthesis_physics::hinge::dihedral_angle;
use glam::{DVec2, DVec3};

use anthesis_maps::{KeyedMaps, MapKind};

use crate::basis::{ANGLE, Layout};
use crate::dense::solve;

/// What the guess needs of the organ.
pub struct Organ<'a> {
    /// The bud's mesh (UVs and triangles).
    pub mesh: &'a Mesh,
    /// Its edges.
    pub topology: &'a Topology,
    /// The bud's positions (any frame).
    pub bud: &'a [DVec3],
    /// The template's growth scale.
    pub dg: f64,
    /// The template's thickness.
    pub thickness: f64,
    /// The growth steps of a run.
    pub steps: u32,
}

/// The parameters of the guess for `target` (same vertices as the bud).
pub fn guess(organ: &Organ<'_>, target: &[DVec3], layout: &Layout) -> Vec<f64> {
    let grid = layout.growth;
    let n = f64::from(organ.steps.max(1));
    let dg = organ.dg;
    let rate = |stretch: f64| (stretch.max(1e-6).powf(1.0 / n) - 1.0) / dg;

    // Stretches per triangle.
    let mut e_rows = Vec::new();
    let mut w_rows = Vec::new();
    for tri in &organ.mesh.triangles {
        let uv = tri.map(|i| organ.mesh.uvs[i as usize]);
        let x = tri.map(|i| organ.bud[i as usize]);
        let y = tri.map(|i| target[i as usize]);
        let Some((along, across)) = stretches(x, y, uv) else {
            continue;
        };
        let area = 0.5 * (x[1] - x[0]).cross(x[2] - x[0]).length();
        let centre = (uv[0] + uv[1] + uv[2]) / 3.0;
        let weights = grid.weights(centre);
        e_rows.push((weights.clone(), rate(along), area));
        w_rows.push((weights, rate(across), area));
    }
    let e = project(grid.len(), &e_rows);
    let w = project(grid.len(), &w_rows);

    // Curvature changes per interior edge: three fields (along-along,
    // along-across, across-across) fitted to the normal curvature across
    // each edge.
    let mut k_rows = Vec::new();
    for edge in &organ.topology.edges {
        let Some(hinge) = edge.hinge() else {
            continue;
        };
        let change = curvature(hinge.map(|i| target[i as usize]))
            - curvature(hinge.map(|i| organ.bud[i as usize]));
        if !change.is_finite() {
            continue;
        }
        let left = organ.mesh.triangles[edge.left.triangle as usize];
        let y = left.map(|i| target[i as usize]);
        let uv = left.map(|i| organ.mesh.uvs[i as usize]);
        let normal = (y[1] - y[0]).cross(y[2] - y[0]).normalize_or_zero();
        let along = growth_direction(y, uv, DVec2::Y, normal);
        let across = normal.cross(along);
        let [a, b] = edge.vertices.map(|i| target[i as usize]);
        let t = normal.cross(b - a).normalize_or_zero();
        let (ta, tc) = (t.dot(along), t.dot(across));
        let mid_uv = 0.5
            * (organ.mesh.uvs[edge.vertices[0] as usize]
                + organ.mesh.uvs[edge.vertices[1] as usize]);
        let phi = grid.weights(mid_uv);
        let mut row = Vec::with_capacity(3 * grid.len());
        row.extend(phi.iter().map(|f| f * ta * ta));
        row.extend(phi.iter().map(|f| f * 2.0 * ta * tc));
        row.extend(phi.iter().map(|f| f * tc * tc));
        let length = (b - a).length();
        k_rows.push((row, change, length));
    }
    let k = project(3 * grid.len(), &k_rows);
    let to_rate = organ.thickness / (n * dg);

    let mut p = vec![0.0; layout.len()];
    for key in 0..layout.key_steps.len() {
        for (i, node) in layout.range(key, 0).enumerate() {
            let e_in = e[i] + k[i] * to_rate;
            let w_in = w[i] + k[2 * grid.len() + i] * to_rate;
            p[node] = e[i];
            p[layout.range(key, 1).start + i] = w[i];
            p[layout.range(key, 2).start + i] = e_in;
            p[layout.range(key, 3).start + i] = w_in;
        }
        for node in layout.range(key, ANGLE) {
            p[node] = 0.0;
        }
    }
    clamp(layout, &mut p);
    p
}

/// Puts every parameter within its field's bounds.
pub fn clamp(layout: &Layout, p: &mut [f64]) {
    for (i, value) in p.iter_mut().enumerate() {
        let (lo, hi) = Layout::bounds(layout.field_of(i));
        *value = if value.is_finite() {
            value.clamp(lo, hi)
        } else {
            0.0
        };
    }
}

/// The stretch of triangle `x` into `y` along the growth direction (+v
/// mapped through the bud triangle's UV layout) and across it.
fn stretches(x: [DVec3; 3], y: [DVec3; 3], uv: [DVec2; 3]) -> Option<(f64, f64)> {
    let du1 = uv[1] - uv[0];
    let du2 = uv[2] - uv[0];
    let det = du1.perp_dot(du2);
    if det.abs() < 1e-14 {
        return None;
    }
    // The 3D image of a UV vector `d` on a triangle `p`.
    let image = |p: [DVec3; 3], d: DVec2| {
        let a = d.perp_dot(du2) / det;
        let b = du1.perp_dot(d) / det;
        (p[1] - p[0]) * a + (p[2] - p[0]) * b
    };
    let normal = (x[1] - x[0]).cross(x[2] - x[0]).normalize_or_zero();
    let along = growth_direction(x, uv, DVec2::Y, normal);
    let across = normal.cross(along);
    // The UV vectors whose images on the bud are `along` and `across`.
    let uv_of = |v: DVec3| {
        let e1 = x[1] - x[0];
        let e2 = x[2] - x[0];
        // v = e1 a + e2 b in the least-squares sense.
        let (g11, g12, g22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
        let (r1, r2) = (e1.dot(v), e2.dot(v));
        let g = g11 * g22 - g12 * g12;
        if g.abs() < 1e-300 {
            return None;
        }
        let a = (r1 * g22 - r2 * g12) / g;
        let b = (r2 * g11 - r1 * g12) / g;
        Some(du1 * a + du2 * b)
    };
    let da = uv_of(along)?;
    let dc = uv_of(across)?;
    let (la, lc) = (image(x, da).length(), image(x, dc).length());
    if la <= 0.0 || lc <= 0.0 {
        return None;
    }
    Some((image(y, da).length() / la, image(y, dc).length() / lc))
}

/// The normal curvature across a hinge: its dihedral angle over the
/// distance between its two triangles' centroids across the edge.
fn curvature(hinge: [DVec3; 4]) -> f64 {
    let [i, j, k, l] = hinge;
    let edge = (j - i).length();
    if edge <= 0.0 {
        return f64::NAN;
    }
    let area = |a: DVec3, b: DVec3, c: DVec3| 0.5 * (b - a).cross(c - a).length();
    let distance = 2.0 * (area(i, j, k) + area(j, i, l)) / (3.0 * edge);
    if distance <= 0.0 {
        return f64::NAN;
    }
    dihedral_angle(hinge) / distance
}

/// Least-squares node values of a field from `rows` (basis weights, value,
/// weight), with a small pull of each node towards the weighted mean so
/// that nodes no row reaches stay defined.
fn project(unknowns: usize, rows: &[(Vec<f64>, f64, f64)]) -> Vec<f64> {
    let mut a = vec![0.0; unknowns * unknowns];
    let mut b = vec![0.0; unknowns];
    let (mut sum, mut total) = (0.0, 0.0);
    for (phi, value, weight) in rows {
        for r in 0..unknowns {
            if phi[r] == 0.0 {
                continue;
            }
            b[r] += weight * phi[r] * value;
            for c in 0..unknowns {
                a[r * unknowns + c] += weight * phi[r] * phi[c];
            }
        }
        sum += weight * value;
        total += weight;
    }
    let mean = if total > 0.0 { sum / total } else { 0.0 };
    let trace: f64 = (0..unknowns).map(|i| a[i * unknowns + i]).sum();
    let ridge = 1e-4 * trace / unknowns.max(1) as f64 + 1e-300;
    for i in 0..unknowns {
        a[i * unknowns + i] += ridge;
        b[i] += ridge * mean;
    }
    solve(unknowns, a, b).unwrap_or_else(|| vec![mean; unknowns])
}

/// The parameters nearest (least squares over a 24 × 24 grid of UV points)
/// to the growth maps `maps` as they are at each key's step: the project's
/// own maps in the fit's basis, the other start the fit tries.
pub fn from_maps(layout: &Layout, maps: &KeyedMaps) -> Vec<f64> {
    const SAMPLES: usize = 24;
    let points: Vec<DVec2> = (0..SAMPLES * SAMPLES)
        .map(|i| {
            DVec2::new(
                ((i % SAMPLES) as f64 + 0.5) / SAMPLES as f64,
                ((i / SAMPLES) as f64 + 0.5) / SAMPLES as f64,
            )
        })
        .collect();
    let kinds = [
        MapKind::EGrowth,
        MapKind::WGrowth,
        MapKind::EGrowthIn,
        MapKind::WGrowthIn,
    ];
    let mut p = vec![0.0; layout.len()];
    for (key, &step) in layout.key_steps.iter().enumerate() {
        let step = f64::from(step);
        for (field, kind) in kinds.iter().enumerate() {
            let rows: Vec<(Vec<f64>, f64, f64)> = points
                .iter()
                .map(|&uv| {
                    let value = maps.scalar_triangle_value_at(*kind, step, [uv, uv, uv]);
                    (layout.growth.weights(uv), value, 1.0)
                })
                .collect();
            let values = project(layout.growth.len(), &rows);
            p[layout.range(key, field)].copy_from_slice(&values);
        }
        if !layout.direction.is_empty() {
            let rows: Vec<(Vec<f64>, f64, f64)> = points
                .iter()
                .map(|&uv| {
                    let d = maps.direction_triangle_value_at(step, [uv, uv, uv]);
                    (layout.direction.weights(uv), d.x.atan2(d.y), 1.0)
                })
                .collect();
            let values = project(layout.direction.len(), &rows);
            p[layout.range(key, ANGLE)].copy_from_slice(&values);
        }
    }
    clamp(layout, &mut p);
    p
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::basis::Grid;
    use anthesis_maps::{DirectionMap, GrowthMaps, ScalarMap};

    #[test]
    fn maps_the_basis_can_hold_are_put_in_it_as_they_are() {
        // e-growth rising linearly from base to tip, the rest constant,
        // the direction turned 0.3 rad: node values of a 1 x 3 grid.
        let mut maps = GrowthMaps::uniform();
        maps.e_growth = ScalarMap::from_fn(64, 64, |uv| (0.2 + 0.6 * uv.y) as f32);
        maps.w_growth = ScalarMap::constant(0.4);
        maps.e_growth_in = ScalarMap::constant(0.7);
        maps.w_growth_in = ScalarMap::constant(0.1);
        maps.direction = DirectionMap::constant(DVec2::new(0.3f64.sin(), 0.3f64.cos()));
        let layout = Layout {
            growth: Grid {
                nodes_u: 1,
                nodes_v: 3,
            },
            direction: Grid {
                nodes_u: 1,
                nodes_v: 1,
            },
            key_steps: vec![0],
        };
        let p = from_maps(&layout, &KeyedMaps::single(maps));
        let want = [
            0.2, 0.5, 0.8, 0.4, 0.4, 0.4, 0.7, 0.7, 0.7, 0.1, 0.1, 0.1, 0.3,
        ];
        assert_eq!(p.len(), want.len());
        for (got, want) in p.iter().zip(want) {
            // Within the map's 32-bit floats and bilinear sampling near
            // the edges.
            assert!((got - want).abs() < 2e-3, "{p:?}");
        }
    }
}

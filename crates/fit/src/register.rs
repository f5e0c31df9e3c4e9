//! Registration: where a target in its own frame (a scan, a model from
//! another program) sits on the organ, before the fit.
//!
//! The rigid motion, and with `scale` a uniform scale, that best puts the
//! target on the organ's current shape with its base on the organ's base:
//!
//! - **Robust start.** The principal axes of the two surfaces
//!   (area-weighted) are matched in each of the four ways that keep a
//!   right-handed frame (the axes' signs are arbitrary), and the target is
//!   also tried where it is; with `scale`, the first scale makes the two
//!   spreads equal.
//! - **Trimmed ICP** from each start (Besl and McKay 1992; trimmed as in
//!   Chetverikov et al. 2002): both ways, each target vertex paired with
//!   its nearest point on the organ and each organ particle with its
//!   nearest point on the target, the farthest tenth of each side's pairs
//!   left out (a scan's stray bits, a target longer than the organ is
//!   now; a pair whose two surfaces face opposite ways is no pair, normal
//!   compatibility as in Rusinkiewicz and Levoy 2001, so the target's inner
//!   side, the side its faces wind counter-clockwise around as the organ's
//!   do, ends on the organ's inner side and a nearly flat petal is not
//!   laid on upside down), plus the organ's base particles paired with
//!   their nearest points on the target's outline, with twice a side's
//!   weight (so the target's base, where its outline meets the organ's
//!   base, ends there, where growth cannot move it); each step the
//!   weighted least-squares similarity of the pairs (Umeyama 1991, through
//!   `nalgebra`'s SVD), until it stops moving.
//! - The start whose result is nearest (the trimmed cost) wins.
//!
//! The organ's current shape is what the project's maps grow now, not the
//! target's shape, so the fit refines the rigid part as it goes
//! ([`refine`], the scale held).

use glam::{DMat3, DQuat, DVec3};
use nalgebra::Matrix3;

use crate::surface::{Placed, Rim, Similarity, Surface, vertex_weights};

/// How a registration went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Registration {
    /// Where the target is put.
    pub placement: Similarity,
    /// The starts tried.
    pub starts: usize,
    /// ICP steps over all starts.
    pub steps: usize,
}

/// The share of each side's pairs kept by the trimmed ICP.
pub const KEPT: f64 = 0.9;
/// At most this many target vertices take part in the ICP (evenly picked).
const MAX_SAMPLES: usize = 4000;
/// The base pairs' weight against a whole side's (1).
const BASE_WEIGHT: f64 = 2.0;
/// ICP steps per start at most.
const MAX_STEPS: usize = 60;

/// A target vertex taking part in the ICP: where it is (target frame), its
/// area weight and its normal.
struct Sample {
    x: DVec3,
    w: f64,
    normal: DVec3,
}

/// A pair for the least-squares similarity: `x` in the target's frame,
/// `y` in the world, and its weight.
struct Pair {
    x: DVec3,
    y: DVec3,
    w: f64,
}

/// Registers `target` (its own frame) on the organ's shape `organ` (world
/// frame, on `triangles`), whose base particles are `base`: see the module
/// documentation.
pub fn register(
    target: &Surface,
    organ: &[DVec3],
    triangles: &[[u32; 3]],
    base: &[u32],
    scale: bool,
) -> Registration {
    let organ_surface = Surface::new(organ.to_vec(), triangles.to_vec());
    let organ_weights = vertex_weights(organ, triangles);
    let target_weights = target.vertex_weights();
    let target_normals = anthesis_mesh::vertex_normals(&target.positions, &target.triangles);
    let rim = Rim::new(&target.positions, &target.triangles);
    // The base particles on the organ's outline: those the target's
    // outline passes through (others are inside the surface).
    let base: Vec<u32> = base
        .iter()
        .copied()
        .filter(|&b| organ_surface.is_rim(b as usize))
        .collect();
    let base = base.as_slice();
    let stride = target.positions.len().div_ceil(MAX_SAMPLES).max(1);
    let samples: Vec<Sample> = (0..target.positions.len())
        .step_by(stride)
        .map(|i| Sample {
            x: target.positions[i],
            w: target_weights[i] * stride as f64,
            normal: target_normals[i],
        })
        .collect();

    let (organ_centre, organ_axes, organ_spread) = principal_axes(organ, &organ_weights);
    let (target_centre, target_axes, target_spread) =
        principal_axes(&target.positions, &target_weights);
    let first_scale = if scale && target_spread > 0.0 {
        (organ_spread / target_spread).sqrt()
    } else {
        1.0
    };
    let mut starts = vec![Similarity::IDENTITY];
    for signs in [
        [1.0, 1.0, 1.0],
        [1.0, -1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
    ] {
        let flipped = DMat3::from_cols(
            signs[0] * target_axes.x_axis,
            signs[1] * target_axes.y_axis,
            signs[2] * target_axes.z_axis,
        );
        let mut rotation = organ_axes * flipped.transpose();
        if rotation.determinant() < 0.0 {
            // The organ's axes are left-handed: flip its last one.
            let fixed = DMat3::from_cols(organ_axes.x_axis, organ_axes.y_axis, -organ_axes.z_axis);
            rotation = fixed * flipped.transpose();
        }
        let rotation = DQuat::from_mat3(&rotation).normalize();
        starts.push(Similarity {
            rotation,
            scale: first_scale,
            translation: organ_centre - first_scale * (rotation * target_centre),
        });
    }

    let mut best: Option<(f64, Similarity)> = None;
    let mut steps = 0;
    for start in &starts {
        let mut placement = *start;
        let mut last = f64::INFINITY;
        for _ in 0..MAX_STEPS {
            steps += 1;
            let (pairs, cost) = pairs(
                target,
                &samples,
                &organ_surface,
                &organ_weights,
                Some((base, &rim)),
                placement,
                KEPT,
                organ_spread,
            );
            let next = similarity(&pairs, scale.then_some(()), placement.scale);
            let Some(next) = next else { break };
            placement = next;
            if last.is_finite() && (last - cost).abs() <= 1e-9 * last.max(1e-300) {
                break;
            }
            last = cost;
        }
        let (_, cost) = pairs(
            target,
            &samples,
            &organ_surface,
            &organ_weights,
            Some((base, &rim)),
            placement,
            KEPT,
            organ_spread,
        );
        if best.is_none_or(|(c, _)| cost < c) {
            best = Some((cost, placement));
        }
    }
    Registration {
        placement: best.map_or(Similarity::IDENTITY, |(_, p)| p),
        starts: starts.len(),
        steps,
    }
}

/// A few ICP steps of the rigid part alone (the scale held), untrimmed,
/// with the base on the target's outline: the placement that lowers the fit's own cost
/// against the organ's shape now. Returns the placement after `steps`
/// steps; the caller keeps it only if its cost is lower.
pub fn refine(
    target: &Surface,
    organ: &[DVec3],
    triangles: &[[u32; 3]],
    base: &[u32],
    placement: Similarity,
    steps: usize,
) -> Similarity {
    let organ_surface = Surface::new(organ.to_vec(), triangles.to_vec());
    let rim = Rim::new(&target.positions, &target.triangles);
    let base: Vec<u32> = base
        .iter()
        .copied()
        .filter(|&b| organ_surface.is_rim(b as usize))
        .collect();
    let organ_weights = vertex_weights(organ, triangles);
    let target_weights = target.vertex_weights();
    let target_normals = anthesis_mesh::vertex_normals(&target.positions, &target.triangles);
    let samples: Vec<Sample> = (0..target.positions.len())
        .map(|i| Sample {
            x: target.positions[i],
            w: target_weights[i],
            normal: target_normals[i],
        })
        .collect();
    let mut placement = placement;
    for _ in 0..steps {
        let (pairs, _) = pairs(
            target,
            &samples,
            &organ_surface,
            &organ_weights,
            Some((&base, &rim)),
            placement,
            1.0,
            0.0,
        );
        match similarity(&pairs, None, placement.scale) {
            Some(next) => placement = next,
            None => break,
        }
    }
    placement
}

/// The pairs of one ICP step and their (trimmed) weighted cost. A pair
/// whose two surfaces face opposite ways (normal compatibility) is left
/// out of the least squares and costs its squared distance plus
/// `facing_penalty`, so a start that lays the target on upside down is
/// not chosen for its few remaining pairs.
#[allow(clippy::too_many_arguments)]
fn pairs(
    target: &Surface,
    samples: &[Sample],
    organ: &Surface,
    organ_weights: &[f64],
    base: Option<(&[u32], &Rim)>,
    placement: Similarity,
    kept: f64,
    facing_penalty: f64,
) -> (Vec<Pair>, f64) {
    let placed = Placed {
        surface: target,
        placement,
    };
    let mut cost = 0.0;
    let mut out = Vec::new();
    // Target samples to the organ.
    let organ_normals = anthesis_mesh::vertex_normals(&organ.positions, &organ.triangles);
    let mut side: Vec<Candidate> = samples
        .iter()
        .filter_map(|sample| {
            let world = placement.apply(sample.x);
            let near = organ.nearest(world)?;
            Some(Candidate {
                d2: near.point.distance_squared(world),
                facing: near.normal.dot(placement.rotation * sample.normal) >= 0.0,
                pair: Pair {
                    x: sample.x,
                    y: near.point,
                    w: sample.w,
                },
            })
        })
        .collect();
    cost += trim(&mut side, kept, facing_penalty, &mut out);
    // Organ particles to the target.
    let mut side: Vec<Candidate> = organ
        .positions
        .iter()
        .zip(organ_weights)
        .zip(&organ_normals)
        .filter_map(|((&y, &w), normal)| {
            let near = placed.nearest(y)?;
            Some(Candidate {
                d2: near.point.distance_squared(y),
                facing: near.normal.dot(*normal) >= 0.0,
                pair: Pair {
                    x: placement.invert(near.point),
                    y,
                    w,
                },
            })
        })
        .collect();
    cost += trim(&mut side, kept, facing_penalty, &mut out);
    // The organ's base particles to the target's outline: the target's
    // base is where its outline meets the organ's base.
    if let Some((base, rim)) = base.filter(|(base, _)| !base.is_empty()) {
        let w = BASE_WEIGHT / base.len() as f64;
        for &b in base {
            let y = organ.positions[b as usize];
            if let Some(x) = rim.nearest(placement.invert(y)) {
                cost += w * placement.apply(x).distance_squared(y);
                out.push(Pair { x, y, w });
            }
        }
    }
    (out, cost)
}

/// A pair found, its squared distance and whether its surfaces face the
/// same way.
struct Candidate {
    d2: f64,
    facing: bool,
    pair: Pair,
}

/// Keeps the nearest `kept` share (by weight) of `side`'s pairs, those
/// facing the same way moved to `out`; returns their weighted squared
/// distance (plus `facing_penalty` for each facing away), normalised by the
/// weight kept.
fn trim(side: &mut Vec<Candidate>, kept: f64, facing_penalty: f64, out: &mut Vec<Pair>) -> f64 {
    side.sort_by(|a, b| a.d2.total_cmp(&b.d2));
    let total: f64 = side.iter().map(|c| c.pair.w).sum();
    let mut weight = 0.0;
    let mut cost = 0.0;
    for candidate in side.drain(..) {
        if weight >= kept * total && weight > 0.0 {
            break;
        }
        let w = candidate.pair.w;
        weight += w;
        if candidate.facing {
            cost += w * candidate.d2;
            out.push(candidate.pair);
        } else {
            cost += w * (candidate.d2 + facing_penalty);
        }
    }
    if weight > 0.0 { cost / weight } else { 0.0 }
}

/// The weighted least-squares similarity taking the pairs' `x` to their
/// `y` (Umeyama 1991): with `scale` the scale too, else `fixed_scale`.
fn similarity(pairs: &[Pair], scale: Option<()>, fixed_scale: f64) -> Option<Similarity> {
    let total: f64 = pairs.iter().map(|p| p.w).sum();
    if total <= 0.0 || !total.is_finite() {
        return None;
    }
    let mx = pairs.iter().map(|p| p.w * p.x).sum::<DVec3>() / total;
    let my = pairs.iter().map(|p| p.w * p.y).sum::<DVec3>() / total;
    let mut covariance = Matrix3::<f64>::zeros();
    let mut spread = 0.0;
    for p in pairs {
        let (x, y) = (p.x - mx, p.y - my);
        covariance += p.w
            * nalgebra::Vector3::new(y.x, y.y, y.z)
            * nalgebra::Vector3::new(x.x, x.y, x.z).transpose();
        spread += p.w * x.length_squared();
    }
    covariance /= total;
    spread /= total;
    let svd = covariance.svd(true, true);
    let (u, v_t) = (svd.u?, svd.v_t?);
    let sign = (u.determinant() * v_t.determinant()).signum();
    let d = Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 1.0, sign));
    let r = u * d * v_t;
    let rotation = DMat3::from_cols(
        DVec3::new(r[(0, 0)], r[(1, 0)], r[(2, 0)]),
        DVec3::new(r[(0, 1)], r[(1, 1)], r[(2, 1)]),
        DVec3::new(r[(0, 2)], r[(1, 2)], r[(2, 2)]),
    );
    let rotation = DQuat::from_mat3(&rotation).normalize();
    let s = match scale {
        Some(()) if spread > 0.0 => {
            let values = svd.singular_values;
            (values[0] + values[1] + sign * values[2]) / spread
        }
        _ => fixed_scale,
    };
    if !(s.is_finite() && s > 0.0 && rotation.is_finite()) {
        return None;
    }
    Some(Similarity {
        rotation,
        scale: s,
        translation: my - s * (rotation * mx),
    })
}

/// Area-weighted centroid, principal axes (columns, largest spread first,
/// right-handed) and total spread (the covariance's trace) of `points`.
fn principal_axes(points: &[DVec3], weights: &[f64]) -> (DVec3, DMat3, f64) {
    let total: f64 = weights.iter().sum::<f64>().max(1e-300);
    let centre = points
        .iter()
        .zip(weights)
        .map(|(p, w)| *w * *p)
        .sum::<DVec3>()
        / total;
    let mut covariance = Matrix3::<f64>::zeros();
    for (p, w) in points.iter().zip(weights) {
        let d = *p - centre;
        let d = nalgebra::Vector3::new(d.x, d.y, d.z);
        covariance += *w * d * d.transpose();
    }
    covariance /= total;
    let eigen = covariance.symmetric_eigen();
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eigen.eigenvalues[b].total_cmp(&eigen.eigenvalues[a]));
    let column = |k: usize| {
        let c = eigen.eigenvectors.column(order[k]);
        DVec3::new(c[0], c[1], c[2])
    };
    let (x, y) = (column(0), column(1));
    let axes = DMat3::from_cols(x, y, x.cross(y));
    (centre, axes, covariance.trace())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A curved, tapered petal-like sheet: no symmetry a registration
    /// could be fooled by but the one its shape has.
    fn petal() -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let mesh = anthesis_mesh::generate::test_petal(10.0, 4.0, 9, 19);
        let positions = mesh
            .positions
            .iter()
            .map(|p| DVec3::new(p.x, p.y, p.z - 0.04 * p.y * p.y + 0.1 * p.x * p.x))
            .collect();
        (positions, mesh.triangles)
    }

    #[test]
    fn a_moved_turned_and_scaled_copy_is_put_back() {
        let (organ, triangles) = petal();
        let base: Vec<u32> = (0..organ.len() as u32)
            .filter(|&i| organ[i as usize].y < 0.3)
            .collect();
        assert!(!base.is_empty());
        let moved = Similarity {
            rotation: DQuat::from_axis_angle(DVec3::new(0.3, -1.0, 0.5).normalize(), 2.2),
            scale: 0.1,
            translation: DVec3::new(40.0, -3.0, 7.0),
        };
        // The target in its own frame: the organ moved away.
        let scan: Vec<DVec3> = organ.iter().map(|&p| moved.apply(p)).collect();
        let target = Surface::new(scan.clone(), triangles.clone());
        let registration = register(&target, &organ, &triangles, &base, true);
        let placement = registration.placement;
        // The placement undoes the motion: each scan point back where it
        // came from.
        let worst = scan
            .iter()
            .zip(&organ)
            .map(|(x, p)| placement.apply(*x).distance(*p))
            .fold(0.0, f64::max);
        assert!(worst < 1e-6, "{worst}: {placement:?}");
        assert!((placement.scale - 10.0).abs() < 1e-6, "{placement:?}");
        // Without scale, a rigid motion is found for a rigid copy.
        let rigid = Similarity {
            scale: 1.0,
            ..moved
        };
        let scan: Vec<DVec3> = organ.iter().map(|&p| rigid.apply(p)).collect();
        let target = Surface::new(scan.clone(), triangles.clone());
        let placement = register(&target, &organ, &triangles, &base, false).placement;
        assert_eq!(placement.scale, 1.0);
        let worst = scan
            .iter()
            .zip(&organ)
            .map(|(x, p)| placement.apply(*x).distance(*p))
            .fold(0.0, f64::max);
        assert!(worst < 1e-6, "{worst}: {placement:?}");
    }

    #[test]
    fn a_target_cupped_the_other_way_keeps_its_inner_side_on_the_organs() {
        // The organ cups one way, the target (the same outline, faces
        // wound alike) the other: turned over about its long axis it
        // would lie on the organ closer, but inner side on outer side.
        let mesh = anthesis_mesh::generate::test_petal(10.0, 4.0, 9, 19);
        let cupped = |k: f64| -> Vec<DVec3> {
            mesh.positions
                .iter()
                .map(|p| DVec3::new(p.x, p.y, p.z + k * p.x * p.x))
                .collect()
        };
        let organ = cupped(0.15);
        let base: Vec<u32> = (0..organ.len() as u32)
            .filter(|&i| organ[i as usize].y < 0.3)
            .collect();
        let moved = Similarity {
            rotation: DQuat::from_axis_angle(DVec3::new(0.5, 0.2, -1.0).normalize(), 1.1),
            scale: 1.0,
            translation: DVec3::new(-8.0, 3.0, 2.0),
        };
        let scan: Vec<DVec3> = cupped(-0.15).iter().map(|&p| moved.apply(p)).collect();
        let target = Surface::new(scan, mesh.triangles.clone());
        let placement = register(&target, &organ, &mesh.triangles, &base, false).placement;
        let left = (placement.rotation * moved.rotation)
            .to_axis_angle()
            .1
            .to_degrees();
        assert!(left < 10.0, "{left}° from undoing the motion");
    }

    #[test]
    fn umeyama_recovers_a_similarity_from_exact_pairs() {
        let known = Similarity {
            rotation: DQuat::from_rotation_z(0.7) * DQuat::from_rotation_x(-0.4),
            scale: 2.5,
            translation: DVec3::new(1.0, 2.0, -3.0),
        };
        let xs = [
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            DVec3::new(1.0, 2.0, 3.0),
        ];
        let pairs: Vec<Pair> = xs
            .iter()
            .map(|&x| Pair {
                x,
                y: known.apply(x),
                w: 1.0,
            })
            .collect();
        let found = similarity(&pairs, Some(()), 1.0).expect("regular");
        assert!((found.scale - 2.5).abs() < 1e-12);
        assert!((found.translation - known.translation).length() < 1e-12);
        assert!(found.rotation.angle_between(known.rotation) < 1e-9);
        let held = similarity(&pairs, None, 2.5).expect("regular");
        assert!((held.translation - known.translation).length() < 1e-12);
    }
}

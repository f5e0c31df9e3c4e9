//! Numbers that say what shape a flower has at a keyframe, so tests can
//! tell a reflexed lily from a closed bud and a bell from a funnel or a
//! shallow ball.
//!
//! All descriptors are measured on the organ surfaces through their UVs:
//! a point at a given `(u, v)` is found by interpolating the keyframe
//! positions over the triangle that contains it in UV. The *midrib* is the
//! line `u = 0.5` from `v = 0` (base) to `v = 1` (tip); *lamina lines* are
//! `u = 0.25` and `u = 0.75` from `v = 0` to [`LAMINA_END_V`].
//!
//! # Angles
//!
//! The *opening angle* of a piece of a line is the angle of its chord from
//! the flower axis (+Y), measured in the meridional plane through the
//! chord's midpoint: 0° points straight up along the axis, 90° horizontally
//! away from it, more than 90° downwards (a *reflexed* piece), and negative
//! angles lean in towards the axis (a closed bud's tip). The *turning* of a
//! line is how much that angle grows from its first piece to its last:
//! positive when the organ bends outwards (towards reflexing) along its
//! length, negative when it curls in. The *cone angle* is the opening angle
//! of the midrib's chord from the base to `v = 0.75`: the half-angle of the
//! cone the organ's lower three quarters make (about 40° for a funnel, 70°
//! and more for a saucer).
//!
//! # Cross-sections
//!
//! *Cupping* is the sagitta of the cross-section `v = 0.5` (the distance of
//! the midrib from the chord joining the two points at `u = 0.1` and
//! `u = 0.9`) divided by that chord, signed along the organ's inner normal:
//! positive when the margins lie towards the inner side (a cup open to the
//! flower axis), negative when the lamina bulges towards the inner side.
//!
//! # Neighbours
//!
//! The *margin overlap* of two neighbouring organs at `v` is how far, in
//! azimuth about the axis, the row `v` of one organ reaches past where the
//! row `v` of the next organ counter-clockwise (seen from above) begins:
//! positive where they overlap seen from above (a contorted corolla),
//! negative where a gap opens between them. *Wrong-side depths* check
//! collisions geometrically: the signed distance of each particle of one
//! organ from the nearest point of the other organ's triangles, where that
//! point lies on the organ and not on its rim.

use anthesis_mesh::Mesh;
use glam::{DVec2, DVec3};

/// Where the lamina lines end: a pointed organ has no lamina at its tip.
pub const LAMINA_END_V: f64 = 0.9;

/// Finds surface points by UV on one organ.
pub struct UvSampler<'a> {
    mesh: &'a Mesh,
}

impl<'a> UvSampler<'a> {
    /// `mesh` supplies UVs and triangles (the organ's template mesh).
    pub fn new(mesh: &'a Mesh) -> Self {
        UvSampler { mesh }
    }

    /// The point at `point_in_uv` on the organ whose particles are at
    /// `positions_in_world`, or `None` if no triangle covers that UV.
    /// Points just outside the UV layout (within a small tolerance) are
    /// taken from the nearest triangle.
    pub fn point(&self, positions_in_world: &[DVec3], point_in_uv: DVec2) -> Option<DVec3> {
        let mut best: Option<(f64, usize, [f64; 3])> = None;
        for (t, tri) in self.mesh.triangles.iter().enumerate() {
            let [a, b, c] = tri.map(|i| self.mesh.uvs[i as usize]);
            let Some(w) = barycentric(point_in_uv, a, b, c) else {
                continue;
            };
            // How far outside the triangle the point is (0 inside).
            let outside = -w.iter().copied().fold(0.0, f64::min);
            if best.is_none_or(|(o, _, _)| outside < o) {
                best = Some((outside, t, w));
            }
            if outside == 0.0 {
                break;
            }
        }
        let (outside, t, w) = best?;
        if outside > 0.05 {
            return None;
        }
        let tri = self.mesh.triangles[t];
        Some(
            (0..3)
                .map(|k| w[k] * positions_in_world[tri[k] as usize])
                .sum(),
        )
    }

    /// Points along the line `u` from `v_from` to `v_to`, `count` of them
    /// (at least 2), skipping any that fall outside the layout.
    pub fn line(
        &self,
        positions_in_world: &[DVec3],
        u: f64,
        v_from: f64,
        v_to: f64,
        count: usize,
    ) -> Vec<DVec3> {
        let count = count.max(2);
        (0..count)
            .filter_map(|k| {
                let v = v_from + (v_to - v_from) * k as f64 / (count - 1) as f64;
                self.point(positions_in_world, DVec2::new(u, v))
            })
            .collect()
    }
}

fn barycentric(p: DVec2, a: DVec2, b: DVec2, c: DVec2) -> Option<[f64; 3]> {
    let (v0, v1, v2) = (b - a, c - a, p - a);
    let det = v0.perp_dot(v1);
    if det.abs() < 1e-18 {
        return None;
    }
    let wb = v2.perp_dot(v1) / det;
    let wc = v0.perp_dot(v2) / det;
    Some([1.0 - wb - wc, wb, wc])
}

/// The opening angle of the chord from `from` to `to` (see the module
/// documentation), in degrees.
pub fn opening_angle_deg(from: DVec3, to: DVec3) -> f64 {
    let d = to - from;
    let mid = 0.5 * (from + to);
    let radial = DVec2::new(mid.x, mid.z).normalize_or(DVec2::Y);
    let outwards = d.x * radial.x + d.z * radial.y;
    outwards.atan2(d.y).to_degrees()
}

/// The turning of a polyline in degrees: how much the opening angle of its
/// pieces grows from the first piece to the last, summed piece by piece so
/// that a line curling past straight down keeps counting; 0 for fewer than
/// 3 points.
pub fn turning_deg(line: &[DVec3]) -> f64 {
    let angles: Vec<f64> = line
        .windows(2)
        .filter(|w| w[0].distance_squared(w[1]) > 0.0)
        .map(|w| opening_angle_deg(w[0], w[1]))
        .collect();
    angles
        .windows(2)
        .map(|w| (w[1] - w[0] + 180.0).rem_euclid(360.0) - 180.0)
        .sum()
}

/// What one organ looks like at one keyframe.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrganShape {
    /// Opening angles (degrees) of the midrib's base, middle and tip thirds.
    pub midrib_angles_deg: [f64; 3],
    /// Turning of the midrib, degrees.
    pub midrib_turning_deg: f64,
    /// Turning of the midrib's upper half (`v` from 0.5 to 1), degrees: a
    /// flaring tip turns outwards by tens of degrees, a rolled-up one past
    /// 180°.
    pub upper_turning_deg: f64,
    /// Opening angle of the chord from the base to `v = 0.75` (the cone
    /// angle, see the module documentation), degrees.
    pub cone_angle_deg: f64,
    /// Mean turning of the two lamina lines (`u = 0.25`, `u = 0.75`).
    pub lamina_turning_deg: f64,
    /// Cupping of the cross-section at `v = 0.5` (see the module docs).
    pub cupping: f64,
    /// Swelling of the lamina at `v = 0.5`: how far each half of the
    /// cross-section (midrib to `u = 0.1`, midrib to `u = 0.9`) bulges
    /// towards the inner side at its middle (`u = 0.3`, `u = 0.7`), over the
    /// half's chord; the mean of both halves. Positive when the lamina halves
    /// swell inwards either side of a midrib that lies behind them (paper
    /// Fig. 13), negative when each half is cupped.
    pub swelling: f64,
    /// Distance from the flower axis of the midrib at `v` = 0.25, 0.5,
    /// 0.75 and 1.
    pub radius_profile: [f64; 4],
    /// Height of the midrib at the same `v`.
    pub height_profile: [f64; 4],
    /// Length of the midrib.
    pub midrib_length: f64,
}

/// Why a shape could not be measured.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ShapeError {
    /// A point the measures sample (on the midrib or a cross line) lies
    /// outside every triangle of the organ's UV layout.
    #[error("the organ's UV layout does not cover (u, v) = ({u:.2}, {v:.2})")]
    UvNotCovered {
        /// The point's `u` (across the organ).
        u: f64,
        /// The point's `v` (base to tip).
        v: f64,
    },
    /// The keyframe's positions do not match the template mesh.
    #[error("{positions} positions for a mesh of {vertices} vertices")]
    WrongCount {
        /// How many positions were given.
        positions: usize,
        /// How many vertices the template mesh has.
        vertices: usize,
    },
    /// The template mesh is not a manifold, consistently oriented surface.
    #[error("the organ's mesh has no surface topology: {0}")]
    Mesh(#[from] anthesis_mesh::MeshError),
}

/// Measures one organ: `mesh` is its template mesh (for UVs and
/// triangles), `positions_in_world` its particles at the keyframe.
pub fn organ_shape(mesh: &Mesh, positions_in_world: &[DVec3]) -> Result<OrganShape, ShapeError> {
    if positions_in_world.len() != mesh.vertex_count() {
        return Err(ShapeError::WrongCount {
            positions: positions_in_world.len(),
            vertices: mesh.vertex_count(),
        });
    }
    let sampler = UvSampler::new(mesh);
    let at = |u: f64, v: f64| {
        sampler
            .point(positions_in_world, DVec2::new(u, v))
            .ok_or(ShapeError::UvNotCovered { u, v })
    };
    let line = |u: f64, v_end: f64| -> Result<Vec<DVec3>, ShapeError> {
        (0..=40)
            .map(|k| at(u, v_end * f64::from(k) / 40.0))
            .collect::<Result<Vec<_>, _>>()
    };
    let midrib = line(0.5, 1.0)?;
    let third = |a: usize, b: usize| opening_angle_deg(midrib[a], midrib[b]);
    let midrib_angles_deg = [third(0, 13), third(13, 27), third(27, 40)];
    let lamina_turning_deg =
        0.5 * (turning_deg(&line(0.25, LAMINA_END_V)?) + turning_deg(&line(0.75, LAMINA_END_V)?));

    let (left, right, centre) = (at(0.9, 0.5)?, at(0.1, 0.5)?, at(0.5, 0.5)?);
    let chord = right - left;
    let to_centre = centre - left;
    let along = chord.normalize_or_zero();
    let off_chord = to_centre - along * to_centre.dot(along);
    let inner_normal = inner_normal_near(mesh, positions_in_world, DVec2::new(0.5, 0.5));
    let cupping = if chord.length() > 0.0 {
        -off_chord.dot(inner_normal) / chord.length()
    } else {
        0.0
    };

    let bulge = |midrib_u: f64, half_u: f64, margin_u: f64| -> Result<f64, ShapeError> {
        let (a, b, c) = (at(midrib_u, 0.5)?, at(margin_u, 0.5)?, at(half_u, 0.5)?);
        let chord = b - a;
        let length = chord.length();
        if length == 0.0 {
            return Ok(0.0);
        }
        let along = chord / length;
        let to_c = c - a;
        Ok((to_c - along * to_c.dot(along)).dot(inner_normal) / length)
    };
    let swelling = 0.5 * (bulge(0.5, 0.3, 0.1)? + bulge(0.5, 0.7, 0.9)?);

    let radius = |p: DVec3| DVec2::new(p.x, p.z).length();
    let profile_points = [10, 20, 30, 40].map(|k| midrib[k]);
    Ok(OrganShape {
        midrib_angles_deg,
        midrib_turning_deg: turning_deg(&midrib),
        upper_turning_deg: turning_deg(&midrib[20..]),
        cone_angle_deg: opening_angle_deg(midrib[0], midrib[30]),
        lamina_turning_deg,
        cupping,
        swelling,
        radius_profile: profile_points.map(radius),
        height_profile: profile_points.map(|p| p.y),
        midrib_length: midrib.windows(2).map(|w| w[0].distance(w[1])).sum(),
    })
}

/// The unit inner normal of the triangle nearest `point_in_uv`.
fn inner_normal_near(mesh: &Mesh, positions_in_world: &[DVec3], point_in_uv: DVec2) -> DVec3 {
    let nearest = (0..mesh.triangles.len()).min_by(|&a, &b| {
        let centre = |t: usize| mesh.triangle_uvs(t).iter().sum::<DVec2>() / 3.0;
        centre(a)
            .distance_squared(point_in_uv)
            .total_cmp(&centre(b).distance_squared(point_in_uv))
    });
    nearest.map_or(DVec3::ZERO, |t| {
        let [a, b, c] = mesh.triangles[t].map(|i| positions_in_world[i as usize]);
        (b - a).cross(c - a).normalize_or_zero()
    })
}

/// The shape of a whole flower (or of a group of its organs, e.g. the
/// lily's petals): each organ's shape and their means.
#[derive(Debug, Clone, PartialEq)]
pub struct FlowerShape {
    /// Each organ's shape, in the order the organs were given.
    pub organs: Vec<OrganShape>,
    /// Means over the organs of each [`OrganShape`] field.
    pub mean: OrganShape,
}

/// Measures the organs given as `(template mesh, positions)` pairs.
pub fn flower_shape<'a>(
    organs: impl IntoIterator<Item = (&'a Mesh, &'a [DVec3])>,
) -> Result<FlowerShape, ShapeError> {
    let organs = organs
        .into_iter()
        .map(|(mesh, positions)| organ_shape(mesh, positions))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(FlowerShape::of_organs(organs))
}

impl FlowerShape {
    /// The shape of a group of measured organs: them and their means (all
    /// zero for no organs).
    pub fn of_organs(organs: Vec<OrganShape>) -> FlowerShape {
        let n = organs.len().max(1) as f64;
        let mean_of = |f: &dyn Fn(&OrganShape) -> f64| organs.iter().map(f).sum::<f64>() / n;
        let mean = OrganShape {
            midrib_angles_deg: [0, 1, 2].map(|k| mean_of(&|o| o.midrib_angles_deg[k])),
            midrib_turning_deg: mean_of(&|o| o.midrib_turning_deg),
            upper_turning_deg: mean_of(&|o| o.upper_turning_deg),
            cone_angle_deg: mean_of(&|o| o.cone_angle_deg),
            lamina_turning_deg: mean_of(&|o| o.lamina_turning_deg),
            cupping: mean_of(&|o| o.cupping),
            swelling: mean_of(&|o| o.swelling),
            radius_profile: [0, 1, 2, 3].map(|k| mean_of(&|o| o.radius_profile[k])),
            height_profile: [0, 1, 2, 3].map(|k| mean_of(&|o| o.height_profile[k])),
            midrib_length: mean_of(&|o| o.midrib_length),
        };
        FlowerShape { organs, mean }
    }
}

/// The azimuth of `p` about the flower axis (+Y), in degrees, as organs
/// are placed: 0 on +Z, 90 on +X.
pub fn azimuth_deg(p: DVec3) -> f64 {
    p.x.atan2(p.z).to_degrees()
}

/// The signed difference `a − b` of two azimuths, in `(−180, 180]` degrees.
fn azimuth_difference_deg(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(360.0);
    if d > 180.0 { d - 360.0 } else { d }
}

/// How far the row `v` of an organ reaches on either side of its midrib, in
/// azimuth: `(towards decreasing, towards increasing)` azimuth, degrees
/// from the midrib's azimuth at `v`, each the extreme over the row.
fn row_reach_deg(
    mesh: &Mesh,
    positions_in_world: &[DVec3],
    v: f64,
) -> Result<(f64, f64, f64), ShapeError> {
    let sampler = UvSampler::new(mesh);
    let at = |u: f64| {
        sampler
            .point(positions_in_world, DVec2::new(u, v))
            .ok_or(ShapeError::UvNotCovered { u, v })
    };
    let centre = azimuth_deg(at(0.5)?);
    let (mut low, mut high) = (0.0f64, 0.0f64);
    for k in 0..=ROW_SAMPLES {
        let d = azimuth_difference_deg(
            azimuth_deg(at(f64::from(k) / f64::from(ROW_SAMPLES))?),
            centre,
        );
        low = low.min(d);
        high = high.max(d);
    }
    Ok((centre, low, high))
}

/// Points sampled across a row for [`margin_overlap_deg`].
const ROW_SAMPLES: u32 = 40;

/// The margin overlap at `v` (see the module documentation) of an organ
/// (`organ`: template mesh and world positions) and the next organ
/// counter-clockwise seen from above (`next`), in degrees: positive where
/// they overlap, negative where a gap opens between them.
pub fn margin_overlap_deg(
    organ: (&Mesh, &[DVec3]),
    next: (&Mesh, &[DVec3]),
    v: f64,
) -> Result<f64, ShapeError> {
    for (mesh, positions) in [organ, next] {
        if positions.len() != mesh.vertex_count() {
            return Err(ShapeError::WrongCount {
                positions: positions.len(),
                vertices: mesh.vertex_count(),
            });
        }
    }
    let (centre, _, reach) = row_reach_deg(organ.0, organ.1, v)?;
    let (next_centre, next_reach, _) = row_reach_deg(next.0, next.1, v)?;
    Ok(reach - next_reach - azimuth_difference_deg(next_centre, centre))
}

/// Where the particles of one organ lie relative to a neighbour's surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SideCheck {
    /// Particles whose nearest point on the neighbour lies on it (not on its
    /// rim) within the search distance.
    pub over: usize,
    /// The smallest signed distance among them, along the neighbour's
    /// normal towards the side the particles belong on: negative when some
    /// particle is on the wrong side (`f64::INFINITY` when none is over).
    pub closest: f64,
    /// How many of them lie on the wrong side by more than the tolerance.
    pub wrong: usize,
}

/// Checks geometrically that the particles of organ `moving` lie on their
/// side of organ `other`'s triangle surface (see [`side_distances`]):
/// particles flagged in `skip` (e.g. the base particles the receptacle
/// places) are left out, and a particle is wrong when its signed distance
/// is below `−tolerance`.
pub fn side_check(
    moving: &[DVec3],
    skip: &[bool],
    other: &[DVec3],
    other_mesh: &Mesh,
    side: f64,
    reach: f64,
    tolerance: f64,
) -> Result<SideCheck, ShapeError> {
    let mut check = SideCheck {
        over: 0,
        closest: f64::INFINITY,
        wrong: 0,
    };
    let distances = side_distances(moving, other, other_mesh, side, reach)?;
    for (i, distance) in distances.into_iter().enumerate() {
        let Some(distance) = distance else { continue };
        if skip.get(i).copied().unwrap_or(false) {
            continue;
        }
        check.over += 1;
        check.closest = check.closest.min(distance);
        if distance < -tolerance {
            check.wrong += 1;
        }
    }
    Ok(check)
}

/// The signed distance of each particle of organ `moving` from organ
/// `other`'s triangle surface, along `other`'s normal towards the side
/// `moving` belongs on: `side` is +1 if that is `other`'s inner side
/// (`moving` lies inside it), −1 if its outer side. Inner normals follow the
/// triangles' winding, as in the organ template frame. Each particle is
/// measured from its nearest point on `other`'s triangles (brute force,
/// independent of the simulator's tracking); `None` when that point is
/// farther than `reach` or lies on `other`'s rim (the particle is beyond
/// the organ, not over it).
pub fn side_distances(
    moving: &[DVec3],
    other: &[DVec3],
    other_mesh: &Mesh,
    side: f64,
    reach: f64,
) -> Result<Vec<Option<f64>>, ShapeError> {
    let mut rim = vec![false; other_mesh.vertex_count()];
    for edge in anthesis_mesh::Topology::build(other_mesh)?.boundary_edges() {
        for vertex in edge {
            rim[vertex as usize] = true;
        }
    }
    let distance = |x: DVec3| {
        let mut best: Option<(f64, [u32; 3], DVec3, [f64; 3])> = None;
        for tri in &other_mesh.triangles {
            let [a, b, c] = tri.map(|k| other[k as usize]);
            let (point, weights) = anthesis_mesh::nearest::closest_point_on_triangle(x, a, b, c);
            let d2 = point.distance_squared(x);
            if best.is_none_or(|(bd, ..)| d2 < bd) {
                best = Some((d2, *tri, point, weights));
            }
        }
        let (d2, tri, point, weights) = best?;
        // On the rim: every corner the nearest point leans on is a rim
        // particle (a point on an interior edge or corner is inside).
        let on_rim = anthesis_mesh::nearest::on_rim(tri, weights, &rim);
        if d2 > reach * reach || on_rim {
            return None;
        }
        let [a, b, c] = tri.map(|k| other[k as usize]);
        let normal = (b - a).cross(c - a).normalize_or_zero() * side;
        Some((x - point).dot(normal))
    };
    Ok(moving.iter().map(|&x| distance(x)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use anthesis_mesh::generate::parametric_grid;
    use std::f64::consts::PI;

    #[test]
    fn a_group_of_organs_has_the_mean_of_each_measure() {
        let shape = |x: f64| OrganShape {
            midrib_angles_deg: [x, 2.0 * x, 3.0 * x],
            midrib_turning_deg: x,
            upper_turning_deg: 0.5 * x,
            cone_angle_deg: 4.0 * x,
            lamina_turning_deg: -x,
            cupping: 0.25 * x,
            swelling: 0.5 * x,
            radius_profile: [x; 4],
            height_profile: [x, 0.0, x, 0.0],
            midrib_length: 10.0 + x,
        };
        let group = FlowerShape::of_organs(vec![shape(1.0), shape(3.0)]);
        assert_eq!(group.organs, vec![shape(1.0), shape(3.0)]);
        assert_eq!(group.mean, shape(2.0));
        let none = FlowerShape::of_organs(Vec::new());
        assert_eq!(none.mean.midrib_length, 0.0);
    }

    #[test]
    fn opening_angles_read_from_the_axis_outwards() {
        let base = DVec3::new(0.0, 0.0, 5.0);
        let up = opening_angle_deg(base, base + DVec3::Y);
        let out = opening_angle_deg(base, base + DVec3::Z);
        let down = opening_angle_deg(base, base - DVec3::Y);
        let inwards = opening_angle_deg(base, base + DVec3::new(0.0, 1.0, -1.0));
        assert!(up.abs() < 1e-9 && (out - 90.0).abs() < 1e-9, "{up} {out}");
        assert!((down - 180.0).abs() < 1e-9 && (inwards + 45.0).abs() < 1e-9);
        // Any azimuth: outwards is away from the axis.
        let side = DVec3::new(5.0, 0.0, 0.0);
        assert!((opening_angle_deg(side, side + DVec3::X) - 90.0).abs() < 1e-9);
    }

    #[test]
    fn turning_of_a_reflexing_arc_is_its_angle_even_past_straight_down() {
        // A quarter circle then more: from pointing up to pointing down and
        // back in (270°), bending outwards all along.
        let arc: Vec<DVec3> = (0..=90)
            .map(|k| {
                let a = 1.5 * PI * f64::from(k) / 90.0;
                DVec3::new(0.0, 10.0 * a.sin(), 5.0 + 10.0 * (1.0 - a.cos()))
            })
            .collect();
        // Measured between the first and last chords, whose directions are
        // 89 of the 90 segments apart.
        let expected = 270.0 * 89.0 / 90.0;
        assert!(
            (turning_deg(&arc) - expected).abs() < 1e-6,
            "{}",
            turning_deg(&arc)
        );
        let reversed: Vec<DVec3> = arc.iter().rev().copied().collect();
        assert!(turning_deg(&reversed) < -260.0);
    }

    /// An upright organ at azimuth 0, 5 from the axis, `u` along −X so its
    /// winding normal faces the axis (−Z); `cup` pulls the margins towards
    /// the axis.
    fn upright(cup: f64) -> Mesh {
        parametric_grid(12, 24, |uv| {
            let x = -(uv.x - 0.5) * 10.0;
            DVec3::new(x, 30.0 * uv.y, 5.0 - cup * x * x)
        })
    }

    #[test]
    fn flat_upright_organ_has_zero_angles_turning_and_cupping() {
        let mesh = upright(0.0);
        let shape = organ_shape(&mesh, &mesh.positions).expect("measurable");
        for angle in shape.midrib_angles_deg {
            assert!(angle.abs() < 1e-6, "{shape:?}");
        }
        assert!(shape.midrib_turning_deg.abs() < 1e-6);
        assert!(shape.cupping.abs() < 1e-9 && shape.swelling.abs() < 1e-9);
        assert!((shape.midrib_length - 30.0).abs() < 1e-9);
        assert!((shape.radius_profile[3] - 5.0).abs() < 1e-9);
        assert!((shape.height_profile[1] - 15.0).abs() < 1e-9);
    }

    #[test]
    fn cupped_organ_has_positive_cupping_and_cupped_halves() {
        let mesh = upright(0.1);
        // The mesh winds around +Z or −Z depending on the grid; the
        // measures use the winding normal, so check it faces the axis.
        let normal = anthesis_mesh::vertex_normals(&mesh.positions, &mesh.triangles)[0];
        assert!(normal.z < 0.0, "test mesh must face the axis: {normal}");
        let shape = organ_shape(&mesh, &mesh.positions).expect("measurable");
        assert!(shape.cupping > 0.05, "{shape:?}");
        assert!(shape.swelling < 0.0, "each half is cupped: {shape:?}");
        let bulged = upright(-0.1);
        let inverted = organ_shape(&bulged, &bulged.positions).expect("measurable");
        assert!(
            inverted.cupping < -0.05 && inverted.swelling > 0.0,
            "{inverted:?}"
        );
    }

    #[test]
    fn wrong_position_count_is_refused() {
        let mesh = upright(0.0);
        assert_eq!(
            organ_shape(&mesh, &mesh.positions[1..]),
            Err(ShapeError::WrongCount {
                positions: mesh.vertex_count() - 1,
                vertices: mesh.vertex_count()
            })
        );
    }

    /// The upright organ tilted outwards by `tilt_deg` about its base and
    /// turned about the axis by `azimuth_deg`.
    fn placed(mesh: &Mesh, tilt_deg: f64, azimuth_deg: f64) -> Vec<DVec3> {
        let tilt = glam::DQuat::from_rotation_x(tilt_deg.to_radians());
        let turn = glam::DQuat::from_rotation_y(azimuth_deg.to_radians());
        let base = DVec3::new(0.0, 0.0, 5.0);
        mesh.positions
            .iter()
            .map(|&p| turn * (base + tilt * (p - base)))
            .collect()
    }

    #[test]
    fn a_flat_organ_tilted_out_has_that_cone_angle_and_no_turning() {
        let mesh = upright(0.0);
        for tilt in [0.0, 20.0, 55.0] {
            let positions = placed(&mesh, tilt, 0.0);
            let shape = organ_shape(&mesh, &positions).expect("measurable");
            assert!(
                (shape.cone_angle_deg - tilt).abs() < 1e-6,
                "{tilt}: {shape:?}"
            );
            assert!(shape.upper_turning_deg.abs() < 1e-6, "{shape:?}");
        }
    }

    #[test]
    fn margin_overlap_is_the_azimuth_two_neighbours_share() {
        // Each upright sheet 10 wide at radius 5 spans ±45° about its
        // midrib (atan(5/5)); neighbours 80° apart share 10°, 100° apart
        // leave a 10° gap.
        let mesh = upright(0.0);
        let organ = placed(&mesh, 0.0, 0.0);
        for (apart, expected) in [(80.0, 10.0), (100.0, -10.0)] {
            let next = placed(&mesh, 0.0, apart);
            let overlap =
                margin_overlap_deg((&mesh, &organ), (&mesh, &next), 0.5).expect("measurable");
            assert!((overlap - expected).abs() < 1e-6, "{apart}: {overlap}");
        }
    }

    #[test]
    fn side_check_finds_particles_on_the_wrong_side_of_a_neighbour() {
        // A sheet facing the axis (inner side −Z) and a copy 0.2 further in
        // lies on its inner side; 0.2 further out, on the wrong side.
        let mesh = upright(0.0);
        let shifted = |dz: f64| -> Vec<DVec3> {
            mesh.positions
                .iter()
                .map(|&p| p + DVec3::new(0.0, 0.0, dz))
                .collect()
        };
        let skip = vec![false; mesh.vertex_count()];
        let check = |dz: f64| {
            side_check(&shifted(dz), &skip, &mesh.positions, &mesh, 1.0, 1.0, 0.01)
                .expect("measurable")
        };
        let inside = check(-0.2);
        assert!(inside.over > 0 && inside.wrong == 0, "{inside:?}");
        assert!((inside.closest - 0.2).abs() < 1e-9, "{inside:?}");
        let outside = check(0.2);
        assert_eq!(outside.wrong, outside.over, "{outside:?}");
        assert!(outside.over > 0 && (outside.closest + 0.2).abs() < 1e-9);
        // Beyond `reach`, nothing is over.
        let far = check(-2.0);
        assert_eq!(far.over, 0);
    }
}

//! Distances between two triangle surfaces of any triangulation: the
//! organ's simulated shape and a target mesh (another resolution, another
//! tool's mesh, a scan).
//!
//! The distance of a point to a surface is to its nearest point on the
//! surface's triangles, found in an R*-tree of the triangles (`rstar`,
//! exact point–triangle distances, so the nearest triangle is the true
//! one, not the one of the nearest vertex). Two surfaces are compared both
//! ways: every vertex of each to the other's triangles, each side weighted
//! by its vertices' areas (a third of their triangles'), so a fine patch of
//! a scan counts no more than a coarse one of the same size:
//!
//! - `mean²` of a side is the area-weighted mean of its squared distances;
//! - the RMS surface distance is `sqrt((mean²_organ + mean²_target) / 2)`;
//! - the largest distance is the largest of either side's vertices.
//!
//! One way alone would not do: an organ that grew only half as long as the
//! target lies on it (organ → target near zero) while half the target is
//! uncovered (target → organ large).

use anthesis_mesh::nearest::closest_point_on_triangle;
use glam::{DQuat, DVec3};
use rstar::{AABB, PointDistance, RTree, RTreeObject};

/// One triangle in the tree: its index and corners.
#[derive(Debug, Clone)]
struct Triangle {
    index: u32,
    corners: [DVec3; 3],
}

impl RTreeObject for Triangle {
    type Envelope = AABB<[f64; 3]>;

    fn envelope(&self) -> Self::Envelope {
        let [a, b, c] = self.corners;
        AABB::from_corners(a.min(b).min(c).to_array(), a.max(b).max(c).to_array())
    }
}

impl PointDistance for Triangle {
    fn distance_2(&self, point: &[f64; 3]) -> f64 {
        let p = DVec3::from_array(*point);
        let [a, b, c] = self.corners;
        closest_point_on_triangle(p, a, b, c).0.distance_squared(p)
    }
}

/// The nearest point of a surface to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nearest {
    /// The triangle it lies on.
    pub triangle: u32,
    /// Its barycentric weights on that triangle's corners.
    pub weights: [f64; 3],
    /// The point.
    pub point: DVec3,
    /// The triangle's unit normal (zero for a degenerate triangle).
    pub normal: DVec3,
    /// Whether it lies on the surface's rim (an edge or corner on the
    /// boundary), where the surface ends rather than curves away.
    pub on_rim: bool,
}

/// A triangle surface with its nearest-point tree.
#[derive(Debug, Clone)]
pub struct Surface {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Triangles (vertex indices).
    pub triangles: Vec<[u32; 3]>,
    rim: Vec<bool>,
    tree: RTree<Triangle>,
}

impl Surface {
    /// The surface of `triangles` over `positions` (indices must be in
    /// range; nothing else is asked of the triangulation).
    pub fn new(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> Surface {
        let rim = rim_vertices(&triangles, positions.len());
        let tree = RTree::bulk_load(
            triangles
                .iter()
                .enumerate()
                .map(|(i, t)| Triangle {
                    index: i as u32,
                    corners: t.map(|v| positions[v as usize]),
                })
                .collect(),
        );
        Surface {
            positions,
            triangles,
            rim,
            tree,
        }
    }

    /// Whether vertex `v` is on the rim.
    pub fn is_rim(&self, v: usize) -> bool {
        self.rim.get(v).copied().unwrap_or(false)
    }

    /// The point of the surface nearest `p` (`None` for a surface without
    /// triangles).
    pub fn nearest(&self, p: DVec3) -> Option<Nearest> {
        let triangle = self.tree.nearest_neighbor(&p.to_array())?;
        let [a, b, c] = triangle.corners;
        let (point, weights) = closest_point_on_triangle(p, a, b, c);
        let corners = self.triangles[triangle.index as usize];
        Some(Nearest {
            triangle: triangle.index,
            weights,
            point,
            normal: (b - a).cross(c - a).normalize_or_zero(),
            on_rim: anthesis_mesh::nearest::on_rim(corners, weights, &self.rim),
        })
    }

    /// Each vertex's share of the surface's area (a third of each of its
    /// triangles'), summing to 1; equal shares when there is no area.
    pub fn vertex_weights(&self) -> Vec<f64> {
        vertex_weights(&self.positions, &self.triangles)
    }
}

/// Each vertex's share of the area of `triangles` over `positions`.
pub fn vertex_weights(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<f64> {
    let mut weights = vec![0.0; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|v| positions[v as usize]);
        let third = (b - a).cross(c - a).length() / 6.0;
        for &v in t {
            weights[v as usize] += third;
        }
    }
    let total: f64 = weights.iter().sum();
    if total > 0.0 && total.is_finite() {
        weights.iter_mut().for_each(|w| *w /= total);
    } else {
        let n = positions.len().max(1) as f64;
        weights.iter_mut().for_each(|w| *w = 1.0 / n);
    }
    weights
}

/// One boundary edge in a [`Rim`]'s tree.
#[derive(Debug, Clone)]
struct Segment {
    ends: [DVec3; 2],
}

impl Segment {
    fn nearest(&self, p: DVec3) -> DVec3 {
        let [a, b] = self.ends;
        let ab = b - a;
        let t = if ab.length_squared() > 0.0 {
            ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        a + t * ab
    }
}

impl RTreeObject for Segment {
    type Envelope = AABB<[f64; 3]>;

    fn envelope(&self) -> Self::Envelope {
        let [a, b] = self.ends;
        AABB::from_corners(a.min(b).to_array(), a.max(b).to_array())
    }
}

impl PointDistance for Segment {
    fn distance_2(&self, point: &[f64; 3]) -> f64 {
        let p = DVec3::from_array(*point);
        self.nearest(p).distance_squared(p)
    }
}

/// A surface's outline: its boundary edges (those of one triangle), for
/// the nearest point on it.
#[derive(Debug, Clone)]
pub struct Rim {
    tree: RTree<Segment>,
}

impl Rim {
    /// The outline of `triangles` over `positions`.
    pub fn new(positions: &[DVec3], triangles: &[[u32; 3]]) -> Rim {
        let mut edges: std::collections::HashMap<(u32, u32), u32> =
            std::collections::HashMap::new();
        for t in triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        let mut segments: Vec<Segment> = edges
            .into_iter()
            .filter(|&(_, count)| count == 1)
            .map(|((a, b), _)| Segment {
                ends: [positions[a as usize], positions[b as usize]],
            })
            .collect();
        // A fixed order whatever the hash map's.
        segments.sort_by(|s, t| {
            let key = |s: &Segment| [s.ends[0].to_array(), s.ends[1].to_array()];
            key(s)
                .iter()
                .flatten()
                .zip(key(t).iter().flatten())
                .map(|(x, y)| x.total_cmp(y))
                .find(|o| o.is_ne())
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        Rim {
            tree: RTree::bulk_load(segments),
        }
    }

    /// The point of the outline nearest `p` (`None` for a closed surface).
    pub fn nearest(&self, p: DVec3) -> Option<DVec3> {
        self.tree
            .nearest_neighbor(&p.to_array())
            .map(|segment| segment.nearest(p))
    }
}

/// The vertices on an edge that only one triangle has.
fn rim_vertices(triangles: &[[u32; 3]], vertex_count: usize) -> Vec<bool> {
    let mut edges: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut rim = vec![false; vertex_count];
    for ((a, b), count) in edges {
        if count == 1 {
            rim[a as usize] = true;
            rim[b as usize] = true;
        }
    }
    rim
}

/// A similarity transform, `world = scale · rotation · x + translation`:
/// where a registered target sits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Similarity {
    /// The rotation.
    pub rotation: DQuat,
    /// The uniform scale (1 for a rigid motion).
    pub scale: f64,
    /// The translation.
    pub translation: DVec3,
}

impl Default for Similarity {
    fn default() -> Self {
        Similarity::IDENTITY
    }
}

impl Similarity {
    /// No motion.
    pub const IDENTITY: Similarity = Similarity {
        rotation: DQuat::IDENTITY,
        scale: 1.0,
        translation: DVec3::ZERO,
    };

    /// `x` moved.
    pub fn apply(&self, x: DVec3) -> DVec3 {
        self.scale * (self.rotation * x) + self.translation
    }

    /// The point `x` whose image is `world`.
    pub fn invert(&self, world: DVec3) -> DVec3 {
        self.rotation.inverse() * ((world - self.translation) / self.scale)
    }

    /// The rotation's angle in degrees.
    pub fn angle_deg(&self) -> f64 {
        self.rotation.to_axis_angle().1.to_degrees()
    }
}

/// A target surface where a similarity puts it: queries in the world
/// frame, the tree built once in the target's own frame.
#[derive(Debug, Clone)]
pub struct Placed<'a> {
    /// The target in its own frame.
    pub surface: &'a Surface,
    /// Where it is put.
    pub placement: Similarity,
}

impl Placed<'_> {
    /// The nearest point of the placed target to the world point `p`
    /// (point and normal in the world frame).
    pub fn nearest(&self, p: DVec3) -> Option<Nearest> {
        let mut near = self.surface.nearest(self.placement.invert(p))?;
        near.point = self.placement.apply(near.point);
        near.normal = self.placement.rotation * near.normal;
        Some(near)
    }

    /// The target's vertices in the world frame.
    pub fn vertices(&self) -> Vec<DVec3> {
        self.surface
            .positions
            .iter()
            .map(|&x| self.placement.apply(x))
            .collect()
    }
}

/// How far two surfaces are apart, both ways (see the module
/// documentation), in the surfaces' units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Apart {
    /// Area-weighted mean squared distance of the organ's vertices to the
    /// target.
    pub organ_mean_square: f64,
    /// Area-weighted mean squared distance of the target's vertices to the
    /// organ.
    pub target_mean_square: f64,
    /// The largest distance of any vertex of either to the other.
    pub max: f64,
}

impl Apart {
    /// The RMS surface distance: `sqrt` of the two sides' mean.
    pub fn rms(&self) -> f64 {
        (0.5 * (self.organ_mean_square + self.target_mean_square)).sqrt()
    }

    /// The least-squares cost the fit lowers (twice the RMS squared).
    pub fn cost(&self) -> f64 {
        self.organ_mean_square + self.target_mean_square
    }
}

/// One residual of the fit, linear in the organ's positions `s`:
/// `Σ weights[k] · direction · s[particles[k]] − offset`. Its value at the
/// shape it was made at is a signed distance (or one component of a
/// vector to the nearest point), scaled by the square root of its vertex's
/// area share.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    /// The organ particles it reads.
    pub particles: [u32; 3],
    /// Their weights.
    pub weights: [f64; 3],
    /// The direction the distance is measured along, times the square
    /// root of the vertex's area share.
    pub direction: DVec3,
    /// The constant part.
    pub offset: f64,
}

impl Row {
    /// The residual at organ positions `s`.
    pub fn value(&self, s: &[DVec3]) -> f64 {
        (0..3)
            .map(|k| self.weights[k] * self.direction.dot(s[self.particles[k] as usize]))
            .sum::<f64>()
            - self.offset
    }
}

/// The organ's shape `s` (on `organ_triangles`) against the placed
/// target: how far apart, and the residual rows of the fit's Gauss–Newton
/// model at `s` (correspondences by projection, made afresh at each shape
/// the fit accepts).
///
/// Each vertex of either surface gives one row along the direction its
/// distance grows (the nearest triangle's normal where the nearest point
/// is inside the surface, the direction to the nearest point on an edge),
/// the first-order model of its distance with the surface's curvature
/// left out (point-to-plane, as in Chen and Medioni 1992); a vertex whose
/// nearest point is on the other surface's rim, where the surface ends,
/// gives three rows (the vector to that point, point-to-point as in Besl
/// and McKay 1992), so that an organ too short is pulled along, not only
/// towards, the target.
pub fn compare(
    s: &[DVec3],
    organ_triangles: &[[u32; 3]],
    target: &Placed<'_>,
    target_weights: &[f64],
    rows: Option<&mut Vec<Row>>,
) -> Apart {
    let organ = Surface::new(s.to_vec(), organ_triangles.to_vec());
    let organ_weights = organ.vertex_weights();
    let targets = target.vertices();
    let mut apart = Apart {
        organ_mean_square: 0.0,
        target_mean_square: 0.0,
        max: 0.0,
    };
    let mut out = rows;
    // Organ vertices to the target.
    for (i, &p) in s.iter().enumerate() {
        let Some(near) = target.nearest(p) else {
            continue;
        };
        let d = p - near.point;
        let distance = d.length();
        apart.organ_mean_square += organ_weights[i] * distance * distance;
        apart.max = apart.max.max(distance);
        if let Some(rows) = out.as_deref_mut() {
            let root = organ_weights[i].sqrt();
            let single = [i as u32, 0, 0];
            let one = [1.0, 0.0, 0.0];
            for direction in directions(d, distance, &near) {
                rows.push(Row {
                    particles: single,
                    weights: one,
                    direction: root * direction,
                    offset: root * direction.dot(near.point),
                });
            }
        }
    }
    // Target vertices to the organ.
    for (j, &t) in targets.iter().enumerate() {
        let Some(near) = organ.nearest(t) else {
            continue;
        };
        let d = near.point - t;
        let distance = d.length();
        apart.target_mean_square += target_weights[j] * distance * distance;
        apart.max = apart.max.max(distance);
        if let Some(rows) = out.as_deref_mut() {
            let root = target_weights[j].sqrt();
            let corners = organ_triangles[near.triangle as usize];
            for direction in directions(d, distance, &near) {
                rows.push(Row {
                    particles: corners,
                    weights: near.weights,
                    direction: root * direction,
                    offset: root * direction.dot(t),
                });
            }
        }
    }
    apart
}

/// The directions one vertex's distance is modelled along (see
/// [`compare`]); `d` runs from the fixed end of the pair (a target point)
/// to the end that moves with the organ, so a row's value is the distance
/// (signed, along a normal).
fn directions(d: DVec3, distance: f64, near: &Nearest) -> Vec<DVec3> {
    if near.on_rim {
        return vec![DVec3::X, DVec3::Y, DVec3::Z];
    }
    let inside = near.weights.iter().all(|&w| w > 1e-9);
    if (inside || distance <= 1e-12) && near.normal != DVec3::ZERO {
        // Signed along the normal: the sign follows d.
        vec![near.normal]
    } else if distance > 0.0 {
        vec![d / distance]
    } else {
        vec![DVec3::X, DVec3::Y, DVec3::Z]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sheet(n: usize, size: f64, z: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let mesh = anthesis_mesh::generate::flat_sheet(size, size, n, n);
        let positions = mesh
            .positions
            .iter()
            .map(|p| DVec3::new(p.x, p.y, p.z + z))
            .collect();
        (positions, mesh.triangles)
    }

    #[test]
    fn the_nearest_point_is_that_of_trying_every_triangle() {
        let mesh = anthesis_mesh::generate::test_petal(10.0, 4.0, 7, 15);
        let surface = Surface::new(mesh.positions.clone(), mesh.triangles.clone());
        let mut seed = 99u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..200 {
            let p = DVec3::new(next() * 16.0 - 8.0, next() * 20.0 - 5.0, next() * 8.0 - 4.0);
            let brute = (0..mesh.triangles.len())
                .map(|t| {
                    let [a, b, c] = mesh.triangle_positions(t);
                    closest_point_on_triangle(p, a, b, c).0.distance(p)
                })
                .fold(f64::INFINITY, f64::min);
            let near = surface.nearest(p).expect("triangles");
            assert!((near.point.distance(p) - brute).abs() < 1e-12, "{p}");
        }
    }

    #[test]
    fn two_parallel_sheets_are_their_gap_apart_whatever_their_meshes() {
        // A 4x4 and a 9x9 sheet of the same square, 0.3 apart.
        let (s, st) = sheet(4, 2.0, 0.0);
        let (t, tt) = sheet(9, 2.0, 0.3);
        let target = Surface::new(t, tt);
        let weights = target.vertex_weights();
        let placed = Placed {
            surface: &target,
            placement: Similarity::IDENTITY,
        };
        let mut rows = Vec::new();
        let apart = compare(&s, &st, &placed, &weights, Some(&mut rows));
        assert!((apart.rms() - 0.3).abs() < 1e-12, "{apart:?}");
        assert!((apart.max - 0.3).abs() < 1e-12, "{apart:?}");
        // The rows' squares sum to the cost at the shape they were made at.
        let sum: f64 = rows.iter().map(|r| r.value(&s).powi(2)).sum();
        assert!(
            (sum - apart.cost()).abs() < 1e-12,
            "{sum} vs {}",
            apart.cost()
        );
    }

    #[test]
    fn a_half_sheet_on_a_whole_one_is_far_from_it_the_other_way() {
        // The organ covers y in [0, 1] of a target covering [0, 2]: the
        // organ's side is zero, the target's uncovered half is up to 1
        // away (from y = 2 to the organ's rim at y = 1).
        let mesh = anthesis_mesh::generate::flat_sheet(2.0, 1.0, 5, 5);
        let target_mesh = anthesis_mesh::generate::flat_sheet(2.0, 2.0, 5, 9);
        let target = Surface::new(target_mesh.positions.clone(), target_mesh.triangles.clone());
        let placed = Placed {
            surface: &target,
            placement: Similarity::IDENTITY,
        };
        let apart = compare(
            &mesh.positions,
            &mesh.triangles,
            &placed,
            &target.vertex_weights(),
            None,
        );
        assert!(apart.organ_mean_square < 1e-24, "{apart:?}");
        assert!((apart.max - 1.0).abs() < 1e-9, "{apart:?}");
        assert!(apart.target_mean_square > 0.05, "{apart:?}");
    }

    #[test]
    fn the_rim_is_the_outline_and_its_nearest_point_lies_on_it() {
        // A 2 x 2 sheet: its outline is the square's four sides.
        let (t, tt) = sheet(5, 2.0, 0.0);
        let rim = Rim::new(&t, &tt);
        // From the middle of the sheet, the nearest outline point is a
        // side's middle, 1 away; from outside a corner, the corner.
        let middle = DVec3::new(0.0, 1.0, 0.5);
        let near = rim.nearest(middle).expect("an outline");
        assert!(
            (near.distance(middle) - 0.5f64.hypot(1.0)).abs() < 1e-12,
            "{near}"
        );
        let corner = rim.nearest(DVec3::new(3.0, 4.0, 0.0)).expect("an outline");
        assert!(
            (corner - DVec3::new(1.0, 2.0, 0.0)).length() < 1e-12,
            "{corner}"
        );
    }

    #[test]
    fn a_placed_surface_answers_in_the_world_frame() {
        let (t, tt) = sheet(3, 1.0, 0.0);
        let target = Surface::new(t, tt);
        let placement = Similarity {
            rotation: DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2),
            scale: 2.0,
            translation: DVec3::new(0.0, 0.0, 5.0),
        };
        let placed = Placed {
            surface: &target,
            placement,
        };
        // The unit sheet in z = 0 becomes a 2x2 sheet in the plane y = 0
        // (z from 5), so a point at y = 0.7 above its middle is 0.7 away.
        let p = DVec3::new(0.5, 0.7, 6.0);
        let near = placed.nearest(p).expect("triangles");
        assert!((near.point - DVec3::new(0.5, 0.0, 6.0)).length() < 1e-12);
        assert!((near.normal.abs() - DVec3::Y).length() < 1e-12);
        let back = placement.invert(placement.apply(DVec3::new(0.3, -0.2, 0.9)));
        assert!((back - DVec3::new(0.3, -0.2, 0.9)).length() < 1e-12);
    }
}

//! What a biologist measures on a run (issue 41 item 3): per keyframe and
//! organ, the mean and Gaussian curvature, the principal stretches against
//! the bud, the midrib's and the margin's length and the contact area. One
//! implementation for `anthesis measure`, the window's Measure panel and
//! Python's `anthesis.measure`.
//!
//! - **Curvature** per vertex by the discrete operators of Meyer, Desbrun,
//!   Schröder and Barr ("Discrete differential-geometry operators for
//!   triangulated 2-manifolds", 2003): K is the angle defect over the mixed
//!   Voronoi area, H half the cotangent Laplacian of the positions (the
//!   mean-curvature normal) over the same area, signed along the vertex
//!   normal (the area-weighted sum of its triangles' normals). On a sphere
//!   whose triangles wind counter-clockwise seen from outside H = 1/R and
//!   K = 1/R². Rim vertices get NaN (their angle defect is the rim's
//!   geodesic curvature, not K). Summaries: the median over the interior
//!   vertices and the mean over them weighted by their mixed areas.
//! - **Principal stretches** per triangle: the singular values of the map
//!   from the triangle in the bud (keyframe 0) to the triangle now, largest
//!   first (1: unchanged; 1.4: 40 % longer). Per vertex: the mean over its
//!   triangles weighted by their area in the bud. Summaries: the mean of
//!   each over the organ weighted by the triangles' area in the bud.
//! - **Midrib length**: the curve u = 0.5 from v = 0 to v = 1 traced
//!   through the UV layout at [`MIDRIB_SAMPLES`] points (each in the first
//!   triangle that holds it), summed as a polyline.
//! - **Margin length**: the rim without its base: the boundary edges with
//!   at least one end above v = [`MARGIN_BASE_V`].
//! - **Contact area**: the mixed Voronoi area (as for the curvatures;
//!   these areas tile the surface) of the organ's vertices that lie within
//!   the contact distance of another simulated organ's surface or of a
//!   part's (receptacle, stamens, pistil, stem; their flat triangles) at
//!   that keyframe. The simulation holds a particle it keeps off a
//!   neighbour at the collision offset from the neighbour's (Phong)
//!   surface, so the distance is by default twice the project's
//!   `collision_offset` ([`default_contact_distance`]): every particle the
//!   simulation holds in contact counts, with room for the flat triangles
//!   lying inside the Phong surface. Per vertex, as the simulation counts
//!   particles (its `contact_particles`, which also counts an organ held
//!   off itself); an organ simulated alone touches only the parts.
//!
//! Everything is in the project's length units; [`Quantity`] scales a
//! summary into the project's real unit (millimetres) for tables.

use std::collections::HashMap;
use std::f64::consts::PI;

use anthesis_mesh::Mesh;
use anthesis_mesh::nearest::closest_point_on_triangle;
use glam::{DVec2, DVec3};
use rayon::prelude::*;

/// Points the midrib is traced at, from the base to the tip.
pub const MIDRIB_SAMPLES: usize = 400;

/// The margin leaves out rim edges with both ends at or below this v (the
/// base, where the organ sits on the receptacle).
pub const MARGIN_BASE_V: f64 = 0.05;

/// The contact distance [`measure_keyframe`] uses for a project whose
/// collision offset is `collision_offset`: twice it.
pub fn default_contact_distance(collision_offset: f64) -> f64 {
    2.0 * collision_offset
}

/// Per vertex: the sum of its triangles' angles at it, its mixed Voronoi
/// area, the cotangent Laplacian of the positions and the area-weighted
/// normal.
struct CurvatureParts {
    angle_sum: Vec<f64>,
    area: Vec<f64>,
    laplacian: Vec<DVec3>,
    normal: Vec<DVec3>,
}

fn cot(a: DVec3, b: DVec3) -> f64 {
    a.dot(b) / a.cross(b).length().max(1e-300)
}

fn curvature_parts(x: &[DVec3], triangles: &[[u32; 3]]) -> CurvatureParts {
    let n = x.len();
    let mut parts = CurvatureParts {
        angle_sum: vec![0.0; n],
        area: vec![0.0; n],
        laplacian: vec![DVec3::ZERO; n],
        normal: vec![DVec3::ZERO; n],
    };
    for tri in triangles {
        let f = tri.map(|i| i as usize);
        let p = f.map(|i| x[i]);
        let face_normal = (p[1] - p[0]).cross(p[2] - p[0]);
        let face_area = 0.5 * face_normal.length();
        let mut angles = [0.0; 3];
        let mut cots = [0.0; 3];
        for k in 0..3 {
            let (u, v) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
            let cos = u.dot(v) / (u.length() * v.length()).max(1e-300);
            angles[k] = cos.clamp(-1.0, 1.0).acos();
            cots[k] = cot(u, v);
        }
        let obtuse = angles.map(|a| a > PI / 2.0);
        let any_obtuse = obtuse.iter().any(|&o| o);
        for k in 0..3 {
            let (i, j, l) = (f[k], f[(k + 1) % 3], f[(k + 2) % 3]);
            parts.angle_sum[i] += angles[k];
            parts.normal[i] += face_normal;
            // Edge (j, l) is opposite corner k: weight cot(angle at k).
            let w = cots[k] * (x[j] - x[l]);
            parts.laplacian[j] += w;
            parts.laplacian[l] -= w;
            // Mixed area: Voronoi in non-obtuse triangles, else a half or a
            // quarter of the triangle.
            let share = if !any_obtuse {
                ((x[j] - x[i]).length_squared() * cots[(k + 2) % 3]
                    + (x[l] - x[i]).length_squared() * cots[(k + 1) % 3])
                    / 8.0
            } else if obtuse[k] {
                face_area / 2.0
            } else {
                face_area / 4.0
            };
            parts.area[i] += share;
        }
    }
    parts
}

/// Whether each vertex lies on an edge used by one triangle only.
pub fn boundary_vertices(triangles: &[[u32; 3]], vertex_count: usize) -> Vec<bool> {
    let mut on = vec![false; vertex_count];
    for [a, b] in boundary_edges(triangles) {
        on[a as usize] = true;
        on[b as usize] = true;
    }
    on
}

/// The edges used by one triangle only, each as its two vertices (smaller
/// first), in ascending order.
pub fn boundary_edges(triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let mut count: HashMap<[u32; 2], u32> = HashMap::new();
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *count.entry([a.min(b), a.max(b)]).or_default() += 1;
        }
    }
    let mut edges: Vec<[u32; 2]> = count
        .into_iter()
        .filter(|&(_, c)| c == 1)
        .map(|(e, _)| e)
        .collect();
    edges.sort_unstable();
    edges
}

/// Per vertex: the angle defect 2π − Σθ (radians) and the mixed Voronoi
/// area (length²); K = defect / area at interior vertices.
pub fn angle_defects_and_areas(x: &[DVec3], triangles: &[[u32; 3]]) -> (Vec<f64>, Vec<f64>) {
    let parts = curvature_parts(x, triangles);
    let defect = parts.angle_sum.iter().map(|s| 2.0 * PI - s).collect();
    (defect, parts.area)
}

/// Mean and Gaussian curvature per vertex, with the mixed Voronoi areas
/// (the weights of the area-weighted summaries). NaN on the rim (given as
/// `boundary`, see [`boundary_vertices`]).
pub struct Curvatures {
    /// H per vertex (1/length): positive where the surface bends away from
    /// its normal (a sphere with outward normals).
    pub mean: Vec<f64>,
    /// K per vertex (1/length²).
    pub gaussian: Vec<f64>,
    /// The mixed Voronoi area of each vertex (length²).
    pub area: Vec<f64>,
}

/// [`Curvatures`] of the surface `x`, `triangles`, NaN where `boundary`.
pub fn vertex_curvatures(x: &[DVec3], triangles: &[[u32; 3]], boundary: &[bool]) -> Curvatures {
    let parts = curvature_parts(x, triangles);
    let mut mean = Vec::with_capacity(x.len());
    let mut gaussian = Vec::with_capacity(x.len());
    for i in 0..x.len() {
        if boundary.get(i).copied().unwrap_or(false) {
            mean.push(f64::NAN);
            gaussian.push(f64::NAN);
            continue;
        }
        let area = parts.area[i];
        gaussian.push((2.0 * PI - parts.angle_sum[i]) / area);
        let mean_normal = parts.laplacian[i] / (2.0 * area);
        let unit = parts.normal[i] / parts.normal[i].length();
        mean.push(0.5 * mean_normal.dot(unit));
    }
    Curvatures {
        mean,
        gaussian,
        area: parts.area,
    }
}

/// The principal stretches of one triangle from `rest` to `now` (corner
/// positions): the singular values of the in-plane deformation gradient,
/// largest first. A degenerate rest triangle gives NaN.
pub fn triangle_stretches(rest: [DVec3; 3], now: [DVec3; 3]) -> [f64; 2] {
    let (e1, e2) = (rest[1] - rest[0], rest[2] - rest[0]);
    let t1 = e1 / e1.length();
    let normal = e1.cross(e2);
    let t2 = (normal / normal.length()).cross(t1);
    // The rest edges in the triangle's own frame, as the columns of R.
    let (r00, r01, r10, r11) = (e1.dot(t1), e2.dot(t1), e1.dot(t2), e2.dot(t2));
    let det = r00 * r11 - r01 * r10;
    let (d1, d2) = (now[1] - now[0], now[2] - now[0]);
    // F = [d1 d2] R⁻¹: its two columns.
    let f1 = (d1 * r11 - d2 * r10) / det;
    let f2 = (d2 * r00 - d1 * r01) / det;
    // The right Cauchy-Green tensor C = FᵀF and its eigenvalues.
    let (a, b, d) = (f1.dot(f1), f1.dot(f2), f2.dot(f2));
    let half_trace = 0.5 * (a + d);
    let root = (0.25 * (a - d) * (a - d) + b * b).sqrt();
    let major = half_trace + root;
    // The smaller one as det C / λ₁: no cancellation when they differ a lot.
    let det_c = (a * d - b * b).max(0.0);
    let minor = if major > 0.0 { det_c / major } else { 0.0 };
    [major.sqrt(), minor.sqrt()]
}

/// [`triangle_stretches`] of every triangle from `rest` to `now`.
pub fn principal_stretches(rest: &[DVec3], now: &[DVec3], triangles: &[[u32; 3]]) -> Vec<[f64; 2]> {
    triangles
        .iter()
        .map(|t| {
            let c = t.map(|i| i as usize);
            triangle_stretches(c.map(|i| rest[i]), c.map(|i| now[i]))
        })
        .collect()
}

/// A curve through the UV layout, as a triangle and barycentric weights
/// per point (points outside every triangle left out): the same points on
/// every keyframe of a run.
#[derive(Debug, Clone)]
pub struct UvPath {
    points: Vec<(usize, [f64; 3])>,
}

impl UvPath {
    /// The points `uv` of the layout `uvs`, `triangles`, each in the first
    /// triangle that holds it (within 1e-12 in barycentric terms).
    pub fn new(uvs: &[DVec2], triangles: &[[u32; 3]], uv: &[DVec2]) -> UvPath {
        let points = uv
            .iter()
            .filter_map(|&q| {
                triangles.iter().enumerate().find_map(|(m, t)| {
                    let [a, b, c] = t.map(|i| uvs[i as usize]);
                    let (v0, v1, d) = (b - a, c - a, q - a);
                    let det = v0.x * v1.y - v0.y * v1.x;
                    let s = (d.x * v1.y - d.y * v1.x) / det;
                    let t = (v0.x * d.y - v0.y * d.x) / det;
                    (s >= -1e-12 && t >= -1e-12 && s + t <= 1.0 + 1e-12)
                        .then_some((m, [1.0 - s - t, s, t]))
                })
            })
            .collect();
        UvPath { points }
    }

    /// The midrib: u = 0.5 from v = 0 to v = 1 at `samples` points.
    pub fn midrib(uvs: &[DVec2], triangles: &[[u32; 3]], samples: usize) -> UvPath {
        let step = 1.0 / (samples.max(2) - 1) as f64;
        let uv: Vec<DVec2> = (0..samples)
            .map(|i| DVec2::new(0.5, (i as f64 * step).min(1.0)))
            .collect();
        UvPath::new(uvs, triangles, &uv)
    }

    /// How many of the points lie in the layout.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether no point lies in the layout.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The points on the surface `x` (same vertices as the layout).
    pub fn points(&self, x: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
        self.points
            .iter()
            .map(|&(m, w)| {
                let c = triangles[m].map(|i| x[i as usize]);
                w[0] * c[0] + w[1] * c[1] + w[2] * c[2]
            })
            .collect()
    }

    /// The length of the polyline through the points on the surface `x`.
    pub fn length(&self, x: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
        let points = self.points(x, triangles);
        points.windows(2).map(|p| p[0].distance(p[1])).sum()
    }
}

/// The margin of a layout: its boundary edges with at least one end above
/// v = `base_v`.
pub fn margin_edges(uvs: &[DVec2], triangles: &[[u32; 3]], base_v: f64) -> Vec<[u32; 2]> {
    boundary_edges(triangles)
        .into_iter()
        .filter(|e| e.iter().any(|&i| uvs[i as usize].y > base_v))
        .collect()
}

/// The summed length of `edges` on the surface `x`.
pub fn edges_length(x: &[DVec3], edges: &[[u32; 2]]) -> f64 {
    edges
        .iter()
        .map(|&[a, b]| x[a as usize].distance(x[b as usize]))
        .sum()
}

/// A uniform grid over one organ's triangles, each entered in every cell
/// its box (grown by the contact distance) touches.
struct TriangleGrid {
    cell: f64,
    cells: HashMap<[i64; 3], Vec<u32>>,
    low: DVec3,
    high: DVec3,
}

impl TriangleGrid {
    fn new(x: &[DVec3], triangles: &[[u32; 3]], distance: f64) -> TriangleGrid {
        let boxes: Vec<(DVec3, DVec3)> = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| x[i as usize]);
                (a.min(b).min(c) - distance, a.max(b).max(c) + distance)
            })
            .collect();
        let extent = boxes
            .iter()
            .map(|(lo, hi)| (*hi - *lo).max_element())
            .sum::<f64>()
            / boxes.len().max(1) as f64;
        let cell = extent.max(distance).max(1e-12);
        let key = |p: DVec3| (p / cell).floor().as_i64vec3().to_array();
        let mut cells: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        let (mut low, mut high) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for (t, (lo, hi)) in boxes.iter().enumerate() {
            low = low.min(*lo);
            high = high.max(*hi);
            let (a, b) = (key(*lo), key(*hi));
            for i in a[0]..=b[0] {
                for j in a[1]..=b[1] {
                    for k in a[2]..=b[2] {
                        cells.entry([i, j, k]).or_default().push(t as u32);
                    }
                }
            }
        }
        TriangleGrid {
            cell,
            cells,
            low,
            high,
        }
    }

    /// Whether `p` lies within `distance` of one of the triangles.
    fn near(&self, p: DVec3, x: &[DVec3], triangles: &[[u32; 3]], distance: f64) -> bool {
        if p.cmplt(self.low).any() || p.cmpgt(self.high).any() {
            return false;
        }
        let key = (p / self.cell).floor().as_i64vec3().to_array();
        self.cells.get(&key).is_some_and(|list| {
            list.iter().any(|&t| {
                let [a, b, c] = triangles[t as usize].map(|i| x[i as usize]);
                closest_point_on_triangle(p, a, b, c).0.distance(p) <= distance
            })
        })
    }
}

/// A surface as positions and triangles.
pub type Surface<'a> = (&'a [DVec3], &'a [[u32; 3]]);

/// Per organ, per vertex: whether it lies within `distance` of another
/// organ of `organs` or of one of `parts` (each organ's and part's
/// positions and triangles at one keyframe).
pub fn contact_vertices(
    organs: &[Surface<'_>],
    parts: &[Surface<'_>],
    distance: f64,
) -> Vec<Vec<bool>> {
    let grids = grids(organs, distance);
    let part_grids = grids_of(parts, distance);
    (0..organs.len())
        .into_par_iter()
        .map(|o| contact_of(&grids, organs, &part_grids, parts, o, distance))
        .collect()
}

/// [`contact_vertices`] of organ `organ` only.
pub fn contact_vertices_of(
    organs: &[Surface<'_>],
    parts: &[Surface<'_>],
    organ: usize,
    distance: f64,
) -> Vec<bool> {
    let grids = grids(organs, distance);
    let part_grids = grids_of(parts, distance);
    contact_of(&grids, organs, &part_grids, parts, organ, distance)
}

fn grids(organs: &[Surface<'_>], distance: f64) -> Vec<TriangleGrid> {
    grids_of(organs, distance)
}

fn grids_of(surfaces: &[Surface<'_>], distance: f64) -> Vec<TriangleGrid> {
    surfaces
        .par_iter()
        .map(|(x, t)| TriangleGrid::new(x, t, distance))
        .collect()
}

fn contact_of(
    grids: &[TriangleGrid],
    organs: &[Surface<'_>],
    part_grids: &[TriangleGrid],
    parts: &[Surface<'_>],
    o: usize,
    distance: f64,
) -> Vec<bool> {
    let (x, _) = organs[o];
    let apart =
        |a: &TriangleGrid, b: &TriangleGrid| a.high.cmplt(b.low).any() || a.low.cmpgt(b.high).any();
    let others: Vec<(&TriangleGrid, Surface<'_>)> = (0..organs.len())
        .filter(|&b| b != o)
        .map(|b| (&grids[b], organs[b]))
        .chain(part_grids.iter().zip(parts.iter().copied()))
        .filter(|(grid, _)| !apart(&grids[o], grid))
        .collect();
    x.iter()
        .map(|&p| {
            others
                .iter()
                .any(|(grid, (y, t))| grid.near(p, y, t, distance))
        })
        .collect()
}

/// What of an organ stays the same over a run: its triangles, its UV
/// layout's midrib and margin, its rim. Built once per organ.
#[derive(Debug, Clone)]
pub struct OrganLayout {
    triangles: Vec<[u32; 3]>,
    boundary: Vec<bool>,
    midrib: UvPath,
    margin: Vec<[u32; 2]>,
}

impl OrganLayout {
    /// The layout of an organ whose mesh (template) is `mesh`.
    pub fn new(mesh: &Mesh) -> OrganLayout {
        OrganLayout::with_margin_base(mesh, MARGIN_BASE_V)
    }

    /// [`OrganLayout::new`] with the margin's base at v = `base_v`
    /// instead of [`MARGIN_BASE_V`].
    pub fn with_margin_base(mesh: &Mesh, base_v: f64) -> OrganLayout {
        OrganLayout {
            triangles: mesh.triangles.clone(),
            boundary: boundary_vertices(&mesh.triangles, mesh.vertex_count()),
            midrib: UvPath::midrib(&mesh.uvs, &mesh.triangles, MIDRIB_SAMPLES),
            margin: margin_edges(&mesh.uvs, &mesh.triangles, base_v),
        }
    }

    /// The organ's triangles.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }
}

/// One organ at one keyframe: the fields per vertex and triangle, and the
/// summary a table row holds. Lengths in project units.
#[derive(Debug, Clone)]
pub struct OrganMeasure {
    /// H per vertex (1/length), NaN on the rim.
    pub mean_curvature: Vec<f64>,
    /// K per vertex (1/length²), NaN on the rim.
    pub gaussian_curvature: Vec<f64>,
    /// Principal stretches per triangle against the bud, largest first.
    pub stretches: Vec<[f64; 2]>,
    /// Principal stretches per vertex: its triangles' weighted by their
    /// area in the bud.
    pub vertex_stretches: Vec<[f64; 2]>,
    /// Per vertex: whether it touches another organ or a part.
    pub contact: Vec<bool>,
    /// The summary.
    pub summary: Summary,
}

/// One organ at one keyframe, as a table row holds it (project units).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Summary {
    /// Surface area (length²).
    pub area: f64,
    /// Median of H over the interior vertices.
    pub mean_curvature_median: f64,
    /// Mean of H over the interior vertices, weighted by their areas.
    pub mean_curvature_mean: f64,
    /// Median of K over the interior vertices.
    pub gaussian_curvature_median: f64,
    /// Mean of K over the interior vertices, weighted by their areas.
    pub gaussian_curvature_mean: f64,
    /// The larger principal stretch, mean over the triangles weighted by
    /// their area in the bud.
    pub stretch_major_mean: f64,
    /// The smaller principal stretch, the same mean.
    pub stretch_minor_mean: f64,
    /// Length of the midrib.
    pub midrib_length: f64,
    /// Length of the margin.
    pub margin_length: f64,
    /// The mixed area of the vertices touching another organ or a part
    /// (length²).
    pub contact_area: f64,
}

/// One column of a table of [`Summary`]s: its name, what it reads and the
/// power of length it has (to scale it into the real unit).
#[derive(Debug, Clone, Copy)]
pub struct Quantity {
    /// The column's name (`mean_curvature_median`).
    pub name: &'static str,
    /// Words for a legend or a plot's axis.
    pub label: &'static str,
    /// Length to this power: 1 a length, 2 an area, -1 a curvature, 0 none.
    pub length_power: i32,
    /// The value in a summary (project units).
    pub get: fn(&Summary) -> f64,
}

impl Quantity {
    /// The unit of the column when lengths are in `length` (`mm`):
    /// `mm`, `mm^2`, `1/mm`, `1/mm^2`, or `1` for a ratio.
    pub fn unit(&self, length: &str) -> String {
        match self.length_power {
            0 => "1".to_string(),
            1 => length.to_string(),
            p if p > 1 => format!("{length}^{p}"),
            -1 => format!("1/{length}"),
            p => format!("1/{length}^{}", -p),
        }
    }

    /// The value of `summary` with one project unit `scale` real units
    /// long.
    pub fn value(&self, summary: &Summary, scale: f64) -> f64 {
        (self.get)(summary) * scale.powi(self.length_power)
    }
}

/// The columns of a table of [`Summary`]s, in order.
pub const QUANTITIES: [Quantity; 10] = [
    Quantity {
        name: "area",
        label: "surface area",
        length_power: 2,
        get: |s| s.area,
    },
    Quantity {
        name: "mean_curvature_median",
        label: "mean curvature H, median",
        length_power: -1,
        get: |s| s.mean_curvature_median,
    },
    Quantity {
        name: "mean_curvature_mean",
        label: "mean curvature H, area-weighted mean",
        length_power: -1,
        get: |s| s.mean_curvature_mean,
    },
    Quantity {
        name: "gaussian_curvature_median",
        label: "Gaussian curvature K, median",
        length_power: -2,
        get: |s| s.gaussian_curvature_median,
    },
    Quantity {
        name: "gaussian_curvature_mean",
        label: "Gaussian curvature K, area-weighted mean",
        length_power: -2,
        get: |s| s.gaussian_curvature_mean,
    },
    Quantity {
        name: "stretch_major_mean",
        label: "larger principal stretch, mean",
        length_power: 0,
        get: |s| s.stretch_major_mean,
    },
    Quantity {
        name: "stretch_minor_mean",
        label: "smaller principal stretch, mean",
        length_power: 0,
        get: |s| s.stretch_minor_mean,
    },
    Quantity {
        name: "midrib_length",
        label: "midrib length",
        length_power: 1,
        get: |s| s.midrib_length,
    },
    Quantity {
        name: "margin_length",
        label: "margin length",
        length_power: 1,
        get: |s| s.margin_length,
    },
    Quantity {
        name: "contact_area",
        label: "contact area",
        length_power: 2,
        get: |s| s.contact_area,
    },
];

/// The median of the values that are not NaN (the mean of the middle two
/// of an even count, as numpy's `nanmedian`); NaN when there are none.
pub fn nan_median(values: &[f64]) -> f64 {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| !x.is_nan()).collect();
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_unstable_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

/// The mean of the values that are not NaN weighted by `weights`; NaN
/// when there are none.
pub fn weighted_mean(values: &[f64], weights: &[f64]) -> f64 {
    let (sum, total) = values
        .iter()
        .zip(weights)
        .filter(|(v, _)| !v.is_nan())
        .fold((0.0, 0.0), |(s, t), (v, w)| (s + v * w, t + w));
    if total > 0.0 { sum / total } else { f64::NAN }
}

/// Every organ at one keyframe: `layouts`, `bud` and `now` per organ, in
/// the same order, contact measured against the other organs of `now` and
/// the `parts` (their surfaces at that keyframe) within `contact_distance`.
pub fn measure_keyframe(
    layouts: &[OrganLayout],
    bud: &[Vec<DVec3>],
    now: &[Vec<DVec3>],
    parts: &[Surface<'_>],
    contact_distance: f64,
) -> Vec<OrganMeasure> {
    let surfaces: Vec<Surface<'_>> = layouts
        .iter()
        .zip(now)
        .map(|(l, x)| (x.as_slice(), l.triangles.as_slice()))
        .collect();
    let contact = contact_vertices(&surfaces, parts, contact_distance);
    layouts
        .par_iter()
        .zip(bud)
        .zip(now)
        .zip(contact)
        .map(|(((layout, bud), x), contact)| measure_organ(layout, bud, x, contact))
        .collect()
}

/// One organ at one keyframe, its vertices' `contact` given.
pub fn measure_organ(
    layout: &OrganLayout,
    bud: &[DVec3],
    x: &[DVec3],
    contact: Vec<bool>,
) -> OrganMeasure {
    let triangles = &layout.triangles;
    let curvature = vertex_curvatures(x, triangles, &layout.boundary);
    let stretches = principal_stretches(bud, x, triangles);
    let area_now: Vec<f64> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| x[i as usize]);
            0.5 * (b - a).cross(c - a).length()
        })
        .collect();
    let area_bud: Vec<f64> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| bud[i as usize]);
            0.5 * (b - a).cross(c - a).length()
        })
        .collect();
    let n = x.len();
    let mut stretch_sum = vec![[0.0; 2]; n];
    let mut bud_weight = vec![0.0; n];
    for (m, t) in triangles.iter().enumerate() {
        for &i in t {
            let i = i as usize;
            stretch_sum[i][0] += area_bud[m] * stretches[m][0];
            stretch_sum[i][1] += area_bud[m] * stretches[m][1];
            bud_weight[i] += area_bud[m];
        }
    }
    let vertex_stretches = stretch_sum
        .iter()
        .zip(&bud_weight)
        .map(|(s, w)| [s[0] / w, s[1] / w])
        .collect();
    let major: Vec<f64> = stretches.iter().map(|s| s[0]).collect();
    let minor: Vec<f64> = stretches.iter().map(|s| s[1]).collect();
    let summary = Summary {
        area: area_now.iter().sum(),
        mean_curvature_median: nan_median(&curvature.mean),
        mean_curvature_mean: weighted_mean(&curvature.mean, &curvature.area),
        gaussian_curvature_median: nan_median(&curvature.gaussian),
        gaussian_curvature_mean: weighted_mean(&curvature.gaussian, &curvature.area),
        stretch_major_mean: weighted_mean(&major, &area_bud),
        stretch_minor_mean: weighted_mean(&minor, &area_bud),
        midrib_length: layout.midrib.length(x, triangles),
        margin_length: edges_length(x, &layout.margin),
        // Folded from +0 (a sum of nothing is -0 in Rust, "-0" in a table).
        contact_area: curvature
            .area
            .iter()
            .zip(&contact)
            .filter(|(_, c)| **c)
            .fold(0.0, |sum, (a, _)| sum + a),
    };
    OrganMeasure {
        mean_curvature: curvature.mean,
        gaussian_curvature: curvature.gaussian,
        stretches,
        vertex_stretches,
        contact,
        summary,
    }
}

/// One project unit in millimetres and the unit's name for a table: `mm`
/// when the project states its real unit, else 1 and `unit` (the project's
/// own length unit).
pub fn real_scale(unit: Option<anthesis_flower::unit::Unit>) -> (f64, &'static str) {
    match unit {
        Some(unit) => (unit.metres() * 1e3, "mm"),
        None => (1.0, "unit"),
    }
}

//! Bud builders: organs (petals, sepals) from parametric surfaces — bicubic
//! Bézier patches and PDE sweep surfaces — remeshed into near-isotropic
//! triangle meshes with UVs.
//!
//! ```
//! use anthesis_bud::{RemeshOptions, build_organ, lily_petal_surface};
//!
//! let bud = build_organ(&lily_petal_surface(), &RemeshOptions::new(1.3))?;
//! assert!(bud.quality.min_angle_deg >= 30.0);
//! println!("{} vertices, mean edge {:.2}", bud.quality.vertices, bud.quality.mean_edge);
//! # Ok::<(), anthesis_bud::BudError>(())
//! ```
//!
//! Conventions (ARCHITECTURE.md): the surface is given in the organ template
//! frame (base at the origin, growing along +Y, inner side facing −Z). The
//! mesh UVs are the surface parameters: `u` across (midrib at `u = 0.5` for a
//! symmetric surface), `v` from the base (`0`) to the tip (`1`). Triangles
//! wind counter-clockwise around the normal that points to the inner side
//! (see [`InnerSide`]).
//!
//! The mesh is built in three steps: rows of points at constant 3D spacing
//! along `v`, each spaced evenly in 3D arc length and staggered like a
//! hexagonal lattice, with the margins sampled separately at the target
//! spacing; rows and margins stitched into triangle strips; then alternating
//! edge flips (raising the smallest angle) and tangential smoothing in the
//! parameter domain, with boundary vertices sliding along their boundary.

#![warn(missing_docs)]

pub mod bspline;
pub mod dynamic;
mod examples;
pub mod formats;
mod from_mesh;
mod net;
mod quality;
mod remesh;
mod scan;
mod sketch;
mod surface;
mod sweep_edit;
mod vein;

pub use examples::{eustoma_petal_surface, lily_petal_surface};
pub use from_mesh::{MeshSurface, remesh_mesh};
pub use net::mirrored;
pub use quality::{
    MeshQuality, crossing_depth, find_self_intersection, quality, self_intersections,
};
pub use scan::{
    ScanCorners, ScanError, ScanFit, ScanFitOptions, ScanOutline, fit_scan, middle_length,
    midrib_length, reversed_across,
};
pub use sketch::{
    PetalSketch, SKETCH_COLUMNS, SKETCH_ROWS, SketchError, SketchFrame, SketchTool, SketchedPetal,
    StrokeRole,
};
pub use surface::{BezierCurve, BezierPatch, MAX_STRETCH_TO_BEND, PdeSweep, Surface, bernstein3};
pub use sweep_edit::SweepCurve;
pub use vein::{SideStroke, Vein, VeinError, bend_along_vein};

use anthesis_mesh::{Mesh, MeshError};
use thiserror::Error;

/// Which side of the surface is the organ's inner (adaxial) side; the mesh
/// winds counter-clockwise around the normal pointing to it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum InnerSide {
    /// The side the surface faces on average towards −Z (the template
    /// frame's inner direction): the winding is chosen so the area-weighted
    /// mean normal has a negative Z component. If the mean normal has no Z
    /// component at all, the surface normal `dS/du × dS/dv` is kept.
    #[default]
    Auto,
    /// The side `dS/du × dS/dv` points to.
    AlongSurfaceNormal,
    /// The side `−(dS/du × dS/dv)` points to.
    AgainstSurfaceNormal,
}

/// The version of what the remesher gives ([`remesh_mesh`] and the
/// surface remeshers it shares code with). Caches key remeshed meshes on it
/// (`anthesis_flower::remesh_cache`), so **bump it in the same commit as
/// any change that can change the mesh remeshed from the same input**: a
/// cache keyed on the old value would otherwise go on serving the old mesh.
/// The flower crate's `a_changed_remesher_must_bump_its_version` test holds
/// the digest of a remesh made at this version and fails when the output
/// changes without the bump.
pub const REMESH_VERSION: u32 = 1;

/// How to remesh a surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RemeshOptions {
    /// The mean 3D edge length to aim for (the paper: 1.3 for a lily petal,
    /// 1.4 for a sepal, 2.0 for an Eustoma petal).
    pub target_edge: f64,
    /// Rounds of edge flips + tangential smoothing.
    pub smoothing_iterations: usize,
    /// The mesh is refused if its smallest angle (degrees) is below this.
    pub min_angle_floor_deg: f64,
    /// The mesh is refused if it would need more vertices than this.
    pub max_vertices: usize,
    /// Which side of the surface the triangles' winding makes the inner one.
    pub inner_side: InnerSide,
    /// Check the finished mesh for self-intersections (cheap: a spatial hash).
    pub check_self_intersection: bool,
}

impl RemeshOptions {
    /// Defaults for `target_edge`: 40 smoothing rounds, quality floor 20°,
    /// at most 200 000 vertices, inner side chosen automatically,
    /// self-intersection check on.
    pub fn new(target_edge: f64) -> Self {
        RemeshOptions {
            target_edge,
            smoothing_iterations: 40,
            min_angle_floor_deg: 20.0,
            max_vertices: 200_000,
            inner_side: InnerSide::Auto,
            check_self_intersection: true,
        }
    }
}

/// A remeshed organ and its quality.
#[derive(Debug, Clone, PartialEq)]
pub struct Bud {
    /// The mesh, in the template frame, with UVs = surface parameters.
    pub mesh: Mesh,
    /// Its edge lengths and angles.
    pub quality: MeshQuality,
}

/// Why a surface could not be meshed.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum BudError {
    #[error("the target edge length must be a positive number, got {0}")]
    /// The target edge length is zero, negative or not finite.
    InvalidTargetEdge(f64),
    #[error("the surface has a non-finite point (NaN or infinite) at (u, v) = ({u:.3}, {v:.3})")]
    /// The surface is NaN or infinite somewhere.
    NonFinitePoint {
        /// Where, across.
        u: f64,
        /// Where, from base to tip.
        v: f64,
    },
    #[error(
        "the surface has no length from base to tip (its lines of constant u are single points)"
    )]
    /// Base and tip coincide.
    ZeroLength,
    #[error(
        "the surface has zero width at v = {v:.3}; only the tip (v = 1) may come to a point, the base and the blade need a width"
    )]
    /// A row below the tip has no width.
    ZeroWidth {
        /// The row, from base (0) to tip (1).
        v: f64,
    },
    #[error(
        "target edge {target_edge} is too large for this organ ({length:.3} long from base to tip): it would get {rows} rows of vertices, at least 3 are needed"
    )]
    /// The target edge is too long for the organ.
    TooFewRows {
        /// The target edge length asked for.
        target_edge: f64,
        /// The organ's length from base to tip.
        length: f64,
        /// The rows it would get.
        rows: usize,
    },
    #[error(
        "target edge {target_edge} is too small for this organ (area {area:.3}): it would need about {estimated} vertices, more than the limit of {limit}"
    )]
    /// The target edge is too short for the organ.
    TooManyVertices {
        /// The target edge length asked for.
        target_edge: f64,
        /// The surface's area.
        area: f64,
        /// The vertices it would need, estimated from the area.
        estimated: usize,
        /// [`RemeshOptions::max_vertices`].
        limit: usize,
    },
    #[error(
        "the mesh quality is below the floor: triangle {triangle} has a {angle_deg:.1}° angle, the smallest allowed is {floor_deg:.1}° (the shape may have a very sharp tip or corner, or the target edge is too large for its narrow parts)"
    )]
    /// A triangle's smallest angle is below the floor.
    PoorQuality {
        /// The worst triangle.
        triangle: usize,
        /// Its smallest angle.
        angle_deg: f64,
        /// [`RemeshOptions::min_angle_floor_deg`].
        floor_deg: f64,
    },
    #[error(
        "the surface intersects itself: triangles {first} and {second} of the mesh cross (near {near_in_template})"
    )]
    /// Two triangles of the mesh cross.
    SelfIntersection {
        /// One of them.
        first: usize,
        /// The other.
        second: usize,
        /// Roughly where, in the template frame.
        near_in_template: glam::DVec3,
    },
    #[error(
        "the UV layout is not one span across at v = {v:.4}: a line of constant v crosses its outline {crossings} times, not twice (the remesher needs u across and v from base to tip, without holes or bays that turn back)"
    )]
    /// A line of constant `v` crosses the UV outline other than twice.
    UvNotMonotone {
        /// The line, in the mesh's UVs.
        v: f64,
        /// How often it crosses the outline.
        crossings: usize,
    },
    #[error(
        "the UV layout overlaps or folds over itself: its triangles cover {covered_area:.4} of UV area, its outline holds {outline_area:.4}"
    )]
    /// The UV triangles overlap (cover more area than the outline holds) or
    /// wind both ways.
    UvOverlap {
        /// The UV triangles' areas added up.
        covered_area: f64,
        /// The area inside the UV outline.
        outline_area: f64,
    },
    #[error("the mesh has no UV layout to remesh in: its UVs all lie on one line or point")]
    /// The UVs span no area.
    NoUvArea,
    /// The finished mesh failed validation.
    #[error("the remeshed organ is not a valid mesh: {0}")]
    InvalidMesh(#[from] MeshError),
}

/// Remeshes `surface` into a near-isotropic triangle mesh with mean edge
/// close to `options.target_edge`, UVs equal to the surface parameters and
/// the winding chosen by `options.inner_side`; reports its quality.
pub fn build_organ(surface: &dyn Surface, options: &RemeshOptions) -> Result<Bud, BudError> {
    let mut mesh = remesh::remesh(surface, options, remesh::SurfaceKind::Bud)?;
    orient(&mut mesh, options.inner_side);
    checked(mesh, options)
}

/// Validates a finished mesh and measures it; refuses it below the quality
/// floor or, if asked, when it crosses itself.
fn checked(mesh: Mesh, options: &RemeshOptions) -> Result<Bud, BudError> {
    anthesis_mesh::validate::validate(&mesh)?;
    let quality = quality(&mesh);
    if quality.min_angle_deg < options.min_angle_floor_deg {
        return Err(BudError::PoorQuality {
            triangle: quality.min_angle_triangle,
            angle_deg: quality.min_angle_deg,
            floor_deg: options.min_angle_floor_deg,
        });
    }
    if options.check_self_intersection
        && let Some([first, second]) = find_self_intersection(&mesh)
    {
        let near_in_template = mesh.triangle_positions(first).iter().sum::<glam::DVec3>() / 3.0;
        return Err(BudError::SelfIntersection {
            first,
            second,
            near_in_template,
        });
    }
    Ok(Bud { mesh, quality })
}

/// The area-weighted mean normal direction of the mesh as wound (not
/// normalised; zero for an empty mesh).
pub fn mean_normal(mesh: &Mesh) -> glam::DVec3 {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            (b - a).cross(c - a)
        })
        .sum()
}

/// Whether `mesh`'s inner side (the side its triangles wind
/// counter-clockwise around) faces the template frame's inner direction,
/// −Z, on average: `Some(true)` when the area-weighted mean normal points to
/// −Z, `Some(false)` to +Z, `None` when it has no Z component (a mesh
/// standing edge-on to Z: no side is inner by this test).
pub fn inner_side_faces_minus_z(mesh: &Mesh) -> Option<bool> {
    let z = mean_normal(mesh).z;
    if z < 0.0 {
        Some(true)
    } else if z > 0.0 {
        Some(false)
    } else {
        None
    }
}

/// `mesh` with its inner side swapped: every triangle wound the other way
/// (positions, UVs and vertex order stay, so painted maps stay valid).
pub fn with_inner_side_flipped(mesh: &Mesh) -> Mesh {
    let mut flipped = mesh.clone();
    for t in &mut flipped.triangles {
        t.swap(1, 2);
    }
    flipped
}

/// Sets the winding. The remesher winds counter-clockwise in UV, i.e. around
/// `dS/du × dS/dv`.
fn orient(mesh: &mut Mesh, inner_side: InnerSide) {
    let flip = match inner_side {
        InnerSide::AlongSurfaceNormal => false,
        InnerSide::AgainstSurfaceNormal => true,
        InnerSide::Auto => mean_normal(mesh).z > 0.0,
    };
    if flip {
        for t in &mut mesh.triangles {
            t.swap(1, 2);
        }
    }
}

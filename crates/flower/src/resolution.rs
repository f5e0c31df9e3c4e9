//! The resolution a flower is simulated at: every template remeshed at one
//! mean edge length (project units), or the meshes as built.
//!
//! The remeshed meshes are derived: a [`Project`] keeps the meshes the user
//! made and the setting ([`SimulationSettings::resolution`]); [`resolve`]
//! gives the project to simulate, each template's mesh remeshed by
//! [`anthesis_bud::remesh_mesh`] (the bud remesher, through the mesh's UV
//! layout), so the painted maps, which are rasters over the UVs, apply
//! unchanged. The same flower can be simulated coarse while painting and
//! fine for the final export.
//!
//! Why one edge length in project units and not a factor of each
//! template's own edge: organs touch and are pushed apart particle by
//! particle, so organs meshed alike behave alike; a length is what the
//! paper reports (Table 1: 1.3 for a lily petal) and what the window shows
//! beside the particle counts it gives; and a factor would mean something
//! different for every imported mesh.
//!
//! [`SimulationSettings::resolution`]: crate::SimulationSettings::resolution

use anthesis_bud::{BudError, RemeshOptions, remesh_mesh};
use anthesis_mesh::Mesh;
use thiserror::Error;

use crate::{MIN_BASE_PARTICLES, Project, Template};

/// How finely the templates are simulated.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Resolution {
    /// The meshes as they were built or imported.
    #[default]
    AsBuilt,
    /// Every template remeshed at this mean edge length (project units).
    MeanEdge(f64),
}

impl Resolution {
    /// The mean edge asked for, if any.
    pub fn mean_edge(self) -> Option<f64> {
        match self {
            Resolution::AsBuilt => None,
            Resolution::MeanEdge(edge) => Some(edge),
        }
    }
}

/// The most particles one remeshed template may have. Far more than a
/// film-resolution petal (4,000 to 10,000); the memory check of a run
/// (`anthesis_sim::memory`) usually refuses well before this.
pub const MAX_PARTICLES_PER_TEMPLATE: usize = 200_000;

/// Why a template could not be remeshed.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("template \"{template}\" cannot be remeshed at mean edge {mean_edge}: {problem}")]
pub struct ResolutionError {
    /// The template's name.
    pub template: String,
    /// The edge asked for.
    pub mean_edge: f64,
    /// What went wrong.
    pub problem: ResolutionProblem,
}

/// What went wrong remeshing a template.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ResolutionProblem {
    /// The remesher could not build a mesh at this edge length (too long
    /// or too short for the organ, or too many particles).
    #[error(transparent)]
    Remesh(#[from] BudError),
    /// No particle of the new mesh lies in the template's base region, so
    /// the organ would float free of the receptacle.
    #[error(
        "no particle of the new mesh lies in the base region (v ≤ {v_max}, {u_min} ≤ u ≤ {u_max}), so nothing would attach it; widen base_region or use a finer edge"
    )]
    NoBase {
        /// The base region's upper `v` limit.
        v_max: f64,
        /// The base region's lower `u` limit.
        u_min: f64,
        /// The base region's upper `u` limit.
        u_max: f64,
    },
    /// The new mesh has fewer base particles than attach an organ
    /// ([`MIN_BASE_PARTICLES`], what loading a project asks for).
    #[error(
        "the new mesh has {particles} base particles where the old had {old}; at least {MIN_BASE_PARTICLES} are needed to attach the organ; use a finer edge or widen base_region"
    )]
    TooFewBaseParticles {
        /// Base particles in the new mesh.
        particles: usize,
        /// Base particles in the mesh as built.
        old: usize,
    },
}

/// The options the remesh uses at `mean_edge`.
pub(crate) fn options(mean_edge: f64) -> RemeshOptions {
    RemeshOptions {
        max_vertices: MAX_PARTICLES_PER_TEMPLATE,
        ..RemeshOptions::new(mean_edge)
    }
}

/// `template`'s mesh remeshed at `mean_edge` (see the module
/// documentation); its base region must still hold at least
/// [`MIN_BASE_PARTICLES`], as loading a project asks of every template (a
/// remesh that left fewer was taken and the run then stopped without
/// naming the edge).
pub fn remesh_template(template: &Template, mean_edge: f64) -> Result<Mesh, ResolutionError> {
    let error = |problem: ResolutionProblem| ResolutionError {
        template: template.name.clone(),
        mean_edge,
        problem,
    };
    let bud = remesh_mesh(&template.mesh, &options(mean_edge))
        .map_err(|e| error(ResolutionProblem::Remesh(e)))?;
    let region = template.base_region;
    let base = region.particles(&bud.mesh).len();
    let old = region.particles(&template.mesh).len();
    if base == 0 && old > 0 {
        return Err(error(ResolutionProblem::NoBase {
            v_max: region.v_max,
            u_min: region.u_min,
            u_max: region.u_max,
        }));
    }
    if base < MIN_BASE_PARTICLES {
        return Err(error(ResolutionProblem::TooFewBaseParticles {
            particles: base,
            old,
        }));
    }
    Ok(bud.mesh)
}

/// The project to simulate: `project` with every template remeshed as its
/// resolution says (unchanged, but for the setting, when it is
/// [`Resolution::AsBuilt`]), through the installed remesh cache
/// ([`remesh_template_cached`](crate::remesh_cache::remesh_template_cached)). The result's resolution is `AsBuilt`: its
/// meshes are the resolution. The first template that cannot be remeshed is
/// an error naming it.
pub fn resolve(project: &Project) -> Result<Project, ResolutionError> {
    let mut resolved = project.clone();
    resolved.settings.resolution = Resolution::AsBuilt;
    if let Resolution::MeanEdge(edge) = project.settings.resolution {
        // A two-state template keeps its mesh: its open shape has that
        // mesh's vertices, which a remesh would not keep.
        for template in &mut resolved.flower.templates {
            if template.two_state.is_none() {
                template.mesh = crate::remesh_cache::remesh_template_cached(template, edge)?;
            }
        }
    }
    Ok(resolved)
}

/// About how many particles and triangles `mesh` gets remeshed at
/// `mean_edge`, from its area and outline, without remeshing it (for memory
/// estimates before a run). An equilateral mesh of edge `h` has a triangle
/// per `√3/4 · h²` of area; a vertex on the outline, every `h` along it,
/// counts half in that area.
pub fn predicted_size(mesh: &Mesh, mean_edge: f64) -> (usize, usize) {
    if !(mean_edge > 0.0 && mean_edge.is_finite()) {
        return (mesh.vertex_count(), mesh.triangle_count());
    }
    let per_triangle = 3f64.sqrt() / 4.0 * mean_edge * mean_edge;
    let triangles = (mesh.area() / per_triangle).min(1e15);
    let particles = triangles / 2.0 + (outline_length(mesh) / mean_edge).min(1e15) / 2.0 + 1.0;
    (particles as usize, triangles as usize)
}

/// The length of `mesh`'s outline (its boundary edges); 0 when its
/// topology cannot be built.
fn outline_length(mesh: &Mesh) -> f64 {
    anthesis_mesh::Topology::build(mesh)
        .map(|topology| {
            topology
                .boundary_edges()
                .map(|[a, b]| mesh.positions[a as usize].distance(mesh.positions[b as usize]))
                .sum()
        })
        .unwrap_or(0.0)
}

/// The particles an organ's interactive proxy aims at. A proxy is the same
/// template remeshed coarser, simulated before the converged run so that an
/// edit shows at once (the window's "proxy first"). Chosen by the latency
/// budget (README "Speed"): an edit on the built-in lily's early key reruns
/// from the bud, and its proxy (six organs of about this size, 100
/// keyframes, 0.44 s of solver time) must be on screen within 0.6 s while
/// the window draws on the same two cores; at 250 particles it took
/// 0.76–0.84 s, at this size 0.55–0.76 s (runs of 7 strokes, from pixels).
/// What that costs in shape is measured by the `refine` example's
/// `--proxy` (the lily petal's tip 12.5 % of its midrib away from the
/// converged one at keyframe 100, the Eustoma's 1.3–3.4 %).
pub const PROXY_PARTICLES: usize = 180;

/// The mean edge at which `mesh` is remeshed to about `particles`
/// particles (the inverse of [`predicted_size`]), or `None` for a mesh
/// without area.
pub fn edge_for_particles(mesh: &Mesh, particles: usize) -> Option<f64> {
    // predicted particles = A / (√3/2 · h²) + L / (2h) + 1: a quadratic in
    // x = 1/h, a·x² + b·x − c = 0, with its one positive root.
    let a = mesh.area() * 2.0 / 3f64.sqrt();
    let b = outline_length(mesh) / 2.0;
    let c = (particles as f64 - 1.0).max(1.0);
    if !(a > 0.0 && a.is_finite() && b.is_finite()) {
        return None;
    }
    let x = (-b + (b * b + 4.0 * a * c).sqrt()) / (2.0 * a);
    (x > 0.0 && x.is_finite()).then(|| 1.0 / x)
}

/// The mean edge of `mesh`'s proxy ([`PROXY_PARTICLES`]), or `None` when
/// the mesh has no more than twice that many particles: a proxy would then
/// save too little to be worth a second run.
pub fn proxy_edge(mesh: &Mesh) -> Option<f64> {
    if mesh.vertex_count() <= 2 * PROXY_PARTICLES {
        return None;
    }
    edge_for_particles(mesh, PROXY_PARTICLES)
}

/// `template`'s proxy mesh: its mesh remeshed at [`proxy_edge`]; where that
/// fails or leaves too few base particles, at a finer edge (up to three
/// tries, each a quarter finer). `None` when the mesh is coarse enough
/// already or no coarser mesh works. Remeshed through the installed remesh
/// cache ([`remesh_template_cached`](crate::remesh_cache::remesh_template_cached)):
/// the edge is a function of the mesh, so a launch or an edit that leaves
/// a template's mesh as it was reads its proxy back.
pub fn proxy_mesh(template: &Template) -> Option<Mesh> {
    let mut edge = proxy_edge(&template.mesh)?;
    for _ in 0..3 {
        if let Ok(mesh) = crate::remesh_cache::remesh_template_cached(template, edge)
            && mesh.vertex_count() < template.mesh.vertex_count()
        {
            return Some(mesh);
        }
        edge *= 0.75;
    }
    None
}

/// The proxy of `project` (a project at its resolution: its meshes are
/// simulated as they are): every template that has a [`proxy_mesh`] on
/// it, the rest unchanged; `None` when no template has one.
pub fn proxy(project: &Project) -> Option<Project> {
    let mut proxy = project.clone();
    let mut coarser = false;
    for template in &mut proxy.flower.templates {
        if let Some(mesh) = proxy_mesh(template) {
            template.mesh = mesh;
            coarser = true;
        }
    }
    coarser.then_some(proxy)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{BaseRegion, Flower, Organ, Placement, SimulationSettings};
    use anthesis_mesh::generate::test_petal;

    fn template(mesh: Mesh) -> Template {
        crate::test_template("petal", mesh)
    }

    fn project(mesh: Mesh, resolution: Resolution) -> Project {
        Project {
            name: "test".to_string(),
            flower: Flower {
                templates: vec![template(mesh)],
                organs: vec![Organ {
                    name: "petal-1".to_string(),
                    template: 0,
                    placement: Placement {
                        position: glam::DVec3::ZERO,
                        azimuth_deg: 0.0,
                        joint_angle_deg: 0.0,
                        orientation: glam::DQuat::IDENTITY,
                    },
                }],
                overlaps: Vec::new(),
                structure: None,
                parts: Vec::new(),
                unit: None,
            },
            settings: SimulationSettings {
                resolution,
                ..SimulationSettings::default()
            },
        }
    }

    #[test]
    fn as_built_changes_nothing_and_an_edge_remeshes_every_template() {
        let mesh = test_petal(10.0, 5.0, 9, 17);
        let same = resolve(&project(mesh.clone(), Resolution::AsBuilt)).expect("resolves");
        assert_eq!(same, project(mesh.clone(), Resolution::AsBuilt));
        let fine = resolve(&project(mesh.clone(), Resolution::MeanEdge(0.4))).expect("resolves");
        let remeshed = &fine.flower.templates[0].mesh;
        assert!(remeshed.vertex_count() > 2 * mesh.vertex_count());
        assert_eq!(fine.settings.resolution, Resolution::AsBuilt);
        // The prediction is close to what the remesh gives.
        let (predicted, _) = predicted_size(&mesh, 0.4);
        let actual = remeshed.vertex_count() as f64;
        assert!(
            (predicted as f64 - actual).abs() < 0.1 * actual,
            "{predicted} vs {actual}"
        );
        // The base region still picks the base row, across the whole base.
        let base = fine.flower.templates[0].base_region.particles(remeshed);
        let xs: Vec<f64> = base
            .iter()
            .map(|&i| remeshed.positions[i as usize].x)
            .collect();
        let width = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            - xs.iter().copied().fold(f64::INFINITY, f64::min);
        let old_base = BaseRegion::default().particles(&mesh);
        let old_xs: Vec<f64> = old_base
            .iter()
            .map(|&i| mesh.positions[i as usize].x)
            .collect();
        let old_width = old_xs.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            - old_xs.iter().copied().fold(f64::INFINITY, f64::min);
        // The old base row's corners are base particles again (a finer mesh
        // has more particles below v_max: margin particles too).
        assert!(width >= old_width - 1e-9, "{width} vs {old_width}");
        for corner in [glam::DVec2::new(0.0, 0.0), glam::DVec2::new(1.0, 0.0)] {
            let at = mesh
                .uvs
                .iter()
                .position(|uv| *uv == corner)
                .expect("corner");
            assert!(
                base.iter()
                    .any(|&i| remeshed.positions[i as usize].distance(mesh.positions[at]) < 1e-9),
                "base corner {corner} is not a base particle"
            );
        }
    }

    #[test]
    fn a_failure_names_the_template_and_why() {
        let mesh = test_petal(10.0, 5.0, 9, 17);
        let error = resolve(&project(mesh, Resolution::MeanEdge(1e-4))).expect_err("too fine");
        let text = error.to_string();
        assert!(
            text.starts_with("template \"petal\" cannot be remeshed at mean edge 0.0001"),
            "{text}"
        );
        assert!(text.contains("more than the limit of 200000"), "{text}");
    }

    #[test]
    fn a_remesh_leaving_too_few_base_particles_to_attach_is_refused_naming_the_edge() {
        // The base of this petal is 1.25 wide: at mean edge 2 the base row
        // of the new mesh holds two particles, fewer than loading a project
        // asks of a template.
        let template = template(test_petal(10.0, 5.0, 9, 17));
        let region = template.base_region;
        assert!(region.particles(&template.mesh).len() >= MIN_BASE_PARTICLES);
        let coarse = remesh_mesh(&template.mesh, &options(2.0)).expect("remeshes");
        let base = region.particles(&coarse.mesh).len();
        assert!(base > 0 && base < MIN_BASE_PARTICLES, "{base}");
        let error = remesh_template(&template, 2.0).expect_err("too few base particles");
        assert!(
            matches!(
                error.problem,
                ResolutionProblem::TooFewBaseParticles { particles, .. } if particles == base
            ),
            "{error:?}"
        );
        let text = error.to_string();
        assert!(
            text.starts_with("template \"petal\" cannot be remeshed at mean edge 2:"),
            "{text}"
        );
        assert!(text.contains("at least 3 are needed"), "{text}");
        // What the remesh gives is a project that loads: a resolution that
        // works passes the same check.
        let fine = remesh_template(&template, 0.8).expect("fine remesh");
        assert!(region.particles(&fine).len() >= MIN_BASE_PARTICLES);
    }

    #[test]
    fn a_base_region_the_new_mesh_misses_is_refused() {
        let mesh = test_petal(10.0, 5.0, 9, 17);
        let mut template = template(mesh);
        // The old mesh has a row at v = 1/16; a coarse mesh has none there.
        template.base_region = BaseRegion {
            v_max: 0.07,
            u_min: 0.4,
            u_max: 0.6,
        };
        assert!(!template.base_region.particles(&template.mesh).is_empty());
        match remesh_template(&template, 2.5) {
            Err(ResolutionError {
                problem:
                    ResolutionProblem::NoBase { .. } | ResolutionProblem::TooFewBaseParticles { .. },
                ..
            }) => {}
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn a_proxy_edge_gives_about_the_particles_it_aims_at() {
        let fine = test_petal(40.0, 15.0, 30, 60);
        let edge = proxy_edge(&fine).expect("a fine mesh has a proxy");
        let remeshed = remesh_template(&template(fine.clone()), edge).expect("remeshed");
        let particles = remeshed.vertex_count() as f64;
        let aim = PROXY_PARTICLES as f64;
        assert!(
            (particles - aim).abs() < 0.25 * aim,
            "{particles} particles at edge {edge}"
        );
        // The prediction inverts: the edge predicts the particles asked for.
        let (predicted, _) = predicted_size(&fine, edge);
        assert!((predicted as f64 - aim).abs() <= 1.0, "{predicted}");
        // A mesh already coarse has none.
        let coarse = test_petal(40.0, 15.0, 8, 12);
        assert!(coarse.vertex_count() <= 2 * PROXY_PARTICLES);
        assert_eq!(proxy_edge(&coarse), None);
    }
}

//! The project as the window simulates and shows it: each template's mesh
//! at the project's resolution (`anthesis_flower::resolution`), remeshed
//! only when its mesh or the resolution changes. The document keeps the
//! meshes as built; painting (in UV), saving and undo work on those.
//!
//! Next to it, the *proxy*: the same project with every template remeshed
//! coarser (`anthesis_flower::resolution::proxy_mesh`, about
//! `PROXY_PARTICLES` particles an organ; the same UV layout, so the same
//! maps), simulated first after every edit so the edit shows at once. A
//! template already that coarse keeps its mesh in the proxy; when none is
//! coarser there is no proxy. Proxy meshes are remeshed only when the
//! converged mesh they come from changes.

use std::sync::Arc;

use anthesis_flower::remesh_cache::remesh_template_cached;
use anthesis_flower::resolution::proxy_mesh;
use anthesis_flower::{Project, Resolution};
use anthesis_mesh::Mesh;
use anthesis_sim::Selection;
use anthesis_sim::memory::{self, KeyframeCost};

/// One template's mesh remeshed at an edge, or why it could not be.
struct Remeshed {
    /// The mesh it was made from.
    built: Mesh,
    mean_edge: f64,
    mesh: Result<Mesh, String>,
}

/// The project to simulate and show, kept up to date with the document.
#[derive(Default)]
pub struct Resolved {
    /// The document revision it was made from.
    revision: Option<u64>,
    /// Per template, the last remesh (kept while its mesh and the edge stay
    /// the same, so a stroke or a parameter edit remeshes nothing).
    remeshed: Vec<Option<Remeshed>>,
    project: Option<Arc<Project>>,
    /// Per template, its proxy mesh (`None`: the converged mesh serves).
    proxies: Vec<Option<ProxyMesh>>,
    proxy: Option<Arc<Project>>,
}

/// One template's proxy: the converged mesh it was made from and the
/// coarser mesh (`None` when that mesh is coarse enough or no coarser one
/// could be made).
struct ProxyMesh {
    converged: Mesh,
    mesh: Option<Mesh>,
}

impl Resolved {
    /// Remeshes what `project`'s resolution needs into the cache, without
    /// changing the project shown. Refuses (with the message) a resolution
    /// whose run of the whole flower would not fit in memory, judged on the
    /// predicted sizes before anything is remeshed, and one where a template
    /// cannot be remeshed (the message names it and says why).
    pub fn prepare(&mut self, project: &Project) -> Result<(), String> {
        let Some(edge) = project.settings.resolution.mean_edge() else {
            return Ok(());
        };
        memory::check_run(project, &Selection::All, KeyframeCost::Kept)
            .map_err(|e| e.to_string())?;
        self.remeshed
            .resize_with(project.flower.templates.len(), || None);
        let mut first_problem = None;
        for (template, slot) in project.flower.templates.iter().zip(&mut self.remeshed) {
            if !slot
                .as_ref()
                .is_some_and(|r| r.mean_edge == edge && r.built == template.mesh)
            {
                *slot = Some(Remeshed {
                    built: template.mesh.clone(),
                    mean_edge: edge,
                    mesh: remesh_template_cached(template, edge).map_err(|e| e.to_string()),
                });
            }
            if let Some(Remeshed { mesh: Err(e), .. }) = slot {
                first_problem.get_or_insert_with(|| e.clone());
            }
        }
        first_problem.map_or(Ok(()), Err)
    }

    /// Brings the resolved project up to date with `project` at document
    /// revision `revision`. A template that cannot be remeshed keeps its
    /// mesh as built, and the message says so (once, when it is new).
    pub fn update(&mut self, project: &Project, revision: u64) -> Option<String> {
        if self.revision == Some(revision) && self.project.is_some() {
            return None;
        }
        self.revision = Some(revision);
        let problem = self.prepare(project).err();
        let mut resolved = project.clone();
        resolved.settings.resolution = Resolution::AsBuilt;
        if let Some(edge) = project.settings.resolution.mean_edge() {
            for (template, slot) in resolved.flower.templates.iter_mut().zip(&self.remeshed) {
                if let Some(Remeshed {
                    built,
                    mean_edge,
                    mesh: Ok(mesh),
                }) = slot
                    && *mean_edge == edge
                    && *built == template.mesh
                {
                    template.mesh = mesh.clone();
                }
            }
        }
        self.proxy = self.make_proxy(&resolved);
        let changed_meshes = self.project.as_ref().is_none_or(|old| {
            old.flower.templates.len() != resolved.flower.templates.len()
                || old
                    .flower
                    .templates
                    .iter()
                    .zip(&resolved.flower.templates)
                    .any(|(a, b)| a.mesh != b.mesh)
        });
        self.project = Some(Arc::new(resolved));
        problem
            .filter(|_| changed_meshes)
            .map(|e| format!("{e}; simulating the meshes as built where it failed"))
    }

    /// The project at its resolution (as last updated).
    pub fn project(&self) -> Option<&Arc<Project>> {
        self.project.as_ref()
    }

    /// The proxy of the project at its resolution (as last updated), if
    /// any template has a coarser one.
    pub fn proxy(&self) -> Option<&Arc<Project>> {
        self.proxy.as_ref()
    }

    /// The proxy of `resolved` (a project at its resolution), its meshes
    /// made again only where a converged mesh changed.
    fn make_proxy(&mut self, resolved: &Project) -> Option<Arc<Project>> {
        self.proxies
            .resize_with(resolved.flower.templates.len(), || None);
        let mut proxy = resolved.clone();
        let mut coarser = false;
        for (template, slot) in proxy.flower.templates.iter_mut().zip(&mut self.proxies) {
            if !slot.as_ref().is_some_and(|p| p.converged == template.mesh) {
                *slot = Some(ProxyMesh {
                    converged: template.mesh.clone(),
                    mesh: proxy_mesh(template),
                });
            }
            if let Some(ProxyMesh {
                mesh: Some(mesh), ..
            }) = slot
            {
                template.mesh = mesh.clone();
                coarser = true;
            }
        }
        coarser.then(|| Arc::new(proxy))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn meshes_follow_the_resolution_and_are_kept_between_edits() {
        let mut project = anthesis_sim::fixtures::whorl(2, 8, 14, 3);
        let built = project.flower.templates[0].mesh.clone();
        let mut resolved = Resolved::default();
        assert_eq!(resolved.update(&project, 1), None);
        assert_eq!(
            resolved.project().expect("made").flower.templates[0].mesh,
            built
        );
        let edge = anthesis_bud::quality(&built).mean_edge / 2.0;
        project.settings.resolution = Resolution::MeanEdge(edge);
        assert_eq!(resolved.update(&project, 2), None);
        let fine = resolved.project().expect("made").flower.templates[0]
            .mesh
            .clone();
        assert!(fine.vertex_count() > 3 * built.vertex_count());
        // The shown project is as built at its own meshes.
        assert_eq!(
            resolved.project().expect("made").settings.resolution,
            Resolution::AsBuilt
        );
        // A parameter edit keeps the remeshed mesh (same value, no remesh).
        project.flower.templates[0].dg += 0.001;
        assert_eq!(resolved.update(&project, 3), None);
        assert_eq!(
            resolved.project().expect("made").flower.templates[0].mesh,
            fine
        );
        // Back to as built.
        project.settings.resolution = Resolution::AsBuilt;
        resolved.update(&project, 4);
        assert_eq!(
            resolved.project().expect("made").flower.templates[0].mesh,
            built
        );
    }

    #[test]
    fn a_template_that_cannot_be_remeshed_keeps_its_mesh_and_says_why() {
        let mut project = anthesis_sim::fixtures::whorl(1, 8, 14, 3);
        let built = project.flower.templates[0].mesh.clone();
        project.settings.resolution = Resolution::MeanEdge(1000.0);
        let mut resolved = Resolved::default();
        let message = resolved.prepare(&project).expect_err("too coarse");
        assert!(message.starts_with("template \"petal\" cannot be remeshed at mean edge 1000"));
        let message = resolved.update(&project, 1).expect("a message");
        assert!(message.ends_with("simulating the meshes as built where it failed"));
        assert_eq!(
            resolved.project().expect("made").flower.templates[0].mesh,
            built
        );
        // An edge that would make millions of particles is refused by the
        // memory estimate before anything is remeshed.
        project.settings.resolution = Resolution::MeanEdge(1e-5);
        let message = resolved.prepare(&project).expect_err("too fine");
        assert!(message.starts_with("this run needs about"), "{message}");
    }

    #[test]
    fn the_proxy_is_coarser_keeps_the_maps_and_is_made_again_only_when_a_mesh_changes() {
        let mut project = anthesis_sim::fixtures::whorl(2, 30, 50, 3);
        let mut resolved = Resolved::default();
        resolved.update(&project, 1);
        let converged = Arc::clone(resolved.project().expect("made"));
        let proxy = Arc::clone(resolved.proxy().expect("a fine flower has a proxy"));
        for (fine, coarse) in converged
            .flower
            .templates
            .iter()
            .zip(&proxy.flower.templates)
        {
            let (fine_count, coarse_count) = (fine.mesh.vertex_count(), coarse.mesh.vertex_count());
            assert!(
                coarse_count * 3 < fine_count,
                "{}: {coarse_count} of {fine_count}",
                fine.name
            );
            assert_eq!(fine.maps, coarse.maps, "the same maps");
            assert_eq!(fine.base_region, coarse.base_region);
        }
        assert_eq!(proxy.flower.organs, converged.flower.organs);
        assert_eq!(proxy.settings, converged.settings);

        // A stroke: the same proxy meshes, the new maps.
        anthesis_sim::fixtures::stroke_near_tip(&mut project, 0, 1);
        resolved.update(&project, 2);
        let stroked = Arc::clone(resolved.proxy().expect("a proxy"));
        assert_eq!(
            stroked.flower.templates[0].mesh,
            proxy.flower.templates[0].mesh
        );
        assert_eq!(
            stroked.flower.templates[0].maps,
            project.flower.templates[0].maps
        );

        // A coarse flower has no proxy.
        let coarse = anthesis_sim::fixtures::whorl(2, 6, 10, 3);
        resolved.update(&coarse, 3);
        assert!(resolved.proxy().is_none());
    }
}

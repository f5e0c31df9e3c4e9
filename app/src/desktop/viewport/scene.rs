//! The scene the viewport shows: the organs at the playhead (simulated or
//! in their bud placement; the current result or, while asked, the one
//! before the last edit), their bounds, and the meshes handed to the
//! renderer (template colour, selection highlight, a map overlay or a
//! per-vertex [`ScalarField`]), kept in a [`SceneCache`] while what they
//! show does not change.

use std::sync::Arc;

use anthesis_flower::Project;
use anthesis_flower::parts::{PartPiece, part_pieces};
use anthesis_maps::MapKind;
use anthesis_render::OrganMesh;
use glam::DVec3;

use anthesis_sim::worker::RunId;

use super::field::{FieldInput, FieldShown, ScalarField, ViewField};
pub use super::organ::SceneOrgan;
use crate::desktop::session::{ShownAt, SimSession};

/// The organs at keyframe time `time`: simulated organs from the run (on
/// the meshes of the frame shown: a proxy's are coarser), the others (when
/// `show_others`) in their bud placement. An organ whose keyframes no
/// longer fit its template (the mesh was replaced) is shown as a bud.
pub fn build_scene(
    project: &Project,
    session: &SimSession,
    time: f64,
    show_others: bool,
) -> Vec<SceneOrgan> {
    build_scene_of(
        project,
        session.shown_at(time).as_ref(),
        session.organs(),
        show_others,
    )
}

/// The organs of `shown` (the frames at one time, one position list per
/// organ of `organs`, in that order), as [`build_scene`] places them.
pub fn build_scene_of(
    project: &Project,
    shown: Option<&ShownAt>,
    organs: &[usize],
    show_others: bool,
) -> Vec<SceneOrgan> {
    let flower = &project.flower;
    let mut scene = Vec::new();
    for (i, organ) in flower.organs.iter().enumerate() {
        let slot = organs.iter().position(|&o| o == i);
        let simulated = slot.and_then(|s| {
            let shown = shown?;
            let mesh = &shown
                .meshes
                .flower
                .organs
                .get(i)
                .map(|_| shown.meshes.flower.template_of(i))?
                .mesh;
            let positions = shown.positions.get(s)?;
            (positions.len() == mesh.vertex_count()).then_some((positions, mesh))
        });
        let template = flower.template_of(i);
        let (positions_in_world, mesh, simulated) = match simulated {
            Some((positions, mesh)) => (positions.clone(), mesh, true),
            None if slot.is_some() || show_others => (
                template
                    .mesh
                    .positions
                    .iter()
                    .map(|p| organ.placement.world_from_template(*p, 0.0))
                    .collect(),
                &template.mesh,
                false,
            ),
            None => continue,
        };
        scene.push(SceneOrgan {
            organ: i,
            positions_in_world,
            triangles: mesh.triangles.clone(),
            uvs: mesh.uvs.clone(),
            simulated,
        });
    }
    scene
}

/// Axis-aligned bounds of the scene.
pub fn scene_bounds(scene: &[SceneOrgan]) -> Option<(DVec3, DVec3)> {
    let mut points = scene.iter().flat_map(|o| o.positions_in_world.iter());
    let first = *points.next()?;
    Some(points.fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p))))
}

/// The selection highlight, linear RGB (a warm yellow, sRGB 255, 219, 115).
const HIGHLIGHT_LINEAR: [f32; 3] = [1.0, 0.71, 0.17];

/// Meshes for the renderer: each organ in its template colour (linear, as
/// the renderer takes it) or its colour map (`crate::look`, baked once per
/// template and kept in `looks`, one slot per template, while the project
/// is the same: the renderer keeps a texture uploaded while the same image
/// comes back); the selected one tinted towards a warm highlight; organs
/// not simulated (bud placeholders in preview) washed out towards grey;
/// the overlay map as a ramp, or `field` (which wins) where it has values.
pub fn scene_meshes(
    project: &Project,
    scene: &[SceneOrgan],
    selected: Option<usize>,
    overlay: Option<(MapKind, usize)>,
    field: Option<&ScalarField>,
    looks: &mut Vec<Option<crate::look::Look>>,
) -> Vec<OrganMesh> {
    looks.resize(project.flower.templates.len(), None);
    scene
        .iter()
        .enumerate()
        .map(|(in_scene, o)| {
            let template = project.flower.template_of(o.organ);
            let index = project.flower.organs[o.organ].template;
            let (mut colour_linear, texture) = looks[index]
                .get_or_insert_with(|| crate::look::template_look(template))
                .clone();
            if selected == Some(o.organ) {
                for (c, h) in colour_linear.iter_mut().zip(HIGHLIGHT_LINEAR) {
                    *c += 0.45 * (h - *c);
                }
            } else if !o.simulated {
                for c in colour_linear.iter_mut().take(3) {
                    *c = 0.26 + 0.43 * *c;
                }
            }
            let mesh =
                OrganMesh::from_positions(&o.positions_in_world, &o.triangles, colour_linear);
            let mesh = crate::look::with_texture(mesh, &o.uvs, texture.as_ref());
            if let Some(field) = field {
                return match field.ramp_values(in_scene) {
                    Some(values) => mesh.with_overlay(values),
                    None => mesh,
                };
            }
            match overlay {
                Some((kind, key)) => {
                    let map = template.maps.key_clamped(key).maps.scalar(kind);
                    let values = o.uvs.iter().map(|uv| map.sample(*uv) as f32).collect();
                    mesh.with_overlay(values)
                }
                None => mesh,
            }
        })
        .collect()
}

/// What the scene depends on. While none of it changes (the camera turns,
/// the pointer moves, a panel is used) the scene, its meshes (with their
/// normals) and their GPU upload are kept.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneKey {
    /// [`crate::desktop::document::Document::revision`]: which project,
    /// as changed so far.
    pub document_revision: u64,
    /// The run shown, and the frames the view blends
    /// ([`SimSession::frames_at`]: a proxy replaced by the converged
    /// keyframe is another frame).
    pub run: RunId,
    pub frames: Option<(u64, u64)>,
    /// The newest keyframe shown (an earlier run's where this one has not
    /// arrived, see [`SimSession::shown_end`]).
    pub shown_end: Option<u32>,
    pub time_in_keyframes: f64,
    pub selected_organ: usize,
    /// The overlaid map and its time key.
    pub overlay: Option<(MapKind, usize)>,
    /// The per-vertex field drawn instead of the map overlay.
    pub field: Option<ViewField>,
    /// The result before the last edit is shown instead of the current
    /// one, and which ([`SimSession::before_revision`]).
    pub before: bool,
    pub before_revision: u64,
    pub show_others: bool,
    /// The registered fit target shown over the organ
    /// (`crate::desktop::fit::FitDialog::target_overlay`; 0: none).
    pub fit_target: u64,
}

/// What a scene needs from its project that does not change with the
/// time shown: each template's look (its baked colour image) and the
/// parts' pieces, with the meshes of those that do not move. Kept while
/// the project shown is the same `Arc`, so a step in time does not bake
/// the colour maps again (nor upload them again: the renderer keeps a
/// texture while the same image comes back) or rebuild the parts.
struct ProjectStatics {
    project: Arc<Project>,
    looks: Vec<Option<crate::look::Look>>,
    pieces: Vec<PartPiece>,
    /// Per piece, its mesh when it does not move.
    still: Vec<Option<OrganMesh>>,
}

impl ProjectStatics {
    fn of(project: &Arc<Project>) -> ProjectStatics {
        let pieces = part_pieces(&project.flower);
        let still = pieces
            .iter()
            .map(|piece| (!piece.moves()).then(|| crate::parts::piece_mesh(piece, 0.0)))
            .collect();
        ProjectStatics {
            project: Arc::clone(project),
            looks: Vec::new(),
            pieces,
            still,
        }
    }

    /// The parts at `time_in_keyframes`, as [`crate::parts::part_meshes`]
    /// draws them.
    fn part_meshes(&self, time_in_keyframes: f64) -> impl Iterator<Item = OrganMesh> + '_ {
        self.pieces
            .iter()
            .zip(&self.still)
            .map(move |(piece, still)| match still {
                Some(mesh) => mesh.clone(),
                None => crate::parts::piece_mesh(piece, time_in_keyframes),
            })
    }
}

/// The scene shown last and what it was built from.
#[derive(Default)]
pub struct SceneCache {
    key: Option<SceneKey>,
    scene: Arc<Vec<SceneOrgan>>,
    meshes: Arc<Vec<OrganMesh>>,
    /// The field drawn on the scene, when one is asked for.
    field: Option<Arc<FieldShown>>,
    /// Counts the builds; the GPU side uploads the meshes when it changes.
    revision: u64,
    statics: Option<ProjectStatics>,
}

/// What one build makes.
struct Built {
    scene: Vec<SceneOrgan>,
    meshes: Vec<OrganMesh>,
    field: Option<FieldShown>,
}

impl SceneCache {
    /// The scene of `project` (the project as simulated and shown) and
    /// `session` for `key` (the current result, or the one before the last
    /// edit when `key.before` and the session has it), the meshes handed
    /// to the renderer (the organs, then the parts, then the fit's
    /// registered target if shown) and their revision; built again only
    /// when `key` differs from the previous call's. The field `key.field`
    /// asks for is computed with it ([`SceneCache::field`]).
    pub fn get(
        &mut self,
        key: SceneKey,
        project: &Arc<Project>,
        session: &SimSession,
        fit_target: Option<&OrganMesh>,
    ) -> (Arc<Vec<SceneOrgan>>, Arc<Vec<OrganMesh>>, u64) {
        self.get_or_build(key, |statics| {
            let statics = match statics.take() {
                Some(kept) if Arc::ptr_eq(&kept.project, project) => statics.insert(kept),
                _ => statics.insert(ProjectStatics::of(project)),
            };
            let before = if key.before {
                session.before_at(key.time_in_keyframes)
            } else {
                None
            };
            let shown = match before {
                Some(before) => Some(before),
                None => session.shown_at(key.time_in_keyframes),
            };
            let scene = build_scene_of(project, shown.as_ref(), session.organs(), key.show_others);
            let field = key.field.map(|chosen| {
                let meshes = shown.as_ref().map_or(&**project, |s| &*s.meshes);
                compute_field(
                    chosen,
                    &FieldInput {
                        project,
                        meshes,
                        session,
                        time_in_keyframes: key.time_in_keyframes,
                        scene: &scene,
                        before: key.before,
                    },
                )
            });
            let drawn = match &field {
                Some(FieldShown::Field(field)) => Some(field),
                _ => None,
            };
            let mut meshes = scene_meshes(
                project,
                &scene,
                Some(key.selected_organ),
                key.overlay,
                drawn,
                &mut statics.looks,
            );
            meshes.extend(statics.part_meshes(key.time_in_keyframes));
            // The fit dialog's registered target, last (`key.fit_target`
            // changes with it).
            meshes.extend(fit_target.cloned());
            Built {
                scene,
                meshes,
                field,
            }
        })
    }

    /// The scene for `key`, its meshes and their revision; `build` (given
    /// what is kept of the project) runs only when `key` differs from the
    /// previous call's.
    fn get_or_build(
        &mut self,
        key: SceneKey,
        build: impl FnOnce(&mut Option<ProjectStatics>) -> Built,
    ) -> (Arc<Vec<SceneOrgan>>, Arc<Vec<OrganMesh>>, u64) {
        if self.key != Some(key) {
            let built = build(&mut self.statics);
            self.scene = Arc::new(built.scene);
            self.meshes = Arc::new(built.meshes);
            self.field = built.field.map(Arc::new);
            self.key = Some(key);
            self.revision += 1;
        }
        (
            Arc::clone(&self.scene),
            Arc::clone(&self.meshes),
            self.revision,
        )
    }

    /// The field drawn on the scene last built (see [`SceneKey::field`]),
    /// or why there is none.
    pub fn field(&self) -> Option<Arc<FieldShown>> {
        self.field.clone()
    }

    /// The scene last built and what it was built for.
    pub fn last(&self) -> (Option<SceneKey>, Arc<Vec<SceneOrgan>>) {
        (self.key, Arc::clone(&self.scene))
    }

    /// How many times the scene has been built.
    pub fn builds(&self) -> u64 {
        self.revision
    }
}

/// The field `field` on the scene of `input`; `None` when there is
/// nothing to draw (the legend then says why, see [`FieldShown`]).
fn compute_field(field: ViewField, input: &FieldInput<'_>) -> FieldShown {
    match field {
        ViewField::Difference => crate::desktop::difference::difference_field(input),
        ViewField::Measure(field) => crate::desktop::measure_panel::measure_field(field, input),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key() -> SceneKey {
        SceneKey {
            document_revision: 7,
            run: 2,
            frames: Some((10, 11)),
            shown_end: Some(9),
            time_in_keyframes: 4.5,
            selected_organ: 1,
            overlay: None,
            field: None,
            before: false,
            before_revision: 0,
            show_others: true,
            fit_target: 0,
        }
    }

    #[test]
    fn the_scene_is_built_again_only_when_what_it_shows_changes() {
        let mut cache = SceneCache::default();
        let mut builds = 0;
        let mut get = |cache: &mut SceneCache, key: SceneKey| {
            cache
                .get_or_build(key, |_| {
                    builds += 1;
                    Built {
                        scene: Vec::new(),
                        meshes: Vec::new(),
                        field: None,
                    }
                })
                .2
        };
        assert_eq!(get(&mut cache, key()), 1);
        assert_eq!(get(&mut cache, key()), 1, "same key: kept");
        let changes = [
            SceneKey {
                document_revision: 8,
                ..key()
            },
            SceneKey { run: 3, ..key() },
            SceneKey {
                frames: Some((10, 12)),
                ..key()
            },
            SceneKey {
                shown_end: Some(20),
                ..key()
            },
            SceneKey {
                time_in_keyframes: 4.6,
                ..key()
            },
            SceneKey {
                selected_organ: 0,
                ..key()
            },
            SceneKey {
                overlay: Some((MapKind::Bend, 0)),
                ..key()
            },
            SceneKey {
                show_others: false,
                ..key()
            },
            SceneKey {
                field: Some(ViewField::Difference),
                ..key()
            },
            SceneKey {
                before: true,
                ..key()
            },
            SceneKey {
                before_revision: 1,
                ..key()
            },
        ];
        for (i, changed) in changes.into_iter().enumerate() {
            assert_eq!(get(&mut cache, changed), 2 + 2 * i as u64, "{changed:?}");
            assert_eq!(get(&mut cache, key()), 3 + 2 * i as u64, "back");
        }
        assert_eq!(builds, 23);
        assert_eq!(cache.builds(), 23);
    }
}

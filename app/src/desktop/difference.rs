//! See what an edit did (issue 40 item 2): hold [`BEFORE_KEY`] (or the
//! viewport's "Before" button) to see the result before the last edit at
//! the viewed keyframe, release to see the current one; and the
//! difference overlay, how far each point moved between the two, as a
//! [`ScalarField`] in the project's real unit.
//!
//! "Before" is [`SimSession::before`]: the converged keyframes of the last
//! finished run that an edit, undo or redo replaced (after an undo it is
//! the result with the undone edit, so the view shows what the undo
//! changed); a stroke's several runs do not replace it until one finishes.

use std::sync::Arc;

use anthesis_bud::MeshSurface;
use anthesis_mesh::Mesh;
use eframe::egui::{self, Color32, Vec2};
use glam::{DVec2, DVec3};

use super::AnthesisApp;
use super::command::Command;
use super::session::FrameKind;
#[cfg(test)]
use super::session::SimSession;
use super::viewport::field::{FieldInput, FieldShown, Quantity, ScalarField, ViewField};
use super::viewport::{self, SceneKey, SceneOrgan, build_scene_of};

/// The key held to see the result before the last edit (B for "before";
/// no other shortcut uses it). Listed in `menus::SHORTCUTS`.
pub const BEFORE_KEY: egui::Key = egui::Key::B;

/// The badge's colour while the result before the last edit is shown (a
/// violet no other badge uses).
pub const BEFORE_COLOUR: Color32 = Color32::from_rgb(120, 70, 170);

/// What the badge says while the result before the last edit is shown.
pub const BEFORE_BADGE: &str = "BEFORE THE LAST EDIT";

/// The difference overlay: for each point of each simulated organ shown,
/// the distance to the same point (the same UV) of the other result at the
/// same time (the current result when the scene shows the one before the
/// last edit, that one otherwise), in project units, drawn from 0 to the
/// largest. A point of a proxy frame (coarser meshes) is compared with the
/// point at its UV on the other result's surface.
pub fn difference_field(input: &FieldInput<'_>) -> FieldShown {
    let session = input.session;
    let time = input.time_in_keyframes;
    if session.before().is_none() {
        return FieldShown::Nothing(
            "Nothing to compare with yet: the result before an edit is kept once a run \
             has finished and an edit starts another."
                .to_string(),
        );
    }
    let now = session.shown_at(time);
    let other = if input.before {
        now.clone()
    } else {
        session.before_at(time)
    };
    let other_scene = build_scene_of(input.project, other.as_ref(), session.organs(), false);
    let values: Vec<Option<Vec<f64>>> = input
        .scene
        .iter()
        .map(|organ| {
            let there = other_scene
                .iter()
                .find(|o| o.organ == organ.organ && o.simulated)?;
            organ.simulated.then(|| distances(organ, there))
        })
        .collect();
    let mut notes = vec![format!(
        "At keyframe {}: each point against the same point {}.",
        format_time(time),
        if input.before {
            "of the current result"
        } else {
            "before the last edit"
        }
    )];
    if let Some(now) = &now {
        if now.kind == FrameKind::Proxy {
            notes.push(
                "The current result shown is the quick preview (proxy, coarser): the \
                 difference is against the proxy until the full run replaces it."
                    .to_string(),
            );
        } else if now.stale {
            notes.push(
                "The running simulation has not reached this keyframe: the current result \
                 shown is an earlier run's."
                    .to_string(),
            );
        }
    }
    let mut field = ScalarField {
        name: ViewField::Difference.label().to_string(),
        quantity: Quantity::Length(input.project.flower.unit),
        range: [0.0, 0.0],
        values,
        notes,
    };
    field.range = [0.0, field.max().unwrap_or(0.0)];
    FieldShown::Field(field)
}

/// The keyframe time as the timeline's read-out says it ("54.0").
fn format_time(time: f64) -> String {
    format!("{time:.1}")
}

/// How far each point of `here` is from the same point of `there` (the
/// same organ in another result): point by point on the same mesh, else
/// through the UVs (`there` seen as a surface over its UV layout, as the
/// remesher sees a template; a point its layout cannot place is measured
/// to the nearest vertex in UV).
fn distances(here: &SceneOrgan, there: &SceneOrgan) -> Vec<f64> {
    if here.uvs == there.uvs && here.triangles == there.triangles {
        return here
            .positions_in_world
            .iter()
            .zip(&there.positions_in_world)
            .map(|(a, b)| a.distance(*b))
            .collect();
    }
    let mesh = Mesh {
        positions: there.positions_in_world.clone(),
        uvs: there.uvs.clone(),
        triangles: there.triangles.clone(),
    };
    let surface = MeshSurface::new(&mesh).ok();
    here.positions_in_world
        .iter()
        .zip(&here.uvs)
        .map(|(p, uv)| {
            let on_surface = surface.as_ref().map(|s| s.point_at_uv(*uv));
            let other = match on_surface {
                Some(q) if q.is_finite() => q,
                _ => nearest_in_uv(there, *uv),
            };
            p.distance(other)
        })
        .collect()
}

/// The position of `organ`'s vertex nearest `uv` in UV.
fn nearest_in_uv(organ: &SceneOrgan, uv: DVec2) -> DVec3 {
    organ
        .uvs
        .iter()
        .zip(&organ.positions_in_world)
        .min_by(|a, b| {
            a.0.distance_squared(uv)
                .total_cmp(&b.0.distance_squared(uv))
        })
        .map_or(DVec3::NAN, |(_, p)| *p)
}

/// Id of the "Before" button's held state (read the next frame, before the
/// scene is built).
fn before_button_id() -> egui::Id {
    egui::Id::unique("hold to see before")
}

impl AnthesisApp {
    /// Whether the viewport shows the result before the last edit this
    /// frame: [`BEFORE_KEY`] held (not while a text field has the
    /// keyboard) or the viewport's "Before" button held down.
    pub(super) fn wants_before(&self, ctx: &egui::Context) -> bool {
        let key = !ctx.text_edit_focused() && ctx.input(|i| i.key_down(BEFORE_KEY));
        let button = ctx.data(|d| d.get_temp::<bool>(before_button_id()).unwrap_or(false));
        key || button
    }

    /// The scene key's part that says which result is shown:
    /// `(before, before_revision)`.
    pub(super) fn before_in_key(&self, ctx: &egui::Context) -> (bool, u64) {
        (self.wants_before(ctx), self.session.before_revision())
    }

    /// Over the viewport `rect`: the before badge (at badge `row`; returns
    /// the rows used), the toolbar (hold "Before", the "Difference" toggle;
    /// once an edit has a result before it to compare with) and the chosen
    /// field's legend.
    pub(super) fn difference_ui(
        &mut self,
        ui: &mut egui::Ui,
        rect: egui::Rect,
        key: &SceneKey,
        row: usize,
    ) -> usize {
        let mut rows = 0;
        if key.before {
            if self.session.before().is_some() {
                viewport::badge(ui, rect, row, BEFORE_BADGE, BEFORE_COLOUR);
            } else {
                viewport::badge(
                    ui,
                    rect,
                    row,
                    "NO EARLIER RESULT TO SHOW: the current one is shown",
                    BEFORE_COLOUR,
                );
            }
            rows += 1;
        }
        // Once there is something to compare (or a field is chosen).
        if self.session.before().is_some() || self.view.field.is_some() {
            self.difference_toolbar(ui, rect);
        } else {
            ui.ctx()
                .data_mut(|d| d.insert_temp(before_button_id(), false));
        }
        if let (Some(chosen), Some(shown)) = (key.field, self.scene.field()) {
            viewport::field::legend(ui, rect, chosen.label(), &shown);
        }
        rows
    }

    /// The top-right corner of the viewport: a "Before" button to hold and
    /// the difference overlay's toggle.
    fn difference_toolbar(&mut self, ui: &mut egui::Ui, rect: egui::Rect) {
        let ctx = ui.ctx().clone();
        let mut view = self.view;
        let mut held = false;
        egui::Area::new(egui::Id::unique("difference toolbar"))
            .order(egui::Order::Foreground)
            .fixed_pos(rect.right_top() + Vec2::new(-10.0, 10.0))
            .pivot(egui::Align2::RIGHT_TOP)
            .show(&ctx, |ui| {
                egui::Frame::popup(ui.style()).show(ui, |ui| {
                    ui.horizontal(|ui| {
                        let before = ui.button("Before  (hold B)").on_hover_text(
                            "Hold this button or the B key to see the result before the \
                                 last edit at this keyframe; release to see the current one",
                        );
                        held = before.is_pointer_button_down_on();
                        let mut on = view.field == Some(ViewField::Difference);
                        if ui
                            .toggle_value(&mut on, "Difference")
                            .on_hover_text(
                                "Colour the organs by how far each point moved between the \
                                 result before the last edit and the current one, at this \
                                 keyframe",
                            )
                            .changed()
                        {
                            view.field = on.then_some(ViewField::Difference);
                        }
                    });
                });
            });
        let was = ctx.data(|d| d.get_temp::<bool>(before_button_id()).unwrap_or(false));
        if held != was {
            ctx.data_mut(|d| d.insert_temp(before_button_id(), held));
            ctx.request_repaint();
        }
        if view != self.view {
            self.queued.push(Command::SetView(view));
        }
    }

    /// The scene shown last and its key (tests check what the viewport
    /// shows).
    pub fn shown_scene(&self) -> (Option<SceneKey>, Arc<Vec<SceneOrgan>>) {
        self.scene.last()
    }

    /// The field drawn on the scene shown last, or why there is none.
    pub fn shown_field(&self) -> Option<Arc<FieldShown>> {
        self.scene.field()
    }
}

/// The result before the last edit at `time`, for tests of the session.
#[cfg(test)]
fn before_positions(session: &SimSession, time: f64) -> Option<Vec<Vec<DVec3>>> {
    session.before_at(time).map(|s| s.positions)
}

#[cfg(test)]
mod tests {
    use super::*;
    use anthesis_sim::worker::Event;
    use anthesis_sim::{Keyframe, KeyframeStats, Selection};

    /// Keyframe `index` of a run of every organ of `project`, each point
    /// moved by `offset` from its bud position.
    fn keyframe(project: &anthesis_flower::Project, index: u32, offset: DVec3) -> Arc<Keyframe> {
        let positions_in_world = (0..project.flower.organs.len())
            .map(|o| {
                let placement = &project.flower.organs[o].placement;
                project
                    .flower
                    .template_of(o)
                    .mesh
                    .positions
                    .iter()
                    .map(|p| placement.world_from_template(*p, 0.0) + offset)
                    .collect()
            })
            .collect();
        Arc::new(Keyframe {
            index,
            positions_in_world,
            stats: KeyframeStats {
                index,
                energy: 0.0,
                iterations: 1,
                relative_gradient: 0.0,
                seconds: 0.1,
                pushed_particles: 0,
                contact_particles: 0,
            },
        })
    }

    /// Runs `project` to its end in `session`, keyframe `k` moved by `k`
    /// times `step`; `finish`: the run's end arrives.
    fn run(
        session: &mut SimSession,
        project: &Arc<anthesis_flower::Project>,
        step: DVec3,
        finish: bool,
    ) {
        let run = session.start(Arc::clone(project), Selection::All);
        let total = project.settings.keyframes;
        for k in 0..=total {
            let keyframe = keyframe(project, k, step * f64::from(k));
            assert!(session.accept(Event::Keyframe { run, keyframe }, &mut Vec::new()));
        }
        if finish {
            assert!(session.accept(
                Event::Finished {
                    run,
                    keyframes: total,
                    seconds: 1.0
                },
                &mut Vec::new()
            ));
        }
    }

    fn edited(project: &anthesis_flower::Project, dg: f64) -> Arc<anthesis_flower::Project> {
        let mut edited = project.clone();
        edited.flower.templates[0].dg = dg;
        Arc::new(edited)
    }

    fn first_x(positions: Option<Vec<Vec<DVec3>>>) -> f64 {
        positions.expect("a result")[0][0].x
    }

    fn organ_of(mesh: &Mesh, offset: DVec3) -> SceneOrgan {
        SceneOrgan {
            organ: 0,
            positions_in_world: mesh.positions.iter().map(|p| *p + offset).collect(),
            triangles: mesh.triangles.clone(),
            uvs: mesh.uvs.clone(),
            simulated: true,
        }
    }

    #[test]
    fn a_coarser_mesh_is_compared_through_its_uvs_with_the_same_points_of_the_finer() {
        // A proxy's points lie on the fine surface at their UVs: with the
        // fine result moved by t, every proxy point is |t| from its match.
        let project = anthesis_sim::fixtures::whorl(1, 16, 28, 2);
        let template = project.flower.template_of(0);
        let coarse = anthesis_flower::resolution::proxy_mesh(template).expect("a proxy");
        assert!(coarse.vertex_count() * 2 < template.mesh.vertex_count());
        let moved = DVec3::new(0.3, -0.4, 1.2);
        let here = organ_of(&coarse, DVec3::ZERO);
        let there = organ_of(&template.mesh, moved);
        let found = distances(&here, &there);
        assert_eq!(found.len(), coarse.vertex_count());
        for d in found {
            assert!((d - moved.length()).abs() < 1e-9, "{d}");
        }
        // The same mesh: point by point.
        let same = distances(&organ_of(&template.mesh, DVec3::ZERO), &there);
        assert!(same.iter().all(|d| (d - moved.length()).abs() < 1e-12));
    }

    #[test]
    fn before_is_the_finished_result_an_edit_replaced_and_an_undo_swaps_them() {
        let a = Arc::new(anthesis_sim::fixtures::whorl(2, 4, 6, 4));
        let bud_x = first_x(Some(vec![vec![
            a.flower.organs[0]
                .placement
                .world_from_template(a.flower.template_of(0).mesh.positions[0], 0.0),
        ]]));
        let mut session = SimSession::recorded();
        run(&mut session, &a, DVec3::X, true);
        assert!(session.before().is_none(), "nothing before the first run");

        // An edit: its run replaces the first result, which is "before".
        let b = edited(&a, 0.01);
        let revision = session.before_revision();
        run(&mut session, &b, DVec3::X * 2.0, false);
        assert!(session.before_revision() > revision);
        assert_eq!(first_x(before_positions(&session, 3.0)) - bud_x, 3.0);
        // A stroke's further runs, none finished: "before" stays.
        let c = edited(&a, 0.02);
        run(&mut session, &c, DVec3::X * 5.0, false);
        let d = edited(&a, 0.03);
        run(&mut session, &d, DVec3::X * 7.0, true);
        assert_eq!(first_x(before_positions(&session, 3.0)) - bud_x, 3.0);
        assert_eq!(first_x(session.positions_at(3.0)) - bud_x, 21.0);
        // Interpolated between keyframes as the current result is.
        assert_eq!(first_x(before_positions(&session, 2.5)) - bud_x, 2.5);

        // Undo (back to `a`): "before" is the result with the edit.
        run(&mut session, &a, DVec3::X, true);
        assert_eq!(first_x(before_positions(&session, 3.0)) - bud_x, 21.0);
        // Redo: the result without it.
        run(&mut session, &d, DVec3::X * 7.0, true);
        assert_eq!(first_x(before_positions(&session, 3.0)) - bud_x, 3.0);

        // The same project again (run again): "before" stays.
        let revision = session.before_revision();
        run(&mut session, &d, DVec3::X * 7.0, true);
        assert_eq!(session.before_revision(), revision);

        // A preview of one organ has no "before" of its own...
        session.start(Arc::clone(&d), Selection::Only(1));
        assert!(session.before().is_none());
        // ...and the whole flower's comes back with it.
        session.start(Arc::clone(&d), Selection::All);
        assert!(session.before().is_some());

        // A new document forgets it.
        session.forget_shown();
        assert!(session.before().is_none());
    }
}

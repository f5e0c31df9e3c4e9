//! The panels around the viewport and the viewport panel itself. Each
//! draws from the app's state and queues [`Command`]s for what the user
//! asked; none changes the project directly.

use eframe::egui;

use super::command::Command;
use super::params;
use super::timeline;
use super::viewport;
use super::{AnthesisApp, LeftTab, flower_panel};

/// The scroll area a whole side panel scrolls in (the wheel over the
/// panel scrolls it; widgets that take the wheel themselves say so).
pub(super) fn panel_scroll(id: &str) -> egui::ScrollArea {
    egui::ScrollArea::vertical()
        .id_salt(id)
        .auto_shrink([false, false])
}

impl AnthesisApp {
    /// The left panel: organs, preview switch, and the selected organ's
    /// parameters or the Flower panel.
    pub(super) fn organs_panel(&mut self, ui: &mut egui::Ui) {
        // The whole panel scrolls as one, organ list and all, so every
        // control can be reached in a short window.
        panel_scroll("organs panel").show(ui, |ui| self.organs_panel_contents(ui));
    }

    /// What [`AnthesisApp::organs_panel`] scrolls.
    fn organs_panel_contents(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.heading("Organs");
            ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                ui.selectable_value(&mut self.left_tab, LeftTab::Flower, "Flower")
                    .on_hover_text(
                        "The whole flower: templates, arrangement, organs, overlap order, parts",
                    );
                ui.selectable_value(&mut self.left_tab, LeftTab::Organ, "Organ")
                    .on_hover_text("The selected organ's template: parameters and resolution");
            });
        });
        let mut chosen = Vec::new();
        egui::ScrollArea::vertical()
            .id_salt("organ list")
            .max_height(160.0)
            .show(ui, |ui| {
                for (i, organ) in self.project().flower.organs.iter().enumerate() {
                    if ui
                        .selectable_label(i == self.selected_organ, &organ.name)
                        .on_hover_text("Select this organ (or click it in the viewport)")
                        .clicked()
                    {
                        chosen.push(Command::SelectOrgan(i));
                    }
                }
            });
        let mut preview = self.single_organ_preview;
        if ui
            .checkbox(&mut preview, "Single-organ preview  (P)")
            .on_hover_text(
                "Simulate only the selected organ, without collisions: much faster while \
                 painting. Off: the whole flower with collisions.",
            )
            .changed()
        {
            chosen.push(Command::SetSingleOrganPreview(preview));
        }
        ui.separator();
        if self.left_tab == LeftTab::Flower {
            let now = ui.input(|i| i.time);
            chosen.extend(flower_panel::flower_ui(
                ui,
                self.doc.project(),
                &mut self.flower_panel,
                now,
            ));
            self.queued.extend(chosen);
            return;
        }
        let template = self.selected_template();
        let resolved = self.resolved_project();
        let viewed = self.viewed_organ();
        chosen.extend(params::parameters_ui_viewing(
            ui,
            self.doc.project(),
            &resolved,
            template,
            viewed.as_ref(),
        ));
        self.queued.extend(chosen);
    }

    /// The selected organ's shape at the keyframe shown (the playhead
    /// rounded to the nearest computed keyframe), when the run has it.
    fn viewed_organ(&self) -> Option<super::two_state::ViewedOrgan> {
        let organ = self.selected_organ();
        let slot = self.session.organs().iter().position(|&o| o == organ)?;
        let wanted = self.playback.time_in_keyframes.round().max(0.0) as u32;
        let keyframe = self
            .session
            .keyframes()
            .iter()
            .find(|k| k.index == wanted)?;
        Some(super::two_state::ViewedOrgan {
            organ,
            keyframe: keyframe.index,
            positions_in_world: keyframe.positions_in_world.get(slot)?.clone(),
        })
    }

    /// The timeline panel (the playhead is scrubbed directly; buttons
    /// queue commands).
    pub(super) fn timeline_panel(&mut self, ui: &mut egui::Ui) {
        let template = &self.project().flower.templates[self.selected_template()];
        let keys = timeline::KeyMarks {
            template: template.name.clone(),
            steps: template.maps.keys().iter().map(|k| k.step).collect(),
            painted: Some(self.paint.key).filter(|&k| k < template.maps.keys().len()),
        };
        let chosen = timeline::timeline_ui(ui, &mut self.playback, &self.session, &keys);
        self.queued.extend(chosen);
    }

    /// The paint panel for the selected organ's template.
    pub(super) fn paint_panel(&mut self, ui: &mut egui::Ui) {
        let template = self.selected_template();
        // The canvas is sized by the panel's height as shown, not by the
        // scrolled content's (which has no end).
        let shown_height = ui.available_height();
        let chosen = panel_scroll("paint panel")
            .show(ui, |ui| {
                self.paint
                    .ui(ui, self.doc.project(), template, shown_height)
            })
            .inner;
        self.queued.extend(chosen);
    }

    /// The export dialog, when open.
    pub(super) fn export_window(&mut self, ctx: &egui::Context) {
        let selection = self.selection();
        // What the window simulates (remeshed at the project's resolution),
        // for the dialog's "(N now)": the meshes as remeshed, not a
        // prediction of them.
        let simulated = self.resolved_project();
        let simulated_now = selection
            .organs(simulated.flower.organs.len())
            .into_iter()
            .map(|i| simulated.flower.template_of(i).mesh.vertex_count())
            .max()
            .unwrap_or(0);
        let requests = self.export.ui(
            ctx,
            self.session.keyframes().len(),
            self.session.total(),
            self.doc.project(),
            &selection,
            simulated_now,
        );
        if requests.browse {
            self.queued.push(Command::BrowseExportPath);
        }
        if requests.export {
            self.queued.push(Command::StartExport);
        }
    }

    /// The 3D viewport: the scene at the playhead, the camera, picking and
    /// painting on the organ.
    pub(super) fn viewport_panel(&mut self, ui: &mut egui::Ui) {
        self.log.banner_ui(ui);
        let overlay = self.view.overlay.map(|kind| (kind, self.paint.key));
        let fit_target = self.fit.target_overlay().0;
        let (before, before_revision) = self.before_in_key(ui.ctx());
        let key = viewport::SceneKey {
            document_revision: self.doc.revision(),
            run: self.session.run(),
            frames: self.session.frames_at(self.playback.time_in_keyframes),
            shown_end: self.session.shown_end(),
            time_in_keyframes: self.playback.time_in_keyframes,
            selected_organ: self.selected_organ,
            overlay,
            field: self.view.field,
            before,
            before_revision,
            show_others: self.shows_others(),
            fit_target,
        };
        let resolved = self.resolved_project();
        let fit_mesh = self.fit.target_overlay().1;
        let (scene, meshes, revision) = self.scene.get(key, &resolved, &self.session, fit_mesh);
        self.frame_automatically(&scene);
        if !self.has_gpu {
            ui.label("The 3D viewport needs the wgpu renderer.");
            return;
        }
        // The outline of the selected organ as shown (a proxy frame is on
        // the proxy's mesh).
        let outline = match scene.iter().find(|o| o.organ == self.selected_organ) {
            Some(organ) => self.outline.edges_of_triangles(&organ.triangles),
            None => self
                .outline
                .edges_of(&resolved.flower.template_of(self.selected_organ).mesh),
        };
        let viewport_rect = ui.available_rect_before_wrap();
        let response = viewport::viewport_ui(
            ui,
            &mut self.camera,
            self.doc.project(),
            &scene,
            meshes,
            revision,
            &self.view,
            Some((self.selected_organ, outline)),
            Some(self.paint.key),
            self.paint.on_3d,
            self.paint.brush.radius_in_uv,
        );
        self.measure_window(ui.ctx());
        let mut row = self.difference_ui(ui, viewport_rect, &key, 0);
        if let Some((badge, colour)) =
            timeline::viewport_badge(&self.session, key.time_in_keyframes).filter(|_| !key.before)
        {
            viewport::badge(ui, viewport_rect, row, badge, colour);
            row += 1;
        }
        if let Some(warning) =
            timeline::crossing_badge(&self.session, key.time_in_keyframes).filter(|_| !key.before)
        {
            viewport::badge(ui, viewport_rect, row, &warning, timeline::CROSSING_COLOUR);
        }
        let template = self.selected_template();
        // Alt, or the eyedropper, picks the value under the pointer on the
        // organ as on the canvas, instead of painting.
        let picking = ui.input(|i| i.modifiers.alt) || self.paint.eyedropper;
        match response.painting {
            Some(hit)
                if picking && self.project().flower.organs[hit.organ].template == template =>
            {
                let current = &self.doc.project().flower.templates[template];
                self.paint.pick(current, hit.point_in_uv);
                self.paint.end_stroke();
            }
            Some(hit) if self.project().flower.organs[hit.organ].template == template => {
                // The same spacing as on the canvas, in UV along the
                // picked path.
                let dabs = self
                    .paint
                    .stroke_to(self.doc.project(), template, hit.point_in_uv);
                self.queued.extend(dabs);
            }
            _ if response.painting_off_organ => {
                // Off the organ (or on another one): the stroke goes on
                // from where the pointer comes back, not across the gap.
                self.paint.end_stroke();
            }
            _ => {
                if let Some(hit) = response.clicked {
                    self.queued.push(Command::SelectOrgan(hit.organ));
                }
            }
        }
    }
}

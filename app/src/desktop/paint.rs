//! The UV paint canvas: the selected template's UV layout over the selected
//! map of the selected time key, with pan and zoom; brush settings; time
//! keys (add, remove, pick, blend). Dabs and key changes become
//! [`Command::Edit`]s (a stroke is one undo step) and restart the
//! simulation. The brush arithmetic is in [`anthesis_maps::brush`].

use anthesis_flower::{Project, Template};
use anthesis_maps::{Blend, MapKey, MapKind};
use eframe::egui::{self, Color32, Pos2, Rect, Sense, Stroke, Vec2};
use glam::DVec2;

use super::command::{Command, ProjectEdit};
use anthesis_maps::brush::{Brush, BrushMode, PaintTarget};

/// The paint panel's state.
pub struct PaintState {
    pub target: PaintTarget,
    /// Index of the time key being painted.
    pub key: usize,
    pub brush: Brush,
    /// Dragging on the selected organ in the 3D viewport paints too.
    pub on_3d: bool,
    /// Step of a key to add.
    pub new_key_step: u32,
    zoom: f32,
    pan: Vec2,
    /// The previous point of the stroke being painted.
    last_uv: Option<DVec2>,
    texture: Option<egui::TextureHandle>,
}

impl Default for PaintState {
    fn default() -> Self {
        PaintState {
            target: PaintTarget::Scalar(MapKind::EGrowthIn),
            key: 0,
            brush: Brush::default(),
            on_3d: false,
            new_key_step: 50,
            zoom: 1.0,
            pan: Vec2::ZERO,
            last_uv: None,
            texture: None,
        }
    }
}

/// Blue (0) – pale yellow (0.5) – red (1), as the viewport's overlay ramp.
pub fn ramp(value: f32) -> Color32 {
    let t = value.clamp(0.0, 1.0);
    let (a, b, s) = if t < 0.5 {
        ([10.0, 60.0, 190.0], [250.0, 240.0, 200.0], t * 2.0)
    } else {
        ([250.0, 240.0, 200.0], [170.0, 10.0, 10.0], t * 2.0 - 1.0)
    };
    let c = |i: usize| (a[i] + (b[i] - a[i]) * s) as u8;
    Color32::from_rgb(c(0), c(1), c(2))
}

/// The picture of `target` in key `key`: scalar maps through [`ramp`],
/// directions as grey (their arrows are drawn on top).
fn map_image(template: &Template, key: usize, target: PaintTarget) -> egui::ColorImage {
    let maps = &template.maps.key_clamped(key).maps;
    match target {
        PaintTarget::Scalar(kind) => {
            let map = maps.scalar(kind);
            let (w, h) = map.size();
            egui::ColorImage::new(
                [w as usize, h as usize],
                map.values().iter().map(|v| ramp(*v)).collect(),
            )
        }
        PaintTarget::Direction => {
            let map = &maps.direction;
            let (w, h) = map.size();
            egui::ColorImage::new(
                [w as usize, h as usize],
                map.values()
                    .iter()
                    .map(|[u, v]| {
                        let length = (u * u + v * v).sqrt().min(1.0);
                        let g = (90.0 + 120.0 * length) as u8;
                        Color32::from_rgb(g, g, g.saturating_add(20))
                    })
                    .collect(),
            )
        }
    }
}

impl PaintState {
    /// One dab at `point_in_uv` on template `template` of `project` (from
    /// the canvas or the 3D organ); the stroke direction comes from the
    /// previous dab. `None` while a direction stroke has no direction yet.
    pub fn dab(
        &mut self,
        project: &Project,
        template: usize,
        point_in_uv: DVec2,
    ) -> Option<Command> {
        let direction = self.last_uv.map_or(DVec2::ZERO, |last| point_in_uv - last);
        if self.target == PaintTarget::Direction
            && matches!(self.brush.mode, BrushMode::Set | BrushMode::Add)
            && direction.length() < 0.1 * self.brush.radius_in_uv
        {
            // Wait until the stroke has a direction.
            if self.last_uv.is_none() {
                self.last_uv = Some(point_in_uv);
            }
            return None;
        }
        self.last_uv = Some(point_in_uv);
        let (key, target, brush) = (self.key, self.target, self.brush);
        let name = &project.flower.templates.get(template)?.name;
        Some(Command::Edit {
            label: format!(
                "{} stroke on {} of {name}",
                brush.mode.label(),
                target.label()
            ),
            edit: ProjectEdit::Dab {
                template,
                key,
                target,
                brush,
                point_in_uv,
                direction_in_uv: direction,
            },
        })
    }

    /// Ends the stroke (pointer released).
    pub fn end_stroke(&mut self) {
        self.last_uv = None;
    }

    /// The paint panel for template `template` of `project`; returns the
    /// edits the user made.
    pub fn ui(&mut self, ui: &mut egui::Ui, project: &Project, template: usize) -> Vec<Command> {
        let Some(current) = project.flower.templates.get(template) else {
            ui.label("No template.");
            return Vec::new();
        };
        let mut chosen = Vec::new();
        ui.heading(format!("Paint “{}”", current.name));
        self.key = current.maps.clamped_index(self.key);

        egui::Grid::new("paint target")
            .num_columns(2)
            .show(ui, |ui| {
                let label = ui.label("Map").id;
                egui::ComboBox::from_id_salt("paint map")
                    .selected_text(self.target.label())
                    .show_ui(ui, |ui| {
                        for kind in MapKind::ALL {
                            ui.selectable_value(
                                &mut self.target,
                                PaintTarget::Scalar(kind),
                                kind.label(),
                            );
                        }
                        ui.selectable_value(&mut self.target, PaintTarget::Direction, "direction");
                    })
                    .response
                    .labelled_by(label)
                    .on_hover_text(
                        "e/w-growth: growth along/across the growth direction of the base layer; \
                     -in: of the inner layer (inner > base bends the petal outwards); stretch, \
                     bend: stiffness multipliers; direction: drag to paint the growth direction.",
                    );
                ui.end_row();

                let label = ui.label("Time key").id;
                ui.horizontal(|ui| {
                    for (i, key) in current.maps.keys().iter().enumerate() {
                        ui.selectable_value(&mut self.key, i, format!("step {}", key.step))
                            .on_hover_text("Paint the maps that hold at this step");
                    }
                })
                .response
                .labelled_by(label);
                ui.end_row();

                let label = ui.label("New key").id;
                ui.horizontal(|ui| {
                    ui.add(egui::DragValue::new(&mut self.new_key_step).range(0..=100_000))
                        .labelled_by(label)
                        .on_hover_text("Step of the key to add");
                    let exists = current
                        .maps
                        .keys()
                        .iter()
                        .any(|k| k.step == self.new_key_step);
                    if ui
                        .add_enabled(!exists, egui::Button::new("Add key"))
                        .on_hover_text(
                            "Add a key at this step, starting from the selected key's maps",
                        )
                        .clicked()
                    {
                        // The new key starts from the selected key's maps;
                        // applying it selects it for painting.
                        let maps = current.maps.keys()[self.key].maps.clone();
                        let step = self.new_key_step;
                        chosen.push(Command::Edit {
                            label: format!("add key {step} to {}", current.name),
                            edit: ProjectEdit::AddKey {
                                template,
                                key: Box::new(MapKey { step, maps }),
                            },
                        });
                    }
                    if ui
                        .add_enabled(
                            current.maps.keys().len() > 1,
                            egui::Button::new("Remove key"),
                        )
                        .on_hover_text("Remove the selected key (the last key cannot go)")
                        .clicked()
                    {
                        chosen.push(Command::Edit {
                            label: format!("remove key from {}", current.name),
                            edit: ProjectEdit::RemoveKey {
                                template,
                                key: self.key,
                            },
                        });
                        self.key = self.key.saturating_sub(1);
                    }
                });
                ui.end_row();

                let label = ui.label("Blend").id;
                let mut blend = current.maps.blend;
                let blend_name = |b: Blend| match b {
                    Blend::Linear => "linear",
                    Blend::Smooth => "smooth (3s² − 2s³)",
                    Blend::Logistic { .. } => "logistic",
                };
                egui::ComboBox::from_id_salt("blend")
                    .selected_text(blend_name(blend))
                    .show_ui(ui, |ui| {
                        for b in [Blend::Linear, Blend::Smooth, Blend::logistic()] {
                            ui.selectable_value(&mut blend, b, blend_name(b));
                        }
                    })
                    .response
                    .labelled_by(label)
                    .on_hover_text("How the maps change from one key to the next");
                if blend != current.maps.blend {
                    chosen.push(Command::Edit {
                        label: format!("blend of {}", current.name),
                        edit: ProjectEdit::Blend { template, blend },
                    });
                }
                ui.end_row();
            });

        chosen.extend(self.canvas(ui, project, template, current));
        ui.separator();
        egui::ScrollArea::vertical()
            .id_salt("brush settings")
            .show(ui, |ui| self.brush_ui(ui));
        chosen
    }

    /// Brush mode, radius, strength, hardness, value, mirror, 3D painting.
    fn brush_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal_wrapped(|ui| {
            for mode in BrushMode::ALL {
                ui.selectable_value(&mut self.brush.mode, mode, mode.label())
                    .on_hover_text(match mode {
                        BrushMode::Set => "Move values towards the brush value",
                        BrushMode::Add => "Add the brush value",
                        BrushMode::Subtract => "Subtract the brush value",
                        BrushMode::Smooth => "Blur towards the neighbours",
                        BrushMode::Reset => "Back to the map's default (growth 0, stiffness 1)",
                    });
            }
        });
        egui::Grid::new("brush").num_columns(2).show(ui, |ui| {
            let slider = |ui: &mut egui::Ui, name: &str, value: &mut f32, tip: &str| {
                let label = ui.label(name).id;
                ui.add(egui::Slider::new(value, 0.0..=1.0))
                    .labelled_by(label)
                    .on_hover_text(tip);
                ui.end_row();
            };
            let label = ui.label("radius").id;
            ui.add(egui::Slider::new(&mut self.brush.radius_in_uv, 0.005..=0.5).logarithmic(true))
                .labelled_by(label)
                .on_hover_text("Brush radius in UV units (the layout is 1 wide)");
            ui.end_row();
            slider(
                ui,
                "strength",
                &mut self.brush.strength,
                "How much one dab changes a value",
            );
            slider(
                ui,
                "hardness",
                &mut self.brush.hardness,
                "Fraction of the radius at full strength",
            );
            slider(
                ui,
                "value",
                &mut self.brush.value,
                "What set moves towards, and what add and subtract add or take away",
            );
        });
        ui.checkbox(&mut self.brush.mirror, "Mirror about the midrib (u = 0.5)");
        ui.checkbox(&mut self.on_3d, "Paint on the 3D organ (drag on it)")
            .on_hover_text(
                "Dragging on the selected organ in the viewport paints; Shift+drag orbits",
            );
    }

    /// The UV canvas: the map, the UV layout, arrows for the direction map.
    fn canvas(
        &mut self,
        ui: &mut egui::Ui,
        project: &Project,
        template: usize,
        current: &Template,
    ) -> Option<Command> {
        let side = ui
            .available_width()
            .min(0.6 * ui.available_height())
            .max(120.0);
        let (rect, response) = ui.allocate_exact_size(Vec2::splat(side), Sense::click_and_drag());
        response
            .widget_info(|| egui::WidgetInfo::labeled(egui::Role::Canvas, true, "UV paint canvas"));
        let response = response.on_hover_text(
            "Drag to paint; scroll to zoom; right- or middle-drag to pan; double-click to reset the view",
        );
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                let factor = (scroll * 0.003).exp();
                if let Some(pointer) = response.hover_pos() {
                    // Zoom about the pointer.
                    let before = (pointer - rect.min - self.pan) / self.zoom;
                    self.zoom = (self.zoom * factor).clamp(0.5, 16.0);
                    self.pan = pointer - rect.min - before * self.zoom;
                }
            }
        }
        if response.dragged_by(egui::PointerButton::Secondary)
            || response.dragged_by(egui::PointerButton::Middle)
        {
            self.pan += response.drag_delta();
        }
        if response.double_clicked() {
            self.zoom = 1.0;
            self.pan = Vec2::ZERO;
        }
        let (pan, size) = (self.pan, side * self.zoom);
        let to_screen = |uv: DVec2| {
            Pos2::new(
                rect.left() + pan.x + uv.x as f32 * size,
                rect.top() + pan.y + (1.0 - uv.y as f32) * size,
            )
        };
        let to_uv = |p: Pos2| {
            DVec2::new(
                f64::from((p.x - rect.left() - pan.x) / size),
                1.0 - f64::from((p.y - rect.top() - pan.y) / size),
            )
        };

        // A dab where the pointer is pressed or moves while held: holding
        // still does not paint again on every redraw.
        let fresh = ui.input(|i| i.pointer.primary_pressed() || i.pointer.delta() != Vec2::ZERO);
        let painting = (response.dragged_by(egui::PointerButton::Primary) && fresh)
            || (response.clicked() && !response.double_clicked());
        let dab = match response.interact_pointer_pos() {
            Some(pointer) if painting => self.dab(project, template, to_uv(pointer)),
            _ => None,
        };

        // The document as it is before this frame's dab (the app draws
        // again once the dab is applied).
        let shown = current;
        let image = map_image(shown, self.key, self.target);
        let options = egui::TextureOptions::NEAREST;
        match &mut self.texture {
            Some(texture) => texture.set(image, options),
            None => {
                self.texture = Some(ui.ctx().load_texture("paint map", image, options));
            }
        }
        let painter = ui.painter_at(rect);
        painter.rect_filled(rect, 0.0, ui.visuals().extreme_bg_color);
        let image_rect = Rect::from_min_max(
            to_screen(DVec2::new(0.0, 1.0)),
            to_screen(DVec2::new(1.0, 0.0)),
        );
        if let Some(texture) = &self.texture {
            painter.image(
                texture.id(),
                image_rect,
                Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0)),
                Color32::WHITE,
            );
        }
        let mesh = &current.mesh;
        let stroke = Stroke::new(0.5, Color32::from_black_alpha(140));
        let mut shapes = Vec::with_capacity(mesh.triangles.len() * 3);
        for tri in &mesh.triangles {
            for (a, b) in [(tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])] {
                if a < b {
                    shapes.push(egui::Shape::line_segment(
                        [
                            to_screen(mesh.uvs[a as usize]),
                            to_screen(mesh.uvs[b as usize]),
                        ],
                        stroke,
                    ));
                }
            }
        }
        painter.extend(shapes);
        // The midrib.
        painter.line_segment(
            [
                to_screen(DVec2::new(0.5, 0.0)),
                to_screen(DVec2::new(0.5, 1.0)),
            ],
            Stroke::new(1.0, Color32::from_white_alpha(90)),
        );
        if self.target == PaintTarget::Direction {
            let map = &shown.maps.key_clamped(self.key).maps.direction;
            let n = 14;
            let cell = 1.0 / f64::from(n);
            for j in 0..n {
                for i in 0..n {
                    let uv = DVec2::new((f64::from(i) + 0.5) * cell, (f64::from(j) + 0.5) * cell);
                    let d = map.sample(uv);
                    let tip = uv + d.clamp_length_max(1.0) * cell * 0.8;
                    let from = to_screen(uv);
                    painter.arrow(
                        from,
                        to_screen(tip) - from,
                        Stroke::new(1.2, Color32::from_rgb(20, 40, 140)),
                    );
                }
            }
        }
        if let Some(pointer) = response.hover_pos() {
            let r = self.brush.radius_in_uv as f32 * size;
            painter.circle_stroke(pointer, r, Stroke::new(1.0, Color32::WHITE));
            if self.brush.mirror {
                let uv = to_uv(pointer);
                painter.circle_stroke(
                    to_screen(DVec2::new(1.0 - uv.x, uv.y)),
                    r,
                    Stroke::new(1.0, Color32::from_white_alpha(120)),
                );
            }
        }
        dab
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::desktop::document::Document;

    /// A dab on template 0 applied to `doc` as the app applies it: whether
    /// the project changed.
    fn dab(paint: &mut PaintState, doc: &mut Document, point_in_uv: DVec2) -> bool {
        match paint.dab(doc.project(), 0, point_in_uv) {
            Some(Command::Edit { label, edit }) => doc.edit(&label, |p| edit.apply(p)),
            Some(other) => panic!("a dab is an edit, not {other:?}"),
            None => false,
        }
    }

    #[test]
    fn a_stroke_is_one_undo_step_and_direction_waits_for_movement() {
        let mut doc = Document::new(anthesis_sim::fixtures::whorl(1, 4, 6, 3), None);
        let mut paint = PaintState {
            target: PaintTarget::Scalar(MapKind::Bend),
            ..PaintState::default()
        };
        for i in 0..5 {
            assert!(dab(
                &mut paint,
                &mut doc,
                DVec2::new(0.3 + 0.02 * f64::from(i), 0.5)
            ));
        }
        paint.end_stroke();
        doc.seal();
        assert!(doc.undo().is_some_and(|l| l.contains("bend")));
        assert!(doc.undo().is_none(), "the stroke was one step");

        paint.target = PaintTarget::Direction;
        assert!(
            !dab(&mut paint, &mut doc, DVec2::new(0.3, 0.5)),
            "no direction yet"
        );
        assert!(dab(&mut paint, &mut doc, DVec2::new(0.4, 0.5)));
        let keys = doc.project().flower.templates[0].maps.keys();
        let d = keys[0].maps.direction.sample(DVec2::new(0.4, 0.5));
        assert!(d.x > 0.3, "painted towards +u: {d}");
    }

    #[test]
    fn the_ramp_runs_blue_to_red() {
        let low = ramp(0.0);
        let high = ramp(1.0);
        assert!(low.b() > low.r());
        assert!(high.r() > high.b());
    }
}

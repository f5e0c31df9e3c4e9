//! The UV paint canvas: the selected template's UV layout over the selected
//! map of the selected time key, with pan and zoom; brush settings; time
//! keys (add, remove, pick, blend). Dabs and key changes become
//! [`Command::Edit`]s (a stroke is one undo step) and restart the
//! simulation. The brush arithmetic is in [`anthesis_maps::brush`].

use anthesis_flower::{Project, Template};
use anthesis_maps::{Blend, MapKey, MapKind};
use eframe::egui::{self, Color32, Pos2, Rect, Sense, Stroke, Vec2};
use glam::DVec2;

use super::checked_field::{checked_slider, checked_with};
use super::command::{Command, ProjectEdit};
use super::widgets::section;
use super::words;
use anthesis_maps::brush::{Brush, BrushMode, PaintTarget, StrokeDab, StrokeSpacing};

mod canvas;
mod legend;

/// The radius slider's range (UV units) and the `[`/`]` step factor.
const MIN_RADIUS_IN_UV: f64 = 0.005;
const MAX_RADIUS_IN_UV: f64 = 0.5;
const RADIUS_STEP: f64 = 1.25;
/// The `Shift+[`/`Shift+]` strength step.
const STRENGTH_STEP: f32 = 0.1;

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
    /// Where the dabs of the stroke being painted go (along the pointer's
    /// path, a quarter of the radius apart).
    stroke: StrokeSpacing,
    /// A click waiting to become one dab once the double-click time has
    /// passed without a second click (a double-click resets the view and
    /// paints nothing): where, and when (egui time, seconds).
    pending_click: Option<(DVec2, f64)>,
    /// The eyedropper: the next primary click on the canvas picks the value
    /// under the pointer instead of painting (Alt+click always picks).
    pub eyedropper: bool,
    /// Where the pointer is over the canvas (for the value under it).
    hover_uv: Option<DVec2>,
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
            stroke: StrokeSpacing::new(1.0),
            pending_click: None,
            eyedropper: false,
            hover_uv: None,
            texture: None,
        }
    }
}

/// Blue (0) – pale yellow (0.5) – red (1): the viewport's overlay ramp
/// (`anthesis_render::overlay_ramp_linear`, the one definition), encoded
/// to sRGB as the renderer does.
pub fn ramp(value: f32) -> Color32 {
    let [r, g, b] = anthesis_render::overlay_ramp_linear(value);
    Color32::from(egui::Rgba::from_rgb(r, g, b))
}

/// The picture of `target` in key `key`: scalar maps through [`ramp`],
/// directions as grey (their arrows are drawn on top), the colour map as
/// the organ's actual colours.
fn map_image(template: &Template, key: usize, target: PaintTarget) -> egui::ColorImage {
    let maps = &template.maps.key_clamped(key).maps;
    match target {
        PaintTarget::Colour => {
            let (w, h) = template.colour_image_size();
            let image = template.colour_image(w, h);
            egui::ColorImage::from_rgba_unmultiplied([w as usize, h as usize], image.as_raw())
        }
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
    /// The stroke continues to `point_in_uv` on template `template` of
    /// `project` (from the canvas or the 3D organ): the dabs along the path
    /// since the last point, a quarter of the brush radius apart
    /// ([`StrokeSpacing`]), as one edit; the first point of a stroke is one
    /// dab. Direction dabs take the stroke's direction, so the first point
    /// of a direction stroke paints nothing. `None` when there is nothing to
    /// paint.
    pub fn stroke_to(
        &mut self,
        project: &Project,
        template: usize,
        point_in_uv: DVec2,
    ) -> Option<Command> {
        if !self.stroke.started() {
            self.stroke = StrokeSpacing::for_brush(&self.brush);
        }
        let dabs = self.stroke.extend_to(point_in_uv);
        self.edit(project, template, dabs, "stroke")
    }

    /// One dab at `point_in_uv` (a click), as its own edit.
    pub fn dab(
        &mut self,
        project: &Project,
        template: usize,
        point_in_uv: DVec2,
    ) -> Option<Command> {
        let dab = StrokeDab {
            centre_in_uv: point_in_uv,
            direction_in_uv: DVec2::ZERO,
        };
        self.edit(project, template, vec![dab], "dab")
    }

    /// The dabs as one [`ProjectEdit::Dabs`] named after `what` ("stroke",
    /// "dab"): a click's dab and a stroke after it are two undo steps.
    fn edit(
        &self,
        project: &Project,
        template: usize,
        mut dabs: Vec<StrokeDab>,
        what: &str,
    ) -> Option<Command> {
        if self.target == PaintTarget::Direction
            && matches!(self.brush.mode, BrushMode::Set | BrushMode::Add)
        {
            // A direction is painted only where the stroke has one.
            dabs.retain(|d| d.direction_in_uv != DVec2::ZERO);
        }
        if dabs.is_empty() {
            return None;
        }
        let (key, target, brush) = (self.key, self.target, self.brush);
        let name = &project.flower.templates.get(template)?.name;
        Some(Command::Edit {
            label: format!(
                "{} {what} on {} of {name}",
                brush.mode.label(),
                target.label()
            ),
            edit: ProjectEdit::Dabs {
                template,
                key,
                target,
                brush,
                dabs,
            },
        })
    }

    /// The eyedropper: the brush takes the value of the shown scalar map at
    /// `point_in_uv` and becomes a set brush (set moves values towards the
    /// brush value, so painting then lays down the picked value). The
    /// direction map has no brush value: nothing is picked there. Returns
    /// the value picked.
    pub fn pick(&mut self, template: &Template, point_in_uv: DVec2) -> Option<f32> {
        let value = self.value_at(template, point_in_uv)?;
        self.brush.value = value;
        self.brush.mode = BrushMode::Set;
        self.eyedropper = false;
        Some(value)
    }

    /// The value of the shown scalar map at `point_in_uv` (bilinear, as
    /// the simulation samples it); `None` for the direction map.
    pub fn value_at(&self, template: &Template, point_in_uv: DVec2) -> Option<f32> {
        match self.target {
            PaintTarget::Scalar(kind) => Some(
                template
                    .maps
                    .key_clamped(self.key)
                    .maps
                    .scalar(kind)
                    .sample(point_in_uv) as f32,
            ),
            PaintTarget::Direction => None,
            PaintTarget::Colour => Some(
                template
                    .colouring
                    .as_ref()
                    .map_or(0.0, |c| c.mix.sample(point_in_uv) as f32),
            ),
        }
    }

    /// Radius steps of the `]` / `[` shortcuts: one step is a factor of
    /// 1.25, within the radius slider's range.
    pub fn grow_radius(&mut self) {
        self.brush.radius_in_uv = (self.brush.radius_in_uv * RADIUS_STEP).min(MAX_RADIUS_IN_UV);
    }

    /// See [`PaintState::grow_radius`].
    pub fn shrink_radius(&mut self) {
        self.brush.radius_in_uv = (self.brush.radius_in_uv / RADIUS_STEP).max(MIN_RADIUS_IN_UV);
    }

    /// Strength steps of the `Shift+]` / `Shift+[` shortcuts: 0.1, within
    /// `[0, 1]`.
    pub fn raise_strength(&mut self) {
        self.brush.strength = (self.brush.strength + STRENGTH_STEP).min(1.0);
    }

    /// See [`PaintState::raise_strength`].
    pub fn lower_strength(&mut self) {
        self.brush.strength = (self.brush.strength - STRENGTH_STEP).max(0.0);
    }

    /// The `X` shortcut: add becomes subtract and subtract add; any other
    /// mode becomes add (so `X` always leaves an add/subtract brush).
    pub fn toggle_mode(&mut self) {
        self.brush.mode = match self.brush.mode {
            BrushMode::Add => BrushMode::Subtract,
            _ => BrushMode::Add,
        };
    }

    /// Ends the stroke (pointer released, or left the organ).
    pub fn end_stroke(&mut self) {
        self.stroke.end();
    }

    /// The paint panel for template `template` of `project`, in a panel
    /// `shown_height` points tall (the canvas takes at most 60 % of it);
    /// returns the edits the user made.
    pub fn ui(
        &mut self,
        ui: &mut egui::Ui,
        project: &Project,
        template: usize,
        shown_height: f32,
    ) -> Vec<Command> {
        let Some(current) = project.flower.templates.get(template) else {
            ui.label("No template.");
            return Vec::new();
        };
        let mut chosen = Vec::new();
        ui.heading(format!("Paint “{}”", current.name));
        self.key = current.maps.clamped_index(self.key);

        egui::Grid::new("paint map").num_columns(2).show(ui, |ui| {
            let label = ui.label("Map").id;
            egui::ComboBox::from_id_salt("paint map")
                .selected_text(words::label(self.target.label()))
                .show_ui(ui, |ui| {
                    let targets = MapKind::ALL
                        .into_iter()
                        .map(PaintTarget::Scalar)
                        .chain([PaintTarget::Direction, PaintTarget::Colour]);
                    for target in targets {
                        ui.selectable_value(&mut self.target, target, words::label(target.label()))
                            .on_hover_text(words::tooltip(target.label()));
                    }
                })
                .response
                .labelled_by(label)
                .on_hover_text(words::tooltip(self.target.label()));
            ui.end_row();
        });
        let top = ui.cursor().top();
        section(
            ui,
            "Time keys",
            "The maps hold at time keys (steps) and blend between them: which key is \
             painted, its own growth per step, keys added or removed, the blend.",
            |ui| self.keys_grid(ui, project, template, current, &mut chosen),
        );
        // The canvas takes at most 60 % of what the panel shows below the
        // map and keys, as it did before the panel scrolled.
        let room = (shown_height - (ui.cursor().top() - top) - 40.0).max(200.0);
        ui.allocate_ui(egui::vec2(ui.available_width(), room), |ui| {
            chosen.extend(self.canvas(ui, project, template, current));
        });
        self.legend_ui(ui, current);
        if let Some(Some(brush)) = section(
            ui,
            "Brush",
            "How a stroke paints: mode, size, strength, hardness, value; the eyedropper, the \
             mirror and painting on the 3D organ.",
            |ui| self.brush_ui(ui),
        ) {
            chosen.push(brush);
        }
        chosen
    }

    /// The time keys' grid: which key is painted, its own dg, a new key,
    /// the blend.
    fn keys_grid(
        &mut self,
        ui: &mut egui::Ui,
        project: &Project,
        template: usize,
        current: &Template,
        chosen: &mut Vec<Command>,
    ) {
        egui::Grid::new("paint target")
            .num_columns(2)
            .show(ui, |ui| {
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

                self.key_dg_row(ui, (project, template, current), chosen);

                self.new_key_row(ui, (template, current), chosen);

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
    }

    /// The "Key growth (dg)" row of the paint grid: the chosen time key's own growth
    /// scale, or the template's.
    fn key_dg_row(
        &mut self,
        ui: &mut egui::Ui,
        (project, template, current): (&Project, usize, &Template),
        chosen: &mut Vec<Command>,
    ) {
        let label = ui
            .label("Key growth (dg)")
            .on_hover_text(format!(
                "This time key's own growth per step, in place of the template's.\n{}",
                words::tooltip("dg")
            ))
            .id;
        ui.horizontal(|ui| {
            let key = &current.maps.keys()[self.key];
            let mut own = key.dg.is_some();
            let mut dg = key.dg.unwrap_or(current.dg);
            let toggled = ui
                .checkbox(&mut own, "own")
                .on_hover_text(
                    "This key's own growth scale in place of the template's dg, \
                             blended between keys like the maps; negative: the organ \
                             shrinks (wilting after it opened)",
                )
                .changed();
            let dragged = ui
                .add_enabled_ui(own, |ui| {
                    checked_with(ui, "dg", &mut dg, -0.5..=0.5, |d| {
                        d.speed(0.0001).max_decimals(4)
                    })
                })
                .inner
                .labelled_by(label)
                .changed();
            if toggled || dragged {
                let mut value = current.clone();
                if let Some(k) = value.maps.keys_mut().get_mut(self.key) {
                    k.dg = own.then_some(dg);
                }
                chosen.push(Command::Edit {
                    label: format!("dg of key {} of {}", key.step, current.name),
                    edit: ProjectEdit::Template {
                        template,
                        value: Box::new(value),
                        keyframes: project.settings.keyframes,
                    },
                });
            }
        });
        ui.end_row();
    }

    /// The "New key" row of the paint grid: a time key added at a step (a
    /// copy of the chosen key's maps), or the chosen key removed.
    fn new_key_row(
        &mut self,
        ui: &mut egui::Ui,
        (template, current): (usize, &Template),
        chosen: &mut Vec<Command>,
    ) {
        let label = ui.label("New key").id;
        ui.horizontal(|ui| {
            checked_with(
                ui,
                "new key step",
                &mut self.new_key_step,
                0..=100_000,
                |d| d,
            )
            .labelled_by(label)
            .on_hover_text("Step of the key to add");
            let exists = current
                .maps
                .keys()
                .iter()
                .any(|k| k.step == self.new_key_step);
            if ui
                .add_enabled(!exists, egui::Button::new("Add key"))
                .on_hover_text("Add a key at this step, starting from the selected key's maps")
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
                        key: Box::new(MapKey {
                            dg: None,
                            step,
                            maps,
                        }),
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
    }

    /// Brush mode, radius, strength, hardness, value, mirror, 3D painting;
    /// a change of the brush as a command ([`Command::SetBrush`]).
    fn brush_ui(&mut self, ui: &mut egui::Ui) -> Option<Command> {
        let mut brush = self.brush;
        ui.horizontal_wrapped(|ui| {
            for mode in BrushMode::ALL {
                ui.selectable_value(&mut brush.mode, mode, mode.label())
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
            let name = |ui: &mut egui::Ui, symbol: &str| {
                ui.label(words::label(symbol))
                    .on_hover_text(words::tooltip(symbol))
                    .id
            };
            let slider = |ui: &mut egui::Ui, symbol: &str, value: &mut f32| {
                let label = name(ui, symbol);
                checked_slider(ui, &words::label(symbol), value, 0.0..=1.0, |s| s)
                    .labelled_by(label)
                    .on_hover_text(words::tooltip(symbol));
                ui.end_row();
            };
            let label = name(ui, "radius");
            checked_slider(
                ui,
                &words::label("radius"),
                &mut brush.radius_in_uv,
                MIN_RADIUS_IN_UV..=MAX_RADIUS_IN_UV,
                |s| s.logarithmic(true),
            )
            .labelled_by(label)
            .on_hover_text(words::tooltip("radius"));
            ui.end_row();
            slider(ui, "strength", &mut brush.strength);
            slider(ui, "hardness", &mut brush.hardness);
            slider(ui, "value", &mut brush.value);
        });
        ui.toggle_value(&mut self.eyedropper, "Eyedropper")
            .on_hover_text(
                "Click the canvas (or the organ, when painting on the 3D organ) to pick the \
                 value under the pointer as a set brush (Alt+click always picks)",
            );
        ui.checkbox(&mut brush.mirror, "Mirror about the midrib (u = 0.5)");
        ui.checkbox(&mut self.on_3d, "Paint on the 3D organ (drag on it)")
            .on_hover_text(
                "Dragging on the selected organ in the viewport paints; Alt+click picks the \
                 value there; Shift+drag orbits",
            );
        (brush != self.brush).then_some(Command::SetBrush(brush))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::desktop::document::Document;

    /// The stroke on template 0 continued to `point_in_uv`, applied to `doc`
    /// as the app applies it: whether
    /// the project changed.
    fn dab(paint: &mut PaintState, doc: &mut Document, point_in_uv: DVec2) -> bool {
        match paint.stroke_to(doc.project(), 0, point_in_uv) {
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
                DVec2::new(0.3 + 0.03 * f64::from(i), 0.5)
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
        paint.end_stroke();
        let keys = doc.project().flower.templates[0].maps.keys();
        let d = keys[0].maps.direction.sample(DVec2::new(0.4, 0.5));
        assert!(d.x > 0.3, "painted towards +u: {d}");
    }

    #[test]
    fn shortcut_steps_stay_in_the_sliders_ranges_and_x_swaps_add_and_subtract() {
        let mut paint = PaintState::default();
        let r = paint.brush.radius_in_uv;
        paint.grow_radius();
        assert!((paint.brush.radius_in_uv - r * RADIUS_STEP).abs() < 1e-12);
        paint.shrink_radius();
        assert!((paint.brush.radius_in_uv - r).abs() < 1e-12);
        for _ in 0..100 {
            paint.grow_radius();
        }
        assert_eq!(paint.brush.radius_in_uv, MAX_RADIUS_IN_UV);
        for _ in 0..100 {
            paint.shrink_radius();
        }
        assert_eq!(paint.brush.radius_in_uv, MIN_RADIUS_IN_UV);

        paint.brush.strength = 0.5;
        paint.raise_strength();
        assert!((paint.brush.strength - 0.6).abs() < 1e-6);
        for _ in 0..20 {
            paint.lower_strength();
        }
        assert_eq!(paint.brush.strength, 0.0);
        for _ in 0..20 {
            paint.raise_strength();
        }
        assert_eq!(paint.brush.strength, 1.0);

        paint.brush.mode = BrushMode::Set;
        paint.toggle_mode();
        assert_eq!(paint.brush.mode, BrushMode::Add);
        paint.toggle_mode();
        assert_eq!(paint.brush.mode, BrushMode::Subtract);
        paint.toggle_mode();
        assert_eq!(paint.brush.mode, BrushMode::Add);
    }

    #[test]
    fn the_ramp_runs_blue_to_red() {
        let low = ramp(0.0);
        let high = ramp(1.0);
        assert!(low.b() > low.r());
        assert!(high.r() > high.b());
    }
}

//! The paint panel's legend: the colour bar of the shown map (the
//! template's colours on the colour map) and what its values mean.

use super::*;

impl PaintState {
    /// The growth scale of the selected key of `current`: its own, else the
    /// template's.
    fn key_dg(&self, current: &Template) -> f64 {
        current
            .maps
            .keys()
            .get(self.key)
            .and_then(|k| k.dg)
            .unwrap_or(current.dg)
    }

    /// The colour bar of the shown map with its values, what 0 and 1 mean
    /// for that map, and the value under the pointer on the canvas.
    pub(super) fn legend_ui(&mut self, ui: &mut egui::Ui, current: &Template) {
        let hovered = self.hover_uv.take();
        // The canvas's hint as a line, not a tooltip over the legend.
        ui.label(
            egui::RichText::new(
                "Drag to paint, click for one dab; Alt+click picks; Ctrl+wheel zooms; \
                 right- or middle-drag to pan; double-click to reset the view",
            )
            .small()
            .weak(),
        );
        let colours = (self.target == PaintTarget::Colour).then(|| {
            let second = current
                .colouring
                .as_ref()
                .map_or(anthesis_flower::DEFAULT_SECOND_COLOUR, |c| c.second_colour);
            (current.colour, second)
        });
        match self.target {
            PaintTarget::Scalar(_) | PaintTarget::Colour => {
                let (area, _) =
                    ui.allocate_exact_size(Vec2::new(ui.available_width(), 26.0), Sense::hover());
                let bar = Rect::from_min_size(area.min, Vec2::new(area.width(), 12.0));
                let painter = ui.painter_at(area);
                let steps = 64;
                for i in 0..steps {
                    let t0 = i as f32 / steps as f32;
                    let t1 = (i + 1) as f32 / steps as f32;
                    painter.rect_filled(
                        Rect::from_x_y_ranges(
                            bar.left() + t0 * bar.width()..=bar.left() + t1 * bar.width(),
                            bar.y_range(),
                        ),
                        0.0,
                        match colours {
                            Some((base, second)) => blend_colour(base, second, (t0 + t1) / 2.0),
                            None => ramp((t0 + t1) / 2.0),
                        },
                    );
                }
                let value_under = hovered.and_then(|uv| self.value_at(current, uv));
                if let Some(value) = value_under {
                    let x = bar.left() + value.clamp(0.0, 1.0) * bar.width();
                    painter.line_segment(
                        [Pos2::new(x, bar.top()), Pos2::new(x, bar.bottom())],
                        Stroke::new(2.0, Color32::BLACK),
                    );
                }
                // Values under the bar.
                for t in [0.0_f32, 0.25, 0.5, 0.75, 1.0] {
                    let x = bar.left() + t * bar.width();
                    let align = if t == 0.0 {
                        egui::Align2::LEFT_TOP
                    } else if t == 1.0 {
                        egui::Align2::RIGHT_TOP
                    } else {
                        egui::Align2::CENTER_TOP
                    };
                    painter.line_segment(
                        [Pos2::new(x, bar.bottom()), Pos2::new(x, bar.bottom() + 3.0)],
                        Stroke::new(1.0, ui.visuals().text_color()),
                    );
                    painter.text(
                        Pos2::new(x, bar.bottom() + 2.0),
                        align,
                        format!("{t}"),
                        egui::FontId::proportional(11.0),
                        ui.visuals().text_color(),
                    );
                }
                let (text, meant) = match self.target {
                    PaintTarget::Scalar(kind) => (
                        legend(kind, self.key_dg(current)),
                        value_under.map(|v| meaning(kind, self.key_dg(current), v)),
                    ),
                    _ => (
                        "colour: how much of the second colour shows over the base colour \
                         (both picked in the parameters panel). 0 = the base colour, 1 = the \
                         second colour; not simulated, so painting it recomputes no keyframe."
                            .to_string(),
                        value_under.map(|v| format!(" = {:.0} % second colour", 100.0 * v)),
                    ),
                };
                ui.label(egui::RichText::new(text).small());
                ui.label(match (hovered, value_under) {
                    (Some(uv), Some(value)) => format!(
                        "under the pointer (u {:.2}, v {:.2}): {value:.3}{}",
                        uv.x,
                        uv.y,
                        meant.unwrap_or_default()
                    ),
                    _ => "under the pointer: –".to_string(),
                });
            }
            PaintTarget::Direction => {
                ui.label(
                    egui::RichText::new(
                        "direction: arrows show the growth direction in UV (e-growth acts \
                         along it, w-growth across it); brighter grey = longer vector, \
                         dark = no direction painted",
                    )
                    .small(),
                );
                let under = hovered.map(|uv| {
                    let d = current.maps.key_clamped(self.key).maps.direction.sample(uv);
                    format!(
                        "under the pointer (u {:.2}, v {:.2}): direction ({:.2}, {:.2})",
                        uv.x, uv.y, d.x, d.y
                    )
                });
                ui.label(under.unwrap_or_else(|| "under the pointer: –".to_string()));
            }
        }
    }
}

/// The base colour blended towards the second by `t` (linear colours, as
/// the renderer blends them), for the screen.
fn blend_colour(base: [f32; 4], second: [f32; 4], t: f32) -> Color32 {
    let c = |i: usize| base[i] + (second[i] - base[i]) * t;
    egui::Rgba::from_rgb(c(0), c(1), c(2)).into()
}

/// What 0 and 1 mean for map `kind` of a template growing at most `dg` per
/// step (rate = 1 + dg · value, paper eq. 2; stiffness = template constant
/// · value).
pub fn legend(kind: MapKind, dg: f64) -> String {
    let percent = 100.0 * dg;
    match kind {
        MapKind::EGrowth | MapKind::WGrowth | MapKind::EGrowthIn | MapKind::WGrowthIn => {
            let (layer, way) = match kind {
                MapKind::EGrowth => ("base layer", "along the growth direction"),
                MapKind::WGrowth => ("base layer", "across the growth direction"),
                MapKind::EGrowthIn => ("inner layer", "along the growth direction"),
                _ => ("inner layer", "across the growth direction"),
            };
            format!(
                "{}: relative growth per step of the {layer} {way}. 0 = no growth, \
                 1 = {percent:+.1} % per step (dg = {dg} at this key; rate = 1 + dg · value). \
                 Inner > base bends the organ outwards.",
                crate::desktop::words::label(kind.label())
            )
        }
        MapKind::Stretch | MapKind::Bend => format!(
            "{}: multiplier of the template's {} stiffness. 0 = none (limp), \
             1 = the template's full stiffness (the default).",
            crate::desktop::words::label(kind.label()),
            if kind == MapKind::Stretch {
                "stretch"
            } else {
                "bend"
            }
        ),
    }
}

/// `value` of map `kind` in the map's own terms, e.g. " = +1.2 % per step".
fn meaning(kind: MapKind, dg: f64, value: f32) -> String {
    match kind {
        MapKind::Stretch | MapKind::Bend => format!(" = {:.0} % of the stiffness", 100.0 * value),
        _ => format!(" = {:+.2} % per step", 100.0 * dg * f64::from(value)),
    }
}

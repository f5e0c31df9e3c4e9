//! Per-vertex scalar fields drawn on the organs shown: one number per point
//! of each organ (how far it moved since the last edit, a curvature, a
//! stretch...), with a name, what the numbers are ([`Quantity`]: a length in
//! the project's real unit, one over a length, a plain ratio) and the range
//! the colour ramp spans. The scene draws a field through the one overlay
//! ramp (`anthesis_render::overlay_ramp_linear`, as the map overlay and the
//! paint canvas), and [`legend`] draws its colour bar, range, maximum and
//! mean in the viewport's corner.
//!
//! A new field is a variant of [`ViewField`] (its [`ViewField::label`] and
//! an arm of [`compute`], which gets the scene shown in [`FieldInput`]);
//! [`ViewOptions::field`](super::ViewOptions::field) chooses the one shown.

use anthesis_flower::Project;
use anthesis_flower::unit::Unit;
use eframe::egui::{self, Color32, Pos2, Rect, Stroke, Vec2};

use super::organ::SceneOrgan;
use crate::desktop::session::SimSession;

/// The fields the viewport can draw on the organs (at most one at a time;
/// it replaces the map overlay while shown).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum ViewField {
    /// How far each point moved between the result before the last edit
    /// and the one shown (`crate::desktop::difference`).
    Difference,
    /// A measurement of the organs at the time shown
    /// (`crate::desktop::measure_panel`).
    Measure(MeasureField),
}

impl ViewField {
    /// Every field, in the order menus list them.
    pub const ALL: [ViewField; 6] = [
        ViewField::Difference,
        ViewField::Measure(MeasureField::MeanCurvature),
        ViewField::Measure(MeasureField::GaussianCurvature),
        ViewField::Measure(MeasureField::StretchMajor),
        ViewField::Measure(MeasureField::StretchMinor),
        ViewField::Measure(MeasureField::Contact),
    ];

    /// The field's name, as menus and the legend say it.
    pub fn label(self) -> &'static str {
        match self {
            ViewField::Difference => "Moved by the last edit",
            ViewField::Measure(field) => field.label(),
        }
    }
}

/// What a field is computed from: the scene as shown (its organs' points,
/// triangles and UVs), the project whose template meshes the scene's
/// simulated organs are on (a proxy frame's are the proxy's, coarser), the
/// session and the time shown.
pub struct FieldInput<'a> {
    /// The project as simulated and shown (the document's at the project's
    /// resolution).
    pub project: &'a Project,
    /// The project whose template meshes the simulated organs of `scene`
    /// are on: `meshes.flower.template_of(organ).mesh` is the rest shape
    /// of a simulated [`SceneOrgan`] (same points, same triangles).
    pub meshes: &'a Project,
    pub session: &'a SimSession,
    pub time_in_keyframes: f64,
    pub scene: &'a [SceneOrgan],
    /// The scene shows the result before the last edit (the key is held),
    /// not the current one.
    pub before: bool,
}

/// What a field's numbers are, so the legend can say them in words people
/// read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Quantity {
    /// A length in project units: shown in the project's real unit when it
    /// states one (`unit = "1.8 mm"`), else in "units".
    Length(Option<Unit>),
    /// One over a length in project units (a curvature): per mm, per cm...
    /// when the project states its unit.
    PerLength(Option<Unit>),
    /// A plain number with a suffix ("", "%", "×").
    Plain(&'static str),
}

/// Real lengths a legend may write values in: the symbol, metres per one,
/// and from how many metres on it is used (µm below 0.01 mm, mm below
/// 10 cm, cm below 1 m, as `Unit::describe` says sizes).
const LENGTH_SCALES: [(&str, f64, f64); 4] = [
    ("µm", 1e-6, 0.0),
    ("mm", 1e-3, 1e-5),
    ("cm", 1e-2, 0.1),
    ("m", 1.0, 1.0),
];

impl Quantity {
    /// The unit a legend whose largest value is `largest` writes every
    /// value in, and that unit's amount per project unit: µm, mm, cm or m
    /// (see [`LENGTH_SCALES`]), "units" when the project states none.
    pub fn scale(&self, largest: f64) -> (String, f64) {
        match *self {
            Quantity::Length(Some(unit)) => {
                let metres = largest.abs() * unit.metres();
                let (symbol, per, _) = LENGTH_SCALES
                    .iter()
                    .rev()
                    .find(|(_, _, from)| metres >= *from)
                    .unwrap_or(&LENGTH_SCALES[0]);
                (symbol.to_string(), unit.metres() / per)
            }
            Quantity::PerLength(Some(unit)) => {
                // Per mm for the curvatures of petals; per µm... never.
                let per = 1e-3;
                ("1/mm".to_string(), per / unit.metres())
            }
            Quantity::Length(None) => ("units".to_string(), 1.0),
            Quantity::PerLength(None) => ("1/unit".to_string(), 1.0),
            Quantity::Plain(suffix) => (suffix.to_string(), 1.0),
        }
    }

    /// `value` written in the unit [`Quantity::scale`] chose for a legend
    /// whose largest value is `largest`, to three significant digits:
    /// `"0.412 mm"`.
    pub fn format(&self, value: f64, largest: f64) -> String {
        let (symbol, per_project_unit) = self.scale(largest);
        let amount = value * per_project_unit;
        let magnitude = (largest.abs() * per_project_unit).max(amount.abs());
        let decimals = if magnitude >= 100.0 {
            0
        } else if magnitude >= 10.0 {
            1
        } else if magnitude >= 1.0 {
            2
        } else {
            3
        };
        if symbol.is_empty() {
            format!("{amount:.decimals$}")
        } else {
            format!("{amount:.decimals$} {symbol}")
        }
    }
}

/// A per-vertex scalar field on the organs of a scene.
#[derive(Debug, Clone, PartialEq)]
pub struct ScalarField {
    /// What it is, as the legend's title says it.
    pub name: String,
    pub quantity: Quantity,
    /// The values the ramp's ends stand for (blue, red), in the field's
    /// own numbers (project units for a length); values outside are drawn
    /// at the ends.
    pub range: [f64; 2],
    /// One entry per organ of the scene, in its order: the value at each
    /// point of the organ as shown, or `None` where the field says nothing
    /// (the organ is drawn without the ramp). A NaN value is a point the
    /// field could not be computed at: drawn at the low end and left out of
    /// [`ScalarField::max`] and [`ScalarField::mean`].
    pub values: Vec<Option<Vec<f64>>>,
    /// Lines under the legend: what the field is measured against, what it
    /// cannot say ("against the proxy...").
    pub notes: Vec<String>,
}

impl ScalarField {
    /// Every finite value.
    fn finite(&self) -> impl Iterator<Item = f64> + '_ {
        self.values
            .iter()
            .flatten()
            .flatten()
            .copied()
            .filter(|v| v.is_finite())
    }

    /// The largest value, if any.
    pub fn max(&self) -> Option<f64> {
        self.finite().reduce(f64::max)
    }

    /// The smallest value, if any.
    pub fn min(&self) -> Option<f64> {
        self.finite().reduce(f64::min)
    }

    /// The mean over every point with a value (each point counts once).
    pub fn mean(&self) -> Option<f64> {
        let (sum, count) = self
            .finite()
            .fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
        (count > 0).then(|| sum / count as f64)
    }

    /// The ramp position (0 at `range[0]`, 1 at `range[1]`) of each point
    /// of the scene's organ `index`, as the renderer's overlay takes it.
    pub fn ramp_values(&self, index: usize) -> Option<Vec<f32>> {
        let values = self.values.get(index)?.as_ref()?;
        let [low, high] = self.range;
        let span = high - low;
        Some(
            values
                .iter()
                .map(|&v| {
                    let t = if span > 0.0 { (v - low) / span } else { 0.0 };
                    if t.is_finite() {
                        t.clamp(0.0, 1.0) as f32
                    } else {
                        0.0
                    }
                })
                .collect(),
        )
    }
}

/// What the viewport shows of the chosen field: the field, or why there is
/// none (shown where the legend would be).
#[derive(Debug, Clone, PartialEq)]
pub enum FieldShown {
    Field(ScalarField),
    Nothing(String),
}

/// Blue (0) – pale yellow (0.5) – red (1): the overlay ramp encoded to
/// sRGB for egui, as the renderer draws it.
fn ramp_colour(t: f32) -> Color32 {
    let [r, g, b] = anthesis_render::overlay_ramp_linear(t);
    Color32::from(egui::Rgba::from_rgb(r, g, b))
}

/// Width of the legend box, in points.
const LEGEND_WIDTH: f32 = 280.0;

/// Draws the legend of `shown` in the bottom-right corner of the viewport
/// `rect`: the field's name, the colour bar with its range in the field's
/// unit, the maximum and mean, and its notes; or the reason there is no
/// field. Labels are egui widgets, so tests and screen readers find them.
pub fn legend(ui: &mut egui::Ui, rect: Rect, name: &str, shown: &FieldShown) {
    let area = egui::Area::new(egui::Id::unique("field legend"))
        .order(egui::Order::Foreground)
        .fixed_pos(Pos2::new(
            rect.right() - LEGEND_WIDTH - 12.0,
            rect.bottom() - 12.0,
        ))
        .pivot(egui::Align2::LEFT_BOTTOM)
        .interactable(false);
    area.show(ui.ctx(), |ui| {
        egui::Frame::popup(ui.style()).show(ui, |ui| {
            ui.set_width(LEGEND_WIDTH);
            match shown {
                FieldShown::Nothing(why) => {
                    ui.strong(name);
                    ui.label(why.as_str());
                }
                FieldShown::Field(field) => field_legend(ui, field),
            }
        });
    });
}

fn field_legend(ui: &mut egui::Ui, field: &ScalarField) {
    let [low, high] = field.range;
    let largest = low.abs().max(high.abs());
    let (symbol, _) = field.quantity.scale(largest);
    if symbol.is_empty() {
        ui.strong(field.name.as_str());
    } else {
        ui.strong(format!("{} ({symbol})", field.name));
    }
    let (area, _) =
        ui.allocate_exact_size(Vec2::new(ui.available_width(), 28.0), egui::Sense::hover());
    let bar = Rect::from_min_size(area.min, Vec2::new(area.width(), 12.0));
    let painter = ui.painter_at(area);
    let steps = 64;
    for i in 0..steps {
        let (t0, t1) = (i as f32 / steps as f32, (i + 1) as f32 / steps as f32);
        painter.rect_filled(
            Rect::from_x_y_ranges(
                bar.left() + t0 * bar.width()..=bar.left() + t1 * bar.width(),
                bar.y_range(),
            ),
            0.0,
            ramp_colour((t0 + t1) / 2.0),
        );
    }
    for (t, align) in [
        (0.0_f32, egui::Align2::LEFT_TOP),
        (0.5, egui::Align2::CENTER_TOP),
        (1.0, egui::Align2::RIGHT_TOP),
    ] {
        let x = bar.left() + t * bar.width();
        painter.line_segment(
            [Pos2::new(x, bar.bottom()), Pos2::new(x, bar.bottom() + 3.0)],
            Stroke::new(1.0, ui.visuals().text_color()),
        );
        let value = low + f64::from(t) * (high - low);
        painter.text(
            Pos2::new(x, bar.bottom() + 3.0),
            align,
            field.quantity.format(value, largest),
            egui::FontId::proportional(11.0),
            ui.visuals().text_color(),
        );
    }
    match (field.max(), field.mean()) {
        (Some(max), Some(mean)) => {
            ui.label(format!(
                "max {}, mean {}",
                field.quantity.format(max, largest),
                field.quantity.format(mean, largest)
            ));
        }
        _ => {
            ui.label("no values");
        }
    }
    for note in &field.notes {
        ui.label(egui::RichText::new(note.as_str()).small());
    }
}

/// A per-vertex measurement the viewport can colour the organs by.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum MeasureField {
    MeanCurvature,
    GaussianCurvature,
    StretchMajor,
    StretchMinor,
    Contact,
}

impl MeasureField {
    pub const ALL: [MeasureField; 5] = [
        MeasureField::MeanCurvature,
        MeasureField::GaussianCurvature,
        MeasureField::StretchMajor,
        MeasureField::StretchMinor,
        MeasureField::Contact,
    ];

    /// The name menus and the legend give it.
    pub fn label(self) -> &'static str {
        match self {
            MeasureField::MeanCurvature => "Mean curvature H",
            MeasureField::GaussianCurvature => "Gaussian curvature K",
            MeasureField::StretchMajor => "Larger principal stretch",
            MeasureField::StretchMinor => "Smaller principal stretch",
            MeasureField::Contact => "Contact with other organs",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field(values: Vec<Option<Vec<f64>>>, range: [f64; 2]) -> ScalarField {
        ScalarField {
            name: "test".to_string(),
            quantity: Quantity::Plain(""),
            range,
            values,
            notes: Vec::new(),
        }
    }

    #[test]
    fn max_and_mean_count_every_point_once_and_skip_organs_without_values() {
        let f = field(
            vec![Some(vec![1.0, 2.0, f64::NAN]), None, Some(vec![6.0])],
            [0.0, 6.0],
        );
        assert_eq!(f.max(), Some(6.0));
        assert_eq!(f.min(), Some(1.0));
        assert_eq!(f.mean(), Some(3.0));
        assert_eq!(field(vec![None], [0.0, 1.0]).mean(), None);
    }

    #[test]
    fn ramp_values_span_the_range_and_clamp_outside_it() {
        let f = field(
            vec![Some(vec![-1.0, 2.0, 3.0, 4.0, 9.0, f64::NAN])],
            [2.0, 4.0],
        );
        assert_eq!(f.ramp_values(0), Some(vec![0.0, 0.0, 0.5, 1.0, 1.0, 0.0]));
        assert_eq!(f.ramp_values(1), None);
        // An empty range (nothing moved): every point at the low end.
        let flat = field(vec![Some(vec![0.0, 0.0])], [0.0, 0.0]);
        assert_eq!(flat.ramp_values(0), Some(vec![0.0, 0.0]));
    }

    #[test]
    fn lengths_are_written_in_the_projects_real_unit_scaled_to_the_largest() {
        let unit = Unit::parse("1.8 mm").ok();
        let length = Quantity::Length(unit);
        // 0.5 units of 1.8 mm: 0.9 mm.
        assert_eq!(length.format(0.5, 0.5), "0.900 mm");
        // 100 units: 18 cm.
        assert_eq!(length.format(100.0, 100.0), "18.0 cm");
        // Small moves in µm.
        assert_eq!(length.format(0.001, 0.001), "1.80 µm");
        // A smaller value of the same legend keeps the legend's unit.
        assert_eq!(length.format(0.05, 0.5), "0.090 mm");
        assert_eq!(Quantity::Length(None).format(0.25, 1.0), "0.25 units");
        assert_eq!(Quantity::Plain("%").format(12.345, 20.0), "12.3 %");
        let per = Quantity::PerLength(unit);
        // One over 1.8 mm: 0.556 per mm.
        assert_eq!(per.format(1.0, 1.0), "0.556 1/mm");
    }
}

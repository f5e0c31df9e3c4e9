//! View → Measurements: the measurements of `anthesis_sim::measure` (the
//! ones `anthesis measure` writes) in the window. The organs coloured by a
//! per-vertex measurement at the time shown (mean or Gaussian curvature,
//! a principal stretch against the bud, contact), through the viewport's
//! field overlay and its legend ([`measure_field`], a
//! [`ViewField::Measure`]); and a plot of any table column of one organ
//! over the keyframes shown, the viewed keyframe marked.
//!
//! The window's state (open, organ, column, the summaries computed) lives
//! in egui's memory, so the app's state keeps only the view's field.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use anthesis_mesh::Mesh;
use anthesis_sim::measure::{
    self as engine, OrganLayout, OrganMeasure, QUANTITIES, Summary, real_scale,
};
use eframe::egui::{self, Stroke};
use glam::DVec3;

use super::AnthesisApp;
use super::command::Command;
use super::session::SimSession;
use super::viewport::field::FieldInput;
pub use super::viewport::field::MeasureField;
use super::viewport::{FieldShown, Quantity, ScalarField, SceneOrgan, ViewField};

/// What the legend says of a field, besides its numbers.
fn explain(field: MeasureField) -> &'static str {
    match field {
        MeasureField::MeanCurvature => {
            "Half the cotangent Laplacian along the normal of the inner side (Meyer et al. \
                 2003); a sphere of radius R has 1/R. Rim points have none (drawn at the low end)."
        }
        MeasureField::GaussianCurvature => {
            "The angle defect over the mixed Voronoi area: positive on a cup, negative on a \
                 saddle, 0 where the surface unrolls flat. Rim points have none (drawn at the \
                 low end)."
        }
        MeasureField::StretchMajor | MeasureField::StretchMinor => {
            "Against the bud (keyframe 0): 1 unchanged, 1.4 forty per cent longer; each \
                 point the mean of its triangles weighted by their area in the bud."
        }
        MeasureField::Contact => {
            "Points within twice the collision offset of another organ or a part \
                 (receptacle, stamens, pistil): 100 %; the contact area is their Voronoi area."
        }
    }
}

/// One unit of length's name and its curvatures' units, as static text
/// the legend keeps.
fn suffixes(unit: &str) -> (&'static str, &'static str) {
    if unit == "mm" {
        ("1/mm", "1/mm²")
    } else {
        ("1/unit", "1/unit²")
    }
}

/// The organs' measures at one frame: per organ of `organs` (positions
/// and the template mesh they are on), against `bud` (the same organs at
/// keyframe 0, `None` where its mesh differs: no stretch there), in
/// contact with each other and the parts of `flower` at `time` within
/// `distance`.
fn measure_organs(
    organs: &[(&[DVec3], &Mesh)],
    bud: &[Option<&[DVec3]>],
    flower: &anthesis_flower::Flower,
    time: f64,
    distance: f64,
) -> Vec<OrganMeasure> {
    let pieces: Vec<anthesis_render::OrganMesh> = crate::parts::part_meshes(flower, time);
    let parts: Vec<(Vec<DVec3>, Vec<[u32; 3]>)> = pieces
        .iter()
        .map(|p| {
            (
                p.positions_in_world
                    .iter()
                    .map(|q| DVec3::from_array(q.map(f64::from)))
                    .collect(),
                p.triangles.clone(),
            )
        })
        .collect();
    let surfaces: Vec<engine::Surface<'_>> = parts
        .iter()
        .map(|(x, t)| (x.as_slice(), t.as_slice()))
        .collect();
    let layouts: Vec<OrganLayout> = organs.iter().map(|(_, m)| OrganLayout::new(m)).collect();
    let now: Vec<Vec<DVec3>> = organs.iter().map(|(x, _)| x.to_vec()).collect();
    let buds: Vec<Vec<DVec3>> = bud
        .iter()
        .zip(&now)
        .map(|(b, x)| b.unwrap_or(x).to_vec())
        .collect();
    let mut measures = engine::measure_keyframe(&layouts, &buds, &now, &surfaces, distance);
    for (m, b) in measures.iter_mut().zip(bud) {
        if b.is_none() {
            m.vertex_stretches
                .iter_mut()
                .for_each(|s| *s = [f64::NAN; 2]);
            m.summary.stretch_major_mean = f64::NAN;
            m.summary.stretch_minor_mean = f64::NAN;
        }
    }
    measures
}

/// The field `field` on the scene of `input`.
pub(crate) fn measure_field(field: MeasureField, input: &FieldInput<'_>) -> FieldShown {
    let session = input.session;
    let simulated: Vec<&SceneOrgan> = input.scene.iter().filter(|o| o.simulated).collect();
    if simulated.is_empty() {
        return FieldShown::Nothing("No simulated organ is shown yet.".to_string());
    }
    let bud = session.shown_at(0.0);
    let meshes: Vec<Mesh> = simulated
        .iter()
        .map(|o| Mesh {
            positions: o.positions_in_world.clone(),
            uvs: o.uvs.clone(),
            triangles: o.triangles.clone(),
        })
        .collect();
    let organs: Vec<(&[DVec3], &Mesh)> = simulated
        .iter()
        .zip(&meshes)
        .map(|(o, m)| (o.positions_in_world.as_slice(), m))
        .collect();
    let buds: Vec<Option<&[DVec3]>> = simulated
        .iter()
        .map(|o| {
            let slot = session.organs().iter().position(|&i| i == o.organ)?;
            let positions = bud.as_ref()?.positions.get(slot)?;
            (positions.len() == o.positions_in_world.len()).then_some(positions.as_slice())
        })
        .collect();
    let distance = engine::default_contact_distance(input.project.settings.collision_offset);
    let measures = measure_organs(
        &organs,
        &buds,
        &input.project.flower,
        input.time_in_keyframes,
        distance,
    );
    let (scale, unit) = real_scale(input.project.flower.unit);
    let (per_length, per_area) = suffixes(unit);
    let mut by_organ: HashMap<usize, Vec<f64>> = HashMap::new();
    for (o, m) in simulated.iter().zip(&measures) {
        let values = match field {
            MeasureField::MeanCurvature => m.mean_curvature.iter().map(|h| h / scale).collect(),
            MeasureField::GaussianCurvature => m
                .gaussian_curvature
                .iter()
                .map(|k| k / (scale * scale))
                .collect(),
            MeasureField::StretchMajor => m.vertex_stretches.iter().map(|s| s[0]).collect(),
            MeasureField::StretchMinor => m.vertex_stretches.iter().map(|s| s[1]).collect(),
            MeasureField::Contact => m
                .contact
                .iter()
                .map(|&c| if c { 100.0 } else { 0.0 })
                .collect(),
        };
        by_organ.insert(o.organ, values);
    }
    let values: Vec<Option<Vec<f64>>> = input
        .scene
        .iter()
        .map(|o| {
            o.simulated
                .then(|| by_organ.get(&o.organ).cloned())
                .flatten()
        })
        .collect();
    let quantity = match field {
        MeasureField::MeanCurvature => Quantity::Plain(per_length),
        MeasureField::GaussianCurvature => Quantity::Plain(per_area),
        MeasureField::StretchMajor | MeasureField::StretchMinor => Quantity::Plain("×"),
        MeasureField::Contact => Quantity::Plain("%"),
    };
    let mut notes = vec![explain(field).to_string()];
    if buds.iter().any(Option::is_none)
        && matches!(
            field,
            MeasureField::StretchMajor | MeasureField::StretchMinor
        )
    {
        notes.push(
            "The bud shown is on other meshes than this frame (the quick preview): no stretch \
             until the run's frames replace it."
                .to_string(),
        );
    }
    let mut shown = ScalarField {
        name: field.label().to_string(),
        quantity,
        range: [0.0, 1.0],
        values,
        notes,
    };
    shown.range = range(field, &shown);
    FieldShown::Field(shown)
}

/// The ramp's range: curvatures symmetric about 0 up to the 95th
/// percentile of their size (a few sharp points do not wash out the rest),
/// stretches their smallest to largest, contact 0 to 100 %.
fn range(field: MeasureField, shown: &ScalarField) -> [f64; 2] {
    match field {
        MeasureField::MeanCurvature | MeasureField::GaussianCurvature => {
            let mut sizes: Vec<f64> = shown
                .values
                .iter()
                .flatten()
                .flatten()
                .filter(|v| v.is_finite())
                .map(|v| v.abs())
                .collect();
            sizes.sort_unstable_by(f64::total_cmp);
            let top = sizes
                .get((sizes.len() as f64 * 0.95) as usize)
                .or(sizes.last())
                .copied()
                .unwrap_or(0.0);
            [-top, top]
        }
        MeasureField::StretchMajor | MeasureField::StretchMinor => [
            shown.min().unwrap_or(1.0).min(1.0),
            shown.max().unwrap_or(1.0).max(1.0),
        ],
        MeasureField::Contact => [0.0, 100.0],
    }
}

/// The summaries of the simulated organs (by project organ index) per
/// (frame serial, bud serial): each frame is measured once.
type Kept = HashMap<(u64, u64), HashMap<usize, Summary>>;

/// The window's state, kept in egui's memory.
#[derive(Clone)]
struct PanelState {
    open: bool,
    /// Index into the project's organs.
    organ: Option<usize>,
    /// Index into [`QUANTITIES`].
    quantity: usize,
    /// The summaries measured so far.
    summaries: Arc<Mutex<Kept>>,
}

impl Default for PanelState {
    fn default() -> Self {
        PanelState {
            open: false,
            organ: None,
            quantity: 7, // midrib_length
            summaries: Arc::default(),
        }
    }
}

fn state_id() -> egui::Id {
    egui::Id::unique("measure panel")
}

fn state(ctx: &egui::Context) -> PanelState {
    ctx.data(|d| d.get_temp::<PanelState>(state_id()))
        .unwrap_or_default()
}

/// The View menu's entry that opens the window.
pub(crate) fn menu_entry(ui: &mut egui::Ui) {
    if ui.button("Measurements…").clicked() {
        let mut s = state(ui.ctx());
        s.open = true;
        ui.ctx().data_mut(|d| d.insert_temp(state_id(), s));
    }
}

/// Frames measured per window frame at most: the rest next frame.
const FRAMES_PER_PAINT: usize = 25;

/// The summaries of frame `index` of `session` (keyed by the frames'
/// serials), measured now when not yet kept; `None` when there is no
/// such frame yet.
fn summaries_at(
    session: &SimSession,
    index: u32,
    distance: f64,
    kept: &mut Kept,
    budget: &mut usize,
) -> Option<HashMap<usize, Summary>> {
    let (serial, _) = session.frames_at(f64::from(index))?;
    let (bud_serial, _) = session.frames_at(0.0)?;
    if let Some(found) = kept.get(&(serial, bud_serial)) {
        return Some(found.clone());
    }
    if *budget == 0 {
        return None;
    }
    *budget -= 1;
    let shown = session.shown_at(f64::from(index))?;
    let bud = session.shown_at(0.0)?;
    let flower = &shown.meshes.flower;
    let mut organs = Vec::new();
    let mut buds = Vec::new();
    let mut which = Vec::new();
    for (slot, &organ) in session.organs().iter().enumerate() {
        let (Some(positions), Some(template)) = (
            shown.positions.get(slot),
            flower.organs.get(organ).map(|_| flower.template_of(organ)),
        ) else {
            continue;
        };
        if positions.len() != template.mesh.vertex_count() {
            continue;
        }
        organs.push((positions.as_slice(), &template.mesh));
        buds.push(
            bud.positions
                .get(slot)
                .filter(|b| b.len() == positions.len())
                .map(Vec::as_slice),
        );
        which.push(organ);
    }
    let measures = measure_organs(&organs, &buds, flower, f64::from(index), distance);
    let found: HashMap<usize, Summary> = which
        .into_iter()
        .zip(measures)
        .map(|(organ, m)| (organ, m.summary))
        .collect();
    if kept.len() > 20_000 {
        kept.clear();
    }
    kept.insert((serial, bud_serial), found.clone());
    Some(found)
}

/// A value to four significant digits.
fn significant(value: f64) -> String {
    if !value.is_finite() {
        return "none".to_string();
    }
    format!("{value:.4e}")
        .parse::<f64>()
        .map_or_else(|_| value.to_string(), |v| v.to_string())
}

impl AnthesisApp {
    /// The Measurements window, when open.
    pub(crate) fn measure_window(&mut self, ctx: &egui::Context) {
        let mut s = state(ctx);
        if !s.open {
            return;
        }
        let mut open = true;
        let mut view = self.view;
        let project = self.doc.project();
        let (scale, unit) = real_scale(project.flower.unit);
        let distance = engine::default_contact_distance(project.settings.collision_offset);
        let names: Vec<(usize, String)> = self
            .session
            .organs()
            .iter()
            .filter_map(|&i| project.flower.organs.get(i).map(|o| (i, o.name.clone())))
            .collect();
        let organ = s
            .organ
            .filter(|o| names.iter().any(|(i, _)| i == o))
            .or_else(|| names.first().map(|(i, _)| *i));
        let viewed = self.playback.time_in_keyframes;
        let mut more = false;
        egui::Window::new("Measurements")
            .open(&mut open)
            .default_width(420.0)
            .show(ctx, |ui| {
                ui.label("Colour the organs by:");
                ui.horizontal_wrapped(|ui| {
                    let none = !matches!(view.field, Some(ViewField::Measure(_)));
                    if ui.selectable_label(none, "nothing").clicked() && !none {
                        view.field = None;
                    }
                    for field in MeasureField::ALL {
                        let chosen = Some(ViewField::Measure(field));
                        ui.radio_value(&mut view.field, chosen, field.label());
                    }
                });
                ui.separator();
                ui.horizontal(|ui| {
                    let organ_name = organ
                        .and_then(|o| names.iter().find(|(i, _)| *i == o))
                        .map_or("none", |(_, n)| n.as_str());
                    egui::ComboBox::from_label("organ")
                        .selected_text(organ_name)
                        .show_ui(ui, |ui| {
                            for (i, name) in &names {
                                ui.selectable_value(&mut s.organ, Some(*i), name.as_str());
                            }
                        });
                    egui::ComboBox::from_label("over time")
                        .selected_text(QUANTITIES[s.quantity.min(QUANTITIES.len() - 1)].label)
                        .show_ui(ui, |ui| {
                            for (k, q) in QUANTITIES.iter().enumerate() {
                                ui.selectable_value(&mut s.quantity, k, q.label);
                            }
                        });
                });
                let Some(organ) = organ else {
                    ui.label("No simulated organ yet.");
                    return;
                };
                let quantity = QUANTITIES[s.quantity.min(QUANTITIES.len() - 1)];
                let end = self.session.shown_end().unwrap_or(0);
                let mut budget = FRAMES_PER_PAINT;
                let series: Vec<(u32, f64)> = {
                    let mut kept = s
                        .summaries
                        .lock()
                        .unwrap_or_else(std::sync::PoisonError::into_inner);
                    (0..=end)
                        .filter_map(|k| {
                            let found =
                                summaries_at(&self.session, k, distance, &mut kept, &mut budget);
                            more |= found.is_none() && budget == 0;
                            let summary = found?.get(&organ).copied()?;
                            Some((k, quantity.value(&summary, scale)))
                        })
                        .collect()
                };
                let unit_text = quantity.unit(unit);
                ui.label(format!(
                    "{} ({unit_text}) over the keyframes",
                    quantity.label
                ));
                plot(ui, &series, end, viewed);
                let at = viewed.round().max(0.0) as u32;
                match series.iter().find(|(k, _)| *k == at) {
                    Some((_, value)) => ui.label(format!(
                        "{} at keyframe {at}: {} {unit_text}",
                        quantity.name,
                        significant(*value)
                    )),
                    None => ui.label(format!("keyframe {at} is not measured yet")),
                };
                ui.small(
                    "The columns of `anthesis measure`; lengths in mm when the project states \
                     its unit.",
                );
            });
        s.open = open;
        ctx.data_mut(|d| d.insert_temp(state_id(), s));
        if more {
            ctx.request_repaint();
        }
        if view != self.view {
            self.queued.push(Command::SetView(view));
        }
    }
}

/// `series` (keyframe, value) over keyframes 0 to `end` as a line, its
/// range written at the left, the keyframe `viewed` marked.
fn plot(ui: &mut egui::Ui, series: &[(u32, f64)], end: u32, viewed: f64) {
    let width = ui.available_width().clamp(160.0, 560.0);
    let (response, painter) = ui.allocate_painter(egui::vec2(width, 140.0), egui::Sense::hover());
    let visuals = ui.visuals();
    painter.rect_filled(response.rect, 2.0, visuals.extreme_bg_color);
    let rect = response.rect.shrink2(egui::vec2(6.0, 14.0));
    let finite = series.iter().map(|(_, v)| *v).filter(|v| v.is_finite());
    let low = finite.clone().fold(f64::INFINITY, f64::min);
    let high = finite.fold(f64::NEG_INFINITY, f64::max);
    let last = f64::from(end.max(1));
    let x_of = |k: f64| rect.left() + rect.width() * (k / last).clamp(0.0, 1.0) as f32;
    let marker = Stroke::new(1.5, visuals.strong_text_color());
    painter.vline(x_of(viewed), rect.y_range(), marker);
    if !(low.is_finite() && high.is_finite()) {
        return;
    }
    let span = if high > low { high - low } else { 1.0 };
    let y_of = |v: f64| rect.bottom() - rect.height() * ((v - low) / span) as f32;
    let axis = Stroke::new(1.0, visuals.weak_text_color());
    painter.hline(rect.x_range(), y_of(low), axis);
    painter.hline(rect.x_range(), y_of(high), axis);
    let font = egui::FontId::proportional(11.0);
    let text = visuals.text_color();
    painter.text(
        egui::pos2(rect.left(), y_of(high) - 2.0),
        egui::Align2::LEFT_BOTTOM,
        significant(high),
        font.clone(),
        text,
    );
    painter.text(
        egui::pos2(rect.left(), y_of(low) + 2.0),
        egui::Align2::LEFT_TOP,
        significant(low),
        font,
        text,
    );
    let points: Vec<egui::Pos2> = series
        .iter()
        .filter(|(_, v)| v.is_finite())
        .map(|&(k, v)| egui::pos2(x_of(f64::from(k)), y_of(v)))
        .collect();
    painter.add(egui::Shape::line(
        points,
        Stroke::new(2.0, egui::Color32::from_rgb(220, 120, 40)),
    ));
    response.on_hover_text(format!(
        "Keyframes 0 to {end} across; the bold line marks the keyframe shown."
    ));
}

//! The Flower panel's "Sketched bud" section (issue 14 item 7,
//! the floral blossom paper §3.2): the user draws one curved
//! stroke in a side view of the flower (the axis up the middle, the
//! receptacle's height as the ground line), the initial primary vein of a
//! petal; the bud is the chosen template bent along it and instanced on a
//! golden-angle spiral or where the arrangement puts the template's organs
//! ([`anthesis_flower::sketched_bud`]).
//!
//! The result is worked out when the stroke is finished and shown before
//! it is applied: the smoothed vein, a top view of the petals' azimuths,
//! the nesting step, and which organs would cross (then Apply is not
//! offered). Applying is one undo step.

use anthesis_bud::SideStroke;
use anthesis_flower::Flower;
use anthesis_flower::sketched_bud::{BudPlacement, SketchedBud};
use eframe::egui::{self, Color32, RichText};
use glam::DVec2;

use super::command::{Command, ProjectEdit};
use super::sketch_panel::{canvas_height, in_room, large_button};

/// The shortest stroke accepted, as a fraction of the view's height.
const SHORTEST_STROKE: f64 = 0.05;

/// The section's state.
#[derive(Debug)]
pub struct BudSketchState {
    /// The template whose bud is drawn.
    template: usize,
    /// The stroke as drawn, side-view points `(r, h)`.
    stroke: Vec<DVec2>,
    /// A golden-angle spiral (else: where the arrangement puts the organs).
    spiral: bool,
    /// Petals on the spiral.
    count: usize,
    /// The stroke is the opened flower's vein (§3.2), not the bud's.
    opening: bool,
    /// What the finished stroke makes, and what it was made of.
    result: Option<(Key, Result<Made, String>)>,
    /// The view's side-view rectangle and its screen rectangle, last frame.
    view: Option<(Frame, egui::Rect)>,
    /// The section is in the large canvas (a window over the viewport).
    large: bool,
}

/// What a result was made of: template, spiral, count, opening, flower.
type Key = (usize, bool, usize, bool, usize);

/// What a finished stroke makes.
#[derive(Debug)]
enum Made {
    /// A bud.
    Bud(SketchedBud),
    /// The flower opening to the stroke, and which organs cross when open.
    Opening(Flower, Option<(String, String)>),
}

/// How the side view maps to the screen.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Frame {
    centre: DVec2,
    /// Screen pixels per project unit.
    scale: f64,
}

impl Default for BudSketchState {
    fn default() -> Self {
        BudSketchState {
            template: 0,
            stroke: Vec::new(),
            spiral: true,
            count: 5,
            opening: false,
            result: None,
            view: None,
            large: false,
        }
    }
}

impl BudSketchState {
    /// Whether the section is open in the large canvas.
    pub fn large(&self) -> bool {
        self.large
    }

    /// Where side-view point `(r, h)` was drawn in the last frame.
    pub fn on_screen(&self, side: DVec2) -> Option<egui::Pos2> {
        let (frame, rect) = self.view?;
        Some(frame.to_screen(rect, side))
    }

    /// Why the stroke makes no bud, or which organs cross, as shown.
    pub fn problem(&self) -> Option<String> {
        match &self.result {
            Some((_, Err(e))) => Some(e.clone()),
            Some((_, Ok(Made::Bud(bud)))) => bud.crossing.as_ref().map(crossing_text),
            Some((_, Ok(Made::Opening(_, crossing)))) => crossing.as_ref().map(crossing_text),
            None => None,
        }
    }

    /// The bud the stroke makes, when it makes one.
    pub fn bud(&self) -> Option<&SketchedBud> {
        match &self.result {
            Some((_, Ok(Made::Bud(bud)))) => Some(bud),
            _ => None,
        }
    }

    /// The flower opening to the stroke's shape, when the stroke is the
    /// opened flower's and makes one.
    pub fn opening(&self) -> Option<&Flower> {
        match &self.result {
            Some((_, Ok(Made::Opening(flower, _)))) => Some(flower),
            _ => None,
        }
    }
}

impl Frame {
    fn to_screen(self, rect: egui::Rect, p: DVec2) -> egui::Pos2 {
        let q = (p - self.centre) * self.scale;
        egui::pos2(rect.center().x + q.x as f32, rect.center().y - q.y as f32)
    }

    fn to_side(self, rect: egui::Rect, p: egui::Pos2) -> DVec2 {
        let q = DVec2::new(
            f64::from(p.x - rect.center().x),
            f64::from(rect.center().y - p.y),
        );
        self.centre + q / self.scale
    }
}

fn crossing_text((a, b): &(String, String)) -> String {
    if a == b {
        format!("{a} would cross itself: draw the stroke with gentler bends")
    } else {
        format!(
            "{a} and {b} would cross in this bud: start the stroke further from the axis, use \
             fewer petals, or narrower ones"
        )
    }
}

/// A fingerprint of the flower (a result made of another one is stale).
fn fingerprint(flower: &Flower) -> usize {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for t in &flower.templates {
        t.name.hash(&mut h);
        for p in &t.mesh.positions {
            p.to_array().map(f64::to_bits).hash(&mut h);
        }
    }
    for o in &flower.organs {
        o.name.hash(&mut h);
        o.placement
            .position
            .to_array()
            .map(f64::to_bits)
            .hash(&mut h);
    }
    h.finish() as usize
}

/// Where the template's first organ has its base, `(r, h)`.
fn first_base(flower: &Flower, template: usize) -> Option<DVec2> {
    flower
        .organs
        .iter()
        .find(|o| o.template == template)
        .map(|o| {
            let p = o.placement.position;
            DVec2::new(p.x.hypot(p.z), p.y)
        })
}

/// The side-view points `(r, h)` of the midrib (vertices near u = 0.5,
/// base to tip) of a template shape `positions` placed as `organ`.
fn side_midrib(
    positions: &[glam::DVec3],
    uvs: &[DVec2],
    organ: &anthesis_flower::Organ,
) -> Vec<DVec2> {
    let mut midrib: Vec<(f64, DVec2)> = positions
        .iter()
        .zip(uvs)
        .filter(|(_, uv)| (uv.x - 0.5).abs() < 0.02)
        .map(|(p, uv)| {
            let w = organ.placement.world_from_template(*p, 0.0);
            (uv.y, DVec2::new(w.x.hypot(w.z), w.y))
        })
        .collect();
    midrib.sort_by(|a, b| a.0.total_cmp(&b.0));
    midrib.into_iter().map(|(_, p)| p).collect()
}

/// The section; pushes the edit chosen onto `commands`.
pub fn bud_sketch_ui(
    ui: &mut egui::Ui,
    (flower, keyframes): (&Flower, u32),
    state: &mut BudSketchState,
    commands: &mut Vec<Command>,
) {
    if flower.templates.is_empty() {
        return;
    }
    egui::CollapsingHeader::new("Sketched bud")
        .id_salt("sketched bud")
        .show(ui, |ui| {
            let large = state.large;
            if !in_room(ui, "Sketched bud", large, |ui| {
                rows(ui, (flower, keyframes), state, commands, large);
            }) {
                state.large = false;
            }
        })
        .header_response
        .on_hover_text(
            "Draw one curved stroke in the side view: the primary vein of a petal in the bud. \
             The template is bent along it and its petals are placed around the axis on copies \
             of it.",
        );
}

fn rows(
    ui: &mut egui::Ui,
    (flower, keyframes): (&Flower, u32),
    state: &mut BudSketchState,
    commands: &mut Vec<Command>,
    large: bool,
) {
    state.template = state.template.min(flower.templates.len() - 1);
    let index = state.template;
    large_button(ui, "Large bud canvas", &mut state.large);
    option_rows(ui, flower, index, state);

    // The view: the axis up the middle, the ground at the receptacle.
    let template = &flower.templates[index];
    let length = template
        .vein
        .as_ref()
        .map(|v| v.length())
        .unwrap_or_else(|| {
            template
                .mesh
                .positions
                .iter()
                .map(|p| p.y)
                .fold(0.0, f64::max)
        })
        .max(1.0);
    let base = first_base(flower, index).unwrap_or(DVec2::ZERO);
    // The axis a fifth of the way in from the left, the ground near the
    // bottom: room for a petal leaning out or curving in.
    let extent = 1.15 * length.max(base.x + 0.6 * length);
    // In the large canvas, the rows under the view (the top view, the
    // petal count, Apply) keep about this much room.
    let size = if large {
        egui::vec2(
            ui.available_width().max(160.0),
            canvas_height(ui, 260.0, 220.0, true),
        )
    } else {
        egui::vec2(ui.available_width().clamp(160.0, 360.0), 260.0)
    };
    let (response, painter) = ui.allocate_painter(size, egui::Sense::drag());
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Canvas, true, "bud side view"));
    let rect = response.rect;
    let frame = Frame {
        centre: DVec2::new(0.4 * extent, base.y + 0.45 * extent),
        scale: (f64::from(rect.height()) / (1.1 * extent))
            .min(f64::from(rect.width()) / (1.25 * extent)),
    };
    state.view = Some((frame, rect));
    let to_screen = |p: DVec2| frame.to_screen(rect, p);
    painter.rect_filled(rect, 4.0, ui.visuals().extreme_bg_color);
    let faint = egui::Stroke::new(1.0, ui.visuals().weak_text_color());
    let axis_x = to_screen(DVec2::ZERO).x;
    painter.line_segment(
        [
            egui::pos2(axis_x, rect.top()),
            egui::pos2(axis_x, rect.bottom()),
        ],
        egui::Stroke::new(1.0, Color32::from_rgb(90, 140, 90)),
    );
    let ground = to_screen(DVec2::new(0.0, base.y)).y;
    painter.line_segment(
        [
            egui::pos2(rect.left(), ground),
            egui::pos2(rect.right(), ground),
        ],
        faint,
    );
    painter.text(
        rect.left_top() + egui::vec2(6.0, 4.0),
        egui::Align2::LEFT_TOP,
        "side view: axis, ground; draw a petal's vein",
        egui::FontId::proportional(11.0),
        ui.visuals().weak_text_color(),
    );
    // The template's midrib as it is now, at its first organ, for scale.
    if let Some(organ) = flower.organs.iter().find(|o| o.template == index) {
        let points = side_midrib(&template.mesh.positions, &template.mesh.uvs, organ);
        painter.add(egui::Shape::line(
            points.into_iter().map(to_screen).collect(),
            faint,
        ));
    }

    track_stroke(state, &response, frame, rect);
    let drawn: Vec<egui::Pos2> = state.stroke.iter().map(|p| to_screen(*p)).collect();
    painter.add(egui::Shape::line(
        drawn,
        egui::Stroke::new(1.5, ui.visuals().strong_text_color()),
    ));

    make_from_stroke(
        state,
        (flower, keyframes),
        index,
        extent,
        response.dragged(),
    );
    draw_results(ui, &painter, (frame, rect), index, state);
    apply_row(ui, flower, index, state, commands);
}

/// The stroke being drawn on the side view: a press starts a new one (and
/// forgets the last result), a drag adds points at least 1.5 px apart.
fn track_stroke(
    state: &mut BudSketchState,
    response: &egui::Response,
    frame: Frame,
    rect: egui::Rect,
) {
    if response.drag_started() {
        state.stroke.clear();
        state.result = None;
        if let Some(p) = response.interact_pointer_pos() {
            state.stroke.push(frame.to_side(rect, p));
        }
    }
    if response.dragged()
        && let Some(p) = response.interact_pointer_pos()
    {
        let q = frame.to_side(rect, p);
        if state
            .stroke
            .last()
            .is_none_or(|last| last.distance(q) * frame.scale > 1.5)
        {
            state.stroke.push(q);
        }
    }
}

/// The rows of what to draw: the bud or its opening, the spiral or the
/// arrangement's places (and how many petals), and a warning where an
/// L-system places the organs.
fn option_rows(ui: &mut egui::Ui, flower: &Flower, index: usize, state: &mut BudSketchState) {
    let others = flower.organs.iter().any(|o| o.template != index);
    ui.horizontal(|ui| {
        let label = ui.label("petal").id;
        egui::ComboBox::from_id_salt("bud template")
            .selected_text(flower.templates[index].name.as_str())
            .show_ui(ui, |ui| {
                for (i, t) in flower.templates.iter().enumerate() {
                    ui.selectable_value(&mut state.template, i, t.name.as_str());
                }
            })
            .response
            .labelled_by(label);
    });
    let has_bud = flower.templates[index].vein.is_some();
    ui.horizontal_wrapped(|ui| {
        let label = ui.label("draw").id;
        ui.radio_value(&mut state.opening, false, "the bud")
            .labelled_by(label)
            .on_hover_text("The stroke is a petal's vein in the bud");
        ui.add_enabled_ui(has_bud, |ui| {
            ui.radio_value(&mut state.opening, true, "the opened flower")
                .on_hover_text(
                    "The stroke is a petal's vein in the open flower: the petals then open \
                     from the bud to it by the two-state blossom instead of growing",
                )
                .on_disabled_hover_text("Sketch and apply the bud first");
        });
    });
    if !has_bud {
        state.opening = false;
    }
    ui.horizontal_wrapped(|ui| {
        ui.add_enabled_ui(!others && !state.opening, |ui| {
            ui.radio_value(&mut state.spiral, true, "golden-angle spiral")
                .on_hover_text("Petals 137.5° apart, each later one nested inside")
                .on_disabled_hover_text(
                    "The flower has organs of other templates, which a spiral would replace",
                );
        });
        ui.radio_value(&mut state.spiral, false, "the arrangement's places")
            .on_hover_text("Where the flower's arrangement puts this template's organs");
    });
    if others {
        state.spiral = false;
    }
    let turtle_placed = matches!(
        flower.structure,
        Some(anthesis_flower::structure::Structure::LSystem { .. })
    ) && flower.organs[..flower.made_organ_count()]
        .iter()
        .any(|o| o.template == index);
    if turtle_placed && !state.spiral {
        ui.label(
            RichText::new(
                "The L-system places these organs in its turtle's frames: the stroke bends the \
                 petal as seen in its own frame (its base at the stroke's start) and does not \
                 move the organs.",
            )
            .color(ui.visuals().warn_fg_color),
        );
    }
    if state.spiral && !state.opening {
        ui.horizontal(|ui| {
            let label = ui.label("petals").id;
            super::checked_field::checked_with(ui, "petals", &mut state.count, 1..=40, |d| d)
                .labelled_by(label);
        });
    }
}

/// Makes the bud or the opening the stroke asks for, once the stroke is
/// drawn (not while `dragging`) and when it or what it depends on changed.
fn make_from_stroke(
    state: &mut BudSketchState,
    (flower, keyframes): (&Flower, u32),
    index: usize,
    extent: f64,
    dragging: bool,
) {
    // What the stroke makes.
    let key = (
        index,
        state.spiral,
        state.count,
        state.opening,
        fingerprint(flower),
    );
    let stale = state.result.as_ref().is_none_or(|(k, _)| *k != key);
    if !dragging && state.stroke.len() > 1 && stale {
        let minimum = SHORTEST_STROKE * 1.1 * extent;
        let result = SideStroke::new(&state.stroke, minimum)
            .map_err(|e| e.to_string())
            .and_then(|stroke| {
                if state.opening {
                    return flower
                        .with_sketched_opening(index, &stroke.vein, keyframes)
                        .map(|(flower, crossing)| Made::Opening(flower, crossing))
                        .map_err(|e| e.to_string());
                }
                let placement = if state.spiral {
                    BudPlacement::GoldenSpiral { count: state.count }
                } else {
                    BudPlacement::Arrangement
                };
                flower
                    .with_sketched_bud(index, &stroke, placement)
                    .map(Made::Bud)
                    .map_err(|e| e.to_string())
            });
        state.result = Some((key, result));
    }
}

/// What the stroke made, over the side view: the open shape's midrib or
/// the smoothed vein, the bud's top view and its petal count.
fn draw_results(
    ui: &mut egui::Ui,
    painter: &egui::Painter,
    (frame, rect): (Frame, egui::Rect),
    index: usize,
    state: &BudSketchState,
) {
    let to_screen = |p: DVec2| frame.to_screen(rect, p);
    if let Some(opened) = state.opening() {
        // The open shape's midrib from the organ's base.
        if let (Some(organ), Some(animation)) = (
            opened.organs.iter().find(|o| o.template == index),
            &opened.templates[index].two_state,
        ) {
            let points = side_midrib(&animation.open, &opened.templates[index].mesh.uvs, organ);
            painter.add(egui::Shape::line(
                points.into_iter().map(to_screen).collect(),
                egui::Stroke::new(2.5, Color32::from_rgb(255, 170, 40)),
            ));
        }
    }
    if let Some((_, Ok(Made::Bud(bud)))) = &state.result {
        if let Some(vein) = &bud.flower.templates[index].vein {
            // The vein as it will be: smoothed, from the base.
            if let Some(base) = first_base(&bud.flower, index) {
                let points = vein
                    .points()
                    .iter()
                    .map(|p| to_screen(base + DVec2::new(p.y, p.x)))
                    .collect();
                painter.add(egui::Shape::line(
                    points,
                    egui::Stroke::new(2.5, Color32::from_rgb(255, 170, 40)),
                ));
            }
        }
        top_view(ui, &bud.flower, index);
        ui.label(format!(
            "{} petals{}",
            bud.flower
                .organs
                .iter()
                .filter(|o| o.template == index)
                .count(),
            if bud.radius_step > 0.0 {
                format!(
                    ", each later one {:.2} further in and lower",
                    bud.radius_step
                )
            } else {
                String::new()
            }
        ));
    }
}

/// Why nothing was made, or "Apply opening" / "Apply bud" (one undo step
/// each) when what was made has no crossing.
fn apply_row(
    ui: &mut egui::Ui,
    flower: &Flower,
    index: usize,
    state: &BudSketchState,
    commands: &mut Vec<Command>,
) {
    if let Some(problem) = state.problem() {
        ui.label(RichText::new(problem).color(ui.visuals().error_fg_color));
    }
    if state.opening {
        let crossing = matches!(&state.result, Some((_, Ok(Made::Opening(_, Some(_))))));
        let ready = state.opening().filter(|_| !crossing);
        let apply = ui
            .add_enabled(ready.is_some(), egui::Button::new("Apply opening"))
            .on_hover_text(
                "The petals open from the bud to the stroke's shape by the two-state blossom \
                 over the project's keyframes (one undo step)",
            )
            .on_disabled_hover_text("Draw a stroke whose open petals do not cross");
        if apply.clicked()
            && let Some(opened) = ready
        {
            commands.push(Command::Edit {
                label: format!("sketched opening of {}", flower.templates[index].name),
                edit: ProjectEdit::Flower(Box::new(opened.clone())),
            });
        }
        return;
    }
    let ready = state.bud().filter(|b| b.crossing.is_none());
    let apply = ui
        .add_enabled(ready.is_some(), egui::Button::new("Apply bud"))
        .on_hover_text("Bend the template along the stroke and place its petals (one undo step)")
        .on_disabled_hover_text("Draw a stroke that makes a bud whose petals do not cross");
    if apply.clicked()
        && let Some(bud) = ready
    {
        commands.push(Command::Edit {
            label: format!("sketched bud of {}", flower.templates[index].name),
            edit: ProjectEdit::Flower(Box::new(bud.flower.clone())),
        });
    }
}

/// A small view from above: the axis and each organ of the template as a
/// line from its base outwards at its azimuth.
fn top_view(ui: &mut egui::Ui, flower: &Flower, template: usize) {
    let organs: Vec<_> = flower
        .organs
        .iter()
        .filter(|o| o.template == template)
        .collect();
    let (response, painter) = ui.allocate_painter(egui::vec2(120.0, 120.0), egui::Sense::hover());
    let rect = response.rect;
    painter.rect_filled(rect, 4.0, ui.visuals().extreme_bg_color);
    let reach = flower.templates[template]
        .mesh
        .positions
        .iter()
        .map(|p| p.z.max(0.0))
        .fold(0.0, f64::max);
    let outer = organs
        .iter()
        .map(|o| o.placement.position.x.hypot(o.placement.position.z))
        .fold(0.0, f64::max)
        + reach
        + 1e-6;
    let scale = 0.45 * f64::from(rect.width()) / outer;
    let at = |x: f64, z: f64| rect.center() + egui::vec2((x * scale) as f32, (z * scale) as f32);
    painter.circle_filled(rect.center(), 2.0, Color32::from_rgb(90, 140, 90));
    for (k, o) in organs.iter().enumerate() {
        let a = o.placement.azimuth_deg.to_radians();
        let r = o.placement.position.x.hypot(o.placement.position.z);
        let from = at(r * a.sin(), r * a.cos());
        let to = at(
            (r + reach.max(0.2 * outer)) * a.sin(),
            (r + reach.max(0.2 * outer)) * a.cos(),
        );
        let shade = 255 - (150 * k / organs.len().max(1)) as u8;
        painter.line_segment(
            [from, to],
            egui::Stroke::new(2.0, Color32::from_rgb(shade, 120, 160)),
        );
    }
}

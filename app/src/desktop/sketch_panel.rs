//! The Shape section's sketched petal editor
//! (the floral blossom paper §3.1, `anthesis_bud::PetalSketch`):
//! a canvas in the base plane where the two outline strokes, the vein and
//! cross-sections are drawn with the mouse, the B-spline surface's control
//! net and outline drawn live over them, a side view of the bent rows, the
//! particle count and mesh quality of the petal at the section's edge, and
//! Apply, which replaces the template's mesh and keeps its strokes in one
//! undo step (the maps stay: they live in UV space).
//!
//! A template made with "New sketched petal" starts from
//! [`PetalSketch::petal`]; any other template can get a sketched shape
//! ("Sketch a new shape"), which starts from an empty canvas with the
//! template's mesh shown faintly behind it.

use std::collections::BTreeMap;

use anthesis_bud::{
    Bud, MeshQuality, PetalSketch, RemeshOptions, SketchError, SketchTool, SketchedPetal, Surface,
};
use anthesis_flower::{Flower, TemplateSource};
use eframe::egui::{self, Color32, Pos2, RichText, Stroke};
use glam::{DVec2, DVec3};

use super::background::Background;
use super::command::{Command, ProjectEdit};
use super::widgets::quality_text;

/// The canvas's height, in points.
const CANVAS_HEIGHT: f32 = 300.0;
/// The side view's height, in points.
const SIDE_HEIGHT: f32 = 110.0;
/// What the canvas shows at least: the simple petal's size around the
/// base (x from −12 to 12, y from −2 to 24).
const DEFAULT_VIEW: [DVec2; 2] = [DVec2::new(-12.0, -2.0), DVec2::new(12.0, 24.0)];
/// A drawn stroke keeps a pointer position this far (points) from the last.
const MIN_SPACING: f32 = 2.0;
/// The preview is not computed past this many particles (Apply still
/// meshes it).
const PREVIEW_MAX_VERTICES: usize = 50_000;

/// The tools, with their labels.
const TOOLS: [(SketchTool, &str, &str); 5] = [
    (
        SketchTool::Auto,
        "auto roles",
        "The first three strokes are the outline and the vein (any order, any direction); then \
         a stroke across the petal is a cross-section and one along it replaces the nearest \
         outline stroke or the vein",
    ),
    (
        SketchTool::LeftOutline,
        "left outline",
        "Redraw the left margin",
    ),
    (
        SketchTool::RightOutline,
        "right outline",
        "Redraw the right margin",
    ),
    (
        SketchTool::Vein,
        "primary vein",
        "Redraw the primary vein (the midrib)",
    ),
    (
        SketchTool::CrossSection,
        "cross-section",
        "Draw across the petal from margin to margin: the row of control points nearest its \
         start bends like the stroke (a stroke sagging towards the base cups the petal)",
    ),
];

/// A sketch being edited: the template's saved strokes it started from
/// (`None`: a new shape for a template that has none) and the strokes as
/// drawn since.
#[derive(Debug, Clone)]
struct Draft {
    saved: Option<PetalSketch>,
    sketch: PetalSketch,
    /// The sketches before each change, for "Undo stroke" (the last
    /// [`UNDO_STROKES`]).
    undo: Vec<PetalSketch>,
}

/// How many changes of a draft "Undo stroke" goes back.
const UNDO_STROKES: usize = 50;

/// The petal meshed for the preview.
type Preview = Background<Bud, String>;

/// The map from the sketch plane to the canvas.
#[derive(Debug, Clone, Copy, PartialEq)]
struct View {
    /// The canvas's centre on screen.
    centre_on_screen: Pos2,
    /// The sketch point there.
    centre: DVec2,
    /// Points per project unit.
    scale: f64,
}

impl View {
    fn to_screen(self, p: DVec2) -> Pos2 {
        let d = (p - self.centre) * self.scale;
        Pos2::new(
            self.centre_on_screen.x + d.x as f32,
            self.centre_on_screen.y - d.y as f32,
        )
    }

    fn to_sketch(self, at: Pos2) -> DVec2 {
        let d = at - self.centre_on_screen;
        self.centre + DVec2::new(f64::from(d.x), -f64::from(d.y)) / self.scale
    }
}

/// The sketch editor's state (in the Shape section's).
#[derive(Debug, Default)]
pub struct SketchState {
    /// The sketches being edited, by template name.
    drafts: BTreeMap<String, Draft>,
    /// What a new stroke is drawn as.
    tool: SketchTool,
    /// The stroke being drawn, in the sketch plane.
    drawing: Option<Vec<DVec2>>,
    /// The canvas's map while a stroke is drawn (the view does not move
    /// under the pointer) and as last drawn.
    view: Option<View>,
    /// The petal meshed at the section's edge (on a thread of its own), for
    /// the sketch and edge it was made of.
    preview: Option<(u64, Preview)>,
    /// Why Apply could not mesh the petal.
    apply_error: Option<String>,
    /// The editor is in the large canvas (a window over the viewport).
    large: bool,
    /// The canvas zoomed by Ctrl+wheel: times the fitted view, and the
    /// sketch point at its centre (`None`: fitted).
    zoom: Option<(f64, DVec2)>,
}

impl SketchState {
    /// The strokes being edited for template `name`, once shown.
    pub fn sketch(&self, name: &str) -> Option<&PetalSketch> {
        self.drafts.get(name).map(|d| &d.sketch)
    }

    /// Whether the editor is open in the large canvas.
    pub fn large(&self) -> bool {
        self.large
    }

    /// Where sketch-plane point `p` was on the canvas in the last frame.
    pub fn sketch_to_screen(&self, p: DVec2) -> Option<Pos2> {
        self.view.map(|v| v.to_screen(p))
    }

    /// The previewed mesh numbers, or why the sketch cannot be meshed;
    /// `None` while it is being meshed.
    pub fn preview(&self) -> Option<Result<&MeshQuality, &str>> {
        let answer = self.preview.as_ref().and_then(|(_, p)| p.answer())?;
        Some(
            answer
                .as_ref()
                .map(|bud| &bud.quality)
                .map_err(String::as_str),
        )
    }
}

/// A hash of the sketch and the edge: whether the preview was made of them.
fn key(sketch: &PetalSketch, edge: f64) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    let mut stroke = |s: &[DVec2]| {
        s.len().hash(&mut h);
        for p in s {
            p.to_array().map(f64::to_bits).hash(&mut h);
        }
    };
    stroke(&sketch.left);
    stroke(&sketch.right);
    stroke(&sketch.vein);
    for s in &sketch.sections {
        stroke(s);
    }
    edge.to_bits().hash(&mut h);
    h.finish()
}

/// A template of a new sketched petal (`PetalSketch::petal`, meshed at
/// `edge`) with the uniform maps of a simple petal.
pub fn new_sketched_template(edge: f64) -> Result<anthesis_flower::Template, String> {
    let sketch = PetalSketch::petal();
    let petal = sketch.build().map_err(|e| e.to_string())?;
    let bud = anthesis_bud::build_organ(&petal.surface, &RemeshOptions::new(edge))
        .map_err(|e| e.to_string())?;
    let mut template =
        anthesis_garden::five_petal::simple_template_of_mesh("sketched petal", bud.mesh);
    template.source = Some(TemplateSource::Sketch { sketch, edge });
    Ok(template)
}

/// The sketch editor for template `index`, meshing at `edge`; pushes Apply
/// onto `commands`.
pub fn sketch_ui(
    ui: &mut egui::Ui,
    (flower, index): (&Flower, usize),
    edge: f64,
    state: &mut SketchState,
    commands: &mut Vec<Command>,
) {
    let template = &flower.templates[index];
    let name = template.name.as_str();
    let saved = match &template.source {
        Some(TemplateSource::Sketch { sketch, .. }) => Some(sketch.clone()),
        _ => None,
    };
    sync_draft(state, name, &saved);
    if !state.drafts.contains_key(name) {
        if ui
            .button("Sketch a new shape")
            .on_hover_text(
                "Draw this template's petal on a canvas: two outline strokes and the primary \
                 vein, then cross-sections; Apply replaces its mesh (its maps stay)",
            )
            .clicked()
        {
            state.drafts.insert(
                name.to_string(),
                Draft {
                    saved: None,
                    sketch: PetalSketch::default(),
                    undo: Vec::new(),
                },
            );
        }
        state.view = None;
        return;
    }
    let large = state.large;
    if !in_room(ui, "Sketched petal", large, |ui| {
        editor(ui, (flower, index), edge, state, commands, large);
    }) {
        state.large = false;
    }
}

/// Shows `body` (an editor's rows) in the panel, or when `large` in a
/// resizable window over the viewport (the large canvas), with a line in
/// the panel that says so and brings it back; false when the window was
/// closed. The same `body` draws both: strokes follow the same rules.
pub(super) fn in_room(
    ui: &mut egui::Ui,
    title: &str,
    large: bool,
    body: impl FnOnce(&mut egui::Ui),
) -> bool {
    if !large {
        body(ui);
        return true;
    }
    let mut open = true;
    ui.horizontal_wrapped(|ui| {
        ui.label(format!("{title}: open in the large canvas."));
        if ui
            .button("Back to the panel")
            .on_hover_text("Close the large canvas and edit here again")
            .clicked()
        {
            open = false;
        }
    });
    if open {
        // Over the viewport, right of the left panel, as large as fits.
        let screen = ui.ctx().content_rect();
        let min = egui::pos2(screen.left() + 290.0, screen.top() + 40.0);
        let max = egui::pos2(
            (min.x + 960.0).min(screen.right() - 20.0),
            (screen.bottom() - 60.0).max(min.y + LARGE_MIN.y),
        );
        egui::Window::new(title)
            .id(egui::Id::unique(("large canvas", title)))
            .open(&mut open)
            .default_rect(egui::Rect::from_min_max(min, max.max(min + LARGE_MIN)))
            .min_size(LARGE_MIN)
            .collapsible(false)
            .resizable(true)
            .show(ui.ctx(), body);
    }
    open
}

/// A button that opens an editor in the large canvas (`large`).
pub(super) fn large_button(ui: &mut egui::Ui, label: &str, large: &mut bool) {
    if !*large
        && ui
            .button(label)
            .on_hover_text(
                "Edit in a large resizable window over the viewport (the same strokes and \
                 rules; close it to come back here)",
            )
            .clicked()
    {
        *large = true;
    }
}

/// A canvas's height: `small` in the panel; in the large canvas what the
/// window has left after `below` points of rows under it (at least
/// `small`).
pub(super) fn canvas_height(ui: &egui::Ui, small: f32, below: f32, large: bool) -> f32 {
    if large {
        (ui.available_height() - below).max(small)
    } else {
        small
    }
}

/// The smallest large canvas window.
const LARGE_MIN: egui::Vec2 = egui::vec2(420.0, 480.0);

/// The editor's rows: the tools, the canvas, what the strokes make and
/// Apply; in the panel or (`state.large`) in the large canvas's window,
/// by the same code.
fn editor(
    ui: &mut egui::Ui,
    (flower, index): (&Flower, usize),
    edge: f64,
    state: &mut SketchState,
    commands: &mut Vec<Command>,
    large: bool,
) {
    let template = &flower.templates[index];
    let name = template.name.as_str();
    let Some(draft) = state.drafts.get(name).cloned() else {
        return;
    };
    ui.horizontal_wrapped(|ui| {
        ui.strong("Sketched petal").on_hover_text(
            "Draw with the mouse on the canvas: the two margins and the primary vein (any \
             order, any direction), then cross-sections across the petal. The petal is a \
             B-spline surface whose control points are spread evenly inside the outline; Apply \
             meshes it at the remesh edge above.",
        );
        large_button(ui, "Large sketch canvas", &mut state.large);
    });
    ui.horizontal_wrapped(|ui| {
        ui.label("draw");
        for (tool, label, hover) in TOOLS {
            ui.selectable_value(&mut state.tool, tool, label)
                .on_hover_text(hover);
        }
    });
    let mut sketch = draft.sketch.clone();
    let undone = stroke_row(ui, &draft, &mut sketch);
    let built = sketch.build();
    let before = sketch.clone();

    // In the large canvas, the rows under it (messages, side view,
    // preview, Apply) keep about this much room.
    let height = canvas_height(ui, CANVAS_HEIGHT, 260.0, large);
    canvas(
        ui,
        template,
        &mut sketch,
        built.as_ref().ok(),
        state,
        height,
    );
    let built = if sketch == before {
        built
    } else {
        // A stroke was drawn: shown from the next frame.
        ui.ctx().request_repaint();
        sketch.build()
    };
    // Under the canvas, so the canvas does not move when it changes.
    match &built {
        Ok(_) => {}
        Err(SketchError::Missing(_)) => {
            let missing: Vec<&str> = [
                (&sketch.left, "left outline"),
                (&sketch.right, "right outline"),
                (&sketch.vein, "primary vein"),
            ]
            .iter()
            .filter(|(s, _)| s.is_empty())
            .map(|(_, n)| *n)
            .collect();
            ui.label(format!(
                "to draw: {} (any order, any direction)",
                missing.join(", ")
            ));
        }
        Err(e) => {
            ui.label(RichText::new(e.to_string()).color(ui.visuals().error_fg_color));
        }
    }
    if let Ok(petal) = &built {
        side_view(ui, petal);
    }

    let k = preview_ui(ui, state, (&sketch, edge), &built);
    apply_ui(
        ui,
        (flower, index),
        (&sketch, edge, k),
        &built,
        state,
        commands,
    );
    if let Some(d) = state.drafts.get_mut(name) {
        if undone {
            d.undo.pop();
        } else if sketch != d.sketch {
            d.undo.push(std::mem::take(&mut d.sketch));
            if d.undo.len() > UNDO_STROKES {
                d.undo.remove(0);
            }
        }
        d.sketch = sketch;
    }
}

/// A saved sketch that changed (an Apply, an undo, a project opened)
/// replaces the draft of the template named `name`.
fn sync_draft(state: &mut SketchState, name: &str, saved: &Option<PetalSketch>) {
    match state.drafts.get(name) {
        Some(draft) if draft.saved == *saved => {}
        _ => match saved {
            Some(sketch) => {
                state.drafts.insert(
                    name.to_string(),
                    Draft {
                        saved: saved.clone(),
                        sketch: sketch.clone(),
                        undo: Vec::new(),
                    },
                );
            }
            None => {
                state.drafts.remove(name);
            }
        },
    }
}

/// "Undo stroke", "Remove cross-sections" and "Clear strokes" on
/// `sketch`; whether the last stroke was taken back.
fn stroke_row(ui: &mut egui::Ui, draft: &Draft, sketch: &mut PetalSketch) -> bool {
    let mut undone = false;
    ui.horizontal_wrapped(|ui| {
        if ui
            .add_enabled(!draft.undo.is_empty(), egui::Button::new("Undo stroke"))
            .on_hover_text("Take back the last stroke (or Clear strokes, or Remove cross-sections)")
            .clicked()
            && let Some(previous) = draft.undo.last()
        {
            *sketch = previous.clone();
            undone = true;
        }
        if ui
            .add_enabled(
                !sketch.sections.is_empty(),
                egui::Button::new("Remove cross-sections"),
            )
            .on_hover_text("Make the petal flat again")
            .clicked()
        {
            sketch.sections.clear();
        }
        if ui
            .add_enabled(
                *sketch != PetalSketch::default(),
                egui::Button::new("Clear strokes"),
            )
            .on_hover_text("Start again from an empty canvas")
            .clicked()
        {
            *sketch = PetalSketch::default();
        }
    });
    undone
}

/// The preview of `sketch` meshed at `edge`, made on a thread of its own
/// when either changed, and its numbers; returns what the preview is of.
fn preview_ui(
    ui: &mut egui::Ui,
    state: &mut SketchState,
    (sketch, edge): (&PetalSketch, f64),
    built: &Result<SketchedPetal, SketchError>,
) -> u64 {
    // The preview at the section's edge, meshed on a thread of its own
    // (no spinner: the thread asks for a frame when it is done).
    let k = key(sketch, edge);
    if state.preview.as_ref().is_none_or(|(old, _)| *old != k) {
        let preview = match built {
            Ok(petal) => {
                let options = RemeshOptions {
                    max_vertices: PREVIEW_MAX_VERTICES,
                    ..RemeshOptions::new(edge)
                };
                let surface = petal.surface.clone();
                Background::start(
                    "anthesis-sketch-preview",
                    "the mesher",
                    |message| message,
                    ui.ctx(),
                    move || {
                        anthesis_bud::build_organ(&surface, &options).map_err(|e| e.to_string())
                    },
                )
            }
            Err(e) => Preview::Done(Err(e.to_string())),
        };
        state.preview = Some((k, preview));
    }
    if let Some((_, preview)) = &mut state.preview {
        preview.poll();
    }
    if built.is_ok() {
        match state.preview.as_ref().and_then(|(_, p)| p.answer()) {
            Some(Ok(bud)) => {
                ui.label(format!("sketched: {}", quality_text(&bud.quality)));
            }
            Some(Err(e)) => {
                ui.label(
                    RichText::new(format!("cannot mesh: {e}")).color(ui.visuals().error_fg_color),
                );
            }
            None => {
                ui.label("meshing…");
            }
        }
    }
    k
}

/// "Apply sketch": the preview's mesh when it is of these strokes and this
/// edge (`k`, [`key`]), else the sketch meshed now, as the template's shape
/// (one undo step); or why not.
fn apply_ui(
    ui: &mut egui::Ui,
    (flower, index): (&Flower, usize),
    (sketch, edge, k): (&PetalSketch, f64, u64),
    built: &Result<SketchedPetal, SketchError>,
    state: &mut SketchState,
    commands: &mut Vec<Command>,
) {
    let name = flower.templates[index].name.as_str();
    if ui
        .add_enabled(built.is_ok(), egui::Button::new("Apply sketch"))
        .on_hover_text(
            "Mesh the sketched petal at the remesh edge and use it for the template (its maps \
             stay; one undo step)",
        )
        .clicked()
        && let Ok(petal) = built
    {
        // The preview's mesh when it is of these strokes and this edge (the
        // mesher is deterministic), else meshed now.
        let meshed = match &state.preview {
            Some((made_of, Background::Done(Ok(bud)))) if *made_of == k => Ok(bud.clone()),
            _ => anthesis_bud::build_organ(&petal.surface, &RemeshOptions::new(edge))
                .map_err(|e| e.to_string()),
        };
        match meshed {
            Ok(bud) => {
                state.apply_error = None;
                let source = TemplateSource::Sketch {
                    sketch: sketch.clone(),
                    edge,
                };
                match flower.with_shape(index, bud.mesh, source) {
                    Ok(edited) => commands.push(Command::Edit {
                        label: format!("sketched shape of {name}"),
                        edit: ProjectEdit::Flower(Box::new(edited)),
                    }),
                    Err(e) => state.apply_error = Some(format!("cannot use the sketch: {e}")),
                }
            }
            Err(e) => state.apply_error = Some(format!("cannot mesh the sketch: {e}")),
        }
    }
    if let Some(error) = &state.apply_error {
        ui.label(RichText::new(error).color(ui.visuals().error_fg_color));
    }
}

/// The canvas: the template's mesh faintly, the strokes, the control net
/// and outline of the petal; drawing on it adds a stroke to `sketch`.
fn canvas(
    ui: &mut egui::Ui,
    template: &anthesis_flower::Template,
    sketch: &mut PetalSketch,
    petal: Option<&SketchedPetal>,
    state: &mut SketchState,
    height: f32,
) {
    let size = egui::vec2(ui.available_width().max(160.0), height);
    let (response, painter) = ui.allocate_painter(size, egui::Sense::drag());
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Canvas, true, "sketch canvas"));
    let rect = response.rect;
    // The map: kept while drawing, else fitted to what there is to show
    // (zoomed by Ctrl+wheel).
    let view = match (state.view, &state.drawing) {
        (Some(view), Some(_)) if view.centre_on_screen == rect.center() => view,
        (_, drawing) => {
            let fitted = fitted_view(rect, template, sketch);
            if drawing.is_none() {
                zoom_on_wheel(ui, &response, fitted, state);
            }
            match state.zoom {
                Some((zoom, centre)) => View {
                    centre,
                    scale: fitted.scale * zoom,
                    ..fitted
                },
                None => fitted,
            }
        }
    };
    painter.rect_filled(rect, 4.0, ui.visuals().extreme_bg_color);
    painter.text(
        rect.left_bottom() + egui::vec2(6.0, -4.0),
        egui::Align2::LEFT_BOTTOM,
        "Ctrl+wheel zooms (the wheel scrolls the panel)",
        egui::FontId::proportional(11.0),
        ui.visuals().weak_text_color(),
    );
    let faint = Stroke::new(1.0, ui.visuals().weak_text_color().gamma_multiply(0.35));
    // The template's mesh seen from its inner side's back (x, y).
    for t in &template.mesh.triangles {
        let [a, b, c] = t.map(|i| view.to_screen(template.mesh.positions[i as usize].truncate()));
        painter.line_segment([a, b], faint);
        painter.line_segment([b, c], faint);
        painter.line_segment([c, a], faint);
    }
    // The base: the template frame's origin, growing up.
    let origin = view.to_screen(DVec2::ZERO);
    let axis = Stroke::new(1.0, Color32::from_rgb(90, 140, 90));
    painter.line_segment(
        [origin - egui::vec2(8.0, 0.0), origin + egui::vec2(8.0, 0.0)],
        axis,
    );
    painter.line_segment([origin, origin - egui::vec2(0.0, 16.0)], axis);
    // The petal: its control net and its outline.
    if let Some(petal) = petal {
        draw_petal(&painter, view, petal);
    }
    // The strokes as drawn.
    let colours = [
        (&sketch.left, Color32::from_rgb(90, 160, 255)),
        (&sketch.right, Color32::from_rgb(90, 160, 255)),
        (&sketch.vein, Color32::from_rgb(110, 210, 110)),
    ];
    for (s, colour) in colours {
        painter.add(egui::Shape::line(
            s.iter().map(|p| view.to_screen(*p)).collect(),
            Stroke::new(2.0, colour),
        ));
    }
    for s in &sketch.sections {
        painter.add(egui::Shape::line(
            s.iter().map(|p| view.to_screen(*p)).collect(),
            Stroke::new(2.0, Color32::from_rgb(255, 170, 40)),
        ));
    }

    // Drawing.
    if response.drag_started() {
        let from = ui
            .input(|i| i.pointer.press_origin())
            .or(response.interact_pointer_pos());
        state.drawing = from.map(|at| vec![view.to_sketch(at)]);
    }
    if let Some(points) = &mut state.drawing {
        if let Some(at) = response.interact_pointer_pos()
            && points
                .last()
                .is_none_or(|last| view.to_screen(*last).distance(at) >= MIN_SPACING)
        {
            points.push(view.to_sketch(at));
        }
        painter.add(egui::Shape::line(
            points.iter().map(|p| view.to_screen(*p)).collect(),
            Stroke::new(2.0, ui.visuals().strong_text_color()),
        ));
    }
    if response.drag_stopped()
        && let Some(points) = state.drawing.take()
    {
        if points.len() >= 2 {
            *sketch = sketch.with_stroke(state.tool, points);
        }
    } else if !response.dragged() && !response.drag_started() {
        state.drawing = None;
    }
    state.view = Some(view);
}

/// The map that fits the default view, the strokes and the template's
/// mesh into `rect` (less 12 points a side).
fn fitted_view(
    rect: egui::Rect,
    template: &anthesis_flower::Template,
    sketch: &PetalSketch,
) -> View {
    let (mut low, mut high) = (DEFAULT_VIEW[0], DEFAULT_VIEW[1]);
    let strokes = [&sketch.left, &sketch.right, &sketch.vein]
        .into_iter()
        .chain(&sketch.sections);
    for p in strokes.flatten() {
        low = low.min(*p);
        high = high.max(*p);
    }
    for p in &template.mesh.positions {
        low = low.min(p.truncate());
        high = high.max(p.truncate());
    }
    let inner = rect.shrink(12.0);
    let extent = (high - low).max(DVec2::splat(1e-6));
    let scale = (f64::from(inner.width()) / extent.x).min(f64::from(inner.height()) / extent.y);
    View {
        centre_on_screen: rect.center(),
        centre: (low + high) * 0.5,
        scale,
    }
}

/// Ctrl+wheel over the canvas (egui's zoom modifier; the wheel alone
/// scrolls the panel): zooms the view about the pointer, from the fitted
/// view (1) to [`MAX_ZOOM`] times it.
fn zoom_on_wheel(ui: &egui::Ui, response: &egui::Response, fitted: View, state: &mut SketchState) {
    let factor = f64::from(ui.input(egui::InputState::zoom_delta));
    let Some(pointer) = response.hover_pos().filter(|_| factor != 1.0) else {
        return;
    };
    let (zoom, centre) = state.zoom.unwrap_or((1.0, fitted.centre));
    let now = View {
        centre,
        scale: fitted.scale * zoom,
        ..fitted
    };
    let under = now.to_sketch(pointer);
    let zoom = (zoom * factor).clamp(1.0, MAX_ZOOM);
    let d = pointer - fitted.centre_on_screen;
    let offset = DVec2::new(f64::from(d.x), -f64::from(d.y)) / (fitted.scale * zoom);
    state.zoom = (zoom > 1.0).then_some((zoom, under - offset));
}

/// How far Ctrl+wheel zooms the sketch canvas in, times the fitted view.
const MAX_ZOOM: f64 = 20.0;

/// The sketched petal over the canvas: its control net and its outline.
fn draw_petal(painter: &egui::Painter, view: View, petal: &SketchedPetal) {
    let net = petal.control_in_sketch();
    let line = Stroke::new(1.0, Color32::from_rgb(150, 150, 170));
    for (j, row) in net.iter().enumerate() {
        for (i, p) in row.iter().enumerate() {
            let at = view.to_screen(*p);
            if let Some(q) = row.get(i + 1) {
                painter.line_segment([at, view.to_screen(*q)], line);
            }
            if let Some(q) = net.get(j + 1).map(|r| r[i]) {
                painter.line_segment([at, view.to_screen(q)], line);
            }
            painter.circle_filled(at, 2.5, Color32::from_rgb(200, 200, 220));
        }
    }
    let outline: Vec<Pos2> = boundary(&petal.surface)
        .into_iter()
        .map(|p| view.to_screen(petal.frame.to_sketch(p.truncate())))
        .collect();
    painter.add(egui::Shape::closed_line(
        outline,
        Stroke::new(1.5, Color32::from_rgb(235, 150, 175)),
    ));
}

/// The surface's outline: base, right margin, tip, left margin.
fn boundary(surface: &dyn Surface) -> Vec<DVec3> {
    const STEPS: usize = 40;
    let t = |k: usize| k as f64 / STEPS as f64;
    let mut points = Vec::with_capacity(4 * STEPS);
    points.extend((0..STEPS).map(|k| surface.point(DVec2::new(t(k), 0.0))));
    points.extend((0..STEPS).map(|k| surface.point(DVec2::new(1.0, t(k)))));
    points.extend((0..STEPS).map(|k| surface.point(DVec2::new(1.0 - t(k), 1.0))));
    points.extend((0..STEPS).map(|k| surface.point(DVec2::new(0.0, 1.0 - t(k)))));
    points
}

/// The side view: each bent row's section through the surface, across
/// (x) against height, the inner side (−Z) up.
fn side_view(ui: &mut egui::Ui, petal: &SketchedPetal) {
    if petal.section_rows.is_empty() {
        ui.label("no cross-sections: the petal is flat");
        return;
    }
    ui.label("cross-sections from the base (inner side, −Z, up)");
    let v = petal.surface.row_parameters();
    let sections: Vec<Vec<DVec2>> = petal
        .section_rows
        .iter()
        .map(|row| {
            (0..=40)
                .map(|k| {
                    let p = petal.surface.point(DVec2::new(k as f64 / 40.0, v[*row]));
                    DVec2::new(p.x, -p.z)
                })
                .collect()
        })
        .collect();
    let (mut low, mut high) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for p in sections.iter().flatten() {
        low = low.min(*p);
        high = high.max(*p);
    }
    let size = egui::vec2(ui.available_width().max(160.0), SIDE_HEIGHT);
    let (response, painter) = ui.allocate_painter(size, egui::Sense::hover());
    let rect = response.rect;
    painter.rect_filled(rect, 4.0, ui.visuals().extreme_bg_color);
    let inner = rect.shrink(10.0);
    let extent = (high - low).max(DVec2::splat(1.0));
    let scale = (f64::from(inner.width()) / extent.x).min(f64::from(inner.height()) / extent.y);
    let centre = (low + high) * 0.5;
    let to_screen = |p: DVec2| {
        let d = (p - centre) * scale;
        Pos2::new(rect.center().x + d.x as f32, rect.center().y - d.y as f32)
    };
    // The base plane (height 0).
    let zero = to_screen(DVec2::new(centre.x, 0.0)).y;
    painter.line_segment(
        [
            Pos2::new(inner.left(), zero),
            Pos2::new(inner.right(), zero),
        ],
        Stroke::new(1.0, ui.visuals().weak_text_color().gamma_multiply(0.5)),
    );
    for (section, row) in sections.iter().zip(&petal.section_rows) {
        painter.add(egui::Shape::line(
            section.iter().map(|p| to_screen(*p)).collect(),
            Stroke::new(2.0, Color32::from_rgb(255, 170, 40)),
        ));
        for p in &petal.surface.control[*row] {
            painter.circle_filled(
                to_screen(DVec2::new(p.x, -p.z)),
                2.5,
                Color32::from_rgb(200, 200, 220),
            );
        }
    }
}

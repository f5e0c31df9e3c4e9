//! The PDE petal editor in the Flower panel (issue 14 item 3) of a
//! template whose source is a PDE sweep (the review of a scanned petal,
//! which makes one, is `scan_panel.rs`).
//!
//! **Editor.** The sweep's two margins (`u = 0` and `u = 1`) and their
//! across-tangents are cubic Bézier curves. Like Blender's curve tools, the
//! margins are drawn with their control polygons and draggable control
//! points, and each tangent as a handle: an arrow from the margin's control
//! point into the surface, to where the generator's Bézier control point
//! sits (`C0 + T0/3` at margin 1, `C1 − T1/3` at margin 2, since `u` runs
//! from margin 1 to margin 2); dragging the arrow's head turns and
//! stretches the tangent. The 2D view looks from the front (x, y) or the side (z, y);
//! the chosen point's numbers can be typed. Symmetric editing about the
//! midrib is on by default. The surface (eq. 12 of Chaudhry et al.,
//! closed form, so cheap) is drawn live as iso-lines, and the mesh it would
//! become at the Shape section's edge is built on every change, so its
//! particle count and quality are shown before **Apply surface**, which
//! replaces the template's mesh and source in one undo step (the maps
//! stay).

use std::collections::BTreeMap;

use anthesis_bud::{Bud, PdeSweep, RemeshOptions, Surface, SweepCurve};
use anthesis_flower::{Flower, TemplateSource};
use eframe::egui::{self, Color32, RichText};
use glam::{DVec2, DVec3};

use super::checked_field::{checked_slider, checked_with};
use super::command::{Command, ProjectEdit};
use super::scan_panel::ScanReview;
use super::sketch_panel::{canvas_height, in_room, large_button};
use super::widgets::quality_text;

/// The names of a curve's control points, base to tip.
const POINT_NAMES: [&str; 4] = ["base", "lower", "upper", "tip"];

/// The name of a curve in the editor.
fn curve_name(curve: SweepCurve) -> &'static str {
    match curve {
        SweepCurve::Margin0 => "margin 1",
        SweepCurve::Margin1 => "margin 2",
        SweepCurve::Tangent0 => "tangent 1",
        SweepCurve::Tangent1 => "tangent 2",
    }
}

/// The PDE editor's state, and the scanned petal under review.
#[derive(Debug, Default)]
pub struct PdeState {
    /// The sweeps being edited, by template name: the template's saved
    /// sweep they started from, and the sweep as edited.
    drafts: BTreeMap<String, (PdeSweep, PdeSweep)>,
    /// The point being edited: curve (margins and tangents by index in
    /// [`SweepCurve::ALL`]) and control point.
    point: (usize, usize),
    /// Edit each point alone (off: its mirror image follows).
    asymmetric: bool,
    /// The 2D view from the side (z, y) instead of the front (x, y).
    side_view: bool,
    /// Where the margins' control points and the tangents' handle heads
    /// were drawn in the last frame, by curve in [`SweepCurve::ALL`] order.
    on_screen: Option<[[egui::Pos2; 4]; 4]>,
    /// The mesh the draft would become: the draft and edge it was built
    /// from, and the result.
    built: Option<((PdeSweep, u64), Result<Bud, String>)>,
    /// Why the surface could not be applied.
    error: Option<String>,
    /// A scanned petal being reviewed.
    pub(super) scan: Option<ScanReview>,
    /// The editor is in the large canvas (a window over the viewport).
    large: bool,
}

impl PdeState {
    /// The sweep of the template named `name` as edited, once shown.
    pub fn sweep(&self, name: &str) -> Option<&PdeSweep> {
        self.drafts.get(name).map(|(_, draft)| draft)
    }

    /// Where control point `index` of `curve` was drawn (a tangent: its
    /// handle's head).
    pub fn point_on_screen(&self, curve: SweepCurve, index: usize) -> Option<egui::Pos2> {
        self.on_screen
            .and_then(|p| p.get(curve as usize).and_then(|c| c.get(index)).copied())
    }

    /// The particle count and quality of the mesh the draft would become,
    /// or why it cannot be meshed.
    pub fn built(&self) -> Option<Result<&anthesis_bud::MeshQuality, &str>> {
        self.built.as_ref().map(|(_, b)| match b {
            Ok(bud) => Ok(&bud.quality),
            Err(e) => Err(e.as_str()),
        })
    }

    /// Whether the editor is open in the large canvas.
    pub fn large(&self) -> bool {
        self.large
    }

    /// The scanned petal under review.
    pub fn scan(&self) -> Option<&ScanReview> {
        self.scan.as_ref()
    }
}

/// A new template of [`PdeSweep::petal`] meshed at `edge`, with uniform
/// maps (like the simple petal).
pub fn new_pde_template(edge: f64) -> Result<anthesis_flower::Template, String> {
    let sweep = PdeSweep::petal();
    let bud =
        anthesis_bud::build_organ(&sweep, &RemeshOptions::new(edge)).map_err(|e| e.to_string())?;
    let mut template = anthesis_garden::five_petal::simple_template_of_mesh("pde petal", bud.mesh);
    template.source = Some(TemplateSource::Pde { sweep, edge });
    Ok(template)
}

/// A key for what a mesh was built from.
fn edge_bits(edge: f64) -> u64 {
    edge.to_bits()
}

/// The PDE editor of template `index` whose saved sweep is `saved`; `edge`
/// is the Shape section's remesh edge. In the panel, or in the large
/// canvas (`sketch_panel::in_room`).
pub fn pde_ui(
    ui: &mut egui::Ui,
    (flower, index): (&Flower, usize),
    saved: PdeSweep,
    edge: f64,
    state: &mut PdeState,
    commands: &mut Vec<Command>,
) {
    let large = state.large;
    if !in_room(ui, "PDE surface", large, |ui| {
        editor(ui, (flower, index), saved, edge, state, commands, large);
    }) {
        state.large = false;
    }
}

/// The editor's rows, in the panel or in the large canvas.
fn editor(
    ui: &mut egui::Ui,
    (flower, index): (&Flower, usize),
    saved: PdeSweep,
    edge: f64,
    state: &mut PdeState,
    commands: &mut Vec<Command>,
    large: bool,
) {
    let name = flower.templates[index].name.clone();
    let mut sweep = match state.drafts.get(&name) {
        Some((from, draft)) if *from == saved => *draft,
        _ => saved,
    };
    let before = sweep;
    ui.horizontal_wrapped(|ui| {
        ui.strong("PDE surface").on_hover_text(
            "A sweep between the two margins (curves from the base to the tip) meeting them \
             with the across-tangents drawn as handles (pde-surfaces-lily.txt eq. 12). Drag a \
             point or a handle's head, or type the chosen point's numbers; Apply surface meshes \
             it at the remesh edge above.",
        );
        large_button(ui, "Large PDE canvas", &mut state.large);
    });
    let mut symmetric = !state.asymmetric;
    ui.horizontal_wrapped(|ui| {
        ui.checkbox(&mut symmetric, "symmetric about the midrib")
            .on_hover_text("A point's mirror image across the midrib moves with it");
        ui.selectable_value(&mut state.side_view, false, "front")
            .on_hover_text("Looking at the inner side: x across, y from base to tip");
        ui.selectable_value(&mut state.side_view, true, "side")
            .on_hover_text("From the side: z across, y from base to tip");
    });
    state.asymmetric = !symmetric;
    // In the large canvas, the rows under the view keep about this much.
    let height = canvas_height(ui, 240.0, 170.0, large);
    sweep = sweep_view(ui, state, (sweep, height), symmetric);

    // The chosen point's numbers.
    ui.horizontal(|ui| {
        let label = ui.label("point").id;
        let (c, k) = state.point;
        egui::ComboBox::from_id_salt("pde point")
            .selected_text(format!(
                "{} {}",
                curve_name(SweepCurve::ALL[c]),
                POINT_NAMES[k]
            ))
            .show_ui(ui, |ui| {
                for (c, curve) in SweepCurve::ALL.iter().enumerate() {
                    for (k, point) in POINT_NAMES.iter().enumerate() {
                        ui.selectable_value(
                            &mut state.point,
                            (c, k),
                            format!("{} {point}", curve_name(*curve)),
                        );
                    }
                }
            })
            .response
            .labelled_by(label);
    });
    let (c, k) = state.point;
    let curve = SweepCurve::ALL[c];
    let mut p = sweep.curve(curve).control[k];
    let mut typed = false;
    ui.horizontal(|ui| {
        for (axis, value) in [("x", &mut p.x), ("y", &mut p.y), ("z", &mut p.z)] {
            let label = ui.label(axis).id;
            let limit = anthesis_mesh::validate::MAX_COORDINATE;
            typed |= checked_with(ui, axis, value, -limit..=limit, |d| {
                d.speed(0.05).max_decimals(3)
            })
            .labelled_by(label)
            .changed();
        }
    })
    .response
    .on_hover_text(if curve.is_margin() {
        "The margin's control point, in the template frame"
    } else {
        "The across-tangent dS/du at that control point (a vector; the handle shows a third of it, \
         into the surface)"
    });
    if typed {
        sweep = sweep.with_point(curve, k, p, symmetric);
    }
    let mut lambda = sweep.stretch_to_bend();
    ui.horizontal(|ui| {
        let label = ui
            .label("k_s/k_b")
            .on_hover_text(
                "Stretch over bend stiffness of the generator (seed eq. 5): 0 gives the cubic \
                 of eq. 12, larger values pull it taut between the margins",
            )
            .id;
        if checked_slider(
            ui,
            "k_s/k_b",
            &mut lambda,
            0.0..=anthesis_bud::MAX_STRETCH_TO_BEND,
            |slider| slider.logarithmic(true).smallest_positive(0.01),
        )
        .labelled_by(label)
        .changed()
        {
            sweep = sweep.with_stretch_to_bend(lambda);
        }
    });
    if sweep != before {
        state.error = None;
    }
    state.drafts.insert(name.clone(), (saved, sweep));

    mesh_and_apply(ui, (flower, index), (sweep, edge), state, commands);
}

/// The 2D view of the sweep: its margins with their control polygons and
/// points, the tangent handles and the surface's iso-lines; returns the
/// sweep with the point dragged moved (and its mirror image when
/// `symmetric`).
fn sweep_view(
    ui: &mut egui::Ui,
    state: &mut PdeState,
    (sweep, height): (PdeSweep, f32),
    symmetric: bool,
) -> PdeSweep {
    let side = state.side_view;
    // The view: margins, their control polygons and points, tangent
    // handles and the surface's iso-lines.
    let across = |p: DVec3| if side { p.z } else { p.x };
    let flat = |p: DVec3| DVec2::new(across(p), p.y);
    let handle = |c: usize, k: usize| {
        let margin = if c == 2 { &sweep.curve0 } else { &sweep.curve1 };
        let t = if c == 2 {
            &sweep.tangent0
        } else {
            &sweep.tangent1
        };
        // The generator's inner Bézier control points: both handles
        // point into the surface.
        let sign = if c == 2 { 1.0 } else { -1.0 };
        margin.control[k] + sign * t.control[k] / 3.0
    };
    let handled: [[DVec3; 4]; 4] = [
        sweep.curve0.control,
        sweep.curve1.control,
        std::array::from_fn(|k| handle(2, k)),
        std::array::from_fn(|k| handle(3, k)),
    ];
    let iso = iso_lines(&sweep);
    let samples = CURVE_SAMPLES;
    let (mut low, mut high) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for p in handled.iter().flatten().chain(iso.iter().flatten()) {
        low = low.min(flat(*p));
        high = high.max(flat(*p));
    }
    let size = egui::vec2(ui.available_width().max(120.0), height);
    let (response, painter) = ui.allocate_painter(size, egui::Sense::hover());
    let rect = response.rect.shrink(14.0);
    let extent = (high - low).max(DVec2::splat(1e-6));
    let scale = (f64::from(rect.width()) / extent.x).min(f64::from(rect.height()) / extent.y);
    let middle = (low + high) * 0.5;
    let to_screen = |p: DVec3| {
        let q = flat(p) - middle;
        egui::pos2(
            rect.center().x + (q.x * scale) as f32,
            rect.center().y - (q.y * scale) as f32,
        )
    };
    painter.rect_filled(response.rect, 4.0, ui.visuals().extreme_bg_color);
    let weak = egui::Stroke::new(1.0, ui.visuals().weak_text_color());
    for line in &iso {
        let points: Vec<egui::Pos2> = line.iter().map(|p| to_screen(*p)).collect();
        painter.add(egui::Shape::line(points, weak));
    }
    if !side {
        let x = to_screen(DVec3::ZERO).x;
        painter.line_segment(
            [egui::pos2(x, rect.top()), egui::pos2(x, rect.bottom())],
            egui::Stroke::new(1.0, Color32::from_rgb(90, 140, 90)),
        );
    }
    let margin_colour = Color32::from_rgb(120, 170, 255);
    let handle_colour = Color32::from_rgb(230, 120, 200);
    for (c, curve) in [sweep.curve0, sweep.curve1].iter().enumerate() {
        let drawn: Vec<egui::Pos2> = (0..=samples)
            .map(|j| to_screen(curve.at(j as f64 / samples as f64)))
            .collect();
        painter.add(egui::Shape::line(
            drawn,
            egui::Stroke::new(2.0, margin_colour),
        ));
        for k in 0..3 {
            painter.line_segment(
                [to_screen(curve.control[k]), to_screen(curve.control[k + 1])],
                egui::Stroke::new(1.0, margin_colour.gamma_multiply(0.5)),
            );
        }
        for k in 0..4 {
            painter.arrow(
                to_screen(curve.control[k]),
                to_screen(handled[c + 2][k]) - to_screen(curve.control[k]),
                egui::Stroke::new(1.5, handle_colour),
            );
        }
    }
    let points = handled.map(|c| c.map(to_screen));
    let mut moved = None;
    for (c, curve_points) in points.iter().enumerate() {
        for (k, at) in curve_points.iter().enumerate() {
            let id = ui.scope_id().with(("pde point", c, k));
            let (picked, shift) = super::widgets::view_point(ui, id, *at, 12.0, (scale, side));
            if picked {
                state.point = (c, k);
            }
            if let Some(shift) = shift {
                moved = Some((c, k, shift));
            }
            let chosen = state.point == (c, k);
            let colour = if chosen {
                Color32::from_rgb(255, 170, 40)
            } else if c < 2 {
                ui.visuals().strong_text_color()
            } else {
                handle_colour
            };
            painter.circle_filled(*at, if chosen { 5.0 } else { 4.0 }, colour);
        }
    }
    state.on_screen = Some(points);
    match moved {
        Some(dragged) => with_dragged(sweep, dragged, symmetric),
        None => sweep,
    }
}

/// Points along each curve and iso-line the view draws.
const CURVE_SAMPLES: usize = 24;

/// Lines of constant `u` and of constant `v` across `sweep`, 8 spans
/// each, [`CURVE_SAMPLES`] spans along.
fn iso_lines(sweep: &PdeSweep) -> Vec<Vec<DVec3>> {
    let lines = 8;
    let samples = CURVE_SAMPLES;
    (0..=lines)
        .map(|i| {
            (0..=samples)
                .map(|j| {
                    sweep.point(DVec2::new(
                        i as f64 / lines as f64,
                        j as f64 / samples as f64,
                    ))
                })
                .collect()
        })
        .chain((0..=lines).map(|j| {
            (0..=samples)
                .map(|i| {
                    sweep.point(DVec2::new(
                        i as f64 / samples as f64,
                        j as f64 / lines as f64,
                    ))
                })
                .collect()
        }))
        .collect()
}

/// `sweep` with control point `k` of curve `c` (by index in
/// [`SweepCurve::ALL`]) dragged by `shift` in the template frame, and its
/// mirror image too when `symmetric`.
fn with_dragged(
    sweep: PdeSweep,
    (c, k, shift): (usize, usize, DVec3),
    symmetric: bool,
) -> PdeSweep {
    let curve = SweepCurve::ALL[c];
    // A handle's head moves the tangent three times as far (the other
    // way at margin 2, whose handle is C1 − T1/3).
    let value = match curve {
        SweepCurve::Margin0 | SweepCurve::Margin1 => sweep.curve(curve).control[k] + shift,
        SweepCurve::Tangent0 => sweep.curve(curve).control[k] + 3.0 * shift,
        SweepCurve::Tangent1 => sweep.curve(curve).control[k] - 3.0 * shift,
    };
    sweep.with_point(curve, k, value, symmetric)
}

/// The mesh the sweep would become at `edge` (built when either changes)
/// with "Apply surface", or why it cannot be meshed or used.
fn mesh_and_apply(
    ui: &mut egui::Ui,
    (flower, index): (&Flower, usize),
    (sweep, edge): (PdeSweep, f64),
    state: &mut PdeState,
    commands: &mut Vec<Command>,
) {
    let name = &flower.templates[index].name;
    // The mesh it would become, built when the draft or edge changes.
    let key = (sweep, edge_bits(edge));
    if state.built.as_ref().is_none_or(|(k, _)| *k != key) {
        let built =
            anthesis_bud::build_organ(&sweep, &RemeshOptions::new(edge)).map_err(|e| e.to_string());
        state.built = Some((key, built));
    }
    match state.built.as_ref().map(|(_, b)| b) {
        Some(Ok(bud)) => {
            ui.label(format!("surface meshed: {}", quality_text(&bud.quality)));
            if ui
                .button("Apply surface")
                .on_hover_text(
                    "Use this mesh and these curves for the template (its maps stay; one undo \
                     step)",
                )
                .clicked()
            {
                let source = TemplateSource::Pde { sweep, edge };
                match flower.with_shape(index, bud.mesh.clone(), source) {
                    Ok(edited) => commands.push(Command::Edit {
                        label: format!("PDE surface of {name}"),
                        edit: ProjectEdit::Flower(Box::new(edited)),
                    }),
                    Err(e) => state.error = Some(format!("cannot use the surface: {e}")),
                }
            }
        }
        Some(Err(e)) => {
            ui.label(
                RichText::new(format!("cannot mesh the surface: {e}"))
                    .color(ui.visuals().error_fg_color),
            );
        }
        None => {}
    }
    if let Some(error) = &state.error {
        ui.label(RichText::new(error).color(ui.visuals().error_fg_color));
    }
}

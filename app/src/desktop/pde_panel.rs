//! PDE petals in the Flower panel (issue 14 items 3 and 6): the PDE petal
//! editor of a template whose source is a PDE sweep, and the review of a
//! scanned petal before it becomes a template.
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
//! midrib is on by default. The surface (eq. 12 of `pde-surfaces-lily.txt`,
//! closed form, so cheap) is drawn live as iso-lines, and the mesh it would
//! become at the Shape section's edge is built on every change, so its
//! particle count and quality are shown before **Apply surface**, which
//! replaces the template's mesh and source in one undo step (the maps
//! stay).
//!
//! **Scanned petal.** "Import scanned petal…" reads an OBJ without UVs
//! (`anthesis_mesh::load_obj_shape`), finds its outline's base and tip and
//! fits a sweep (`anthesis_bud::fit_scan`). The review shows the outline
//! with the base corners and the tip; choosing a corner and clicking on
//! the outline moves it, and the fit is made again. The fit error is shown
//! as a fraction of the petal's length; **Make template** adds the
//! template (PDE source, so it can be edited again) with one organ, in one
//! undo step.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use anthesis_bud::{
    Bud, PdeSweep, RemeshOptions, ScanCorners, ScanFit, ScanFitOptions, ScanOutline, Surface,
    SweepCurve,
};
use anthesis_flower::{Flower, TemplateSource};
use anthesis_mesh::Mesh;
use eframe::egui::{self, Color32, DragValue, RichText};
use glam::{DVec2, DVec3};

use super::background::Background;
use super::command::{Command, ProjectEdit};
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

/// The PDE editor's and the scan review's state.
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

    /// The scanned petal under review.
    pub fn scan(&self) -> Option<&ScanReview> {
        self.scan.as_ref()
    }
}

/// A scanned petal under review.
#[derive(Debug)]
pub struct ScanReview {
    /// The file and the template name it gives.
    path: PathBuf,
    name: String,
    mesh: Arc<Mesh>,
    outline: ScanOutline,
    /// The corners in use (found, or moved by the user).
    corners: ScanCorners,
    /// The corners found automatically.
    detected: ScanCorners,
    flip: bool,
    /// The edge to mesh at (the petal's length / 36 once fitted, until
    /// the user sets one).
    edge: f64,
    edge_set: bool,
    /// The corner a click on the outline moves: 0, 1 the base's, 2, 3 the
    /// tip's ends.
    moving: usize,
    /// The last fit, or why there is none.
    fit: Result<ScanFit, String>,
    /// A fit to start (the corners or the inner side changed).
    fit_needed: bool,
    /// The fit being made on its own thread.
    fitting: Option<Background<ScanFit, String>>,
    /// The mesh of the fit at the edge.
    built: Option<(u64, Result<Bud, String>)>,
    /// The frame the view draws in (the last fit's).
    view: Option<(glam::DMat3, DVec3)>,
    /// Where the outline's vertices were drawn.
    on_screen: Vec<egui::Pos2>,
}

impl ScanReview {
    /// Reads the scan at `path` and finds its outline and corners; the
    /// fit is made on a thread of its own once the review is shown.
    /// `edge` is the edge offered until the fit gives the petal's length.
    /// Also what the reader said about the file (statements read past,
    /// vertices joined).
    pub fn read(path: &Path, edge: f64) -> Result<(ScanReview, Vec<String>), String> {
        let file = anthesis_mesh::load_obj_shape(path).map_err(|e| e.to_string())?;
        let notes = file.warnings.iter().map(|w| w.to_string()).collect();
        let mesh = file.mesh;
        let outline = ScanOutline::of(&mesh).map_err(|e| e.to_string())?;
        let detected = outline.detect_corners(&mesh);
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().trim().to_string())
            .filter(|s| !s.is_empty())
            .unwrap_or_else(|| "scanned".to_string());
        Ok((
            ScanReview {
                path: path.to_path_buf(),
                name,
                mesh: Arc::new(mesh),
                outline,
                corners: detected,
                detected,
                flip: false,
                edge,
                edge_set: false,
                moving: 0,
                fit: Err("not fitted yet".to_string()),
                fit_needed: true,
                fitting: None,
                built: None,
                view: None,
                on_screen: Vec::new(),
            },
            notes,
        ))
    }

    /// Fits again with the current corners and inner side (on the next
    /// frame; a fit under way is dropped).
    fn refit(&mut self) {
        self.fit_needed = true;
        self.fitting = None;
        self.built = None;
    }

    /// Starts the fit that is needed and takes the answer of the one under
    /// way; `ctx` is asked for a frame when it is done.
    fn poll(&mut self, ctx: &egui::Context) {
        if std::mem::take(&mut self.fit_needed) {
            let options = ScanFitOptions {
                flip_inner_side: self.flip,
                ..ScanFitOptions::default()
            };
            let (mesh, corners) = (Arc::clone(&self.mesh), self.corners);
            self.fitting = Some(Background::start(
                "anthesis-scan-fit",
                "the fit",
                |message| message,
                ctx,
                move || {
                    anthesis_bud::fit_scan(&mesh, Some(corners), &options)
                        .map_err(|e| e.to_string())
                },
            ));
        }
        if let Some(fitting) = &mut self.fitting {
            fitting.poll();
            let Some(Background::Done(answer)) = self.fitting.take_if(|f| f.answer().is_some())
            else {
                return;
            };
            if let Ok(fit) = &answer {
                self.view = Some((fit.rotation, fit.origin));
                // An edge for about 36 rows along the petal (the lily's
                // 1.3 for its 47).
                if !self.edge_set {
                    self.edge = fit.length / 36.0;
                }
            }
            self.fit = answer;
            self.built = None;
        }
    }

    /// The fit, or why there is none; `None` while it is being made.
    pub fn fit(&self) -> Option<Result<&ScanFit, &str>> {
        if self.fit_needed || self.fitting.is_some() {
            return None;
        }
        Some(self.fit.as_ref().map_err(String::as_str))
    }

    /// The corners in use and the ones found automatically.
    pub fn corners(&self) -> (ScanCorners, ScanCorners) {
        (self.corners, self.detected)
    }

    /// Where the outline's vertex at loop position `k` was drawn.
    pub fn outline_on_screen(&self, k: usize) -> Option<egui::Pos2> {
        self.on_screen.get(k).copied()
    }

    /// The outline (loop positions to mesh vertices).
    pub fn outline(&self) -> &ScanOutline {
        &self.outline
    }

    /// The scan as read.
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
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
/// is the Shape section's remesh edge.
pub fn pde_ui(
    ui: &mut egui::Ui,
    (flower, index): (&Flower, usize),
    saved: PdeSweep,
    edge: f64,
    state: &mut PdeState,
    commands: &mut Vec<Command>,
) {
    let name = flower.templates[index].name.clone();
    let mut sweep = match state.drafts.get(&name) {
        Some((from, draft)) if *from == saved => *draft,
        _ => saved,
    };
    let before = sweep;
    ui.strong("PDE surface").on_hover_text(
        "A sweep between the two margins (curves from the base to the tip) meeting them with \
         the across-tangents drawn as handles (pde-surfaces-lily.txt eq. 12). Drag a point or \
         a handle's head, or type the chosen point's numbers; Apply surface meshes it at the \
         remesh edge above.",
    );
    let mut symmetric = !state.asymmetric;
    ui.horizontal(|ui| {
        ui.checkbox(&mut symmetric, "symmetric about the midrib")
            .on_hover_text("A point's mirror image across the midrib moves with it");
        ui.selectable_value(&mut state.side_view, false, "front")
            .on_hover_text("Looking at the inner side: x across, y from base to tip");
        ui.selectable_value(&mut state.side_view, true, "side")
            .on_hover_text("From the side: z across, y from base to tip");
    });
    state.asymmetric = !symmetric;
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
    let lines = 8;
    let samples = 24;
    let iso: Vec<Vec<DVec3>> = (0..=lines)
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
        .collect();
    let (mut low, mut high) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for p in handled.iter().flatten().chain(iso.iter().flatten()) {
        low = low.min(flat(*p));
        high = high.max(flat(*p));
    }
    let size = egui::vec2(ui.available_width().max(120.0), 240.0);
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
    if let Some((c, k, shift)) = moved {
        let curve = SweepCurve::ALL[c];
        // A handle's head moves the tangent three times as far (the other
        // way at margin 2, whose handle is C1 − T1/3).
        let value = match curve {
            SweepCurve::Margin0 | SweepCurve::Margin1 => sweep.curve(curve).control[k] + shift,
            SweepCurve::Tangent0 => sweep.curve(curve).control[k] + 3.0 * shift,
            SweepCurve::Tangent1 => sweep.curve(curve).control[k] - 3.0 * shift,
        };
        sweep = sweep.with_point(curve, k, value, symmetric);
    }

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
            typed |= ui
                .add(DragValue::new(value).speed(0.05).max_decimals(3))
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
        if ui
            .add(
                egui::Slider::new(&mut lambda, 0.0..=anthesis_bud::MAX_STRETCH_TO_BEND)
                    .logarithmic(true)
                    .smallest_positive(0.01),
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

/// The corner names of the scan review.
const CORNER_NAMES: [&str; 4] = ["base corner 1", "base corner 2", "tip", "tip end 2"];

/// The review of a scanned petal, when one is open; returns the flower
/// with the new template when it is made.
pub fn scan_ui(
    ui: &mut egui::Ui,
    flower: &Flower,
    state: &mut PdeState,
    commands: &mut Vec<Command>,
) -> Option<usize> {
    let review = state.scan.as_mut()?;
    review.poll(ui.ctx());
    let mut made = None;
    let mut close = false;
    ui.group(|ui| {
        let file = review.path.file_name().map_or_else(
            || review.path.display().to_string(),
            |f| f.to_string_lossy().into_owned(),
        );
        ui.strong(format!("Scanned petal: {file}"))
            .on_hover_text(format!(
                "{}\n\nThe scan's outline seen from its inner side, with its base (the two base \
                 corners, orange) and tip (magenta). Choose a corner and click on the outline to \
                 move it; the surface (grey lines) is fitted again.",
                review.path.display()
            ));
        ui.label(format!(
            "{} vertices, {} triangles, outline of {} vertices",
            review.mesh.vertex_count(),
            review.mesh.triangle_count(),
            review.outline.len()
        ));
        let mut changed = false;
        ui.horizontal(|ui| {
            let label = ui.label("move").id;
            let pointed = review.corners.pointed();
            egui::ComboBox::from_id_salt("scan corner")
                .selected_text(CORNER_NAMES[review.moving])
                .show_ui(ui, |ui| {
                    for (k, name) in CORNER_NAMES.iter().enumerate() {
                        if k == 3 && pointed {
                            continue;
                        }
                        ui.selectable_value(&mut review.moving, k, *name);
                    }
                })
                .response
                .labelled_by(label);
            let mut rounded = !pointed;
            if ui
                .checkbox(&mut rounded, "tip is a span")
                .on_hover_text("Off: the tip is one point (a pointed petal)")
                .changed()
            {
                let n = review.outline.len();
                let t = review.corners.tip[0];
                review.corners.tip = if rounded {
                    [t, (t + (n / 20).max(1)) % n]
                } else {
                    [t, t]
                };
                if !rounded && review.moving == 3 {
                    review.moving = 2;
                }
                changed = true;
            }
            if ui
                .button("Found corners")
                .on_hover_text("Back to the base and tip found automatically")
                .clicked()
            {
                review.corners = review.detected;
                changed = true;
            }
        });
        if review.moving == 3 && review.corners.pointed() {
            review.moving = 2;
        }

        // The view.
        let (rotation, origin) = review.view.unwrap_or((glam::DMat3::IDENTITY, DVec3::ZERO));
        let flat: Vec<DVec2> = review
            .outline
            .vertices
            .iter()
            .map(|&v| {
                let p = rotation * (review.mesh.positions[v as usize] - origin);
                DVec2::new(p.x, p.y)
            })
            .collect();
        let (mut low, mut high) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for p in &flat {
            low = low.min(*p);
            high = high.max(*p);
        }
        let size = egui::vec2(ui.available_width().max(120.0), 220.0);
        let (response, painter) = ui.allocate_painter(size, egui::Sense::click());
        let rect = response.rect.shrink(14.0);
        let extent = (high - low).max(DVec2::splat(1e-6));
        let scale = (f64::from(rect.width()) / extent.x).min(f64::from(rect.height()) / extent.y);
        let middle = (low + high) * 0.5;
        let to_screen = |q: DVec2| {
            let q = q - middle;
            egui::pos2(
                rect.center().x + (q.x * scale) as f32,
                rect.center().y - (q.y * scale) as f32,
            )
        };
        painter.rect_filled(response.rect, 4.0, ui.visuals().extreme_bg_color);
        review.on_screen = flat.iter().map(|q| to_screen(*q)).collect();
        // The fitted surface's iso-lines, faint.
        if let Ok(fit) = &review.fit {
            let into_view = |p: DVec3| {
                // The fit is in its own template frame; the view is the
                // last fit's, which is this one.
                to_screen(DVec2::new(p.x, p.y))
            };
            let lines = 6;
            for i in 0..=lines {
                let points: Vec<egui::Pos2> = (0..=20)
                    .map(|j| {
                        into_view(
                            fit.sweep
                                .point(DVec2::new(i as f64 / lines as f64, j as f64 / 20.0)),
                        )
                    })
                    .collect();
                painter.add(egui::Shape::line(
                    points,
                    egui::Stroke::new(1.0, ui.visuals().weak_text_color()),
                ));
            }
        }
        // The outline, its spans coloured: base, margins, tip.
        let n = review.outline.len();
        let [b0, b1] = review.corners.base;
        let [t0, t1] = review.corners.tip;
        let steps = |k: usize| (k + n - b0) % n;
        let base_colour = Color32::from_rgb(240, 170, 60);
        let tip_colour = Color32::from_rgb(220, 90, 200);
        let margin_colour = Color32::from_rgb(120, 170, 255);
        for k in 0..n {
            let s = steps(k);
            let colour = if s < steps(b1) {
                base_colour
            } else if s >= steps(t0) && s < steps(t1) {
                tip_colour
            } else {
                margin_colour
            };
            painter.line_segment(
                [review.on_screen[k], review.on_screen[(k + 1) % n]],
                egui::Stroke::new(2.0, colour),
            );
        }
        for (k, corner) in [b0, b1, t0, t1].iter().enumerate() {
            let colour = if k < 2 { base_colour } else { tip_colour };
            let radius = if k == review.moving { 6.0 } else { 4.0 };
            painter.circle_filled(review.on_screen[*corner], radius, colour);
        }
        if response.clicked()
            && let Some(at) = response.interact_pointer_pos()
        {
            let nearest = (0..n).min_by(|&a, &b| {
                review.on_screen[a]
                    .distance_sq(at)
                    .total_cmp(&review.on_screen[b].distance_sq(at))
            });
            if let Some(k) = nearest {
                match review.moving {
                    0 => review.corners.base[0] = k,
                    1 => review.corners.base[1] = k,
                    2 if review.corners.pointed() => review.corners.tip = [k, k],
                    2 => review.corners.tip[0] = k,
                    _ => review.corners.tip[1] = k,
                }
                changed = true;
            }
        }
        ui.horizontal(|ui| {
            if ui
                .checkbox(&mut review.flip, "inner side convex")
                .on_hover_text(
                    "Off: the side the scan is concave to is the inner (adaxial) side, facing \
                     the flower's axis",
                )
                .changed()
            {
                changed = true;
            }
            let label = ui.label("edge").id;
            let speed = (review.edge * 0.01).max(1e-4);
            if ui
                .add(
                    DragValue::new(&mut review.edge)
                        .range(1e-4..=1e4)
                        .speed(speed)
                        .max_decimals(4),
                )
                .labelled_by(label)
                .changed()
            {
                review.edge_set = true;
                review.built = None;
            }
        });
        if changed {
            review.refit();
            // The fit starts in the next frame.
            ui.ctx().request_repaint();
        }
        let fitting = review.fit_needed || review.fitting.is_some();
        match &review.fit {
            // No spinner: it would ask for frames all the time; the fit's
            // thread asks for one when it is done.
            _ if fitting => {
                ui.label("fitting…");
            }
            Ok(fit) => {
                let [rms, max] = fit.relative_scan_to_surface();
                let [back_rms, back_max] = fit.relative_surface_to_scan();
                ui.label(format!(
                    "fit error: RMS {:.2} %, max {:.2} % of the length {:.3} (surface to scan: \
                     RMS {:.2} %, max {:.2} %)",
                    100.0 * rms,
                    100.0 * max,
                    fit.length,
                    100.0 * back_rms,
                    100.0 * back_max
                ));
                let key = edge_bits(review.edge);
                if review.built.as_ref().is_none_or(|(k, _)| *k != key) {
                    let built =
                        anthesis_bud::build_organ(&fit.sweep, &RemeshOptions::new(review.edge))
                            .map_err(|e| e.to_string());
                    review.built = Some((key, built));
                }
            }
            Err(e) => {
                ui.label(
                    RichText::new(format!("cannot fit: {e}")).color(ui.visuals().error_fg_color),
                );
            }
        }
        let mut refused = None;
        ui.horizontal(|ui| {
            match (&review.fit, review.built.as_ref().map(|(_, b)| b)) {
                _ if fitting => {}
                (Ok(fit), Some(Ok(bud))) => {
                    ui.label(format!("meshed: {}", quality_text(&bud.quality)));
                    if ui
                        .button("Make template")
                        .on_hover_text(
                            "A new template of the fitted surface (a PDE petal, to edit again) \
                             with uniform maps and one organ (one undo step)",
                        )
                        .clicked()
                    {
                        let mut template = anthesis_garden::five_petal::simple_template_of_mesh(
                            &review.name,
                            bud.mesh.clone(),
                        );
                        template.source = Some(TemplateSource::Pde {
                            sweep: fit.sweep,
                            edge: review.edge,
                        });
                        match flower.with_template_and_organ(template) {
                            Ok(added) => {
                                let index = added.templates.len() - 1;
                                commands.push(Command::Edit {
                                    label: format!(
                                        "import scanned petal {}",
                                        added.templates[index].name
                                    ),
                                    edit: ProjectEdit::Flower(Box::new(added)),
                                });
                                made = Some(index);
                                close = true;
                            }
                            Err(e) => refused = Some(e.to_string()),
                        }
                    }
                }
                (Ok(_), Some(Err(e))) => {
                    ui.label(
                        RichText::new(format!("cannot mesh: {e}"))
                            .color(ui.visuals().error_fg_color),
                    );
                }
                _ => {}
            }
            if ui.button("Cancel scan").clicked() {
                close = true;
            }
        });
        if let Some(e) = refused {
            review.built = Some((edge_bits(review.edge), Err(e)));
        }
    });
    if close {
        state.scan = None;
    }
    made
}

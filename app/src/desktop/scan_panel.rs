//! The review of a scanned petal in the Flower panel (issue 14 item 6),
//! before it becomes a template.
//!
//! **Scanned petal.** "Import scanned petal…" reads an OBJ without UVs
//! (`anthesis_mesh::load_obj_shape`), finds its outline's base and tip and
//! fits a sweep (`anthesis_bud::fit_scan`). The review shows the outline
//! with the base corners and the tip; choosing a corner and clicking on
//! the outline moves it, and the fit is made again. The fit error is shown
//! as a fraction of the petal's length; **Make template** adds the
//! template (PDE source, so it can be edited again) with one organ, in one
//! undo step.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anthesis_bud::{
    Bud, RemeshOptions, ScanCorners, ScanFit, ScanFitOptions, ScanOutline, Surface,
};
use anthesis_flower::{Flower, TemplateSource};
use anthesis_mesh::Mesh;
use eframe::egui::{self, Color32, RichText};
use glam::{DVec2, DVec3};

use super::background::Background;
use super::command::{Command, ProjectEdit};
use super::widgets::quality_text;

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

/// The corner names of the scan review.
const CORNER_NAMES: [&str; 4] = ["base corner 1", "base corner 2", "tip", "tip end 2"];

/// The review of a scanned petal, when one is open; returns the flower
/// with the new template when it is made.
pub fn scan_ui(
    ui: &mut egui::Ui,
    flower: &Flower,
    scan: &mut Option<ScanReview>,
    commands: &mut Vec<Command>,
) -> Option<usize> {
    let review = scan.as_mut()?;
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
        corner_row(ui, review, &mut changed);
        if review.moving == 3 && review.corners.pointed() {
            review.moving = 2;
        }

        outline_view(ui, review, &mut changed);
        ui.horizontal_wrapped(|ui| {
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
            if super::checked_field::checked_with(ui, "edge", &mut review.edge, 1e-4..=1e4, |d| {
                d.speed(speed).max_decimals(4)
            })
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
                let key = review.edge.to_bits();
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
        make_row(
            ui,
            flower,
            review,
            fitting,
            commands,
            (&mut made, &mut close),
        );
    });
    if close {
        *scan = None;
    }
    made
}

/// The row that chooses the corner a click moves, whether the tip is a
/// span, and goes back to the corners found; sets `changed` when the
/// corners changed.
fn corner_row(ui: &mut egui::Ui, review: &mut ScanReview, changed: &mut bool) {
    ui.horizontal_wrapped(|ui| {
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
            *changed = true;
        }
        if ui
            .button("Found corners")
            .on_hover_text("Back to the base and tip found automatically")
            .clicked()
        {
            review.corners = review.detected;
            *changed = true;
        }
    });
}

/// The scan seen from its fitted frame: the fitted surface's iso-lines,
/// the outline coloured by span with its corners; a click on the outline
/// moves the chosen corner there (and sets `changed`).
fn outline_view(ui: &mut egui::Ui, review: &mut ScanReview, changed: &mut bool) {
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
            *changed = true;
        }
    }
}

/// The fit's mesh numbers with "Make template" (which sets `made` to the
/// new template and `close`), or why it cannot be meshed, and "Cancel
/// scan" (which sets `close`).
fn make_row(
    ui: &mut egui::Ui,
    flower: &Flower,
    review: &mut ScanReview,
    fitting: bool,
    commands: &mut Vec<Command>,
    (made, close): (&mut Option<usize>, &mut bool),
) {
    let mut refused = None;
    ui.horizontal_wrapped(|ui| {
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
                            *made = Some(index);
                            *close = true;
                        }
                        Err(e) => refused = Some(e.to_string()),
                    }
                }
            }
            (Ok(_), Some(Err(e))) => {
                ui.label(
                    RichText::new(format!("cannot mesh: {e}")).color(ui.visuals().error_fg_color),
                );
            }
            _ => {}
        }
        if ui.button("Cancel scan").clicked() {
            *close = true;
        }
    });
    if let Some(e) = refused {
        review.built = Some((review.edge.to_bits(), Err(e)));
    }
}

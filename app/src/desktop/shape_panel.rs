//! The Flower panel's Shape section: one template's mesh remeshed at a
//! mean edge the user picks, with the particle count and the mesh quality
//! of the new mesh shown before it is accepted, and which side of it is
//! the inner one (with a flip when an import came in the wrong way).
//!
//! The remeshing is `anthesis_bud::remesh_mesh`'s (the mesh is remeshed
//! through its UV layout, so the painted maps stay valid); it runs on a
//! thread of its own and the section shows the answer when it comes.
//! Accepting is one [`ProjectEdit::Mesh`].

use std::collections::BTreeMap;

use anthesis_bud::{BezierPatch, Bud, BudError, MeshQuality, RemeshOptions};
use anthesis_flower::{Flower, TemplateSource};
use anthesis_mesh::Mesh;
use eframe::egui::{self, Color32, RichText};
use glam::DVec3;

use super::background::Background;
use super::checked_field::checked_with;
use super::command::{Command, ProjectEdit};
use super::widgets::{quality_text, view_point};

/// What the remesher said about one template at one edge.
type Preview = Background<Bud, BudError>;

/// A remesh that could not give a mesh, as the remesher's error.
fn remesh_failed(message: String) -> BudError {
    BudError::InvalidMesh(anthesis_mesh::MeshError::Io(message))
}

/// The Shape section's state.
#[derive(Debug, Default)]
pub struct ShapeState {
    /// The template shown.
    pub(super) template: usize,
    /// The mean edge to remesh at (`None`: the template's own).
    pub(super) edge: Option<f64>,
    /// The preview and what it was made of: template, edge, mesh.
    preview: Option<((usize, u64, u64), Preview)>,
    /// The template's own mesh quality, and the mesh it was measured on.
    current: Option<(u64, MeshQuality)>,
    /// Open the section in the next frame (a template was just made).
    pub(super) open_now: bool,
    /// The Bézier nets being edited, by template name: the template's
    /// saved net they started from, and the net as edited (applied to the
    /// template with "Apply net"). A saved net that changed (an undo, a
    /// project opened) replaces the draft.
    drafts: BTreeMap<String, (BezierPatch, BezierPatch)>,
    /// The control point being edited: row (base to tip), column.
    point: (usize, usize),
    /// Edit each point alone (off: its mirror image about the midrib
    /// follows).
    asymmetric: bool,
    /// The 2D view looks from the side (z, y) instead of the front (x, y).
    side_view: bool,
    /// Where the control points were drawn in the last frame.
    on_screen: Option<[[egui::Pos2; 4]; 4]>,
    /// Why the net could not be meshed.
    net_error: Option<String>,
    /// The PDE editor and the scanned petal review.
    pub(super) pde: super::pde_panel::PdeState,
    /// The sketched petal editor.
    pub(super) sketch: super::sketch_panel::SketchState,
}

impl ShapeState {
    /// The Bézier net of the template named `name` as edited, once the
    /// section has shown it.
    pub fn net(&self, name: &str) -> Option<&BezierPatch> {
        self.drafts.get(name).map(|(_, draft)| draft)
    }

    /// Where control point `(row, column)` was drawn in the 2D view.
    pub fn control_point_on_screen(&self, row: usize, column: usize) -> Option<egui::Pos2> {
        self.on_screen
            .and_then(|p| p.get(row).and_then(|r| r.get(column)).copied())
    }

    /// Why the net could not be meshed, if it could not.
    pub fn net_error(&self) -> Option<&str> {
        self.net_error.as_deref()
    }

    /// The PDE editor's and the scan review's state.
    pub fn pde(&self) -> &super::pde_panel::PdeState {
        &self.pde
    }

    /// The sketched petal editor's state.
    pub fn sketch(&self) -> &super::sketch_panel::SketchState {
        &self.sketch
    }

    /// The template the section shows.
    pub fn template(&self) -> usize {
        self.template
    }

    /// The previewed remesh: the particle count and quality, or why the
    /// shape cannot be meshed; `None` while it is being computed or when
    /// there is none.
    pub fn preview(&self) -> Option<Result<&MeshQuality, String>> {
        match self.preview.as_ref().and_then(|(_, p)| p.answer())? {
            Ok(bud) => Some(Ok(&bud.quality)),
            Err(e) => Some(Err(e.to_string())),
        }
    }
}

/// A fingerprint of a mesh: whether the preview was made of this one.
fn fingerprint(mesh: &Mesh) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for p in &mesh.positions {
        p.to_array().map(f64::to_bits).hash(&mut h);
    }
    for uv in &mesh.uvs {
        uv.to_array().map(f64::to_bits).hash(&mut h);
    }
    mesh.triangles.hash(&mut h);
    h.finish()
}

/// The Shape section for the flower's templates; pushes the edits chosen
/// onto `commands`.
pub fn shape_ui(
    ui: &mut egui::Ui,
    flower: &Flower,
    state: &mut ShapeState,
    commands: &mut Vec<Command>,
) {
    if flower.templates.is_empty() {
        return;
    }
    let open = std::mem::take(&mut state.open_now).then_some(true);
    egui::CollapsingHeader::new("Shape")
        .id_salt("template shape")
        .open(open)
        .show(ui, |ui| shape_rows(ui, flower, state, commands))
        .header_response
        .on_hover_text(
            "One template's mesh: remesh it at another mean edge (its painted maps stay, they \
             live in UV space) and see which side is its inner one.",
        );
}

/// The Shape section's rows (while it is open: only then is a preview
/// computed).
fn shape_rows(
    ui: &mut egui::Ui,
    flower: &Flower,
    state: &mut ShapeState,
    commands: &mut Vec<Command>,
) {
    // Not written back when clamped: a template added this frame is in
    // the flower from the next one.
    let before = state.template.min(flower.templates.len() - 1);
    let mut index = before;
    ui.horizontal(|ui| {
        let label = ui.label("template").id;
        let selected = flower.templates[index].name.as_str();
        egui::ComboBox::from_id_salt("shape template")
            .selected_text(selected)
            .show_ui(ui, |ui| {
                for (i, t) in flower.templates.iter().enumerate() {
                    ui.selectable_value(&mut index, i, &t.name);
                }
            })
            .response
            .labelled_by(label);
    });
    if index != before {
        state.template = index;
        state.edge = None;
    }
    let template = &flower.templates[index];
    let mesh = &template.mesh;
    let print = fingerprint(mesh);
    let current = match state.current {
        Some((p, q)) if p == print => q,
        _ => {
            let q = anthesis_bud::quality(mesh);
            state.current = Some((print, q));
            q
        }
    };
    ui.label(format!("now: {}", quality_text(&current)));

    inner_side_row(ui, (template, index), commands);

    // Remeshing.
    let mut edge = state.edge.unwrap_or(current.mean_edge);
    ui.horizontal(|ui| {
        let label = ui
            .label("remesh edge")
            .on_hover_text("The mean edge length to remesh at, in project units");
        let speed = (edge * 0.01).max(1e-4);
        if checked_with(ui, "remesh edge", &mut edge, 1e-4..=1e4, |d| {
            d.speed(speed).max_decimals(4)
        })
        .labelled_by(label.id)
        .changed()
        {
            state.edge = Some(edge);
        }
    });
    let key = (index, edge.to_bits(), print);
    if state.preview.as_ref().is_none_or(|(k, _)| *k != key) {
        let owned = mesh.clone();
        let preview = Background::start(
            "anthesis-remesh-preview",
            "the remesher",
            remesh_failed,
            ui.ctx(),
            move || anthesis_bud::remesh_mesh(&owned, &RemeshOptions::new(edge)),
        );
        state.preview = Some((key, preview));
    }
    if let Some((_, preview)) = &mut state.preview {
        preview.poll();
    }
    remesh_result(ui, (flower, index), edge, state, commands);
    if let Some(TemplateSource::Bezier { net: saved, .. }) = &template.source {
        let saved = *saved;
        let draft = match state.drafts.get(&template.name) {
            Some((from, draft)) if *from == saved => *draft,
            _ => saved,
        };
        state.drafts.insert(template.name.clone(), (saved, draft));
        ui.separator();
        bezier_ui(ui, (flower, index), draft, edge, state, commands);
    } else if let Some(TemplateSource::Pde { sweep, .. }) = template.source {
        state.on_screen = None;
        ui.separator();
        super::pde_panel::pde_ui(ui, (flower, index), sweep, edge, &mut state.pde, commands);
    } else {
        state.on_screen = None;
        ui.separator();
        super::sketch_panel::sketch_ui(ui, (flower, index), edge, &mut state.sketch, commands);
    }
}

/// Which side of template `index` is inner, with a button that flips it
/// when it faces the wrong way (one undo step).
fn inner_side_row(
    ui: &mut egui::Ui,
    (template, index): (&anthesis_flower::Template, usize),
    commands: &mut Vec<Command>,
) {
    let mesh = &template.mesh;
    ui.horizontal_wrapped(|ui| {
        match anthesis_bud::inner_side_faces_minus_z(mesh) {
            Some(true) => ui.label("inner side: −Z (the template frame's inner side)"),
            Some(false) => ui.label(
                RichText::new("inner side: +Z (the template frame wants −Z: flip it?)")
                    .color(ui.visuals().warn_fg_color),
            ),
            None => ui.label("inner side: edge-on to Z (no side faces the axis)"),
        }
        .on_hover_text(
            "The side the triangles wind counter-clockwise around: the organ's inner (adaxial) \
             side, which the growth maps' 'in' layers belong to.",
        );
        if ui
            .button("Flip inner side")
            .on_hover_text("Wind every triangle the other way (one undo step)")
            .clicked()
        {
            commands.push(Command::Edit {
                label: format!("flip inner side of {}", template.name),
                edit: ProjectEdit::Mesh {
                    template: index,
                    mesh: Box::new(anthesis_bud::with_inner_side_flipped(mesh)),
                },
            });
        }
    });
}

/// The remeshed preview's numbers with "Remesh" (one undo step), or why
/// the template cannot be remeshed at `edge`.
fn remesh_result(
    ui: &mut egui::Ui,
    (flower, index): (&Flower, usize),
    edge: f64,
    state: &ShapeState,
    commands: &mut Vec<Command>,
) {
    let template = &flower.templates[index];
    match state.preview.as_ref().and_then(|(_, p)| p.answer()) {
        Some(Ok(bud)) => {
            ui.label(format!("remeshed: {}", quality_text(&bud.quality)));
            if ui
                .button("Remesh")
                .on_hover_text("Use this mesh for the template (its maps stay; one undo step)")
                .clicked()
            {
                let label = format!("remesh {} at edge {edge}", template.name);
                let edit = match &template.source {
                    // A shape made in the app remembers the edge it is
                    // meshed at, so editing it again keeps that.
                    Some(source) => {
                        let mut edited = flower.clone();
                        edited.templates[index].mesh = bud.mesh.clone();
                        edited.templates[index].source = Some(source.with_edge(edge));
                        ProjectEdit::Flower(Box::new(edited))
                    }
                    None => ProjectEdit::Mesh {
                        template: index,
                        mesh: Box::new(bud.mesh.clone()),
                    },
                };
                commands.push(Command::Edit { label, edit });
            }
        }
        Some(Err(e)) => {
            ui.label(
                RichText::new(format!("cannot remesh: {e}")).color(ui.visuals().error_fg_color),
            );
        }
        // No spinner: it would ask for frames all the time; the remesher's
        // thread asks for one when it is done.
        None => {
            ui.label("remeshing…");
        }
    }
}

/// The names of a net's rows, base to tip.
const ROW_NAMES: [&str; 4] = ["base", "lower", "upper", "tip"];

/// The Bézier net editor of template `index` (named `name`): the net in a
/// 2D view (front or side) whose points can be dragged, the chosen point's
/// coordinates typed in, and "Apply net", which meshes the patch at
/// `edge` and replaces the template's mesh (one undo step; the maps stay).
fn bezier_ui(
    ui: &mut egui::Ui,
    (flower, index): (&Flower, usize),
    mut net: BezierPatch,
    edge: f64,
    state: &mut ShapeState,
    commands: &mut Vec<Command>,
) {
    let name = flower.templates[index].name.as_str();
    ui.strong("Bézier net").on_hover_text(
        "The 4×4 control net of the bicubic patch: rows from the base to the tip, columns \
         across (the midrib between the middle two). Drag a point in the view or type its \
         coordinates; Apply net remeshes the petal at the remesh edge above.",
    );
    let before = net;
    let mut symmetric = !state.asymmetric;
    ui.horizontal_wrapped(|ui| {
        ui.checkbox(&mut symmetric, "symmetric about the midrib")
            .on_hover_text("A point's mirror image across the midrib moves with it");
        ui.selectable_value(&mut state.side_view, false, "front")
            .on_hover_text("Looking at the inner side: x across, y from base to tip");
        ui.selectable_value(&mut state.side_view, true, "side")
            .on_hover_text("From the side: z (inner side to the left), y from base to tip");
    });
    state.asymmetric = !symmetric;
    let (row, column) = state.point;

    net = net_view(ui, state, net, symmetric);

    // The chosen point's coordinates.
    ui.horizontal(|ui| {
        let label = ui.label("control point").id;
        egui::ComboBox::from_id_salt("bezier point")
            .selected_text(format!("{} row, column {}", ROW_NAMES[row], column + 1))
            .show_ui(ui, |ui| {
                for (j, name) in ROW_NAMES.iter().enumerate() {
                    for i in 0..4 {
                        ui.selectable_value(
                            &mut state.point,
                            (j, i),
                            format!("{name} row, column {}", i + 1),
                        );
                    }
                }
            })
            .response
            .labelled_by(label);
    });
    let (row, column) = state.point;
    let mut p = net.control[row][column];
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
    });
    if typed {
        net = net.with_point(row, column, p, symmetric);
    }
    if net != before
        && let Some((_, draft)) = state.drafts.get_mut(name)
    {
        *draft = net;
    }

    if ui
        .button("Apply net")
        .on_hover_text(
            "Mesh the patch at the remesh edge and use it for the template (one undo step)",
        )
        .clicked()
    {
        match anthesis_bud::build_organ(&net, &RemeshOptions::new(edge)) {
            Ok(bud) => {
                // The mesh and the net it was made of, in one step.
                match flower.with_shape(index, bud.mesh, TemplateSource::Bezier { net, edge }) {
                    Ok(edited) => {
                        state.net_error = None;
                        commands.push(Command::Edit {
                            label: format!("Bézier net of {name}"),
                            edit: ProjectEdit::Flower(Box::new(edited)),
                        });
                    }
                    Err(e) => state.net_error = Some(format!("cannot use the net: {e}")),
                }
            }
            Err(e) => state.net_error = Some(format!("cannot mesh the net: {e}")),
        }
    }
    if let Some(error) = &state.net_error {
        ui.label(RichText::new(error).color(ui.visuals().error_fg_color));
    }
}

/// The 2D view of the net, front (x, y) or side (z, y): its rows and
/// columns, the midrib plane, its control points; returns the net with the
/// point dragged moved (and its mirror image when `symmetric`).
fn net_view(
    ui: &mut egui::Ui,
    state: &mut ShapeState,
    mut net: BezierPatch,
    symmetric: bool,
) -> BezierPatch {
    // The 2D view.
    let across = |p: DVec3, side: bool| if side { p.z } else { p.x };
    let side = state.side_view;
    let (mut low, mut high) = (
        glam::DVec2::splat(f64::INFINITY),
        glam::DVec2::splat(f64::NEG_INFINITY),
    );
    for p in net.control.iter().flatten() {
        let q = glam::DVec2::new(across(*p, side), p.y);
        low = low.min(q);
        high = high.max(q);
    }
    let size = egui::vec2(ui.available_width().max(120.0), 220.0);
    let (response, painter) = ui.allocate_painter(size, egui::Sense::hover());
    let rect = response.rect.shrink(14.0);
    let extent = (high - low).max(glam::DVec2::splat(1e-6));
    let scale = (f64::from(rect.width()) / extent.x).min(f64::from(rect.height()) / extent.y);
    let middle = (low + high) * 0.5;
    let to_screen = |p: DVec3| {
        let q = glam::DVec2::new(across(p, side), p.y) - middle;
        egui::pos2(
            rect.center().x + (q.x * scale) as f32,
            rect.center().y - (q.y * scale) as f32,
        )
    };
    painter.rect_filled(response.rect, 4.0, ui.visuals().extreme_bg_color);
    let line = egui::Stroke::new(1.0, ui.visuals().weak_text_color());
    let points = net.control.map(|r| r.map(to_screen));
    for j in 0..4 {
        for i in 0..4 {
            if i < 3 {
                painter.line_segment([points[j][i], points[j][i + 1]], line);
            }
            if j < 3 {
                painter.line_segment([points[j][i], points[j + 1][i]], line);
            }
        }
    }
    // The midrib plane in the front view.
    if !side {
        let x = to_screen(DVec3::ZERO).x;
        painter.line_segment(
            [egui::pos2(x, rect.top()), egui::pos2(x, rect.bottom())],
            egui::Stroke::new(1.0, Color32::from_rgb(90, 140, 90)),
        );
    }
    let mut moved = None;
    for (j, r) in points.iter().enumerate() {
        for (i, at) in r.iter().enumerate() {
            let id = ui.scope_id().with(("bezier point", j, i));
            let (picked, shift) = view_point(ui, id, *at, 14.0, (scale, side));
            if picked {
                state.point = (j, i);
            }
            if let Some(shift) = shift {
                moved = Some((j, i, net.control[j][i] + shift));
            }
            let chosen = state.point == (j, i);
            let colour = if chosen {
                Color32::from_rgb(255, 170, 40)
            } else {
                ui.visuals().strong_text_color()
            };
            painter.circle_filled(*at, if chosen { 5.0 } else { 4.0 }, colour);
        }
    }
    state.on_screen = Some(points);
    if let Some((j, i, q)) = moved {
        net = net.with_point(j, i, q, symmetric);
    }
    net
}

//! The Flower panel's Shape section: one template's mesh remeshed at a
//! mean edge the user picks, with the particle count and the mesh quality
//! of the new mesh shown before it is accepted, and which side of it is
//! the inner one (with a flip when an import came in the wrong way).
//!
//! The remeshing is `anthesis_bud::remesh_mesh`'s (the mesh is remeshed
//! through its UV layout, so the painted maps stay valid); it runs on a
//! thread of its own and the section shows the answer when it comes.
//! Accepting is one [`ProjectEdit::Mesh`].

use std::sync::mpsc::{Receiver, TryRecvError, sync_channel};

use anthesis_bud::{Bud, BudError, MeshQuality, RemeshOptions};
use anthesis_flower::Flower;
use anthesis_mesh::Mesh;
use eframe::egui::{self, DragValue, RichText};

use super::command::{Command, ProjectEdit};

/// What the remesher said about one template at one edge.
#[derive(Debug)]
enum Preview {
    /// Still remeshing.
    Waiting(Receiver<Result<Bud, BudError>>),
    Done(Result<Bud, BudError>),
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
}

impl ShapeState {
    /// The template the section shows.
    pub fn template(&self) -> usize {
        self.template
    }

    /// The previewed remesh: the particle count and quality, or why the
    /// shape cannot be meshed; `None` while it is being computed or when
    /// there is none.
    pub fn preview(&self) -> Option<Result<&MeshQuality, String>> {
        match &self.preview {
            Some((_, Preview::Done(Ok(bud)))) => Some(Ok(&bud.quality)),
            Some((_, Preview::Done(Err(e)))) => Some(Err(e.to_string())),
            _ => None,
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

/// One row of mesh numbers.
fn quality_text(q: &MeshQuality) -> String {
    format!(
        "{} particles, mean edge {:.3}, smallest angle {:.1}°, edge spread {:.0} %",
        q.vertices,
        q.mean_edge,
        q.min_angle_deg,
        100.0 * q.edge_spread
    )
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
    state.template = state.template.min(flower.templates.len() - 1);
    ui.horizontal(|ui| {
        let label = ui.label("template").id;
        let selected = flower.templates[state.template].name.as_str();
        let before = state.template;
        egui::ComboBox::from_id_salt("shape template")
            .selected_text(selected)
            .show_ui(ui, |ui| {
                for (i, t) in flower.templates.iter().enumerate() {
                    ui.selectable_value(&mut state.template, i, &t.name);
                }
            })
            .response
            .labelled_by(label);
        if state.template != before {
            state.edge = None;
        }
    });
    let index = state.template;
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

    // Inner side.
    ui.horizontal(|ui| {
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

    // Remeshing.
    let mut edge = state.edge.unwrap_or(current.mean_edge);
    ui.horizontal(|ui| {
        let label = ui
            .label("remesh edge")
            .on_hover_text("The mean edge length to remesh at, in project units");
        let speed = (edge * 0.01).max(1e-4);
        if ui
            .add(
                DragValue::new(&mut edge)
                    .range(1e-4..=1e4)
                    .speed(speed)
                    .max_decimals(4),
            )
            .labelled_by(label.id)
            .changed()
        {
            state.edge = Some(edge);
        }
    });
    let key = (index, edge.to_bits(), print);
    if state.preview.as_ref().is_none_or(|(k, _)| *k != key) {
        let (send, receive) = sync_channel(1);
        let owned = mesh.clone();
        let ctx = ui.ctx().clone();
        let spawned = std::thread::Builder::new()
            .name("anthesis-remesh-preview".into())
            .spawn(move || {
                let _ = send.send(anthesis_bud::remesh_mesh(&owned, &RemeshOptions::new(edge)));
                ctx.request_repaint();
            });
        let preview = match spawned {
            Ok(_) => Preview::Waiting(receive),
            Err(e) => Preview::Done(Err(BudError::InvalidMesh(anthesis_mesh::MeshError::Io(
                format!("cannot start the remesher: {e}"),
            )))),
        };
        state.preview = Some((key, preview));
    }
    if let Some((_, preview)) = &mut state.preview
        && let Preview::Waiting(receive) = preview
    {
        match receive.try_recv() {
            Ok(result) => *preview = Preview::Done(result),
            Err(TryRecvError::Empty) => {}
            Err(TryRecvError::Disconnected) => {
                *preview = Preview::Done(Err(BudError::InvalidMesh(anthesis_mesh::MeshError::Io(
                    "the remesher stopped".to_string(),
                ))));
            }
        }
    }
    match state.preview.as_ref().map(|(_, p)| p) {
        Some(Preview::Done(Ok(bud))) => {
            ui.label(format!("remeshed: {}", quality_text(&bud.quality)));
            if ui
                .button("Remesh")
                .on_hover_text("Use this mesh for the template (its maps stay; one undo step)")
                .clicked()
            {
                commands.push(Command::Edit {
                    label: format!("remesh {} at edge {edge}", template.name),
                    edit: ProjectEdit::Mesh {
                        template: index,
                        mesh: Box::new(bud.mesh.clone()),
                    },
                });
            }
        }
        Some(Preview::Done(Err(e))) => {
            ui.label(
                RichText::new(format!("cannot remesh: {e}")).color(ui.visuals().error_fg_color),
            );
        }
        // No spinner: it would ask for frames all the time; the remesher's
        // thread asks for one when it is done.
        Some(Preview::Waiting(_)) | None => {
            ui.label("remeshing…");
        }
    }
}

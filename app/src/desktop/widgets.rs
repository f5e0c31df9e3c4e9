//! Widgets more than one panel draws: the mesh numbers and a draggable
//! control point in a 2D view of the template frame (the Bézier net, the
//! PDE sweep and the sketched petal editors).

use anthesis_bud::MeshQuality;
use eframe::egui;
use glam::DVec3;

/// One row of mesh numbers.
pub fn quality_text(q: &MeshQuality) -> String {
    format!(
        "{} particles, mean edge {:.3}, smallest angle {:.1}°, edge spread {:.0} %",
        q.vertices,
        q.mean_edge,
        q.min_angle_deg,
        100.0 * q.edge_spread
    )
}

/// A control point drawn at `at` (a square of `size` pixels) in a 2D view
/// of the template frame, front (x, y) or `side` (z, y), at `scale` pixels
/// per unit: whether it was picked (clicked, or a drag started on it), and
/// while it is dragged, how far it moved in the template frame.
pub fn view_point(
    ui: &egui::Ui,
    id: egui::Id,
    at: egui::Pos2,
    size: f32,
    (scale, side): (f64, bool),
) -> (bool, Option<DVec3>) {
    let hit = ui.interact(
        egui::Rect::from_center_size(at, egui::vec2(size, size)),
        id,
        egui::Sense::click_and_drag(),
    );
    let shift = hit.dragged().then(|| {
        let d = hit.drag_delta();
        let (across, up) = (f64::from(d.x) / scale, -f64::from(d.y) / scale);
        if side {
            DVec3::new(0.0, up, across)
        } else {
            DVec3::new(across, up, 0.0)
        }
    });
    (hit.clicked() || hit.drag_started(), shift)
}

/// A section of a side panel that the user can fold away: its title with
/// `tooltip`, open at first; egui remembers (and eframe saves between
/// launches) whether it is open. Returns what `add_contents` returned
/// when the section is open.
pub(super) fn section<R>(
    ui: &mut egui::Ui,
    title: &str,
    tooltip: &str,
    add_contents: impl FnOnce(&mut egui::Ui) -> R,
) -> Option<R> {
    let shown = egui::CollapsingHeader::new(egui::RichText::new(title).strong())
        .id_salt(("section", title))
        .default_open(true)
        .show(ui, add_contents);
    shown.header_response.on_hover_text(tooltip);
    shown.body_returned
}

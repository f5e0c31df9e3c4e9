//! The export dialog's window: the path, the options of the format it
//! names, the run it exports, and the Export button with the export's
//! progress (the dialog's state and the export thread are `export.rs`).

use std::path::PathBuf;

use anthesis_export::Encoding;
use anthesis_flower::Project;
use anthesis_sim::Selection;
use anthesis_sim::batch::Format;
use eframe::egui;

use super::{
    ExportDialog, ExportRequests, ExportState, MAX_DIALOG_RENDER_LEVEL, RUN_SHARE, TimingMode,
    edge_text, run_note, shown_edge, target_format,
};
use crate::animation;
use crate::desktop::checked_field::{checked_number, checked_with};

/// A labelled row editing an angle in degrees within `[-limit, limit]`;
/// returns the editor's response.
fn angle_row(ui: &mut egui::Ui, name: &str, degrees: &mut f64, limit: f64) -> egui::Response {
    let label = ui.label(name).id;
    let response =
        checked_with(ui, name, degrees, -limit..=limit, |d| d.suffix("°")).labelled_by(label);
    ui.end_row();
    response
}

impl ExportDialog {
    /// The dialog window. `keyframes_ready` and `keyframes_total` describe
    /// what would be exported; `project` (the document's, meshes as built)
    /// and `selection` what a run of its own would simulate;
    /// `simulated_now` the particles of the largest selected organ as the
    /// window simulates it.
    pub fn ui(
        &mut self,
        ctx: &egui::Context,
        keyframes_ready: usize,
        keyframes_total: u32,
        project: &Project,
        selection: &Selection,
        simulated_now: usize,
    ) -> ExportRequests {
        self.suggest_edge(project);
        let mut requests = ExportRequests::default();
        let mut open = self.open;
        egui::Window::new("Export the animation")
            .open(&mut open)
            .resizable(false)
            .collapsible(false)
            .show(ctx, |ui| {
                ui.horizontal(|ui| {
                    let label = ui.label("Export to").id;
                    ui.add(
                        egui::TextEdit::singleline(&mut self.path)
                            .hint_text("/path/to/flower.glb")
                            .desired_width(300.0),
                    )
                    .labelled_by(label)
                    .on_hover_text(
                        "Where the animation goes (replaced atomically): FILE.glb for an \
                         animated glTF, FILE.usda or FILE.usdc for a USD layer as text or binary \
                         (Blender, Houdini), \
                         FILE.gif for a rendered animation (slides)",
                    );
                    if ui.button("Browse…").clicked() {
                        requests.browse = true;
                    }
                });
                // Only the options of the chosen format: a GIF has its own,
                // a USD layer has timing and normals.
                let target = PathBuf::from(self.path.trim());
                let format = target_format(&target);
                self.options_grid(ui, format, project, selection, simulated_now);
                self.status_rows(ui, keyframes_ready, keyframes_total, project, selection);
                if self.export_row(ui) {
                    requests.export = true;
                }
            });
        self.open = open;
        requests
    }

    /// The .gif rows of the options grid: size, keyframe step, camera and
    /// turn, speed.
    fn gif_options_ui(&mut self, ui: &mut egui::Ui) {
        let a = &mut self.animation;
        let label = ui.label("GIF size").id;
        ui.horizontal(|ui| {
            checked_with(ui, "GIF width", &mut a.width, 16..=4096, |d| {
                d.suffix(" px")
            })
            .labelled_by(label);
            ui.label("×");
            checked_with(ui, "GIF height", &mut a.height, 16..=4096, |d| {
                d.suffix(" px")
            })
            .labelled_by(label);
        });
        ui.end_row();
        let label = ui.label("Every Nth keyframe").id;
        checked_with(
            ui,
            "Every Nth keyframe",
            &mut self.animation_step,
            1..=1000,
            |d| d,
        )
        .labelled_by(label);
        ui.end_row();
        angle_row(ui, "Camera azimuth", &mut a.azimuth_deg, 360.0);
        angle_row(ui, "Camera elevation", &mut a.elevation_deg, 90.0);
        angle_row(ui, "Camera turn", &mut a.turn_deg, 720.0)
            .on_hover_text("How far the camera circles the flower over the animation");
        let label = ui.label("GIF frames per second").id;
        checked_number(
            ui,
            "GIF frames per second",
            &mut a.frames_per_second,
            1.0,
            1.0..=animation::MAX_GIF_FRAMES_PER_SECOND,
        )
        .labelled_by(label);
        ui.end_row();
    }

    /// The "Organs" row, shown while one organ is previewed: the whole
    /// flower (the default) or the previewed organ alone.
    fn scope_ui(&mut self, ui: &mut egui::Ui, project: &Project, organ: usize) {
        ui.label("Organs").on_hover_text(
            "The window previews one organ; the export can hold the whole flower (run \
             with collisions, from the keyframes kept from before the preview or a run of its \
             own) or the previewed organ alone",
        );
        let name = project
            .flower
            .organs
            .get(organ)
            .map_or("the previewed organ", |o| o.name.as_str());
        ui.horizontal(|ui| {
            ui.radio_value(&mut self.whole_flower, true, "whole flower");
            ui.radio_value(&mut self.whole_flower, false, format!("{name} alone"));
        });
        ui.end_row();
    }

    /// The "Simulation" row: export the window's keyframes, or a run of
    /// its own at another mean edge, with the particles that makes in the
    /// largest simulated organ (or why the run would not fit).
    fn resimulate_ui(
        &mut self,
        ui: &mut egui::Ui,
        project: &Project,
        selection: &Selection,
        now: usize,
    ) {
        let label = ui
            .label("Simulation")
            .on_hover_text(
                "Paint coarse, export fine: the export can run the flower again with every \
                 template remeshed at another mean edge (the painted maps kept), without \
                 changing the project or the window's run",
            )
            .id;
        ui.horizontal(|ui| {
            ui.checkbox(&mut self.resimulate, "run again at mean edge");
            let shown = shown_edge(project);
            let speed = 0.01 * self.resimulate_edge;
            let edge = &mut self.resimulate_edge;
            ui.add_enabled_ui(self.resimulate, |ui| {
                checked_with(ui, "mean edge", edge, 1e-3 * shown..=1e3 * shown, |d| {
                    d.speed(speed).max_decimals(4)
                })
            })
            .inner
            .labelled_by(label);
        });
        ui.end_row();
        if !self.resimulate {
            return;
        }
        ui.label("");
        // What the run makes and whether it fits, worked out again only
        // when something it depends on changes (it clones the project and
        // reads the free memory).
        let organs = selection.organs(project.flower.organs.len());
        let key = (
            self.resimulate_edge.to_bits(),
            organs.clone(),
            project.settings.keyframes,
            project
                .flower
                .templates
                .iter()
                .map(|t| t.mesh.vertex_count())
                .collect::<Vec<_>>(),
            now,
        );
        if self.run_note.as_ref().is_none_or(|(k, _)| *k != key) {
            self.run_note = Some((
                key,
                run_note(project, selection, &organs, self.resimulate_edge, now),
            ));
        }
        if let Some((_, note)) = &self.run_note {
            match note {
                Ok(text) => ui.label(text),
                Err(text) => ui.colored_label(egui::Color32::from_rgb(210, 50, 40), text),
            };
        }
        ui.end_row();
    }

    /// The options grid: the smooth mesh, the organs and the run, then
    /// the options of `format` (a GIF's own; a .glb's or a USD layer's
    /// timing and normals, a .glb's morph targets and encoding).
    fn options_grid(
        &mut self,
        ui: &mut egui::Ui,
        format: Format,
        project: &Project,
        selection: &Selection,
        simulated_now: usize,
    ) {
        egui::Grid::new("export options")
            .num_columns(2)
            .show(ui, |ui| {
                let label = ui
                    .label("Smooth mesh")
                    .on_hover_text(
                        "Levels of Loop subdivision of every organ: a finer render mesh \
                         driven by the simulated one, about four times the vertices per \
                         level (0 = the simulated mesh as it is)",
                    )
                    .id;
                checked_with(
                    ui,
                    "Smooth mesh",
                    &mut self.render_level,
                    0..=MAX_DIALOG_RENDER_LEVEL,
                    |d| d.prefix("subdivide ").suffix(" ×"),
                )
                .labelled_by(label);
                ui.end_row();
                if let Selection::Only(organ) = selection {
                    self.scope_ui(ui, project, *organ);
                }
                self.resimulate_ui(ui, project, selection, simulated_now);
                if format == Format::Gif {
                    self.gif_options_ui(ui);
                    return;
                }
                ui.label("Timing");
                ui.horizontal(|ui| {
                    ui.radio_value(
                        &mut self.timing_mode,
                        TimingMode::FramesPerSecond,
                        "keyframes per second",
                    );
                    ui.radio_value(&mut self.timing_mode, TimingMode::Duration, "total seconds");
                });
                ui.end_row();
                match self.timing_mode {
                    TimingMode::FramesPerSecond => {
                        let label = ui.label("Keyframes per second").id;
                        checked_number(
                            ui,
                            "Keyframes per second",
                            &mut self.frames_per_second,
                            0.5,
                            0.1..=240.0,
                        )
                        .labelled_by(label);
                    }
                    TimingMode::Duration => {
                        let label = ui.label("Duration (s)").id;
                        checked_number(
                            ui,
                            "Duration (s)",
                            &mut self.duration_seconds,
                            0.1,
                            0.1..=3600.0,
                        )
                        .labelled_by(label);
                    }
                }
                ui.end_row();
                if format.has_morph_targets() {
                    let label = ui
                        .label("Most morph targets")
                        .on_hover_text(
                            "Per mesh; longer runs are resampled to this many keyframes \
                             (clients slow down with very many targets)",
                        )
                        .id;
                    checked_with(
                        ui,
                        "Most morph targets",
                        &mut self.max_morph_targets,
                        2..=2000,
                        |d| d,
                    )
                    .labelled_by(label);
                    ui.end_row();
                }
                ui.label("Normals");
                ui.checkbox(&mut self.normals, "store normals")
                    .on_hover_text("Without them the file is about half as large");
                ui.end_row();
                if !format.has_morph_targets() {
                    return;
                }
                ui.label("Encoding");
                ui.horizontal(|ui| {
                    for encoding in Encoding::ALL {
                        ui.radio_value(&mut self.encoding, encoding, encoding.to_string());
                    }
                })
                .response
                .on_hover_text(
                    "dense: plain floats, read everywhere; sparse: only moving vertices; \
                     quantized: KHR_mesh_quantization, about half the size; \
                     meshopt: quantized and compressed (EXT_meshopt_compression), \
                     the smallest, for three.js with its meshopt decoder",
                );
                ui.end_row();
                ui.label("Opens in");
                ui.label(self.encoding.clients());
                ui.end_row();
            });
    }

    /// What the export will hold: the window's keyframes computed so far,
    /// a run of its own, or the whole flower while one organ is previewed.
    fn status_rows(
        &self,
        ui: &mut egui::Ui,
        keyframes_ready: usize,
        keyframes_total: u32,
        project: &Project,
        selection: &Selection,
    ) {
        let after_bud = keyframes_ready.saturating_sub(1);
        let whole_of_preview = matches!(selection, Selection::Only(_)) && self.whole_flower;
        if whole_of_preview && !self.resimulate {
            ui.label(
                "The export holds the whole flower: its keyframes from before the \
                 preview if nothing changed since, else a run of its own (with progress); \
                 the window keeps its preview",
            );
        } else if self.resimulate {
            ui.label(format!(
                "The export runs all {} keyframes again at mean edge {}; \
                 the window keeps its run",
                project.settings.keyframes,
                edge_text(self.resimulate_edge)
            ));
        } else {
            ui.label(format!(
                "{after_bud} of {keyframes_total} keyframes computed{}",
                if (after_bud as u32) < keyframes_total {
                    " — the export holds the computed ones"
                } else {
                    ""
                }
            ));
        }
    }

    /// The Export button and the export's state (progress with Cancel,
    /// the file written or the error); whether Export was clicked.
    fn export_row(&mut self, ui: &mut egui::Ui) -> bool {
        let mut export = false;
        ui.horizontal(|ui| {
            let running = self.is_running();
            if ui
                .add_enabled(!running, egui::Button::new("Export"))
                .clicked()
            {
                export = true;
            }
            match &self.state {
                ExportState::Idle => {}
                ExportState::Running { progress } => {
                    let bar = egui::ProgressBar::new(*progress).desired_width(200.0);
                    ui.add(match self.running_run {
                        Some(total) if *progress < RUN_SHARE => {
                            let done = (progress / RUN_SHARE * total as f32).floor();
                            bar.text(format!("running: keyframe {done} of {total}"))
                        }
                        Some(_) => bar.text("writing the file"),
                        None => bar.show_percentage(),
                    });
                    if ui.button("Cancel").clicked() {
                        self.cancel();
                    }
                }
                ExportState::Done { path, bytes } => {
                    ui.label(format!(
                        "Wrote {} ({:.1} MB)",
                        path.display(),
                        *bytes as f64 / 1.0e6
                    ));
                }
                ExportState::Failed { message } => {
                    ui.colored_label(egui::Color32::from_rgb(210, 50, 40), message);
                }
            }
        });
        export
    }
}

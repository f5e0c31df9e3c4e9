//! File → New: a gallery of starting points, each the bud of a flower
//! built into the binary (the garden's names, so a new built-in appears
//! here by itself), rendered offscreen by `anthesis-render` on a thread
//! of its own when the gallery first opens, and kept for the session.
//! Choosing one starts a new project from it (after "save changes?").

use std::sync::mpsc;

use eframe::egui;

use super::AnthesisApp;
use super::command::Command;

/// Thumbnail size in pixels.
pub const THUMBNAIL_SIDE: u32 = 150;

/// Starting points in a row.
const GALLERY_COLUMNS: usize = 3;

/// What the rendering thread says about one starting point.
struct Rendered {
    name: &'static str,
    /// The project's name, or `None` when it did not load.
    title: Option<String>,
    picture: Result<image::RgbaImage, String>,
}

/// The picture of a starting point.
enum Picture {
    Waiting,
    Ready(egui::TextureHandle),
    Failed(String),
}

struct Entry {
    name: &'static str,
    title: String,
    picture: Picture,
}

/// The gallery's state.
#[derive(Default)]
pub struct Gallery {
    /// The window is shown.
    pub open: bool,
    entries: Vec<Entry>,
    rendered: Option<mpsc::Receiver<Rendered>>,
}

/// The starting points: the garden's built-in flowers this build carries,
/// in the garden's order.
pub fn starting_points() -> Vec<&'static str> {
    let built_in = anthesis_garden::builtin_names();
    anthesis_garden::FLOWER_NAMES
        .iter()
        .copied()
        .filter(|name| built_in.contains(name))
        .collect()
}

/// Renders the bud of each of `names` on this thread, sending each
/// picture as it is done and waking the window.
fn render_all(names: Vec<&'static str>, send: mpsc::SyncSender<Rendered>, ctx: egui::Context) {
    let mut renderer = anthesis_render::OffscreenRenderer::new().map_err(|e| e.to_string());
    for name in names {
        let (title, picture) = match anthesis_garden::builtin(name) {
            Some(Ok(project)) => {
                let picture = match renderer.as_mut() {
                    Ok(renderer) => crate::thumbnail::bud_picture(
                        renderer,
                        &project,
                        THUMBNAIL_SIDE,
                        THUMBNAIL_SIDE,
                    )
                    .map_err(|e| format!("{e:#}")),
                    Err(e) => Err(format!("no renderer: {e}")),
                };
                (Some(project.name), picture)
            }
            Some(Err(e)) => (None, Err(e.to_string())),
            None => (None, Err("not built in".to_string())),
        };
        if send
            .send(Rendered {
                name,
                title,
                picture,
            })
            .is_err()
        {
            return;
        }
        ctx.request_repaint();
    }
}

impl Gallery {
    /// Opens the window; the first time, starts rendering the pictures.
    pub fn show(&mut self, ctx: &egui::Context) {
        self.open = true;
        if !self.entries.is_empty() {
            return;
        }
        let names = starting_points();
        self.entries = names
            .iter()
            .map(|&name| Entry {
                name,
                title: name.to_string(),
                picture: Picture::Waiting,
            })
            .collect();
        // One message per starting point: the thread never waits.
        let (send, receive) = mpsc::sync_channel(names.len());
        let wake = ctx.clone();
        let spawned = std::thread::Builder::new()
            .name("anthesis-thumbnails".to_string())
            .spawn(move || render_all(names, send, wake));
        match spawned {
            Ok(_) => self.rendered = Some(receive),
            Err(e) => {
                for entry in &mut self.entries {
                    entry.picture = Picture::Failed(format!("cannot start rendering: {e}"));
                }
            }
        }
    }

    /// Whether every picture is rendered (or failed).
    pub fn pictures_done(&self) -> bool {
        !self.entries.is_empty()
            && self
                .entries
                .iter()
                .all(|e| !matches!(e.picture, Picture::Waiting))
    }

    /// Takes the pictures rendered so far.
    fn receive(&mut self, ctx: &egui::Context) {
        let Some(receive) = &self.rendered else {
            return;
        };
        while let Ok(rendered) = receive.try_recv() {
            let Some(entry) = self.entries.iter_mut().find(|e| e.name == rendered.name) else {
                continue;
            };
            if let Some(title) = rendered.title {
                entry.title = title;
            }
            entry.picture = match rendered.picture {
                Ok(image) => {
                    let size = [image.width() as usize, image.height() as usize];
                    let colour = egui::ColorImage::from_rgba_unmultiplied(size, image.as_raw());
                    Picture::Ready(ctx.load_texture(
                        format!("starting point {}", rendered.name),
                        colour,
                        egui::TextureOptions::LINEAR,
                    ))
                }
                Err(message) => Picture::Failed(message),
            };
        }
    }

    /// The window; returns the starting point chosen.
    fn ui(&mut self, ctx: &egui::Context) -> Option<&'static str> {
        if !self.open {
            return None;
        }
        self.receive(ctx);
        let mut chosen = None;
        let mut open = true;
        let side = THUMBNAIL_SIDE as f32;
        egui::Window::new("New flower")
            .open(&mut open)
            .collapsible(false)
            .resizable(false)
            .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
            .show(ctx, |ui| {
                ui.label("Start from one of these (each shown as its bud):");
                egui::Grid::new("starting points")
                    .num_columns(GALLERY_COLUMNS)
                    .spacing([12.0, 12.0])
                    .show(ui, |ui| {
                        for (i, entry) in self.entries.iter().enumerate() {
                            ui.vertical(|ui| {
                                ui.set_width(side + 8.0);
                                let picture = match &entry.picture {
                                    Picture::Ready(texture) => ui.add(egui::Button::image(
                                        egui::Image::new(texture)
                                            .alt_text(format!("bud of {}", entry.title))
                                            .fit_to_exact_size(egui::vec2(side, side)),
                                    )),
                                    Picture::Waiting => ui.add(
                                        egui::Button::new("rendering…")
                                            .min_size(egui::vec2(side, side)),
                                    ),
                                    Picture::Failed(why) => ui.add(
                                        egui::Button::new(format!("no picture: {why}"))
                                            .wrap()
                                            .min_size(egui::vec2(side, side)),
                                    ),
                                };
                                let title = ui.add(
                                    egui::Button::new(&entry.title).min_size(egui::vec2(side, 0.0)),
                                );
                                let hover = format!(
                                    "A new project from `{}` (anthesis new --from {})",
                                    entry.name, entry.name
                                );
                                let picture = picture.on_hover_text(hover.clone());
                                let title = title.on_hover_text(hover);
                                if picture.clicked() || title.clicked() {
                                    chosen = Some(entry.name);
                                }
                            });
                            if (i + 1) % GALLERY_COLUMNS == 0 {
                                ui.end_row();
                            }
                        }
                    });
            });
        if !open || chosen.is_some() {
            self.open = false;
        }
        if !self.pictures_done() {
            ctx.request_repaint_after(std::time::Duration::from_millis(100));
        }
        chosen
    }
}

impl AnthesisApp {
    /// The New gallery, when open.
    pub(super) fn gallery_window(&mut self, ctx: &egui::Context) {
        if let Some(name) = self.gallery.ui(ctx) {
            self.queued.push(Command::NewFrom(name.to_string()));
        }
    }

    /// Whether the New gallery is open and every picture in it rendered
    /// (for tests).
    pub fn gallery_pictures_done(&self) -> bool {
        self.gallery.open && self.gallery.pictures_done()
    }
}

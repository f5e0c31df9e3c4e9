//! The log panel: warnings and errors the user should see, newest last,
//! plus the newest error as a banner until dismissed, or until a later
//! attempt of the same kind succeeds (see [`Topic`]). Every entry is also
//! written to standard error, for a user who started the app from a
//! terminal (and for measuring: the edit latency is logged here).

use eframe::egui::{self, Color32, RichText};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Level {
    Info,
    Warning,
    Error,
}

/// What an error is about. A later success of the same kind shows the
/// problem is gone, so it clears that error's banner.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Topic {
    /// Opening, saving or starting a project.
    Project,
    /// Starting or running the simulation.
    Simulation,
    /// Writing an export.
    Export,
    /// Loading a map image or a mesh into a template.
    Import,
    /// Remeshing at the project's resolution.
    Resolution,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    pub level: Level,
    pub message: String,
}

/// Most entries kept.
const LOG_LIMIT: usize = 500;

#[derive(Debug, Default)]
pub struct Log {
    entries: Vec<Entry>,
    /// The error shown in the banner, if not dismissed, and what it is
    /// about (`None`: only dismissing clears it).
    banner: Option<(Option<Topic>, String)>,
}

impl Log {
    pub fn info(&mut self, message: impl Into<String>) {
        self.push(Level::Info, message.into());
    }

    pub fn warn(&mut self, message: impl Into<String>) {
        self.push(Level::Warning, message.into());
    }

    /// Logs an error and shows it in the banner until dismissed.
    pub fn error(&mut self, message: impl Into<String>) {
        self.show_error(None, message.into());
    }

    /// Logs an error about `topic` and shows it in the banner until
    /// dismissed or until [`Log::succeeded`] with the same topic.
    pub fn error_about(&mut self, topic: Topic, message: impl Into<String>) {
        self.show_error(Some(topic), message.into());
    }

    /// An attempt about `topic` succeeded: a banner about the same topic is
    /// out of date and goes (the log keeps the entry).
    pub fn succeeded(&mut self, topic: Topic) {
        if self.banner.as_ref().is_some_and(|(t, _)| *t == Some(topic)) {
            self.banner = None;
        }
    }

    fn show_error(&mut self, topic: Option<Topic>, message: String) {
        self.banner = Some((topic, message.clone()));
        self.push(Level::Error, message);
    }

    fn push(&mut self, level: Level, message: String) {
        let tag = match level {
            Level::Info => "info",
            Level::Warning => "warning",
            Level::Error => "error",
        };
        // Never a panic when standard error is full or closed.
        crate::cli::stream::write_err(format_args!("anthesis {tag}: {message}\n"));
        self.entries.push(Entry { level, message });
        if self.entries.len() > LOG_LIMIT {
            self.entries.remove(0);
        }
    }

    pub fn entries(&self) -> &[Entry] {
        &self.entries
    }

    pub fn banner(&self) -> Option<&str> {
        self.banner.as_ref().map(|(_, message)| message.as_str())
    }

    pub fn dismiss_banner(&mut self) {
        self.banner = None;
    }

    /// The log panel's contents.
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.strong("Log");
            if ui.small_button("Clear").clicked() {
                self.entries.clear();
            }
        });
        egui::ScrollArea::vertical()
            .stick_to_bottom(true)
            .auto_shrink([false, false])
            .show(ui, |ui| {
                for entry in &self.entries {
                    let (tag, colour) = match entry.level {
                        Level::Info => ("info", ui.visuals().weak_text_color()),
                        Level::Warning => ("warning", Color32::from_rgb(200, 140, 0)),
                        Level::Error => ("error", Color32::from_rgb(210, 50, 40)),
                    };
                    ui.horizontal_wrapped(|ui| {
                        ui.label(RichText::new(tag).color(colour).monospace());
                        ui.label(&entry.message);
                    });
                }
            });
    }

    /// The error banner above the viewport; returns nothing, dismissed on
    /// click.
    pub fn banner_ui(&mut self, ui: &mut egui::Ui) {
        let Some((_, message)) = self.banner.clone() else {
            return;
        };
        egui::Frame::new()
            .fill(Color32::from_rgb(120, 30, 25))
            .inner_margin(6.0)
            .show(ui, |ui| {
                ui.horizontal(|ui| {
                    if ui.button("Dismiss").clicked() {
                        self.dismiss_banner();
                    }
                    ui.add(
                        egui::Label::new(
                            RichText::new(format!("Error: {message}")).color(Color32::WHITE),
                        )
                        .wrap(),
                    );
                });
            });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_success_clears_only_a_banner_of_its_own_topic() {
        let mut log = Log::default();
        log.error_about(Topic::Simulation, "the simulation stopped: diverged");
        log.succeeded(Topic::Export);
        assert_eq!(log.banner(), Some("the simulation stopped: diverged"));
        log.succeeded(Topic::Simulation);
        assert_eq!(log.banner(), None);
        assert_eq!(log.entries().len(), 1, "the log keeps the error");

        log.error("no wgpu renderer");
        log.succeeded(Topic::Simulation);
        assert_eq!(log.banner(), Some("no wgpu renderer"), "only dismissed");
        log.error_about(Topic::Export, "export failed");
        log.error_about(Topic::Project, "cannot save");
        log.succeeded(Topic::Export);
        assert_eq!(log.banner(), Some("cannot save"), "the newest error shows");
    }
}

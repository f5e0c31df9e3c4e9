//! The log panel: warnings and errors the user should see, newest last,
//! plus the newest error as a banner until dismissed.

use eframe::egui::{self, Color32, RichText};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Level {
    Info,
    Warning,
    Error,
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
    /// The error shown in the banner, if not dismissed.
    banner: Option<String>,
}

impl Log {
    pub fn info(&mut self, message: impl Into<String>) {
        self.push(Level::Info, message.into());
    }

    pub fn warn(&mut self, message: impl Into<String>) {
        self.push(Level::Warning, message.into());
    }

    /// Logs an error and shows it in the banner.
    pub fn error(&mut self, message: impl Into<String>) {
        let message = message.into();
        self.banner = Some(message.clone());
        self.push(Level::Error, message);
    }

    fn push(&mut self, level: Level, message: String) {
        self.entries.push(Entry { level, message });
        if self.entries.len() > LOG_LIMIT {
            self.entries.remove(0);
        }
    }

    pub fn entries(&self) -> &[Entry] {
        &self.entries
    }

    pub fn banner(&self) -> Option<&str> {
        self.banner.as_deref()
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
                    let (tag, color) = match entry.level {
                        Level::Info => ("info", ui.visuals().weak_text_color()),
                        Level::Warning => ("warning", Color32::from_rgb(200, 140, 0)),
                        Level::Error => ("error", Color32::from_rgb(210, 50, 40)),
                    };
                    ui.horizontal_wrapped(|ui| {
                        ui.label(RichText::new(tag).color(color).monospace());
                        ui.label(&entry.message);
                    });
                }
            });
    }

    /// The error banner above the viewport; returns nothing, dismissed on
    /// click.
    pub fn banner_ui(&mut self, ui: &mut egui::Ui) {
        let Some(message) = self.banner.clone() else {
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

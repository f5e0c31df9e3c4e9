//! The menu bar and the keyboard shortcuts. Both only make [`Command`]s;
//! [`AnthesisApp::apply`] carries them out.

use eframe::egui::{self, Key, KeyboardShortcut, Modifiers};

use super::AnthesisApp;
use super::command::Command;

impl AnthesisApp {
    /// The commands of this frame's keyboard shortcuts. Shortcuts that
    /// edit or move in time are left to a text field that has the
    /// keyboard.
    pub(super) fn shortcut_commands(&self, ctx: &egui::Context) -> Vec<Command> {
        let command = |key| KeyboardShortcut::new(Modifiers::COMMAND, key);
        let command_shift = |key| KeyboardShortcut::new(Modifiers::COMMAND | Modifiers::SHIFT, key);
        let consume = |shortcut: KeyboardShortcut| ctx.input_mut(|i| i.consume_shortcut(&shortcut));
        let mut commands = Vec::new();
        // Shift variants first: Ctrl+Shift+Z also matches Ctrl+Z. A text
        // field that has the keyboard keeps Ctrl+Z for itself.
        if !ctx.egui_wants_keyboard_input() {
            if consume(command_shift(Key::Z)) || consume(command(Key::Y)) {
                commands.push(Command::Redo);
            }
            if consume(command(Key::Z)) {
                commands.push(Command::Undo);
            }
        }
        let with_command = [
            (command_shift(Key::S), Command::SaveAs),
            (command(Key::S), Command::Save),
            (command(Key::O), Command::OpenProject(None)),
            (command(Key::N), Command::NewProject),
            (command(Key::E), Command::OpenExportDialog),
        ];
        for (shortcut, action) in with_command {
            if consume(shortcut) {
                commands.push(action);
            }
        }
        if ctx.egui_wants_keyboard_input() {
            return commands;
        }
        let mut wireframe = self.view;
        wireframe.wireframe = !wireframe.wireframe;
        let plain = [
            (Key::Space, Command::TogglePlay),
            (Key::ArrowLeft, Command::StepKeyframe(-1)),
            (Key::ArrowRight, Command::StepKeyframe(1)),
            (Key::Home, Command::GoToStart),
            (Key::End, Command::GoToEnd),
            (Key::F, Command::FrameAll),
            (Key::W, Command::SetView(wireframe)),
            (
                Key::P,
                Command::SetSingleOrganPreview(!self.single_organ_preview),
            ),
        ];
        for (key, action) in plain {
            if ctx.input_mut(|i| i.consume_key(Modifiers::NONE, key)) {
                commands.push(action);
            }
        }
        commands
    }

    /// The menu bar; what is chosen is queued as commands.
    pub(super) fn menu_bar(&mut self, ui: &mut egui::Ui) {
        let mut chosen = Vec::new();
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                if ui.button("New").clicked() {
                    chosen.push(Command::NewProject);
                }
                if ui.button("Open…  (Ctrl+O)").clicked() {
                    chosen.push(Command::OpenProject(None));
                }
                ui.menu_button("Open recent", |ui| {
                    if self.settings.recent.is_empty() {
                        ui.label("(none yet)");
                    }
                    for path in &self.settings.recent {
                        if ui.button(path.display().to_string()).clicked() {
                            chosen.push(Command::OpenProject(Some(path.clone())));
                        }
                    }
                });
                ui.separator();
                if ui.button("Save  (Ctrl+S)").clicked() {
                    chosen.push(Command::Save);
                }
                if ui.button("Save as…  (Ctrl+Shift+S)").clicked() {
                    chosen.push(Command::SaveAs);
                }
                ui.separator();
                if ui.button("Export animation…  (Ctrl+E)").clicked() {
                    chosen.push(Command::OpenExportDialog);
                }
                ui.separator();
                if ui.button("Quit").clicked() {
                    chosen.push(Command::Quit);
                }
            });
            ui.menu_button("Edit", |ui| {
                let undo = self.doc.undo_label().map(|l| format!("Undo {l}  (Ctrl+Z)"));
                if ui
                    .add_enabled(
                        undo.is_some(),
                        egui::Button::new(undo.unwrap_or_else(|| "Undo".into())),
                    )
                    .clicked()
                {
                    chosen.push(Command::Undo);
                }
                let redo = self
                    .doc
                    .redo_label()
                    .map(|l| format!("Redo {l}  (Ctrl+Shift+Z)"));
                if ui
                    .add_enabled(
                        redo.is_some(),
                        egui::Button::new(redo.unwrap_or_else(|| "Redo".into())),
                    )
                    .clicked()
                {
                    chosen.push(Command::Redo);
                }
            });
            ui.menu_button("View", |ui| {
                let mut view = self.view;
                ui.checkbox(&mut view.wireframe, "Wireframe  (W)");
                ui.checkbox(&mut view.direction_arrows, "Growth direction arrows");
                ui.checkbox(&mut view.show_others, "Other organs as buds in preview");
                ui.menu_button("Map overlay", |ui| {
                    ui.radio_value(&mut view.overlay, None, "none");
                    for kind in anthesis_maps::MapKind::ALL {
                        ui.radio_value(&mut view.overlay, Some(kind), kind.label());
                    }
                });
                if view != self.view {
                    chosen.push(Command::SetView(view));
                }
                if ui.button("Frame all  (F)").clicked() {
                    chosen.push(Command::FrameAll);
                }
                let mut show_log = self.settings.show_log;
                if ui.checkbox(&mut show_log, "Log panel").changed() {
                    chosen.push(Command::ShowLog(show_log));
                }
            });
        });
        self.queued.extend(chosen);
    }
}

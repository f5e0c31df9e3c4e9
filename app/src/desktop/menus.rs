//! The menu bar and the keyboard shortcuts. Both only make [`Command`]s;
//! [`AnthesisApp::apply`] carries them out.

use eframe::egui::{self, Event, Key, KeyboardShortcut, Modifiers};

use super::AnthesisApp;
use super::command::Command;

/// Where a shortcut works.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scope {
    /// Also while a text field has the keyboard (Ctrl+S, Ctrl+O...).
    Everywhere,
    /// Not while a text field has the keyboard: the key types or edits
    /// text there (plain keys, Ctrl+Z).
    NotTyping,
}

/// One keyboard shortcut: the keys that trigger it, what it does, and the
/// command it makes. [`SHORTCUTS`] is the one list the handler matches
/// and the Help → Shortcuts window and the README show.
pub struct Shortcut {
    /// The keys, the first as shown; the others are the same key as other
    /// keyboard layouts report it (Shift+[ arrives as `{` on a US layout).
    pub keys: &'static [KeyboardShortcut],
    /// What it does, as the Shortcuts window says it.
    pub does: &'static str,
    pub scope: Scope,
    /// The command, from the app's state (toggles read what is on now).
    pub command: fn(&AnthesisApp) -> Command,
}

impl Shortcut {
    /// How the shortcut is written: `Ctrl+Shift+Z`, `[`, `Left`.
    pub fn label(&self) -> String {
        let Some(shortcut) = self.keys.first() else {
            return String::new();
        };
        let mut text = egui::ModifierNames::NAMES.format(&shortcut.modifiers, false);
        if !text.is_empty() {
            text.push('+');
        }
        let key = shortcut.logical_key;
        text.push_str(match key {
            Key::ArrowLeft | Key::ArrowRight | Key::ArrowUp | Key::ArrowDown => key.name(),
            _ => key.symbol_or_name(),
        });
        text
    }

    /// Whether a press of `key` with `modifiers` is this shortcut. Ctrl and
    /// Shift must be exactly as listed; Alt is ignored (AltGr types `[` on
    /// some layouts).
    fn matches(&self, key: Key, modifiers: Modifiers) -> bool {
        self.keys.iter().any(|s| {
            s.logical_key == key
                && s.modifiers.command == (modifiers.command || modifiers.ctrl)
                && s.modifiers.shift == modifiers.shift
        })
    }
}

const fn plain(key: Key) -> KeyboardShortcut {
    KeyboardShortcut::new(Modifiers::NONE, key)
}
const fn shift(key: Key) -> KeyboardShortcut {
    KeyboardShortcut::new(Modifiers::SHIFT, key)
}
const fn ctrl(key: Key) -> KeyboardShortcut {
    KeyboardShortcut::new(Modifiers::COMMAND, key)
}
const fn ctrl_shift(key: Key) -> KeyboardShortcut {
    KeyboardShortcut::new(Modifiers::COMMAND.plus(Modifiers::SHIFT), key)
}

/// Every keyboard shortcut of the window.
pub const SHORTCUTS: &[Shortcut] = &[
    Shortcut {
        keys: &[ctrl(Key::Z)],
        does: "Undo",
        scope: Scope::NotTyping,
        command: |_| Command::Undo,
    },
    Shortcut {
        keys: &[ctrl_shift(Key::Z), ctrl(Key::Y)],
        does: "Redo",
        scope: Scope::NotTyping,
        command: |_| Command::Redo,
    },
    Shortcut {
        keys: &[ctrl(Key::N)],
        does: "New project",
        scope: Scope::Everywhere,
        command: |_| Command::NewProject,
    },
    Shortcut {
        keys: &[ctrl(Key::O)],
        does: "Open a project",
        scope: Scope::Everywhere,
        command: |_| Command::OpenProject(None),
    },
    Shortcut {
        keys: &[ctrl(Key::S)],
        does: "Save",
        scope: Scope::Everywhere,
        command: |_| Command::Save,
    },
    Shortcut {
        keys: &[ctrl_shift(Key::S)],
        does: "Save as",
        scope: Scope::Everywhere,
        command: |_| Command::SaveAs,
    },
    Shortcut {
        keys: &[ctrl(Key::E)],
        does: "Export the animation",
        scope: Scope::Everywhere,
        command: |_| Command::OpenExportDialog,
    },
    Shortcut {
        keys: &[plain(Key::OpenBracket)],
        does: "Smaller brush (radius ÷ 1.25)",
        scope: Scope::NotTyping,
        command: |_| Command::StepBrushRadius { larger: false },
    },
    Shortcut {
        keys: &[plain(Key::CloseBracket)],
        does: "Larger brush (radius × 1.25)",
        scope: Scope::NotTyping,
        command: |_| Command::StepBrushRadius { larger: true },
    },
    Shortcut {
        keys: &[
            shift(Key::OpenBracket),
            shift(Key::OpenCurlyBracket),
            plain(Key::OpenCurlyBracket),
        ],
        does: "Weaker brush (strength − 0.1)",
        scope: Scope::NotTyping,
        command: |_| Command::StepBrushStrength { stronger: false },
    },
    Shortcut {
        keys: &[
            shift(Key::CloseBracket),
            shift(Key::CloseCurlyBracket),
            plain(Key::CloseCurlyBracket),
        ],
        does: "Stronger brush (strength + 0.1)",
        scope: Scope::NotTyping,
        command: |_| Command::StepBrushStrength { stronger: true },
    },
    Shortcut {
        keys: &[plain(Key::X)],
        does: "Brush to subtract from add, else to add",
        scope: Scope::NotTyping,
        command: |_| Command::SwapBrushAddSubtract,
    },
    Shortcut {
        keys: &[plain(Key::Space)],
        does: "Play or pause",
        scope: Scope::NotTyping,
        command: |_| Command::TogglePlay,
    },
    Shortcut {
        keys: &[plain(Key::ArrowLeft)],
        does: "One keyframe back",
        scope: Scope::NotTyping,
        command: |_| Command::StepKeyframe(-1),
    },
    Shortcut {
        keys: &[plain(Key::ArrowRight)],
        does: "One keyframe forwards",
        scope: Scope::NotTyping,
        command: |_| Command::StepKeyframe(1),
    },
    Shortcut {
        keys: &[plain(Key::Home)],
        does: "First keyframe",
        scope: Scope::NotTyping,
        command: |_| Command::GoToStart,
    },
    Shortcut {
        keys: &[plain(Key::End)],
        does: "Newest keyframe (and follow new ones)",
        scope: Scope::NotTyping,
        command: |_| Command::GoToEnd,
    },
    Shortcut {
        keys: &[plain(Key::F)],
        does: "Frame the camera on the flower",
        scope: Scope::NotTyping,
        command: |_| Command::FrameAll,
    },
    Shortcut {
        keys: &[plain(Key::W)],
        does: "Wireframe on or off",
        scope: Scope::NotTyping,
        command: |app| {
            let mut view = app.view;
            view.wireframe = !view.wireframe;
            Command::SetView(view)
        },
    },
    Shortcut {
        keys: &[plain(Key::P)],
        does: "Single-organ preview on or off",
        scope: Scope::NotTyping,
        command: |app| Command::SetSingleOrganPreview(!app.single_organ_preview),
    },
    Shortcut {
        keys: &[plain(super::difference::BEFORE_KEY)],
        does: "Hold: the result before the last edit (release: the current one)",
        scope: Scope::NotTyping,
        command: |app| Command::SetView(app.view),
    },
    Shortcut {
        keys: &[plain(Key::H)],
        does: "Undo history window",
        scope: Scope::NotTyping,
        command: |app| Command::ShowHistory(!app.settings.show_history),
    },
];

/// The shortcut of `does` as written (for menu entries); empty if none.
pub fn shortcut_label(does: &str) -> String {
    SHORTCUTS
        .iter()
        .find(|s| s.does == does)
        .map(Shortcut::label)
        .unwrap_or_default()
}

/// The shortcuts as a Markdown table (the README's list is this text, a
/// test checks).
#[cfg(test)]
fn shortcuts_markdown() -> String {
    let mut text = String::from("| keys | does |\n|---|---|\n");
    for s in SHORTCUTS {
        let keys = s.label().replace('|', "\\|");
        text.push_str(&format!("| `{keys}` | {} |\n", s.does));
    }
    text
}

impl AnthesisApp {
    /// The commands of this frame's keyboard shortcuts, one per key press
    /// (five presses of Right in one frame are five steps). A text field
    /// that has the keyboard keeps the keys it types or edits with (see
    /// [`Scope`]); the presses taken are removed from the frame's input.
    pub(super) fn shortcut_commands(&self, ctx: &egui::Context) -> Vec<Command> {
        let typing = ctx.text_edit_focused();
        let mut commands = Vec::new();
        ctx.input_mut(|i| {
            i.events.retain(|event| {
                let Event::Key {
                    key,
                    modifiers,
                    pressed: true,
                    ..
                } = event
                else {
                    return true;
                };
                let found = SHORTCUTS.iter().find(|s| {
                    (s.scope == Scope::Everywhere || !typing) && s.matches(*key, *modifiers)
                });
                match found {
                    Some(shortcut) => {
                        commands.push((shortcut.command)(self));
                        false
                    }
                    None => true,
                }
            });
        });
        commands
    }

    /// Help → Shortcuts: every shortcut of [`SHORTCUTS`].
    pub(super) fn shortcuts_window(&mut self, ctx: &egui::Context) {
        let mut open = self.show_shortcuts;
        egui::Window::new("Shortcuts")
            .open(&mut open)
            .resizable(false)
            .collapsible(false)
            .show(ctx, |ui| {
                egui::Grid::new("shortcuts")
                    .num_columns(2)
                    .striped(true)
                    .show(ui, |ui| {
                        for s in SHORTCUTS {
                            ui.monospace(s.label());
                            ui.label(s.does);
                            ui.end_row();
                        }
                    });
                ui.label(
                    "While a text field has the keyboard, it keeps the keys without \
                     Ctrl and Ctrl+Z / Ctrl+Shift+Z.",
                );
            });
        if open != self.show_shortcuts {
            self.queued.push(Command::ShowShortcuts(open));
        }
    }

    /// Help → Getting started and Help → About, when open.
    pub(super) fn help_windows(&mut self, ctx: &egui::Context) {
        egui::Window::new("Getting started")
            .open(&mut self.help.getting_started)
            .default_width(420.0)
            .collapsible(false)
            .show(ctx, |ui| {
                for (title, lines) in GETTING_STARTED {
                    ui.strong(*title);
                    for line in *lines {
                        ui.label(format!("•  {line}"));
                    }
                    ui.add_space(6.0);
                }
            });
        egui::Window::new("About Anthesis")
            .open(&mut self.help.about)
            .resizable(false)
            .collapsible(false)
            .show(ctx, |ui| {
                ui.heading(format!("Anthesis {}", env!("CARGO_PKG_VERSION")));
                ui.label(ABOUT);
            });
    }

    /// The undo history: every step by its label, the applied ones first;
    /// a click undoes or redoes up to that step.
    pub(super) fn history_window(&mut self, ctx: &egui::Context) {
        if !self.settings.show_history {
            return;
        }
        let mut open = true;
        let position = self.doc.history_position();
        let mut chosen = None;
        egui::Window::new("History")
            .open(&mut open)
            .default_width(260.0)
            .show(ctx, |ui| {
                egui::ScrollArea::vertical()
                    .max_height(320.0)
                    .show(ui, |ui| {
                        let opened = ui
                            .selectable_label(position == 0, "Opened")
                            .on_hover_text("The project as opened (undo everything)");
                        if opened.clicked() {
                            chosen = Some(0);
                        }
                        for (i, label) in self.doc.history_labels().enumerate() {
                            let step = i + 1;
                            let text = if step <= position {
                                egui::RichText::new(label)
                            } else {
                                // Undone: redo up to here by clicking.
                                egui::RichText::new(label).weak().italics()
                            };
                            if ui.selectable_label(step == position, text).clicked() {
                                chosen = Some(step);
                            }
                        }
                    });
            });
        if let Some(step) = chosen
            && step != position
        {
            self.queued.push(Command::GoToHistory(step));
        }
        if !open {
            self.queued.push(Command::ShowHistory(false));
        }
    }

    /// The menu bar; what is chosen is queued as commands.
    pub(super) fn menu_bar(&mut self, ui: &mut egui::Ui) {
        let mut chosen = Vec::new();
        let mut open_fit = false;
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                self.file_menu(ui, &mut chosen);
            });
            ui.menu_button("Edit", |ui| {
                let undo = self
                    .doc
                    .undo_label()
                    .map(|l| with_keys(&format!("Undo {l}"), "Undo"));
                if ui
                    .add_enabled(
                        undo.is_some(),
                        egui::Button::new(undo.unwrap_or_else(|| with_keys("Undo", "Undo"))),
                    )
                    .clicked()
                {
                    chosen.push(Command::Undo);
                }
                let redo = self
                    .doc
                    .redo_label()
                    .map(|l| with_keys(&format!("Redo {l}"), "Redo"));
                if ui
                    .add_enabled(
                        redo.is_some(),
                        egui::Button::new(redo.unwrap_or_else(|| with_keys("Redo", "Redo"))),
                    )
                    .clicked()
                {
                    chosen.push(Command::Redo);
                }
                ui.separator();
                if ui.button("Fit growth maps to a target…").clicked() {
                    open_fit = true;
                }
            });
            ui.menu_button("View", |ui| {
                let mut view = self.view;
                ui.checkbox(
                    &mut view.wireframe,
                    with_keys("Wireframe", "Wireframe on or off"),
                );
                ui.checkbox(&mut view.direction_arrows, "Growth direction arrows");
                ui.checkbox(&mut view.show_others, "Other organs as buds in preview");
                ui.menu_button("Map overlay", |ui| {
                    ui.radio_value(&mut view.overlay, None, "none");
                    for kind in anthesis_maps::MapKind::ALL {
                        ui.radio_value(
                            &mut view.overlay,
                            Some(kind),
                            super::words::label(kind.label()),
                        )
                        .on_hover_text(super::words::tooltip(kind.label()));
                    }
                });
                super::measure_panel::menu_entry(ui);
                if view != self.view {
                    chosen.push(Command::SetView(view));
                }
                if ui
                    .button(with_keys("Frame all", "Frame the camera on the flower"))
                    .clicked()
                {
                    chosen.push(Command::FrameAll);
                }
                let mut show_log = self.settings.show_log;
                if ui.checkbox(&mut show_log, "Log panel").changed() {
                    chosen.push(Command::ShowLog(show_log));
                }
                let mut show_history = self.settings.show_history;
                if ui
                    .checkbox(
                        &mut show_history,
                        with_keys("Undo history", "Undo history window"),
                    )
                    .changed()
                {
                    chosen.push(Command::ShowHistory(show_history));
                }
            });
            ui.menu_button("Help", |ui| {
                if ui.button("Getting started").clicked() {
                    self.help.getting_started = true;
                }
                if ui.button("Shortcuts").clicked() {
                    chosen.push(Command::ShowShortcuts(true));
                }
                if ui.button("About Anthesis").clicked() {
                    self.help.about = true;
                }
            });
        });
        self.queued.extend(chosen);
        if open_fit {
            self.fit.open = true;
        }
    }

    /// The File menu's entries (the recent projects among them).
    fn file_menu(&self, ui: &mut egui::Ui, chosen: &mut Vec<Command>) {
        if ui.button("New").clicked() {
            chosen.push(Command::NewProject);
        }
        if ui.button(with_keys("Open…", "Open a project")).clicked() {
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
        if ui.button(with_keys("Save", "Save")).clicked() {
            chosen.push(Command::Save);
        }
        if ui.button(with_keys("Save as…", "Save as")).clicked() {
            chosen.push(Command::SaveAs);
        }
        ui.separator();
        if ui
            .button(with_keys("Export animation…", "Export the animation"))
            .clicked()
        {
            chosen.push(Command::OpenExportDialog);
        }
        ui.separator();
        if ui.button("Quit").clicked() {
            chosen.push(Command::Quit);
        }
    }
}

/// Which Help windows are open.
#[derive(Debug, Default)]
pub struct HelpWindows {
    pub getting_started: bool,
    pub about: bool,
}

/// Help → Getting started: the three jobs, a few lines each.
pub const GETTING_STARTED: &[(&str, &[&str])] = &[
    (
        "Paint",
        &[
            "Pick an organ on the left (or click it in the viewport); the paint panel on the \
             right shows its template's maps.",
            "Choose a map (Growth along, inner side bends petals outwards) and drag on the UV \
             canvas; tick “Paint on the 3D organ” to paint on the flower itself.",
            "[ and ] change the brush size, X swaps add and subtract, Ctrl+Z undoes a stroke.",
            "Every stroke restarts the simulation: a coarse preview first, then the full run.",
        ],
    ),
    (
        "Scrub",
        &[
            "Drag on the timeline at the bottom to see any keyframe; Left and Right step one.",
            "Space plays the opening; the bar turns green as keyframes are computed.",
            "P simulates the selected organ alone, much faster while painting.",
        ],
    ),
    (
        "Export",
        &[
            "File > Export animation… (Ctrl+E) writes .glb (glTF), .usda/.usdc (USD) or a .gif.",
            "The file is named after the project and goes beside it unless you choose \
             another place.",
            "File > Save keeps the project (a .anthesis.toml with its maps) to open again.",
        ],
    ),
];

/// Help → About: what the program is (no links: the window opens none).
pub const ABOUT: &str = "Authoring flower-opening animations by painted growth, after \
    Ijiri, Yokoo, Kawabata and Igarashi, “Surface-based Growth Simulation for Opening \
    Flowers” (2008). Paint where a petal grows; the simulation opens the bud; export the \
    animation.";

/// A menu entry's text with its shortcut (from [`SHORTCUTS`]), if any.
fn with_keys(text: &str, does: &str) -> String {
    match shortcut_label(does) {
        keys if keys.is_empty() => text.to_string(),
        keys => format!("{text}  ({keys})"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_readme_lists_every_shortcut_as_the_table_has_it() {
        let readme = include_str!("../../../README.md");
        let table = shortcuts_markdown();
        assert!(
            readme.contains(&table),
            "README.md's shortcut list differs from SHORTCUTS; put this in it:\n{table}"
        );
    }

    #[test]
    fn no_two_shortcuts_share_a_key() {
        for (i, a) in SHORTCUTS.iter().enumerate() {
            for b in &SHORTCUTS[i + 1..] {
                for key in a.keys {
                    assert!(
                        !b.matches(key.logical_key, key.modifiers),
                        "{} and {} share {}",
                        a.does,
                        b.does,
                        a.label()
                    );
                }
            }
        }
    }

    #[test]
    fn shift_bracket_is_not_bracket_and_labels_read_as_written() {
        let find = |does: &str| SHORTCUTS.iter().find(|s| s.does.starts_with(does));
        let smaller = find("Smaller brush").expect("listed");
        let weaker = find("Weaker brush").expect("listed");
        assert!(smaller.matches(Key::OpenBracket, Modifiers::NONE));
        assert!(!smaller.matches(Key::OpenBracket, Modifiers::SHIFT));
        // A US layout reports Shift+[ as '{' with Shift held.
        assert!(weaker.matches(Key::OpenCurlyBracket, Modifiers::SHIFT));
        assert!(weaker.matches(Key::OpenBracket, Modifiers::SHIFT));
        assert!(!weaker.matches(Key::OpenBracket, Modifiers::NONE));
        assert_eq!(smaller.label(), "[");
        assert_eq!(weaker.label(), "Shift+[");
        assert_eq!(find("Redo").expect("listed").label(), "Ctrl+Shift+Z");
        assert_eq!(find("One keyframe back").expect("listed").label(), "Left");
    }
}

//! The Flower panel's L-system editor: the rules typed with their errors
//! highlighted where they point, checked as they are typed, and applied as
//! one undo step.

use super::*;

/// The byte range of the text an L-system error points at: the character
/// at its line and column (the end of the line when the column is past
/// it), or its whole line.
fn error_range(text: &str, error: &LSystemError) -> Option<Range<usize>> {
    let (line, column) = match error {
        LSystemError::Syntax { line, column, .. } => (*line, Some(*column)),
        LSystemError::UnknownName { line, .. } | LSystemError::Arity { line, .. } => (*line, None),
        _ => return None,
    };
    let mut start = 0;
    for (n, l) in text.split('\n').enumerate() {
        let end = start + l.len();
        if n + 1 == line {
            return Some(match column {
                None => start..end,
                Some(column) => match l.char_indices().nth(column.saturating_sub(1)) {
                    Some((at, c)) => start + at..start + at + c.len_utf8(),
                    // Past the end: the line's last character, if any.
                    None => match l.char_indices().last() {
                        Some((at, c)) => start + at..start + at + c.len_utf8(),
                        None => start..end,
                    },
                },
            });
        }
        start = end + 1;
    }
    None
}

/// The text laid out with the error's characters on red.
fn highlighted(
    ui: &egui::Ui,
    text: &str,
    at: Option<&Range<usize>>,
    wrap: f32,
) -> egui::text::LayoutJob {
    let font = egui::TextStyle::Monospace.resolve(ui.style());
    let normal = egui::TextFormat::simple(font.clone(), ui.visuals().text_color());
    let mut job = egui::text::LayoutJob {
        wrap: egui::text::TextWrapping {
            max_width: wrap,
            ..Default::default()
        },
        ..Default::default()
    };
    match at.filter(|r| r.end <= text.len() && text.is_char_boundary(r.start)) {
        Some(range) if !range.is_empty() => {
            job.append(&text[..range.start], 0.0, normal.clone());
            let mut marked = egui::TextFormat::simple(font, Color32::WHITE);
            marked.background = Color32::from_rgb(200, 40, 40);
            job.append(&text[range.clone()], 0.0, marked);
            job.append(&text[range.end..], 0.0, normal);
        }
        _ => job.append(text, 0.0, normal),
    }
    job
}

/// The surface letters `~X` of an L-system's text, in order.
fn surface_letters(text: &str) -> Vec<char> {
    let mut letters = Vec::new();
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        if c == '~'
            && let Some(&letter) = chars.peek()
            && letter.is_alphabetic()
            && !letters.contains(&letter)
        {
            letters.push(letter);
        }
    }
    letters
}

impl FlowerPanelState {
    /// Checks `text` as the flower's L-system: the flower it makes, or the
    /// error to show.
    fn check(
        &mut self,
        flower: &Flower,
        text: &str,
        steps: u32,
        surfaces: &BTreeMap<char, usize>,
    ) -> Option<Flower> {
        let structure = Structure::LSystem {
            text: text.to_string(),
            steps,
            surfaces: surfaces.clone(),
            units: self.units,
        };
        match flower.with_structure(Some(structure)) {
            Ok(made) => {
                self.error = None;
                Some(made)
            }
            Err(error) => {
                let at = match &error {
                    anthesis_flower::edit::EditError::Structure(StructureError::LSystem(e)) => {
                        error_range(text, e)
                    }
                    _ => None,
                };
                self.error = Some(TextError {
                    message: error.to_string(),
                    at,
                });
                None
            }
        }
    }

    /// The L-system editor; `now` is the input time in seconds.
    pub(super) fn lsystem_ui(
        &mut self,
        ui: &mut egui::Ui,
        flower: &Flower,
        (text, steps, surfaces): (&str, u32, &BTreeMap<char, usize>),
        now: f64,
    ) -> Option<Outcome> {
        // Follow the project (an undo, another project) unless typing.
        if self.typed_at.is_none() && self.source.as_deref() != Some(text) {
            self.text = text.to_string();
            self.source = Some(text.to_string());
            self.error = None;
        }
        let mut out = None;
        let error_at = self.error.as_ref().and_then(|e| e.at.clone());
        let mut layouter = |ui: &egui::Ui, buffer: &dyn egui::TextBuffer, wrap: f32| {
            let job = highlighted(ui, buffer.as_str(), error_at.as_ref(), wrap);
            ui.fonts_mut(|f| f.layout_job(job))
        };
        let edit = ui.add(
            egui::TextEdit::multiline(&mut self.text)
                .id_salt("lsystem text")
                .code_editor()
                .desired_rows(6)
                .desired_width(f32::INFINITY)
                .layouter(&mut layouter),
        );
        let edit = edit.on_hover_text(
            "One statement a line: constants (angle = 30), axiom: …, productions A(x) -> … . \
             ~X places an organ of the template chosen for surface X below.",
        );
        if edit.changed() {
            self.typed_at = Some(now);
            let typed = self.text.clone();
            self.check(flower, &typed, steps, surfaces);
        }
        if let Some(error) = &self.error {
            ui.label(RichText::new(&error.message).color(ui.visuals().error_fg_color));
        }
        if let Some(at) = self.typed_at {
            let waited = now - at;
            if waited >= TYPING_PAUSE_SECONDS {
                self.typed_at = None;
                let typed = self.text.clone();
                if typed != text
                    && let Some(made) = self.check(flower, &typed, steps, surfaces)
                {
                    self.source = Some(typed);
                    out = Some(Outcome::Edit("L-system text".to_string(), made));
                } else if self.error.is_none() {
                    self.source = Some(typed);
                }
            } else {
                ui.ctx()
                    .request_repaint_after(std::time::Duration::from_secs_f64(
                        TYPING_PAUSE_SECONDS - waited + 0.01,
                    ));
            }
        }
        // Steps and surfaces apply at once (with the text as it is, when
        // it is valid).
        let mut steps_now = steps;
        let mut surfaces_now = surfaces.clone();
        let mut label = None;
        ui.horizontal(|ui| {
            let l = ui.label("derivation steps");
            if crate::desktop::checked_field::checked_with(
                ui,
                "derivation steps",
                &mut steps_now,
                0..=anthesis_flower::structure::lsystem::MAX_STEPS,
                |d| d,
            )
            .labelled_by(l.id)
            .changed()
            {
                label = Some("derivation steps".to_string());
            }
        });
        for letter in surface_letters(&self.text) {
            ui.horizontal(|ui| {
                let name = ui.label(format!("surface ~{letter}")).id;
                let mut template = surfaces_now.get(&letter).copied().unwrap_or(usize::MAX);
                if template_combo(ui, ("surface", letter), name, flower, &mut template) {
                    surfaces_now.insert(letter, template);
                    label = Some(format!("surface ~{letter}"));
                }
            });
        }
        if let Some(label) = label {
            let typed = self.text.clone();
            if let Some(made) = self.check(flower, &typed, steps_now, &surfaces_now) {
                self.typed_at = None;
                self.source = Some(typed);
                out = Some(Outcome::Edit(label, made));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use anthesis_flower::structure::lsystem::LSystem;

    #[test]
    fn the_error_range_is_the_character_at_the_line_and_column() {
        let text = "axiom: A\nA -> F(1 B";
        let error = LSystem::parse(text).unwrap_err();
        let range = error_range(text, &error).unwrap();
        assert_eq!(&text[range], "B");
        // Past the end of the line: its last character.
        let text = "axiom: A\nA -> F(1";
        let error = LSystem::parse(text).unwrap_err();
        let range = error_range(text, &error).unwrap();
        assert_eq!(&text[range], "1");
        // An unknown name: its line.
        let text = "axiom: A\nA -> F(len)";
        let error = LSystem::parse(text).unwrap_err();
        assert_eq!(&text[error_range(text, &error).unwrap()], "A -> F(len)");
    }

    #[test]
    fn surface_letters_are_found_once_in_order() {
        assert_eq!(surface_letters("axiom: [~p] ~c ~p F ~"), vec!['p', 'c']);
    }
}

//! The open project: the model being edited, where it lives on disk, whether
//! it has unsaved changes, and undo/redo of every edit.

use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};

use anthesis_flower::Project;

/// Most undo steps kept (each holds a copy of the project before the edit).
pub const UNDO_LIMIT: usize = 200;

/// One undoable step: the project as it was before, and what the edit was.
#[derive(Debug, Clone)]
struct Step {
    label: String,
    before: Project,
}

/// A number no other project state of this process has had.
fn next_revision() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(1);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

/// The project being edited, with its history.
#[derive(Debug, Clone)]
pub struct Document {
    project: Project,
    /// Where it was opened from or last saved to; `None` for a new project.
    pub path: Option<PathBuf>,
    undo: Vec<Step>,
    redo: Vec<Step>,
    /// The last step may still absorb edits with the same label (a drag,
    /// a brush stroke) until [`Document::seal`].
    open_step: bool,
    /// Edits since the last save (the history position of the saved state).
    saved_at: Option<usize>,
    /// Changes whenever the project does (edit, undo, redo) and differs
    /// between documents, so views can keep what they built from it.
    revision: u64,
}

impl Document {
    /// A document for `project`, unchanged since `path` (if any).
    pub fn new(project: Project, path: Option<PathBuf>) -> Document {
        Document {
            project,
            path,
            undo: Vec::new(),
            redo: Vec::new(),
            open_step: false,
            saved_at: Some(0),
            revision: next_revision(),
        }
    }

    /// Identifies the project as it is now: equal revisions, equal
    /// projects (see the field).
    pub fn revision(&self) -> u64 {
        self.revision
    }

    pub fn project(&self) -> &Project {
        &self.project
    }

    /// Applies `change` to the project as one undoable edit named `label`.
    /// Consecutive edits with the same label merge into one step until
    /// [`Document::seal`] is called (the UI seals when the pointer is
    /// released, so a drag is one step). Returns whether the project changed.
    pub fn edit(&mut self, label: &str, change: impl FnOnce(&mut Project)) -> bool {
        let before = self.project.clone();
        change(&mut self.project);
        if self.project == before {
            return false;
        }
        self.revision = next_revision();
        let merge = self.open_step && self.undo.last().is_some_and(|s| s.label == label);
        if !merge {
            self.undo.push(Step {
                label: label.to_string(),
                before,
            });
            if self.undo.len() > UNDO_LIMIT {
                self.undo.remove(0);
                self.saved_at = self.saved_at.and_then(|s| s.checked_sub(1));
            }
            if self.saved_at.is_some_and(|s| s >= self.undo.len()) {
                // The saved state was in the redo branch we drop now.
                self.saved_at = None;
            }
            self.redo.clear();
        }
        self.open_step = true;
        true
    }

    /// Ends the open step: the next edit starts a new undo step.
    pub fn seal(&mut self) {
        self.open_step = false;
    }

    /// Undoes the last step; returns its label.
    pub fn undo(&mut self) -> Option<String> {
        let step = self.undo.pop()?;
        let after = std::mem::replace(&mut self.project, step.before);
        self.revision = next_revision();
        self.redo.push(Step {
            label: step.label.clone(),
            before: after,
        });
        self.open_step = false;
        Some(step.label)
    }

    /// Redoes the last undone step; returns its label.
    pub fn redo(&mut self) -> Option<String> {
        let step = self.redo.pop()?;
        let before = std::mem::replace(&mut self.project, step.before);
        self.revision = next_revision();
        self.undo.push(Step {
            label: step.label.clone(),
            before,
        });
        self.open_step = false;
        Some(step.label)
    }

    pub fn undo_label(&self) -> Option<&str> {
        self.undo.last().map(|s| s.label.as_str())
    }

    pub fn redo_label(&self) -> Option<&str> {
        self.redo.last().map(|s| s.label.as_str())
    }

    /// Every step's label, oldest first: the steps that can be undone, then
    /// the ones that can be redone (the next redo first).
    pub fn history_labels(&self) -> impl Iterator<Item = &str> {
        let undo = self.undo.iter();
        let redo = self.redo.iter().rev();
        undo.chain(redo).map(|s| s.label.as_str())
    }

    /// How many steps of [`Document::history_labels`] are applied now.
    pub fn history_position(&self) -> usize {
        self.undo.len()
    }

    /// Undoes or redoes until `position` steps are applied (clamped to the
    /// history); returns the labels undone or redone, in order.
    pub fn go_to(&mut self, position: usize) -> Vec<String> {
        let mut moved = Vec::new();
        while self.undo.len() > position {
            moved.extend(self.undo());
        }
        while self.undo.len() < position {
            match self.redo() {
                Some(label) => moved.push(label),
                None => break,
            }
        }
        moved
    }

    /// Whether there are changes since the project was opened or saved.
    pub fn is_dirty(&self) -> bool {
        self.saved_at != Some(self.undo.len())
    }

    /// Marks the project as changed since it was saved (recovered work
    /// that is not in its file).
    pub fn mark_unsaved(&mut self) {
        self.saved_at = None;
    }

    /// Records that the project is now saved at `path`.
    pub fn mark_saved(&mut self, path: PathBuf) {
        self.path = Some(path);
        self.saved_at = Some(self.undo.len());
        self.open_step = false;
    }

    /// The name shown in the title bar.
    pub fn title(&self) -> String {
        let file = self
            .path
            .as_ref()
            .and_then(|p| p.file_name())
            .map(|n| n.to_string_lossy().into_owned());
        let name = file.unwrap_or_else(|| format!("{} (not saved)", self.project.name));
        if self.is_dirty() {
            format!("{name} *")
        } else {
            name
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn doc() -> Document {
        Document::new(anthesis_sim::fixtures::whorl(1, 4, 6, 3), None)
    }

    #[test]
    fn undo_and_redo_restore_each_edit_and_the_dirty_flag() {
        let mut doc = doc();
        let original = doc.project().clone();
        assert!(!doc.is_dirty());
        doc.edit("dg", |p| p.flower.templates[0].dg = 0.01);
        doc.seal();
        doc.edit("thickness", |p| p.flower.templates[0].thickness = 0.5);
        assert!(doc.is_dirty());
        assert_eq!(doc.undo().as_deref(), Some("thickness"));
        assert_eq!(doc.project().flower.templates[0].thickness, 0.2);
        assert_eq!(doc.project().flower.templates[0].dg, 0.01);
        assert_eq!(doc.undo().as_deref(), Some("dg"));
        assert_eq!(doc.project(), &original);
        assert!(!doc.is_dirty(), "back at the opened state");
        assert_eq!(doc.redo().as_deref(), Some("dg"));
        assert_eq!(doc.project().flower.templates[0].dg, 0.01);
        assert!(doc.is_dirty());
    }

    #[test]
    fn a_drag_is_one_step_until_sealed_and_no_op_edits_are_not_steps() {
        let mut doc = doc();
        for i in 1..=5 {
            doc.edit("dg", |p| p.flower.templates[0].dg = 0.001 * f64::from(i));
        }
        assert!(!doc.edit("dg", |p| p.flower.templates[0].dg = 0.005));
        doc.seal();
        doc.edit("dg", |p| p.flower.templates[0].dg = 0.5);
        doc.undo();
        assert_eq!(doc.project().flower.templates[0].dg, 0.005);
        doc.undo();
        assert_eq!(doc.project().flower.templates[0].dg, 0.003);
        assert!(doc.undo().is_none());
    }

    #[test]
    fn saving_clears_dirty_and_a_new_edit_after_undo_drops_the_saved_branch() {
        let mut doc = doc();
        doc.edit("dg", |p| p.flower.templates[0].dg = 0.01);
        doc.mark_saved(PathBuf::from("/tmp/x.anthesis.toml"));
        assert!(!doc.is_dirty());
        doc.undo();
        assert!(doc.is_dirty());
        doc.edit("thickness", |p| p.flower.templates[0].thickness = 0.3);
        assert!(doc.is_dirty());
        assert!(doc.redo().is_none());
        assert_eq!(doc.title(), "x.anthesis.toml *");
    }

    #[test]
    fn going_to_a_history_step_undoes_or_redoes_up_to_it() {
        let mut doc = doc();
        let original = doc.project().clone();
        for (i, label) in ["dg", "thickness", "kb"].iter().enumerate() {
            doc.edit(label, |p| p.flower.templates[0].dg = 0.1 * (i + 1) as f64);
            doc.seal();
        }
        let after_first = {
            let mut d = doc.clone();
            d.go_to(1);
            d.project().clone()
        };
        assert_eq!(
            doc.history_labels().collect::<Vec<_>>(),
            ["dg", "thickness", "kb"]
        );
        assert_eq!(doc.history_position(), 3);
        assert_eq!(doc.go_to(1), ["kb", "thickness"]);
        assert_eq!(doc.history_position(), 1);
        assert_eq!(doc.project().flower.templates[0].dg, 0.1);
        assert_eq!(doc.project(), &after_first);
        // The redo steps stay listed, after the applied ones.
        assert_eq!(
            doc.history_labels().collect::<Vec<_>>(),
            ["dg", "thickness", "kb"]
        );
        assert_eq!(doc.go_to(0), ["dg"]);
        assert_eq!(doc.project(), &original);
        assert!(!doc.is_dirty());
        assert_eq!(
            doc.go_to(99),
            ["dg", "thickness", "kb"],
            "clamped to the history"
        );
        assert!((doc.project().flower.templates[0].dg - 0.3).abs() < 1e-12);
        assert!(doc.go_to(3).is_empty());
    }

    #[test]
    fn the_revision_changes_with_the_project_only() {
        let mut doc = doc();
        let other = super::Document::new(doc.project().clone(), None);
        assert_ne!(doc.revision(), other.revision(), "another document");
        let opened = doc.revision();
        assert!(!doc.edit("thickness", |p| p.flower.templates[0].thickness = 0.2));
        doc.seal();
        assert_eq!(doc.revision(), opened, "no change, same revision");
        doc.edit("dg", |p| p.flower.templates[0].dg = 0.02);
        let edited = doc.revision();
        assert_ne!(edited, opened);
        doc.undo();
        assert_ne!(doc.revision(), edited);
        doc.redo();
        doc.mark_saved(PathBuf::from("/tmp/y.anthesis.toml"));
        let saved = doc.revision();
        assert_eq!(doc.revision(), saved, "saving changes no project");
    }
}

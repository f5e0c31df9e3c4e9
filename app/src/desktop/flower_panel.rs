//! The Flower panel: the flower as a whole. Its templates (add a simple
//! petal or a copy, remove one), its arrangement (listed organs, whorls,
//! a golden-angle spiral or an L-system, whose text is checked as it is
//! typed and applied when typing pauses), its organs (add and remove the
//! listed ones), the overlap order (which organ lies inside which, each
//! pair swappable) and the parts that do not grow.
//!
//! The panel only edits data: what an edit does to the organs and rules
//! is `anthesis_flower::edit`'s, and every change is one
//! [`ProjectEdit::Flower`] (or [`ProjectEdit::Parts`]), undoable and
//! re-simulated like a stroke.

use std::collections::BTreeMap;
use std::ops::Range;

use anthesis_flower::edit::{RuleOrigin, lsystem_like, spiral_like, whorls_like};
use anthesis_flower::structure::lsystem::LSystemError;
use anthesis_flower::structure::{Spiral, Structure, StructureError, Whorl};
use anthesis_flower::{Flower, Project};
use eframe::egui::{self, Color32, RichText};

use super::bud_sketch::{BudSketchState, bud_sketch_ui};
use super::checked_field::checked_with;
use super::command::{Command, ProjectEdit};
use super::parts_panel;
use super::shape_panel::{ShapeState, shape_ui};

mod arrangement;
mod lsystem;

use arrangement::arrangement_ui;

/// How long typing must pause before the L-system text is applied.
pub const TYPING_PAUSE_SECONDS: f64 = 0.5;

/// The panel's own state: the L-system text being typed.
#[derive(Debug, Default)]
pub struct FlowerPanelState {
    /// The L-system text as shown (the project's, or what is being typed).
    text: String,
    /// The project's text when `text` was last taken from it.
    source: Option<String>,
    /// When the text was last typed in, while it waits to be applied.
    typed_at: Option<f64>,
    /// What is wrong with `text`, if anything.
    error: Option<TextError>,
    /// Why the last edit was refused.
    refused: Option<String>,
    /// The template a new organ is made of.
    new_organ_template: usize,
    /// A template name being typed: the template and the text.
    renaming: Option<(usize, String)>,
    /// The L-system's units (project units per turtle unit), kept as the
    /// project has them.
    units: f64,
    /// The Shape section: remeshing and the inner side of one template.
    shape: ShapeState,
    /// The Sketched bud section.
    bud: BudSketchState,
}

/// An error of the L-system text and where it is.
#[derive(Debug, Clone, PartialEq)]
struct TextError {
    message: String,
    /// Bytes of the text to highlight.
    at: Option<Range<usize>>,
}

impl FlowerPanelState {
    /// The L-system text shown (for tests).
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The error shown under the L-system text, if any.
    pub fn text_error(&self) -> Option<&str> {
        self.error.as_ref().map(|e| e.message.as_str())
    }

    /// Why the last edit (or import) was refused, as shown in the panel.
    pub fn refused(&self) -> Option<&str> {
        self.refused.as_deref()
    }

    /// Shows why an edit made outside the panel (an import) was refused.
    pub(super) fn refuse(&mut self, message: String) {
        self.refused = Some(message);
    }

    /// A template was imported: it is the one the Shape section shows.
    pub(super) fn imported(&mut self, template: usize) {
        self.refused = None;
        self.shape.template = template;
        self.shape.edge = None;
        self.shape.open_now = true;
    }

    /// A scanned petal was read: it is reviewed in the panel.
    pub(super) fn scan_read(&mut self, review: super::scan_panel::ScanReview) {
        self.refused = None;
        self.shape.pde.scan = Some(review);
    }

    /// The Shape section's state (for tests).
    pub fn shape(&self) -> &ShapeState {
        &self.shape
    }

    /// The Sketched bud section's state (for tests).
    pub fn bud_sketch(&self) -> &BudSketchState {
        &self.bud
    }
}

/// Which kind of arrangement.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Listed,
    Whorls,
    Spiral,
    LSystem,
}

impl Kind {
    fn of(structure: Option<&Structure>) -> Kind {
        match structure {
            None => Kind::Listed,
            Some(Structure::Whorls { .. }) => Kind::Whorls,
            Some(Structure::Spiral(_)) => Kind::Spiral,
            Some(Structure::LSystem { .. }) => Kind::LSystem,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Kind::Listed => "Listed organs",
            Kind::Whorls => "Whorls",
            Kind::Spiral => "Spiral",
            Kind::LSystem => "L-system",
        }
    }
}

/// What the panel asks for: an edited flower with its label, or a message.
enum Outcome {
    Edit(String, Flower),
    Refused(String),
}

/// The mean edge a new Bézier, PDE or sketched petal is meshed at (the
/// simple petal's).
fn new_shape_edge() -> f64 {
    anthesis_garden::five_petal::SIMPLE_PETAL_EDGE * anthesis_garden::flowers::EDGE_SCALE
}

/// A new template of [`BezierPatch::petal`](anthesis_bud::BezierPatch::petal)
/// meshed at [`new_shape_edge`], with uniform maps.
fn new_bezier_template() -> Result<anthesis_flower::Template, String> {
    let net = anthesis_bud::BezierPatch::petal();
    let edge = new_shape_edge();
    let bud = anthesis_bud::build_organ(&net, &anthesis_bud::RemeshOptions::new(edge))
        .map_err(|e| e.to_string())?;
    let mut template =
        anthesis_garden::five_petal::simple_template_of_mesh("bezier petal", bud.mesh);
    template.source = Some(anthesis_flower::TemplateSource::Bezier { net, edge });
    Ok(template)
}

/// A template made by one of the "New … petal" buttons added with one
/// organ of it, and shown in the Shape section; or why it was not.
fn with_new_shape(
    flower: &Flower,
    state: &mut FlowerPanelState,
    made: Result<anthesis_flower::Template, String>,
) -> Outcome {
    match made.and_then(|t| flower.with_template_and_organ(t).map_err(|e| e.to_string())) {
        Ok(added) => {
            let index = added.templates.len() - 1;
            let name = added.templates[index].name.clone();
            state.shape.template = index;
            state.shape.edge = None;
            state.shape.open_now = true;
            Outcome::Edit(format!("add template {name}"), added)
        }
        Err(error) => Outcome::Refused(error),
    }
}

fn outcome(
    label: impl Into<String>,
    result: Result<Flower, anthesis_flower::edit::EditError>,
) -> Outcome {
    match result {
        Ok(flower) => Outcome::Edit(label.into(), flower),
        Err(error) => Outcome::Refused(error.to_string()),
    }
}

/// A labelled number row (see `parts_panel`).
fn number(
    ui: &mut egui::Ui,
    label: &str,
    tooltip: &str,
    value: &mut f64,
    range: std::ops::RangeInclusive<f64>,
) -> bool {
    parts_panel::row(ui, label, tooltip, value, range)
}

/// A template chooser; returns whether it changed.
fn template_combo(
    ui: &mut egui::Ui,
    id: impl std::hash::Hash + std::fmt::Debug,
    label: egui::Id,
    flower: &Flower,
    template: &mut usize,
) -> bool {
    let before = *template;
    let selected = flower
        .templates
        .get(*template)
        .map_or("(none)", |t| t.name.as_str());
    egui::ComboBox::from_id_salt(id)
        .selected_text(selected)
        .show_ui(ui, |ui| {
            for (i, t) in flower.templates.iter().enumerate() {
                ui.selectable_value(template, i, &t.name);
            }
        })
        .response
        .labelled_by(label);
    *template != before
}

/// Shows the Flower panel for `project`; returns the edits the user made.
/// `now` is the input time in seconds (typing pauses are measured in it).
pub fn flower_ui(
    ui: &mut egui::Ui,
    project: &Project,
    state: &mut FlowerPanelState,
    now: f64,
) -> Vec<Command> {
    let flower = &project.flower;
    let mut outcomes: Vec<Outcome> = Vec::new();
    let mut commands_early: Vec<Command> = Vec::new();

    templates_ui(ui, flower, state, &mut outcomes, &mut commands_early);
    ui.separator();

    // A scanned petal under review.
    if let Some(index) =
        super::scan_panel::scan_ui(ui, flower, &mut state.shape.pde.scan, &mut commands_early)
    {
        state.shape.template = index;
        state.shape.edge = None;
        state.shape.open_now = true;
    }

    // The shape of one template.
    shape_ui(ui, flower, &mut state.shape, &mut commands_early);
    bud_sketch_ui(
        ui,
        (flower, project.settings.keyframes),
        &mut state.bud,
        &mut commands_early,
    );
    ui.separator();

    arrangement_ui(ui, flower, state, now, &mut outcomes);
    ui.separator();

    organs_ui(ui, flower, state, &mut outcomes);
    ui.separator();

    overlaps_ui(ui, flower, &mut outcomes);
    ui.separator();

    let mut commands = commands_early;
    for out in outcomes {
        match out {
            Outcome::Edit(label, flower) => {
                state.refused = None;
                commands.push(Command::Edit {
                    label,
                    edit: ProjectEdit::Flower(Box::new(flower)),
                });
            }
            Outcome::Refused(message) => state.refused = Some(message),
        }
    }
    // Parts.
    commands.extend(parts_panel::parts_ui(ui, project));
    commands
}

/// The Templates section: each template (renamed in place, removed),
/// then the buttons that add one (from a shape, a mesh or a scan).
fn templates_ui(
    ui: &mut egui::Ui,
    flower: &Flower,
    state: &mut FlowerPanelState,
    outcomes: &mut Vec<Outcome>,
    commands_early: &mut Vec<Command>,
) {
    // Templates.
    ui.strong("Templates")
        .on_hover_text("The organ types: a mesh, growth maps and material each.");
    for (i, template) in flower.templates.iter().enumerate() {
        let organs = flower.organs.iter().filter(|o| o.template == i).count();
        ui.horizontal(|ui| {
            // The name as typed, applied when the field is left.
            let mut text = match &state.renaming {
                Some((t, typed)) if *t == i => typed.clone(),
                _ => template.name.clone(),
            };
            let label = ui.label("name").id;
            let field = ui
                .add(egui::TextEdit::singleline(&mut text).desired_width(90.0))
                .labelled_by(label)
                .on_hover_text("The template's name (Enter or leaving the field renames it)");
            if field.lost_focus() {
                state.renaming = None;
                if text.trim() != template.name {
                    outcomes.push(outcome(
                        format!("rename template {} to {}", template.name, text.trim()),
                        flower.with_template_renamed(i, &text),
                    ));
                }
            } else if field.has_focus() {
                state.renaming = Some((i, text));
            }
            ui.label(format!(
                "{organs} organ{}",
                if organs == 1 { "" } else { "s" }
            ));
            let remove = ui
                .add_enabled(
                    flower.templates.len() > 1,
                    egui::Button::new("Remove").small(),
                )
                .on_hover_text("Remove the template, its organs and the whorls that use it");
            if remove.clicked() {
                outcomes.push(outcome(
                    format!("remove template {}", template.name),
                    flower.without_template(i),
                ));
            }
        });
    }
    add_template_ui(ui, flower, state, outcomes, commands_early);
}

/// The buttons that add a template: the simple petal, a new Bézier, PDE
/// or sketched petal, an OBJ, a scanned petal, or a copy of the chosen one.
fn add_template_ui(
    ui: &mut egui::Ui,
    flower: &Flower,
    state: &mut FlowerPanelState,
    outcomes: &mut Vec<Outcome>,
    commands_early: &mut Vec<Command>,
) {
    ui.horizontal_wrapped(|ui| {
        if ui
            .button("Add simple petal")
            .on_hover_text("A flat, slightly cupped petal with uniform growth maps, to paint")
            .clicked()
        {
            match anthesis_garden::five_petal::simple_petal_template(
                "petal",
                anthesis_garden::flowers::EDGE_SCALE,
            ) {
                Ok(template) => {
                    let added = flower.with_template(template);
                    let name = added
                        .templates
                        .last()
                        .map_or(String::new(), |t| t.name.clone());
                    outcomes.push(Outcome::Edit(format!("add template {name}"), added));
                }
                Err(error) => outcomes.push(Outcome::Refused(error.to_string())),
            }
        }
        if ui
            .button("New Bézier petal")
            .on_hover_text(
                "A new template from a 4×4 Bézier control net (edit it under Shape) with uniform \
                 growth maps, and one organ of it",
            )
            .clicked()
        {
            outcomes.push(with_new_shape(flower, state, new_bezier_template()));
        }
        if ui
            .button("New PDE petal")
            .on_hover_text(
                "A new template from a PDE sweep between two margin curves (edit its curves and \
                 tangents under Shape) with uniform growth maps, and one organ of it",
            )
            .clicked()
        {
            let made = super::pde_panel::new_pde_template(new_shape_edge());
            outcomes.push(with_new_shape(flower, state, made));
        }
        if ui
            .button("New sketched petal")
            .on_hover_text(
                "A new template of a petal drawn with strokes (two margins, the vein, \
                 cross-sections; redraw them under Shape) with uniform growth maps, and one \
                 organ of it",
            )
            .clicked()
        {
            let made = super::sketch_panel::new_sketched_template(new_shape_edge());
            outcomes.push(with_new_shape(flower, state, made));
        }
        let source = state
            .new_organ_template
            .min(flower.templates.len().saturating_sub(1));
        if ui
            .button("Import OBJ…")
            .on_hover_text(
                "A new template of an OBJ mesh (UVs: u across, v from base to tip; inner side \
                 facing −Z) with uniform growth maps, and one organ of it",
            )
            .clicked()
        {
            commands_early.push(Command::BrowseTemplateObj);
        }
        if ui
            .button("Import scanned petal…")
            .on_hover_text(
                "A new template fitted to a petal mesh of any triangulation without UVs (a scan \
                 or CAD export): check its base and tip, see the fit error, then make it",
            )
            .clicked()
        {
            commands_early.push(Command::BrowseScan);
        }
        if let Some(template) = flower.templates.get(source)
            && ui
                .button("Duplicate template")
                .on_hover_text("A copy of the template chosen under Organs, to change on its own")
                .clicked()
        {
            let added = flower.with_template(template.clone());
            let name = added
                .templates
                .last()
                .map_or(String::new(), |t| t.name.clone());
            outcomes.push(Outcome::Edit(format!("add template {name}"), added));
        }
    });
}

/// The Organs section: the organs listed and made, and a new listed organ.
fn organs_ui(
    ui: &mut egui::Ui,
    flower: &Flower,
    state: &mut FlowerPanelState,
    outcomes: &mut Vec<Outcome>,
) {
    // Organs.
    let made = flower.made_organ_count();
    egui::CollapsingHeader::new(format!("Organs ({})", flower.organs.len()))
        .id_salt("flower organs")
        .show(ui, |ui| {
            for (i, organ) in flower.organs.iter().enumerate() {
                ui.horizontal(|ui| {
                    let template = flower
                        .templates
                        .get(organ.template)
                        .map_or("?", |t| t.name.as_str());
                    ui.label(format!("{} ({template})", organ.name));
                    if i < made {
                        ui.weak("arranged");
                    } else if ui
                        .small_button("Remove organ")
                        .on_hover_text("Remove this listed organ and its overlap rules")
                        .clicked()
                    {
                        outcomes.push(outcome(
                            format!("remove organ {}", organ.name),
                            flower.without_organ(i),
                        ));
                    }
                });
                if i >= made
                    && let Some((field, moved)) = placement_rows(ui, organ, i)
                {
                    outcomes.push(outcome(
                        format!("{field} of {}", organ.name),
                        flower.with_organ_changed(i, moved),
                    ));
                }
            }
        });
    ui.horizontal(|ui| {
        let mut template = state
            .new_organ_template
            .min(flower.templates.len().saturating_sub(1));
        let label = ui.label("new organ of").id;
        template_combo(ui, "new organ template", label, flower, &mut template);
        state.new_organ_template = template;
        if ui
            .button("Add organ")
            .on_hover_text("One more organ of this template, listed after the arranged ones")
            .clicked()
            && let Some(organ) = flower.new_organ(template)
        {
            let name = organ.name.clone();
            outcomes.push(outcome(
                format!("add organ {name}"),
                flower.with_organ(organ),
            ));
        }
    });
}

/// The Overlap order section: which organ of each overlapping pair lies
/// inside, and where the rule comes from; a click swaps a pair.
fn overlaps_ui(ui: &mut egui::Ui, flower: &Flower, outcomes: &mut Vec<Outcome>) {
    // Overlap order.
    let origins = flower.rule_origins();
    egui::CollapsingHeader::new(format!("Overlap order ({} pairs)", flower.overlaps.len()))
        .id_salt("overlap order")
        .show(ui, |ui| {
            if flower.overlaps.is_empty() {
                ui.label("No organs overlap: none lies inside another.");
            }
            // By pair, whichever way round: a swapped pair keeps its row.
            let mut order: Vec<usize> = (0..flower.overlaps.len()).collect();
            order.sort_by_key(|&i| {
                let o = flower.overlaps[i];
                (o.inner.min(o.outer), o.inner.max(o.outer))
            });
            for i in order {
                let (Some(rule), Some(origin)) = (flower.overlaps.get(i), origins.get(i)) else {
                    continue;
                };
                let (Some(inner), Some(outer)) =
                    (flower.organs.get(rule.inner), flower.organs.get(rule.outer))
                else {
                    continue;
                };
                ui.horizontal(|ui| {
                    ui.label(format!("{} inside {}", inner.name, outer.name));
                    match origin {
                        RuleOrigin::Made => ui.weak("arranged"),
                        RuleOrigin::Overridden => ui.label(RichText::new("swapped").italics()),
                        RuleOrigin::Listed => ui.weak("listed"),
                    };
                    if ui
                        .small_button("Swap")
                        .on_hover_text("The other way round: the outer one lies inside")
                        .clicked()
                    {
                        outcomes.push(outcome(
                            format!("swap {} and {}", inner.name, outer.name),
                            flower.with_rule_swapped(i),
                        ));
                    }
                });
            }
        });
}

/// Where a listed organ sits: its base's azimuth and distance from the
/// axis, its height and its joint angle. A turn about the axis turns the
/// whole organ (position and facing); returns the field changed and the
/// moved organ.
fn placement_rows(
    ui: &mut egui::Ui,
    organ: &anthesis_flower::Organ,
    id: usize,
) -> Option<(&'static str, anthesis_flower::Organ)> {
    let p = organ.placement;
    let at_deg = p.position.x.atan2(p.position.z).to_degrees();
    let (mut azimuth, mut distance, mut height, mut joint) = (
        at_deg,
        p.position.x.hypot(p.position.z),
        p.position.y,
        p.joint_angle_deg,
    );
    let mut field = None;
    egui::Grid::new(("organ placement", id))
        .num_columns(2)
        .spacing([12.0, 4.0])
        .show(ui, |ui| {
            let rows: [(&'static str, &str, &mut f64, std::ops::RangeInclusive<f64>); 4] = [
                (
                    "azimuth",
                    "Where its base sits around the axis, in degrees (0: +Z).",
                    &mut azimuth,
                    -360.0..=360.0,
                ),
                (
                    "distance",
                    "Distance of its base from the axis.",
                    &mut distance,
                    0.0..=1000.0,
                ),
                (
                    "height",
                    "Height of its base.",
                    &mut height,
                    -1000.0..=1000.0,
                ),
                (
                    "joint angle",
                    "Initial tilt outwards, in degrees.",
                    &mut joint,
                    -180.0..=180.0,
                ),
            ];
            for (name, tooltip, value, range) in rows {
                if number(ui, name, tooltip, value, range) && field.is_none() {
                    field = Some(name);
                }
            }
        });
    let field = field?;
    let mut moved = organ.clone();
    let turn = glam::DQuat::from_rotation_y((azimuth - at_deg).to_radians());
    let turned = turn * p.position;
    let horizontal = glam::DVec2::new(turned.x, turned.z);
    let horizontal = if horizontal.length() > 1e-12 {
        horizontal.normalize() * distance
    } else {
        let a = azimuth.to_radians();
        glam::DVec2::new(a.sin(), a.cos()) * distance
    };
    moved.placement.position = glam::DVec3::new(horizontal.x, height, horizontal.y);
    moved.placement.azimuth_deg = p.azimuth_deg + (azimuth - at_deg);
    moved.placement.joint_angle_deg = joint;
    Some((field, moved))
}

/// Whorls start open when there are few of them.
fn draft_len_is_small(n: usize) -> bool {
    n <= 2
}

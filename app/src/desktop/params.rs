//! The parameters panel: the selected organ's template (dg, thickness,
//! Ks, Kb, joint schedule, base region, base and second colour), the
//! project's keyframe count, the two-state opening (g, T, the velocity
//! curve and their plot; [`super::two_state`]) and
//! its resolution (with the particles each organ gets), each with a tooltip
//! saying what it does. An edit becomes a [`Command::Edit`], so each is
//! undoable and restarts the simulation.

use anthesis_flower::resolution::predicted_size;
use anthesis_flower::{Colouring, DEFAULT_SECOND_COLOUR, JointRamp, Project, Resolution, Template};
use eframe::egui;

use super::checked_field::{checked_with, flagged};

use super::command::{Command, ProjectEdit};
use super::two_state::{ViewedOrgan, two_state_ui};
use super::widgets::section;
use super::words;

/// A labelled number row of the parameter `symbol`, named and explained
/// by [`words`]; returns whether it changed.
fn number(
    ui: &mut egui::Ui,
    symbol: &str,
    value: &mut f64,
    speed: f64,
    range: std::ops::RangeInclusive<f64>,
) -> bool {
    let tooltip = words::tooltip(symbol);
    let label_response = ui.label(words::label(symbol)).on_hover_text(&tooltip);
    let changed =
        super::checked_field::checked_number(ui, &words::label(symbol), value, speed, range)
            .labelled_by(label_response.id)
            .on_hover_text(tooltip)
            .changed();
    ui.end_row();
    changed
}

/// Shows the panel for template `template` of `project` (`resolved` is the
/// project at its resolution, as simulated: it gives the particle counts);
/// returns the edit the user made, if any.
pub fn parameters_ui(
    ui: &mut egui::Ui,
    project: &Project,
    resolved: &Project,
    template: usize,
) -> Option<Command> {
    parameters_ui_viewing(ui, project, resolved, template, None)
}

/// [`parameters_ui`] knowing the selected organ's shape at the keyframe
/// shown (for "Open shape from keyframe N").
pub fn parameters_ui_viewing(
    ui: &mut egui::Ui,
    project: &Project,
    resolved: &Project,
    template: usize,
    viewed: Option<&ViewedOrgan>,
) -> Option<Command> {
    let Some(original) = project.flower.templates.get(template) else {
        ui.label("No organ selected.");
        return None;
    };

    let mut draft: Template = original.clone();
    let mut keyframes = project.settings.keyframes;
    let name = draft.name.clone();
    let mut changed_field: Option<&str> = None;
    let mut mark = |changed: bool, field: &'static str| {
        if changed && changed_field.is_none() {
            changed_field = Some(field);
        }
    };

    ui.heading(format!("Template “{name}”"));
    egui::Grid::new("template parameters")
        .num_columns(2)
        .spacing([12.0, 6.0])
        .show(ui, |ui| {
            mark(number(ui, "dg", &mut draft.dg, 0.0001, -0.5..=0.5), "dg");
            mark(
                number(ui, "thickness", &mut draft.thickness, 0.005, 0.001..=100.0),
                "thickness",
            );
            mark(
                number(ui, "Ks", &mut draft.stretch_stiffness, 0.1, 0.001..=1.0e6),
                "Ks",
            );
            mark(
                number(ui, "Kb", &mut draft.bend_stiffness, 0.1, 0.001..=1.0e6),
                "Kb",
            );
            let tooltip = words::tooltip("keyframes");
            let label = ui.label(words::label("keyframes")).on_hover_text(&tooltip);
            // A checked field, as the others: a typed count out of range or
            // not a number is marked and logged, not silently clamped.
            let changed = checked_with(
                ui,
                &words::label("keyframes"),
                &mut keyframes,
                1..=anthesis_flower::MAX_KEYFRAMES,
                |d| d.speed(1.0),
            )
            .labelled_by(label.id)
            .on_hover_text(tooltip)
            .changed();
            mark(changed, "keyframes");
            ui.end_row();
        });

    base_region_ui(ui, &mut draft, &mut mark);
    joint_schedule_ui(ui, &mut draft, &mut mark);

    if let Some(command) = two_state_ui(ui, project, template, &mut draft, viewed, &mut mark) {
        return Some(command);
    }
    if let Some(edit) = resolution_ui(ui, project, resolved, template) {
        return Some(edit);
    }
    colour_ui(ui, &mut draft, &mut mark);

    let field = changed_field?;
    Some(Command::Edit {
        label: edit_label(field, &name),
        edit: ProjectEdit::Template {
            template,
            value: Box::new(draft),
            keyframes,
        },
    })
}

/// The Base region section: the UV box whose particles attach the organ.
fn base_region_ui(
    ui: &mut egui::Ui,
    draft: &mut Template,
    mark: &mut dyn FnMut(bool, &'static str),
) {
    section(
        ui,
        "Base region",
        "Particles whose UV lies here attach the organ to the receptacle.",
        |ui| {
            egui::Grid::new("base region")
                .num_columns(2)
                .show(ui, |ui| {
                    let base = &mut draft.base_region;
                    mark(
                        number(ui, "v max", &mut base.v_max, 0.002, 0.0..=1.0),
                        "base v max",
                    );
                    mark(
                        number(ui, "u min", &mut base.u_min, 0.005, 0.0..=1.0),
                        "base u min",
                    );
                    mark(
                        number(ui, "u max", &mut base.u_max, 0.005, 0.0..=1.0),
                        "base u max",
                    );
                });
        },
    );
}

/// The largest step a joint ramp's fields accept.
const STEP_MAX: u32 = 100_000;

/// What is wrong with a ramp that ends before it starts (a run refuses
/// it), with the range each of its step fields accepts given the
/// other; `None` for a ramp that runs forwards.
fn backwards_ramp(ramp: &JointRamp) -> Option<String> {
    (ramp.to_step < ramp.from_step).then(|| {
        format!(
            "to step {} is before from step {}: a run stops at a ramp that ends before it \
             starts (to step accepts {} to {STEP_MAX} with this from step; from step accepts 0 \
             to {} with this to step)",
            ramp.to_step, ramp.from_step, ramp.from_step, ramp.to_step
        )
    })
}

/// The Joint schedule section: each ramp's steps and degrees, removed or
/// added.
fn joint_schedule_ui(
    ui: &mut egui::Ui,
    draft: &mut Template,
    mark: &mut dyn FnMut(bool, &'static str),
) {
    section(
        ui,
        "Joint schedule",
        "How the organ tilts outwards at its base over the steps: each ramp adds its degrees \
         evenly over its steps. Paper: lily +23° over steps 1–60.",
        |ui| joint_ramps_ui(ui, draft, mark),
    );
}

/// The joint schedule's ramps and "Add ramp".
fn joint_ramps_ui(
    ui: &mut egui::Ui,
    draft: &mut Template,
    mark: &mut dyn FnMut(bool, &'static str),
) {
    let mut remove = None;
    egui::Grid::new("joint schedule")
        .num_columns(4)
        .show(ui, |ui| {
            let header = |ui: &mut egui::Ui, symbol: &str| {
                ui.label(words::label(symbol))
                    .on_hover_text(words::tooltip(symbol))
                    .id
            };
            let from_label = header(ui, "from step");
            let to_label = header(ui, "to step");
            let degrees_label = header(ui, "degrees");
            ui.end_row();
            for (i, ramp) in draft.joint_schedule.iter_mut().enumerate() {
                let from = checked_with(ui, "from step", &mut ramp.from_step, 0..=STEP_MAX, |d| d);
                let to = checked_with(ui, "to step", &mut ramp.to_step, 0..=STEP_MAX, |d| d);
                // A ramp that ends before it starts adds nothing: both
                // fields are what make it so.
                let [from, to] = flagged(ui, [from, to], backwards_ramp(ramp));
                mark(
                    from.labelled_by(from_label)
                        .on_hover_text(words::tooltip("from step"))
                        .changed(),
                    "joint from",
                );
                mark(
                    to.labelled_by(to_label)
                        .on_hover_text(words::tooltip("to step"))
                        .changed(),
                    "joint to",
                );
                mark(
                    checked_with(ui, "degrees", &mut ramp.angle_deg, -180.0..=180.0, |d| {
                        d.speed(0.1).suffix("°")
                    })
                    .labelled_by(degrees_label)
                    .on_hover_text(words::tooltip("degrees"))
                    .changed(),
                    "joint degrees",
                );
                if ui
                    .small_button("Remove")
                    .on_hover_text("Remove this ramp")
                    .clicked()
                {
                    remove = Some(i);
                }
                ui.end_row();
            }
        });
    if let Some(i) = remove {
        draft.joint_schedule.remove(i);
        mark(true, "remove joint ramp");
    }
    if ui
        .button("Add ramp")
        .on_hover_text("Add a joint ramp after the last one")
        .clicked()
    {
        let from = draft.joint_schedule.last().map_or(0, |r| r.to_step);
        draft.joint_schedule.push(JointRamp {
            from_step: from,
            to_step: from + 20,
            angle_deg: 5.0,
        });
        mark(true, "add joint ramp");
    }
}

/// The Colour section: the base colour, the colour map's second colour,
/// and removing the colour map.
fn colour_ui(ui: &mut egui::Ui, draft: &mut Template, mark: &mut dyn FnMut(bool, &'static str)) {
    section(
        ui,
        "Colour",
        "What the organ looks like (not simulated): the base colour, and a second colour \
         painted over it with the paint panel's colour map.",
        |ui| colour_rows(ui, draft, mark),
    );
}

/// The Colour section's rows.
fn colour_rows(ui: &mut egui::Ui, draft: &mut Template, mark: &mut dyn FnMut(bool, &'static str)) {
    egui::Grid::new("template colours")
        .num_columns(2)
        .show(ui, |ui| {
            let (base, changed) = colour_row(
                ui,
                "base colour",
                "The organ's colour where the colour map is 0 (everywhere without one).",
                draft.colour,
            );
            if changed {
                draft.colour = base;
                mark(true, "base colour");
            }
            let second = draft
                .colouring
                .as_ref()
                .map_or(DEFAULT_SECOND_COLOUR, |c| c.second_colour);
            let (second, changed) = colour_row(
                ui,
                "second colour",
                "The colour painted over the base colour where the colour map is 1 (paint it \
                 with the paint panel's target “colour”).",
                second,
            );
            if changed {
                draft
                    .colouring
                    .get_or_insert_with(|| Colouring {
                        second_colour: second,
                        mix: anthesis_maps::ScalarMap::constant(0.0),
                        layers: Vec::new(),
                    })
                    .second_colour = second;
                mark(true, "second colour");
            }
        });
    if draft.colouring.is_some()
        && ui
            .button("Remove colour map")
            .on_hover_text("The organ goes back to its base colour all over")
            .clicked()
    {
        draft.colouring = None;
        mark(true, "colour map");
    }
}

/// A labelled colour button (linear RGBA, alpha kept); returns the colour
/// and whether it changed.
fn colour_row(ui: &mut egui::Ui, label: &str, tooltip: &str, linear: [f32; 4]) -> ([f32; 4], bool) {
    let label = ui.label(label).on_hover_text(tooltip);
    let mut rgba = egui::Rgba::from_rgb(linear[0], linear[1], linear[2]);
    let changed = egui::color_picker::color_edit_button_rgba(
        ui,
        &mut rgba,
        egui::color_picker::Alpha::Opaque,
    )
    .labelled_by(label.id)
    .on_hover_text(tooltip)
    .changed();
    ui.end_row();
    let clamp = |c: f32| c.clamp(0.0, 1.0);
    (
        [clamp(rgba.r()), clamp(rgba.g()), clamp(rgba.b()), linear[3]],
        changed,
    )
}

/// The undo step's name for a changed parameter: what changed and whose it
/// is (the keyframe count is the project's, the rest the template's).
fn edit_label(field: &str, template_name: &str) -> String {
    const PROJECT_FIELDS: [&str; 1] = ["keyframes"];
    if PROJECT_FIELDS.contains(&field) {
        format!("{field} of the project")
    } else {
        format!("{field} of {template_name}")
    }
}

/// The Resolution section: the mean edge every template is simulated at
/// and the particles per organ; returns the edit made.
fn resolution_ui(
    ui: &mut egui::Ui,
    project: &Project,
    resolved: &Project,
    template: usize,
) -> Option<Command> {
    section(
        ui,
        "Resolution (whole flower)",
        &words::tooltip("mean edge"),
        |ui| resolution_rows(ui, project, resolved, template),
    )
    .flatten()
}

/// The resolution row and the particles per organ; returns the edit made.
fn resolution_rows(
    ui: &mut egui::Ui,
    project: &Project,
    resolved: &Project,
    template: usize,
) -> Option<Command> {
    let current = project.settings.resolution;
    let built_edge = project
        .flower
        .templates
        .get(template)
        .map(|t| anthesis_bud::quality(&t.mesh).mean_edge)
        .unwrap_or(1.0);
    let draft_id = ui.scope_id().with("mean edge while dragged");
    let dragged_edge: Option<f64> = ui.data(|d| d.get_temp(draft_id));
    let mut chosen = None;
    let tooltip = words::tooltip("mean edge");
    egui::Grid::new("resolution")
        .num_columns(2)
        .spacing([12.0, 6.0])
        .show(ui, |ui| {
            let mut remesh = current.mean_edge().is_some();
            if ui
                .checkbox(&mut remesh, words::label("mean edge"))
                .on_hover_text(&tooltip)
                .changed()
            {
                chosen = Some(if remesh {
                    Resolution::MeanEdge(round_to_3_digits(built_edge))
                } else {
                    Resolution::AsBuilt
                });
            }
            match current.mean_edge() {
                Some(edge) => {
                    let mut value = dragged_edge.unwrap_or(edge);
                    let response = checked_with(
                        ui,
                        "mean edge",
                        &mut value,
                        1e-3 * built_edge..=1e3 * built_edge,
                        |d| {
                            d.speed(0.01 * edge)
                                .max_decimals(4)
                                // A typed edge counts when entered: on the
                                // way to 0.5, "0" would be the smallest
                                // edge, remeshed (or refused) at once.
                                .update_while_editing(false)
                        },
                    )
                    .on_hover_text(&tooltip);
                    if response.dragged() {
                        ui.data_mut(|d| d.insert_temp(draft_id, value));
                    } else {
                        ui.data_mut(|d| d.remove::<f64>(draft_id));
                        if (response.changed() || response.drag_stopped()) && value != edge {
                            chosen = Some(Resolution::MeanEdge(value));
                        }
                    }
                }
                None => {
                    ui.label("as built");
                }
            }
            ui.end_row();
        });
    // Particles per organ, template by template (the organs of a template
    // share its mesh).
    egui::Grid::new("particles per organ")
        .num_columns(2)
        .spacing([12.0, 2.0])
        .show(ui, |ui| {
            for (i, (t, r)) in project
                .flower
                .templates
                .iter()
                .zip(&resolved.flower.templates)
                .enumerate()
            {
                let organs = project.flower.organs.iter().filter(|o| o.template == i).count();
                let name = if organs == 1 {
                    t.name.clone()
                } else {
                    format!("{} ×{organs}", t.name)
                };
                let particles = match dragged_edge {
                    Some(edge) => format!("≈ {}", grouped(predicted_size(&t.mesh, edge).0 as u64)),
                    None => grouped(r.mesh.vertex_count() as u64),
                };
                let label = if i == template {
                    egui::RichText::new(name).strong()
                } else {
                    egui::RichText::new(name)
                };
                ui.label(label);
                ui.label(format!("{particles} particles"))
                    .on_hover_text(format!(
                        "Particles of each organ of template “{}” at this resolution (as built: {})",
                        t.name,
                        grouped(t.mesh.vertex_count() as u64)
                    ));
                ui.end_row();
            }
        });
    chosen.map(|resolution| Command::Edit {
        label: "resolution".to_string(),
        edit: ProjectEdit::Resolution(resolution),
    })
}

/// `value` rounded to three significant digits (a starting edge a person
/// can read).
pub fn round_to_3_digits(value: f64) -> f64 {
    if !(value > 0.0 && value.is_finite()) {
        return 1.0;
    }
    let scale = 10f64.powi(2 - value.log10().floor() as i32);
    (value * scale).round() / scale
}

/// `n` with a comma every three digits, as the window and the README write
/// counts.
pub fn grouped(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::edit_label;

    #[test]
    fn an_undo_step_names_whose_value_changed() {
        assert_eq!(edit_label("keyframes", "petal"), "keyframes of the project");
        assert_eq!(edit_label("thickness", "petal"), "thickness of petal");
    }
}

//! The parts section of the parameters panel: the flower's organs that do
//! not grow (stamens, pistils, the stem, the receptacle), each with the
//! parameters of its kind, its colours and its schedule; buttons add a part
//! sized to the flower or remove one. Every edit is one
//! [`ProjectEdit::Parts`] (the whole list, which is small), so it is
//! undoable and re-simulates like any other edit.

use anthesis_flower::parts::{Part, PartShape, Tube, default_colours, instance_name};
use anthesis_flower::{JointRamp, Project};
use eframe::egui::{self, Rgba};

use super::checked_field::{self, checked_with};

use super::command::{Command, ProjectEdit};

/// The unit of a part's or an arrangement's row, from the last word of its
/// label (the rows are lengths or angles), in the words of
/// [`super::words`].
fn unit_of(label: &str) -> Option<&'static str> {
    match label.rsplit(' ').next()? {
        "length" | "radius" | "size" | "depth" | "height" | "distance" | "step" => {
            Some("project units (lengths)")
        }
        "curvature" | "tilt" | "offset" | "angle" | "span" | "divergence" | "azimuth" => {
            Some("degrees")
        }
        _ => None,
    }
}

/// A labelled number row; returns whether it changed. Its tooltip ends
/// with the row's unit.
pub(super) fn row(
    ui: &mut egui::Ui,
    label: &str,
    tooltip: &str,
    value: &mut f64,
    range: std::ops::RangeInclusive<f64>,
) -> bool {
    let name = label;
    let tooltip = match unit_of(label) {
        Some(unit) => format!("{tooltip}\nUnit: {unit}."),
        None => tooltip.to_owned(),
    };
    let tooltip = tooltip.as_str();
    let label = ui.label(label).on_hover_text(tooltip);
    let speed = (0.01 * (*range.end() - *range.start()).abs()).clamp(1e-3, 1.0);
    let changed = checked_with(ui, name, value, range, |d| d.speed(speed).max_decimals(3))
        .labelled_by(label.id)
        .on_hover_text(tooltip)
        .changed();
    ui.end_row();
    changed
}

/// A tube's three rows.
fn tube_rows(ui: &mut egui::Ui, what: &str, tube: &mut Tube) -> bool {
    let mut changed = row(
        ui,
        &format!("{what} length"),
        "Length along its centre line.",
        &mut tube.length,
        0.01..=1000.0,
    );
    let widest = 0.5 * tube.length;
    changed |= row(
        ui,
        &format!("{what} radius"),
        "Radius (at most half the length).",
        &mut tube.radius,
        0.001..=widest,
    );
    changed |= row(
        ui,
        &format!("{what} curvature"),
        "How far it turns outwards over its length (negative: inwards).",
        &mut tube.curvature_deg,
        -360.0..=360.0,
    );
    changed
}

/// A colour row; returns whether it changed.
fn colour_row(ui: &mut egui::Ui, label: &str, colour: &mut [f32; 4]) -> bool {
    ui.label(label);
    let mut rgba = Rgba::from_rgba_unmultiplied(colour[0], colour[1], colour[2], colour[3]);
    let changed = egui::color_picker::color_edit_button_rgba(
        ui,
        &mut rgba,
        egui::color_picker::Alpha::Opaque,
    )
    .on_hover_text(format!("The {label}"))
    .changed();
    ui.end_row();
    if changed {
        *colour = rgba.to_rgba_unmultiplied();
        for c in colour.iter_mut() {
            *c = c.clamp(0.0, 1.0);
        }
    }
    changed
}

/// The rows of one part; returns the name of the field that changed.
fn part_rows(ui: &mut egui::Ui, part: &mut Part) -> Option<&'static str> {
    let mut changed = None;
    let mut mark = |c: bool, field: &'static str| {
        if c && changed.is_none() {
            changed = Some(field);
        }
    };
    let receptacle = matches!(part.shape, PartShape::Receptacle { .. });
    if !receptacle {
        let mut count = part.count;
        let label = ui.label("count").on_hover_text("How many around the axis.");
        mark(
            checked_with(
                ui,
                "count",
                &mut count,
                1..=anthesis_flower::parts::MAX_PART_COUNT,
                |d| d,
            )
            .labelled_by(label.id)
            .changed(),
            "count",
        );
        part.count = count;
        ui.end_row();
        mark(
            row(
                ui,
                "ring radius",
                "Distance of the bases from the flower axis.",
                &mut part.ring_radius,
                0.0..=1000.0,
            ),
            "ring radius",
        );
        mark(
            row(
                ui,
                "offset",
                "Azimuth of the first one, in degrees (0 faces +Z).",
                &mut part.offset_deg,
                -360.0..=360.0,
            ),
            "offset",
        );
        mark(
            row(
                ui,
                "tilt",
                "Initial tilt outwards, in degrees; the schedule adds to it.",
                &mut part.angle_deg,
                -180.0..=180.0,
            ),
            "tilt",
        );
    }
    mark(
        row(
            ui,
            "height",
            "Height of the bases (the organs sit at 0).",
            &mut part.height,
            -1000.0..=1000.0,
        ),
        "height",
    );
    shape_fields(ui, &mut part.shape, &mut mark);
    mark(colour_row(ui, "colour", &mut part.colour), "colour");
    if matches!(
        part.shape,
        PartShape::Stamen { .. } | PartShape::Pistil { .. }
    ) {
        mark(
            colour_row(ui, "head colour", &mut part.head_colour),
            "head colour",
        );
    } else {
        part.head_colour = part.colour;
    }
    changed
}

/// The rows of what the part is: a stamen's filament and anther, a
/// pistil's style, stigma and ovary, a stem, or the receptacle's radius
/// and depth.
fn shape_fields(
    ui: &mut egui::Ui,
    shape: &mut PartShape,
    mark: &mut dyn FnMut(bool, &'static str),
) {
    match shape {
        PartShape::Stamen {
            filament,
            anther_length,
            anther_radius,
            anther_tilt_deg,
        } => {
            mark(tube_rows(ui, "filament", filament), "filament");
            mark(
                row(
                    ui,
                    "anther length",
                    "Along its long axis.",
                    anther_length,
                    0.01..=100.0,
                ),
                "anther length",
            );
            mark(
                row(
                    ui,
                    "anther radius",
                    "Across it.",
                    anther_radius,
                    0.001..=100.0,
                ),
                "anther radius",
            );
            mark(
                row(
                    ui,
                    "anther tilt",
                    "0: the anther continues the filament; 90: it lies across the tip (a \
                     lily's).",
                    anther_tilt_deg,
                    -180.0..=180.0,
                ),
                "anther tilt",
            );
        }
        PartShape::Pistil {
            style,
            stigma_radius,
            stigma_lobes,
            ovary_length,
            ovary_radius,
        } => {
            mark(tube_rows(ui, "style", style), "style");
            mark(
                row(
                    ui,
                    "stigma size",
                    "The reach of each lobe.",
                    stigma_radius,
                    0.001..=100.0,
                ),
                "stigma size",
            );
            let label = ui.label("stigma lobes");
            mark(
                checked_with(
                    ui,
                    "stigma lobes",
                    stigma_lobes,
                    1..=anthesis_flower::parts::MAX_STIGMA_LOBES,
                    |d| d,
                )
                .labelled_by(label.id)
                .changed(),
                "stigma lobes",
            );
            ui.end_row();
            mark(
                row(
                    ui,
                    "ovary length",
                    "0 for no ovary.",
                    ovary_length,
                    0.0..=100.0,
                ),
                "ovary length",
            );
            mark(
                row(
                    ui,
                    "ovary radius",
                    "0 for no ovary.",
                    ovary_radius,
                    0.0..=100.0,
                ),
                "ovary radius",
            );
        }
        PartShape::Pedicel { stalk } => mark(tube_rows(ui, "stem", stalk), "stem"),
        PartShape::Receptacle { radius, depth } => {
            mark(
                row(ui, "radius", "Where the organs sit.", radius, 0.01..=1000.0),
                "radius",
            );
            mark(
                row(
                    ui,
                    "depth",
                    "How far it reaches down.",
                    depth,
                    0.01..=1000.0,
                ),
                "depth",
            );
        }
    }
}

/// The schedule rows of one part; returns the field that changed.
fn schedule_rows(ui: &mut egui::Ui, part: &mut Part, id: usize) -> Option<&'static str> {
    let mut changed = None;
    let mut remove = None;
    egui::Grid::new(("part schedule", id))
        .num_columns(4)
        .show(ui, |ui| {
            if part.schedule.is_empty() {
                return;
            }
            // Named columns, as the joint schedule's: three bare numbers
            // in a row do not say which is which.
            const FROM: &str = "The turn starts after this step";
            const TO: &str = "The turn is done at this step";
            const TURN: &str = "Degrees it turns outwards (unit: degrees)";
            let header = |ui: &mut egui::Ui, name: &str, tooltip: &str| {
                ui.label(name).on_hover_text(tooltip).id
            };
            let from_label = header(ui, "From step", FROM);
            let to_label = header(ui, "To step", TO);
            let turn_label = header(ui, "Turn (degrees)", TURN);
            ui.end_row();
            for (i, ramp) in part.schedule.iter_mut().enumerate() {
                if checked_with(ui, "from step", &mut ramp.from_step, 0..=100_000, |d| d)
                    .labelled_by(from_label)
                    .on_hover_text(FROM)
                    .changed()
                {
                    changed = Some("schedule");
                }
                if checked_with(ui, "to step", &mut ramp.to_step, 0..=100_000, |d| d)
                    .labelled_by(to_label)
                    .on_hover_text(TO)
                    .changed()
                {
                    changed = Some("schedule");
                }
                if checked_with(ui, "degrees", &mut ramp.angle_deg, -180.0..=180.0, |d| {
                    d.speed(0.1).suffix("°")
                })
                .labelled_by(turn_label)
                .on_hover_text(TURN)
                .changed()
                {
                    changed = Some("schedule");
                }
                if ui
                    .small_button("Remove")
                    .on_hover_text("Remove this turn")
                    .clicked()
                {
                    remove = Some(i);
                }
                ui.end_row();
                if ramp.to_step < ramp.from_step {
                    // A ramp goes forwards: said, not done silently.
                    checked_field::say(
                        ui.ctx(),
                        format!(
                            "to step {} is before from step {}; set to {} (a ramp goes forwards)",
                            ramp.to_step, ramp.from_step, ramp.from_step
                        ),
                    );
                    ramp.to_step = ramp.from_step;
                }
            }
        });
    if let Some(i) = remove {
        part.schedule.remove(i);
        changed = Some("schedule");
    }
    if ui
        .button("Add turn")
        .on_hover_text("Turn it outwards over some steps, like a joint schedule")
        .clicked()
    {
        let from = part.schedule.last().map_or(20, |r| r.to_step);
        part.schedule.push(JointRamp {
            from_step: from,
            to_step: from + 60,
            angle_deg: 20.0,
        });
        changed = Some("schedule");
    }
    changed
}

/// The length of the flower's organs as built (their tallest template),
/// which new parts are sized by.
fn organ_length(project: &Project) -> f64 {
    project
        .flower
        .templates
        .iter()
        .flat_map(|t| t.mesh.positions.iter().map(|p| p.y))
        .fold(1.0, f64::max)
}

/// A new part of `kind` sized to the flower, named to clash with nothing.
pub fn new_part(project: &Project, kind: &str) -> Part {
    let length = organ_length(project);
    let ring = project
        .flower
        .organs
        .iter()
        .map(|o| o.placement.position.x.hypot(o.placement.position.z))
        .fold(0.5, f64::max);
    let taken = |name: &str, count: u32| {
        (0..count).any(|k| {
            let instance = instance_name(name, count, k);
            project.flower.organs.iter().any(|o| o.name == instance)
                || project
                    .flower
                    .parts
                    .iter()
                    .any(|p| (0..p.count).any(|j| p.instance_name(j) == instance))
        })
    };
    let (base, shape, count) = match kind {
        "stamen" => (
            "stamen",
            PartShape::Stamen {
                filament: Tube {
                    length: 0.55 * length,
                    radius: 0.006 * length,
                    curvature_deg: 6.0,
                },
                anther_length: 0.09 * length,
                anther_radius: 0.013 * length,
                anther_tilt_deg: 0.0,
            },
            5,
        ),
        "pistil" => (
            "pistil",
            PartShape::Pistil {
                style: Tube {
                    length: 0.6 * length,
                    radius: 0.008 * length,
                    curvature_deg: 0.0,
                },
                stigma_radius: 0.025 * length,
                stigma_lobes: 3,
                ovary_length: 0.15 * length,
                ovary_radius: 0.025 * length,
            },
            1,
        ),
        "pedicel" => (
            "pedicel",
            PartShape::Pedicel {
                stalk: Tube {
                    length: 0.7 * length,
                    radius: 0.02 * length,
                    curvature_deg: -10.0,
                },
            },
            1,
        ),
        _ => (
            "receptacle",
            PartShape::Receptacle {
                radius: 1.1 * ring,
                depth: 0.7 * ring,
            },
            1,
        ),
    };
    let mut name = base.to_string();
    let mut n = 2;
    while taken(&name, count) {
        name = format!("{base}{n}");
        n += 1;
    }
    let (colour, head_colour) = default_colours(&shape);
    Part {
        name,
        shape,
        count,
        ring_radius: match kind {
            "stamen" => 0.4 * ring,
            _ => 0.0,
        },
        height: match kind {
            "pedicel" => -0.5 * ring,
            _ => 0.0,
        },
        offset_deg: 0.0,
        angle_deg: if kind == "stamen" { 3.0 } else { 0.0 },
        schedule: Vec::new(),
        colour,
        head_colour,
    }
}

/// Shows the parts of `project`; returns the edit the user made, if any.
pub fn parts_ui(ui: &mut egui::Ui, project: &Project) -> Option<Command> {
    let mut draft = project.flower.parts.clone();
    let mut label: Option<String> = None;
    let mut remove = None;
    ui.strong("Parts (do not grow)").on_hover_text(
        "Stamens, pistils, the stem and the receptacle: shown and exported with the flower; \
         the growing organs are kept outside them. A turn moves them over the steps.",
    );
    for (i, part) in draft.iter_mut().enumerate() {
        let title = if part.count > 1 {
            format!("{} “{}” × {}", part.shape.kind(), part.name, part.count)
        } else {
            format!("{} “{}”", part.shape.kind(), part.name)
        };
        egui::CollapsingHeader::new(title)
            .id_salt(("part", i))
            .show(ui, |ui| {
                let before = part.clone();
                let mut field = None;
                egui::Grid::new(("part rows", i))
                    .num_columns(2)
                    .spacing([12.0, 4.0])
                    .show(ui, |ui| field = part_rows(ui, part));
                if !matches!(part.shape, PartShape::Receptacle { .. }) {
                    field = field.or(schedule_rows(ui, part, i));
                }
                if let Some(field) = field {
                    // A value the part cannot take (a radius over half a
                    // new length) is not kept.
                    if part.check().is_ok() {
                        label = Some(format!("{field} of {}", part.name));
                    } else {
                        *part = before;
                    }
                }
                if ui
                    .button("Remove part")
                    .on_hover_text("Remove it from the flower")
                    .clicked()
                {
                    remove = Some(i);
                }
            });
    }
    if let Some(i) = remove {
        label = Some(format!("remove {}", draft[i].name));
        draft.remove(i);
    }
    ui.horizontal_wrapped(|ui| {
        let has_receptacle = draft
            .iter()
            .any(|p| matches!(p.shape, PartShape::Receptacle { .. }));
        for (kind, button, tooltip) in [
            ("stamen", "Add stamens", "Five stamens sized to the flower"),
            ("pistil", "Add pistil", "A pistil with a three-lobed stigma"),
            ("pedicel", "Add stem", "The stem below the receptacle"),
            (
                "receptacle",
                "Add receptacle",
                "A receptacle of its own size",
            ),
        ] {
            if kind == "receptacle" && has_receptacle {
                continue;
            }
            if ui.button(button).on_hover_text(tooltip).clicked() {
                let mut with = project.clone();
                with.flower.parts = draft.clone();
                let part = new_part(&with, kind);
                label = Some(format!("add {}", part.name));
                draft.push(part);
            }
        }
    });
    let label = label?;
    Some(Command::Edit {
        label,
        edit: ProjectEdit::Parts(draft),
    })
}

#[cfg(test)]
mod tests {
    use super::unit_of;

    #[test]
    fn rows_say_their_unit_from_their_last_word() {
        assert_eq!(unit_of("filament length"), Some("project units (lengths)"));
        assert_eq!(unit_of("radius step"), Some("project units (lengths)"));
        assert_eq!(unit_of("anther tilt"), Some("degrees"));
        assert_eq!(unit_of("divergence"), Some("degrees"));
        assert_eq!(unit_of("count"), None);
    }
}

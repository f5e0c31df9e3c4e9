//! The Flower panel's Arrangement section: what places the organs
//! (listed, whorls, a golden-angle spiral or an L-system) and the rows that
//! edit whorls and spirals.

use super::*;

/// The rows of one whorl; returns the field that changed.
fn whorl_rows(
    ui: &mut egui::Ui,
    flower: &Flower,
    whorl: &mut Whorl,
    id: usize,
) -> Option<&'static str> {
    let mut changed = None;
    let mut mark = |c: bool, field: &'static str| {
        if c && changed.is_none() {
            changed = Some(field);
        }
    };
    egui::Grid::new(("whorl rows", id))
        .num_columns(2)
        .spacing([12.0, 4.0])
        .show(ui, |ui| {
            let label = ui.label("template").id;
            mark(
                template_combo(ui, ("whorl template", id), label, flower, &mut whorl.template),
                "template",
            );
            ui.end_row();
            let label = ui.label("count").on_hover_text("How many organs around the axis.");
            let mut count = whorl.count as u32;
            mark(
                checked_with(ui, "count", &mut count, 1..=64, |d| d)
                    .labelled_by(label.id)
                    .changed(),
                "count",
            );
            whorl.count = count as usize;
            ui.end_row();
            mark(
                number(ui, "offset", "Azimuth of the first organ, in degrees (0 faces +Z).", &mut whorl.offset_deg, -360.0..=360.0),
                "offset",
            );
            mark(
                number(ui, "radius", "Distance of the organs' bases from the axis.", &mut whorl.radius, 0.0..=1000.0),
                "radius",
            );
            mark(
                number(ui, "height", "Height of the organs' bases.", &mut whorl.height, -1000.0..=1000.0),
                "height",
            );
            mark(
                number(ui, "joint angle", "Initial tilt outwards, in degrees.", &mut whorl.joint_angle_deg, -180.0..=180.0),
                "joint angle",
            );
            mark(
                number(
                    ui,
                    "half span",
                    "Half the angle about the axis an organ covers at its widest: organs of two whorls \
                     whose spans meet get an overlap rule.",
                    &mut whorl.half_span_deg,
                    0.0..=180.0,
                ),
                "half span",
            );
        });
    changed
}

/// The rows of the spiral; returns the field that changed.
fn spiral_rows(ui: &mut egui::Ui, flower: &Flower, spiral: &mut Spiral) -> Option<&'static str> {
    let mut changed = None;
    let mut mark = |c: bool, field: &'static str| {
        if c && changed.is_none() {
            changed = Some(field);
        }
    };
    egui::Grid::new("spiral rows")
        .num_columns(2)
        .spacing([12.0, 4.0])
        .show(ui, |ui| {
            let label = ui.label("template").id;
            mark(
                template_combo(ui, "spiral template", label, flower, &mut spiral.template),
                "template",
            );
            ui.end_row();
            let label = ui
                .label("count")
                .on_hover_text("How many organs along the spiral.");
            let mut count = spiral.count as u32;
            mark(
                checked_with(ui, "count", &mut count, 1..=256, |d| d)
                    .labelled_by(label.id)
                    .changed(),
                "count",
            );
            spiral.count = count as usize;
            ui.end_row();
            mark(
                number(
                    ui,
                    "divergence",
                    "Angle between consecutive organs (the golden angle: 137.5°).",
                    &mut spiral.divergence_deg,
                    -360.0..=360.0,
                ),
                "divergence",
            );
            mark(
                number(
                    ui,
                    "first radius",
                    "Distance of the first (outermost) organ from the axis.",
                    &mut spiral.first_radius,
                    0.0..=1000.0,
                ),
                "first radius",
            );
            mark(
                number(
                    ui,
                    "first height",
                    "Height of the first organ's base.",
                    &mut spiral.first_height,
                    -1000.0..=1000.0,
                ),
                "first height",
            );
            mark(
                number(
                    ui,
                    "radius step",
                    "Each later organ sits this much nearer the axis.",
                    &mut spiral.radius_step,
                    -100.0..=100.0,
                ),
                "radius step",
            );
            mark(
                number(
                    ui,
                    "height step",
                    "Each later organ sits this much higher.",
                    &mut spiral.height_step,
                    -100.0..=100.0,
                ),
                "height step",
            );
            mark(
                number(
                    ui,
                    "joint angle",
                    "Initial tilt outwards, in degrees.",
                    &mut spiral.joint_angle_deg,
                    -180.0..=180.0,
                ),
                "joint angle",
            );
            mark(
                number(
                    ui,
                    "half span",
                    "Half the angle an organ covers about the axis.",
                    &mut spiral.half_span_deg,
                    0.0..=180.0,
                ),
                "half span",
            );
        });
    changed
}

/// The Arrangement section: what places the organs (listed, whorls, a
/// spiral or an L-system) and its settings, and why an edit was refused.
pub(super) fn arrangement_ui(
    ui: &mut egui::Ui,
    flower: &Flower,
    state: &mut FlowerPanelState,
    now: f64,
    outcomes: &mut Vec<Outcome>,
) {
    // Arrangement.
    ui.strong("Arrangement").on_hover_text(
        "Where the organs go: listed one by one, whorls (rings, innermost first), a golden-angle \
         spiral or an L-system whose ~X places an organ.",
    );
    let kind = Kind::of(flower.structure.as_ref());
    let mut chosen = kind;
    ui.horizontal(|ui| {
        let label = ui.label("arrange by").id;
        egui::ComboBox::from_id_salt("arrangement kind")
            .selected_text(kind.name())
            .show_ui(ui, |ui| {
                for k in [Kind::Listed, Kind::Whorls, Kind::Spiral, Kind::LSystem] {
                    ui.selectable_value(&mut chosen, k, k.name());
                }
            })
            .response
            .labelled_by(label);
    });
    if chosen != kind {
        let whorls = whorls_like(flower);
        let result = match chosen {
            Kind::Listed => flower.with_structure(None),
            Kind::Whorls => flower.arranged_by(Structure::Whorls {
                whorls,
                contorted: false,
            }),
            Kind::Spiral => match spiral_like(&whorls) {
                Some(spiral) => flower.arranged_by(Structure::Spiral(spiral)),
                None => Err(anthesis_flower::edit::EditError::NoOrgans),
            },
            Kind::LSystem => {
                let (text, steps, surfaces) = lsystem_like(&whorls);
                flower.arranged_by(Structure::LSystem {
                    text,
                    steps,
                    surfaces,
                    units: 1.0,
                })
            }
        };
        outcomes.push(outcome(
            format!("arrange by {}", chosen.name().to_lowercase()),
            result,
        ));
    }
    structure_ui(ui, flower, state, now, outcomes);
    if let Some(refused) = &state.refused {
        ui.label(RichText::new(refused).color(ui.visuals().error_fg_color));
    }
}

/// The settings of the flower's structure: its whorls (edited, added),
/// its spiral or its L-system.
fn structure_ui(
    ui: &mut egui::Ui,
    flower: &Flower,
    state: &mut FlowerPanelState,
    now: f64,
    outcomes: &mut Vec<Outcome>,
) {
    match &flower.structure {
        None => {
            ui.label("Each organ is placed on its own (see Organs).");
        }
        Some(Structure::Whorls { whorls, contorted }) => {
            let mut draft = whorls.clone();
            let mut contorted_now = *contorted;
            let mut label = None;
            if ui
                .checkbox(&mut contorted_now, "contorted")
                .on_hover_text(
                    "One ring whose organs each lie beneath their right-hand neighbour (Eustoma)",
                )
                .changed()
            {
                label = Some("contorted".to_string());
            }
            let mut remove = None;
            for (i, whorl) in draft.iter_mut().enumerate() {
                egui::CollapsingHeader::new(format!("whorl “{}” × {}", whorl.name, whorl.count))
                    .id_salt(("whorl", i))
                    .default_open(draft_len_is_small(whorls.len()))
                    .show(ui, |ui| {
                        if let Some(field) = whorl_rows(ui, flower, whorl, i) {
                            label = Some(format!("{field} of whorl {}", whorl.name));
                        }
                        if ui
                            .add_enabled(whorls.len() > 1, egui::Button::new("Remove whorl"))
                            .clicked()
                        {
                            remove = Some(i);
                        }
                    });
            }
            if let Some(i) = remove {
                label = Some(format!("remove whorl {}", draft[i].name));
                draft.remove(i);
            }
            if ui
                .button("Add whorl")
                .on_hover_text("A ring outside the others, its organs between theirs")
                .clicked()
                && let Some(last) = draft.last()
            {
                let name =
                    anthesis_flower::edit::unique_name(&format!("{} outer", last.name), |n| {
                        draft.iter().any(|w| w.name == n)
                    });
                let step = 360.0 / last.count.max(1) as f64;
                let added = Whorl {
                    name,
                    offset_deg: last.offset_deg + 0.5 * step,
                    radius: last.radius * 1.15 + 0.1,
                    ..last.clone()
                };
                label = Some(format!("add whorl {}", added.name));
                draft.push(added);
            }
            if let Some(label) = label {
                outcomes.push(outcome(
                    label,
                    flower.with_structure(Some(Structure::Whorls {
                        whorls: draft,
                        contorted: contorted_now,
                    })),
                ));
            }
        }
        Some(Structure::Spiral(spiral)) => {
            let mut draft = spiral.clone();
            if let Some(field) = spiral_rows(ui, flower, &mut draft) {
                outcomes.push(outcome(
                    format!("{field} of the spiral"),
                    flower.with_structure(Some(Structure::Spiral(draft))),
                ));
            }
        }
        Some(Structure::LSystem {
            text,
            steps,
            surfaces,
            units,
        }) => {
            state.units = *units;
            let now_text = text.clone();
            if let Some(out) = state.lsystem_ui(ui, flower, (&now_text, *steps, surfaces), now) {
                outcomes.push(out);
            }
        }
    }
}

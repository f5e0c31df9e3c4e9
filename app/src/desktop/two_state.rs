//! The parameters panel's "Two-state opening" section (issue 15 item 1):
//! a template animated from its bud to an open shape by the two-state
//! blossom instead of grown. Shows and edits g and T of G(t; g, T) and the
//! velocity curve, plots both over the keyframes, and makes a template
//! two-state from an OBJ (a command: the file dialog) or from the shape its
//! organ has at the viewed keyframe of the current run.

use anthesis_flower::{Project, Template, TwoStateAnimation, joint_angle_after};
use anthesis_twostate::VelocityCurve;
use eframe::egui::{self, Stroke};
use glam::DVec3;

use super::checked_field::checked_with;
use super::command::Command;

/// The selected organ's shape at the keyframe the viewport shows, when
/// that keyframe has been computed.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewedOrgan {
    /// The organ's index in the project.
    pub organ: usize,
    /// The keyframe shown (0 is the bud).
    pub keyframe: u32,
    /// The organ's positions at that keyframe, in the world frame.
    pub positions_in_world: Vec<DVec3>,
}

/// `viewed`'s shape taken back to the template frame of its organ (the
/// placement and the joint schedule at its keyframe undone): an open shape
/// for `template`, or `None` when the vertex counts differ (a run at
/// another resolution).
pub fn open_shape_from_keyframe(
    project: &Project,
    template: &Template,
    viewed: &ViewedOrgan,
) -> Option<Vec<DVec3>> {
    let organ = project.flower.organs.get(viewed.organ)?;
    if viewed.positions_in_world.len() != template.mesh.positions.len() {
        return None;
    }
    let extra = joint_angle_after(&template.joint_schedule, viewed.keyframe);
    Some(
        viewed
            .positions_in_world
            .iter()
            .map(|p| organ.placement.template_from_world(*p, extra))
            .collect(),
    )
}

/// Colour of G(t) in the plot.
const GROWTH_COLOUR: egui::Color32 = egui::Color32::from_rgb(230, 140, 60);
/// Colour of the velocity curve in the plot.
const VELOCITY_COLOUR: egui::Color32 = egui::Color32::from_rgb(90, 160, 230);

/// The section for `draft` (template `template` of `project`): edits go
/// into `draft` and are reported through `mark` (one undo step each, as
/// the rest of the panel); a command (the file dialog) is returned.
pub fn two_state_ui(
    ui: &mut egui::Ui,
    project: &Project,
    template: usize,
    draft: &mut Template,
    viewed: Option<&ViewedOrgan>,
    mark: &mut dyn FnMut(bool, &'static str),
) -> Option<Command> {
    super::widgets::section(
        ui,
        "Two-state opening",
        "Animate this template's organs from the bud to an open shape (the two-state blossom) \
         instead of growing them: no growth maps, no solve. Growing organs keep off them; \
         they never give way.",
        |ui| two_state_rows(ui, project, template, draft, viewed, mark),
    )
    .flatten()
}

/// What the Two-state opening section holds.
fn two_state_rows(
    ui: &mut egui::Ui,
    project: &Project,
    template: usize,
    draft: &mut Template,
    viewed: Option<&ViewedOrgan>,
    mark: &mut dyn FnMut(bool, &'static str),
) -> Option<Command> {
    let mut command = None;
    ui.horizontal_wrapped(|ui| {
        if ui
            .button("Open shape from OBJ…")
            .on_hover_text(
                "An OBJ with this template's mesh moved: the same vertices in the same order \
                 and the same triangles, in the template frame",
            )
            .clicked()
        {
            command = Some(Command::BrowseOpenShape(template));
        }
        let from_run = viewed.filter(|v| {
            project.flower.organs.get(v.organ).map(|o| o.template) == Some(template)
                && v.keyframe > 0
        });
        let label = match from_run {
            Some(v) => format!("Open shape from keyframe {}", v.keyframe),
            None => "Open shape from keyframe …".to_owned(),
        };
        // None too when the run is at another resolution (other vertices).
        let taken = from_run.and_then(|v| open_shape_from_keyframe(project, draft, v));
        let button = ui.add_enabled(taken.is_some(), egui::Button::new(label));
        if button
            .on_hover_text(
                "The selected organ's shape at the keyframe shown, taken back to the template \
                 frame, as the open shape (show a computed keyframe after the bud)",
            )
            .on_disabled_hover_text(
                "Show a computed keyframe after the bud of this organ, simulated with the \
                 template's mesh as built",
            )
            .clicked()
            && let Some(open) = taken
        {
            let keyframes = project.settings.keyframes;
            match &mut draft.two_state {
                Some(animation) => animation.open = open,
                None => draft.two_state = Some(TwoStateAnimation::new(open, keyframes)),
            }
            mark(true, "open shape");
        }
        if draft.two_state.is_some()
            && ui
                .button("Grow instead")
                .on_hover_text("Drop the open shape: the organs grow by their maps again")
                .clicked()
        {
            draft.two_state = None;
            mark(true, "two-state opening");
        }
    });
    let Some(animation) = &mut draft.two_state else {
        ui.label("Grown by its maps (no open shape).");
        return command;
    };
    timing_grid(ui, animation, mark);
    let mut follow = animation.velocity == VelocityCurve::FollowGrowth;
    if ui
        .checkbox(&mut follow, "velocity follows G")
        .on_hover_text(
            "The cells' growth directions turn with G's timing; untick to draw the velocity \
             curve by points (time / T, fraction of the turn)",
        )
        .changed()
    {
        animation.velocity = if follow {
            VelocityCurve::FollowGrowth
        } else {
            VelocityCurve::Points(vec![[0.0, 0.0], [0.5, 0.5], [1.0, 1.0]])
        };
        mark(true, "velocity curve");
    }
    if let VelocityCurve::Points(points) = &mut animation.velocity {
        velocity_points_ui(ui, points, mark);
    }
    plot(
        ui,
        animation,
        project.settings.keyframes,
        viewed.map(|v| v.keyframe),
    );
    command
}

/// The growth function's g and T of the two-state opening.
fn timing_grid(
    ui: &mut egui::Ui,
    animation: &mut TwoStateAnimation,
    mark: &mut dyn FnMut(bool, &'static str),
) {
    egui::Grid::new("two-state timing")
        .num_columns(2)
        .spacing([12.0, 6.0])
        .show(ui, |ui| {
            let tip = super::words::tooltip("g");
            let label = ui.label(super::words::label("g")).on_hover_text(&tip);
            mark(
                checked_with(ui, "g", &mut animation.growth.g, 0.01..=60.0, |d| {
                    d.speed(0.05).max_decimals(3)
                })
                .labelled_by(label.id)
                .on_hover_text(&tip)
                .changed(),
                "g",
            );
            ui.end_row();
            let tip = super::words::tooltip("T");
            let label = ui.label(super::words::label("T")).on_hover_text(&tip);
            mark(
                checked_with(
                    ui,
                    "T",
                    &mut animation.growth.duration,
                    0.5..=f64::from(anthesis_flower::MAX_KEYFRAMES),
                    |d| d.speed(0.5).max_decimals(2),
                )
                .labelled_by(label.id)
                .on_hover_text(&tip)
                .changed(),
                "T",
            );
            ui.end_row();
        });
}

/// The velocity curve's points, each time kept between its neighbours'.
fn velocity_points_ui(
    ui: &mut egui::Ui,
    points: &mut Vec<[f64; 2]>,
    mark: &mut dyn FnMut(bool, &'static str),
) {
    let mut remove = None;
    egui::Grid::new("velocity points")
        .num_columns(3)
        .show(ui, |ui| {
            let time_label = ui.label("time / T").id;
            let fraction_label = ui.label("fraction").id;
            ui.end_row();
            let count = points.len();
            for i in 0..count {
                let low = if i > 0 { points[i - 1][0] + 1e-3 } else { 0.0 };
                let high = if i + 1 < count {
                    points[i + 1][0] - 1e-3
                } else {
                    1.0
                };
                let point = &mut points[i];
                mark(
                    checked_with(ui, "time / T", &mut point[0], low..=high.max(low), |d| {
                        d.speed(0.01).max_decimals(3)
                    })
                    .labelled_by(time_label)
                    .changed(),
                    "velocity point",
                );
                mark(
                    checked_with(ui, "fraction", &mut point[1], -1.0..=2.0, |d| {
                        d.speed(0.01).max_decimals(3)
                    })
                    .labelled_by(fraction_label)
                    .changed(),
                    "velocity point",
                );
                if count > 1 && ui.small_button("Remove").clicked() {
                    remove = Some(i);
                }
                ui.end_row();
            }
        });
    if let Some(i) = remove {
        points.remove(i);
        mark(true, "remove velocity point");
    }
    let last = points.last().map_or(0.0, |p| p[0]);
    if last < 1.0
        && ui
            .button("Add point")
            .on_hover_text("A point halfway between the last one and time 1")
            .clicked()
    {
        let value = points.last().map_or(0.0, |p| p[1]);
        points.push([0.5 * (last + 1.0), value]);
        mark(true, "add velocity point");
    }
}

/// G(t) (as the fraction of the way to the open ratios, g/6 at T) and the
/// velocity curve over keyframes 0 to `keyframes`, with the viewed
/// keyframe marked.
fn plot(ui: &mut egui::Ui, animation: &TwoStateAnimation, keyframes: u32, viewed: Option<u32>) {
    let width = ui.available_width().clamp(120.0, 400.0);
    let (response, painter) = ui.allocate_painter(egui::vec2(width, 100.0), egui::Sense::hover());
    let rect = response.rect.shrink2(egui::vec2(4.0, 8.0));
    let visuals = ui.visuals();
    painter.rect_filled(response.rect, 2.0, visuals.extreme_bg_color);
    let growth = &animation.growth;
    let samples = 120usize;
    let last = f64::from(keyframes.max(1));
    let curve = |f: &dyn Fn(f64) -> f64| -> Vec<f64> {
        (0..=samples)
            .map(|i| f(last * i as f64 / samples as f64))
            .collect()
    };
    let g_values = curve(&|t| growth.fraction(t));
    let v_values = curve(&|t| animation.velocity.fraction(growth, t));
    let top = g_values
        .iter()
        .chain(&v_values)
        .copied()
        .filter(|v| v.is_finite())
        .fold(1.0, f64::max);
    let bottom = g_values
        .iter()
        .chain(&v_values)
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0, f64::min);
    let span = (top - bottom).max(1e-9);
    let to_screen = |i: usize, v: f64| {
        egui::pos2(
            rect.left() + rect.width() * i as f32 / samples as f32,
            rect.bottom() - rect.height() * ((v - bottom) / span) as f32,
        )
    };
    let axis = Stroke::new(1.0, visuals.weak_text_color());
    // 0 and 1 (the open shape's ratios; the end of the turn).
    for level in [0.0, 1.0] {
        let y = to_screen(0, level).y;
        painter.hline(rect.x_range(), y, axis);
    }
    let t_end = (growth.duration / last).min(1.0) as f32;
    if t_end.is_finite() {
        let x = rect.left() + rect.width() * t_end;
        painter.vline(
            x,
            rect.y_range(),
            Stroke::new(1.0, visuals.weak_text_color()),
        );
    }
    if let Some(k) = viewed {
        let x = rect.left() + rect.width() * (f64::from(k) / last).min(1.0) as f32;
        painter.vline(
            x,
            rect.y_range(),
            Stroke::new(1.5, visuals.strong_text_color()),
        );
    }
    for (values, colour) in [(&g_values, GROWTH_COLOUR), (&v_values, VELOCITY_COLOUR)] {
        let points: Vec<egui::Pos2> = values
            .iter()
            .enumerate()
            .map(|(i, v)| to_screen(i, *v))
            .collect();
        painter.add(egui::Shape::line(points, Stroke::new(2.0, colour)));
    }
    response.on_hover_text(format!(
        "Over keyframes 0 to {keyframes}: G(t) as the fraction of the way to the open shape's \
         ratios (orange; g/6 = {:.2} at T = {:.1}) and the velocity curve, the fraction of the \
         directions' turn (blue). The thin line marks T, the bold one the keyframe shown.",
        growth.g / 6.0,
        growth.duration
    ));
    ui.horizontal(|ui| {
        ui.colored_label(GROWTH_COLOUR, "— G(t)");
        ui.colored_label(VELOCITY_COLOUR, "— velocity");
        ui.weak(format!("0 … {keyframes} keyframes"));
    });
}

//! Number fields that say what became of a typed value. egui's `DragValue`
//! clamps a typed value into its range and drops text that is not a number
//! without a word ("abc" in dg reverted, a thickness of −1 became 0.001,
//! fps 0 became 0.1). A checked field notes both: the field is outlined
//! and its tooltip says why for a few seconds, and a line with the accepted
//! range goes to the log ([`take_notices`], drained by the app each frame).
//! A run that fails while a template holds a value at the edge of its
//! field's range names it ([`values_at_limits`]).

use std::cell::RefCell;
use std::ops::RangeInclusive;

use eframe::egui::{self, DragValue};

/// How long a refused or clamped field stays marked, in seconds.
const MARK_SECONDS: f64 = 6.0;

/// What became of text typed into a field with `range`.
#[derive(Debug, Clone, PartialEq)]
pub enum Typed {
    /// A number in the range: taken as typed.
    Taken(f64),
    /// A number outside the range: the field holds the nearest end.
    Clamped {
        /// What was typed.
        typed: f64,
        /// What the field holds.
        to: f64,
    },
    /// Not a number: the field keeps its value.
    Refused(String),
    /// A number with a fraction in a field of whole numbers (a count, a
    /// step): the field keeps its value.
    NotWhole(String),
}

/// Reads `text` typed into a field accepting `range` (what `DragValue`
/// would make of it, said instead of done silently).
pub fn read_typed(text: &str, range: &RangeInclusive<f64>) -> Typed {
    match text.trim().parse::<f64>() {
        Ok(value) if value.is_nan() => Typed::Refused(text.to_owned()),
        Ok(value) if range.contains(&value) => Typed::Taken(value),
        Ok(value) => Typed::Clamped {
            typed: value,
            to: value.clamp(*range.start(), *range.end()),
        },
        Err(_) => Typed::Refused(text.to_owned()),
    }
}

/// [`read_typed`] for a field of whole numbers: a fraction is refused
/// (`DragValue` would silently cut "2.5" to 2).
pub fn read_typed_whole(text: &str, range: &RangeInclusive<f64>) -> Typed {
    match read_typed(text, range) {
        Typed::Taken(value) | Typed::Clamped { typed: value, .. } if value.fract() != 0.0 => {
            Typed::NotWhole(text.to_owned())
        }
        read => read,
    }
}

/// The log line for `typed` into the field `label`, or none when it was
/// taken as typed.
pub fn notice(label: &str, typed: &Typed, range: &RangeInclusive<f64>) -> Option<String> {
    let accepted = format!("{label} accepts {} to {}", range.start(), range.end());
    let shown = |text: &str| text.chars().take(40).collect::<String>();
    match typed {
        Typed::Taken(_) => None,
        Typed::Clamped { typed, to } => Some(format!(
            "{label} {typed} is out of range ({accepted}); set to {to}"
        )),
        Typed::Refused(text) => Some(format!(
            "`{}` is not a number; {label} kept its value ({accepted})",
            shown(text)
        )),
        Typed::NotWhole(text) => Some(format!(
            "`{}` is not a whole number; {label} kept its value ({accepted}, whole numbers)",
            shown(text)
        )),
    }
}

/// The tooltip of a field holding `value` outside its `range` (as loaded
/// from a file or set by a command; the field does not change it).
pub fn outside_note(label: &str, value: f64, range: &RangeInclusive<f64>) -> Option<String> {
    (!range.contains(&value)).then(|| {
        let value = shortest(value);
        format!(
            "{label} {value} is outside what the field accepts ({} to {}); it is kept as it \
             is until you type or drag a new value",
            range.start(),
            range.end()
        )
    })
}

/// `value` as written for a person: a value that came from an `f32`
/// field as that field shows it ("1.7", not "1.7000000476837158").
fn shortest(value: f64) -> String {
    let single = value as f32;
    if f64::from(single) == value {
        single.to_string()
    } else {
        value.to_string()
    }
}

/// A number field like `DragValue::new(value).speed(speed).range(range)`
/// that marks and logs a typed value it refuses or clamps. Returns the
/// response.
pub fn checked_number(
    ui: &mut egui::Ui,
    label: &str,
    value: &mut f64,
    speed: f64,
    range: RangeInclusive<f64>,
) -> egui::Response {
    checked_with(ui, label, value, range, |drag| {
        drag.speed(speed).max_decimals(5)
    })
}

/// A `DragValue` over `value` (any number type) with `range`, styled by
/// `style` (speed, suffix, decimals), that marks and logs a typed value
/// it refuses (not a number, or a fraction for a whole-number field) or
/// clamps into `range`, and marks without changing it a value already
/// outside `range` (egui would clamp it silently when drawn). Returns the
/// response.
pub fn checked_with<N: egui::emath::Numeric>(
    ui: &mut egui::Ui,
    label: &str,
    value: &mut N,
    range: RangeInclusive<N>,
    style: impl FnOnce(DragValue<'_>) -> DragValue<'_>,
) -> egui::Response {
    let range_f64 = range.start().to_f64()..=range.end().to_f64();
    let typed: RefCell<Option<Typed>> = RefCell::new(None);
    let parse_range = range_f64.clone();
    // The same each frame (a slider's response is its number box's while
    // that has focus, its rail's otherwise).
    let key = ui.next_auto_id();
    let response = ui.add(style(
        DragValue::new(value)
            .range(range)
            .clamp_existing_to_range(false)
            .custom_parser(|text| {
                let read = if N::INTEGRAL {
                    read_typed_whole(text, &parse_range)
                } else {
                    read_typed(text, &parse_range)
                };
                keep_typed(read, &typed)
            }),
    ));
    let outside = outside_note(label, value.to_f64(), &range_f64);
    mark_typed(
        ui,
        (key, response),
        label,
        typed.into_inner(),
        &range_f64,
        outside,
    )
}

/// Logs what became of a typed value (once), and marks the field while
/// that is recent or while its value is `outside` its range (said once
/// in the log too).
fn mark_typed(
    ui: &mut egui::Ui,
    (key, mut response): (egui::Id, egui::Response),
    label: &str,
    typed: Option<Typed>,
    range: &RangeInclusive<f64>,
    outside: Option<String>,
) -> egui::Response {
    let id = response.id.with("checked field notice");
    let said_id = response.id.with("checked field said");
    let pending_id = response.id.with("checked field pending");
    let now = ui.input(|i| i.time);
    if response.gained_focus() {
        // A new edit: what it refuses is said again.
        ui.data_mut(|d| d.remove::<String>(said_id));
    }
    // What the text typed so far makes; egui reads it at every keystroke
    // ("-" on the way to "-1") and again as the edit ends, so only what
    // the last reading made is said, once the field lets go.
    if let Some(typed) = typed {
        match notice(label, &typed, range) {
            Some(message) => ui.data_mut(|d| {
                d.insert_temp(pending_id, message);
            }),
            None => ui.data_mut(|d| d.remove::<String>(pending_id)),
        }
    }
    if !response.has_focus()
        && let Some(message) = ui.data_mut(|d| d.remove_temp::<String>(pending_id))
    {
        let said: Option<String> = ui.data(|d| d.get_temp(said_id));
        ui.data_mut(|d| {
            d.insert_temp(id, (message.clone(), now));
            d.insert_temp(said_id, message.clone());
        });
        if said.as_ref() != Some(&message) {
            push_notice(ui.ctx(), message);
        }
    }
    // A value outside the range that no edit made (loaded from a file,
    // picked by the eyedropper) is said once, when the field first shows
    // it.
    let outside_said_id = key.with("checked field outside said");
    match &outside {
        Some(message) => {
            let said: Option<String> = ui.data(|d| d.get_temp(outside_said_id));
            if said.as_ref() != Some(message) {
                ui.data_mut(|d| d.insert_temp(outside_said_id, message.clone()));
                push_notice(ui.ctx(), message.clone());
            }
        }
        None => ui.data_mut(|d| d.remove::<String>(outside_said_id)),
    }
    let marked: Option<(String, f64)> = ui.data(|d| d.get_temp(id));
    let recent = match marked {
        Some((message, since)) if now - since < MARK_SECONDS => {
            ui.ctx()
                .request_repaint_after(std::time::Duration::from_secs_f64(MARK_SECONDS));
            Some(message)
        }
        Some(_) => {
            ui.data_mut(|d| d.remove::<(String, f64)>(id));
            None
        }
        None => None,
    };
    if let Some(message) = recent.or(outside) {
        ui.painter().rect_stroke(
            response.rect.expand(1.0),
            2.0,
            egui::Stroke::new(1.5, ui.visuals().error_fg_color),
            egui::StrokeKind::Outside,
        );
        response = response.on_hover_text(message);
    }
    response
}

/// A slider like `Slider::new(value, range)` whose number box marks and
/// logs a typed value it refuses or clamps into `range` (a drag never
/// leaves it), and that keeps, marks and logs once a value already outside
/// `range` (egui's slider would clamp it silently when drawn). Returns the
/// response.
pub fn checked_slider<N: egui::emath::Numeric>(
    ui: &mut egui::Ui,
    label: &str,
    value: &mut N,
    range: RangeInclusive<N>,
    style: impl FnOnce(egui::Slider<'_>) -> egui::Slider<'_>,
) -> egui::Response {
    let range_f64 = range.start().to_f64()..=range.end().to_f64();
    let typed: RefCell<Option<Typed>> = RefCell::new(None);
    let parse_range = range_f64.clone();
    // The same each frame (a slider's response is its number box's while
    // that has focus, its rail's otherwise).
    let key = ui.next_auto_id();
    let response = ui.add(
        style(egui::Slider::new(value, range))
            // egui's default clamps a value outside the range as it is
            // drawn: a value loaded or picked outside it is kept instead
            // (and marked below); a drag or a typed value stays inside.
            .clamping(egui::SliderClamping::Edits)
            .custom_parser(|text| keep_typed(read_typed(text, &parse_range), &typed)),
    );
    let outside = outside_note(label, value.to_f64(), &range_f64);
    mark_typed(
        ui,
        (key, response),
        label,
        typed.into_inner(),
        &range_f64,
        outside,
    )
}

/// Outlines the fields of `responses` and gives each `problem` as its
/// tooltip while there is one (values that are each in range but do not
/// work together, as a ramp ending before it starts: every field that
/// makes it so is outlined). The problem goes to the log once per edit,
/// when it ends (not at each keystroke or drag step on the way), and once
/// when a project is opened with it.
pub fn flagged<const N: usize>(
    ui: &mut egui::Ui,
    responses: [egui::Response; N],
    problem: Option<String>,
) -> [egui::Response; N] {
    let Some(first) = responses.first() else {
        return responses;
    };
    let said_id = first.id.with("flagged");
    if responses.iter().any(egui::Response::changed) {
        // A new value: what it makes is said again when the edit ends.
        ui.data_mut(|d| d.remove::<String>(said_id));
    }
    let Some(problem) = problem else {
        ui.data_mut(|d| d.remove::<String>(said_id));
        return responses;
    };
    let editing = responses.iter().any(|r| r.has_focus() || r.dragged());
    let said: Option<String> = ui.data(|d| d.get_temp(said_id));
    if !editing && said.as_ref() != Some(&problem) {
        ui.data_mut(|d| d.insert_temp(said_id, problem.clone()));
        push_notice(ui.ctx(), problem.clone());
    }
    responses.map(|response| {
        ui.painter().rect_stroke(
            response.rect.expand(1.0),
            2.0,
            egui::Stroke::new(1.5, ui.visuals().error_fg_color),
            egui::StrokeKind::Outside,
        );
        response.on_hover_text(problem.as_str())
    })
}

/// Says `message` in the log with the refused and clamped values (a value
/// a panel changed on its own, as a ramp's end moved up to its start).
pub fn say(ctx: &egui::Context, message: String) {
    push_notice(ctx, message);
}

fn notices_id() -> egui::Id {
    egui::Id::unique("checked field notices")
}

fn push_notice(ctx: &egui::Context, message: String) {
    ctx.data_mut(|d| {
        d.get_temp_mut_or_default::<Vec<String>>(notices_id())
            .push(message)
    });
}

/// The notices of refused and clamped values since the last call, for the
/// log.
pub fn take_notices(ctx: &egui::Context) -> Vec<String> {
    ctx.data_mut(|d| std::mem::take(d.get_temp_mut_or_default::<Vec<String>>(notices_id())))
}

/// The ranges of the template fields a run depends on, as the parameters
/// panel gives them: (label, value, range).
pub fn template_fields(
    template: &anthesis_flower::Template,
) -> [(&'static str, f64, RangeInclusive<f64>); 4] {
    [
        ("dg", template.dg, DG_RANGE),
        ("thickness", template.thickness, THICKNESS_RANGE),
        ("Ks", template.stretch_stiffness, STIFFNESS_RANGE),
        ("Kb", template.bend_stiffness, STIFFNESS_RANGE),
    ]
}

/// The range of the dg field.
pub const DG_RANGE: RangeInclusive<f64> = -0.5..=0.5;
/// The range of the thickness field.
pub const THICKNESS_RANGE: RangeInclusive<f64> = 0.001..=100.0;
/// The range of the stiffness fields.
pub const STIFFNESS_RANGE: RangeInclusive<f64> = 0.001..=1.0e6;

/// The values of `project`'s templates that sit at an end of their field's
/// range (where a typed value was clamped to), each said for a failure
/// message: "thickness 0.001 of petal is the lowest the field accepts
/// (0.001 to 100)".
pub fn values_at_limits(project: &anthesis_flower::Project) -> Vec<String> {
    let mut said = Vec::new();
    for template in &project.flower.templates {
        for (label, value, range) in template_fields(template) {
            let end = if value <= *range.start() {
                "lowest"
            } else if value >= *range.end() {
                "highest"
            } else {
                continue;
            };
            said.push(format!(
                "{label} {value} of {} is the {end} the field accepts ({} to {})",
                template.name,
                range.start(),
                range.end()
            ));
        }
    }
    said
}

/// What a field's parser hands egui for `read` (the number the field holds,
/// or none when the text is refused), kept in `typed` so the field can be
/// marked and the edit logged after the frame.
fn keep_typed(read: Typed, typed: &RefCell<Option<Typed>>) -> Option<f64> {
    let value = match read {
        Typed::Taken(v) | Typed::Clamped { to: v, .. } => Some(v),
        Typed::Refused(_) | Typed::NotWhole(_) => None,
    };
    *typed.borrow_mut() = Some(read);
    value
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn typed_values_are_taken_clamped_or_refused_and_said() {
        let range = THICKNESS_RANGE;
        assert_eq!(read_typed(" 0.2 ", &range), Typed::Taken(0.2));
        assert_eq!(
            read_typed("-1", &range),
            Typed::Clamped {
                typed: -1.0,
                to: 0.001
            }
        );
        assert_eq!(read_typed("abc", &range), Typed::Refused("abc".into()));
        assert_eq!(read_typed("NaN", &range), Typed::Refused("NaN".into()));
        assert_eq!(notice("thickness", &Typed::Taken(0.2), &range), None);
        assert_eq!(
            notice("thickness", &read_typed("-1", &range), &range).as_deref(),
            Some("thickness -1 is out of range (thickness accepts 0.001 to 100); set to 0.001")
        );
        assert_eq!(
            notice("dg", &read_typed("abc", &DG_RANGE), &DG_RANGE).as_deref(),
            Some("`abc` is not a number; dg kept its value (dg accepts -0.5 to 0.5)")
        );
    }

    #[test]
    fn a_fraction_in_a_whole_number_field_is_refused_and_a_loaded_value_outside_is_noted() {
        let range = 1.0..=10_000.0;
        assert_eq!(read_typed_whole("7", &range), Typed::Taken(7.0));
        assert_eq!(
            read_typed_whole("2.5", &range),
            Typed::NotWhole("2.5".into())
        );
        assert_eq!(
            read_typed_whole("20000", &range),
            Typed::Clamped {
                typed: 20_000.0,
                to: 10_000.0
            }
        );
        assert_eq!(
            notice("keyframes", &read_typed_whole("2.5", &range), &range).as_deref(),
            Some(
                "`2.5` is not a whole number; keyframes kept its value (keyframes accepts 1 to 10000, whole numbers)"
            )
        );
        assert_eq!(outside_note("thickness", 0.2, &THICKNESS_RANGE), None);
        assert_eq!(
            outside_note("thickness", 150.0, &THICKNESS_RANGE).as_deref(),
            Some(
                "thickness 150 is outside what the field accepts (0.001 to 100); it is kept as \
                 it is until you type or drag a new value"
            )
        );
    }

    #[test]
    fn only_what_the_finished_edit_makes_is_said_not_each_keystroke() {
        use egui_kittest::Harness;
        use egui_kittest::kittest::Queryable;
        let mut harness = Harness::new_ui_state(
            |ui, state: &mut (f64, Vec<String>)| {
                let label = ui.label("dg");
                checked_number(ui, "dg", &mut state.0, 0.0001, DG_RANGE).labelled_by(label.id);
                state.1.extend(take_notices(ui.ctx()));
            },
            (0.003, Vec::new()),
        );
        harness.get_by_label("dg").focus();
        harness.run();
        harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
        // "-" alone is not a number, but the edit goes on to "-1".
        for key in ["-", "1"] {
            harness.get_by_label("dg").type_text(key);
            harness.run();
        }
        assert_eq!(
            harness.state().1,
            Vec::<String>::new(),
            "nothing while typing"
        );
        harness.key_press(egui::Key::Enter);
        harness.run();
        harness.run();
        assert_eq!(
            harness.state().1,
            ["dg -1 is out of range (dg accepts -0.5 to 0.5); set to -0.5"]
        );
    }

    #[test]
    fn a_value_at_the_end_of_its_range_is_named() {
        let mut project = anthesis_garden::five_petal::five_petal().expect("the five-petal start");
        assert_eq!(values_at_limits(&project), Vec::<String>::new());
        project.flower.templates[0].thickness = *THICKNESS_RANGE.start();
        assert_eq!(
            values_at_limits(&project),
            ["thickness 0.001 of petal is the lowest the field accepts (0.001 to 100)"]
        );
    }

    #[test]
    fn a_refused_and_a_clamped_field_are_logged_once() {
        use egui_kittest::Harness;
        use egui_kittest::kittest::Queryable;
        let mut harness = Harness::new_ui_state(
            |ui, state: &mut (f64, Vec<String>)| {
                let label = ui.label("thickness");
                checked_number(ui, "thickness", &mut state.0, 0.005, THICKNESS_RANGE)
                    .labelled_by(label.id);
                state.1.extend(take_notices(ui.ctx()));
            },
            (0.2, Vec::new()),
        );
        for text in ["abc", "-1"] {
            harness.get_by_label("thickness").focus();
            harness.run();
            harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
            harness.get_by_label("thickness").type_text(text);
            harness.key_press(egui::Key::Enter);
            harness.run();
        }
        let (value, notices) = harness.state().clone();
        assert_eq!(
            notices,
            [
                "`abc` is not a number; thickness kept its value (thickness accepts 0.001 to 100)",
                "thickness -1 is out of range (thickness accepts 0.001 to 100); set to 0.001",
            ]
        );
        assert_eq!(value, 0.001);
    }
}

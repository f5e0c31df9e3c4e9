//! Sliders keep a value outside their range (issue 40 item 3): egui's
//! slider clamps the value it shows into its range as it is drawn, so a
//! brush value the eyedropper picked from a map loaded from a file (a bend
//! stiffness of 1.7, with the slider's range 0 to 1) became 1 without a
//! word. The slider now keeps it bit for bit, outlines it and says so once
//! in the log.

use anthesis_maps::MapKind;
use anthesis_maps::ScalarMap;
use anthesis_maps::brush::{BrushMode, PaintTarget};
use eframe::egui;
use egui_kittest::kittest::Queryable;

use super::refusals::{log_lines, tooltip_of};
use super::{canvas_at, open_saved, small_flower};

#[test]
fn a_brush_value_picked_outside_the_slider_range_is_kept_outlined_and_said_once() {
    // A project file whose bend map holds 1.7 everywhere (stiffer than the
    // slider's 0 to 1).
    let mut project = small_flower();
    let picked: f32 = 1.7;
    project.flower.templates[0].maps.keys_mut()[0].maps.bend = ScalarMap::constant(picked);
    let (mut harness, _dir) = open_saved(&project, "stiff.anthesis");
    harness.state_mut().paint_mut().target = PaintTarget::Scalar(MapKind::Bend);
    harness.run();
    // Alt+click on the canvas picks the value there.
    let pos = canvas_at(&harness, 0.5, 0.5);
    harness.hover_at(pos);
    for pressed in [true, false] {
        harness.event_modifiers(
            egui::Event::PointerButton {
                pos,
                button: egui::PointerButton::Primary,
                pressed,
                modifiers: egui::Modifiers::ALT,
            },
            egui::Modifiers::ALT,
        );
    }
    for _ in 0..5 {
        harness.run();
    }
    let brush = harness.state_mut().paint_mut().brush;
    assert_eq!(brush.mode, BrushMode::Set, "picked");
    assert_eq!(
        brush.value.to_bits(),
        picked.to_bits(),
        "drawn for five frames, the slider kept {picked}, not {}",
        brush.value
    );
    let said = "Brush value (value) 1.7 is outside what the field accepts (0 to 1); it is kept as it is until \
                you type or drag a new value";
    assert!(
        tooltip_of(&mut harness, "value", 0).contains(said),
        "the slider is outlined with why as its tooltip"
    );
    for _ in 0..3 {
        harness.run();
    }
    let lines = log_lines(&harness);
    assert_eq!(
        lines.iter().filter(|l| l.as_str() == said).count(),
        1,
        "said once: {lines:?}"
    );
    // Typing a value in range takes it, and the mark goes.
    let label = anthesis_app::desktop::words::label("value");
    let field = harness
        .get_all_by_label(&label)
        .last()
        .expect("the slider's number box")
        .rect();
    harness
        .get_all_by_label(&label)
        .last()
        .expect("box")
        .focus();
    harness.run();
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness
        .get_all_by_label(&label)
        .last()
        .expect("box")
        .type_text("0.25");
    harness.key_press(egui::Key::Enter);
    harness.run();
    harness.run();
    assert_eq!(harness.state_mut().paint_mut().brush.value, 0.25);
    assert_eq!(
        harness
            .get_all_by_label(&label)
            .last()
            .expect("box")
            .rect()
            .min,
        field.min,
        "the same box"
    );
    assert!(!tooltip_of(&mut harness, "value", 0).contains("is outside"));
}

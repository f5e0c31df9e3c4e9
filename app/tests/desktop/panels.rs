//! The side panels at 1280×800 (issue 40): each scrolls as a whole under
//! the wheel so its last control comes into view, its sections fold, the
//! parameters carry plain names beside their symbols, the Help menu's
//! pages open, and the timeline's tooltip stays off the read-out while
//! the playhead is dragged.

use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;

use anthesis_app::desktop::AnthesisApp;

/// The wheel turned by `dy` points (negative: the content moves up, as
/// scrolling down) with the pointer at `at`, over a few frames.
fn wheel_at(harness: &mut Harness<'_, AnthesisApp>, at: egui::Pos2, dy: f32) {
    harness.hover_at(at);
    harness.run_steps(2);
    for _ in 0..6 {
        harness.event(egui::Event::MouseWheel {
            unit: egui::MouseWheelUnit::Point,
            delta: egui::vec2(0.0, dy / 6.0),
            phase: egui::TouchPhase::Move,
            source: egui::MouseWheelSource::Wheel,
            modifiers: egui::Modifiers::NONE,
        });
        harness.step();
    }
    // (Tooltips may still fade: steps, not run-until-settled.)
    harness.run_steps(8);
}

/// The top of the bottom panels (the timeline's buttons): what the side
/// panels show ends above it.
fn panels_bottom(harness: &Harness<'_, AnthesisApp>) -> f32 {
    harness.get_by_label("Start").rect().top()
}

#[test]
fn the_wheel_scrolls_each_side_panel_to_its_last_control_at_1280_by_800() {
    let mut harness = super::opened_small_flower();
    let bottom = panels_bottom(&harness);
    // The paint panel's last control starts below the fold.
    let last_paint = "Paint on the 3D organ (drag on it)";
    assert!(
        harness.get_by_label(last_paint).rect().bottom() > bottom,
        "the paint panel fits without scrolling: the test shows nothing"
    );
    // The wheel over the brush section (not over the canvas) scrolls the
    // whole panel.
    let brush = harness.get_by_label("Brush").rect().center();
    wheel_at(&mut harness, brush, -2000.0);
    let shown = harness.get_by_label(last_paint).rect();
    assert!(
        shown.bottom() <= bottom && shown.top() > 0.0,
        "{last_paint} at {shown:?}, the panels end at {bottom}"
    );
    harness.get_by_label(last_paint).click();
    harness.run();
    assert!(harness.state_mut().paint_mut().on_3d, "reached and ticked");

    // The left panel: its last control is the second colour.
    let last_left = "second colour";
    assert!(harness.get_by_label(last_left).rect().bottom() > bottom);
    // (Over the parameters, not the organ list, which scrolls itself.)
    let parameters = harness.get_by_label("Base region").rect().center();
    wheel_at(&mut harness, parameters, -3000.0);
    let shown = harness.get_by_label(last_left).rect();
    assert!(
        shown.bottom() <= bottom && shown.top() > 0.0,
        "{last_left} at {shown:?}, the panels end at {bottom}"
    );
    // The pointer off the panels, so no tooltip covers them.
    harness.hover_at(egui::pos2(640.0, 300.0));
    harness.run_steps(8);
    harness.snapshot("panels_scrolled_to_the_end_1280x800");
}

#[test]
fn sections_fold_and_parameters_say_what_they_are() {
    let mut harness = super::opened_small_flower();
    // Plain words with the symbol kept, and the map list in the same
    // words.
    harness.get_by_label("Growth per step (dg)");
    harness.get_by_label("Stretch stiffness (Ks)");
    let map = "Growth along, inner side (e-growth-in)";
    assert!(
        harness.query_by_label(map).is_some() || harness.query_by_value(map).is_some(),
        "the map chosen is named in plain words"
    );
    // A folded section hides its controls; unfolded, they are back.
    assert!(harness.query_by_label("Eyedropper").is_some());
    harness.get_by_label("Brush").click();
    harness.run();
    assert!(harness.query_by_label("Eyedropper").is_none(), "folded");
    harness.get_by_label("Base region").click();
    harness.run();
    assert!(harness.query_by_label("Base height (v max)").is_none());
    harness.snapshot("panels_sections_folded");
    harness.get_by_label("Brush").click();
    harness.run();
    assert!(harness.query_by_label("Eyedropper").is_some(), "unfolded");
}

#[test]
fn help_has_a_getting_started_page_and_an_about_box_with_the_version() {
    let mut harness = super::opened_small_flower();
    harness.get_by_label("Help").click();
    harness.run();
    harness.get_by_label("Getting started").click();
    harness.run();
    for section in ["Paint", "Scrub", "Export"] {
        assert!(
            harness.query_all_by_label(section).count() >= 1,
            "{section} is explained"
        );
    }
    harness.get_by_label_contains("File > Export animation…");
    harness.get_by_label("Help").click();
    harness.run();
    harness.get_by_label("About Anthesis").click();
    harness.run();
    harness.get_by_label(&format!("Anthesis {}", env!("CARGO_PKG_VERSION")));
}

#[test]
fn the_timeline_tooltip_leaves_the_read_out_alone_while_scrubbing() {
    let mut harness = super::opened_small_flower();
    let timeline = harness.get_by_label("Timeline").rect();
    let tooltip = "Timeline: green cells are computed keyframes";
    // Resting on the timeline explains it.
    harness.hover_at(timeline.center());
    for _ in 0..8 {
        harness.step();
    }
    harness.run();
    assert!(
        harness.query_by_label_contains(tooltip).is_some(),
        "the tooltip shows while hovering"
    );
    // Dragging the playhead: no tooltip, the read-out shows the keyframe.
    harness.drag_at(timeline.center());
    harness.run();
    for step in 1..=6 {
        harness.hover_at(timeline.center() + egui::vec2(20.0 * step as f32, 0.0));
        harness.step();
        assert!(
            harness.query_by_label_contains(tooltip).is_none(),
            "no tooltip while scrubbing"
        );
    }
    harness.run();
    assert!(harness.query_by_label_contains(tooltip).is_none());
    let readout = harness
        .query_all_by_label_contains(" / 20")
        .find(|n| n.rect().top() < timeline.top())
        .expect("the keyframe read-out")
        .rect();
    assert!(readout.bottom() < timeline.top(), "{readout:?}");
    harness.drop_at(timeline.center() + egui::vec2(120.0, 0.0));
    harness.run();
}

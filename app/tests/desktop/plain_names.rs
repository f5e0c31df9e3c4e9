//! Plain names for every number (issue 40 item 5), found going through
//! the real window at 1280×800: a part's turn schedule showed three bare
//! numbers in a row (20, 80, 30.0°) with no column names; it now has the
//! joint schedule's headers, and its fields are labelled by them; the Edit
//! menu's Undo and Redo said their shortcuts only once there was something
//! to undo.

use egui_kittest::kittest::Queryable;

use super::{click_in_view, opened_small_flower};

#[test]
fn a_parts_turn_schedule_names_its_columns() {
    let mut harness = opened_small_flower();
    harness.get_by_label("Flower").click();
    harness.run();
    click_in_view(&mut harness, "Add stamens");
    click_in_view(&mut harness, "stamen “stamen” × 5");
    if harness.state().project().flower.parts[0]
        .schedule
        .is_empty()
    {
        click_in_view(&mut harness, "Add turn");
    }
    let ramp = harness.state().project().flower.parts[0].schedule[0];
    for (name, value) in [
        ("From step", ramp.from_step.to_string()),
        ("To step", ramp.to_step.to_string()),
        ("Turn (degrees)", format!("{:.1}°", ramp.angle_deg)),
    ] {
        let field = harness.get_by_label(name);
        assert_eq!(field.value().as_deref(), Some(value.as_str()), "{name}");
    }
}

#[test]
fn undo_and_redo_show_their_shortcuts_even_with_nothing_to_undo() {
    let mut harness = opened_small_flower();
    assert_eq!(harness.state().document().undo_label(), None);
    harness.get_by_label("Edit").click();
    harness.run();
    // Written as the File menu writes its shortcuts ("Open…  (Ctrl+O)"):
    // a greyed "Undo" alone did not say which keys undo.
    for item in ["Undo  (Ctrl+Z)", "Redo  (Ctrl+Shift+Z)"] {
        assert!(harness.query_by_label(item).is_some(), "{item}");
    }
}

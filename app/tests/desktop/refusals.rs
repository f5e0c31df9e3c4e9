//! Every refusal is said (issue 40 item 3, issue 38 item 5): a typed value
//! out of range or not a number marks its field and logs the accepted
//! range, a value already outside a field's range is kept and marked, a
//! run that fails while the user chose a value outside the range runs
//! settle in names it, and damaged recoveries do not pile up.

use anthesis_sim::SimError;
use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT, Queryable};

use anthesis_app::desktop::words;

use super::{AnthesisApp, harness, small_flower};

/// Types `text` into the field of the parameter `symbol` (the `nth` of
/// them; labelled with its plain words) and presses Enter.
fn type_into(harness: &mut Harness<'_, AnthesisApp>, symbol: &str, nth: usize, text: &str) {
    let label = words::label(symbol);
    let label = label.as_str();
    harness
        .get_all_by_label(label)
        .nth(nth)
        .expect(label)
        .focus();
    harness.run();
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness
        .get_all_by_label(label)
        .nth(nth)
        .expect(label)
        .type_text(text);
    harness.key_press(egui::Key::Enter);
    harness.run();
}

/// Types `keys` into the `nth` field of `symbol`, one frame each, and
/// presses Enter.
fn type_keys(harness: &mut Harness<'_, AnthesisApp>, symbol: &str, nth: usize, keys: &[&str]) {
    let label = words::label(symbol);
    let field = |harness: &Harness<'_, AnthesisApp>| {
        harness
            .get_all_by_label(&label)
            .nth(nth)
            .expect("the field")
            .rect()
    };
    let at = field(harness).center();
    harness
        .get_all_by_label(&label)
        .nth(nth)
        .expect("the field")
        .focus();
    harness.run();
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    for key in keys {
        assert_eq!(field(harness).center(), at, "the same field");
        harness
            .get_all_by_label(&label)
            .nth(nth)
            .expect("the field")
            .type_text(key);
        harness.run();
    }
    harness.key_press(egui::Key::Enter);
    harness.run();
}

/// The tooltip shown while the pointer is over the `nth` field of
/// `symbol` (all its texts, one per line).
pub(crate) fn tooltip_of(
    harness: &mut Harness<'_, AnthesisApp>,
    symbol: &str,
    nth: usize,
) -> String {
    let label = words::label(symbol);
    harness
        .get_all_by_label(&label)
        .nth(nth)
        .expect("the field")
        .scroll_to_me();
    harness.run();
    let before = texts(harness);
    harness
        .get_all_by_label(&label)
        .nth(nth)
        .expect("the field")
        .hover();
    harness.run();
    harness.run();
    let mut after = texts(harness);
    for text in before {
        if let Some(i) = after.iter().position(|t| *t == text) {
            after.remove(i);
        }
    }
    // The pointer off the panels again.
    harness.hover_at(egui::pos2(640.0, 300.0));
    harness.run();
    after.join("\n")
}

/// Every text shown in the window.
fn texts(harness: &Harness<'_, AnthesisApp>) -> Vec<String> {
    harness
        .get_all_by(|n| n.label().is_some() || n.value().is_some())
        .filter_map(|n| n.accesskit_node().label().or_else(|| n.value()))
        .collect()
}

pub(crate) fn log_lines(harness: &Harness<'_, AnthesisApp>) -> Vec<String> {
    harness
        .state()
        .log()
        .entries()
        .iter()
        .map(|e| e.message.clone())
        .collect()
}

#[test]
fn thickness_minus_one_is_marked_and_logged_and_the_failed_run_names_it() {
    let mut harness = harness(small_flower());
    harness.run();
    type_into(&mut harness, "thickness", 0, "abc");
    type_into(&mut harness, "thickness", 0, "-1");
    let lines = log_lines(&harness);
    for said in [
        "`abc` is not a number; Thickness kept its value (Thickness accepts 0.001 to 100)",
        "Thickness -1 is out of range (Thickness accepts 0.001 to 100); set to 0.001",
    ] {
        assert_eq!(
            lines.iter().filter(|l| l.as_str() == said).count(),
            1,
            "{said:?} once in {lines:?}"
        );
    }
    // The same refusal in a new edit is said again.
    type_into(&mut harness, "thickness", 0, "abc");
    let again = log_lines(&harness)
        .iter()
        .filter(|l| l.starts_with("`abc` is not a number; Thickness"))
        .count();
    assert_eq!(again, 2);
    let petal = &harness.state().project().flower.templates[0];
    assert_eq!(petal.thickness, 0.001);
    let length = anthesis_flower::scale::organ_length(&petal.mesh);
    // The run then stops in a way whose own message says nothing of the
    // thickness (a crossing, say): the window names it with its range.
    let failure = SimError::NotConverged {
        keyframe: 6,
        organ: "petal-1".into(),
        iterations: 50,
        relative_gradient: 9.867e-6,
        held_against: Vec::new(),
        values: Vec::new(),
    };
    harness.state_mut().report_run_failure(&failure.to_string());
    harness.run();
    let lines = log_lines(&harness);
    let stopped: Vec<&String> = lines
        .iter()
        .filter(|l| l.starts_with("the simulation stopped"))
        .collect();
    assert_eq!(stopped.len(), 1, "{lines:?}");
    let expected = format!(
        "the simulation stopped: keyframe 6, organ `petal-1`: not converged after 50 iterations \
         (relative gradient 9.867e-6) (thickness 0.001 of `petal` is below the range where the \
         solver converges ({} to",
        (length / 2000.0 * 1e5).round() / 1e5
    );
    assert!(
        stopped[0].starts_with(&expected),
        "{}\n{expected}",
        stopped[0]
    );
    // Said once: not again as "the lowest the field accepts".
    assert_eq!(
        stopped[0].matches("thickness 0.001").count(),
        1,
        "{}",
        stopped[0]
    );
}

#[test]
fn a_fraction_in_a_count_is_refused_and_a_backwards_joint_ramp_is_flagged() {
    let mut harness = harness(small_flower());
    harness.run();
    let keyframes = harness.state().project().settings.keyframes;
    type_into(&mut harness, "keyframes", 0, "2.5");
    assert_eq!(harness.state().project().settings.keyframes, keyframes);
    assert!(
        log_lines(&harness).contains(
            &"`2.5` is not a whole number; Steps (keyframes) kept its value (Steps (keyframes) \
              accepts 1 to 10000, whole numbers)"
                .to_string()
        ),
        "{:?}",
        log_lines(&harness)
    );
    // A ramp from step 0 to 60; its end typed before its start.
    harness.get_by_label("Add ramp").click();
    harness.run();
    let ramps = harness.state().project().flower.templates[0]
        .joint_schedule
        .len();
    type_into(&mut harness, "from step", ramps - 1, "50");
    // "10" typed a key at a time: the end passes through 1 on the way, and
    // only what the finished edit makes is said, once.
    type_keys(&mut harness, "to step", ramps - 1, &["1", "0"]);
    let ramp = harness.state().project().flower.templates[0].joint_schedule[ramps - 1];
    assert_eq!((ramp.from_step, ramp.to_step), (50, 10));
    let backwards = "to step 10 is before from step 50: a run stops at a ramp that ends \
                     before it starts (to step accepts 50 to 100000 with this from step; from step accepts 0 to 10 with \
                     this to step)";
    let lines = log_lines(&harness);
    assert_eq!(
        lines.iter().filter(|l| l.as_str() == backwards).count(),
        1,
        "{lines:?}"
    );
    assert!(
        !lines.iter().any(|l| l.starts_with("to step 1 is before")),
        "a keystroke on the way is not said: {lines:?}"
    );
    // Both fields that make it wrong are outlined with the problem as
    // their tooltip.
    for symbol in ["from step", "to step"] {
        assert!(
            tooltip_of(&mut harness, symbol, ramps - 1).contains(backwards),
            "{symbol}"
        );
    }
    // More frames, and hovering, say nothing more.
    harness.run();
    let lines = log_lines(&harness);
    assert_eq!(
        lines.iter().filter(|l| l.as_str() == backwards).count(),
        1,
        "{lines:?}"
    );
    // The start moved back before the end: no outline, nothing said.
    type_into(&mut harness, "from step", ramps - 1, "5");
    assert!(!tooltip_of(&mut harness, "to step", ramps - 1).contains("ends before it starts"));
    assert!(
        !log_lines(&harness)
            .iter()
            .any(|l| l.starts_with("to step 10 is before from step 5:"))
    );
    // Out of range: clamped and said.
    type_into(&mut harness, "to step", ramps - 1, "200000");
    assert!(
        log_lines(&harness).contains(
            &"to step 200000 is out of range (to step accepts 0 to 100000); set to 100000"
                .to_string()
        ),
        "{:?}",
        log_lines(&harness)
    );
}

#[test]
fn a_value_loaded_outside_its_fields_range_is_kept_not_clamped() {
    let mut project = small_flower();
    project.flower.templates[0].thickness = 150.0;
    let mut harness = harness(project);
    for _ in 0..3 {
        harness.run();
    }
    let app = harness.state();
    assert_eq!(app.project().flower.templates[0].thickness, 150.0);
    assert!(
        !app.document().is_dirty(),
        "drawing the field edited nothing"
    );
}

#[test]
fn old_and_surplus_damaged_recoveries_are_removed_at_launch_and_said() {
    let dir = tempfile::tempdir().expect("tempdir");
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .expect("after 1970")
        .as_secs();
    for days in [1, 2, 3, 4, 40] {
        let folder = dir.path().join(format!("damaged-{}", now - days * 86_400));
        std::fs::create_dir_all(&folder).expect("mkdir");
    }
    let mut harness = harness(small_flower());
    harness.state_mut().enable_autosave(
        anthesis_flower::project::recovery::RecoveryFolder::new(dir.path()),
        std::time::Duration::from_secs(3600),
    );
    harness.run();
    let removed: Vec<String> = log_lines(&harness)
        .into_iter()
        .filter(|l| l.starts_with("removed the damaged recovery"))
        .collect();
    assert_eq!(removed.len(), 2, "{removed:?}");
    assert!(
        removed
            .iter()
            .any(|l| l.contains("set aside 40 days ago; set aside more than 30 days ago")),
        "{removed:?}"
    );
    assert!(
        removed
            .iter()
            .any(|l| l.contains("only the newest 3 damaged recoveries are kept")),
        "{removed:?}"
    );
    let left = std::fs::read_dir(dir.path()).expect("list").count();
    assert_eq!(left, 3);
}

//! A project file that states no unit opens in the window with its old
//! meaning and a note in the log saying which unit was assumed and how to
//! state one.

use anthesis_app::desktop::log::Level;

const NOTE: &str =
    "note: the project does not say what its unit is, so one unit is taken as one metre";

fn notes(harness: &egui_kittest::Harness<'_, anthesis_app::desktop::AnthesisApp>) -> Vec<String> {
    harness
        .state()
        .log()
        .entries()
        .iter()
        .filter(|e| e.message.starts_with(NOTE))
        .map(|e| {
            assert_eq!(e.level, Level::Warning, "{}", e.message);
            e.message.clone()
        })
        .collect()
}

#[test]
fn a_project_without_a_unit_opens_as_before_with_a_note_in_the_log() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("flower.anthesis.toml");
    let project = super::small_flower();
    assert_eq!(project.flower.unit, None);
    anthesis_flower::project::save_project(&project, &path).expect("saves");

    let mut harness = super::harness(project.clone());
    harness.run();
    assert!(notes(&harness).is_empty(), "not before a file is opened");
    harness.state_mut().open_path(&path);
    harness.run();
    let found = notes(&harness);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(
        found[0]
            .contains("add e.g. `unit = \"1 mm\"` after its `name = …` line in the project file"),
        "{}",
        found[0]
    );
    // The old meaning: still no unit, nothing rescaled.
    assert_eq!(harness.state().project().flower.unit, None);
    assert_eq!(
        harness.state().project().flower.templates[0].mesh,
        project.flower.templates[0].mesh
    );

    // A file that states its unit opens without the note.
    let mut stated = project;
    stated.flower.unit = anthesis_flower::Unit::millimetres(1.0);
    anthesis_flower::project::save_project(&stated, &path).expect("saves");
    harness.state_mut().open_path(&path);
    harness.run();
    assert_eq!(notes(&harness).len(), 1, "no second note");
    assert_eq!(
        harness.state().project().flower.unit,
        anthesis_flower::Unit::millimetres(1.0)
    );
}

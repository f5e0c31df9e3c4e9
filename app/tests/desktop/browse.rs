//! The fit dialog's target can be chosen in a file dialog (issue 40: every
//! control reachable without hunting): under Xvfb the target OBJ could
//! only be typed as a path, while the export's path had a Browse… button.

use egui_kittest::kittest::Queryable;

use super::harness_with_file_browser;

#[test]
fn the_fit_target_is_chosen_with_browse() {
    let dir = tempfile::tempdir().expect("temp dir");
    let target = dir.path().join("open.obj");
    std::fs::write(&target, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").expect("write");
    let mut harness = harness_with_file_browser(&dir.path().join("flower.anthesis.toml"));
    harness.get_by_label("Edit").click();
    harness.run();
    harness.get_by_label("Fit growth maps to a target…").click();
    harness.run();
    assert_eq!(harness.state().fit_dialog().target, "");
    harness.get_by_label("Browse…").click();
    harness.run();
    // The browser opens in the project's folder, listing OBJ files.
    harness.get_by_label("🗋 open.obj").click();
    harness.run();
    harness.get_by_label("Open").click();
    harness.run();
    assert_eq!(
        harness.state().fit_dialog().target,
        target.display().to_string()
    );
    assert_eq!(
        harness.get_by_label("Target OBJ").value().as_deref(),
        Some(target.display().to_string().as_str()),
        "the field shows it"
    );
}

//! View → Measurements: the organs coloured by a measurement with its
//! legend, and a column of `anthesis measure` read at the viewed keyframe.

use anthesis_app::desktop::measure_panel::MeasureField;
use anthesis_app::desktop::viewport::ViewField;
use anthesis_sim::measure::{MIDRIB_SAMPLES, UvPath};
use egui_kittest::kittest::{NodeT, Queryable};

use super::{opened_small_flower, recorded_keyframes};

#[test]
fn the_measurements_window_colours_the_organs_and_reads_the_midrib_over_time() {
    let mut harness = opened_small_flower();
    harness.get_by_label("View").click();
    harness.run();
    harness.get_by_label("Measurements…").click();
    harness.run();
    harness.get_by_label("Gaussian curvature K").click();
    harness.run();
    assert_eq!(
        harness.state().view_options().field,
        Some(ViewField::Measure(MeasureField::GaussianCurvature))
    );
    // The legend names the field in the project's units (the fixture
    // states none).
    harness.get_by_label_contains("Gaussian curvature K (1/unit²)");

    // The midrib of the first organ at the viewed keyframe, as the
    // recorded opening puts it.
    let app = harness.state();
    let at = app.playback().time_in_keyframes.round() as usize;
    let project = app.project().clone();
    let keyframes = recorded_keyframes(&project, &app.selection());
    let mesh = &project.flower.template_of(0).mesh;
    let expected = UvPath::midrib(&mesh.uvs, &mesh.triangles, MIDRIB_SAMPLES)
        .length(&keyframes[at].positions_in_world[0], &mesh.triangles);
    let label = format!("midrib_length at keyframe {at}: ");
    let node = harness.get_by_label_contains(&label);
    let access = node.accesskit_node();
    let text = access
        .label()
        .filter(|l| !l.is_empty())
        .or_else(|| access.value())
        .unwrap_or_default();
    let value: f64 = text
        .trim_start_matches(label.as_str())
        .trim_end_matches(" unit")
        .parse()
        .unwrap_or_else(|_| panic!("a number in {text:?}"));
    assert!(
        (value - expected).abs() <= 1e-3 * expected,
        "{value} against {expected}"
    );

    // "nothing" takes the colouring off again.
    harness.get_by_label("nothing").click();
    harness.run();
    assert_eq!(harness.state().view_options().field, None);
}

//! See what an edit did (issue 40 item 2): B held shows the result before
//! the last edit, the difference overlay says how far each point moved, in
//! the project's unit, and undo makes the result with the undone edit
//! "before". Recorded keyframes, as the rest of this suite.

use anthesis_app::desktop::viewport::{FieldShown, Quantity, ViewField};
use anthesis_app::desktop::{AnthesisApp, Command, ProjectEdit};
use anthesis_flower::unit::Unit;
use anthesis_flower::{Project, joint_angle_after};
use anthesis_sim::Selection;
use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use glam::DVec3;

/// The viewed keyframe.
const VIEWED: u32 = 12;
/// How much further the edit turns petal 0's template's joint ramp.
const TURN_DEG: f64 = 15.0;

/// The small flower with a real unit (1.8 mm).
fn flower() -> Project {
    let mut project = super::small_flower();
    project.flower.unit = Some(Unit::parse("1.8 mm").expect("a unit"));
    project
}

/// The positions of the recorded keyframe `k` of `project`, as fed.
fn recorded_at(project: &Project, k: u32) -> Vec<Vec<DVec3>> {
    super::recorded_keyframes(project, &Selection::All)[k as usize]
        .positions_in_world
        .clone()
}

/// The simulated organs' positions in the scene the viewport shows last,
/// and whether it is the result before the last edit.
fn shown(harness: &Harness<'_, AnthesisApp>) -> (bool, Vec<Vec<DVec3>>) {
    let (key, scene) = harness.state().shown_scene();
    let before = key.expect("a scene was built").before;
    let positions = scene
        .iter()
        .filter(|o| o.simulated)
        .map(|o| o.positions_in_world.clone())
        .collect();
    (before, positions)
}

fn assert_close(a: &[Vec<DVec3>], b: &[Vec<DVec3>], what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: organs");
    for (a, b) in a.iter().zip(b) {
        assert_eq!(a.len(), b.len(), "{what}: points");
        for (p, q) in a.iter().zip(b) {
            assert!(p.distance(*q) < 1e-9, "{what}: {p} against {q}");
        }
    }
}

/// Turns every template's joint ramp `TURN_DEG` further, as one edit.
fn turn_the_joints(harness: &mut Harness<'_, AnthesisApp>) {
    let app = harness.state_mut();
    let mut turned = app.project().flower.templates[0].clone();
    turned.joint_schedule[0].angle_deg += TURN_DEG;
    let keyframes = app.project().settings.keyframes;
    app.apply(Command::Edit {
        label: "joint degrees of petal".to_string(),
        edit: ProjectEdit::Template {
            template: 0,
            value: Box::new(turned),
            keyframes,
        },
    });
    harness.run();
}

/// The analytic move of every point of the edited organs at keyframe `k`:
/// the recorded opening turns each point about its organ's joint axis
/// (template +X through the base) by the ramp's angle at `k`, so a point
/// at distance r from the axis moves 2 r sin(δ / 2) when the angle grows
/// by δ. Organs of other templates do not move.
fn analytic_moves(before: &Project, after: &Project, k: u32) -> Vec<f64> {
    let mut moves = Vec::new();
    for i in 0..before.flower.organs.len() {
        let delta = joint_angle_after(&after.flower.template_of(i).joint_schedule, k)
            - joint_angle_after(&before.flower.template_of(i).joint_schedule, k);
        for p in &before.flower.template_of(i).mesh.positions {
            // The recorded curl (see `recorded_keyframes`).
            let z = p.z + 0.004 * f64::from(k) * p.y * p.y;
            let r = (p.y * p.y + z * z).sqrt();
            moves.push(2.0 * r * (delta / 2.0).sin().abs());
        }
    }
    moves
}

#[test]
fn holding_b_shows_the_result_before_the_last_edit_and_the_difference_says_how_far_it_moved() {
    let mut harness = super::harness(flower());
    harness.run();
    super::feed(&mut harness, None);
    harness
        .state_mut()
        .playback_mut()
        .scrub_to(f64::from(VIEWED), Some(20));
    harness.run();
    let old_project = harness.state().project().clone();
    let old = recorded_at(&old_project, VIEWED);

    // No earlier result yet: B says so and shows the current one.
    harness.key_down(egui::Key::B);
    harness.run();
    harness.get_by_label_contains("NO EARLIER RESULT");
    assert_close(&shown(&harness).1, &old, "nothing before the first run");
    harness.key_up(egui::Key::B);
    harness.run();

    turn_the_joints(&mut harness);
    super::feed(&mut harness, None);
    harness.run();
    let new_project = harness.state().project().clone();
    let new = recorded_at(&new_project, VIEWED);
    let (before, now) = shown(&harness);
    assert!(!before);
    assert_close(&now, &new, "the edit's result");

    // Held: the previous positions, badged.
    harness.key_down(egui::Key::B);
    harness.run();
    let (before, then) = shown(&harness);
    assert!(before, "B held shows the result before");
    assert_close(&then, &old, "B held");
    harness.get_by_label_contains("BEFORE THE LAST EDIT");
    harness.snapshot("app_before_the_last_edit");

    // Released: the current one again.
    harness.key_up(egui::Key::B);
    harness.run();
    let (before, now) = shown(&harness);
    assert!(!before);
    assert_close(&now, &new, "B released");
    assert!(
        harness
            .query_by_label_contains("BEFORE THE LAST EDIT")
            .is_none()
    );

    // The difference overlay: its max and mean are the analytic move.
    harness.get_by_label("Difference").click();
    harness.run();
    assert_eq!(
        harness.state().view_options().field,
        Some(ViewField::Difference)
    );
    let moves = analytic_moves(&old_project, &new_project, VIEWED);
    let largest = moves.iter().copied().fold(0.0, f64::max);
    let mean = moves.iter().sum::<f64>() / moves.len() as f64;
    assert!(largest > 0.1, "the edit moves the petals: {largest}");
    let field = harness.state().shown_field().expect("a field");
    let FieldShown::Field(field) = &*field else {
        panic!("the difference is drawn: {field:?}");
    };
    let max = field.max().expect("values");
    assert!(
        (max - largest).abs() < 1e-9 * largest,
        "{max} against {largest}"
    );
    assert!((field.mean().expect("values") - mean).abs() < 1e-9 * largest);
    assert_eq!(field.range, [0.0, max], "the ramp spans 0 to the max");
    // The legend says them in the project's unit (1.8 mm).
    let unit = Quantity::Length(Some(Unit::parse("1.8 mm").expect("a unit")));
    let said = format!(
        "max {}, mean {}",
        unit.format(largest, largest),
        unit.format(mean, largest)
    );
    assert!(said.contains(" mm"), "{said}");
    harness.get_by_label(&said);
    harness.snapshot("app_difference_overlay");

    // Undo: its run makes the edit's result "before".
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run();
    super::feed(&mut harness, None);
    harness.run();
    assert_close(&shown(&harness).1, &old, "undone");
    harness.key_down(egui::Key::B);
    harness.run();
    let (before, then) = shown(&harness);
    assert!(before);
    assert_close(&then, &new, "before the undo: the edit's result");
    harness.key_up(egui::Key::B);
    harness.run();
}

/// `project` with every template at its proxy mesh, as the window makes
/// it (`anthesis_flower::resolution::proxy_mesh`).
fn proxy_of(project: &Project) -> Project {
    let mut proxy = project.clone();
    for template in &mut proxy.flower.templates {
        if let Some(mesh) = anthesis_flower::resolution::proxy_mesh(template) {
            template.mesh = mesh;
        }
    }
    proxy
}

#[test]
fn the_difference_is_against_the_proxy_while_the_proxy_is_shown() {
    use anthesis_sim::worker::Event;
    use std::sync::Arc;

    // Fine enough to have a proxy (448 particles an organ).
    let mut project = anthesis_sim::fixtures::whorl(6, 16, 28, 20);
    project.flower.unit = Some(Unit::parse("1.8 mm").expect("a unit"));
    let mut harness = super::harness(project);
    harness.run();
    super::feed(&mut harness, None);
    harness.run();
    harness
        .state_mut()
        .playback_mut()
        .scrub_to(f64::from(VIEWED), Some(20));
    harness.state_mut().view_options_mut().field = Some(ViewField::Difference);
    let old_project = harness.state().project().clone();
    turn_the_joints(&mut harness);

    // The edit's run shows its proxy at the viewed keyframe first: the
    // recorded opening of the proxy's coarser meshes.
    let app = harness.state_mut();
    let project = app.project().clone();
    let proxy = proxy_of(&project);
    let particles = |p: &Project| p.flower.template_of(0).mesh.vertex_count();
    assert!(
        particles(&proxy) < particles(&project) / 2,
        "a coarser proxy"
    );
    let run = app.session().run();
    let keyframes = super::recorded_keyframes(&proxy, &Selection::All);
    let session = app.session_mut();
    let mut failures = Vec::new();
    session.accept(
        Event::Started {
            run,
            organs: Vec::new(),
            keyframes: project.settings.keyframes,
            first_computed: 1,
            proxy: true,
        },
        &mut failures,
    );
    for keyframe in keyframes.into_iter().skip(VIEWED as usize).take(2) {
        session.accept(
            Event::Proxy {
                run,
                keyframe: Arc::new(keyframe),
            },
            &mut failures,
        );
    }
    assert!(failures.is_empty());
    harness.run();
    harness.get_by_label_contains("the difference is against the proxy");
    let field = harness.state().shown_field().expect("a field");
    let FieldShown::Field(field) = &*field else {
        panic!("the difference is drawn: {field:?}");
    };
    // On the proxy's points, each compared with the same UV of the fine
    // result before: the analytic move of the proxy's points, but for the
    // fine mesh's straight edges across the recorded curl (a few
    // hundredths of a unit).
    let proxy_old = proxy_of(&old_project);
    let moves = analytic_moves(&proxy_old, &proxy, VIEWED);
    let largest = moves.iter().copied().fold(0.0, f64::max);
    let max = field.max().expect("values");
    assert_eq!(
        field.values.iter().flatten().map(Vec::len).sum::<usize>(),
        moves.len(),
        "one value per proxy point"
    );
    assert!(
        (max - largest).abs() < 0.01 * largest,
        "{max} against {largest}"
    );
}

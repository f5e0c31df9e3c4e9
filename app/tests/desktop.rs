//! The whole desktop app in egui_kittest with the wgpu renderer (software
//! Vulkan is enough): clicking through the panels, keyboard shortcuts,
//! undo/redo, the unsaved-changes prompt, export, errors, and image
//! snapshots. Keyframes are RECORDED (a fixed, analytic opening fed to the
//! app as worker events), not computed by the live solver, so snapshots do
//! not move when the physics changes.

use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anthesis_app::desktop::{AnthesisApp, Pending, Startup};
use anthesis_flower::{Project, joint_angle_after};
use anthesis_sim::worker::Event;
use anthesis_sim::{Keyframe, KeyframeStats, Selection};
use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;

#[path = "desktop/browse.rs"]
mod browse;
mod common;
#[path = "desktop/difference.rs"]
mod difference;
#[path = "desktop/measure.rs"]
mod measure;
#[path = "desktop/panels.rs"]
mod panels;
#[path = "desktop/plain_names.rs"]
mod plain_names;
#[path = "desktop/refusals.rs"]
mod refusals;
#[path = "desktop/sketch_room.rs"]
mod sketch_room;
#[path = "desktop/sliders.rs"]
mod sliders;
#[path = "desktop/units.rs"]
mod units;

/// A small flower (six organs, coarse meshes) with 20 keyframes.
fn small_flower() -> Project {
    let mut project = anthesis_sim::fixtures::whorl(6, 8, 14, 20);
    project.name = "Recorded test flower".to_string();
    project
}

/// A recorded opening: keyframe `k` tilts every simulated organ by the
/// template's joint schedule plus 2° per keyframe and curls it outwards a
/// little with height, with made-up statistics.
fn recorded_keyframes(project: &Project, selection: &Selection) -> Vec<Keyframe> {
    let organs: Vec<usize> = match selection {
        Selection::All => (0..project.flower.organs.len()).collect(),
        Selection::Only(i) => vec![*i],
    };
    (0..=project.settings.keyframes)
        .map(|k| {
            let positions_in_world = organs
                .iter()
                .map(|&i| {
                    let organ = &project.flower.organs[i];
                    let template = project.flower.template_of(i);
                    let extra = joint_angle_after(&template.joint_schedule, k)
                        + f64::from(k) * 2f64.to_radians();
                    template
                        .mesh
                        .positions
                        .iter()
                        .map(|p| {
                            let curl = 0.004 * f64::from(k) * p.y * p.y;
                            let bent = glam::DVec3::new(p.x, p.y, p.z + curl);
                            organ.placement.world_from_template(bent, extra)
                        })
                        .collect()
                })
                .collect();
            Keyframe {
                index: k,
                positions_in_world,
                stats: KeyframeStats {
                    index: k,
                    energy: f64::from(k * k) * 0.01,
                    iterations: 2 + k % 3,
                    relative_gradient: 1e-7,
                    seconds: 0.05,
                    pushed_particles: 0,
                    contact_particles: 0,
                },
            }
        })
        .collect()
}

fn harness(project: Project) -> Harness<'static, AnthesisApp> {
    // egui_kittest's default: a frame is 0.25 s (4 frames a second).
    harness_stepping(project, 0.25)
}

/// The app with `step_seconds` of time per frame.
fn harness_stepping(project: Project, step_seconds: f32) -> Harness<'static, AnthesisApp> {
    Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .with_step_dt(step_seconds)
        .wgpu()
        .build_eframe(move |cc| {
            AnthesisApp::new(
                cc,
                Startup {
                    project: Some((project, None)),
                    live: false,
                    restore: false,
                    warnings: Vec::new(),
                },
            )
            .expect("the app starts")
        })
}

/// Feeds the current run `up_to` keyframes (all when `None`) and, when
/// all, its end.
fn feed(harness: &mut Harness<'_, AnthesisApp>, up_to: Option<u32>) {
    let app = harness.state_mut();
    let project = app.project().clone();
    let selection = app.selection();
    let run = app.session().run();
    let keyframes = recorded_keyframes(&project, &selection);
    let total = project.settings.keyframes;
    let last = up_to.unwrap_or(total);
    let mut failures = Vec::new();
    let session = app.session_mut();
    session.accept(
        Event::Started {
            run,
            organs: Vec::new(),
            keyframes: total,
            first_computed: 1,
            proxy: false,
        },
        &mut failures,
    );
    for keyframe in keyframes.into_iter().take(last as usize + 1) {
        session.accept(
            Event::Keyframe {
                run,
                keyframe: Arc::new(keyframe),
            },
            &mut failures,
        );
    }
    if last == total {
        session.accept(
            Event::Finished {
                run,
                keyframes: total,
                seconds: 1.0,
            },
            &mut failures,
        );
    }
    assert!(failures.is_empty());
}

/// The small flower launched with its whole recorded opening received.
fn opened_small_flower() -> Harness<'static, AnthesisApp> {
    let mut harness = harness(small_flower());
    harness.run();
    feed(&mut harness, None);
    harness.run();
    harness
}

#[test]
fn first_frame_shows_the_flower_opening_and_the_timeline() {
    let mut harness = harness(small_flower());
    harness.run();
    assert_eq!(harness.state().session().run(), 1, "a run starts at launch");
    feed(&mut harness, Some(8));
    harness.run();
    assert_eq!(
        harness.state().playback().time_in_keyframes,
        8.0,
        "follows new keyframes"
    );
    harness.get_by_label_contains("simulating keyframe 9/20");
    // The status line says how long the run took: fixed, so the picture
    // does not depend on the machine's load.
    harness
        .state_mut()
        .session_mut()
        .freeze_elapsed(Duration::from_millis(2400));
    harness.run();
    harness.get_by_label_contains("2.4 s elapsed");
    harness.snapshot("app_simulating");

    feed(&mut harness, None);
    harness.run();
    harness.get_by_label("20 keyframes in 1.0 s");
    assert_eq!(harness.state().playback().time_in_keyframes, 20.0);
    harness.snapshot("app_open_flower");
}

#[test]
fn timeline_buttons_and_shortcuts_scrub_step_and_play() {
    let mut harness = opened_small_flower();

    harness.get_by_label("Start").click();
    harness.run();
    assert_eq!(harness.state().playback().time_in_keyframes, 0.0);
    harness.get_by_label("Next").click();
    harness.run();
    assert_eq!(harness.state().playback().time_in_keyframes, 1.0);

    harness.key_press(egui::Key::ArrowRight);
    harness.key_press(egui::Key::ArrowRight);
    harness.run();
    assert_eq!(harness.state().playback().time_in_keyframes, 3.0);
    harness.key_press(egui::Key::ArrowLeft);
    harness.run();
    assert_eq!(harness.state().playback().time_in_keyframes, 2.0);
    harness.key_press(egui::Key::End);
    harness.run();
    assert_eq!(harness.state().playback().time_in_keyframes, 20.0);
    harness.key_press(egui::Key::Home);
    harness.run();
    assert_eq!(harness.state().playback().time_in_keyframes, 0.0);

    // Space plays: a few frames later the time has moved on.
    harness.key_press(egui::Key::Space);
    harness.step();
    harness.step();
    harness.step();
    assert!(harness.state().playback().playing);
    assert!(harness.state().playback().time_in_keyframes > 0.0);
    harness.key_press(egui::Key::Space);
    harness.step();
    assert!(!harness.state().playback().playing);

    // A scrub half-way along the timeline, between keyframes, is shown
    // interpolated.
    let timeline = harness.get_by_label("Timeline").rect();
    harness.state_mut().playback_mut().scrub_to(9.5, Some(20));
    harness.run();
    assert_eq!(harness.state().playback().time_in_keyframes, 9.5);
    harness.snapshot("app_scrubbed_between_keyframes");
    assert!(timeline.width() > 500.0);
}

#[test]
fn an_edit_keeps_the_viewed_frame_stale_until_the_new_run_reaches_it() {
    use anthesis_app::desktop::{Command, ProjectEdit};
    let mut project = small_flower();
    // Keys inside the run, so the timeline marks them.
    for (key, step) in project.flower.templates[0]
        .maps
        .keys_mut()
        .iter_mut()
        .zip([6, 14])
    {
        key.step = step;
    }
    let mut harness = harness(project);
    harness.run();
    feed(&mut harness, None);
    harness.state_mut().playback_mut().scrub_to(12.0, Some(20));
    harness.run();
    let shown = |harness: &Harness<'_, AnthesisApp>| {
        harness.state().session().positions_at(12.0).expect("shown")
    };
    let old = shown(&harness);

    // An edit that changes the opening (the joint ramp turns further).
    let app = harness.state_mut();
    let mut turned = app.project().flower.templates[0].clone();
    turned.joint_schedule[0].angle_deg += 15.0;
    let keyframes = app.project().settings.keyframes;
    let run = app.session().run();
    app.apply(Command::Edit {
        label: "joint degrees of petal".to_string(),
        edit: ProjectEdit::Template {
            template: 0,
            value: Box::new(turned),
            keyframes,
        },
    });
    harness.run();
    let app = harness.state();
    assert!(app.session().run() > run, "the edit started a new run");
    assert_eq!(app.playback().time_in_keyframes, 12.0, "the playhead stays");
    assert!(app.session().is_stale_at(12.0));
    assert_eq!(shown(&harness), old, "the previous result stays shown");

    // The new run's first keyframes arrive: keyframe 12 is still stale.
    feed(&mut harness, Some(8));
    harness.run();
    assert_eq!(harness.state().playback().time_in_keyframes, 12.0);
    assert!(harness.state().session().is_stale_at(12.0));
    assert!(
        harness
            .get_by_label_contains("stale: previous result until the run reaches 12")
            .rect()
            .width()
            > 0.0
    );
    // The elapsed time in the status line is fixed, so the picture does not
    // depend on how fast the machine ran the test (it said "under 0.1 s"
    // once at load 7).
    harness
        .state_mut()
        .session_mut()
        .freeze_elapsed(Duration::from_millis(100));
    harness.run();
    harness.get_by_label_contains("0.1 s elapsed");
    harness.snapshot("app_stale_after_an_edit");

    // It reaches keyframe 12: the new result is shown.
    feed(&mut harness, Some(13));
    harness.run();
    let app = harness.state();
    assert!(!app.session().is_stale_at(12.0));
    assert_ne!(shown(&harness), old, "the new opening is shown");
    assert_eq!(app.playback().time_in_keyframes, 12.0);
}

#[test]
fn a_key_gets_its_own_growth_scale_in_the_paint_panel_as_one_undo_step() {
    let mut harness = opened_small_flower();
    let first_run = harness.state().session().run();
    let template_dg = harness.state().project().flower.templates[0].dg;
    let selected = |h: &Harness<'static, AnthesisApp>| {
        h.state().project().flower.templates[0]
            .maps
            .keys()
            .iter()
            .map(|k| k.dg)
            .collect::<Vec<_>>()
    };
    assert!(selected(&harness).iter().all(Option::is_none));
    harness.get_by_label("own").click();
    harness.run();
    // The selected (first) key takes the template's dg as its own, to
    // change from there; the run restarts and the undo names the key.
    let keys = selected(&harness);
    assert_eq!(keys[0], Some(template_dg), "{keys:?}");
    assert!(keys[1..].iter().all(Option::is_none), "{keys:?}");
    assert!(harness.state().session().run() > first_run);
    let label = harness.state().document().undo_label().map(str::to_owned);
    assert!(
        label.as_deref().is_some_and(|l| l.starts_with("dg of key")),
        "{label:?}"
    );
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run();
    assert!(selected(&harness).iter().all(Option::is_none));
}

#[test]
fn parameter_edits_restart_the_run_and_undo_redo_with_shortcuts() {
    let mut harness = opened_small_flower();
    let first_run = harness.state().session().run();
    let ramps = harness.state().project().flower.templates[0]
        .joint_schedule
        .len();

    harness.get_by_label("Add ramp").click();
    harness.run();
    let app = harness.state();
    assert_eq!(
        app.project().flower.templates[0].joint_schedule.len(),
        ramps + 1
    );
    assert!(app.document().is_dirty());
    assert!(app.session().run() > first_run, "the edit restarts the run");

    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run();
    assert_eq!(
        harness.state().project().flower.templates[0]
            .joint_schedule
            .len(),
        ramps
    );
    assert!(!harness.state().document().is_dirty());
    harness.key_press_modifiers(
        egui::Modifiers::COMMAND | egui::Modifiers::SHIFT,
        egui::Key::Z,
    );
    harness.run();
    assert_eq!(
        harness.state().project().flower.templates[0]
            .joint_schedule
            .len(),
        ramps + 1
    );
}

#[test]
fn selecting_an_organ_and_single_organ_preview_simulate_only_that_organ() {
    let mut harness = harness(small_flower());
    harness.run();
    harness.get_by_label("sepal-2").click();
    harness.run();
    assert_eq!(harness.state().selected_organ(), 3);
    let before = harness.state().session().run();
    harness.get_by_label("Single-organ preview  (P)").click();
    harness.run();
    let app = harness.state();
    assert_eq!(app.selection(), Selection::Only(3));
    assert!(app.session().run() > before);
    assert_eq!(app.session().organs(), &[3]);
    feed(&mut harness, None);
    harness.run();
    harness.snapshot("app_single_organ_preview");
    // P leaves the preview: the whole flower again.
    harness.key_press(egui::Key::P);
    harness.run();
    assert_eq!(harness.state().selection(), Selection::All);
}

#[test]
fn view_menu_turns_on_the_wireframe_and_a_map_overlay() {
    let mut harness = opened_small_flower();
    harness.get_by_label("View").click();
    harness.run();
    harness.get_by_label("Wireframe  (W)").click();
    harness.run();
    harness.get_by_label("View").click();
    harness.run();
    harness.get_by_label("Map overlay").hover();
    harness.run();
    harness
        .get_by_label("Growth along, inner side (e-growth-in)")
        .click();
    harness.run();
    harness.key_press(egui::Key::Escape);
    harness.run();
    harness.snapshot("app_wireframe_overlay");
}

#[test]
fn new_with_unsaved_changes_asks_first_and_dont_save_discards() {
    let mut harness = harness(small_flower());
    harness.run();
    harness.get_by_label("Add ramp").click();
    harness.run();
    assert!(harness.state().document().is_dirty());
    harness.get_by_label("File").click();
    harness.run();
    harness.get_by_label("New").click();
    harness.run();
    // The gallery of starting points; the lily asks first.
    harness.get_by_label("New flower");
    wait_for_gallery(&mut harness);
    harness.get_by_label("Asiatic lily").click();
    harness.run();
    assert_eq!(
        harness.state().pending(),
        Some(&Pending::New("lily".into()))
    );
    harness.get_by_label("Unsaved changes");
    harness.get_by_label("Cancel").click();
    harness.run();
    assert_eq!(harness.state().pending(), None);
    assert!(
        harness.state().document().is_dirty(),
        "cancel keeps the work"
    );

    harness.state_mut().request(Pending::New("lily".into()));
    harness.run();
    harness.get_by_label("Don't save").click();
    harness.run();
    let app = harness.state();
    assert!(!app.document().is_dirty());
    assert_eq!(
        app.project(),
        &anthesis_app::desktop::default_project().expect("a default flower")
    );
}

#[test]
fn save_then_open_round_trips_and_a_bad_file_is_an_error_that_keeps_the_work() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("flower.anthesis.toml");
    let mut harness = harness(small_flower());
    harness.run();
    harness.get_by_label("Add ramp").click();
    harness.run();
    assert!(harness.state_mut().save_to(&path));
    harness.run();
    assert!(!harness.state().document().is_dirty());
    let saved = harness.state().project().clone();

    let bad = dir.path().join("bad.anthesis.toml");
    std::fs::write(&bad, "format = \"anthesis-project\"\nversion = 99\n").expect("write");
    harness.state_mut().open_path(&bad);
    harness.run();
    assert_eq!(harness.state().project(), &saved, "the work stays");
    let banner = harness.state().log().banner().expect("an error is shown");
    assert!(banner.contains("newer Anthesis"), "{banner}");
    harness.get_by_label("Dismiss").click();
    harness.run();
    assert!(harness.state().log().banner().is_none());

    harness.state_mut().open_path(&path);
    harness.run();
    let app = harness.state();
    assert_eq!(app.project().flower.templates[0].joint_schedule.len(), 2);
    assert_eq!(app.document().path.as_deref(), Some(path.as_path()));

    // The project's folder opens its one project file, which becomes the
    // document's path (so Save writes the file, not the folder).
    std::fs::remove_file(&bad).expect("remove");
    harness.state_mut().open_path(dir.path());
    harness.run();
    assert_eq!(
        harness.state().document().path.as_deref(),
        Some(path.as_path())
    );
}

#[test]
fn a_failed_run_is_shown_and_the_app_keeps_going() {
    let mut harness = harness(small_flower());
    harness.run();
    let run = harness.state().session().run();
    let mut failures = Vec::new();
    harness.state_mut().session_mut().accept(
        Event::Failed {
            run,
            error: anthesis_sim::SimError::NoSuchOrgan(9),
        },
        &mut failures,
    );
    assert_eq!(failures.len(), 1);
    harness.run();
    harness.get_by_label_contains("stopped at keyframe 0");
    harness.get_by_label("Simulate").click();
    harness.run();
    assert!(harness.state().session().run() > run);
}

/// Steps `harness` until the export dialog says it wrote `out` (failing
/// after `limit`).
fn wait_for_export(harness: &mut Harness<'_, AnthesisApp>, out: &Path, limit: Duration) {
    let started = Instant::now();
    while !out.exists() || harness.query_by_label_contains("Wrote ").is_none() {
        assert!(
            started.elapsed() < limit,
            "export hangs; state {:?}, path {:?}, log: {:?}",
            harness.state().export_dialog().state(),
            harness.state().export_dialog().path,
            harness.state().log().entries()
        );
        std::thread::sleep(Duration::from_millis(20));
        harness.step();
    }
}

/// The JSON chunk of the .glb at `path`.
fn glb_json(path: &Path) -> String {
    let bytes = std::fs::read(path).expect("exported file");
    assert_eq!(&bytes[..4], b"glTF");
    let json_length = u32::from_le_bytes([bytes[12], bytes[13], bytes[14], bytes[15]]) as usize;
    String::from_utf8(bytes[20..20 + json_length].to_vec()).expect("JSON chunk")
}

#[test]
fn the_export_dialog_runs_the_flower_again_at_a_finer_edge_for_the_file_only() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("fine.glb");
    let mut harness = opened_small_flower();
    let before = harness.state().project().clone();
    harness.state_mut().open_export();
    harness.run();
    harness.state_mut().export_dialog_mut().path = "fine.glb".to_string();
    harness.get_by_label("run again at mean edge").click();
    harness.run();
    harness.get_by_label_contains("particles in the largest organ (112 now)");
    harness.get_by_label_contains("The export runs all 20 keyframes again at mean edge 0.716;");
    harness.snapshot("export_dialog_run_again");
    harness.state_mut().export_dialog_mut().path = out.display().to_string();
    harness.run();
    harness.get_by_label("Export").click();
    wait_for_export(&mut harness, &out, Duration::from_secs(120));
    // The file holds the finer meshes; the project and the window's run
    // are as they were.
    let json: serde_json::Value =
        serde_json::from_str(&glb_json(&out)).expect("the JSON chunk parses");
    let most_vertices = json["accessors"]
        .as_array()
        .expect("accessors")
        .iter()
        .filter_map(|a| a["count"].as_u64())
        .max()
        .expect("counts");
    let built = before.flower.template_of(0).mesh.vertex_count() as u64;
    assert!(most_vertices > 2 * built, "{most_vertices} vs {built}");
    assert_eq!(harness.state().project(), &before);
    assert_eq!(harness.state().session().keyframes().len(), 21);
}

#[test]
fn the_export_dialogs_particles_now_are_those_the_window_simulates() {
    // At a resolution the "(N now)" is the largest remeshed organ's count,
    // the number the parameters panel shows, not a prediction of it (a
    // flower made elsewhere showed 434 there against 452 simulated).
    use anthesis_app::desktop::{Command, ProjectEdit};
    use anthesis_flower::Resolution;
    let mut harness = opened_small_flower();
    let edge = anthesis_bud::quality(&harness.state().project().flower.templates[0].mesh).mean_edge;
    harness.state_mut().apply(Command::Edit {
        label: "resolution".to_string(),
        edit: ProjectEdit::Resolution(Resolution::MeanEdge(0.7 * edge)),
    });
    harness.run();
    let simulated = harness.state_mut().resolved_project();
    let now = (0..simulated.flower.organs.len())
        .map(|i| simulated.flower.template_of(i).mesh.vertex_count())
        .max()
        .expect("organs");
    let project = harness.state().project();
    let predicted = (0..project.flower.organs.len())
        .map(|i| {
            anthesis_flower::resolution::predicted_size(
                &project.flower.template_of(i).mesh,
                0.7 * edge,
            )
            .0
        })
        .max()
        .expect("organs");
    harness.state_mut().open_export();
    harness.run();
    harness.get_by_label("run again at mean edge").click();
    harness.run();
    harness.get_by_label_contains(&format!("particles in the largest organ ({now} now)"));
    // The prediction would have said otherwise on this mesh.
    assert_ne!(predicted, now, "the case does not tell the two apart");
}

#[test]
fn the_export_dialog_writes_a_glb_and_reports_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("flower.glb");
    let mut harness = opened_small_flower();
    harness.get_by_label("File").click();
    harness.run();
    harness.get_by_label("Export animation…  (Ctrl+E)").click();
    harness.run();
    assert_eq!(
        harness.state().export_dialog().path,
        "Recorded_test_flower.glb",
        "a file name is suggested"
    );
    harness.state_mut().open_export();
    harness.get_by_label("Export to").click();
    harness.run();
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness
        .get_by_label("Export to")
        .type_text(&out.display().to_string());
    harness.run();
    harness.get_by_label("meshopt").click();
    harness.run();
    harness.get_by_label("Export").click();
    wait_for_export(&mut harness, &out, Duration::from_secs(60));
    let json = glb_json(&out);
    assert!(
        json.contains("EXT_meshopt_compression") && json.contains("KHR_mesh_quantization"),
        "the option was used"
    );
}

/// Drags across the UV canvas from `from` to `to` (fractions of its size).
fn stroke_on_canvas(harness: &mut Harness<'_, AnthesisApp>, from: egui::Vec2, to: egui::Vec2) {
    let canvas = harness.get_by_label("UV paint canvas").rect();
    let at = |f: egui::Vec2| canvas.min + f * canvas.size();
    harness.hover_at(at(from));
    harness.run();
    harness.drag_at(at(from));
    harness.run();
    for i in 1..=8 {
        let t = i as f32 / 8.0;
        harness.hover_at(at(from + (to - from) * t));
        harness.run();
    }
    harness.drop_at(at(to));
    harness.run();
}

#[test]
fn a_stroke_on_the_uv_canvas_paints_the_map_restarts_and_undoes_in_one_step() {
    let mut harness = opened_small_flower();
    let before = harness.state().project().clone();
    let run = harness.state().session().run();
    harness.get_by_label("subtract").click();
    harness.run();
    stroke_on_canvas(&mut harness, egui::vec2(0.3, 0.3), egui::vec2(0.4, 0.6));
    let app = harness.state();
    assert_ne!(app.project(), &before, "the stroke painted");
    assert!(app.session().run() > run, "the stroke restarted the run");
    // Mirrored: both sides of the midrib changed alike.
    let map = &app.project().flower.templates[0].maps.keys()[0]
        .maps
        .e_growth_in;
    let left = map.sample(glam::DVec2::new(0.35, 0.55));
    let right = map.sample(glam::DVec2::new(0.65, 0.55));
    let was = before.flower.templates[0].maps.keys()[0]
        .maps
        .e_growth_in
        .sample(glam::DVec2::new(0.35, 0.55));
    assert!(left < was, "subtracted: {left} < {was}");
    assert!((left - right).abs() < 1e-6, "mirrored: {left} vs {right}");
    feed(&mut harness, None);
    harness.run();
    // The log is cleared for the snapshot.
    harness.get_by_label("Clear").click();
    harness.hover_at(egui::pos2(600.0, 300.0));
    harness.run();
    harness.snapshot("app_after_stroke");

    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run();
    assert_eq!(harness.state().project(), &before, "one stroke, one undo");
}

/// The small flower with a hard, full-strength set brush of radius 0.06
/// (two pixels of its 32-pixel maps)
/// painting 0 on the bend map (1 everywhere before), no mirror.
fn hard_brush_on_bend(step_seconds: f32) -> Harness<'static, AnthesisApp> {
    use anthesis_maps::MapKind;
    use anthesis_maps::brush::{Brush, BrushMode, PaintTarget};
    let mut harness = harness_stepping(small_flower(), step_seconds);
    harness.run();
    let paint = harness.state_mut().paint_mut();
    paint.target = PaintTarget::Scalar(MapKind::Bend);
    paint.brush = Brush {
        mode: BrushMode::Set,
        radius_in_uv: 0.06,
        strength: 1.0,
        hardness: 1.0,
        value: 0.0,
        mirror: false,
    };
    harness.run();
    harness
}

/// The canvas position of `point_in_uv` (the canvas at its initial view:
/// the UV square fills it, v up).
fn canvas_at(harness: &Harness<'_, AnthesisApp>, u: f32, v: f32) -> egui::Pos2 {
    let canvas = harness.get_by_label("UV paint canvas").rect();
    canvas.min + egui::vec2(u, 1.0 - v) * canvas.size()
}

fn bend_at(harness: &Harness<'_, AnthesisApp>, u: f64, v: f64) -> f64 {
    harness.state().project().flower.templates[0].maps.keys()[0]
        .maps
        .bend
        .sample(glam::DVec2::new(u, v))
}

/// `count` primary clicks (press and release) at `pos`, a frame per event.
fn click(harness: &mut Harness<'_, AnthesisApp>, pos: egui::Pos2, count: usize) {
    harness.hover_at(pos);
    harness.step();
    for pressed in [true, false].repeat(count) {
        harness.event(egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        });
    }
    harness.step();
}

#[test]
fn a_stroke_at_four_frames_a_second_leaves_no_gaps_between_long_pointer_jumps() {
    // The harness steps 0.25 s per frame: the pointer jumps 0.2-0.3 UV per
    // frame, three to five brush radii.
    let mut harness = hard_brush_on_bend(0.25);
    let path = [(0.2_f32, 0.3_f32), (0.45, 0.5), (0.55, 0.75), (0.8, 0.6)];
    harness.hover_at(canvas_at(&harness, path[0].0, path[0].1));
    harness.step();
    harness.drag_at(canvas_at(&harness, path[0].0, path[0].1));
    harness.step();
    for &(u, v) in &path[1..] {
        harness.hover_at(canvas_at(&harness, u, v));
        harness.step();
    }
    harness.drop_at(canvas_at(&harness, path[3].0, path[3].1));
    harness.step();
    harness.step();
    // Every point of the path is painted (a hard brush sets 0 within its
    // radius; dabs at most a quarter radius apart leave every point well
    // inside one).
    for pair in path.windows(2) {
        for i in 0..=50 {
            let t = f64::from(i) / 50.0;
            let u = f64::from(pair[0].0) + t * f64::from(pair[1].0 - pair[0].0);
            let v = f64::from(pair[0].1) + t * f64::from(pair[1].1 - pair[0].1);
            let value = bend_at(&harness, u, v);
            assert!(value < 0.05, "a gap at ({u:.3}, {v:.3}): {value}");
        }
    }
    // Away from the path nothing changed.
    assert!((bend_at(&harness, 0.2, 0.8) - 1.0).abs() < 1e-6);
    assert!((bend_at(&harness, 0.8, 0.2) - 1.0).abs() < 1e-6);
    // One stroke, one undo step.
    assert!(
        harness
            .state()
            .document()
            .undo_label()
            .is_some_and(|l| l.contains("stroke on bend"))
    );
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run();
    assert!(
        (bend_at(&harness, 0.45, 0.5) - 1.0).abs() < 1e-6,
        "undone at once"
    );
}

#[test]
fn a_click_paints_one_dab_and_a_double_click_resets_the_view_and_paints_nothing() {
    // 20 frames a second: a press and release a frame apart each, inside
    // egui's 0.3 s double-click time.
    let mut harness = hard_brush_on_bend(0.05);
    let before = harness.state().project().clone();
    let undo_before = harness.state().document().undo_label().map(str::to_owned);

    // A double-click: nothing painted, the history as it was, also after
    // the double-click time has passed.
    let at = canvas_at(&harness, 0.3, 0.5);
    click(&mut harness, at, 2);
    for _ in 0..10 {
        harness.step();
    }
    assert!(
        harness.state().project() == &before,
        "a double-click paints nothing"
    );
    assert_eq!(
        harness.state().document().undo_label().map(str::to_owned),
        undo_before,
        "and leaves the history alone"
    );

    // One click, then the double-click time passes: one dab there.
    let at = canvas_at(&harness, 0.7, 0.4);
    click(&mut harness, at, 1);
    for _ in 0..10 {
        harness.step();
    }
    assert!(
        bend_at(&harness, 0.7, 0.4) < 1e-6,
        "the dab's centre is painted"
    );
    let map = &harness.state().project().flower.templates[0].maps.keys()[0]
        .maps
        .bend;
    let (width, height) = map.size();
    // Every changed pixel is under the one dab (within the radius of the
    // click, with a pixel of slack).
    let pixel = 1.0 / f64::from(width.min(height));
    let mut changed = 0;
    for y in 0..height {
        for x in 0..width {
            let value = map.values()[(y * width + x) as usize];
            if (value - 1.0).abs() > 1e-6 {
                changed += 1;
                let uv = glam::DVec2::new(
                    (f64::from(x) + 0.5) / f64::from(width),
                    1.0 - (f64::from(y) + 0.5) / f64::from(height),
                );
                assert!(
                    uv.distance(glam::DVec2::new(0.7, 0.4)) < 0.06 + pixel,
                    "painted outside the dab at {uv}"
                );
            }
        }
    }
    assert!(changed > 0);
    assert!(
        harness
            .state()
            .document()
            .undo_label()
            .is_some_and(|l| l.contains("dab on bend"))
    );
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run();
    assert_eq!(
        harness.state().project(),
        &before,
        "one click, one undo step"
    );
}

#[test]
fn alt_click_picks_the_value_under_the_pointer_as_a_set_brush() {
    use anthesis_maps::brush::BrushMode;
    let mut harness = hard_brush_on_bend(0.25);
    // Paint 0 somewhere, then pick it up with the add brush selected.
    let at = canvas_at(&harness, 0.5, 0.5);
    click(&mut harness, at, 1);
    for _ in 0..10 {
        harness.step();
    }
    let paint = harness.state_mut().paint_mut();
    paint.brush.mode = BrushMode::Add;
    paint.brush.value = 0.7;
    let before = harness.state().project().clone();
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
    for _ in 0..10 {
        harness.step();
    }
    let brush = harness.state_mut().paint_mut().brush;
    assert_eq!(brush.mode, BrushMode::Set);
    assert!(brush.value.abs() < 1e-6, "picked {}", brush.value);
    assert_eq!(harness.state().project(), &before, "picking paints nothing");
}

#[test]
fn the_canvas_shows_the_brush_outline_and_the_legend_of_the_map() {
    let mut harness = hard_brush_on_bend(0.25);
    harness.state_mut().paint_mut().brush.radius_in_uv = 0.1;
    let pos = canvas_at(&harness, 0.35, 0.6);
    harness.hover_at(pos);
    harness.run();
    assert!(
        harness
            .query_by_label_contains("under the pointer (u 0.35, v 0.60)")
            .is_some()
    );
    assert!(
        harness
            .query_by_label_contains("multiplier of the template's bend stiffness")
            .is_some()
    );
    harness.snapshot("paint_canvas_outline_and_legend");
}

#[test]
fn dragging_on_the_direction_map_paints_the_stroke_direction() {
    let mut harness = harness(small_flower());
    harness.run();
    harness.state_mut().paint_mut().target = anthesis_maps::brush::PaintTarget::Direction;
    harness.run();
    stroke_on_canvas(&mut harness, egui::vec2(0.2, 0.5), egui::vec2(0.4, 0.5));
    let keys = harness.state().project().flower.templates[0].maps.keys();
    let d = keys[0].maps.direction.sample(glam::DVec2::new(0.3, 0.5));
    assert!(d.x > 0.2, "painted along +u: {d}");
    let mirrored = keys[0].maps.direction.sample(glam::DVec2::new(0.7, 0.5));
    assert!(mirrored.x < -0.2, "mirrored to -u: {mirrored}");
    // The painted directions as arrows on the 3D organ too.
    feed(&mut harness, None);
    harness.state_mut().view_options_mut().direction_arrows = true;
    harness.run();
    harness.snapshot("app_direction_painting");
}

#[test]
fn the_default_project_is_the_built_in_lily() {
    let lily = anthesis_app::desktop::default_project().expect("a default flower");
    assert!(lily.name.to_lowercase().contains("lily"), "{}", lily.name);
    assert!(lily.flower.organs.len() >= 6);
}

/// A file as the window system hands it over.
#[derive(Debug)]
struct DroppedOnDisk(std::path::PathBuf);

impl egui::DroppedFile for DroppedOnDisk {
    fn path(&self) -> &std::path::Path {
        &self.0
    }

    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

fn drop(harness: &mut Harness<'_, AnthesisApp>, path: &std::path::Path) {
    harness
        .input_mut()
        .dropped_files
        .push(Arc::new(DroppedOnDisk(path.to_path_buf())));
    harness.run();
}

#[test]
fn dropped_maps_meshes_and_projects_are_used_or_refused_with_a_message() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut harness = harness(small_flower());
    harness.run();
    let run = harness.state().session().run();

    // A PNG of the template's map size replaces the map being painted.
    let png = dir.path().join("ramp.png");
    anthesis_maps::ScalarMap::from_fn(32, 32, |uv| uv.y as f32)
        .save_png(&png, anthesis_maps::BitDepth::Sixteen)
        .expect("write png");
    drop(&mut harness, &png);
    let app = harness.state();
    let map = &app.project().flower.templates[0].maps.keys()[0]
        .maps
        .e_growth_in;
    assert!((map.sample(glam::DVec2::new(0.5, 0.9)) - 0.9).abs() < 1e-3);
    assert!(app.session().run() > run, "a new map restarts the run");
    assert_eq!(
        app.document().undo_label(),
        Some("e-growth-in map of petal")
    );

    // The wrong size is refused, the map stays.
    let before = harness.state().project().clone();
    let small = dir.path().join("small.png");
    anthesis_maps::ScalarMap::from_fn(8, 8, |_| 0.5)
        .save_png(&small, anthesis_maps::BitDepth::Eight)
        .expect("write png");
    drop(&mut harness, &small);
    assert_eq!(harness.state().project(), &before);
    let banner = harness.state().log().banner().expect("error shown");
    assert!(
        banner.contains("8x8") && banner.contains("32x32"),
        "{banner}"
    );

    // A mesh without UVs is refused.
    let obj = dir.path().join("flat.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").expect("write obj");
    drop(&mut harness, &obj);
    assert_eq!(harness.state().project(), &before);
    assert!(
        harness
            .state()
            .log()
            .banner()
            .is_some_and(|b| b.contains("flat.obj")),
        "{:?}",
        harness.state().log().banner()
    );

    // A project opens (after the prompt, since the map drop was an edit).
    let project_path = dir.path().join("other.anthesis.toml");
    let mut other = small_flower();
    other.name = "Dropped flower".to_string();
    anthesis_flower::project::save_project(&other, &project_path).expect("save");
    drop(&mut harness, &project_path);
    harness.get_by_label("Don't save").click();
    harness.run();
    assert_eq!(harness.state().project().name, "Dropped flower");
}

#[test]
fn a_dropped_mesh_in_another_unit_is_offered_converted_kept_or_used_as_it_is() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut harness = harness(small_flower());
    harness.run();
    let before = harness.state().project().clone();
    let original = before.flower.templates[0].mesh.clone();
    // The same petal from a tool working in millimetres: ten times larger.
    let mut in_millimetres = original.clone();
    for p in &mut in_millimetres.positions {
        *p *= 10.0;
    }
    let obj = dir.path().join("petal-mm.obj");
    std::fs::write(&obj, anthesis_mesh::obj_string(&in_millimetres)).expect("write obj");
    let length = |mesh: &anthesis_mesh::Mesh| anthesis_flower::scale::organ_length(mesh);

    // Asked first; nothing changes until answered.
    drop(&mut harness, &obj);
    assert!(harness.state().unit_offer().is_some());
    assert_eq!(harness.state().project(), &before);
    harness.get_by_label_contains("10 times too large");

    // Keep the old mesh: nothing changes.
    harness.get_by_label("Keep the old mesh").click();
    harness.run();
    assert!(harness.state().unit_offer().is_none());
    assert_eq!(harness.state().project(), &before);

    // Convert: the petal comes back at its own size, as one undo step.
    drop(&mut harness, &obj);
    harness.get_by_label("Convert (scale by 0.1)").click();
    harness.run();
    let converted = &harness.state().project().flower.templates[0].mesh;
    assert!((length(converted) - length(&original)).abs() < 1e-9 * length(&original));
    assert_eq!(
        harness.state().document().undo_label(),
        Some("mesh of petal")
    );

    // Use as it is: the user knows best.
    drop(&mut harness, &obj);
    harness.get_by_label("Use as it is").click();
    harness.run();
    let used = &harness.state().project().flower.templates[0].mesh;
    assert!((length(used) - 10.0 * length(&original)).abs() < 1e-9 * length(used));
}

/// eframe's key-value store, in memory.
#[derive(Default)]
struct MemoryStorage(std::collections::HashMap<String, String>);

impl eframe::Storage for MemoryStorage {
    fn get_string(&self, key: &str) -> Option<String> {
        self.0.get(key).cloned()
    }

    fn set_string(&mut self, key: &str, value: String) {
        self.0.insert(key.to_string(), value);
    }

    fn remove_string(&mut self, key: &str) {
        self.0.remove(key);
    }

    fn flush(&mut self) {}
}

#[test]
fn the_last_project_and_view_are_remembered_between_launches() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("kept.anthesis.toml");
    let mut kept = small_flower();
    kept.name = "Kept flower".to_string();
    anthesis_flower::project::save_project(&kept, &path).expect("save");

    let mut first = harness(small_flower());
    first.run();
    first.state_mut().open_path(&path);
    first.state_mut().view_options_mut().wireframe = true;
    first.run();
    let mut storage = MemoryStorage::default();
    eframe::App::save(first.state_mut(), &mut storage);

    let storage: &'static MemoryStorage = Box::leak(Box::new(storage));
    let second = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .wgpu()
        .build_eframe(move |cc| {
            cc.storage = Some(storage);
            AnthesisApp::new(
                cc,
                Startup {
                    project: None,
                    live: false,
                    restore: true,
                    warnings: Vec::new(),
                },
            )
            .expect("the app starts")
        });
    let app = second.state();
    assert_eq!(app.project().name, "Kept flower");
    assert_eq!(app.document().path.as_deref(), Some(path.as_path()));
    assert!(app.view_options().wireframe);
}

/// Paint on the 3D organ, the bend map, with the camera aimed at the middle
/// of petal-1 as it is shown now (the viewport's centre).
fn aimed_at_the_middle_of_petal_1(harness: &mut Harness<'_, AnthesisApp>) {
    // Aim the camera at the middle of petal-1 as it is shown now.
    let app = harness.state_mut();
    let template = &app.project().flower.templates[0];
    let middle = template
        .mesh
        .uvs
        .iter()
        .enumerate()
        .min_by(|a, b| {
            let d = |uv: &glam::DVec2| uv.distance(glam::DVec2::new(0.5, 0.6));
            d(a.1).total_cmp(&d(b.1))
        })
        .map(|(i, _)| i)
        .expect("vertices");
    let shown = app
        .session()
        .keyframes()
        .last()
        .expect("keyframes")
        .positions_in_world[0][middle];
    app.camera_mut().target = shown;
    app.camera_mut().distance = 40.0;
    app.paint_mut().on_3d = true;
    app.paint_mut().target =
        anthesis_maps::brush::PaintTarget::Scalar(anthesis_maps::MapKind::Bend);
    harness.run();
    assert_eq!(
        (
            harness.state_mut().camera_mut().distance,
            harness.state_mut().camera_mut().target
        ),
        (40.0, shown),
        "the camera stays where the test put it"
    );
}

#[test]
fn dragging_on_the_3d_organ_in_paint_mode_paints_its_map() {
    let mut harness = opened_small_flower();
    aimed_at_the_middle_of_petal_1(&mut harness);
    let before = harness.state().project().clone();
    let centre = harness.get_by_label("3D viewport").rect().center();
    harness.hover_at(centre);
    harness.run();
    // The brush outline follows the pointer on the organ.
    harness.snapshot("paint_3d_brush_outline");
    harness.drag_at(centre);
    harness.run();
    harness.hover_at(centre + egui::vec2(4.0, 3.0));
    harness.run();
    harness.drop_at(centre + egui::vec2(4.0, 3.0));
    harness.run();
    let app = harness.state();
    assert_ne!(app.project(), &before, "the 3D stroke painted");
    let bend = &app.project().flower.templates[0].maps.keys()[0].maps.bend;
    assert_eq!(bend.size(), (32, 32), "the constant map became a raster");
    assert!(
        app.document()
            .undo_label()
            .is_some_and(|l| l.contains("bend of petal")),
        "{:?}",
        app.document().undo_label()
    );
}

#[test]
fn time_keys_are_added_picked_removed_and_blended_from_the_paint_panel() {
    let mut harness = harness(small_flower());
    harness.run();
    let keys = |h: &Harness<'_, AnthesisApp>| {
        h.state().project().flower.templates[0]
            .maps
            .keys()
            .iter()
            .map(|k| k.step)
            .collect::<Vec<_>>()
    };
    assert_eq!(keys(&harness), vec![40, 50]);
    harness.state_mut().paint_mut().new_key_step = 70;
    harness.run();
    harness.get_by_label("Add key").click();
    harness.run();
    assert_eq!(keys(&harness), vec![40, 50, 70]);
    assert_eq!(
        harness.state_mut().paint_mut().key,
        2,
        "the new key is picked"
    );
    harness.get_by_label("step 40").click();
    harness.run();
    assert_eq!(harness.state_mut().paint_mut().key, 0);
    harness.get_by_label("Remove key").click();
    harness.run();
    assert_eq!(keys(&harness), vec![50, 70]);

    harness.get_by_label("Blend").click();
    harness.run();
    harness.get_by_label("smooth (3s² − 2s³)").click();
    harness.run();
    assert_eq!(
        harness.state().project().flower.templates[0].maps.blend,
        anthesis_maps::Blend::Smooth
    );
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run();
    assert_eq!(
        harness.state().project().flower.templates[0].maps.blend,
        anthesis_maps::Blend::Linear
    );
}

#[test]
fn closing_the_window_with_unsaved_changes_asks_first() {
    let mut harness = harness(small_flower());
    harness.run();
    harness.get_by_label("Add ramp").click();
    harness.run();
    harness
        .input_mut()
        .viewports
        .entry(egui::ViewportId::ROOT)
        .or_default()
        .events
        .push(egui::ViewportEvent::Close);
    harness.step();
    let cancelled = harness
        .output()
        .viewport_output
        .get(&egui::ViewportId::ROOT)
        .is_some_and(|v| v.commands.contains(&egui::ViewportCommand::CancelClose));
    assert!(cancelled, "the close is held back");
    harness.run();
    assert_eq!(harness.state().pending(), Some(&Pending::Quit));
    harness.get_by_label("Cancel").click();
    harness.run();
    assert_eq!(harness.state().pending(), None);
    assert!(
        harness.state().document().is_dirty(),
        "the work is still there"
    );
}

/// The colour of `picture` around `(x, y)`: the mean of the 3x3 pixels
/// there.
fn colour_around(picture: &image::RgbaImage, x: f64, y: f64) -> [f64; 3] {
    let (x, y) = (x.round() as i64, y.round() as i64);
    let mut sum = [0.0; 3];
    for dy in -1..=1 {
        for dx in -1..=1 {
            let p = picture.get_pixel((x + dx) as u32, (y + dy) as u32);
            for (s, c) in sum.iter_mut().zip(p.0) {
                *s += f64::from(c) / 9.0;
            }
        }
    }
    sum
}

/// Where `point` lands in an image of `width x height` pixels.
fn pixel_of(
    camera: &anthesis_render::Camera,
    point: glam::DVec3,
    width: f64,
    height: f64,
) -> (f64, f64) {
    let clip = camera.view_projection((width / height) as f32) * point.as_vec3().extend(1.0);
    let ndc = clip.truncate() / clip.w;
    (
        (f64::from(ndc.x) + 1.0) * 0.5 * width,
        (1.0 - f64::from(ndc.y)) * 0.5 * height,
    )
}

#[test]
fn the_window_and_anthesis_render_show_an_organ_in_the_same_colour() {
    // Project colours are linear; both paths hand them to the renderer,
    // which encodes once. A saturated orange, where a missing or a double
    // conversion shows most.
    let mut project = anthesis_sim::fixtures::whorl(2, 8, 14, 4);
    project.flower.templates[0].colour = [0.8, 0.3, 0.05, 1.0];
    let (azimuth_deg, elevation_deg) = (project.flower.organs[0].placement.azimuth_deg, 20.0);
    let bud = anthesis_sim::Simulation::new(&project, &Selection::All)
        .expect("simulation")
        .bud();
    let all: Vec<glam::DVec3> = bud.positions_in_world.iter().flatten().copied().collect();
    let bounds = all
        .iter()
        .fold((all[0], all[0]), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    // The middle of organ 0 (the window highlights the selected organ, so
    // organ 1 is selected; from organ 0's azimuth it is behind organ 0).
    let template = &project.flower.templates[0];
    let middle = (0..template.mesh.vertex_count())
        .min_by(|&a, &b| {
            let d = |i: usize| template.mesh.uvs[i].distance(glam::DVec2::new(0.5, 0.5));
            d(a).total_cmp(&d(b))
        })
        .expect("vertices");
    let point = bud.positions_in_world[0][middle];

    // The command line.
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("orange.anthesis.toml");
    anthesis_flower::project::save_project(&project, &path).expect("save");
    let out = common::anthesis(&[
        "render",
        path.to_str().expect("utf-8"),
        "--frames",
        "0",
        "--out",
        dir.path().to_str().expect("utf-8"),
        "--size",
        "320x240",
        "--azimuth",
        &azimuth_deg.to_string(),
        "--elevation",
        &elevation_deg.to_string(),
    ]);
    assert!(out.status.success(), "{}", common::text(&out.stderr));
    let picture = image::open(dir.path().join("frame-000.png"))
        .expect("the picture")
        .to_rgba8();
    let camera = anthesis_render::Camera::framing(bounds.0, bounds.1, azimuth_deg, elevation_deg);
    let (x, y) = pixel_of(&camera, point, 320.0, 240.0);
    let from_command_line = colour_around(&picture, x, y);

    // The window, showing the same bud from the same direction.
    let mut harness = harness(project);
    harness.run();
    let app = harness.state_mut();
    app.select_organ(1);
    let run = app.session().run();
    let mut failures = Vec::new();
    let session = app.session_mut();
    session.accept(
        Event::Started {
            run,
            organs: Vec::new(),
            keyframes: 4,
            first_computed: 1,
            proxy: false,
        },
        &mut failures,
    );
    session.accept(
        Event::Keyframe {
            run,
            keyframe: Arc::new(bud),
        },
        &mut failures,
    );
    assert!(failures.is_empty());
    harness.run();
    let camera = harness.state_mut().camera_mut();
    camera.azimuth_deg = azimuth_deg;
    camera.elevation_deg = elevation_deg;
    camera.frame(bounds);
    let camera = camera.camera();
    harness.run();
    let viewport = harness.get_by_label("3D viewport").rect();
    let scale = f64::from(harness.ctx.pixels_per_point());
    let screen = harness.render().expect("the window renders");
    let (width, height) = (
        f64::from(viewport.width()) * scale,
        f64::from(viewport.height()) * scale,
    );
    let (x, y) = pixel_of(&camera, point, width, height);
    let in_window = colour_around(
        &screen,
        f64::from(viewport.min.x) * scale + x,
        f64::from(viewport.min.y) * scale + y,
    );

    assert!(
        from_command_line[0] > from_command_line[2] + 60.0,
        "the command line's pixel {from_command_line:?} is not the orange organ"
    );
    for channel in 0..3 {
        assert!(
            (from_command_line[channel] - in_window[channel]).abs() <= 6.0,
            "window {in_window:?}, command line {from_command_line:?}"
        );
    }
}

#[test]
fn edits_applied_as_commands_are_undone_and_redone_by_the_undo_and_redo_commands() {
    use anthesis_app::desktop::{Command, ProjectEdit};
    let mut harness = harness(small_flower());
    harness.run();
    let original = harness.state().project().clone();
    let mut thicker = original.flower.templates[0].clone();
    thicker.thickness *= 2.0;
    let edits = [
        ProjectEdit::Template {
            template: 0,
            value: Box::new(thicker),
            keyframes: original.settings.keyframes + 1,
        },
        ProjectEdit::Blend {
            template: 0,
            blend: anthesis_maps::Blend::Smooth,
        },
        ProjectEdit::RemoveKey {
            template: 0,
            key: 0,
        },
    ];
    let app = harness.state_mut();
    let run = app.session().run();
    for (i, edit) in edits.into_iter().enumerate() {
        app.apply(anthesis_app::desktop::Command::Edit {
            label: format!("edit {i}"),
            edit,
        });
    }
    harness.run();
    assert!(
        harness.state().session().run() > run,
        "the edits restarted the run"
    );
    let app = harness.state_mut();
    let edited = app.project().clone();
    assert_ne!(edited, original);
    assert_eq!(app.document().undo_label(), Some("edit 2"));
    for _ in 0..3 {
        app.apply(Command::Undo);
    }
    assert_eq!(
        app.project(),
        &original,
        "three undos give the project back"
    );
    assert!(!app.document().is_dirty());
    for _ in 0..3 {
        app.apply(Command::Redo);
    }
    assert_eq!(app.project(), &edited);
    harness.run();
    assert_eq!(harness.state().project(), &edited);
}

#[test]
fn preview_and_selection_commands_choose_what_the_next_run_simulates() {
    use anthesis_app::desktop::Command;
    let mut harness = harness(small_flower());
    harness.run();
    let run = harness.state().session().run();
    harness.state_mut().apply(Command::SelectOrgan(3));
    harness
        .state_mut()
        .apply(Command::SetSingleOrganPreview(true));
    harness.run();
    let app = harness.state();
    assert_eq!(app.selection(), Selection::Only(3));
    assert!(app.session().run() > run);
    assert_eq!(app.session().organs(), &[3]);
    // An organ that does not exist is not selected.
    harness.state_mut().apply(Command::SelectOrgan(99));
    assert_eq!(harness.state().selected_organ(), 3);
}

#[test]
fn orbiting_the_camera_keeps_the_scene_and_a_new_keyframe_or_edit_rebuilds_it() {
    use anthesis_app::desktop::Command;
    let mut harness = opened_small_flower();
    let built = harness.state().scene_rebuilds();
    let camera = *harness.state_mut().camera_mut();
    // Orbit: drag across the viewport over many frames.
    let centre = harness.get_by_label("3D viewport").rect().center();
    harness.hover_at(centre);
    harness.run();
    harness.drag_at(centre);
    harness.run();
    for i in 1..=10 {
        harness.hover_at(centre + egui::vec2(8.0 * i as f32, 2.0 * i as f32));
        harness.run();
    }
    harness.drop_at(centre + egui::vec2(80.0, 20.0));
    harness.run();
    assert_ne!(
        *harness.state_mut().camera_mut(),
        camera,
        "the camera turned"
    );
    assert_eq!(
        harness.state().scene_rebuilds(),
        built,
        "turning the camera rebuilt the scene"
    );
    // A step in time shows another keyframe: one rebuild.
    harness.state_mut().apply(Command::StepKeyframe(-1));
    harness.run();
    assert_eq!(harness.state().scene_rebuilds(), built + 1);
    // A new overlay: one more.
    let mut view = *harness.state().view_options();
    view.overlay = Some(anthesis_maps::MapKind::Bend);
    harness.state_mut().apply(Command::SetView(view));
    harness.run();
    assert_eq!(harness.state().scene_rebuilds(), built + 2);
    // The wireframe is drawn over the scene: no rebuild.
    view.wireframe = true;
    harness.state_mut().apply(Command::SetView(view));
    harness.run();
    assert_eq!(harness.state().scene_rebuilds(), built + 2);
}

#[test]
fn the_resolution_control_remeshes_reruns_and_undoes() {
    use anthesis_app::desktop::{Command, ProjectEdit};
    use anthesis_flower::Resolution;
    let project = small_flower();
    let built = project.flower.templates[0].mesh.vertex_count();
    let built_edge = anthesis_bud::quality(&project.flower.templates[0].mesh).mean_edge;
    let mut harness = harness(project);
    harness.run();
    let run = harness.state().session().run();
    // Each template's organs and their particles, as built.
    assert!(
        harness
            .query_all_by_label(&format!("{built} particles"))
            .count()
            >= 1
    );
    // (The panel's own click is tested on the panel alone below: here the
    // checkbox sits below the fold of the organs panel's scroll area.)
    harness.state_mut().apply(Command::Edit {
        label: "resolution".to_string(),
        edit: ProjectEdit::Resolution(Resolution::MeanEdge(built_edge)),
    });
    harness.run();
    let resolution = harness.state().project().settings.resolution;
    let edge = resolution
        .mean_edge()
        .unwrap_or_else(|| panic!("not remeshed; log: {:?}", harness.state().log().entries()));
    assert!(
        (edge - built_edge).abs() < 0.01 * built_edge,
        "{edge} vs {built_edge}"
    );
    assert!(harness.state().session().run() > run, "the change re-runs");
    // Half the edge: about four times the particles, shown per organ.
    harness.state_mut().apply(Command::Edit {
        label: "resolution".to_string(),
        edit: ProjectEdit::Resolution(Resolution::MeanEdge(edge / 2.0)),
    });
    harness.run();
    let shown = harness.state_mut().resolved_project();
    let fine = shown.flower.templates[0].mesh.vertex_count();
    assert!(fine > 3 * built && fine < 5 * built, "{fine} vs {built}");
    assert!(
        harness
            .query_all_by_label(&format!("{fine} particles"))
            .count()
            >= 1
    );
    // The document keeps the meshes as built.
    assert_eq!(
        harness.state().project().flower.templates[0]
            .mesh
            .vertex_count(),
        built
    );
    // Undo: the two changes made without the pointer let go are one step,
    // as a drag of the value is.
    harness.state_mut().apply(Command::Undo);
    harness.run();
    assert_eq!(
        harness.state().project().settings.resolution,
        Resolution::AsBuilt
    );
    assert_eq!(
        harness.state_mut().resolved_project().flower.templates[0]
            .mesh
            .vertex_count(),
        built
    );
    // A tiny edge is refused with the memory estimate's message, nothing
    // changes.
    harness.state_mut().apply(Command::Edit {
        label: "resolution".to_string(),
        edit: ProjectEdit::Resolution(Resolution::MeanEdge(edge / 1000.0)),
    });
    harness.run();
    assert_eq!(
        harness.state().project().settings.resolution,
        Resolution::AsBuilt
    );
    let banner = harness.state().log().banner().expect("an error is shown");
    assert!(
        banner.starts_with("the resolution stays as it was: this run needs about"),
        "{banner}"
    );
}

/// The parameters panel alone for template 0 of `project`, `height`
/// points tall, and the commands it queues.
#[allow(clippy::type_complexity)]
fn parameters_panel(
    project: Project,
    resolved: Project,
    height: f32,
) -> (
    Harness<'static>,
    std::rc::Rc<std::cell::RefCell<Vec<anthesis_app::desktop::command::Command>>>,
) {
    let chosen = std::rc::Rc::new(std::cell::RefCell::new(Vec::new()));
    let sink = std::rc::Rc::clone(&chosen);
    let harness = Harness::builder()
        .with_size(egui::vec2(300.0, height))
        .wgpu()
        .build_ui(move |ui| {
            sink.borrow_mut()
                .extend(anthesis_app::desktop::params::parameters_ui(
                    ui, &project, &resolved, 0,
                ));
        });
    (harness, chosen)
}

#[test]
fn the_parameters_panel_with_a_resolution() {
    use anthesis_flower::Resolution;
    let mut project = small_flower();
    let edge = anthesis_bud::quality(&project.flower.templates[0].mesh).mean_edge;
    project.settings.resolution = Resolution::MeanEdge((edge * 0.6 * 100.0).round() / 100.0);
    let resolved = anthesis_flower::resolution::resolve(&project).expect("remeshes");
    let (mut harness, chosen) = parameters_panel(project, resolved, 560.0);
    harness.run();
    let particles = harness.query_all_by_label_contains(" particles").count();
    assert_eq!(particles, 2, "one row per template");
    harness.snapshot("parameters_resolution");
    // Unticking goes back to the meshes as built, as an undoable edit.
    harness.get_by_label("Mesh detail (mean edge)").click();
    harness.run();
    let edits: Vec<String> = chosen.borrow().iter().map(|c| format!("{c:?}")).collect();
    assert!(
        edits.iter().any(|e| e.contains("Resolution(AsBuilt)")),
        "{edits:?}"
    );
}

#[test]
fn a_typed_resolution_is_one_edit_when_entered_not_one_per_key() {
    // Typing 0.5 passed through 0, which the field clamped to its
    // smallest edge and applied as a resolution: the remesh was refused
    // for its memory, and the value typed never arrived.
    use anthesis_flower::Resolution;
    let mut project = small_flower();
    let edge = anthesis_bud::quality(&project.flower.templates[0].mesh).mean_edge;
    project.settings.resolution = Resolution::MeanEdge((edge * 100.0).round() / 100.0);
    let resolved = anthesis_flower::resolution::resolve(&project).expect("remeshes");
    let (mut harness, chosen) = parameters_panel(project, resolved, 560.0);
    harness.run();
    let row = harness
        .get_by_label("Mesh detail (mean edge)")
        .rect()
        .center()
        .y;
    fn field<'h>(harness: &'h Harness<'static>, row: f32) -> egui_kittest::Node<'h> {
        harness
            .get_all_by_role(egui::accesskit::Role::SpinButton)
            .find(|n| (n.rect().center().y - row).abs() < 8.0)
            .expect("the edge field beside the checkbox")
    }
    field(&harness, row).click();
    harness.run();
    let resolutions = |chosen: &std::cell::RefCell<Vec<_>>| -> Vec<String> {
        chosen
            .borrow()
            .iter()
            .map(|c| format!("{c:?}"))
            .filter(|c| c.contains("Resolution("))
            .collect()
    };
    for text in ["0", ".", "5"] {
        field(&harness, row).type_text(text);
        harness.run();
        assert_eq!(resolutions(&chosen), Vec::<String>::new(), "after {text:?}");
    }
    harness.key_press(egui::Key::Enter);
    harness.run();
    let edits = resolutions(&chosen);
    assert_eq!(edits.len(), 1, "{edits:?}");
    assert!(edits[0].contains("Resolution(MeanEdge(0.5))"), "{edits:?}");
}

/// The window on the small flower, then File → Open of `project` saved as
/// `name` in a temporary folder (kept alive by the returned guard); checks
/// it became the document.
fn open_saved(project: &Project, name: &str) -> (Harness<'static, AnthesisApp>, tempfile::TempDir) {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join(name);
    anthesis_flower::project::save_project(project, &path).expect("save");
    let mut harness = harness(small_flower());
    harness.run();
    harness.state_mut().open_path(&path);
    harness.run();
    assert_eq!(
        harness.state().document().path.as_deref(),
        Some(path.as_path())
    );
    (harness, dir)
}

#[test]
fn opening_a_project_with_a_mesh_in_another_unit_warns_and_keeps_it_open() {
    let mut project = small_flower();
    for p in &mut project.flower.templates[0].mesh.positions {
        *p *= 100.0;
    }
    let (harness, _dir) = open_saved(&project, "mm.anthesis.toml");
    let app = harness.state();
    let warning = app
        .log()
        .entries()
        .iter()
        .find(|e| e.message.contains("times too large, perhaps made in"))
        .expect("a warning names the unit");
    assert!(
        warning.message.ends_with("the simulation will likely fail"),
        "{}",
        warning.message
    );
}

#[test]
fn a_project_given_at_launch_shows_what_loading_read_past_in_the_log() {
    let warning = "template `petal`: the mesh's inner side faces +Z".to_string();
    let harness = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .wgpu()
        .build_eframe({
            let warning = warning.clone();
            move |cc| {
                AnthesisApp::new(
                    cc,
                    Startup {
                        project: Some((small_flower(), None)),
                        live: false,
                        restore: false,
                        warnings: vec![warning],
                    },
                )
                .expect("the app starts")
            }
        });
    let entries = harness.state().log().entries();
    assert!(
        entries
            .iter()
            .any(|e| e.message == warning && e.level == anthesis_app::desktop::log::Level::Warning),
        "{entries:?}"
    );
}

#[test]
fn opening_a_project_shows_what_loading_read_past() {
    // A mesh from another tool wound inside out: it loads, and the log
    // says so (the loader's warnings were dropped).
    let mut project = small_flower();
    project.flower.templates[0].mesh =
        anthesis_bud::with_inner_side_flipped(&project.flower.templates[0].mesh);
    let (harness, _dir) = open_saved(&project, "flipped.anthesis.toml");
    let app = harness.state();
    let warnings: Vec<&str> = app
        .log()
        .entries()
        .iter()
        .filter(|e| e.message.contains("the inner side faces +Z"))
        .map(|e| e.message.as_str())
        .collect();
    assert_eq!(warnings.len(), 1, "{:?}", app.log().entries());
    assert!(
        warnings[0].contains("reverse the faces' winding"),
        "{}",
        warnings[0]
    );
}

/// Queues `events` for the next frame, all in that one frame.
fn in_one_frame(harness: &mut Harness<'_, AnthesisApp>, events: Vec<egui::Event>) {
    harness.input_mut().events.extend(events);
    harness.step();
}

fn press(key: egui::Key, modifiers: egui::Modifiers) -> egui::Event {
    egui::Event::Key {
        key,
        physical_key: None,
        pressed: true,
        repeat: false,
        modifiers,
    }
}

#[test]
fn five_key_presses_in_one_frame_are_five_steps() {
    let mut harness = opened_small_flower();
    harness.key_press(egui::Key::Home);
    harness.run();
    assert_eq!(harness.state().playback().time_in_keyframes, 0.0);
    let right = press(egui::Key::ArrowRight, egui::Modifiers::NONE);
    in_one_frame(&mut harness, vec![right; 5]);
    harness.run();
    assert_eq!(harness.state().playback().time_in_keyframes, 5.0);
    let left = press(egui::Key::ArrowLeft, egui::Modifiers::NONE);
    in_one_frame(&mut harness, vec![left; 3]);
    assert_eq!(harness.state().playback().time_in_keyframes, 2.0);
}

#[test]
fn a_brush_setting_is_a_command_and_not_an_undo_step() {
    use anthesis_maps::brush::BrushMode;
    let mut harness = opened_small_flower();
    let mut brush = harness.state_mut().paint_mut().brush;
    brush.strength = 0.25;
    brush.mode = BrushMode::Smooth;
    brush.mirror = !brush.mirror;
    let label = harness.state().document().undo_label().map(str::to_owned);
    harness
        .state_mut()
        .apply(anthesis_app::desktop::Command::SetBrush(brush));
    harness.run();
    assert_eq!(harness.state_mut().paint_mut().brush, brush);
    assert_eq!(
        harness.state().document().undo_label().map(str::to_owned),
        label,
        "not an undo step"
    );
}

#[test]
fn bracket_keys_change_the_brush_on_every_layout_and_x_swaps_add_and_subtract() {
    use anthesis_maps::brush::BrushMode;
    let mut harness = opened_small_flower();
    let radius = harness.state_mut().paint_mut().brush.radius_in_uv;
    let none = egui::Modifiers::NONE;
    let shift = egui::Modifiers::SHIFT;
    in_one_frame(&mut harness, vec![press(egui::Key::CloseBracket, none); 3]);
    let larger = harness.state_mut().paint_mut().brush.radius_in_uv;
    assert!(
        (larger - radius * 1.25f64.powi(3)).abs() < 1e-9,
        "3 × ] in one frame: {radius} -> {larger}"
    );
    harness.key_press(egui::Key::OpenBracket);
    harness.run();
    let smaller = harness.state_mut().paint_mut().brush.radius_in_uv;
    assert!((smaller - radius * 1.25f64.powi(2)).abs() < 1e-9);

    harness.state_mut().paint_mut().brush.strength = 0.5;
    // Shift+[ as a US layout reports it ('{' with Shift), as a layout that
    // keeps '[' reports it, and Shift+] both ways: each press counts.
    in_one_frame(
        &mut harness,
        vec![
            press(egui::Key::OpenCurlyBracket, shift),
            press(egui::Key::OpenBracket, shift),
            press(egui::Key::OpenCurlyBracket, shift),
        ],
    );
    let strength = harness.state_mut().paint_mut().brush.strength;
    assert!((strength - 0.2).abs() < 1e-6, "strength {strength}");
    assert!(
        (harness.state_mut().paint_mut().brush.radius_in_uv - smaller).abs() < 1e-12,
        "Shift+[ is not [",
    );
    in_one_frame(
        &mut harness,
        vec![
            press(egui::Key::CloseCurlyBracket, shift),
            press(egui::Key::CloseBracket, shift),
        ],
    );
    let strength = harness.state_mut().paint_mut().brush.strength;
    assert!((strength - 0.4).abs() < 1e-6, "strength {strength}");

    harness.state_mut().paint_mut().brush.mode = BrushMode::Add;
    harness.key_press(egui::Key::X);
    harness.run();
    assert_eq!(
        harness.state_mut().paint_mut().brush.mode,
        BrushMode::Subtract
    );
    harness.key_press(egui::Key::X);
    harness.run();
    assert_eq!(harness.state_mut().paint_mut().brush.mode, BrushMode::Add);
}

#[test]
fn shortcuts_do_not_fire_while_a_text_field_has_the_keyboard() {
    let mut harness = opened_small_flower();
    harness.state_mut().open_export();
    harness.run();
    harness.get_by_label("Export to").click();
    harness.run();
    let radius = harness.state_mut().paint_mut().brush.radius_in_uv;
    let time = harness.state().playback().time_in_keyframes;
    harness.key_press(egui::Key::OpenBracket);
    harness.key_press(egui::Key::ArrowLeft);
    harness.key_press(egui::Key::X);
    harness.run();
    assert_eq!(harness.state_mut().paint_mut().brush.radius_in_uv, radius);
    assert_eq!(harness.state().playback().time_in_keyframes, time);
}

#[test]
fn the_history_window_lists_the_steps_and_a_click_goes_back_or_forwards() {
    let mut harness = opened_small_flower();
    for (label, dg) in [
        ("first change", 0.011),
        ("second change", 0.012),
        ("third change", 0.013),
    ] {
        let mut template = harness.state().project().flower.templates[0].clone();
        template.dg = dg;
        let keyframes = harness.state().project().settings.keyframes;
        let app = harness.state_mut();
        app.apply(anthesis_app::desktop::Command::Edit {
            label: label.to_string(),
            edit: anthesis_app::desktop::ProjectEdit::Template {
                template: 0,
                value: Box::new(template),
                keyframes,
            },
        });
    }
    harness.get_by_label("View").click();
    harness.run();
    harness.get_by_label("Undo history  (H)").click();
    harness.run();
    harness.get_by_label("third change");
    harness.snapshot("history_window");
    harness.get_by_label("first change").click();
    harness.run();
    assert_eq!(harness.state().document().history_position(), 1);
    assert_eq!(harness.state().project().flower.templates[0].dg, 0.011);
    // The undone steps stay listed: a click redoes up to one.
    harness.get_by_label("third change").click();
    harness.run();
    assert_eq!(harness.state().document().history_position(), 3);
    assert_eq!(harness.state().project().flower.templates[0].dg, 0.013);
    harness.get_by_label("Opened").click();
    harness.run();
    assert_eq!(harness.state().document().history_position(), 0);
    assert!(!harness.state().document().is_dirty());
}

#[test]
fn help_shortcuts_lists_every_shortcut() {
    let mut harness = opened_small_flower();
    harness.get_by_label("Help").click();
    harness.run();
    harness.get_by_label("Shortcuts").click();
    harness.run();
    for keys in [
        "Ctrl+Z",
        "Ctrl+Shift+Z",
        "[",
        "]",
        "Shift+[",
        "Shift+]",
        "X",
        "Right",
    ] {
        harness.get_by_label(keys);
    }
    harness.get_by_label("Brush to subtract from add, else to add");
    harness.snapshot("shortcuts_window");
}

/// How far out the shown flower reaches in the viewport (a fraction of
/// the way to the middle of its shorter side).
fn reach_of_shown_flower(harness: &mut Harness<'_, AnthesisApp>) -> f64 {
    let app = harness.state();
    let shows_others = app.view_options().show_others || !app.single_organ_preview();
    let scene = anthesis_app::desktop::viewport::build_scene(
        app.project(),
        app.session(),
        app.playback().time_in_keyframes,
        shows_others,
    );
    let points: Vec<glam::DVec3> = scene
        .iter()
        .flat_map(|o| o.positions_in_world.iter().copied())
        .collect();
    assert!(!points.is_empty(), "a flower is shown");
    harness.state_mut().camera_mut().reach_in_image(&points)
}

#[test]
fn the_camera_frames_the_flower_at_launch_on_a_preview_switch_and_on_new() {
    let mut harness = opened_small_flower();
    let reach = reach_of_shown_flower(&mut harness);
    assert!((0.6..=0.9).contains(&reach), "at launch: {reach}");
    // Zoomed far out by hand, then the preview switched on: framed on
    // the one organ when its keyframes arrive.
    harness.state_mut().camera_mut().distance *= 5.0;
    harness.key_press(egui::Key::P);
    harness.run();
    assert!(harness.state().single_organ_preview());
    feed(&mut harness, None);
    harness.run();
    let reach = reach_of_shown_flower(&mut harness);
    assert!((0.6..=0.9).contains(&reach), "single organ: {reach}");
    // And back to the whole flower.
    harness.state_mut().camera_mut().distance *= 0.2;
    harness.key_press(egui::Key::P);
    harness.run();
    feed(&mut harness, None);
    harness.run();
    let reach = reach_of_shown_flower(&mut harness);
    assert!((0.6..=0.9).contains(&reach), "whole flower again: {reach}");
    // File → New, the lily: framed.
    harness.state_mut().camera_mut().distance *= 7.0;
    harness
        .state_mut()
        .apply(anthesis_app::desktop::Command::NewFrom("lily".into()));
    harness.run();
    feed(&mut harness, Some(0));
    harness.run();
    let reach = reach_of_shown_flower(&mut harness);
    assert!((0.6..=0.9).contains(&reach), "new project's bud: {reach}");
}

/// A double click on the widget labelled `label`, in one frame.
fn double_click(harness: &mut Harness<'_, AnthesisApp>, label: &str) {
    let pos = harness.get_by_label(label).rect().center();
    let mut events = vec![egui::Event::PointerMoved(pos)];
    for pressed in [true, false, true, false] {
        events.push(egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        });
    }
    in_one_frame(harness, events);
}

/// Runs frames until a widget labelled `label` is shown (the file browser
/// lists a folder it enters a frame or more later; under load, later).
fn wait_for_label(harness: &mut Harness<'_, AnthesisApp>, label: &str) {
    for _ in 0..200 {
        harness.run();
        if harness.query_by_label(label).is_some() {
            return;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    panic!("\"{label}\" was not shown");
}

/// The app on `project` saved at `path`, using the in-app file browser.
fn harness_with_file_browser(path: &std::path::Path) -> Harness<'static, AnthesisApp> {
    let project = small_flower();
    anthesis_flower::project::save_project(&project, path).expect("saves");
    let path = path.to_path_buf();
    // egui_file titles its window and its icons with characters (📂, 🗀,
    // ⬆) that egui's monochrome emoji font draws (the app enables it): no
    // missing glyphs are allowed, so an icon drawn as a box fails here. Its
    // path and file-name fields have no accessible name (egui_file's).
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .with_accessibility_check(false)
        .wgpu()
        .build_eframe(move |cc| {
            let mut app = AnthesisApp::new(
                cc,
                Startup {
                    project: Some((project, Some(path))),
                    live: false,
                    restore: false,
                    warnings: Vec::new(),
                },
            )
            .expect("the app starts");
            app.use_in_app_file_browser();
            app
        });
    harness.run();
    feed(&mut harness, None);
    harness.run();
    harness
}

#[test]
fn the_in_app_file_browser_navigates_filters_and_opens_saves_and_exports() {
    // A fixed folder: the browser shows its path, and the snapshot with it.
    let root = std::path::Path::new("/tmp/anthesis-file-browser-test");
    let _ = std::fs::remove_dir_all(root);
    let sub = root.join("other flowers");
    std::fs::create_dir_all(&sub).expect("folders");
    std::fs::write(root.join("notes.txt"), "not a project").expect("write");
    let mut harness = harness_with_file_browser(&root.join("mine.anthesis.toml"));
    anthesis_flower::project::save_project(&small_flower(), &sub.join("theirs.anthesis.toml"))
        .expect("saves");

    // Open: the project's folder, projects and folders only.
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::O);
    harness.run();
    harness.get_by_label("🗀 other flowers");
    harness.get_by_label("🗋 mine.anthesis.toml");
    assert!(
        harness.query_by_label("🗋 notes.txt").is_none(),
        "filtered out"
    );
    harness.snapshot("file_browser_open");
    // Into the folder, up again, into it again and pick the project there.
    double_click(&mut harness, "🗀 other flowers");
    wait_for_label(&mut harness, "🗋 theirs.anthesis.toml");
    harness.get_by_label("⬆").click();
    wait_for_label(&mut harness, "🗀 other flowers");
    double_click(&mut harness, "🗀 other flowers");
    wait_for_label(&mut harness, "🗋 theirs.anthesis.toml");
    harness.get_by_label("🗋 theirs.anthesis.toml").click();
    harness.run();
    harness.get_by_label("Open").click();
    harness.run();
    assert_eq!(
        harness.state().document().path.as_deref(),
        Some(sub.join("theirs.anthesis.toml").as_path()),
        "the pick became FileChosen, which opened it"
    );

    // Save as: the suggested name in the project's folder.
    harness.key_press_modifiers(
        egui::Modifiers::COMMAND | egui::Modifiers::SHIFT,
        egui::Key::S,
    );
    harness.run();
    harness.get_by_label("Save").click();
    harness.run();
    assert!(sub.join("flower.anthesis.toml").is_file(), "saved");
    assert_eq!(
        harness.state().document().path.as_deref(),
        Some(sub.join("flower.anthesis.toml").as_path())
    );

    // Export → Browse…: the path goes into the export dialog; Cancel
    // leaves it.
    harness.state_mut().open_export();
    harness.run();
    harness.get_by_label("Browse…").click();
    harness.run();
    harness.get_by_label("Save").click();
    harness.run();
    // The name the export dialog's field proposed, from the project's name.
    let named = anthesis_app::desktop::files::default_file_name(&harness.state().project().name);
    assert_eq!(
        harness.state().export_dialog().path,
        sub.join(&named).display().to_string()
    );
    harness.get_by_label("Browse…").click();
    harness.run();
    harness.get_by_label("Cancel").click();
    harness.run();
    assert_eq!(
        harness.state().export_dialog().path,
        sub.join(&named).display().to_string()
    );
    let _ = std::fs::remove_dir_all(root);
}

/// Scrolls the widget labelled `label` into view and clicks it (the
/// parameters panel is taller than the window).
fn click_in_view(harness: &mut Harness<'_, AnthesisApp>, label: &str) {
    harness.get_by_label(label).scroll_to_me();
    harness.run();
    harness.get_by_label(label).click();
    harness.run();
}

#[test]
fn parts_are_added_edited_and_removed_from_the_flower_panel_with_undo() {
    let mut harness = opened_small_flower();
    harness.get_by_label("Flower").click();
    harness.run();
    let first_run = harness.state().session().run();
    assert!(harness.state().project().flower.parts.is_empty());

    click_in_view(&mut harness, "Add stamens");
    let app = harness.state();
    let parts = &app.project().flower.parts;
    assert_eq!(parts.len(), 1);
    assert_eq!(parts[0].name, "stamen");
    assert_eq!(parts[0].count, 5);
    assert!(app.session().run() > first_run, "a part restarts the run");
    let after_add = app.session().run();

    click_in_view(&mut harness, "Add pistil");
    assert_eq!(harness.state().project().flower.parts.len(), 2);
    // The new part's parameters: open it and change its count.
    click_in_view(&mut harness, "stamen “stamen” × 5");
    click_in_view(&mut harness, "count");
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness.get_by_label("count").type_text("7");
    harness.run();
    harness.key_press(egui::Key::Enter);
    harness.run();
    let app = harness.state();
    assert_eq!(app.project().flower.parts[0].count, 7);
    assert!(app.session().run() > after_add);
    assert!(
        app.document()
            .undo_label()
            .is_some_and(|l| l.contains("count of stamen")),
        "{:?}",
        app.document().undo_label()
    );

    harness.snapshot("parts_panel");

    // Undo the count and the pistil; the stamens stay.
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run();
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run();
    let parts = &harness.state().project().flower.parts;
    assert_eq!(parts.len(), 1);
    assert_eq!(parts[0].count, 5);

    click_in_view(&mut harness, "Remove part");
    assert!(harness.state().project().flower.parts.is_empty());
}

#[test]
fn painting_the_colour_target_paints_the_colour_map_shows_its_colours_and_undoes() {
    use anthesis_maps::brush::{Brush, BrushMode, PaintTarget};
    let mut harness = opened_small_flower();
    let before = harness.state().project().clone();
    assert_eq!(before.flower.templates[0].colouring, None);
    let paint = harness.state_mut().paint_mut();
    paint.target = PaintTarget::Colour;
    paint.brush = Brush {
        mode: BrushMode::Set,
        radius_in_uv: 0.08,
        strength: 1.0,
        hardness: 1.0,
        value: 1.0,
        mirror: false,
    };
    harness.run();
    stroke_on_canvas(&mut harness, egui::vec2(0.3, 0.3), egui::vec2(0.3, 0.7));
    let app = harness.state();
    let colouring = app.project().flower.templates[0]
        .colouring
        .as_ref()
        .expect("the stroke made a colour map");
    assert_eq!(
        colouring.second_colour,
        anthesis_flower::DEFAULT_SECOND_COLOUR
    );
    assert_eq!(
        colouring.mix.size(),
        (
            anthesis_flower::COLOUR_PAINT_SIZE,
            anthesis_flower::COLOUR_PAINT_SIZE
        )
    );
    // Canvas (0.3, 0.5) is u 0.3, v 0.5: painted; the other side is not.
    assert!(colouring.mix.sample(glam::DVec2::new(0.3, 0.5)) > 0.9);
    assert_eq!(colouring.mix.sample(glam::DVec2::new(0.8, 0.5)), 0.0);
    // The growth maps are untouched (and `anthesis_sim::resume` keeps
    // every computed keyframe: colours are not simulated).
    assert_eq!(
        app.project().flower.templates[0].maps,
        before.flower.templates[0].maps
    );
    assert!(
        harness
            .query_by_label_contains("0 = the base colour, 1 = the second colour")
            .is_some()
    );
    harness.get_by_label("Clear").click();
    harness.hover_at(egui::pos2(600.0, 300.0));
    harness.run();
    harness.snapshot("paint_colour_target");

    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run();
    assert_eq!(harness.state().project(), &before, "one stroke, one undo");
}

#[test]
fn the_parameters_panel_picks_the_base_and_second_colours() {
    let mut project = small_flower();
    project.flower.templates[0].colouring = Some(anthesis_flower::Colouring {
        second_colour: [0.45, 0.02, 0.06, 1.0],
        mix: anthesis_maps::ScalarMap::from_fn(16, 16, |uv| uv.y as f32),
        layers: Vec::new(),
    });
    let resolved = project.clone();
    let (mut harness, chosen) = parameters_panel(project, resolved, 760.0);
    harness.run();
    assert!(harness.query_by_label("base colour").is_some());
    assert!(harness.query_by_label("second colour").is_some());
    harness.snapshot("parameters_colours");
    // Removing the colour map is one undoable edit of the template.
    harness.get_by_label("Remove colour map").click();
    harness.run();
    let edits: Vec<String> = chosen.borrow().iter().map(|c| format!("{c:?}")).collect();
    assert!(
        edits
            .iter()
            .any(|e| e.contains("colour map of") && e.contains("colouring: None")),
        "{edits:?}"
    );
}

#[test]
fn alt_click_on_the_3d_organ_picks_the_value_under_the_pointer() {
    use anthesis_maps::brush::BrushMode;
    // A bend map of 0.37 everywhere on petal-1's template.
    let mut project = small_flower();
    project.flower.templates[0].maps.keys_mut()[0].maps.bend =
        anthesis_maps::ScalarMap::constant(0.37);
    let mut harness = harness(project);
    harness.run();
    feed(&mut harness, None);
    harness.run();
    aimed_at_the_middle_of_petal_1(&mut harness);
    let paint = harness.state_mut().paint_mut();
    paint.brush.mode = BrushMode::Add;
    paint.brush.value = 0.9;
    let before = harness.state().project().clone();
    let centre = harness.get_by_label("3D viewport").rect().center();
    harness.hover_at(centre);
    harness.run();
    for pressed in [true, false] {
        harness.event_modifiers(
            egui::Event::PointerButton {
                pos: centre,
                button: egui::PointerButton::Primary,
                pressed,
                modifiers: egui::Modifiers::ALT,
            },
            egui::Modifiers::ALT,
        );
        harness.step();
    }
    harness.run();
    let brush = harness.state_mut().paint_mut().brush;
    assert_eq!(brush.mode, BrushMode::Set);
    assert!((brush.value - 0.37).abs() < 1e-6, "picked {}", brush.value);
    assert_eq!(harness.state().project(), &before, "picking paints nothing");
}

/// The built-in starting point `name`.
fn builtin(name: &str) -> Project {
    anthesis_garden::builtin(name)
        .expect("built in")
        .unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Draws `points` (side-view `(r, h)`) as one stroke in the Sketched bud
/// section's view.
fn stroke_in_bud_view(harness: &mut Harness<'_, AnthesisApp>, points: &[glam::DVec2]) {
    harness.get_by_label("bud side view").scroll_to_me();
    settle(harness);
    let screen: Vec<egui::Pos2> = points
        .iter()
        .map(|p| {
            harness
                .state()
                .flower_panel()
                .bud_sketch()
                .on_screen(*p)
                .expect("the view is drawn")
        })
        .collect();
    harness.hover_at(screen[0]);
    settle(harness);
    harness.drag_at(screen[0]);
    settle(harness);
    for p in &screen[1..] {
        harness.hover_at(*p);
        settle(harness);
    }
    harness.drop_at(*screen.last().expect("points"));
    settle(harness);
}

/// Draws the curve `at(t)`, `t` from 0 to 1, as a stroke of 25 points in
/// the Sketched bud section's view, and returns the points.
fn stroke_curve_in_bud_view(
    harness: &mut Harness<'_, AnthesisApp>,
    at: impl Fn(f64) -> glam::DVec2,
) -> Vec<glam::DVec2> {
    let points: Vec<glam::DVec2> = (0..=24).map(|k| at(k as f64 / 24.0)).collect();
    stroke_in_bud_view(harness, &points);
    points
}

/// Scrolls the bud side view into the window, moves the pointer off it
/// and takes the snapshot `name`.
fn snapshot_bud_view(harness: &mut Harness<'_, AnthesisApp>, name: &str) {
    harness.get_by_label("bud side view").scroll_to_me();
    harness.hover_at(egui::pos2(600.0, 300.0));
    settle(harness);
    harness.snapshot(name);
}

#[test]
fn the_sketched_bud_says_when_an_l_system_places_the_organs() {
    // The apple's organs are placed by its L-system, in its turtle's frames.
    let mut harness = harness(builtin("apple"));
    harness.get_by_label("Flower").click();
    settle(&mut harness);
    click_settled(&mut harness, "Sketched bud");
    harness.get_by_label_contains("The L-system places these organs in its turtle's frames");
}

#[test]
fn a_bud_is_sketched_with_one_stroke_and_applied_in_one_undo_step() {
    use anthesis_flower::structure::{GOLDEN_ANGLE_DEG, Structure};
    use glam::DVec2;
    let mut harness = harness(builtin("five-petal"));
    harness.get_by_label("Flower").click();
    settle(&mut harness);
    click_settled(&mut harness, "Sketched bud");
    let before = harness.state().project().clone();

    // A vase: out from the five petals' bases and up, turning back in.
    let stroke = stroke_curve_in_bud_view(&mut harness, |t| {
        DVec2::new(4.0 + 6.0 * (1.4 * t).sin(), 22.0 * t)
    });
    let app = harness.state();
    let section = app.flower_panel().bud_sketch();
    assert_eq!(section.problem(), None);
    let bud = section.bud().expect("the stroke makes a bud");
    assert_eq!(bud.flower.organs.len(), 5);
    assert_eq!(
        harness.state().project(),
        &before,
        "nothing changes until Apply"
    );
    snapshot_bud_view(&mut harness, "flower_panel_sketched_bud");

    click_settled(&mut harness, "Apply bud");
    let app = harness.state();
    let flower = &app.project().flower;
    let Some(Structure::Spiral(spiral)) = &flower.structure else {
        panic!("a spiral: {:?}", flower.structure);
    };
    assert_eq!(spiral.count, 5);
    assert_eq!(spiral.divergence_deg, GOLDEN_ANGLE_DEG);
    let template = &flower.templates[0];
    assert_eq!(
        template.maps, before.flower.templates[0].maps,
        "the maps stay"
    );
    assert_eq!(template.mesh.uvs, before.flower.templates[0].mesh.uvs);
    assert!(template.vein.is_some());
    // The first petal's midrib follows the stroke as drawn (pixels apart at
    // most: the stroke went through the screen).
    let organ = &flower.organs[0];
    let off_stroke = template
        .mesh
        .positions
        .iter()
        .zip(&template.mesh.uvs)
        .filter(|(_, uv)| (uv.x - 0.5).abs() < 1e-6)
        .map(|(p, _)| {
            let w = organ.placement.world_from_template(*p, 0.0);
            let q = DVec2::new(w.x.hypot(w.z), w.y);
            stroke
                .iter()
                .map(|s| s.distance(q))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max);
    assert!(
        off_stroke < 0.6,
        "the midrib is {off_stroke} off the stroke"
    );
    assert!(
        app.document()
            .undo_label()
            .is_some_and(|l| l.contains("sketched bud")),
        "{:?}",
        app.document().undo_label()
    );
    let bud = harness.state().project().clone();

    // The opened flower: a second stroke, out and down, is the open
    // petal's vein; the petals then open to it by the two-state blossom.
    click_settled(&mut harness, "the opened flower");
    stroke_curve_in_bud_view(&mut harness, |t| {
        DVec2::new(4.0 + 16.0 * t, 6.0 * (std::f64::consts::PI * t).sin())
    });
    let section = harness.state().flower_panel().bud_sketch();
    assert_eq!(section.problem(), None);
    assert!(section.opening().is_some());
    assert_eq!(
        harness.state().project(),
        &bud,
        "nothing changes until Apply"
    );
    snapshot_bud_view(&mut harness, "flower_panel_sketched_opening");
    click_settled(&mut harness, "Apply opening");
    let app = harness.state();
    let template = &app.project().flower.templates[0];
    assert_eq!(template.mesh, bud.flower.templates[0].mesh, "the bud stays");
    let animation = template.two_state.as_ref().expect("opens by two states");
    assert_eq!(
        animation.growth.duration,
        f64::from(app.project().settings.keyframes)
    );
    // The open petal's tip is out where the stroke ends, not up.
    let organ = &app.project().flower.organs[0];
    let tip = animation
        .open
        .iter()
        .map(|p| organ.placement.world_from_template(*p, 0.0))
        .max_by(|a, b| a.x.hypot(a.z).total_cmp(&b.x.hypot(b.z)))
        .expect("points");
    assert!(tip.x.hypot(tip.z) > 15.0 && tip.y < 3.0, "{tip}");
    assert_eq!(
        app.document().undo_label(),
        Some("sketched opening of petal")
    );

    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut harness);
    assert_eq!(harness.state().project(), &bud);
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut harness);
    assert_eq!(harness.state().project(), &before, "one undo step each");

    // A stroke across the axis is refused, saying why.
    let across: Vec<DVec2> = (0..=10)
        .map(|k| DVec2::new(-5.0 + k as f64, 2.0 + k as f64))
        .collect();
    stroke_in_bud_view(&mut harness, &across);
    let problem = harness.state().flower_panel().bud_sketch().problem();
    assert!(
        problem
            .as_deref()
            .is_some_and(|p| p.contains("crosses the flower's axis")),
        "{problem:?}"
    );
}

/// Steps until the New gallery has rendered every picture.
fn wait_for_gallery(harness: &mut Harness<'_, AnthesisApp>) {
    let start = Instant::now();
    while !harness.state().gallery_pictures_done() {
        assert!(
            start.elapsed() < Duration::from_secs(180),
            "the gallery's pictures were not rendered in 3 minutes"
        );
        std::thread::sleep(Duration::from_millis(50));
        harness.step();
    }
    harness.run();
}

#[test]
fn file_new_shows_every_built_in_starting_point_as_its_bud_and_opens_the_one_chosen() {
    let mut harness = harness(small_flower());
    harness.run();
    harness.get_by_label("File").click();
    harness.run();
    harness.get_by_label("New").click();
    harness.run();
    harness.get_by_label("New flower");
    wait_for_gallery(&mut harness);
    // Every flower the garden builds in, under its project's name, with
    // its picture (a button with an image: no "rendering…" left).
    for name in anthesis_garden::FLOWER_NAMES {
        let title = builtin(name).name;
        harness.get_by_label(&title);
        harness.get_by_label(&format!("bud of {title}"));
    }
    assert!(harness.query_by_label_contains("rendering").is_none());
    assert!(harness.query_by_label_contains("no picture").is_none());
    harness.snapshot("new_gallery");
    harness.get_by_label("Five petals").click();
    harness.run();
    let app = harness.state();
    assert_eq!(app.project(), &builtin("five-petal"));
    assert!(!app.document().is_dirty(), "a new project is not an edit");
    harness.get_by_label_contains("new project from Five petals (`five-petal`)");
    assert!(
        harness.query_by_label("New flower").is_none(),
        "the gallery closes"
    );
}

#[test]
fn the_gallery_pictures_are_renders_of_the_buds() {
    let mut renderer = anthesis_render::OffscreenRenderer::new().expect("a renderer");
    let five = builtin("five-petal");
    let picture =
        anthesis_app::thumbnail::bud_picture(&mut renderer, &five, 96, 96).expect("renders");
    // The petals' pink covers a good part of the picture; the background
    // has none of it.
    let pink = anthesis_flower::srgb8(anthesis_garden::five_petal::SIMPLE_PINK);
    let pinkish = picture
        .pixels()
        .filter(|p| {
            let [r, g, b, _] = p.0;
            r > g && r > b && i32::from(r) - i32::from(g) > 25 && r > 90
        })
        .count();
    let share = pinkish as f64 / (96.0 * 96.0);
    assert!(
        share > 0.08,
        "{share} of the picture is petal (pink {pink:?})"
    );
    // Another flower is another picture.
    let lily = anthesis_app::thumbnail::bud_picture(&mut renderer, &builtin("lily"), 96, 96)
        .expect("renders");
    assert_ne!(lily, picture);
}

/// Selects the text in the focused widget and types `text` over it.
fn replace_text(harness: &mut Harness<'_, AnthesisApp>, text: &str) {
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness.run();
    harness
        .get_by_role(egui::accesskit::Role::MultilineTextInput)
        .type_text(text);
    harness.step();
}

/// Simulates the app's project to its end with the engine and gives the
/// keyframes to the current run (its time said to be one second, so that
/// snapshots do not depend on the machine).
fn feed_simulated(harness: &mut Harness<'_, AnthesisApp>) {
    let app = harness.state_mut();
    let project = app.project().clone();
    let selection = app.selection();
    let run = app.session().run();
    let mut sim = anthesis_sim::Simulation::new(&project, &selection).expect("simulates");
    let mut computed = vec![sim.bud()];
    while !sim.finished() {
        computed.push(sim.step(&|| false, &mut |_| {}).expect("converges"));
    }
    let mut failures = Vec::new();
    let session = app.session_mut();
    session.accept(
        Event::Started {
            run,
            organs: Vec::new(),
            keyframes: project.settings.keyframes,
            first_computed: 1,
            proxy: false,
        },
        &mut failures,
    );
    for keyframe in computed {
        session.accept(
            Event::Keyframe {
                run,
                keyframe: Arc::new(keyframe),
            },
            &mut failures,
        );
    }
    session.accept(
        Event::Finished {
            run,
            keyframes: project.settings.keyframes,
            seconds: 1.0,
        },
        &mut failures,
    );
    assert!(failures.is_empty());
    harness.run();
}

#[test]
fn a_five_petal_flower_is_built_from_the_empty_start_in_the_flower_panel_and_simulated() {
    let mut harness = harness(builtin("five-petal"));
    harness.run();
    harness.get_by_label("Flower").click();
    harness.run();
    let runs = harness.state().session().run();

    // The whorl: tilt its petals out by typing a joint angle.
    click_in_view(&mut harness, "joint angle");
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness.get_by_label("joint angle").type_text("8");
    harness.run();
    harness.key_press(egui::Key::Enter);
    harness.run();
    let app = harness.state();
    assert!(
        app.project()
            .flower
            .organs
            .iter()
            .all(|o| o.placement.joint_angle_deg == 8.0)
    );
    assert_eq!(
        app.document().undo_label(),
        Some("joint angle of whorl petal")
    );
    assert!(app.session().run() > runs, "the edit re-simulates");

    // The centre: stamens and a pistil.
    click_in_view(&mut harness, "Add stamens");
    click_in_view(&mut harness, "Add pistil");
    assert_eq!(harness.state().project().flower.parts.len(), 2);

    // The arrangement as an L-system: the same five petals.
    let before = harness.state().project().flower.organs.clone();
    click_in_view(&mut harness, "arrange by");
    harness.get_by_label("L-system").click();
    harness.run();
    let flower = &harness.state().project().flower;
    assert!(matches!(
        flower.structure,
        Some(anthesis_flower::structure::Structure::LSystem { .. })
    ));
    assert_eq!(flower.organs.len(), 5);
    for (a, b) in flower.organs.iter().zip(&before) {
        let tip = glam::DVec3::new(0.0, 20.0, 0.0);
        let (a, b) = (
            a.placement.world_from_template(tip, 0.0),
            b.placement.world_from_template(tip, 0.0),
        );
        assert!(a.distance(b) < 1e-9, "{a} {b}");
    }

    // A typo: its place is named, and the flower stays as it was.
    harness
        .get_by_role(egui::accesskit::Role::MultilineTextInput)
        .click();
    harness.run();
    let good = harness.state().project().clone();
    replace_text(
        &mut harness,
        "axiom: A\nA -> [/(0) B] [/(72) B] [/(144 B] [/(216) B] [/(288) B]\n\
         B -> &(90) f(4) ^(90) &(12) ~a\n",
    );
    // Column 32 is the `B` where `)` belongs.
    harness.get_by_label_contains("L-system line 2, column 32");
    for _ in 0..4 {
        harness.step();
    }
    assert_eq!(
        harness.state().project(),
        &good,
        "an invalid text applies nothing"
    );
    let error = harness
        .state()
        .flower_panel()
        .text_error()
        .map(str::to_owned);
    assert!(
        error.as_deref().is_some_and(|e| e.contains("expected")),
        "{error:?}"
    );
    harness.snapshot("flower_panel_lsystem_error");

    // Fixed: applied when typing pauses, as one undo step.
    let fixed = "axiom: A\nA -> [/(0) B] [/(72) B] [/(144) B] [/(216) B] [/(288) B]\n\
                 B -> &(90) f(4) ^(90) &(12) ~a\n";
    replace_text(&mut harness, fixed);
    assert!(harness.state().flower_panel().text_error().is_none());
    assert_eq!(harness.state().project(), &good, "not while typing");
    for _ in 0..4 {
        harness.step();
    }
    harness.run();
    let app = harness.state();
    assert_eq!(app.document().undo_label(), Some("L-system text"));
    let flower = &app.project().flower;
    assert_eq!(flower.organs.len(), 5);
    assert!(matches!(
        &flower.structure,
        Some(anthesis_flower::structure::Structure::LSystem { text, .. }) if text == fixed
    ));
    // The petals lean out 12° in the bud now, where the whorl had 8°.
    let lean = |organ: &anthesis_flower::Organ| {
        let tip = organ
            .placement
            .world_from_template(glam::DVec3::new(0.0, 1.0, 0.0), 0.0)
            - organ.placement.world_from_template(glam::DVec3::ZERO, 0.0);
        tip.y.acos().to_degrees()
    };
    assert!((lean(&flower.organs[0]) - 12.0).abs() < 1e-6);
    assert!((lean(&before[0]) - 8.0).abs() < 1e-6);

    // Simulated by the engine: the petals open.
    feed_simulated(&mut harness);
    let session = harness.state().session();
    let keyframes = session.keyframes();
    let tip_distance = |k: usize| {
        keyframes[k].positions_in_world[0]
            .iter()
            .map(|p| p.x.hypot(p.z))
            .fold(0.0, f64::max)
    };
    assert_eq!(keyframes.len(), 101);
    // Wider all the way: it opens into a saucer, not curling back under.
    for k in (10..=100).step_by(10) {
        assert!(tip_distance(k) > tip_distance(k - 10), "keyframe {k}");
    }
    assert!(
        tip_distance(100) > tip_distance(0) + 5.0,
        "opened: {} -> {}",
        tip_distance(0),
        tip_distance(100)
    );
    harness.get_by_label("100 keyframes in 1.0 s");
    harness.snapshot("flower_panel_five_petals");
}

#[test]
fn whorls_and_the_overlap_order_are_edited_in_the_flower_panel_and_undone() {
    let mut harness = harness(builtin("five-petal"));
    harness.run();
    harness.get_by_label("Flower").click();
    harness.run();
    harness.get_by_label("Overlap order (0 pairs)");

    // A second ring outside the first, its petals between theirs: each
    // inner petal lies inside the two outer ones it meets.
    click_in_view(&mut harness, "Add whorl");
    let flower = &harness.state().project().flower;
    assert_eq!(flower.organs.len(), 10);
    assert_eq!(flower.overlaps.len(), 10);
    assert!(flower.overlaps.iter().all(|o| o.inner < 5 && o.outer >= 5));
    click_in_view(&mut harness, "Overlap order (10 pairs)");
    let first = harness.state().project().flower.overlaps[0];
    let swap = harness
        .get_all_by_label("Swap")
        .next()
        .expect("a swap button");
    swap.scroll_to_me();
    harness.run();
    harness
        .get_all_by_label("Swap")
        .next()
        .expect("a swap button")
        .click();
    harness.run();
    let app = harness.state();
    let overlaps = &app.project().flower.overlaps;
    assert!(!overlaps.contains(&first));
    assert!(overlaps.contains(&anthesis_flower::Overlap {
        inner: first.outer,
        outer: first.inner
    }));
    assert!(
        app.document()
            .undo_label()
            .is_some_and(|l| l.starts_with("swap petal-1")),
        "{:?}",
        app.document().undo_label()
    );
    harness.get_by_label("swapped");
    harness.snapshot("flower_panel_overlap_order");

    // A new template, a listed organ moved out by typing its distance,
    // then undo all the way back.
    click_in_view(&mut harness, "Add simple petal");
    assert_eq!(harness.state().project().flower.templates.len(), 2);
    click_in_view(&mut harness, "Add organ");
    let flower = &harness.state().project().flower;
    assert_eq!(flower.organs.len(), 11);
    assert_eq!(flower.made_organ_count(), 10);
    let added = flower.organs[10].clone();
    click_in_view(&mut harness, "Organs (11)");
    click_in_view(&mut harness, "distance");
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness.get_by_label("distance").type_text("9");
    harness.run();
    harness.key_press(egui::Key::Enter);
    harness.run();
    let app = harness.state();
    let moved = &app.project().flower.organs[10];
    let p = moved.placement.position;
    assert!((p.x.hypot(p.z) - 9.0).abs() < 1e-9, "{p}");
    assert_eq!(moved.placement.azimuth_deg, added.placement.azimuth_deg);
    assert_eq!(
        app.document().undo_label().map(str::to_owned),
        Some(format!("distance of {}", added.name))
    );
    for _ in 0..5 {
        harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
        harness.run();
    }
    assert_eq!(harness.state().project(), &builtin("five-petal"));
    assert_eq!(harness.state().selected_organ(), 0);

    // The template renamed by typing; the whorl's organs keep their names.
    click_in_view(&mut harness, "name");
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness.get_by_label("name").type_text("blade");
    harness.run();
    assert_eq!(
        harness.state().project().flower.templates[0].name,
        "petal",
        "not while typing"
    );
    harness.key_press(egui::Key::Enter);
    harness.run();
    let app = harness.state();
    assert_eq!(app.project().flower.templates[0].name, "blade");
    assert_eq!(app.project().flower.organs[0].name, "petal-1");
    assert_eq!(
        app.document().undo_label(),
        Some("rename template petal to blade")
    );
}

#[test]
fn the_apple_s_l_system_shows_in_the_flower_panel_and_a_whorl_arrangement_replaces_it() {
    let apple = builtin("apple");
    let Some(anthesis_flower::structure::Structure::LSystem { text, .. }) =
        apple.flower.structure.clone()
    else {
        panic!("the apple is arranged by an L-system");
    };
    let mut harness = harness(apple.clone());
    harness.run();
    harness.get_by_label("Flower").click();
    harness.run();
    // Its text as the project has it, without an error, and its pairs.
    assert_eq!(harness.state().flower_panel().text(), text);
    assert!(harness.state().flower_panel().text_error().is_none());
    harness.get_by_value(&text);
    harness.get_by_label(&format!(
        "Overlap order ({} pairs)",
        apple.flower.overlaps.len()
    ));
    // Whorls in its place: one ring per template, as many organs as it had.
    click_in_view(&mut harness, "arrange by");
    harness.get_by_label("Whorls").click();
    harness.run();
    let flower = &harness.state().project().flower;
    assert!(matches!(
        flower.structure,
        Some(anthesis_flower::structure::Structure::Whorls { .. })
    ));
    assert_eq!(flower.organs.len(), apple.flower.organs.len());
    assert_eq!(flower.parts, apple.flower.parts);
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run();
    assert_eq!(harness.state().project(), &apple);
    assert_eq!(harness.state().flower_panel().text(), text);
}

#[test]
fn edit_menu_fits_growth_maps_to_a_target_and_applies_them_as_one_undo_step() {
    let dir = tempfile::tempdir().expect("tempdir");
    let project = small_flower();
    // The first organ's own final shape, as `anthesis simulate --out` writes it.
    let maps = project.flower.template_of(0).maps.clone();
    let shape = anthesis_fit::simulate_final(&project, 0, maps, &|| false).expect("simulates");
    let mut obj = format!("o {}\n", project.flower.organs[0].name);
    for p in &shape {
        obj.push_str(&format!("v {} {} {}\n", p.x, p.y, p.z));
    }
    let target = dir.path().join("open.obj");
    std::fs::write(&target, obj).expect("write");

    let mut harness = harness(project);
    harness.run();
    harness.get_by_label("Edit").click();
    harness.run();
    harness.get_by_label("Fit growth maps to a target…").click();
    harness.run();
    harness.get_by_label("Target OBJ").click();
    harness.run();
    harness
        .get_by_label("Target OBJ")
        .type_text(&target.display().to_string());
    harness.run();
    harness.get_by_label("Fit").click();
    harness.step();
    let started = Instant::now();
    while harness.state().fit_dialog().is_running() {
        assert!(
            started.elapsed() < Duration::from_secs(120),
            "the fit hangs: {:?}",
            harness.state().fit_dialog().state()
        );
        std::thread::sleep(Duration::from_millis(20));
        harness.step();
    }
    harness.run();
    // In the dialog and in the log.
    assert!(
        harness
            .query_all_by_label_contains("fitted: RMS")
            .next()
            .is_some(),
        "{:?}",
        harness.state().fit_dialog().state()
    );
    let before = harness.state().document().project().flower.templates[0]
        .maps
        .clone();
    harness.get_by_label("Apply the fitted maps").click();
    harness.run();
    let after = &harness.state().document().project().flower.templates[0].maps;
    assert_ne!(*after, before);
    assert_eq!(after.keys().len(), 1, "one time key, as asked");
    assert_eq!(
        harness.state().document().undo_label(),
        Some("fit growth maps")
    );
}

#[test]
fn the_fit_dialog_registers_a_target_in_its_own_frame_and_shows_it_over_the_organ() {
    let dir = tempfile::tempdir().expect("tempdir");
    let project = small_flower();
    let maps = project.flower.template_of(0).maps.clone();
    let shape = anthesis_fit::simulate_final(&project, 0, maps, &|| false).expect("simulates");
    // The organ's open shape turned a quarter about +Y and moved away.
    let mut obj = format!("o {}\n", project.flower.organs[0].name);
    for p in &shape {
        obj.push_str(&format!("v {} {} {}\n", -p.z + 40.0, p.y - 5.0, p.x));
    }
    let target = dir.path().join("scan.obj");
    std::fs::write(&target, obj).expect("write");

    let mut harness = harness(project);
    harness.run();
    harness.get_by_label("Edit").click();
    harness.run();
    harness.get_by_label("Fit growth maps to a target…").click();
    harness.run();
    harness.get_by_label("Target OBJ").click();
    harness.run();
    harness
        .get_by_label("Target OBJ")
        .type_text(&target.display().to_string());
    harness.run();
    harness
        .get_by_label("Register the target on the organ first")
        .click();
    harness.run();
    harness.get_by_label("Fit").click();
    harness.step();
    let started = Instant::now();
    while harness.state().fit_dialog().is_running() {
        assert!(
            started.elapsed() < Duration::from_secs(120),
            "the fit hangs: {:?}",
            harness.state().fit_dialog().state()
        );
        std::thread::sleep(Duration::from_millis(20));
        harness.step();
    }
    harness.run();
    // The motion found is said in the dialog, the fit ends on the target,
    // and the target is drawn where the registration put it.
    assert!(
        harness
            .query_all_by_label_contains("registered: turned 90.")
            .next()
            .is_some(),
        "{:?}",
        harness.state().fit_dialog().registered()
    );
    assert!(
        harness
            .query_all_by_label_contains("fitted: RMS")
            .next()
            .is_some(),
        "{:?}",
        harness.state().fit_dialog().state()
    );
    assert!(harness.state().fit_dialog().target_overlay().0 > 0);
}

/// Runs frames until the app stops asking for them (the remesher's
/// thread asks for one more when its preview is ready, at any time).
fn settle(harness: &mut Harness<'_, AnthesisApp>) {
    for _ in 0..50 {
        if harness.try_run().is_ok() {
            return;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    panic!("the app keeps asking for frames");
}

/// [`click_in_view`] with [`settle`].
fn click_settled(harness: &mut Harness<'_, AnthesisApp>, label: &str) {
    harness.get_by_label(label).scroll_to_me();
    settle(harness);
    harness.get_by_label(label).click();
    settle(harness);
}

/// The Shape section's preview once the remesher has answered.
fn wait_for_remesh_preview(
    harness: &mut Harness<'_, AnthesisApp>,
) -> Result<anthesis_bud::MeshQuality, String> {
    for _ in 0..1000 {
        harness.step();
        if let Some(preview) = harness.state().flower_panel().shape().preview() {
            let preview = preview.copied();
            settle(harness);
            return preview;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    panic!("the remesh preview did not come");
}

/// Chooses `file` in the in-app browser opened by "Import OBJ…".
fn import_obj(harness: &mut Harness<'_, AnthesisApp>, file: &str) {
    click_settled(harness, "Import OBJ…");
    harness.get_by_label(&format!("🗋 {file}")).click();
    settle(harness);
    harness.get_by_label("Open").click();
    settle(harness);
}

#[test]
fn an_obj_becomes_a_template_and_is_remeshed_at_a_chosen_edge_keeping_its_maps() {
    let dir = tempfile::tempdir().expect("temp dir");
    let petal = anthesis_mesh::generate::test_petal(4.0, 2.0, 6, 10);
    std::fs::write(
        dir.path().join("bloom.obj"),
        anthesis_mesh::obj_string(&petal),
    )
    .expect("write obj");
    // A face that names a vertex the file does not have.
    std::fs::write(
        dir.path().join("broken.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 9/3\n",
    )
    .expect("write obj");
    // A valid OBJ whose UV layout is a half ring (a line of constant v
    // crosses its outline four times): not a template's layout.
    let mut folded = petal.clone();
    for uv in &mut folded.uvs {
        let (angle, radius) = (std::f64::consts::PI * uv.x, 0.2 + 0.3 * uv.y);
        *uv = glam::DVec2::new(0.5 + radius * angle.cos(), radius * angle.sin());
    }
    std::fs::write(
        dir.path().join("folded.obj"),
        anthesis_mesh::obj_string(&folded),
    )
    .expect("write obj");
    let mut harness = harness_with_file_browser(&dir.path().join("flower.anthesis.toml"));
    harness.get_by_label("Flower").click();
    settle(&mut harness);
    let before = harness.state().project().clone();

    // Import: a new template with the simple petal's uniform maps and one
    // organ of it, in one undo step.
    import_obj(&mut harness, "bloom.obj");
    let app = harness.state();
    let flower = &app.project().flower;
    assert_eq!(flower.templates.len(), before.flower.templates.len() + 1);
    let index = flower.templates.len() - 1;
    let template = &flower.templates[index];
    assert_eq!(template.name, "bloom");
    assert_eq!(template.mesh.positions.len(), petal.positions.len());
    assert_eq!(
        template.maps,
        anthesis_garden::five_petal::simple_petal_maps()
    );
    assert_eq!(flower.organs.len(), before.flower.organs.len() + 1);
    assert_eq!(flower.organs.last().map(|o| o.template), Some(index));
    assert_eq!(app.document().undo_label(), Some("import template bloom"));
    assert_eq!(app.flower_panel().shape().template(), index);

    // The Shape section opened on it: its inner side and, at its own
    // edge, a preview.
    harness.get_by_label("inner side: −Z (the template frame's inner side)");
    wait_for_remesh_preview(&mut harness).expect("the petal remeshes");

    // Flip the inner side: every triangle wound the other way, one step.
    click_settled(&mut harness, "Flip inner side");
    harness.get_by_label("inner side: +Z (the template frame wants −Z: flip it?)");
    let app = harness.state();
    let flipped = &app.project().flower.templates[index].mesh;
    assert_eq!(flipped, &anthesis_bud::with_inner_side_flipped(&petal));
    assert_eq!(
        app.document().undo_label(),
        Some("flip inner side of bloom")
    );
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut harness);
    assert_eq!(
        harness.state().project().flower.templates[index].mesh,
        petal
    );

    // A finer edge: the particle count and quality are shown before
    // anything changes.
    click_settled(&mut harness, "remesh edge");
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness.get_by_label("remesh edge").type_text("0.25");
    settle(&mut harness);
    harness.key_press(egui::Key::Enter);
    let quality = wait_for_remesh_preview(&mut harness).expect("remeshes at 0.25");
    assert!(
        (quality.mean_edge - 0.25).abs() < 0.05,
        "mean edge {}",
        quality.mean_edge
    );
    assert!(quality.vertices > 2 * petal.positions.len());
    harness.get_by_label_contains(&format!("remeshed: {} particles", quality.vertices));
    assert_eq!(
        harness.state().project().flower.templates[index].mesh,
        petal,
        "nothing changes before Remesh"
    );
    let imported = harness.state().project().clone();
    // The log names the temporary folder: cleared for the snapshot.
    harness.get_by_label("Clear").click();
    harness.hover_at(egui::pos2(600.0, 300.0));
    settle(&mut harness);
    harness.snapshot("flower_panel_shape");

    click_settled(&mut harness, "Remesh");
    let app = harness.state();
    let remeshed = &app.project().flower.templates[index];
    assert_eq!(remeshed.mesh.positions.len(), quality.vertices);
    assert_eq!(remeshed.maps, imported.flower.templates[index].maps);
    assert_eq!(
        app.document().undo_label(),
        Some("remesh bloom at edge 0.25")
    );
    // One undo step gives the imported mesh back, the next removes it.
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut harness);
    assert_eq!(harness.state().project(), &imported);
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut harness);
    assert_eq!(
        harness.state().project().flower.templates,
        before.flower.templates
    );
    harness.key_press_modifiers(
        egui::Modifiers::COMMAND | egui::Modifiers::SHIFT,
        egui::Key::Z,
    );
    settle(&mut harness);
    assert_eq!(harness.state().project(), &imported);

    // A broken file is refused with the element it names; nothing changes.
    let now = harness.state().project().clone();
    import_obj(&mut harness, "broken.obj");
    assert_eq!(harness.state().project(), &now);
    let refused = harness
        .state()
        .flower_panel()
        .refused()
        .expect("refused")
        .to_string();
    assert!(
        refused.contains("broken.obj") && refused.contains('9'),
        "{refused}"
    );
    assert!(refused.contains("line 7"), "names the line: {refused}");
    // In the Flower panel and the log's banner.
    assert_eq!(harness.get_all_by_label(&refused).count(), 2);

    // A mesh whose UVs cannot be a template's is refused at import, saying
    // what the convention is and where such a mesh can come in.
    import_obj(&mut harness, "folded.obj");
    assert_eq!(harness.state().project(), &now);
    let refused = harness.state().flower_panel().refused().expect("refused");
    assert!(
        refused.contains("folded.obj")
            && refused.contains("UV")
            && refused.contains("Import scanned petal"),
        "{refused}"
    );
}

#[test]
fn a_bezier_petal_is_made_its_control_points_dragged_and_typed_and_applied_in_one_undo_step() {
    use anthesis_bud::BezierPatch;
    // A new template of the starting net, with one organ, its net in the
    // Shape section.
    let (mut harness, index) = new_shape_template("New Bézier petal", "bezier petal");
    let app = harness.state();
    assert_eq!(
        app.flower_panel().shape().net("bezier petal"),
        Some(&BezierPatch::petal())
    );
    let made = app.project().flower.templates[index].clone();
    wait_for_remesh_preview(&mut harness).expect("the new petal remeshes");

    // Drag the tip's right-hand point 30 pixels to the right in the front
    // view: its mirror image across the midrib moves left with it.
    harness.get_by_label("Bézier net").scroll_to_me();
    settle(&mut harness);
    let from = harness
        .state()
        .flower_panel()
        .shape()
        .control_point_on_screen(3, 3)
        .expect("drawn");
    harness.hover_at(from);
    settle(&mut harness);
    harness.drag_at(from);
    settle(&mut harness);
    for k in 1..=3 {
        harness.hover_at(from + egui::vec2(10.0 * k as f32, 0.0));
        settle(&mut harness);
    }
    harness.drop_at(from + egui::vec2(30.0, 0.0));
    settle(&mut harness);
    let start = BezierPatch::petal();
    let net = *harness
        .state()
        .flower_panel()
        .shape()
        .net("bezier petal")
        .expect("net");
    assert!(
        net.control[3][3].x > start.control[3][3].x + 0.5,
        "{} from {}",
        net.control[3][3],
        start.control[3][3]
    );
    assert_eq!(net.control[3][3].y, start.control[3][3].y);
    assert_eq!(net.control[3][0], anthesis_bud::mirrored(net.control[3][3]));
    assert_eq!(
        harness.state().project().flower.templates[index],
        made,
        "the net is a draft until applied"
    );

    // Type the dragged (now chosen) point's z.
    click_settled(&mut harness, "z");
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness.get_by_label("z").type_text("-1.5");
    settle(&mut harness);
    harness.key_press(egui::Key::Enter);
    settle(&mut harness);
    let net = *harness
        .state()
        .flower_panel()
        .shape()
        .net("bezier petal")
        .expect("net");
    assert_eq!(net.control[3][3].z, -1.5);
    assert_eq!(net.control[3][0].z, -1.5);
    assert!(net.is_symmetric(0.0));
    harness.get_by_label("Bézier net").scroll_to_me();
    harness.hover_at(egui::pos2(600.0, 300.0));
    settle(&mut harness);
    harness.snapshot("flower_panel_bezier");

    // Apply: the patch meshed at the remesh edge replaces the mesh, the
    // maps stay, one undo step.
    click_settled(&mut harness, "Apply net");
    let app = harness.state();
    let applied = &app.project().flower.templates[index];
    let edge = anthesis_bud::quality(&made.mesh).mean_edge;
    let expected =
        anthesis_bud::build_organ(&net, &anthesis_bud::RemeshOptions::new(edge)).expect("meshes");
    assert_eq!(applied.mesh, expected.mesh);
    assert_ne!(applied.mesh, made.mesh);
    assert_eq!(applied.maps, made.maps);
    assert_eq!(
        applied.source,
        Some(anthesis_flower::TemplateSource::Bezier { net, edge })
    );
    assert_eq!(
        app.document().undo_label(),
        Some("Bézier net of bezier petal")
    );
    // The net is saved with the project and read back, to edit again.
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("bezier.anthesis.toml");
    anthesis_flower::project::save_project(app.project(), &path).expect("saves");
    let reopened = anthesis_flower::project::load_project(&path).expect("loads");
    assert_eq!(reopened.flower.templates[index].source, applied.source);
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut harness);
    assert_eq!(harness.state().project().flower.templates[index], made);

    // The undo took the editor's net back with it; a flipped inner side
    // stays flipped when that net is applied again.
    assert_eq!(
        harness.state().flower_panel().shape().net("bezier petal"),
        Some(&start)
    );
    click_settled(&mut harness, "Flip inner side");
    click_settled(&mut harness, "Apply net");
    let mesh = &harness.state().project().flower.templates[index].mesh;
    let again =
        anthesis_bud::build_organ(&start, &anthesis_bud::RemeshOptions::new(edge)).expect("meshes");
    assert_eq!(mesh, &anthesis_bud::with_inner_side_flipped(&again.mesh));
    assert_eq!(anthesis_bud::inner_side_faces_minus_z(mesh), Some(false));

    // Remeshing the patch's template at another edge saves that edge with
    // the net, in the same undo step.
    click_settled(&mut harness, "remesh edge");
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness.get_by_label("remesh edge").type_text("0.9");
    settle(&mut harness);
    harness.key_press(egui::Key::Enter);
    wait_for_remesh_preview(&mut harness).expect("remeshes at 0.9");
    let before_remesh = harness.state().project().flower.templates[index].clone();
    click_settled(&mut harness, "Remesh");
    let remeshed = &harness.state().project().flower.templates[index];
    assert_ne!(remeshed.mesh, before_remesh.mesh);
    assert_eq!(
        remeshed.source,
        Some(anthesis_flower::TemplateSource::Bezier {
            net: start,
            edge: 0.9
        })
    );
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut harness);
    assert_eq!(
        harness.state().project().flower.templates[index],
        before_remesh
    );
}

/// The small flower with the Flower tab open and `button` ("New … petal")
/// clicked: the harness and the new template's index,
/// checked to be named `name`, to come with one organ and to be the one
/// the Shape section shows.
fn new_shape_template(button: &str, name: &str) -> (Harness<'static, AnthesisApp>, usize) {
    let mut harness = opened_small_flower();
    harness.get_by_label("Flower").click();
    settle(&mut harness);
    let before = harness.state().project().clone();
    click_settled(&mut harness, button);
    let app = harness.state();
    let flower = &app.project().flower;
    let index = flower.templates.len() - 1;
    assert_eq!(index, before.flower.templates.len());
    assert_eq!(flower.templates[index].name, name);
    assert_eq!(flower.organs.len(), before.flower.organs.len() + 1);
    assert_eq!(app.flower_panel().shape().template(), index);
    (harness, index)
}

/// Drags from `from` by `by` in three steps, settling between them.
fn drag_by(harness: &mut Harness<'_, AnthesisApp>, from: egui::Pos2, by: egui::Vec2) {
    harness.hover_at(from);
    settle(harness);
    harness.drag_at(from);
    settle(harness);
    for k in 1..=3 {
        harness.hover_at(from + by * (k as f32 / 3.0));
        settle(harness);
    }
    harness.drop_at(from + by);
    settle(harness);
}

#[test]
fn a_pde_petal_is_made_its_margin_dragged_applied_in_one_undo_step_and_saved_with_its_curves() {
    use anthesis_bud::{PdeSweep, SweepCurve};
    // A new template of the starting sweep, with one organ, its curves in
    // the Shape section.
    let (mut harness, index) = new_shape_template("New PDE petal", "pde petal");
    let app = harness.state();
    let flower = &app.project().flower;
    let shape = app.flower_panel().shape();
    let start = PdeSweep::petal();
    assert_eq!(shape.pde().sweep("pde petal"), Some(&start));
    let made = flower.templates[index].clone();
    assert_eq!(
        made.source,
        Some(anthesis_flower::TemplateSource::Pde {
            sweep: start,
            edge: anthesis_garden::five_petal::SIMPLE_PETAL_EDGE
                * anthesis_garden::flowers::EDGE_SCALE
        })
    );
    wait_for_remesh_preview(&mut harness).expect("the new petal remeshes");

    // Drag margin 1's upper control point 30 pixels to the right in the
    // front view: its mirror image on margin 2 moves left with it.
    harness.get_by_label("PDE surface").scroll_to_me();
    settle(&mut harness);
    let from = harness
        .state()
        .flower_panel()
        .shape()
        .pde()
        .point_on_screen(SweepCurve::Margin0, 2)
        .expect("drawn");
    drag_by(&mut harness, from, egui::vec2(30.0, 0.0));
    let sweep = *harness
        .state()
        .flower_panel()
        .shape()
        .pde()
        .sweep("pde petal")
        .expect("sweep");
    let (moved, was) = (sweep.curve0.control[2], start.curve0.control[2]);
    assert!(moved.x > was.x + 0.5, "{moved} from {was}");
    assert_eq!(moved.y, was.y);
    assert_eq!(sweep.curve1.control[2], anthesis_bud::mirrored(moved));
    assert!(sweep.is_symmetric(0.0));
    assert_eq!(
        harness.state().project().flower.templates[index],
        made,
        "the surface is a draft until applied"
    );

    // Drag the upper tangent handle of margin 2 up: the tangent turns
    // (three times the handle's move; that handle is C1 − T1/3, so T1
    // turns down) and its mirror follows.
    let handle = harness
        .state()
        .flower_panel()
        .shape()
        .pde()
        .point_on_screen(SweepCurve::Tangent1, 2)
        .expect("drawn");
    drag_by(&mut harness, handle, egui::vec2(0.0, -15.0));
    let turned = *harness
        .state()
        .flower_panel()
        .shape()
        .pde()
        .sweep("pde petal")
        .expect("sweep");
    assert!(
        turned.tangent1.control[2].y < -0.5,
        "{}",
        turned.tangent1.control[2]
    );
    assert_eq!(turned.tangent1.control[2].x, start.tangent1.control[2].x);
    assert!(turned.is_symmetric(1e-12));
    // The mesh it would become is shown before applying.
    let quality = *harness
        .state()
        .flower_panel()
        .shape()
        .pde()
        .built()
        .expect("built")
        .expect("meshes");
    harness.get_by_label_contains(&format!("surface meshed: {} particles", quality.vertices));
    // The view just above the point chooser: both in sight.
    harness
        .get_all_by_label("point")
        .next()
        .expect("the point chooser")
        .scroll_to_me();
    harness.remove_cursor();
    settle(&mut harness);
    harness.snapshot("flower_panel_pde");

    // Apply: the sweep meshed at the remesh edge replaces the mesh, the
    // maps stay, one undo step.
    click_settled(&mut harness, "Apply surface");
    let app = harness.state();
    let applied = &app.project().flower.templates[index];
    let edge = anthesis_bud::quality(&made.mesh).mean_edge;
    let expected = anthesis_bud::build_organ(&turned, &anthesis_bud::RemeshOptions::new(edge))
        .expect("meshes");
    assert_eq!(applied.mesh, expected.mesh);
    assert_eq!(applied.mesh.vertex_count(), quality.vertices);
    assert_eq!(applied.maps, made.maps);
    assert_eq!(
        applied.source,
        Some(anthesis_flower::TemplateSource::Pde {
            sweep: turned,
            edge
        })
    );
    assert_eq!(
        app.document().undo_label(),
        Some("PDE surface of pde petal")
    );
    // The curves are saved with the project and read back, to edit again.
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("pde.anthesis.toml");
    anthesis_flower::project::save_project(app.project(), &path).expect("saves");
    assert!(
        std::fs::read_to_string(&path)
            .expect("read")
            .contains("kind = \"pde\"")
    );
    let reopened = anthesis_flower::project::load_project(&path).expect("loads");
    assert_eq!(reopened.flower.templates[index].source, applied.source);
    assert_eq!(reopened.flower.templates[index].mesh, applied.mesh);

    // One undo takes mesh, curves and the editor's draft back.
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut harness);
    assert_eq!(harness.state().project().flower.templates[index], made);
    assert_eq!(
        harness
            .state()
            .flower_panel()
            .shape()
            .pde()
            .sweep("pde petal"),
        Some(&start)
    );
}

#[test]
fn a_scanned_petal_is_fitted_its_base_moved_and_made_a_template_in_one_undo_step() {
    let dir = tempfile::tempdir().expect("temp dir");
    // The lily petal as a scan: another triangulation, no UVs, moved.
    let lily = anthesis_mesh::load_obj(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../assets/flowers/lily/meshes/petal.obj"),
    )
    .expect("lily petal");
    let scan = anthesis_bud::remesh_mesh(&lily, &anthesis_bud::RemeshOptions::new(2.0))
        .expect("remeshes")
        .mesh;
    let mut text = String::new();
    for p in &scan.positions {
        text.push_str(&format!("v {} {} {}\n", p.x + 10.0, p.z, -p.y));
    }
    for t in &scan.triangles {
        text.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
    }
    std::fs::write(dir.path().join("scan.obj"), text).expect("write obj");
    let mut harness = harness_with_file_browser(&dir.path().join("flower.anthesis.toml"));
    harness.get_by_label("Flower").click();
    settle(&mut harness);
    let before = harness.state().project().clone();

    click_settled(&mut harness, "Import scanned petal…");
    harness.get_by_label("🗋 scan.obj").click();
    settle(&mut harness);
    harness.get_by_label("Open").click();
    settle(&mut harness);
    assert_eq!(
        harness.state().project().flower,
        before.flower,
        "nothing changes until the template is made"
    );
    let fit = wait_for_scan_fit(&mut harness).expect("fits");
    let panel = harness.state().flower_panel();
    let review = panel.shape().pde().scan().expect("the scan is reviewed");
    let [rms, max] = fit.relative_scan_to_surface();
    assert!(rms < 0.02 && max < 0.05, "RMS {rms}, max {max}");
    let (corners, found) = review.corners();
    assert_eq!(corners, found);
    assert!(corners.pointed());
    harness.get_by_label_contains(&format!("fit error: RMS {:.2} %", 100.0 * rms));
    // The log names the temporary folder: cleared for the picture.
    click_settled(&mut harness, "Clear");
    harness.get_by_label("Scanned petal: scan.obj");
    harness.get_by_label("inner side convex").scroll_to_me();
    harness.remove_cursor();
    settle(&mut harness);
    harness.snapshot("flower_panel_scan");

    // Move the first base corner: click on the outline two vertices
    // further round; the fit is made again with it.
    harness.get_by_label("inner side convex").scroll_to_me();
    settle(&mut harness);
    let review = harness
        .state()
        .flower_panel()
        .shape()
        .pde()
        .scan()
        .expect("review");
    let n = review.outline().len();
    let moved_to = (corners.base[0] + n - 2) % n;
    let at = review.outline_on_screen(moved_to).expect("drawn");
    harness.hover_at(at);
    settle(&mut harness);
    harness.drag_at(at);
    settle(&mut harness);
    // Released where it was pressed, the pointer still there: a click.
    harness.event(egui::Event::PointerButton {
        pos: at,
        button: egui::PointerButton::Primary,
        pressed: false,
        modifiers: egui::Modifiers::NONE,
    });
    settle(&mut harness);
    let refit = wait_for_scan_fit(&mut harness).expect("fits again");
    let review = harness
        .state()
        .flower_panel()
        .shape()
        .pde()
        .scan()
        .expect("review");
    let (now, _) = review.corners();
    assert_eq!(now.base[0], moved_to);
    assert_ne!(refit.sweep, fit.sweep);
    assert_eq!(refit.corners, now);
    click_settled(&mut harness, "Found corners");
    let (back, _) = harness
        .state()
        .flower_panel()
        .shape()
        .pde()
        .scan()
        .expect("review")
        .corners();
    assert_eq!(back, found);
    assert_eq!(wait_for_scan_fit(&mut harness).expect("fits"), fit);

    // Make the template: the fitted sweep as its source, one organ, one
    // undo step.
    click_settled(&mut harness, "Make template");
    let app = harness.state();
    assert!(app.flower_panel().shape().pde().scan().is_none());
    let flower = &app.project().flower;
    assert_eq!(flower.templates.len(), before.flower.templates.len() + 1);
    assert_eq!(flower.organs.len(), before.flower.organs.len() + 1);
    let template = flower.templates.last().expect("made");
    assert_eq!(template.name, "scan");
    let Some(anthesis_flower::TemplateSource::Pde { sweep, edge }) = template.source else {
        panic!("no PDE source: {:?}", template.source);
    };
    assert_eq!(sweep, fit.sweep);
    assert!((edge - fit.length / 36.0).abs() < 1e-12);
    let expected =
        anthesis_bud::build_organ(&sweep, &anthesis_bud::RemeshOptions::new(edge)).expect("meshes");
    assert_eq!(template.mesh, expected.mesh);
    assert_eq!(
        anthesis_bud::inner_side_faces_minus_z(&template.mesh),
        Some(true)
    );
    assert_eq!(
        app.document().undo_label(),
        Some("import scanned petal scan")
    );
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut harness);
    assert_eq!(harness.state().project().flower, before.flower);
}

/// Draws `points` (sketch plane) on the sketch canvas with the pointer:
/// pressed at the first, moved through the others, released at the last.
fn draw_stroke(harness: &mut Harness<'_, AnthesisApp>, points: &[glam::DVec2]) {
    let sketch = harness.state().flower_panel().shape().sketch();
    let on_screen: Vec<egui::Pos2> = points
        .iter()
        .map(|p| sketch.sketch_to_screen(*p).expect("the canvas is drawn"))
        .collect();
    harness.hover_at(on_screen[0]);
    settle(harness);
    harness.drag_at(on_screen[0]);
    settle(harness);
    for at in &on_screen[1..on_screen.len() - 1] {
        harness.hover_at(*at);
        settle(harness);
    }
    harness.drop_at(on_screen[on_screen.len() - 1]);
    settle(harness);
}

/// The sketch editor's preview once its thread has answered.
fn wait_for_sketch_preview(
    harness: &mut Harness<'_, AnthesisApp>,
) -> Result<anthesis_bud::MeshQuality, String> {
    for _ in 0..1000 {
        harness.step();
        if let Some(preview) = harness.state().flower_panel().shape().sketch().preview() {
            let preview = preview.copied().map_err(str::to_string);
            settle(harness);
            return preview;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    panic!("the sketch preview did not come");
}

/// `count + 1` points along `f` over [0, 1].
fn along(count: usize, f: impl Fn(f64) -> glam::DVec2) -> Vec<glam::DVec2> {
    (0..=count).map(|k| f(k as f64 / count as f64)).collect()
}

#[test]
fn a_petal_is_sketched_with_the_pointer_and_applied_in_one_undo_step_keeping_its_maps() {
    use glam::DVec2;
    let mut harness = opened_small_flower();
    harness.get_by_label("Flower").click();
    settle(&mut harness);
    click_settled(&mut harness, "Shape");
    wait_for_remesh_preview(&mut harness).expect("the petal remeshes");
    let before = harness.state().project().flower.templates[0].clone();
    let edge = anthesis_bud::quality(&before.mesh).mean_edge;

    // A new shape for the flower's own petal, from an empty canvas.
    click_settled(&mut harness, "Sketch a new shape");
    let name = before.name.clone();
    assert_eq!(
        harness
            .state()
            .flower_panel()
            .shape()
            .sketch()
            .sketch(&name),
        Some(&anthesis_bud::PetalSketch::default())
    );
    harness.get_by_label("sketch canvas").scroll_to_me();
    settle(&mut harness);
    // The vein first, then the right margin drawn from the tip down, then
    // the left margin from the base up (automatic roles).
    let half_width = |t: f64| 1.0 + 3.5 * (std::f64::consts::PI * t).sin() - t;
    let vein = along(12, |t| DVec2::new(0.0, 18.0 * t));
    let right = along(16, |t| DVec2::new(half_width(1.0 - t), 18.0 * (1.0 - t)));
    let left = along(16, |t| DVec2::new(-half_width(t), 18.0 * t));
    for stroke in [&vein, &right, &left] {
        draw_stroke(&mut harness, stroke);
    }
    let drawn = harness
        .state()
        .flower_panel()
        .shape()
        .sketch()
        .sketch(&name)
        .expect("a draft")
        .clone();
    assert!(drawn.sections.is_empty());
    // The strokes went where the pointer went (within a pixel), sorted into
    // their roles: the left margin on the left.
    for (got, want) in [
        (&drawn.left, &left),
        (&drawn.right, &right),
        (&drawn.vein, &vein),
    ] {
        let (first, last) = (got[0], got[got.len() - 1]);
        assert!(first.distance(want[0]) < 0.2, "{first} vs {}", want[0]);
        assert!(last.distance(want[want.len() - 1]) < 0.2, "{last}");
    }
    let flat = drawn.build().expect("the outline makes a petal");
    assert!(flat.surface.control.iter().flatten().all(|p| p.z == 0.0));

    // A cross-section sagging towards the base over the middle: drawn
    // across, it bends the row nearest its start.
    let reach = half_width(0.5) + 0.4;
    let section = along(16, |t| {
        DVec2::new(-reach + 2.0 * reach * t, 9.0 - 5.0 * t * (1.0 - t))
    });
    draw_stroke(&mut harness, &section);
    // Undo stroke takes it back; drawn again, it is there again.
    click_settled(&mut harness, "Undo stroke");
    settle(&mut harness);
    assert_eq!(
        harness
            .state()
            .flower_panel()
            .shape()
            .sketch()
            .sketch(&name),
        Some(&drawn)
    );
    harness.get_by_label("sketch canvas").scroll_to_me();
    settle(&mut harness);
    draw_stroke(&mut harness, &section);
    let sketch = harness
        .state()
        .flower_panel()
        .shape()
        .sketch()
        .sketch(&name)
        .expect("a draft")
        .clone();
    assert_eq!(
        sketch.sections.len(),
        1,
        "an across stroke is a cross-section"
    );
    assert_eq!(
        (&sketch.left, &sketch.right, &sketch.vein),
        (&drawn.left, &drawn.right, &drawn.vein)
    );
    let petal = sketch.build().expect("the sketch makes a petal");
    let row = petal.section_rows[0];
    assert!(
        petal.surface.control[row][0].z < -0.5,
        "cupped: {}",
        petal.surface.control[row][0]
    );
    assert_eq!(
        harness.state().project().flower.templates[0],
        before,
        "the sketch is a draft until applied"
    );
    let expected =
        anthesis_bud::build_organ(&petal.surface, &anthesis_bud::RemeshOptions::new(edge))
            .expect("meshes");
    let shown = wait_for_sketch_preview(&mut harness).expect("meshes");
    assert_eq!(shown, expected.quality);
    harness.get_by_label(&format!(
        "sketched: {} particles, mean edge {:.3}, smallest angle {:.1}°, edge spread {:.0} %",
        shown.vertices,
        shown.mean_edge,
        shown.min_angle_deg,
        100.0 * shown.edge_spread
    ));
    harness.get_by_label("sketch canvas").scroll_to_me();
    harness.hover_at(egui::pos2(600.0, 300.0));
    settle(&mut harness);
    harness.snapshot("flower_panel_sketch");
    harness.get_by_label("Apply sketch").scroll_to_me();
    settle(&mut harness);
    harness.snapshot("flower_panel_sketch_side");

    // Apply: the petal meshed at the remesh edge replaces the mesh, the
    // maps stay, the strokes are kept, one undo step.
    click_settled(&mut harness, "Apply sketch");
    let app = harness.state();
    let applied = &app.project().flower.templates[0];
    assert_eq!(applied.mesh, expected.mesh);
    assert_eq!(applied.maps, before.maps);
    assert_eq!(
        applied.source,
        Some(anthesis_flower::TemplateSource::Sketch {
            sketch: sketch.clone(),
            edge
        })
    );
    assert_eq!(
        app.document().undo_label(),
        Some(format!("sketched shape of {name}").as_str())
    );
    // The strokes are saved with the project and read back, to edit again.
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("sketch.anthesis.toml");
    anthesis_flower::project::save_project(app.project(), &path).expect("saves");
    let reopened = anthesis_flower::project::load_project(&path).expect("loads");
    assert_eq!(reopened.flower.templates[0].source, applied.source);
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut harness);
    assert_eq!(harness.state().project().flower.templates[0], before);

    // A new sketched petal: a template of the starting strokes with one
    // organ, its sketch in the editor.
    let organs = harness.state().project().flower.organs.len();
    click_settled(&mut harness, "New sketched petal");
    let app = harness.state();
    let flower = &app.project().flower;
    let index = flower.templates.len() - 1;
    assert_eq!(flower.templates[index].name, "sketched petal");
    assert_eq!(flower.organs.len(), organs + 1);
    assert_eq!(app.flower_panel().shape().template(), index);
    assert!(matches!(
        &flower.templates[index].source,
        Some(anthesis_flower::TemplateSource::Sketch { sketch, .. })
            if *sketch == anthesis_bud::PetalSketch::petal()
    ));
    settle(&mut harness);
    assert_eq!(
        harness
            .state()
            .flower_panel()
            .shape()
            .sketch()
            .sketch("sketched petal"),
        Some(&anthesis_bud::PetalSketch::petal())
    );
}

/// The scan review's fit once its thread has answered.
fn wait_for_scan_fit(
    harness: &mut Harness<'_, AnthesisApp>,
) -> Result<anthesis_bud::ScanFit, String> {
    for _ in 0..1000 {
        harness.step();
        let fit = harness
            .state()
            .flower_panel()
            .shape()
            .pde()
            .scan()
            .and_then(|review| review.fit())
            .map(|fit| fit.cloned().map_err(str::to_string));
        if let Some(fit) = fit {
            settle(harness);
            return fit;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    panic!("the scan's fit did not come");
}

#[test]
fn an_edits_proxy_shows_first_badged_and_blue_and_the_converged_run_replaces_it() {
    let mut harness = harness(small_flower());
    harness.run();
    feed(&mut harness, None);
    harness.state_mut().playback_mut().scrub_to(12.0, Some(20));
    harness.run();
    // A run with a proxy: the same flower on coarser meshes, as the window
    // makes for a fine flower.
    let project = Arc::new(harness.state().project().clone());
    let mut proxy = anthesis_sim::fixtures::whorl(6, 5, 9, 20);
    proxy.name = project.name.clone();
    let proxy = Arc::new(proxy);
    let coarse = proxy.flower.template_of(0).mesh.vertex_count();
    assert!(coarse < project.flower.template_of(0).mesh.vertex_count());
    let converged = recorded_keyframes(&project, &Selection::All);
    let proxied = recorded_keyframes(&proxy, &Selection::All);
    let app = harness.state_mut();
    let session = app.session_mut();
    let run = session.start_with_proxy(
        Arc::clone(&project),
        Some(Arc::clone(&proxy)),
        Selection::All,
    );
    let mut failures = Vec::new();
    session.accept(
        Event::Started {
            run,
            organs: Vec::new(),
            keyframes: 20,
            first_computed: 1,
            proxy: true,
        },
        &mut failures,
    );
    let converged_event = |k: &Keyframe| Event::Keyframe {
        run,
        keyframe: Arc::new(k.clone()),
    };
    session.accept(converged_event(&converged[0]), &mut failures);
    for keyframe in proxied.iter().skip(1) {
        let keyframe = Arc::new(keyframe.clone());
        session.accept(Event::Proxy { run, keyframe }, &mut failures);
    }
    harness.run();
    let app = harness.state();
    assert_eq!(app.playback().time_in_keyframes, 12.0, "the playhead stays");
    let shown = app.session().shown_at(12.0).expect("shown");
    assert!(Arc::ptr_eq(&shown.meshes, &proxy), "the proxy is shown");
    assert_eq!(shown.positions[0].len(), coarse);
    assert!(
        harness
            .get_by_label_contains("proxy: coarse preview until the full-resolution run reaches 12")
            .rect()
            .width()
            > 0.0
    );
    harness.snapshot("app_proxy_after_an_edit");

    // The converged keyframes arrive up to 12: they replace the proxy's.
    let app = harness.state_mut();
    let session = app.session_mut();
    for keyframe in converged.iter().skip(1).take(12) {
        session.accept(converged_event(keyframe), &mut failures);
    }
    harness.run();
    let shown = harness.state().session().shown_at(12.0).expect("shown");
    assert!(!Arc::ptr_eq(&shown.meshes, &proxy));
    assert_eq!(
        shown.positions[0].len(),
        project.flower.template_of(0).mesh.vertex_count()
    );
    assert!(
        harness
            .query_by_label_contains("proxy: coarse preview")
            .is_none()
    );
    assert!(failures.is_empty(), "{failures:?}");
}

/// The organ meshes' names in the .glb at `path`.
fn exported_meshes(path: &Path) -> Vec<String> {
    let json: serde_json::Value =
        serde_json::from_str(&glb_json(path)).expect("the JSON chunk parses");
    json["meshes"]
        .as_array()
        .expect("meshes")
        .iter()
        .filter_map(|m| m["name"].as_str().map(str::to_string))
        .collect()
}

#[test]
fn with_one_organ_previewed_the_export_writes_the_whole_flower_unless_asked_for_the_organ() {
    use anthesis_app::desktop::{Command, ProjectEdit};
    let dir = tempfile::tempdir().expect("temp dir");
    // The whole flower ran to its end; then one organ is previewed.
    let mut harness = opened_small_flower();
    let organs = harness.state().project().flower.organs.len();
    harness
        .state_mut()
        .apply(Command::SetSingleOrganPreview(true));
    harness.run();
    assert_eq!(harness.state().selection(), Selection::Only(0));
    feed(&mut harness, None);
    harness.run();
    harness.state_mut().open_export();
    harness.run();
    harness.get_by_label("whole flower");
    harness.get_by_label_contains("The export holds the whole flower");
    // From the keyframes kept from before the preview (no run: the window
    // runs none here, and the file is written at once).
    let whole = dir.path().join("whole.glb");
    harness.state_mut().export_dialog_mut().path = whole.display().to_string();
    harness.run();
    harness.get_by_label("Export").click();
    wait_for_export(&mut harness, &whole, Duration::from_secs(60));
    let names = exported_meshes(&whole);
    for i in 0..organs {
        let name = &harness.state().project().flower.organs[i].name;
        assert!(names.contains(name), "{name} in {names:?}");
    }

    // The organ alone, when asked for.
    harness.get_by_label("petal-1 alone").click();
    harness.run();
    let alone = dir.path().join("alone.glb");
    harness.state_mut().export_dialog_mut().path = alone.display().to_string();
    harness.run();
    harness.get_by_label("Export").click();
    wait_for_export(&mut harness, &alone, Duration::from_secs(60));
    let names = exported_meshes(&alone);
    assert!(names.contains(&"petal-1".to_string()), "{names:?}");
    assert!(!names.contains(&"sepal-1".to_string()), "{names:?}");

    // An edit made in the preview: the kept keyframes are no longer of
    // this project, so the export runs the whole flower itself.
    let mut edited = harness.state().project().flower.templates[1].clone();
    edited.dg += 0.0005;
    let keyframes = harness.state().project().settings.keyframes;
    harness.state_mut().apply(Command::Edit {
        label: "dg of sepal".to_string(),
        edit: ProjectEdit::Template {
            template: 1,
            value: Box::new(edited),
            keyframes,
        },
    });
    harness.get_by_label("whole flower").click();
    harness.run();
    let rerun = dir.path().join("rerun.glb");
    harness.state_mut().export_dialog_mut().path = rerun.display().to_string();
    harness.run();
    harness.get_by_label("Export").click();
    harness.run();
    assert!(
        harness
            .query_by_label_contains("running: keyframe")
            .is_some()
            || harness.query_by_label_contains("Wrote ").is_some(),
        "the export runs the whole flower with progress"
    );
    wait_for_export(&mut harness, &rerun, Duration::from_secs(120));
    let names = exported_meshes(&rerun);
    assert!(names.contains(&"sepal-3".to_string()), "{names:?}");
    // The solver's opening, not the recorded one kept from before.
    assert_ne!(
        std::fs::read(&rerun).expect("written"),
        std::fs::read(&whole).expect("written")
    );
}

//! Autosave and recovery through the whole desktop app (egui_kittest): a
//! brush stroke is autosaved to the recovery folder without touching the
//! user's project, the app goes away without a clean exit (as after a
//! crash or `kill -9`), and the next launch offers the stroke back; the
//! user recovers it (or discards it), saves, and the recovery is gone.

use std::path::Path;
use std::time::{Duration, Instant};

use anthesis_app::desktop::{AnthesisApp, Command, ProjectEdit, Startup};
use anthesis_flower::Project;
use anthesis_flower::project::recovery::RecoveryFolder;
use anthesis_maps::MapKind;
use anthesis_maps::brush::{Brush, PaintTarget};
use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;

fn launch(
    project: Option<(Project, Option<std::path::PathBuf>)>,
    folder: &RecoveryFolder,
) -> Harness<'static, AnthesisApp> {
    let folder = folder.clone();
    Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .wgpu()
        .build_eframe(move |cc| {
            let mut app = AnthesisApp::new(
                cc,
                Startup {
                    project,
                    live: false,
                    restore: false,
                    warnings: Vec::new(),
                },
            )
            .expect("the app starts");
            app.enable_autosave(folder, Duration::ZERO);
            app
        })
}

fn stroke() -> Command {
    Command::Edit {
        label: "paint".into(),
        edit: ProjectEdit::Dabs {
            template: 0,
            key: 0,
            target: PaintTarget::Scalar(MapKind::EGrowth),
            brush: Brush::default(),
            dabs: vec![anthesis_maps::brush::StrokeDab {
                centre_in_uv: glam::DVec2::new(0.5, 0.6),
                direction_in_uv: glam::DVec2::Y,
            }],
        },
    }
}

/// Runs frames until the recovery folder holds a project equal to `want`.
fn wait_for_recovery(
    harness: &mut Harness<'_, AnthesisApp>,
    folder: &RecoveryFolder,
    want: &Project,
) {
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        harness.step();
        if let Some(found) = folder.find()
            && found.load().is_ok_and(|p| &p == want)
        {
            return;
        }
        assert!(
            Instant::now() < deadline,
            "the stroke was not autosaved; log: {:?}",
            harness.state().log()
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// `project` as a save and a load give it back: painted values are
/// quantised to the 16-bit PNGs once.
fn as_saved(project: &Project) -> Project {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("roundtrip.anthesis.toml");
    anthesis_flower::project::save_project(project, &path).expect("save");
    anthesis_flower::project::load_project(&path).expect("load")
}

fn saved_project(dir: &Path) -> (Project, std::path::PathBuf) {
    let project = anthesis_sim::fixtures::whorl(2, 8, 14, 5);
    let path = dir.join("mine/flower.anthesis.toml");
    anthesis_flower::project::save_project(&project, &path).expect("save");
    let project = anthesis_flower::project::load_project(&path).expect("load");
    (project, path)
}

#[test]
fn a_stroke_survives_a_crash_and_is_recovered_at_the_next_launch() {
    let dir = tempfile::tempdir().expect("tempdir");
    let folder = RecoveryFolder::new(dir.path().join("data/recovery"));
    let (project, path) = saved_project(dir.path());
    let on_disk = std::fs::read(&path).expect("read");

    let mut first = launch(Some((project.clone(), Some(path.clone()))), &folder);
    first.run();
    first.state_mut().apply(stroke());
    let painted = as_saved(first.state().project());
    assert_ne!(painted, project, "the stroke changed the map");
    wait_for_recovery(&mut first, &folder, &painted);
    // The user's own file is untouched.
    assert_eq!(std::fs::read(&path).expect("read"), on_disk);
    // A crash: the app is gone without its clean exit.
    std::mem::forget(first);

    // The next launch (which would reopen the saved project) offers the
    // stroke back, saying when it was saved.
    let mut second = launch(Some((project.clone(), Some(path.clone()))), &folder);
    second.run();
    let offer = second.state().recovery_offer().expect("an offer").clone();
    assert_eq!(offer.original.as_deref(), Some(path.as_path()));
    second.get_by_label("Recover unsaved work?");
    second.get_by_label_contains(
        "Changes to flower.anthesis.toml were saved for recovery less than a minute ago.",
    );
    second.snapshot("recovery_offer");
    second.get_by_label("Recover").click();
    second.run();
    let app = second.state();
    assert!(app.recovery_offer().is_none());
    assert_eq!(app.project(), &painted, "the stroke is back");
    assert!(app.document().is_dirty(), "recovered work is not yet saved");
    assert_eq!(app.document().path.as_deref(), Some(path.as_path()));

    // Saving puts the stroke in the user's file and removes the recovery.
    second.state_mut().apply(Command::Save);
    second.run();
    assert!(!second.state().document().is_dirty());
    assert_eq!(
        anthesis_flower::project::load_project(&path).expect("load"),
        painted
    );
    // The version saved over stays as a backup beside it.
    let backup = path
        .parent()
        .expect("folder")
        .join("backup/flower.anthesis.toml");
    assert_eq!(
        anthesis_flower::project::load_project(&backup).expect("backup"),
        project
    );
    let deadline = Instant::now() + Duration::from_secs(30);
    while folder.find().is_some() {
        assert!(Instant::now() < deadline, "the recovery stays after a save");
        second.step();
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn a_discarded_recovery_is_gone_and_the_opened_project_stays() {
    let dir = tempfile::tempdir().expect("tempdir");
    let folder = RecoveryFolder::new(dir.path().join("recovery"));
    let (project, path) = saved_project(dir.path());
    let mut first = launch(Some((project.clone(), Some(path.clone()))), &folder);
    first.run();
    first.state_mut().apply(stroke());
    let painted = as_saved(first.state().project());
    wait_for_recovery(&mut first, &folder, &painted);
    std::mem::forget(first);

    let mut second = launch(Some((project.clone(), Some(path.clone()))), &folder);
    second.run();
    second.get_by_label("Discard").click();
    second.run();
    assert!(second.state().recovery_offer().is_none());
    assert_eq!(second.state().project(), &project);
    assert!(!second.state().document().is_dirty());
    let deadline = Instant::now() + Duration::from_secs(30);
    while folder.find().is_some() {
        assert!(Instant::now() < deadline, "the discarded recovery stays");
        second.step();
        std::thread::sleep(Duration::from_millis(20));
    }
    // And a launch after that offers nothing.
    drop(second);
    let mut third = launch(Some((project, Some(path))), &folder);
    third.run();
    assert!(third.state().recovery_offer().is_none());
}

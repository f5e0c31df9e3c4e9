//! Issue 11 item 1 through the window, with the live solver: an edit
//! reaches the simulation as the app sends it (a command changes the
//! document, the project at its resolution goes to the worker, which edits
//! its last run), the run goes on from the first keyframe the edit can
//! change, and every keyframe the timeline then holds is the same, bit for
//! bit, as a run of that project from the bud. Undo and redo are edits
//! too: undoing a stroke gives the original run's keyframes back.

use std::time::{Duration, Instant};

use anthesis_app::desktop::session::RunStatus;
use anthesis_app::desktop::{AnthesisApp, Command, ProjectEdit, Startup};
use anthesis_flower::Project;
use anthesis_maps::MapKind;
use anthesis_maps::brush::{Brush, PaintTarget, StrokeDab};
use anthesis_sim::{Selection, run};
use eframe::egui;
use egui_kittest::Harness;

fn launch(project: Project) -> Harness<'static, AnthesisApp> {
    Harness::builder()
        .with_size(egui::vec2(1024.0, 700.0))
        .wgpu()
        .build_eframe(move |cc| {
            AnthesisApp::new(
                cc,
                Startup {
                    project: Some((project, None)),
                    live: true,
                    restore: false,
                    warnings: Vec::new(),
                },
            )
            .expect("the app starts")
        })
}

/// Runs frames until a run newer than `after` has finished; returns the
/// first keyframe it computed.
fn finish_run_after(harness: &mut Harness<'_, AnthesisApp>, after: u64) -> u32 {
    let deadline = Instant::now() + Duration::from_secs(600);
    loop {
        harness.step();
        let session = harness.state().session();
        if session.run() > after
            && let RunStatus::Finished { first_computed, .. } = session.status()
        {
            return *first_computed;
        }
        if let RunStatus::Failed { message } = session.status() {
            panic!("the run failed: {message}");
        }
        assert!(Instant::now() < deadline, "the run did not finish");
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// The timeline's keyframes, as bits.
fn shown(harness: &Harness<'_, AnthesisApp>) -> Vec<Vec<u64>> {
    harness
        .state()
        .session()
        .keyframes()
        .iter()
        .map(|k| k.bits())
        .collect()
}

/// Every keyframe of a run of the project the window simulates now, from
/// the bud.
fn from_the_bud(harness: &mut Harness<'_, AnthesisApp>) -> Vec<Vec<u64>> {
    let project = harness.state_mut().resolved_project();
    let mut keyframes = Vec::new();
    run(&project, &Selection::All, &mut |_, k| {
        keyframes.push(k.bits())
    })
    .expect("the run converges");
    keyframes
}

/// Applies `command` and lets its run finish; returns the first keyframe
/// the run computed.
fn apply(harness: &mut Harness<'_, AnthesisApp>, command: Command) -> u32 {
    let run = harness.state().session().run();
    harness.state_mut().apply(command);
    finish_run_after(harness, run)
}

#[test]
fn a_stroke_its_undo_and_redo_give_the_keyframes_of_runs_from_the_bud() {
    // Time keys at 40 and 50 as the lily's: a stroke on the late key
    // changes keyframes from 40 on.
    let project = anthesis_sim::fixtures::whorl(4, 6, 10, 44);
    let mut harness = launch(project);
    finish_run_after(&mut harness, 0);
    let original = from_the_bud(&mut harness);
    assert_eq!(shown(&harness), original);

    let stroke = Command::Edit {
        label: "paint".into(),
        edit: ProjectEdit::Dabs {
            template: 0,
            key: 1,
            target: PaintTarget::Scalar(MapKind::EGrowthIn),
            brush: Brush::default(),
            dabs: [0.7, 0.75, 0.8, 0.85]
                .map(|v| StrokeDab {
                    centre_in_uv: glam::DVec2::new(0.5, v),
                    direction_in_uv: glam::DVec2::Y,
                })
                .to_vec(),
        },
    };
    assert_eq!(apply(&mut harness, stroke), 40);
    let painted = from_the_bud(&mut harness);
    assert_ne!(painted[40..], original[40..], "the stroke changes the run");
    assert_eq!(shown(&harness), painted);

    assert_eq!(apply(&mut harness, Command::Undo), 40);
    assert_eq!(shown(&harness), original, "undone: the original run");
    assert_eq!(apply(&mut harness, Command::Redo), 40);
    assert_eq!(shown(&harness), painted, "redone: the painted run");

    // A colour is not simulated: every keyframe is kept.
    let mut recoloured = harness.state().project().flower.templates[1].clone();
    recoloured.colour = [0.2, 0.4, 0.9, 1.0];
    let edit = Command::Edit {
        label: "colour".into(),
        edit: ProjectEdit::Template {
            template: 1,
            value: Box::new(recoloured),
            keyframes: 44,
        },
    };
    assert_eq!(apply(&mut harness, edit), 45);
    assert_eq!(shown(&harness), painted);
}

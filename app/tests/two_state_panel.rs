//! The parameters panel's two-state section (issue 15 item 1): g, T and the
//! velocity curve of a two-state template, editable (each edit one undo
//! step, a `ProjectEdit::Template`) and plotted; a template made two-state
//! from the organ's shape at the keyframe shown.

use std::cell::RefCell;
use std::rc::Rc;

use anthesis_app::desktop::command::{Command, ProjectEdit};
use anthesis_app::desktop::two_state::{ViewedOrgan, open_shape_from_keyframe};
use anthesis_flower::{Project, TwoStateAnimation, joint_angle_after};
use anthesis_twostate::{GrowthFunction, VelocityCurve};
use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use glam::DVec3;

fn flower() -> Project {
    let mut project = anthesis_sim::fixtures::whorl(6, 8, 14, 20);
    project.name = "Two-state test flower".to_string();
    project
}

/// Organ 0 (template 0) at keyframe `k`, curled a little more each
/// keyframe, in the world frame, as a run would hand it out.
fn viewed(project: &Project, k: u32) -> ViewedOrgan {
    let organ = &project.flower.organs[0];
    let template = project.flower.template_of(0);
    let extra = joint_angle_after(&template.joint_schedule, k);
    ViewedOrgan {
        organ: 0,
        keyframe: k,
        positions_in_world: template
            .mesh
            .positions
            .iter()
            .map(|p| {
                let curled = *p + DVec3::new(0.0, 0.0, 0.01 * f64::from(k) * p.y * p.y);
                organ.placement.world_from_template(curled, extra)
            })
            .collect(),
    }
}

type Chosen = Rc<RefCell<Vec<Command>>>;

fn panel(project: Project, view: Option<ViewedOrgan>) -> (Harness<'static>, Chosen) {
    let chosen: Chosen = Rc::new(RefCell::new(Vec::new()));
    let sink = Rc::clone(&chosen);
    let harness = Harness::builder()
        .with_size(egui::vec2(320.0, 1000.0))
        .wgpu()
        .build_ui(move |ui| {
            sink.borrow_mut()
                .extend(anthesis_app::desktop::params::parameters_ui_viewing(
                    ui,
                    &project,
                    &project,
                    0,
                    view.as_ref(),
                ));
        });
    (harness, chosen)
}

/// The template edits chosen so far.
fn template_edits(chosen: &Chosen) -> Vec<(String, anthesis_flower::Template)> {
    chosen
        .borrow()
        .iter()
        .filter_map(|c| match c {
            Command::Edit {
                label,
                edit: ProjectEdit::Template { value, .. },
            } => Some((label.clone(), (**value).clone())),
            _ => None,
        })
        .collect()
}

#[test]
fn a_two_state_template_shows_g_t_and_the_velocity_curve_plotted() {
    let mut project = flower();
    let bud = project.flower.templates[0].mesh.clone();
    let open: Vec<DVec3> = bud
        .positions
        .iter()
        .map(|p| *p + DVec3::new(0.0, 0.0, 0.05 * p.y * p.y))
        .collect();
    project.flower.templates[0].two_state = Some(TwoStateAnimation {
        open,
        growth: GrowthFunction {
            g: 6.0,
            duration: 16.0,
        },
        velocity: VelocityCurve::Points(vec![[0.0, 0.0], [0.4, 0.8], [1.0, 1.0]]),
    });
    let (mut harness, chosen) = panel(project.clone(), Some(viewed(&project, 10)));
    harness.run();
    harness.get_by_label("Two-state opening");
    harness.get_by_label("Open shape from OBJ…");
    harness.get_by_label("Open shape from keyframe 10");
    harness.get_by_label("Grow instead");
    harness.get_by_label("— G(t)");
    harness.get_by_label("— velocity");
    // One joint ramp and three velocity points.
    assert_eq!(harness.query_all_by_label("Remove").count(), 4);
    harness.snapshot("parameters_two_state");

    // Following G again is one edit of the template.
    harness.get_by_label("velocity follows G").click();
    harness.run();
    let edits = template_edits(&chosen);
    assert_eq!(edits.len(), 1, "{:?}", chosen.borrow());
    assert_eq!(edits[0].0, "velocity curve of petal");
    let animation = edits[0].1.two_state.as_ref().expect("still two-state");
    assert_eq!(animation.velocity, VelocityCurve::FollowGrowth);
    assert_eq!(animation.growth.duration, 16.0);

    // "Grow instead" drops the open shape.
    chosen.borrow_mut().clear();
    harness.get_by_label("Grow instead").click();
    harness.run();
    let edits = template_edits(&chosen);
    assert_eq!(edits.len(), 1);
    assert!(edits[0].1.two_state.is_none());

    // The OBJ button asks for a file for this template.
    chosen.borrow_mut().clear();
    harness.get_by_label("Open shape from OBJ…").click();
    harness.run();
    assert!(
        chosen
            .borrow()
            .iter()
            .any(|c| matches!(c, Command::BrowseOpenShape(0))),
        "{:?}",
        chosen.borrow()
    );
}

#[test]
fn the_keyframe_shown_becomes_the_open_shape_in_the_template_frame() {
    let project = flower();
    assert!(project.flower.templates[0].two_state.is_none());
    let view = viewed(&project, 12);
    let (mut harness, chosen) = panel(project.clone(), Some(view.clone()));
    harness.run();
    harness.get_by_label("Grown by its maps (no open shape).");
    harness.get_by_label("Open shape from keyframe 12").click();
    harness.run();
    let edits = template_edits(&chosen);
    assert_eq!(edits.len(), 1, "{:?}", chosen.borrow());
    assert_eq!(edits[0].0, "open shape of petal");
    let animation = edits[0].1.two_state.as_ref().expect("two-state now");
    // The curl put in at keyframe 12, in the template frame.
    let bud = &project.flower.templates[0].mesh;
    for (got, p) in animation.open.iter().zip(&bud.positions) {
        let want = *p + DVec3::new(0.0, 0.0, 0.12 * p.y * p.y);
        assert!(got.distance(want) < 1e-9, "{got} vs {want}");
    }
    assert_eq!(animation.growth.duration, 20.0, "T is the run's keyframes");
    assert_eq!(animation.growth.g, 6.0);
    assert_eq!(
        open_shape_from_keyframe(&project, &project.flower.templates[0], &view).as_ref(),
        Some(&animation.open)
    );

    // The bud shown gives nothing to take.
    let (mut harness, _chosen) = panel(project.clone(), Some(viewed(&project, 0)));
    harness.run();
    assert!(
        harness
            .query_by_label("Open shape from keyframe …")
            .is_some()
    );

    // Nor does a run at another resolution (other vertices): the button
    // is there but disabled, and a click makes no edit.
    let mut remeshed = viewed(&project, 12);
    remeshed.positions_in_world.pop();
    assert!(open_shape_from_keyframe(&project, &project.flower.templates[0], &remeshed).is_none());
    let (mut harness, chosen) = panel(project.clone(), Some(remeshed));
    harness.run();
    harness.get_by_label("Open shape from keyframe 12").click();
    harness.run();
    assert!(template_edits(&chosen).is_empty(), "{:?}", chosen.borrow());
}

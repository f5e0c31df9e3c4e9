//! Sketching room (issue 40 items 1 and 4): the sketch, PDE and bud
//! editors open in a large canvas drawn by the same code as the panel's
//! (a stroke there lands in the same sketch), the left panel keeps its
//! width when Shape opens, and the mouse wheel over a canvas scrolls the
//! panel while Ctrl+wheel zooms the UV canvas.

use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use glam::DVec2;

use anthesis_app::desktop::AnthesisApp;

use super::{
    along, bend_at, builtin, canvas_at, click_settled, drag_by, draw_stroke, hard_brush_on_bend,
    harness, new_shape_template, opened_small_flower, settle, stroke_in_bud_view,
    wait_for_remesh_preview,
};

/// The right edge of the left panel: where its Flower tab ends.
fn left_panel_right(harness: &Harness<'_, AnthesisApp>) -> f32 {
    harness.get_by_label("Flower").rect().right()
}

/// The sketch of the small flower's petal being edited.
fn petal_sketch(harness: &Harness<'_, AnthesisApp>) -> anthesis_bud::PetalSketch {
    let name = &harness.state().project().flower.templates[0].name;
    harness
        .state()
        .flower_panel()
        .shape()
        .sketch()
        .sketch(name)
        .expect("a draft")
        .clone()
}

/// A mouse wheel event of `dy` points (negative: the content moves up, as
/// when scrolling down) with `modifiers`.
fn wheel(dy: f32, modifiers: egui::Modifiers) -> egui::Event {
    egui::Event::MouseWheel {
        unit: egui::MouseWheelUnit::Point,
        delta: egui::vec2(0.0, dy),
        phase: egui::TouchPhase::Move,
        source: egui::MouseWheelSource::Wheel,
        modifiers,
    }
}

/// Sends one wheel event at `at` and runs frames until the smoothed
/// wheel has been spent.
fn wheel_at(harness: &mut Harness<'_, AnthesisApp>, at: egui::Pos2, event: egui::Event) {
    harness.hover_at(at);
    settle(harness);
    harness.event(event);
    for _ in 0..8 {
        harness.step();
    }
    settle(harness);
}

#[test]
fn the_sketch_opens_in_a_large_canvas_whose_strokes_land_in_the_same_sketch() {
    let mut harness = opened_small_flower();
    harness.get_by_label("Flower").click();
    settle(&mut harness);
    let width = left_panel_right(&harness);
    click_settled(&mut harness, "Shape");
    wait_for_remesh_preview(&mut harness).expect("the petal remeshes");
    click_settled(&mut harness, "Sketch a new shape");
    assert_eq!(
        left_panel_right(&harness),
        width,
        "the left panel keeps its width with Shape and the sketch editor open"
    );
    let small = harness.get_by_label("sketch canvas").rect();

    // The large canvas: the editor moves into a window over the viewport.
    click_settled(&mut harness, "Large sketch canvas");
    assert!(harness.state().flower_panel().shape().sketch().large());
    let large = harness.get_by_label("sketch canvas").rect();
    assert!(
        large.width() > 2.0 * small.width() && large.height() > small.height(),
        "large {large:?} vs small {small:?}"
    );
    assert!(
        large.left() > left_panel_right(&harness),
        "over the viewport, not in the panel: {large:?}"
    );
    harness.get_by_label("Back to the panel");
    assert_eq!(left_panel_right(&harness), width);

    // The vein drawn in the large canvas: the draft's one stroke.
    let vein = along(12, |t| DVec2::new(0.0, 18.0 * t));
    draw_stroke(&mut harness, &vein);
    let drawn = petal_sketch(&harness);
    let strokes: Vec<&Vec<DVec2>> = [&drawn.left, &drawn.right, &drawn.vein]
        .into_iter()
        .filter(|s| !s.is_empty())
        .collect();
    assert_eq!(strokes.len(), 1, "one stroke: {drawn:?}");
    assert!(strokes[0][0].distance(vein[0]) < 0.2, "{}", strokes[0][0]);
    assert!(strokes[0].last().expect("points").distance(vein[12]) < 0.2);

    // Back in the panel: the same sketch, and the margins drawn there join
    // the stroke drawn in the large canvas.
    click_settled(&mut harness, "Back to the panel");
    assert!(!harness.state().flower_panel().shape().sketch().large());
    assert_eq!(
        harness.get_by_label("sketch canvas").rect().width(),
        small.width()
    );
    assert_eq!(petal_sketch(&harness), drawn);
    harness.get_by_label("sketch canvas").scroll_to_me();
    settle(&mut harness);
    let half_width = |t: f64| 1.0 + 3.5 * (std::f64::consts::PI * t).sin() - t;
    let right = along(16, |t| DVec2::new(half_width(1.0 - t), 18.0 * (1.0 - t)));
    let left = along(16, |t| DVec2::new(-half_width(t), 18.0 * t));
    draw_stroke(&mut harness, &right);
    let two = petal_sketch(&harness);
    draw_stroke(&mut harness, &left);
    let three = petal_sketch(&harness);
    // Sorted into their roles as when all three are drawn in the panel.
    for (got, want) in [
        (&three.left, &left),
        (&three.right, &right),
        (&three.vein, &vein),
    ] {
        assert!(got[0].distance(want[0]) < 0.2, "{} vs {}", got[0], want[0]);
        let last = got.last().expect("points");
        assert!(last.distance(*want.last().expect("points")) < 0.2, "{last}");
    }
    three
        .build()
        .expect("strokes from both canvases make one petal");

    // Undo stroke in the large canvas takes back the panel's last stroke:
    // one history for both.
    click_settled(&mut harness, "Large sketch canvas");
    click_settled(&mut harness, "Undo stroke");
    assert_eq!(petal_sketch(&harness), two);
}

#[test]
fn the_bud_view_opens_in_the_large_canvas_and_a_stroke_there_makes_the_bud() {
    let mut harness = harness(builtin("five-petal"));
    harness.get_by_label("Flower").click();
    settle(&mut harness);
    click_settled(&mut harness, "Sketched bud");
    let small = harness.get_by_label("bud side view").rect();
    click_settled(&mut harness, "Large bud canvas");
    assert!(harness.state().flower_panel().bud_sketch().large());
    let large = harness.get_by_label("bud side view").rect();
    assert!(
        large.width() > 2.0 * small.width(),
        "{large:?} vs {small:?}"
    );
    // A stroke there makes the bud, as in the panel.
    let stroke: Vec<DVec2> = (0..=24)
        .map(|k| {
            let t = f64::from(k) / 24.0;
            DVec2::new(4.0 + 6.0 * (1.4 * t).sin(), 22.0 * t)
        })
        .collect();
    stroke_in_bud_view(&mut harness, &stroke);
    let section = harness.state().flower_panel().bud_sketch();
    assert_eq!(section.problem(), None);
    assert_eq!(section.bud().expect("a bud").flower.organs.len(), 5);
    click_settled(&mut harness, "Back to the panel");
    assert!(!harness.state().flower_panel().bud_sketch().large());
}

#[test]
fn the_pde_editor_opens_in_the_large_canvas_and_its_points_drag_there() {
    let (mut harness, _) = new_shape_template("New PDE petal", "pde petal");
    // The remesh preview's answer moves the rows below it: wait for it
    // before clicking there.
    wait_for_remesh_preview(&mut harness).expect("the petal remeshes");
    let pde = |h: &Harness<'_, AnthesisApp>| {
        *h.state()
            .flower_panel()
            .shape()
            .pde()
            .sweep("pde petal")
            .expect("the sweep is shown")
    };
    let small = harness.get_by_label("Large PDE canvas").rect();
    click_settled(&mut harness, "Large PDE canvas");
    assert!(harness.state().flower_panel().shape().pde().large());
    let sweep = pde(&harness);
    // The upper point of margin 1, dragged to the left in the large view.
    let at = harness
        .state()
        .flower_panel()
        .shape()
        .pde()
        .point_on_screen(anthesis_bud::SweepCurve::Margin0, 2)
        .expect("drawn");
    assert!(at.x > small.right(), "in the window: {at:?}");
    drag_by(&mut harness, at, egui::vec2(-30.0, 0.0));
    let moved = pde(&harness);
    assert!(
        moved.curve0.control[2].x < sweep.curve0.control[2].x - 0.1,
        "{:?} -> {:?}",
        sweep.curve0.control[2],
        moved.curve0.control[2]
    );
    click_settled(&mut harness, "Back to the panel");
    assert!(!harness.state().flower_panel().shape().pde().large());
    assert_eq!(pde(&harness), moved, "the same draft in the panel");
}

#[test]
fn the_wheel_over_the_sketch_canvas_scrolls_the_panel_and_ctrl_wheel_zooms_it() {
    let mut harness = opened_small_flower();
    harness.get_by_label("Flower").click();
    settle(&mut harness);
    click_settled(&mut harness, "Shape");
    wait_for_remesh_preview(&mut harness).expect("the petal remeshes");
    click_settled(&mut harness, "Sketch a new shape");
    harness.get_by_label("sketch canvas").scroll_to_me();
    settle(&mut harness);
    let sketch = |h: &Harness<'_, AnthesisApp>, p: DVec2| {
        h.state()
            .flower_panel()
            .shape()
            .sketch()
            .sketch_to_screen(p)
            .expect("drawn")
    };
    let (a, b) = (
        sketch(&harness, DVec2::ZERO),
        sketch(&harness, DVec2::Y * 10.0),
    );
    let canvas = harness.get_by_label("sketch canvas").rect();
    wheel_at(
        &mut harness,
        canvas.center(),
        wheel(-120.0, egui::Modifiers::NONE),
    );
    let (c, d) = (
        sketch(&harness, DVec2::ZERO),
        sketch(&harness, DVec2::Y * 10.0),
    );
    assert!(c.y < a.y - 20.0, "the panel scrolled: {a:?} -> {c:?}");
    assert!(
        ((d - c) - (b - a)).length() < 1e-3,
        "the canvas did not zoom: {:?} vs {:?}",
        d - c,
        b - a
    );

    // Ctrl+wheel zooms the canvas about the pointer, and zooms back out
    // to the fitted view.
    harness.get_by_label("sketch canvas").scroll_to_me();
    settle(&mut harness);
    let (a, b) = (
        sketch(&harness, DVec2::ZERO),
        sketch(&harness, DVec2::Y * 10.0),
    );
    let at = a + egui::vec2(0.0, -30.0);
    wheel_at(&mut harness, at, wheel(120.0, egui::Modifiers::COMMAND));
    let (c, d) = (
        sketch(&harness, DVec2::ZERO),
        sketch(&harness, DVec2::Y * 10.0),
    );
    let zoom = (d - c).length() / (b - a).length();
    assert!(zoom > 1.3, "zoomed in: {zoom}");
    // The sketch point under the pointer stays there.
    let under = at.y + (a.y - at.y) * zoom;
    assert!((c.y - under).abs() < 1.0, "{} vs {under}", c.y);
    assert!((c.x - a.x).abs() < 1.0);
    wheel_at(&mut harness, at, wheel(-2000.0, egui::Modifiers::COMMAND));
    let (e, f) = (
        sketch(&harness, DVec2::ZERO),
        sketch(&harness, DVec2::Y * 10.0),
    );
    assert!(
        ((f - e) - (b - a)).length() < 1e-3,
        "back to the fitted view"
    );
    assert!((e - a).length() < 1e-3);
}

#[test]
fn the_wheel_over_the_uv_canvas_does_not_zoom_and_ctrl_wheel_does() {
    let mut harness = hard_brush_on_bend(0.25);
    let stroke = |h: &mut Harness<'_, AnthesisApp>, u: f32, v: f32| {
        let (from, to) = (canvas_at(h, u, v), canvas_at(h, u + 0.03, v));
        h.hover_at(from);
        h.run();
        h.drag_at(from);
        h.run();
        h.hover_at(to);
        h.run();
        h.drop_at(to);
        h.run();
    };
    // The wheel alone: the view stays, a stroke lands where it would have.
    let centre = harness.get_by_label("UV paint canvas").rect().center();
    harness.get_by_label_contains("Ctrl+wheel zooms");
    wheel_at(&mut harness, centre, wheel(-120.0, egui::Modifiers::NONE));
    stroke(&mut harness, 0.15, 0.15);
    assert!(bend_at(&harness, 0.16, 0.15) < 1e-6, "painted as unzoomed");

    // Ctrl+wheel zooms about the pointer: the same place on screen is
    // another place on the map.
    let centre = harness.get_by_label("UV paint canvas").rect().center();
    wheel_at(&mut harness, centre, wheel(120.0, egui::Modifiers::COMMAND));
    stroke(&mut harness, 0.8, 0.8);
    assert!(
        (bend_at(&harness, 0.81, 0.8) - 1.0).abs() < 1e-6,
        "zoomed: the stroke landed nearer the centre"
    );
}

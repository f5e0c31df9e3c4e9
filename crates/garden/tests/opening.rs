//! The paper's results (§6.1, §6.2), reproduced by simulating the default
//! projects for 100 keyframes and measuring them with
//! `anthesis_garden::shape`: the lily's tepals reflex early, led by the
//! midrib, around a cupped base, swollen near keyframe 75; one Eustoma bud
//! opens to a bell, a funnel or a shallow ball depending on the cultivar's
//! maps, the bell's tube and the funnel keeping their contorted overlap.

use std::time::Instant;

use anthesis_flower::Project;
use anthesis_garden::flowers::{self, Cultivar};
use anthesis_garden::shape::{FlowerShape, OrganShape, flower_shape, margin_overlap_deg};
use anthesis_sim::{Selection, run};

/// The keyframes the tests look at.
const FRAMES: [u32; 6] = [0, 25, 40, 50, 75, 100];

/// Shapes of the organs `organs` (indices into the project's organs, all
/// simulated together with `selection`) at [`FRAMES`].
fn shapes(project: &Project, selection: &Selection, organs: &[usize]) -> Vec<FlowerShape> {
    let started = Instant::now();
    let simulated: Vec<usize> = match selection {
        Selection::All => (0..project.flower.organs.len()).collect(),
        Selection::Only(i) => vec![*i],
    };
    let mut found = Vec::new();
    let result = run(project, selection, &mut |_, keyframe| {
        if FRAMES.contains(&keyframe.index) {
            let measured = flower_shape(organs.iter().map(|&organ| {
                let slot = simulated
                    .iter()
                    .position(|&s| s == organ)
                    .expect("organ simulated");
                (
                    &project.flower.template_of(organ).mesh,
                    keyframe.positions_in_world[slot].as_slice(),
                )
            }))
            .expect("measurable");
            found.push(measured);
        }
    });
    if let Err(error) = result {
        panic!("{}: {error}", project.name);
    }
    eprintln!(
        "{}: {} keyframes in {:.1} s",
        project.name,
        project.settings.keyframes,
        started.elapsed().as_secs_f64()
    );
    assert_eq!(found.len(), FRAMES.len());
    found
}

fn frame(shapes: &[FlowerShape], keyframe: u32) -> &OrganShape {
    let i = FRAMES.iter().position(|&f| f == keyframe).expect("kept");
    &shapes[i].mean
}

fn print(name: &str, shapes: &[FlowerShape]) {
    for (k, s) in FRAMES.iter().zip(shapes) {
        let m = &s.mean;
        eprintln!(
            "{name} kf {k:3}: angles {:6.1} {:6.1} {:6.1}  turning midrib {:6.1} lamina {:6.1}  cupping {:6.3} swelling {:6.3}  cone {:5.1}  radius {:5.1} {:5.1} {:5.1} {:5.1}",
            m.midrib_angles_deg[0],
            m.midrib_angles_deg[1],
            m.midrib_angles_deg[2],
            m.midrib_turning_deg,
            m.lamina_turning_deg,
            m.cupping,
            m.swelling,
            m.cone_angle_deg,
            m.radius_profile[0],
            m.radius_profile[1],
            m.radius_profile[2],
            m.radius_profile[3],
        );
    }
}

fn lily() -> Project {
    flowers::lily().expect("lily")
}

/// An Eustoma cultivar run whole: its shapes at [`FRAMES`] and, at each of
/// them, the smallest margin overlap of neighbouring petals (see
/// `anthesis_garden::shape`) at mid-height (`v = 0.4`).
struct EustomaRun {
    shapes: Vec<FlowerShape>,
    overlap_mid_deg: Vec<f64>,
}

fn eustoma(cultivar: Cultivar) -> EustomaRun {
    let project = flowers::eustoma(cultivar).expect("Eustoma");
    let mesh = &project.flower.templates[0].mesh;
    let mut run = EustomaRun {
        shapes: Vec::new(),
        overlap_mid_deg: Vec::new(),
    };
    let result = anthesis_sim::run(&project, &Selection::All, &mut |_, keyframe| {
        if !FRAMES.contains(&keyframe.index) {
            return;
        }
        let petals = &keyframe.positions_in_world;
        let smallest_overlap = |v: f64| {
            (0..petals.len())
                .map(|i| {
                    let next = (i + 1) % petals.len();
                    margin_overlap_deg((mesh, &petals[i]), (mesh, &petals[next]), v)
                        .expect("measurable")
                })
                .fold(f64::INFINITY, f64::min)
        };
        run.overlap_mid_deg.push(smallest_overlap(0.4));
        run.shapes
            .push(flower_shape(petals.iter().map(|p| (mesh, p.as_slice()))).expect("measurable"));
    });
    if let Err(error) = result {
        panic!("{}: {error}", project.name);
    }
    print(cultivar.folder_name(), &run.shapes);
    eprintln!(
        "{}: overlap at v 0.4 {:?}",
        cultivar.folder_name(),
        run.overlap_mid_deg
    );
    assert_eq!(run.shapes.len(), FRAMES.len());
    run
}

#[test]
fn lily_tepals_open_and_reflex_backwards() {
    let project = lily();
    let all = shapes(&project, &Selection::All, &[0, 1, 2, 3, 4, 5]);
    let petals: Vec<FlowerShape> = all.iter().map(|s| flower_shape_of(s, &[0, 1, 2])).collect();
    let sepals: Vec<FlowerShape> = all.iter().map(|s| flower_shape_of(s, &[3, 4, 5])).collect();
    print("lily petals", &petals);
    print("lily sepals", &sepals);
    for (what, shapes) in [("petals", &petals), ("sepals", &sepals)] {
        let bud = frame(shapes, 0);
        let open = frame(shapes, 100);
        // The bud is closed: tips lean in towards the axis, the midrib
        // curls in along its length.
        assert!(bud.midrib_angles_deg[2] < -10.0, "{what}: {bud:?}");
        assert!(bud.midrib_turning_deg < -60.0, "{what}: {bud:?}");
        // A strong early reflex (§6.1: "in the early stage of opening, the
        // midrib reflexes strongly"): by keyframe 40 every tepal's tip third
        // points below horizontal.
        let at_40 = FRAMES.iter().position(|&f| f == 40).expect("kept");
        for organ in &shapes[at_40].organs {
            assert!(organ.midrib_angles_deg[2] > 90.0, "{what} at 40: {organ:?}");
        }
        // "As the flower matures, the midrib gradually stops warping": once
        // the early growth has stopped, the tips turn at less than half the
        // early rate.
        let tip = |k: u32| frame(shapes, k).midrib_angles_deg[2];
        let early_rate = (tip(40) - tip(0)) / 40.0;
        let late_rate = (tip(100) - tip(50)) / 50.0;
        assert!(
            late_rate < 0.5 * early_rate,
            "{what}: {late_rate:.2}°/keyframe late vs {early_rate:.2}° early"
        );
        // Reflexed backwards around a cupped base: the tips point down, the
        // midrib turns outwards along its length, and the lower third stays
        // steep (a bowl, not a flat star).
        for organ in &shapes[FRAMES.len() - 1].organs {
            assert!(organ.midrib_angles_deg[2] > 120.0, "{what}: {organ:?}");
            assert!(organ.midrib_angles_deg[0] < 45.0, "{what}: {organ:?}");
        }
        assert!(open.midrib_turning_deg > 90.0, "{what}: {open:?}");
        // Laterally flat by then (the bud is cupped).
        assert!(open.cupping < 0.5 * bud.cupping, "{what}: {open:?}");
        // Opening is gradual: the tip angle grows keyframe by keyframe.
        let tips: Vec<f64> = shapes.iter().map(|s| s.mean.midrib_angles_deg[2]).collect();
        assert!(
            tips.windows(2).all(|w| w[1] > w[0]),
            "{what}: tips {tips:?}"
        );
    }
    // Petals and sepals open alike (§6.1).
    let (p, s) = (frame(&petals, 100), frame(&sepals, 100));
    assert!((p.midrib_angles_deg[2] - s.midrib_angles_deg[2]).abs() < 30.0);
}

/// The shape of some organs of a measured flower.
fn flower_shape_of(shape: &FlowerShape, organs: &[usize]) -> FlowerShape {
    FlowerShape::of_organs(organs.iter().map(|&i| shape.organs[i]).collect())
}

#[test]
fn lily_midrib_leads_and_swells_the_petal() {
    // One petal, as the paper's authors tuned a single petal first (§6.3),
    // against the same petal whose midrib grows like its lamina.
    let project = lily();
    let mut control = project.clone();
    control.flower.templates[0].maps =
        flowers::lily_maps(flowers::LilyExcess::PETAL.without_midrib_warping())
            .expect("control maps");
    let lily = shapes(&project, &Selection::Only(0), &[0]);
    let flat_midrib = shapes(&control, &Selection::Only(0), &[0]);
    print("lily petal", &lily);
    print("petal without midrib warping", &flat_midrib);
    // Early on the midrib warps more than the lamina beside it and pulls it
    // back ("midrib leads"): its turning has grown more since the bud.
    let bud = frame(&lily, 0);
    let early = frame(&lily, 25);
    let midrib_gain = early.midrib_turning_deg - bud.midrib_turning_deg;
    let lamina_gain = early.lamina_turning_deg - bud.lamina_turning_deg;
    assert!(
        midrib_gain > lamina_gain + 3.0,
        "midrib +{midrib_gain:.1}°, lamina +{lamina_gain:.1}°"
    );
    // The midrib's warping is what opens the petal early.
    let control_early = frame(&flat_midrib, 25);
    assert!(
        early.midrib_turning_deg > control_early.midrib_turning_deg + 15.0,
        "{early:?} vs {control_early:?}"
    );
    // Fig. 13: at keyframe 75 the petal is swollen by the midrib's
    // warping: the midrib has curled back further than the lamina either
    // side of it (without the warping the lamina leads), and the lamina
    // halves bulge inwards more than without it.
    let (at_75, control_75) = (frame(&lily, 75), frame(&flat_midrib, 75));
    let lead = |s: &OrganShape| s.midrib_turning_deg - s.lamina_turning_deg;
    assert!(lead(at_75) > 0.0, "{at_75:?}");
    assert!(
        lead(at_75) > lead(control_75) + 5.0,
        "{at_75:?} vs {control_75:?}"
    );
    assert!(
        at_75.swelling > control_75.swelling + 0.005,
        "swelling {:.3} vs {:.3} without the midrib",
        at_75.swelling,
        control_75.swelling
    );
}

#[test]
fn one_eustoma_bud_opens_to_a_bell_a_funnel_and_a_shallow_ball() {
    let bell = eustoma(Cultivar::MellowYellow);
    let funnel = eustoma(Cultivar::MaiteLady);
    let ball = eustoma(Cultivar::Pinocchio);
    // One bud.
    assert_eq!(frame(&bell.shapes, 0), frame(&funnel.shapes, 0));
    assert_eq!(frame(&bell.shapes, 0), frame(&ball.shapes, 0));
    let bud = frame(&bell.shapes, 0);
    let (b, f, p) = (
        frame(&bell.shapes, 100),
        frame(&funnel.shapes, 100),
        frame(&ball.shapes, 100),
    );

    // Mellow Yellow, a bell: the lower petal stays a steep tube and the
    // tips flare out and reflex below horizontal without rolling up (the
    // upper half turns outwards by less than half a turn).
    assert!(
        b.midrib_angles_deg[0] < 50.0 && b.midrib_angles_deg[1] < 40.0,
        "{b:?}"
    );
    assert!(b.midrib_angles_deg[2] > 95.0, "{b:?}");
    for petal in &bell.shapes[FRAMES.len() - 1].organs {
        assert!(petal.midrib_angles_deg[2] > 80.0, "{petal:?}");
        assert!(petal.upper_turning_deg < 170.0, "rolled up: {petal:?}");
    }
    // Its reflexing comes late (§6.2: the upper inner region grows late).
    assert!(frame(&bell.shapes, 50).midrib_angles_deg[2] < 30.0);

    // Maite Lady, a funnel: straight petals opening as a narrow cone, tips
    // not reflexed.
    assert!(f.midrib_turning_deg.abs() < 25.0, "not straight: {f:?}");
    assert!(
        (bud.cone_angle_deg + 4.0..35.0).contains(&f.cone_angle_deg),
        "cone angle {:.1} (bud {:.1})",
        f.cone_angle_deg,
        bud.cone_angle_deg
    );
    assert!(f.midrib_angles_deg[2] < 45.0, "{f:?}");

    // Pinocchio, a shallow ball: the base opens widest, the cupped petals
    // turn their tips back in.
    assert!(
        p.midrib_angles_deg[0] > f.midrib_angles_deg[0] + 20.0,
        "{p:?} vs {f:?}"
    );
    assert!(
        p.midrib_angles_deg[0] > b.midrib_angles_deg[0] + 20.0,
        "{p:?} vs {b:?}"
    );
    assert!(p.cupping > 0.12, "not cupped: {p:?}");
    assert!(
        p.midrib_angles_deg[2] < p.midrib_angles_deg[1] - 20.0,
        "tips not incurved: {p:?}"
    );
    assert!(p.midrib_turning_deg < -20.0, "{p:?}");

    // And they differ from each other as the paper's forms do: the funnel's
    // cone is far narrower than the ball's saucer-wide base, the bell's
    // tips reflex where the others' do not.
    assert!(p.cone_angle_deg > f.cone_angle_deg + 40.0, "{p:?} vs {f:?}");
    assert!(b.midrib_angles_deg[2] > f.midrib_angles_deg[2] + 40.0);
    assert!(b.midrib_angles_deg[2] > p.midrib_angles_deg[2] + 40.0);

    // The bell's tube and the funnel keep the bud's contorted overlap all
    // through the opening (seen from above, each petal's margin still lies
    // over its neighbour's at mid-height); the ball opens saucer-wide and
    // its petals part.
    for (name, run) in [("bell", &bell), ("funnel", &funnel)] {
        for (k, overlap) in FRAMES.iter().zip(&run.overlap_mid_deg) {
            assert!(*overlap > 2.0, "{name} kf {k}: overlap {overlap:.1}°");
        }
    }
    let parted = ball.overlap_mid_deg.last().expect("frames");
    assert!(*parted < 0.0, "ball: overlap {parted:.1}°");
}

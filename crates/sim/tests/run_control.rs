//! Single-organ mode, cancelling, typed errors for bad input and divergence,
//! and keyframe statistics.

mod common;

use anthesis_flower::Project;
use anthesis_maps::{GrowthMaps, KeyedMaps, ScalarMap};
use anthesis_mesh::MeshError;
use anthesis_sim::fixtures::whorl;
use anthesis_sim::{Selection, SimError, Simulation};
use common::run_all;
use glam::DVec3;

fn new_error(project: &Project, selection: &Selection) -> SimError {
    match Simulation::new(project, selection) {
        Ok(_) => panic!("Simulation::new accepted {selection:?}"),
        Err(e) => e,
    }
}

#[test]
fn only_one_organ_simulates_exactly_that_organ() {
    let project = whorl(4, 8, 14, 3);
    let sim = Simulation::new(&project, &Selection::Only(1)).expect("organ 1 exists");
    assert_eq!(sim.organs(), vec![project.flower.organs[1].name.as_str()]);
    assert_eq!(sim.organs(), vec!["sepal-1"]);
    let template = project.flower.template_of(1);
    assert_eq!(sim.triangles(0), template.mesh.triangles.as_slice());

    // The bud is organ 1 on the receptacle.
    let placement = project.flower.organs[1].placement;
    let bud = sim.bud();
    assert_eq!(bud.positions_in_world.len(), 1);
    let expected_bud: Vec<DVec3> = template
        .mesh
        .positions
        .iter()
        .map(|p| placement.world_from_template(*p, 0.0))
        .collect();
    assert_eq!(bud.positions_in_world[0], expected_bud);

    // Every keyframe is the one organ, exactly as if the flower had no
    // other organ.
    let (keyframes, error) = run_all(&project, &Selection::Only(1));
    assert_eq!(error, None);
    assert_eq!(keyframes.len(), 4);
    let mut alone = project.clone();
    alone.flower.organs = vec![project.flower.organs[1].clone()];
    alone.flower.overlaps.clear();
    let (alone_keyframes, error) = run_all(&alone, &Selection::All);
    assert_eq!(error, None);
    for (k, a) in keyframes.iter().zip(&alone_keyframes) {
        assert_eq!(k.positions_in_world.len(), 1);
        assert_eq!(
            k.positions_in_world, a.positions_in_world,
            "keyframe {}",
            k.index
        );
    }
    // And not like another organ.
    let (other, _) = run_all(&project, &Selection::Only(0));
    assert_ne!(other[3].positions_in_world, keyframes[3].positions_in_world);
}

#[test]
fn an_organ_index_out_of_range_is_no_such_organ() {
    let project = whorl(4, 8, 14, 3);
    assert_eq!(
        new_error(&project, &Selection::Only(4)),
        SimError::NoSuchOrgan(4)
    );
    assert_eq!(
        new_error(&project, &Selection::Only(usize::MAX)),
        SimError::NoSuchOrgan(usize::MAX)
    );
}

#[test]
fn cancelling_stops_the_step_with_cancelled() {
    let project = whorl(1, 8, 14, 5);
    let mut sim = Simulation::new(&project, &Selection::All).expect("valid project");
    let result = sim.step(&|| true, &mut |_| {});
    assert!(matches!(result, Err(SimError::Cancelled)), "{result:?}");

    // Cancelled while iterating: the progress seen before stops there.
    let mut sim = Simulation::new(&project, &Selection::All).expect("valid project");
    // The cancel check is polled from the threads the organs settle on.
    let polls = std::sync::atomic::AtomicU32::new(0);
    let mut reports = Vec::new();
    let result = sim.step(
        &|| polls.fetch_add(1, std::sync::atomic::Ordering::SeqCst) + 1 > 1,
        &mut |p| reports.push(p),
    );
    assert!(matches!(result, Err(SimError::Cancelled)), "{result:?}");
    assert_eq!(reports.len(), 1, "one iteration ran before the cancel");
    assert_eq!(reports[0].keyframe, 1);
    assert_eq!(reports[0].iteration, 0);
}

/// A run that must stop with a divergence error naming a keyframe and the
/// organ, after only finite keyframes.
fn assert_diverges(project: &Project, what: &str) -> SimError {
    let (keyframes, error) = run_all(project, &Selection::All);
    for k in &keyframes {
        assert!(
            k.positions_in_world.iter().flatten().all(|p| p.is_finite()),
            "{what}: keyframe {} has non-finite positions",
            k.index
        );
    }
    let error = error.unwrap_or_else(|| panic!("{what}: the run finished"));
    let (keyframe, organ) = match &error {
        SimError::Diverged {
            keyframe, organ, ..
        }
        | SimError::NotConverged {
            keyframe, organ, ..
        }
        | SimError::EnergyBlowUp {
            keyframe, organ, ..
        } => (*keyframe, organ.clone()),
        other => panic!("{what}: expected a divergence error, got {other:?}"),
    };
    assert_eq!(organ, "petal-1", "{what}");
    assert!(keyframe >= 1 && keyframe <= project.settings.keyframes);
    assert_eq!(
        keyframes.len() as u32,
        keyframe,
        "{what}: the keyframes before the failing one arrive"
    );
    let message = error.to_string();
    assert!(
        message.contains(&format!("keyframe {keyframe}")) && message.contains("petal-1"),
        "{what}: {message}"
    );
    error
}

#[test]
fn absurd_growth_ends_in_a_typed_error() {
    for dg in [40.0, -0.99] {
        let mut project = whorl(1, 8, 14, 20);
        project.flower.templates[0].dg = dg;
        assert_diverges(&project, &format!("dg {dg}"));
    }
}

#[test]
fn a_run_that_stops_at_an_organ_names_the_organs_it_was_against() {
    // Two petals, one driven through the other while both grow a third a
    // step: they jam within a few keyframes, and the message points the
    // painter at the neighbour that held the organ where it stopped. (At
    // the 60 degree drive a corner of the inner tip passes through the
    // outer petal first, which stops a run too: told to go on past that.)
    for drive_deg in [60.0, 200.0] {
        let mut project = common::inner_driven_into_outer_by(20, true, drive_deg);
        project.flower.templates[0].dg = 0.3;
        let (keyframes, _, error) = common::run_all_warned(&project, &Selection::All);
        let error = error.unwrap_or_else(|| panic!("drive {drive_deg}: the run finished"));
        let (organ, other) = match &error {
            SimError::Diverged { organ, .. }
            | SimError::NotConverged { organ, .. }
            | SimError::EnergyBlowUp { organ, .. } => (
                organ.clone(),
                if organ == "inner" { "outer" } else { "inner" },
            ),
            e => panic!("drive {drive_deg}: expected a stop at an organ, got {e:?}"),
        };
        let message = error.to_string();
        assert!(
            message.contains(&format!("organ `{organ}`: "))
                && message.contains(&format!("; it was against `{other}` "))
                && message.contains(" there: organs grown around"),
            "drive {drive_deg}: {message}"
        );
        assert!(keyframes.len() >= 2, "drive {drive_deg}: stopped at once");
    }
    // On its own nothing held it, and the message says nothing of it.
    let mut alone = whorl(1, 8, 14, 20);
    alone.flower.templates[0].dg = 40.0;
    let message = assert_diverges(&alone, "dg 40 alone").to_string();
    assert!(!message.contains("against"), "{message}");
}

#[test]
fn maps_that_collapse_the_organ_end_in_a_typed_error() {
    // Shrinking along the growth direction only, 20 % a step: triangles
    // flatten until the solver cannot go on.
    let mut project = whorl(1, 8, 14, 30);
    let template = &mut project.flower.templates[0];
    template.dg = -0.2;
    template.maps = KeyedMaps::single(GrowthMaps {
        e_growth: ScalarMap::constant(1.0),
        e_growth_in: ScalarMap::constant(1.0),
        w_growth: ScalarMap::constant(0.0),
        w_growth_in: ScalarMap::constant(0.0),
        ..GrowthMaps::uniform()
    });
    assert_diverges(&project, "collapse");
}

#[test]
fn bad_templates_and_meshes_are_refused_before_running() {
    let good = whorl(2, 8, 14, 3);

    let mut thin = good.clone();
    thin.flower.templates[1].thickness = 0.0;
    match new_error(&thin, &Selection::All) {
        SimError::BadTemplate { template, .. } => assert_eq!(template, "sepal"),
        other => panic!("thickness 0: {other:?}"),
    }
    // Only the selected organ's template matters.
    assert!(Simulation::new(&thin, &Selection::Only(0)).is_ok());

    let mut nan = good.clone();
    nan.flower.templates[0].mesh.positions[5].y = f64::NAN;
    assert_eq!(
        new_error(&nan, &Selection::All),
        SimError::BadMesh {
            template: "petal".into(),
            error: MeshError::NonFinitePosition { vertex: 5 },
        }
    );

    for (what, edit) in [
        (
            "dg NaN",
            (|t| t.dg = f64::NAN) as fn(&mut anthesis_flower::Template),
        ),
        ("dg -1", |t| t.dg = -1.0),
        ("no stretch stiffness", |t| t.stretch_stiffness = 0.0),
        ("thickness NaN", |t| t.thickness = f64::NAN),
        ("no base particles", |t| t.base_region.v_max = -1.0),
    ] {
        let mut bad = good.clone();
        edit(&mut bad.flower.templates[0]);
        match new_error(&bad, &Selection::All) {
            SimError::BadTemplate { template, .. } => assert_eq!(template, "petal", "{what}"),
            other => panic!("{what}: {other:?}"),
        }
    }
}

#[test]
fn keyframe_statistics_report_convergence() {
    let project = whorl(4, 8, 14, 20);
    let tolerance = project.settings.solver.relative_tolerance;
    let (keyframes, error) = run_all(&project, &Selection::All);
    assert_eq!(error, None);
    assert_eq!(keyframes.len(), 21);
    assert_eq!(keyframes[0].stats.iterations, 0);
    for (i, k) in keyframes.iter().enumerate().skip(1) {
        let s = &k.stats;
        assert_eq!((k.index, s.index), (i as u32, i as u32));
        assert!(
            s.relative_gradient <= tolerance,
            "keyframe {i}: gradient {:e} above the tolerance {tolerance:e}",
            s.relative_gradient
        );
        // Every step grows (the maps are non-zero from step 1), so the
        // solver has to move from the bud, where there is no past to
        // extrapolate from; later a keyframe may start within the tolerance
        // (the shape extrapolated through the last two or three).
        let least = if i == 1 { 1 } else { 0 };
        assert!(
            s.iterations >= least && s.iterations <= project.settings.solver.max_iterations,
            "keyframe {i}: {} iterations",
            s.iterations
        );
        assert!(
            s.energy.is_finite() && s.energy > 0.0,
            "keyframe {i}: {s:?}"
        );
        assert!(s.seconds.is_finite() && s.seconds >= 0.0);
    }
}

#[test]
fn a_run_that_fails_for_a_thin_petal_or_a_soft_stretch_names_the_value() {
    // The ranges `values_out_of_range` says are where runs settle: just
    // inside them the test whorl runs to the end, far outside it stops and
    // the message names the value.
    let base = whorl(1, 8, 14, 20);
    let length = anthesis_flower::scale::organ_length(&base.flower.templates[0].mesh);
    let run = |change: &dyn Fn(&mut anthesis_flower::Template)| {
        let mut project = base.clone();
        change(&mut project.flower.templates[0]);
        run_all(&project, &Selection::All)
    };
    let (keyframes, error) = run(&|t| t.thickness = length / 1990.0);
    assert_eq!(
        (keyframes.len(), error),
        (21, None),
        "1,990 thicknesses long"
    );
    let (_, error) = run(&|t| t.thickness = length / 100_000.0);
    let message = error
        .expect("a petal 100,000 thicknesses long stops")
        .to_string();
    assert!(
        message.contains("; thickness 0.000182 of `petal` is below the range where the solver converges (0.0091 to 1.82"),
        "{message}"
    );
    let kb = base.flower.templates[0].bend_stiffness;
    let (keyframes, error) = run(&|t| t.stretch_stiffness = kb / 3000.0);
    assert_eq!((keyframes.len(), error), (21, None), "Kb = 3,000 Ks");
    let (_, error) = run(&|t| t.stretch_stiffness = kb / 20_000.0);
    let message = error.expect("Kb = 20,000 Ks stops").to_string();
    assert!(
        message.contains("not converged") && message.contains("is 20,000 times its Ks"),
        "{message}"
    );
}

//! The fit on a small organ: a target grown from known coarse-basis maps
//! is recovered, the Levenberg–Marquardt steps lower the residual, and bad
//! or unreachable targets are said clearly.

use anthesis_fit::basis::{Grid, Layout, key_steps};
use anthesis_fit::{FitError, FitSettings, fit, read_target, simulate_final};
use anthesis_flower::Project;
use glam::DVec3;

const KEYFRAMES: u32 = 10;

/// One small petal (6 x 10 particles) of ten keyframes, with a growth scale
/// ten times the usual so that ten steps grow it visibly.
fn small_organ() -> Project {
    let mut project = anthesis_sim::fixtures::whorl(1, 6, 10, KEYFRAMES);
    project.flower.templates[0].dg = 0.03;
    project
}

fn layout(direction: Grid) -> Layout {
    Layout {
        growth: Grid {
            nodes_u: 1,
            nodes_v: 2,
        },
        direction,
        key_steps: key_steps(1, KEYFRAMES),
    }
}

fn settings(direction: Grid) -> FitSettings {
    FitSettings {
        growth_nodes: Grid {
            nodes_u: 1,
            nodes_v: 2,
        },
        direction_nodes: direction,
        max_iterations: 20,
        goal_rms: 1e-4,
        ..FitSettings::default()
    }
}

const NO_DIRECTION: Grid = Grid {
    nodes_u: 0,
    nodes_v: 0,
};

/// Node values of e, w, e-in, w-in (base, tip), then the direction's.
const KNOWN: [f64; 8] = [0.2, 0.8, 0.5, 0.3, 0.35, 0.95, 0.5, 0.45];

fn target_of(project: &Project, p: &[f64], layout: &Layout) -> Vec<DVec3> {
    let template = project.flower.template_of(0);
    let maps = layout
        .maps(p, (32, 32), &template.maps)
        .expect("maps of valid parameters");
    simulate_final(project, 0, maps, &|| false).expect("the known maps simulate")
}

#[test]
fn a_target_grown_from_known_basis_maps_is_recovered() {
    let project = small_organ();
    let layout = layout(NO_DIRECTION);
    let target = target_of(&project, &KNOWN, &layout);
    let mut seen = Vec::new();
    let result = fit(
        &project,
        0,
        &target,
        &settings(NO_DIRECTION),
        &mut |p| seen.push(p.rms),
        &|| false,
    )
    .expect("fits");
    // The closed-form guess is a guess; the iterations close the gap.
    assert!(result.guess_rms > 10.0 * result.rms, "{result:?}");
    assert!(result.rms < 3e-4, "RMS {} of the length", result.rms);
    assert!(result.reached());
    // Every accepted step lowered the residual.
    assert!(seen.windows(2).all(|w| w[1] <= w[0]), "{seen:?}");
    // The shape is that of the maps returned, and those are the known ones.
    let again = simulate_final(&project, 0, result.maps.clone(), &|| false).expect("simulates");
    let (rms, _) = anthesis_fit::distances(&again, &target, result.length);
    assert!((rms - result.rms).abs() < 1e-9);
    for (got, want) in result.parameters.iter().zip(KNOWN) {
        assert!(
            (got - want).abs() < 0.01,
            "{:?} vs {KNOWN:?}",
            result.parameters
        );
    }
}

#[test]
fn one_step_from_the_guess_lowers_the_residual_with_the_direction_fitted() {
    let project = small_organ();
    let direction = Grid {
        nodes_u: 2,
        nodes_v: 1,
    };
    let layout = layout(direction);
    // The growth direction turned by 0.3 rad one side, 0.1 the other.
    let mut known = KNOWN.to_vec();
    known.extend([0.3, -0.1]);
    let target = target_of(&project, &known, &layout);
    let result = fit(
        &project,
        0,
        &target,
        &FitSettings {
            max_iterations: 1,
            ..settings(direction)
        },
        &mut |_| {},
        &|| false,
    )
    .expect("fits");
    assert_eq!(result.iterations, 1);
    assert_eq!(result.parameters.len(), 10);
    assert!(
        result.rms < 0.5 * result.guess_rms,
        "one Gauss-Newton step: {} -> {}",
        result.guess_rms,
        result.rms
    );
}

#[test]
fn a_shape_the_bud_cannot_reach_gives_the_best_fit_and_its_error() {
    let project = small_organ();
    let bud = simulate_final(
        &project,
        0,
        anthesis_maps::KeyedMaps::single(anthesis_maps::GrowthMaps::uniform()),
        &|| false,
    )
    .expect("no growth simulates");
    // Three times as long: ten steps at the largest map value grow it 1.34x.
    let base = bud[0];
    let target: Vec<DVec3> = bud.iter().map(|p| base + 3.0 * (*p - base)).collect();
    let result = fit(
        &project,
        0,
        &target,
        &FitSettings {
            max_iterations: 3,
            ..settings(NO_DIRECTION)
        },
        &mut |_| {},
        &|| false,
    )
    .expect("an unreachable target is not an error");
    assert!(!result.reached());
    assert!(result.rms > 0.1, "{}", result.rms);
    let verdict = result.verdict();
    assert!(
        verdict.contains("cannot be grown to this target"),
        "{verdict}"
    );
    assert!(verdict.contains("best fit"), "{verdict}");
    // Full growth everywhere is as near as it gets.
    assert!(
        result.parameters[..4].iter().all(|&e| e > 0.9),
        "{:?}",
        result.parameters
    );
}

#[test]
fn another_mesh_or_a_nan_is_refused_with_a_clear_message() {
    let project = small_organ();
    let count = project.flower.template_of(0).mesh.vertex_count();
    let short = vec![DVec3::ZERO; count - 1];
    let error = fit(
        &project,
        0,
        &short,
        &FitSettings::default(),
        &mut |_| {},
        &|| false,
    )
    .expect_err("wrong vertex count");
    assert!(matches!(error, FitError::VertexCount { .. }));
    let text = error.to_string();
    assert!(text.contains(&format!("{} vertices", count - 1)), "{text}");
    assert!(text.contains(&format!("has {count}")), "{text}");

    let mut nan = vec![DVec3::ONE; count];
    nan[4].y = f64::NAN;
    let error = fit(
        &project,
        0,
        &nan,
        &FitSettings::default(),
        &mut |_| {},
        &|| false,
    )
    .expect_err("NaN");
    assert_eq!(
        error.to_string(),
        "target vertex 5 (from 1) has a coordinate that is not a finite number"
    );
}

#[test]
fn the_target_is_the_object_named_like_the_organ_or_the_only_one() {
    // A one-triangle organ.
    let mesh = anthesis_mesh::Mesh {
        positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
        uvs: vec![glam::DVec2::ZERO, glam::DVec2::X, glam::DVec2::Y],
        triangles: vec![[0, 1, 2]],
    };
    let two = "o receptacle\nv 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\no petal-1\nv 1 2 3\nv 4 5 6\nv 7 8 9\nf 5 6 4\n";
    let petal = read_target(two, "petal-1", &mesh).expect("named object, faces rotated");
    assert_eq!(petal[2], DVec3::new(7.0, 8.0, 9.0));
    let only = "o something\nv 1 2 3\nv 4 5 nan\nv 0 0 0\n";
    let error = read_target(only, "petal-1", &mesh).expect_err("NaN");
    assert!(error.to_string().contains("vertex 2"), "{error}");
    let error = read_target(two, "petal-9", &mesh).expect_err("no such object");
    assert!(error.to_string().contains("petal-9"), "{error}");
    let four = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n";
    let error = read_target(four, "petal-1", &mesh).expect_err("too many");
    assert!(error.to_string().contains("has 3"), "{error}");
    // As many vertices, other triangles: the winding turned over.
    let flipped = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 3 2\n";
    let error = read_target(flipped, "petal-1", &mesh).expect_err("other connectivity");
    assert!(matches!(error, FitError::Connectivity { .. }), "{error}");
    assert!(
        error
            .to_string()
            .contains("not organ `petal-1`'s triangles"),
        "{error}"
    );
    // Positions alone are taken as the organ's vertices in order.
    let bare = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    assert_eq!(
        read_target(bare, "petal-1", &mesh).expect("no faces").len(),
        3
    );
}

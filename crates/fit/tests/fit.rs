//! The fit on a small organ: a target grown from known coarse-basis maps
//! is recovered, the Levenberg–Marquardt steps lower the distance, a target
//! of another mesh (another resolution, shuffled, without UVs, moved) is
//! fitted by surface distance, and bad or unreachable targets and the
//! limits are said clearly.

use anthesis_fit::basis::{Grid, Layout, key_steps};
use anthesis_fit::{
    FitError, FitSettings, Similarity, Stop, Surface, Target, fit, read_target, register_target,
    simulate_final,
};
use anthesis_flower::Project;
use glam::{DQuat, DVec3};

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

fn shape_of(project: &Project, p: &[f64], layout: &Layout) -> Vec<DVec3> {
    let template = project.flower.template_of(0);
    let maps = layout
        .maps(p, (32, 32), &template.maps)
        .expect("maps of valid parameters");
    simulate_final(project, 0, maps, &|| false).expect("the known maps simulate")
}

/// A target of the organ's own mesh (positions in its vertex order).
fn own_mesh(project: &Project, positions: Vec<DVec3>) -> Target {
    let mesh = &project.flower.template_of(0).mesh;
    Target {
        surface: Surface::new(positions, mesh.triangles.clone()),
        uvs: Some(mesh.uvs.clone()),
        warnings: Vec::new(),
    }
}

fn target_of(project: &Project, p: &[f64], layout: &Layout) -> Target {
    own_mesh(project, shape_of(project, p, layout))
}

fn run(project: &Project, target: &Target, settings: &FitSettings) -> anthesis_fit::Fit {
    fit(
        project,
        0,
        target,
        Similarity::IDENTITY,
        settings,
        &mut |_| {},
        &|| false,
    )
    .expect("fits")
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
        Similarity::IDENTITY,
        &settings(NO_DIRECTION),
        &mut |p| seen.push(p.rms),
        &|| false,
    )
    .expect("fits");
    // The closed-form guess is a guess; the iterations close the gap.
    assert!(
        result.guess_rms > 10.0 * result.rms,
        "{} {}",
        result.guess_rms,
        result.rms
    );
    assert!(result.rms < 3e-4, "RMS {} of the length", result.rms);
    assert!(result.reached());
    // Every accepted step lowered the residual.
    assert!(seen.windows(2).all(|w| w[1] <= w[0]), "{seen:?}");
    // The shape is that of the maps returned, and those are the known ones.
    let again = simulate_final(&project, 0, result.maps.clone(), &|| false).expect("simulates");
    let triangles = &project.flower.template_of(0).mesh.triangles;
    let (rms, _) = anthesis_fit::distances(
        &again,
        triangles,
        &target,
        Similarity::IDENTITY,
        result.length,
    );
    assert!((rms - result.rms).abs() < 1e-9);
    // Within 0.03: the surface distance does not see the organ slide
    // along its own surface, which the known maps' positions pinned.
    for (got, want) in result.parameters.iter().zip(KNOWN) {
        assert!(
            (got - want).abs() < 0.03,
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
    let result = run(
        &project,
        &target,
        &FitSettings {
            max_iterations: 1,
            ..settings(direction)
        },
    );
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
    let target = own_mesh(&project, target);
    let result = run(&project, &target, &settings(NO_DIRECTION));
    assert!(!result.reached());
    assert_eq!(result.stop, Stop::Converged, "{:?}", result.parameters);
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
fn a_nan_and_a_target_without_triangles_are_refused_with_a_clear_message() {
    let project = small_organ();
    let count = project.flower.template_of(0).mesh.vertex_count();
    let mut nan = own_mesh(&project, vec![DVec3::ONE; count]);
    nan.surface.positions[4].y = f64::NAN;
    let error = fit(
        &project,
        0,
        &nan,
        Similarity::IDENTITY,
        &FitSettings::default(),
        &mut |_| {},
        &|| false,
    )
    .expect_err("NaN");
    assert_eq!(
        error.to_string(),
        "target vertex 5 (from 1) has a coordinate that is not a finite number"
    );
    let mesh = &project.flower.template_of(0).mesh;
    let error = read_target("v 0 0 0\nv 1 0 0\n", "petal-1", mesh).expect_err("no faces");
    assert!(matches!(error, FitError::NoFaces { .. }), "{error}");
    assert!(error.to_string().contains("no faces"), "{error}");
}

#[test]
fn the_target_is_the_object_named_like_the_organ_or_the_only_one() {
    // A one-triangle organ.
    let mesh = anthesis_mesh::Mesh {
        positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
        uvs: vec![glam::DVec2::ZERO, glam::DVec2::X, glam::DVec2::Y],
        triangles: vec![[0, 1, 2]],
    };
    let two = "o receptacle\nv 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\no petal-1\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 4 5 6 7\n";
    let petal = read_target(two, "petal-1", &mesh).expect("named object, a quad");
    assert_eq!(petal.vertex_count(), 4);
    assert_eq!(
        petal.surface.triangles.len(),
        2,
        "the quad is two triangles"
    );
    assert!(petal.uvs.is_none());
    let only = "o something\nv 1 2 3\nv 4 5 nan\nv 0 0 0\nf 1 2 3\n";
    let error = read_target(only, "petal-1", &mesh).expect_err("NaN");
    assert!(error.to_string().contains("vertex 2"), "{error}");
    let error = read_target(two, "petal-9", &mesh).expect_err("no such object");
    assert!(error.to_string().contains("petal-9"), "{error}");
    // A scan with a stray piece and a triangle without area: read, said.
    let stray = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nv 5 5 5\nv 6 5 5\nv 5 6 5\nv 7 5 5\nf 5 6 7\nf 5 6 8\n";
    let read = read_target(stray, "petal-1", &mesh).expect("a soup");
    assert_eq!(
        read.surface.triangles.len(),
        3,
        "the triangle without area left out"
    );
    assert_eq!(read.warnings.len(), 1, "{:?}", read.warnings);
    assert!(
        read.warnings[0].contains("not one clean surface"),
        "{:?}",
        read.warnings
    );
    assert!(
        read.warnings[0].contains("1 without area"),
        "{:?}",
        read.warnings
    );
    // UVs over the unit square are kept for the first guess.
    let uv = "v 0 0 0\nv 2 0 0\nv 0 2 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n";
    let read = read_target(uv, "petal-1", &mesh).expect("with UVs");
    assert_eq!(read.uvs.expect("UVs")[1], glam::DVec2::X);
    // Positions alone are taken as the organ's vertices in order.
    let bare = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let read = read_target(bare, "petal-1", &mesh).expect("no faces");
    assert_eq!(read.surface.triangles, mesh.triangles);
}

/// The small organ's project at a finer mesh (the same surface remeshed
/// through its UVs, as a finer resolution of the project is).
fn finer(project: &Project, factor: f64) -> Project {
    let template = project.flower.template_of(0);
    let edge = mean_edge(&template.mesh);
    let mut fine = project.clone();
    fine.settings.resolution = anthesis_flower::resolution::Resolution::MeanEdge(factor * edge);
    anthesis_flower::resolution::resolve(&fine).expect("remeshes")
}

fn mean_edge(mesh: &anthesis_mesh::Mesh) -> f64 {
    let (sum, count) = mesh.triangles.iter().fold((0.0, 0), |(s, c), t| {
        let [a, b, c3] = t.map(|v| mesh.positions[v as usize]);
        (s + a.distance(b) + b.distance(c3) + c3.distance(a), c + 3)
    });
    sum / count as f64
}

#[test]
fn a_target_of_another_mesh_is_fitted_by_surface_distance() {
    let project = small_organ();
    let layout = layout(NO_DIRECTION);
    // The organ grown from the known maps on a mesh of about twice as
    // many particles, in another vertex order.
    let fine = finer(&project, 0.7);
    let fine_mesh = fine.flower.template_of(0).mesh.clone();
    assert_ne!(
        fine_mesh.vertex_count(),
        project.flower.template_of(0).mesh.vertex_count()
    );
    let shape = shape_of(&fine, &KNOWN, &layout);
    let target = Target {
        surface: Surface::new(shape, fine_mesh.triangles.clone()),
        uvs: Some(fine_mesh.uvs.clone()),
        warnings: Vec::new(),
    };
    let result = run(&project, &target, &settings(NO_DIRECTION));
    // The two meshes' own shapes differ by their discretisation, so the
    // fit does not reach zero, but comes close and much closer than its
    // start.
    let figures = format!(
        "RMS {}, max {}, guess {}",
        result.rms, result.max, result.guess_rms
    );
    assert!(result.rms < 0.01, "{figures}");
    assert!(result.max < 0.04, "{figures}");
    assert!(result.rms < 0.5 * result.guess_rms, "{figures}");
    let triangles = &project.flower.template_of(0).mesh.triangles;
    let (rms, max) = anthesis_fit::distances(
        &result.shape,
        triangles,
        &target,
        Similarity::IDENTITY,
        result.length,
    );
    assert!((rms - result.rms).abs() < 1e-12 && (max - result.max).abs() < 1e-12);
}

#[test]
fn a_scan_in_its_own_frame_is_registered_and_fitted() {
    let mut project = small_organ();
    let layout = layout(NO_DIRECTION);
    let target = target_of(&project, &KNOWN, &layout);
    // The project's maps now: the known ones, each node 0.1 off, so its
    // current shape (what the scan is registered on) is not the target.
    let off: Vec<f64> = KNOWN
        .iter()
        .enumerate()
        .map(|(i, v)| v + if i % 2 == 0 { 0.1 } else { -0.1 })
        .collect();
    let template = project.flower.template_of(0);
    project.flower.templates[0].maps = layout.maps(&off, (32, 32), &template.maps).expect("maps");
    // The scan: moved and turned, vertices shuffled, no UVs.
    let motion = Similarity {
        rotation: DQuat::from_axis_angle(DVec3::new(1.0, 2.0, -0.5).normalize(), 2.0),
        scale: 1.0,
        translation: DVec3::new(30.0, -4.0, 12.0),
    };
    let n = target.vertex_count();
    let order: Vec<usize> = (0..n).map(|i| (i * 37 + 11) % n).collect();
    assert_eq!(
        {
            let mut sorted = order.clone();
            sorted.sort_unstable();
            sorted.dedup();
            sorted.len()
        },
        n,
        "a permutation"
    );
    let mut new_index = vec![0u32; n];
    for (new, &old) in order.iter().enumerate() {
        new_index[old] = new as u32;
    }
    let scan = Target {
        surface: Surface::new(
            order
                .iter()
                .map(|&old| motion.apply(target.surface.positions[old]))
                .collect(),
            target
                .surface
                .triangles
                .iter()
                .map(|t| t.map(|v| new_index[v as usize]))
                .collect(),
        ),
        uvs: None,
        warnings: Vec::new(),
    };
    let registered = register_target(&project, 0, &scan, false, &|| false).expect("registers");
    // Put back near where it was: the organ's current shape is not the
    // target's, so not exactly, but within a few per cent.
    let placement = registered.registration.placement;
    let worst = order
        .iter()
        .enumerate()
        .map(|(new, &old)| {
            placement
                .apply(scan.surface.positions[new])
                .distance(target.surface.positions[old])
        })
        .fold(0.0, f64::max);
    assert!(worst < 0.1 * registered.length, "{worst} {registered:?}");
    let result = fit(
        &project,
        0,
        &scan,
        placement,
        &FitSettings {
            refine_placement: true,
            ..settings(NO_DIRECTION)
        },
        &mut |_| {},
        &|| false,
    )
    .expect("fits");
    assert!(
        result.rms < 0.005,
        "RMS {}, max {}, {:?}",
        result.rms,
        result.max,
        result.stop
    );
    // The placement refined as the fit went still puts the scan back,
    // within what sliding along a surface so nearly reached allows
    // (measured: 2.0 % of the length at the worst vertex).
    let worst = order
        .iter()
        .enumerate()
        .map(|(new, &old)| {
            result
                .placement
                .apply(scan.surface.positions[new])
                .distance(target.surface.positions[old])
        })
        .fold(0.0, f64::max);
    assert!(worst < 0.03 * result.length, "{worst}");
}

#[test]
fn the_limits_say_they_stopped_the_fit() {
    let project = small_organ();
    let layout = layout(NO_DIRECTION);
    let target = target_of(&project, &KNOWN, &layout);
    // No iteration allowed: the first guess, said to be cut short, not
    // said to be out of the bud's reach.
    let result = run(
        &project,
        &target,
        &FitSettings {
            max_iterations: 0,
            ..settings(NO_DIRECTION)
        },
    );
    assert_eq!(result.stop, Stop::Iterations);
    assert_eq!(result.iterations, 0);
    let verdict = result.verdict();
    assert!(!verdict.contains("cannot be grown"), "{verdict}");
    assert!(verdict.contains("the iteration limit (0)"), "{verdict}");
    // No time at all: not even the first guess is simulated, and the
    // error says so (the time bounds the whole fit).
    let error = fit(
        &project,
        0,
        &target,
        Similarity::IDENTITY,
        &FitSettings {
            max_seconds: 1e-9,
            ..settings(NO_DIRECTION)
        },
        &mut |_| {},
        &|| false,
    )
    .expect_err("no time");
    assert!(matches!(error, FitError::OutOfTime { .. }), "{error}");
    assert!(
        error.to_string().contains("before the first guess"),
        "{error}"
    );
}

#[test]
fn a_flipped_target_has_its_inner_side_the_other_way() {
    let project = small_organ();
    let target = target_of(&project, &KNOWN, &layout(NO_DIRECTION));
    let normals =
        |t: &Target| anthesis_mesh::vertex_normals(&t.surface.positions, &t.surface.triangles);
    let before = normals(&target);
    let flipped = target.clone().flipped();
    assert_eq!(flipped.surface.positions, target.surface.positions);
    for (a, b) in before.iter().zip(normals(&flipped)) {
        assert!((*a + b).length() < 1e-12, "{a} {b}");
    }
}

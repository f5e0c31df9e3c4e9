use super::*;
use anthesis_mesh::Topology;
use anthesis_mesh::generate::test_petal;

/// A test petal's particles and its elastic model at rest there.
fn petal_at_rest() -> (Vec<DVec3>, Elastic) {
    let mesh = test_petal(30.0, 12.0, 9, 17);
    let topology = Topology::build(&mesh).expect("manifold");
    let elastic = Elastic::at_rest(&mesh.positions, &topology);
    (mesh.positions, elastic)
}

/// A petal's Hessian away from rest (springs and hinges both bent),
/// factorised, and a gradient.
fn factorised_petal() -> (NewtonSolver, Elastic) {
    let (positions, elastic) = petal_at_rest();
    let moved: Vec<DVec3> = positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let t = i as f64;
            *p + DVec3::new((1.3 * t).sin(), (0.7 * t).cos(), (2.1 * t).sin()) * 0.3
        })
        .collect();
    let mut solver = NewtonSolver::new(moved.len(), &elastic).expect("analysis");
    solver
        .factorize(&elastic, &[], &moved)
        .expect("positive definite");
    for (i, g) in solver.gradient.iter_mut().enumerate() {
        let t = i as f64;
        *g = DVec3::new(t.sin(), (3.0 * t).cos(), 1.0 - 0.01 * t);
    }
    (solver, elastic)
}

#[test]
fn the_matrix_handed_over_in_order_factorises_as_when_faer_orders_it() {
    let (solver, _) = factorised_petal();
    // faer permuting the same (single-precision) matrix into its AMD
    // order itself.
    let pattern = &solver.pattern;
    let n = pattern.dimension();
    let structure =
        SymbolicSparseColMatRef::new_checked(n, n, pattern.col_ptr(), None, pattern.row_idx());
    let symbolic = factorize_symbolic_cholesky(
        structure,
        Side::Upper,
        SymmetricOrdering::Amd,
        CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        },
    )
    .expect("analysis");
    assert_eq!(symbolic.len_val(), solver.factor.len(), "the same fill");
    let mut memory =
        MemBuffer::new(symbolic.factorize_numeric_llt_scratch::<f32>(Par::Seq, Default::default()));
    let values: Vec<f32> = solver.hessian.iter().map(|&v| v as f32).collect();
    let mut factor = vec![0.0f32; symbolic.len_val()];
    symbolic
        .factorize_numeric_llt(
            &mut factor,
            SparseColMatRef::new(structure, &values[..]),
            Side::Upper,
            LltRegularization::default(),
            Par::Seq,
            MemStack::new(&mut memory),
            Default::default(),
        )
        .expect("positive definite");
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&solver.factor), bits(&factor));
}

#[test]
fn a_fresh_direction_solves_the_newton_system_to_the_target() {
    let (mut solver, _) = factorised_petal();
    let n = solver.pattern.dimension();
    let residual = |solver: &NewtonSolver| -> f64 {
        let mut product = vec![0.0; n];
        solver
            .pattern
            .multiply(&solver.hessian, &solver.direction, &mut product);
        (0..n)
            .map(|i| (product[i] + solver.gradient[i / 3][i % 3]).abs())
            .fold(0.0, f64::max)
    };
    // One iteration (the single-precision factor's own direction,
    // scaled) leaves a residual far above a millionth of the gradient ...
    solver.solve(f64::INFINITY).expect("finite");
    let unrefined = residual(&solver);
    let target = 1e-6;
    assert!(unrefined > 10.0 * target, "{unrefined:e}");
    // ... which refinement brings below it, (H + mu I) d = -g.
    solver.solve(target).expect("finite");
    let refined = residual(&solver);
    assert!(refined <= target, "{refined:e} (unrefined {unrefined:e})");
}

/// A contact holding particle 0 above the plane y = 0 (offset 0).
fn floor() -> Contact {
    Contact {
        particle: 0,
        point: DVec3::ZERO,
        normal: DVec3::Y,
        offset: 0.0,
        weight: 1.0,
    }
}

#[test]
fn the_factor_holds_the_contacts_violated_where_it_was_made() {
    let (mut positions, mut elastic) = petal_at_rest();
    elastic.contact_stiffness = 1000.0;
    // A plane through particle 0 with particle 0 a hair on its wrong
    // side, and one through particle 1 with particle 1 on its side.
    let plane = |p: u32, offset: f64| Contact {
        particle: p,
        point: positions[p as usize],
        normal: DVec3::Z,
        offset,
        weight: 1.0,
    };
    let contacts = [plane(0, 1e-3), plane(1, -1e-3)];
    let mut solver = NewtonSolver::new(positions.len(), &elastic).expect("analysis");
    solver
        .factorize(&elastic, &contacts, &positions)
        .expect("positive definite");
    assert_eq!(solver.held, vec![contacts[0]], "the violated one only");
    assert!(solver.holds(&contacts, &positions));
    // Each particle moving within its side keeps the factor ...
    positions[0].z -= 1e-4;
    positions[1].z += 1e-4;
    assert!(solver.holds(&contacts, &positions));
    // ... particle 0 leaving its contact makes it stale ...
    positions[0].z += 2e-3;
    assert!(!solver.holds(&contacts, &positions));
    // ... and so does particle 1 entering its own.
    positions[0].z -= 2e-3;
    positions[1].z -= 3e-3;
    assert!(!solver.holds(&contacts, &positions));
}

#[test]
fn a_keyframe_converges_only_once_the_remaining_step_is_small() {
    // A petal at rest held by weak anchors (a thousandth of an edge's
    // stiffness) at targets half an edge along x: moving the whole
    // petal costs only the anchors, a soft mode. Off its targets by
    // d, every particle feels a force of 1e-3 F d / edge, below the
    // force tolerance (1e-5 F) for any d under a hundredth of an edge,
    // while the step back is d for every particle.
    let (bud, mut elastic) = petal_at_rest();
    let force = elastic.force_scale();
    let edge = elastic.rest_lengths.iter().sum::<f64>() / elastic.rest_lengths.len() as f64;
    elastic.anchor_stiffness = 1e-3 * force / edge;
    let targets: Vec<DVec3> = bud.iter().map(|p| *p + DVec3::X * 0.5 * edge).collect();
    elastic.anchors = targets
        .iter()
        .enumerate()
        .map(|(i, t)| (i as u32, *t))
        .collect();
    let settings = SolverSettings::default();
    let mut solver = NewtonSolver::new(bud.len(), &elastic).expect("analysis");
    solver.begin_keyframe();
    let mut positions = bud.clone();
    let first = solver
        .step(&elastic, &[], &mut positions, &settings)
        .expect("a step");
    assert!(!first.converged, "half an edge off its targets it moves");
    // 0.6 % of an edge short of the targets: within the force
    // tolerance, more than REMAINING_STEP of the petal's size from them.
    let short = 6e-3 * edge;
    assert!(short > 1.5 * REMAINING_STEP * elastic.size());
    for (p, t) in positions.iter_mut().zip(&targets) {
        *p = *t - DVec3::X * short;
    }
    let off = solver
        .step(&elastic, &[], &mut positions, &settings)
        .expect("a step");
    assert!(
        off.relative_gradient < settings.relative_tolerance,
        "{}: the forces alone would call this converged",
        off.relative_gradient
    );
    assert!(!off.converged, "0.6 % of an edge off its targets");
    let last = solver
        .step(&elastic, &[], &mut positions, &settings)
        .expect("a step");
    assert!(last.converged);
    let left = positions
        .iter()
        .zip(&targets)
        .map(|(p, t)| p.distance(*t))
        .fold(0.0, f64::max);
    assert!(
        left <= REMAINING_STEP * elastic.size(),
        "{left} from the targets, {short} before the last step"
    );
}

#[test]
fn a_step_refactorises_when_the_last_one_left_a_contact() {
    // A petal held at rest by weak springs on every particle (anchors),
    // one of them pulled a tenth of an edge away, and its tip particle a hair
    // inside a contact that a twentieth of that pull draws it off.
    // The first step (fresh factor, contact held) brings the largest
    // force down twentyfold but barely moves the tip, which leaves the
    // contact: modified Newton would keep that factor (the gradient
    // fell more than tenfold), whose stiff penalty pins the tip, for a
    // step that leaves its force as it is.
    let (bud, mut elastic) = petal_at_rest();
    elastic.contact_stiffness = 1000.0;
    elastic.anchor_stiffness = 1.0;
    let by_y = |a: &usize, b: &usize| bud[*a].y.total_cmp(&bud[*b].y);
    let tip = (0..bud.len()).max_by(by_y).expect("particles");
    let base = (0..bud.len()).min_by(by_y).expect("particles");
    let mut positions = bud.clone();
    for (i, p) in positions.iter().enumerate() {
        let pull = match i {
            _ if i == tip => DVec3::Z * 0.01,
            _ if i == base => DVec3::X * 0.2,
            _ => DVec3::ZERO,
        };
        elastic.anchors.push((i as u32, *p + pull));
    }
    let contacts = [Contact {
        particle: tip as u32,
        point: positions[tip],
        normal: DVec3::Z,
        offset: 1e-6,
        weight: 1.0,
    }];
    assert!(contacts[0].violation(positions[tip]) > 0.0);
    let settings = SolverSettings::default();
    let mut solver = NewtonSolver::new(positions.len(), &elastic).expect("analysis");
    solver.begin_keyframe();
    let first = solver
        .step(&elastic, &contacts, &mut positions, &settings)
        .expect("a step");
    assert!(contacts[0].violation(positions[tip]) < 0.0, "the tip left");
    let second = solver
        .step(&elastic, &contacts, &mut positions, &settings)
        .expect("a step");
    assert!(
        second.relative_gradient < 0.1 * first.relative_gradient,
        "{} after {}: a fall that keeps an unchanged factor",
        second.relative_gradient,
        first.relative_gradient
    );
    assert_eq!(solver.factorisations(), 2, "a fresh factor without it");
    let third = solver
        .step(&elastic, &contacts, &mut positions, &settings)
        .expect("a step");
    assert!(
        third.relative_gradient < 0.1 * second.relative_gradient,
        "{} after {}: the tip moved",
        third.relative_gradient,
        second.relative_gradient
    );
}

#[test]
fn a_step_from_an_evaluated_start_is_the_step_that_evaluates_it() {
    // A bent petal with its base anchored and a contact violated: steps
    // from a start evaluated by `evaluate_start` (the elastic energy,
    // gradient and Hessian kept, the penalties added by the step and
    // its factorisation) give the bits of plain steps, also
    // when the positions moved in between (the start is not used) and
    // in the keyframe after that (no gradient kept). So do the steps
    // after the first, which start at the trial the line search
    // accepted with its gradient kept, also when the contacts change
    // in between (the penalties are added by the step) or the
    // positions move (the gradient is evaluated afresh). The plain
    // solver forgets every kept evaluation before each step.
    let (bud, mut elastic) = petal_at_rest();
    elastic.contact_stiffness = 1000.0;
    elastic.anchor_stiffness = 100.0;
    elastic.anchors = (0..9).map(|i| (i, bud[i as usize])).collect();
    let bent: Vec<DVec3> = bud
        .iter()
        .map(|p| *p + DVec3::Z * (0.002 * p.y * p.y))
        .collect();
    let tip = bent.len() - 1;
    let contacts = [Contact {
        particle: tip as u32,
        point: bent[tip] + DVec3::Z * 0.01,
        normal: DVec3::Z,
        offset: 0.0,
        weight: 1.0,
    }];
    let settings = SolverSettings::default();
    let bits = |x: &[DVec3]| {
        x.iter()
            .map(|p| p.to_array().map(f64::to_bits))
            .collect::<Vec<_>>()
    };
    let mut plain = NewtonSolver::new(bud.len(), &elastic).expect("analysis");
    let mut started = NewtonSolver::new(bud.len(), &elastic).expect("analysis");
    // Keyframes starting where the start was evaluated, one starting
    // elsewhere, then two more (the first without a kept gradient).
    let mut from_trials = 0;
    for (keyframe, moved) in [(0, false), (1, false), (2, true), (3, false), (4, false)] {
        let mut start = bent.clone();
        start[tip].z -= 0.001 * keyframe as f64;
        let (mut x, mut y) = (start.clone(), start.clone());
        plain.begin_keyframe();
        started.begin_keyframe();
        let energy = started.evaluate_start(&elastic, &y);
        assert_eq!(energy.to_bits(), elastic.elastic_energy(&y).to_bits());
        let kept = started.start.map(|(_, kept)| kept);
        let expected = if keyframe == 3 {
            Kept::Energy
        } else {
            Kept::GradientAndHessian
        };
        assert_eq!(kept, Some(expected), "keyframe {keyframe}: gradient kept");
        if moved {
            x[3].x += 1e-3;
            y[3].x += 1e-3;
        }
        for i in 0..4 {
            // The contact released in the second step.
            let contacts = if i == 1 { &contacts[..0] } else { &contacts };
            if keyframe == 4 && i == 2 {
                x[5].y += 1e-4;
                y[5].y += 1e-4;
            }
            if i > 0 && matches!(started.start, Some((_, Kept::Gradient))) {
                from_trials += 1;
            }
            plain.start = None;
            let a = plain.step(&elastic, contacts, &mut x, &settings);
            let b = started.step(&elastic, contacts, &mut y, &settings);
            assert_eq!(a, b, "keyframe {keyframe} step {i}");
            assert_eq!(bits(&x), bits(&y), "keyframe {keyframe} step {i}");
        }
        assert_eq!(started.started_there, !moved, "keyframe {keyframe}");
        assert_eq!(started.factorisations(), plain.factorisations());
    }
    assert!(
        from_trials >= 5,
        "{from_trials} steps from an accepted trial"
    );
}

#[test]
fn the_first_fraction_is_the_minimum_of_the_model_with_the_crossed_contact() {
    // The particle at height a moves by -b along y (b > a): the full
    // step crosses the floor by b - a. Model derivative:
    // slope (1 - t) + k (t b - a) b = 0  =>  t = (-slope + k a b) / (k b² - slope).
    let (a, b, k, slope) = (0.2, 1.0, 50.0, -3.0);
    let positions = [DVec3::new(0.0, a, 0.0)];
    let direction = [0.0, -b, 0.0];
    let t = first_fraction(k, &[floor()], &positions, &direction, slope);
    let expected = (-slope + k * a * b) / (k * b * b - slope);
    assert!((t - expected).abs() < 1e-12, "{t} against {expected}");
    assert!(
        t > a / b && t < 1.0,
        "just past the floor, short of the full step"
    );
}

#[test]
fn a_step_that_crosses_no_contact_or_a_violated_one_starts_whole() {
    let k = 50.0;
    // Stays above the floor.
    let t = first_fraction(k, &[floor()], &[DVec3::Y], &[0.0, -0.5, 0.0], -1.0);
    assert_eq!(t, 1.0);
    // Already below it: the Hessian holds that contact already.
    let t = first_fraction(k, &[floor()], &[-DVec3::Y], &[0.0, -0.5, 0.0], -1.0);
    assert_eq!(t, 1.0);
    // No contacts.
    assert_eq!(
        first_fraction(k, &[], &[DVec3::Y], &[0.0, -5.0, 0.0], -1.0),
        1.0
    );
}

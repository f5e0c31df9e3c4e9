use glam::DVec3;

use super::*;

fn curve(f: impl Fn(f64) -> DVec3, intervals: usize) -> NodalCurve {
    NodalCurve::sample(f, intervals)
}

const MATERIAL: Dynamics = Dynamics {
    bend: 1.0,
    stretch: 4.0,
    mass: 2.0,
};

/// A generator bending out and curling, as a tepal's does when it opens.
fn opening(u: f64) -> DVec3 {
    DVec3::new(0.3 * u, 1.5 * u * u, (std::f64::consts::PI * u).sin() * 0.8)
}

#[test]
fn the_banded_cholesky_solves_a_pentadiagonal_system() {
    let n = 9;
    let main: Vec<f64> = (0..n).map(|i| 7.0 + i as f64 * 0.3).collect();
    let off1: Vec<f64> = (0..n - 1).map(|i| -2.0 + 0.1 * i as f64).collect();
    let off2: Vec<f64> = (0..n - 2).map(|i| 0.5 - 0.05 * i as f64).collect();
    let a = Banded::new(main.clone(), off1.clone(), off2.clone());
    let x: Vec<DVec3> = (0..n)
        .map(|i| DVec3::new(i as f64, 1.0 - i as f64 * 0.5, (i * i) as f64 * 0.1))
        .collect();
    // b = A x, row by row from the bands.
    let b: Vec<DVec3> = (0..n)
        .map(|i| {
            let mut s = main[i] * x[i];
            if i >= 1 {
                s += off1[i - 1] * x[i - 1];
            }
            if i + 1 < n {
                s += off1[i] * x[i + 1];
            }
            if i >= 2 {
                s += off2[i - 2] * x[i - 2];
            }
            if i + 2 < n {
                s += off2[i] * x[i + 2];
            }
            s
        })
        .collect();
    let solved = a.cholesky().solve(&b);
    for (got, want) in solved.iter().zip(&x) {
        assert!((*got - *want).length() < 1e-12, "{got} {want}");
    }
}

#[test]
fn with_no_change_between_the_states_every_in_between_is_that_state() {
    // d0 = d1: the force of eq. (20) is the static force of d1, so the
    // scheme must hold it exactly at every time level (a stencil, ghost
    // node or right-hand side wrong anywhere would move it).
    let state = curve(opening, 20);
    let run = in_between(&state, &state, MATERIAL, 10, 1e-12, 0).expect("runs");
    assert_eq!(run.frames.len(), 11);
    assert_eq!(run.correction.corrections, 0);
    for frame in &run.frames {
        for (got, want) in frame.iter().zip(&state.values) {
            assert!((*got - *want).length() < 1e-9, "{got} {want}");
        }
    }
}

/// The generator's slowest mode with the ends held (end and ghost nodes
/// 0): the eigenvector of the interior matrix of smallest eigenvalue, by
/// inverse iteration, as a deformation along `direction` with its
/// eigenvalue.
fn slowest_mode(n: usize, dynamics: Dynamics, direction: DVec3) -> (NodalCurve, f64) {
    let zero = curve(|_| DVec3::ZERO, n);
    let scheme = Scheme::new(&zero, &zero, dynamics);
    let factor = scheme.matrix(0.0).cholesky();
    let mut x: Vec<DVec3> = (1..n).map(|i| DVec3::splat((i * (n - i)) as f64)).collect();
    for _ in 0..200 {
        x = factor.solve(&x);
        let norm = x.iter().map(|v| v.x * v.x).sum::<f64>().sqrt();
        x.iter_mut().for_each(|v| *v /= norm);
    }
    // Rayleigh quotient with the stiffness stencil.
    let mut values = vec![DVec3::ZERO; n + 1];
    for (k, v) in x.iter().enumerate() {
        values[k + 1] = direction * v.x;
    }
    let ends = [DVec3::ZERO; 4];
    let kx: f64 = (1..n)
        .map(|i| scheme.stiffness_times(&values, &ends, i).dot(values[i]))
        .sum();
    let xx: f64 = values.iter().map(|v| v.length_squared()).sum();
    let h = 1.0 / n as f64;
    let mode = NodalCurve {
        // The ghost nodes d1 - 2h s and d(I-1) + 2h s' come out 0.
        slope_start: values[1] / (2.0 * h),
        slope_end: -values[n - 1] / (2.0 * h),
        values,
    };
    (mode, kx / xx)
}

#[test]
fn one_mode_follows_the_known_solution_and_converges_in_time() {
    // d1 = the slowest mode, ends held: the force of eq. (20) is
    // (λ + 2m) d1 and every in-between is the mode times x(t), where
    // m x'' + λ x = λ + 2m, x(0) = x'(0) = 0:
    // x(t) = (1 + 2m/λ)(1 − cos ωt), ω = sqrt(λ/m).
    let dynamics = Dynamics {
        bend: 1.0,
        stretch: 4.0,
        mass: 20.0,
    };
    let n = 24;
    let (mode, lambda) = slowest_mode(n, dynamics, DVec3::new(0.2, 1.0, -0.5));
    let omega = (lambda / dynamics.mass).sqrt();
    let exact = (1.0 + 2.0 * dynamics.mass / lambda) * (1.0 - omega.cos());
    let at_rest = curve(|_| DVec3::ZERO, n);
    let errors: Vec<f64> = [100, 200, 400, 800]
        .iter()
        .map(|&steps| {
            let run = in_between(&at_rest, &mode, dynamics, steps, 0.0, 0).expect("runs");
            // Every node is the mode times the same factor.
            let middle = n / 2;
            let factor = run.frames[steps][middle].y / mode.values[middle].y;
            for (got, shape) in run.frames[steps].iter().zip(&mode.values) {
                assert!((*got - *shape * factor).length() < 1e-9, "{got} {shape}");
            }
            (factor - exact).abs()
        })
        .collect();
    assert!(errors[3] < 0.02 * exact.abs(), "{errors:?} of {exact}");
    for pair in errors.windows(2) {
        let order = (pair[0] / pair[1]).log2();
        assert!((0.85..1.3).contains(&order), "{errors:?}: order {order:.2}");
    }
}

#[test]
fn for_one_mode_the_ratio_correction_of_eq_21_meets_the_state_at_once() {
    let (mode, _) = slowest_mode(24, MATERIAL, DVec3::new(0.0, 1.0, 0.3));
    let at_rest = curve(|_| DVec3::ZERO, 24);
    let run = in_between(&at_rest, &mode, MATERIAL, 50, 1e-10, 10).expect("runs");
    assert_eq!(run.correction.corrections, 1, "{:?}", run.correction);
    assert!(!run.correction.solved);
    assert!(run.correction.final_error < 1e-10, "{:?}", run.correction);
}

#[test]
fn the_force_correction_meets_the_final_state() {
    let n = 40;
    let d0 = curve(|_| DVec3::ZERO, n);
    let d1 = curve(opening, n);
    let first = in_between(&d0, &d1, MATERIAL, 50, 0.0, 0).expect("runs");
    assert!(
        first.correction.final_error > 1e-3,
        "the uncorrected force misses the final state: {:?}",
        first.correction
    );
    let corrected = in_between(&d0, &d1, MATERIAL, 50, 1e-6, 200).expect("runs");
    assert!(
        corrected.correction.final_error <= 1e-6,
        "{:?}",
        corrected.correction
    );
    // Eq. (21) helps first (1.6 % -> about 0.2 %), then the force is solved.
    assert!(
        corrected.correction.corrections >= 2,
        "{:?}",
        corrected.correction
    );
    assert!(corrected.correction.solved, "{:?}", corrected.correction);
    // The first level is the bud, the last the open state.
    let last = &corrected.frames[50];
    for (got, want) in last.iter().zip(&d1.values) {
        assert!((*got - *want).length() <= 1e-6 * 2.0, "{got} {want}");
    }
    assert_eq!(corrected.frames[0], d0.values);
}

#[test]
fn bad_inputs_are_refused() {
    let a = curve(opening, 10);
    let b = curve(opening, 12);
    assert_eq!(
        in_between(&a, &b, MATERIAL, 10, 1e-6, 5).unwrap_err(),
        DynamicError::Nodes(11, 13)
    );
    let soft = Dynamics {
        bend: 0.0,
        ..MATERIAL
    };
    assert_eq!(
        in_between(&a, &a, soft, 10, 1e-6, 5).unwrap_err(),
        DynamicError::Material
    );
    assert_eq!(
        in_between(&a, &a, MATERIAL, 0, 1e-6, 5).unwrap_err(),
        DynamicError::Steps
    );
    let mut nan = a.clone();
    nan.values[3].y = f64::NAN;
    assert_eq!(
        in_between(&a, &nan, MATERIAL, 10, 1e-6, 5).unwrap_err(),
        DynamicError::NotFinite
    );
}

/// The lily petal sweep opened: its margins and tangents turned back about
/// the base (x axis) by an angle growing towards the tip.
fn opened_lily() -> (crate::PdeSweep, crate::PdeSweep) {
    let bud = crate::lily_petal_surface();
    // Points and tangent vectors alike: the k-th control point turned by
    // 0.5 k/3 radians.
    let turn = |curve: &crate::BezierCurve| {
        crate::BezierCurve::new(std::array::from_fn(|k| {
            glam::DQuat::from_rotation_x(0.5 * k as f64 / 3.0) * curve.control[k]
        }))
    };
    let open = crate::PdeSweep::new(
        turn(&bud.curve0),
        turn(&bud.curve1),
        turn(&bud.tangent0),
        turn(&bud.tangent1),
        bud.stretch_to_bend(),
    );
    (bud, open)
}

#[test]
fn a_swept_petal_goes_from_its_bud_to_its_open_state() {
    use crate::Surface;
    let (bud, open) = opened_lily();
    let steps = 40;
    let motion = SweepInBetween::new(&bud, &open, 24, 12, MATERIAL, steps, 1e-6, 30).expect("runs");
    assert_eq!(motion.rows.len(), 13);
    let summary = motion.summary();
    assert!(summary.final_error <= 1e-6, "{summary:?}");
    let length = bud
        .point(glam::DVec2::new(0.5, 1.0))
        .distance(bud.point(glam::DVec2::ZERO));
    // At the nodes of a row the last level is the open state; between rows
    // and nodes the interpolation of it (within a few % of the length).
    for (u, v) in [(0.5, 0.5), (0.25, 0.75), (0.0, 1.0), (0.8, 0.3)] {
        let uv = glam::DVec2::new(u, v);
        assert!(motion.deformation(uv, 0).length() < 1e-12);
        let end = bud.point(uv) + motion.deformation(uv, steps);
        assert!(
            end.distance(open.point(uv)) < 0.02 * length,
            "at {uv}: {end} against {}",
            open.point(uv)
        );
    }
    let node = glam::DVec2::new(0.5, 0.5);
    let end = bud.point(node) + motion.deformation(node, steps);
    assert!(end.distance(open.point(node)) < 1e-5 * length);
    // Halfway it has moved, but not all the way.
    let half = motion
        .deformation(glam::DVec2::new(0.5, 1.0), steps / 2)
        .length();
    let full = motion
        .deformation(glam::DVec2::new(0.5, 1.0), steps)
        .length();
    assert!(half > 0.05 * full && half < 1.5 * full, "{half} of {full}");
}

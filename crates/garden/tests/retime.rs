//! The same opening in another number of keyframes (`retime::in_keyframes`,
//! the time step of `refine --keyframes`): at the same place in the opening
//! every built-in flower grows by the same amount per opening, blends the
//! same keys, holds the same joint angles, has its parts (stamens) where
//! they were and its two-state organs as far along. When the parts' schedules
//! were not scaled, the lily's stamens spread over steps 20–80 of 200
//! keyframes, reached the petal while it was still closed, and 200 and 400
//! keyframes ended 44 % and 39 % of the midrib from 100 (README Accuracy).

use anthesis_flower::{Project, TwoStateAnimation, joint_angle_after};
use anthesis_garden::retime::in_keyframes;

/// Everything `project` times in steps, at `step`: per template the growth
/// scale per opening of each key (`dg · N`, weighted by the key's blend
/// weight), the joint angle and the two-state fraction; per part its angle.
fn timing_at(project: &Project, step: u32) -> Vec<f64> {
    let n = f64::from(project.settings.keyframes);
    let mut values = Vec::new();
    for template in &project.flower.templates {
        let keys = template.maps.keys();
        let mut per_key = vec![0.0; keys.len()];
        for (k, w) in template.maps.weights_at(f64::from(step)) {
            per_key[k] += w * keys[k].dg.unwrap_or(template.dg) * n;
        }
        values.extend(per_key);
        values.push(joint_angle_after(&template.joint_schedule, step));
        if let Some(two) = &template.two_state {
            values.push(two.velocity.fraction(&two.growth, f64::from(step)));
            values.push(two.growth.fraction(f64::from(step)));
        }
    }
    for part in &project.flower.parts {
        values.push(joint_angle_after(&part.schedule, step));
    }
    values
}

fn assert_same_opening(project: &Project, factor: u32) {
    let n = project.settings.keyframes;
    let retimed = in_keyframes(project.clone(), n * factor);
    assert_eq!(retimed.settings.keyframes, n * factor);
    for step in 0..=n {
        let (a, b) = (timing_at(project, step), timing_at(&retimed, step * factor));
        assert_eq!(a.len(), b.len());
        for (i, (x, y)) in a.iter().zip(&b).enumerate() {
            assert!(
                (x - y).abs() <= 1e-12 * x.abs().max(1.0),
                "{} in {} keyframes: value {i} at step {} is {y}, at step {step} of {n} it was {x}",
                project.name,
                n * factor,
                step * factor,
            );
        }
    }
}

#[test]
fn every_built_in_flower_opens_the_same_in_two_and_four_times_the_keyframes() {
    for name in anthesis_garden::builtin_names() {
        let project = anthesis_garden::builtin(name)
            .expect("built in")
            .expect("loads");
        for factor in [2, 4] {
            assert_same_opening(&project, factor);
        }
    }
}

#[test]
fn the_lily_stamens_and_the_decay_keys_growth_scale_are_retimed() {
    let lily = anthesis_garden::builtin("lily")
        .expect("built in")
        .expect("loads");
    let stamens = lily
        .flower
        .parts
        .iter()
        .find(|p| !p.schedule.is_empty())
        .expect("the lily's stamens spread");
    let ramp = stamens.schedule[0];
    let retimed = in_keyframes(lily.clone(), 2 * lily.settings.keyframes);
    let moved = retimed
        .flower
        .parts
        .iter()
        .find(|p| p.name == stamens.name)
        .expect("the same parts");
    assert_eq!(
        (moved.schedule[0].from_step, moved.schedule[0].to_step),
        (2 * ramp.from_step, 2 * ramp.to_step)
    );

    let decay = anthesis_garden::builtin("lily-decay")
        .expect("built in")
        .expect("loads");
    let own = |p: &Project| -> Vec<f64> {
        p.flower.templates[0]
            .maps
            .keys()
            .iter()
            .filter_map(|k| k.dg)
            .collect()
    };
    assert!(!own(&decay).is_empty(), "the decay key has its own dg");
    let halved: Vec<f64> = own(&decay).iter().map(|dg| dg / 2.0).collect();
    let twice = 2 * decay.settings.keyframes;
    assert_eq!(own(&in_keyframes(decay, twice)), halved);
}

#[test]
fn a_two_state_organ_is_as_far_along_at_the_same_place_in_the_opening() {
    let mut project = anthesis_garden::builtin("five-petal")
        .expect("built in")
        .expect("loads");
    let template = &mut project.flower.templates[0];
    let open = template.mesh.positions.clone();
    template.two_state = Some(TwoStateAnimation::new(open, 80));
    assert_same_opening(&project, 2);
    let retimed = in_keyframes(project, 50);
    let two = retimed.flower.templates[0]
        .two_state
        .as_ref()
        .expect("kept");
    assert!((two.growth.duration - 40.0).abs() < 1e-12);
}

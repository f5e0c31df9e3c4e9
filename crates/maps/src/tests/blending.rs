use glam::DVec2;

use crate::{Blend, GrowthMaps, KeyedMaps, MapError, MapKey, MapKind, ScalarMap};

const BLENDS: [Blend; 5] = [
    Blend::Linear,
    Blend::Smooth,
    Blend::Logistic { steepness: 10.0 },
    Blend::Logistic { steepness: 0.5 },
    Blend::Logistic { steepness: 60.0 },
];

/// Maps whose e-growth is the constant `value`.
fn maps_with_e_growth(value: f32) -> GrowthMaps {
    let mut maps = GrowthMaps::uniform();
    maps.e_growth = ScalarMap::constant(value);
    maps
}

fn keyed(steps: &[u32], blend: Blend) -> KeyedMaps {
    let keys = steps
        .iter()
        .map(|&step| MapKey {
            dg: None,
            step,
            maps: maps_with_e_growth(step as f32),
        })
        .collect();
    KeyedMaps::new(keys, blend).expect("distinct steps")
}

#[test]
fn blends_hit_their_endpoints_exactly_and_never_decrease() {
    for blend in BLENDS {
        assert_eq!(blend.apply(0.0), 0.0, "{blend:?}");
        assert_eq!(blend.apply(1.0), 1.0, "{blend:?}");
        assert_eq!(blend.apply(-0.5), 0.0, "{blend:?}");
        assert_eq!(blend.apply(1.5), 1.0, "{blend:?}");
        assert_eq!(blend.apply(f64::NAN), 0.0, "{blend:?}");
        let mut previous = 0.0;
        for i in 0..=1000 {
            let weight = blend.apply(f64::from(i) / 1000.0);
            assert!(weight >= previous, "{blend:?} falls at {i}");
            assert!((0.0..=1.0).contains(&weight));
            previous = weight;
        }
        // All three curves are symmetric about the midpoint.
        for s in [0.1, 0.25, 0.4] {
            let sum = blend.apply(s) + blend.apply(1.0 - s);
            assert!((sum - 1.0).abs() < 1e-12, "{blend:?} at {s}");
        }
        assert!((blend.apply(0.5) - 0.5).abs() < 1e-15, "{blend:?}");
    }
}

#[test]
fn smooth_is_the_cubic_growth_function() {
    // 3s² − 2s³ at s = 1/4: 3/16 − 2/64 = 5/32.
    assert_eq!(Blend::Smooth.apply(0.25), 5.0 / 32.0);
    assert_eq!(Blend::Smooth.apply(0.75), 27.0 / 32.0);
}

#[test]
fn logistic_is_the_rescaled_logistic_function() {
    let sigmoid = |x: f64| 1.0 / (1.0 + (-x).exp());
    for steepness in [1.0, 10.0, 25.0] {
        let blend = Blend::Logistic { steepness };
        for s in [0.05, 0.2, 0.5, 0.7, 0.93] {
            let expected = (sigmoid(steepness * (s - 0.5)) - sigmoid(-steepness / 2.0))
                / (sigmoid(steepness / 2.0) - sigmoid(-steepness / 2.0));
            assert!(
                (blend.apply(s) - expected).abs() < 1e-12,
                "k {steepness}, s {s}"
            );
        }
    }
    // Steeper curves start slower.
    let gentle = Blend::Logistic { steepness: 2.0 }.apply(0.2);
    let steep = Blend::Logistic { steepness: 20.0 }.apply(0.2);
    assert!(steep < gentle && gentle < 0.2);
    // Tiny steepness is linear, a negative one acts like its magnitude, and
    // absurd ones stay finite.
    assert_eq!(Blend::Logistic { steepness: 0.0 }.apply(0.3), 0.3);
    assert!((Blend::Logistic { steepness: 1e-4 }.apply(0.3) - 0.3).abs() < 1e-8);
    assert_eq!(
        Blend::Logistic { steepness: -10.0 }.apply(0.3),
        Blend::Logistic { steepness: 10.0 }.apply(0.3)
    );
    assert_eq!(
        Blend::Logistic {
            steepness: f64::INFINITY
        }
        .apply(0.3),
        0.0
    );
    assert_eq!(
        Blend::Logistic {
            steepness: f64::INFINITY
        }
        .apply(0.7),
        1.0
    );
    assert_eq!(
        Blend::Logistic {
            steepness: f64::NAN
        }
        .apply(0.3),
        0.3
    );
}

#[test]
fn weights_before_after_and_at_keys() {
    let maps = keyed(&[10, 50, 100], Blend::Linear);
    assert_eq!(maps.weights_at(-5.0), [(0, 1.0), (0, 0.0)]);
    assert_eq!(maps.weights_at(0.0), [(0, 1.0), (0, 0.0)]);
    assert_eq!(maps.weights_at(10.0), [(0, 1.0), (1, 0.0)]);
    assert_eq!(maps.weights_at(50.0), [(1, 1.0), (2, 0.0)]);
    assert_eq!(maps.weights_at(100.0), [(2, 1.0), (2, 0.0)]);
    assert_eq!(maps.weights_at(1e9), [(2, 1.0), (2, 0.0)]);
    assert_eq!(maps.weights_at(f64::NAN), [(0, 1.0), (0, 0.0)]);
    // Between keys: a quarter of the way from 10 to 50, and from 50 to 100.
    assert_eq!(maps.weights_at(20.0), [(0, 0.75), (1, 0.25)]);
    assert_eq!(maps.weights_at(62.5), [(1, 0.75), (2, 0.25)]);
}

#[test]
fn the_schedule_weighs_like_the_maps_it_came_from() {
    for blend in BLENDS {
        let maps = keyed(&[10, 50, 100], blend);
        let schedule = maps.schedule();
        for tenth_step in -10..=1200 {
            let step = f64::from(tenth_step) / 10.0;
            assert_eq!(schedule.weights_at(step), maps.weights_at(step), "{step}");
        }
    }
}

#[test]
fn weights_follow_the_blend_and_sum_to_one() {
    for blend in BLENDS {
        let maps = keyed(&[10, 50], blend);
        assert_eq!(maps.weights_at(10.0), [(0, 1.0), (1, 0.0)], "{blend:?}");
        assert_eq!(maps.weights_at(50.0), [(1, 1.0), (1, 0.0)], "{blend:?}");
        let mut previous_later = 0.0;
        for tenth_step in 0..=600 {
            let step = f64::from(tenth_step) / 10.0;
            let weights = maps.weights_at(step);
            let sum = weights[0].1 + weights[1].1;
            assert!((sum - 1.0).abs() < 1e-15, "{blend:?} at {step}");
            // The weight of key 1 never decreases with time.
            let later: f64 = weights
                .iter()
                .filter(|(index, _)| *index == 1)
                .map(|(_, weight)| weight)
                .sum();
            assert!(later >= previous_later, "{blend:?} at {step}");
            previous_later = later;
        }
        let midway = maps.weights_at(30.0);
        assert!((midway[1].1 - 0.5).abs() < 1e-15, "{blend:?}");
        let early = maps.weights_at(14.0)[1].1;
        assert_eq!(early, blend.apply(0.1));
    }
}

#[test]
fn single_key_maps_hold_at_every_step() {
    let maps = KeyedMaps::single(maps_with_e_growth(0.3));
    for step in [-1.0, 0.0, 7.0, 1e6] {
        assert_eq!(maps.weights_at(step), [(0, 1.0), (0, 0.0)]);
    }
}

#[test]
fn keys_are_sorted_and_steps_must_be_distinct() {
    let maps = keyed(&[50, 10, 30], Blend::Smooth);
    let steps: Vec<u32> = maps.keys().iter().map(|key| key.step).collect();
    assert_eq!(steps, [10, 30, 50]);
    assert_eq!(maps.keys()[0].maps.e_growth.values(), &[10.0]);

    assert_eq!(
        KeyedMaps::new(Vec::new(), Blend::Linear),
        Err(MapError::NoKeys)
    );
    let twice = vec![
        MapKey {
            dg: None,
            step: 5,
            maps: GrowthMaps::uniform(),
        },
        MapKey {
            dg: None,
            step: 9,
            maps: GrowthMaps::uniform(),
        },
        MapKey {
            dg: None,
            step: 5,
            maps: GrowthMaps::uniform(),
        },
    ];
    assert_eq!(
        KeyedMaps::new(twice, Blend::Linear),
        Err(MapError::DuplicateStep { step: 5 })
    );
}

#[test]
fn insert_and_remove_keep_the_keys_valid() {
    let mut maps = keyed(&[10, 50], Blend::Linear);
    let index = maps
        .insert(MapKey {
            dg: None,
            step: 30,
            maps: maps_with_e_growth(30.0),
        })
        .expect("new step");
    assert_eq!(index, 1);
    assert_eq!(
        maps.insert(MapKey {
            dg: None,
            step: 50,
            maps: GrowthMaps::uniform()
        }),
        Err(MapError::DuplicateStep { step: 50 })
    );
    assert_eq!(
        maps.remove(7),
        Err(MapError::NoSuchKey { index: 7, count: 3 })
    );
    assert_eq!(maps.remove(0).map(|key| key.step), Ok(10));
    assert_eq!(maps.remove(0).map(|key| key.step), Ok(30));
    assert_eq!(maps.remove(0), Err(MapError::LastKey));
    assert_eq!(maps.keys().len(), 1);
}

#[test]
fn blended_triangle_values_mix_the_keys() {
    let mut early = GrowthMaps::uniform();
    early.direction = crate::DirectionMap::constant(DVec2::new(1.0, 0.0));
    let mut late = maps_with_e_growth(1.0);
    late.direction = crate::DirectionMap::constant(DVec2::new(0.0, 1.0));
    let maps = KeyedMaps::new(
        vec![
            MapKey {
                dg: None,
                step: 0,
                maps: early,
            },
            MapKey {
                dg: None,
                step: 40,
                maps: late,
            },
        ],
        Blend::Linear,
    )
    .expect("two keys");
    let corners_in_uv = [DVec2::ZERO, DVec2::X, DVec2::Y];
    let e_growth = |step| maps.scalar_triangle_value_at(MapKind::EGrowth, step, corners_in_uv);
    assert_eq!(e_growth(0.0), 0.0);
    assert_eq!(e_growth(10.0), 0.25);
    assert_eq!(e_growth(40.0), 1.0);
    assert_eq!(
        maps.scalar_triangle_value_at(MapKind::Bend, 20.0, corners_in_uv),
        1.0
    );
    assert_eq!(
        maps.direction_triangle_value_at(30.0, corners_in_uv),
        DVec2::new(0.25, 0.75)
    );
}

#[test]
fn blend_serialises_in_snake_case_with_a_default_steepness() {
    assert_eq!(
        serde_json::to_string(&Blend::Linear).expect("serialises"),
        "\"linear\""
    );
    assert_eq!(
        serde_json::to_string(&Blend::Smooth).expect("serialises"),
        "\"smooth\""
    );
    assert_eq!(
        serde_json::to_string(&Blend::Logistic { steepness: 4.0 }).expect("serialises"),
        r#"{"logistic":{"steepness":4.0}}"#
    );
    let parsed: Blend = serde_json::from_str(r#"{"logistic":{}}"#).expect("parses");
    assert_eq!(parsed, Blend::logistic());
    assert_eq!(parsed, Blend::Logistic { steepness: 10.0 });
    let kind: MapKind = serde_json::from_str("\"e_growth_in\"").expect("parses");
    assert_eq!(kind, MapKind::EGrowthIn);
}

#[test]
fn a_key_past_the_end_is_the_last_key() {
    let maps = keyed(&[0, 40, 60], Blend::Linear);
    assert_eq!(maps.key_clamped(1).step, 40);
    assert_eq!(maps.key_clamped(2).step, 60);
    assert_eq!(maps.key_clamped(3).step, 60);
    assert_eq!(maps.key_clamped(usize::MAX).step, 60);
    assert_eq!(maps.clamped_index(0), 0);
    assert_eq!(maps.clamped_index(7), 2);
}

#[test]
fn the_raster_size_is_the_first_rasters_and_constants_have_none() {
    let mut maps = keyed(&[0, 40], Blend::Linear);
    assert_eq!(maps.raster_size(), None, "all constants");
    maps.keys_mut()[1].maps.bend = ScalarMap::from_fn(8, 4, |_| 0.5);
    assert_eq!(maps.raster_size(), Some((8, 4)));
}

#[test]
fn the_common_raster_size_is_the_most_frequent_first_read_wins_a_tie_constants_left_out() {
    use crate::common_raster_size;
    assert_eq!(common_raster_size([(1, 1), (1, 1)]), None);
    assert_eq!(
        common_raster_size([(1, 1), (8, 8), (4, 4), (4, 4)]),
        Some((4, 4))
    );
    assert_eq!(common_raster_size([(8, 8), (4, 4), (1, 1)]), Some((8, 8)));
    assert_eq!(
        common_raster_size([(4, 4), (8, 8), (8, 8), (4, 4)]),
        Some((4, 4))
    );
    assert_eq!(common_raster_size([]), None);
}

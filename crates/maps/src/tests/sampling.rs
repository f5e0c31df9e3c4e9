use glam::DVec2;

use crate::{DirectionMap, MapError, ScalarMap};

/// `8u + 4v`: on a 4x4 raster its pixel-centre values (and every sample
/// below) are small dyadic numbers, so bilinear interpolation, which
/// reproduces linear functions, must match it exactly.
fn ramp_in_uv(point_in_uv: DVec2) -> f64 {
    8.0 * point_in_uv.x + 4.0 * point_in_uv.y
}

fn ramp_map() -> ScalarMap {
    ScalarMap::from_fn(4, 4, |point_in_uv| ramp_in_uv(point_in_uv) as f32)
}

#[test]
fn bilinear_sampling_reproduces_a_linear_ramp_exactly_between_pixel_centres() {
    let map = ramp_map();
    // Pixel centres lie at 1/8, 3/8, 5/8, 7/8; sample every 1/64 between the
    // outermost ones, on and off the centres.
    for i in 8..=56 {
        for j in 8..=56 {
            let point_in_uv = DVec2::new(f64::from(i) / 64.0, f64::from(j) / 64.0);
            assert_eq!(
                map.sample(point_in_uv),
                ramp_in_uv(point_in_uv),
                "at {point_in_uv}"
            );
        }
    }
}

#[test]
fn first_stored_row_is_the_top_of_the_image_at_v_one() {
    let map = ramp_map();
    // Pixel (0, 0) is top-left: u = 1/8, v = 7/8.
    assert_eq!(map.pixel_centre_in_uv(0, 0), DVec2::new(0.125, 0.875));
    assert_eq!(map.values()[0], 8.0 * 0.125 + 4.0 * 0.875);
    // The last pixel is bottom-right: u = 7/8, v = 1/8.
    assert_eq!(map.values()[15], 8.0 * 0.875 + 4.0 * 0.125);

    let top_one_bottom_zero = ScalarMap::new(1, 2, vec![1.0, 0.0]).expect("2 values");
    assert_eq!(top_one_bottom_zero.sample(DVec2::new(0.5, 1.0)), 1.0);
    assert_eq!(top_one_bottom_zero.sample(DVec2::new(0.5, 0.0)), 0.0);
    assert_eq!(top_one_bottom_zero.sample(DVec2::new(0.5, 0.5)), 0.5);
}

#[test]
fn sampling_clamps_to_the_edge_pixels() {
    let map = ramp_map();
    let edge = |u: f64, v: f64| ramp_in_uv(DVec2::new(u, v));
    // Between the UV border and the outer pixel centres.
    assert_eq!(map.sample(DVec2::new(0.0, 0.5)), edge(0.125, 0.5));
    assert_eq!(map.sample(DVec2::new(1.0, 0.5)), edge(0.875, 0.5));
    assert_eq!(map.sample(DVec2::new(0.5, 0.0)), edge(0.5, 0.125));
    assert_eq!(map.sample(DVec2::new(0.5, 1.0)), edge(0.5, 0.875));
    // Far outside the UV square: the corner pixels.
    assert_eq!(map.sample(DVec2::new(-3.0, 7.0)), edge(0.125, 0.875));
    assert_eq!(map.sample(DVec2::new(5.0, -2.0)), edge(0.875, 0.125));
    // A constant map is the same everywhere.
    let constant = ScalarMap::constant(0.25);
    for point_in_uv in [DVec2::ZERO, DVec2::ONE, DVec2::new(-1.0, 2.0)] {
        assert_eq!(constant.sample(point_in_uv), 0.25);
    }
}

#[test]
fn triangle_value_follows_paper_equation_1() {
    // 2x2 raster; pixel centres at u, v = 1/4 and 3/4.
    // Top row (v = 3/4): 0, 6. Bottom row (v = 1/4): 12, 24.
    let map = ScalarMap::new(2, 2, vec![0.0, 6.0, 12.0, 24.0]).expect("4 values");
    let corners_in_uv = [
        DVec2::new(0.25, 0.75),
        DVec2::new(0.75, 0.75),
        DVec2::new(0.25, 0.25),
    ];
    // The centroid (5/12, 7/12) sits a third of the way from the top-left
    // centre in both directions: rows 2 and 16, value 2·(2/3) + 16/3 = 20/3.
    let centroid_value = 20.0 / 3.0;
    let centroid_in_uv = DVec2::new(5.0 / 12.0, 7.0 / 12.0);
    assert!((map.sample(centroid_in_uv) - centroid_value).abs() < 1e-12);
    // Eq. 1: (0 + 6 + 12 + 3·20/3) / 6 = 19/3. (A plain mean of the four
    // samples would give 37/6, the corners alone 6.)
    let expected = (0.0 + 6.0 + 12.0 + 3.0 * centroid_value) / 6.0;
    assert!((map.triangle_value(corners_in_uv) - expected).abs() < 1e-12);
    assert!((expected - 19.0 / 3.0).abs() < 1e-12);
    // The corner order does not matter.
    let [a, b, c] = corners_in_uv;
    assert!((map.triangle_value([c, a, b]) - expected).abs() < 1e-12);
}

#[test]
fn new_rejects_empty_rasters_and_wrong_value_counts() {
    assert_eq!(
        ScalarMap::new(0, 3, vec![]),
        Err(MapError::EmptyRaster {
            width: 0,
            height: 3
        })
    );
    assert_eq!(
        ScalarMap::new(3, 2, vec![0.0; 5]),
        Err(MapError::ValueCountMismatch {
            width: 3,
            height: 2,
            expected: 6,
            found: 5
        })
    );
    assert!(matches!(
        DirectionMap::new(2, 2, vec![[0.0, 0.0]; 3]),
        Err(MapError::ValueCountMismatch {
            expected: 4,
            found: 3,
            ..
        })
    ));
    // from_fn cannot fail: a zero size becomes 1.
    assert_eq!(ScalarMap::from_fn(0, 5, |_| 1.0).size(), (1, 5));
}

#[test]
fn check_size_reports_expected_and_found() {
    let map = ScalarMap::from_fn(3, 2, |_| 0.0);
    assert_eq!(map.check_size((3, 2)), Ok(()));
    let error = map.check_size((2, 3)).expect_err("2x3 is not 3x2");
    assert_eq!(
        error,
        MapError::WrongSize {
            expected: (2, 3),
            found: (3, 2)
        }
    );
    assert_eq!(
        error.to_string(),
        "map is 3x2 pixels but 2x3 pixels were expected"
    );
    let direction = DirectionMap::constant(DVec2::Y);
    assert!(matches!(
        direction.check_size((4, 4)),
        Err(MapError::WrongSize { found: (1, 1), .. })
    ));
}

#[test]
fn direction_sampling_is_bilinear_per_component_and_keeps_signs() {
    // Left pixel (-1, 0), right pixel (1, 1); one row.
    let map = DirectionMap::new(2, 1, vec![[-1.0, 0.0], [1.0, 1.0]]).expect("2 values");
    assert_eq!(map.sample(DVec2::new(0.5, 0.5)), DVec2::new(0.0, 0.5));
    assert_eq!(map.sample(DVec2::new(0.375, 0.9)), DVec2::new(-0.5, 0.25));
    assert_eq!(map.sample(DVec2::new(-1.0, 0.0)), DVec2::new(-1.0, 0.0));
    // Eq. 1 on each component: corners at u = 0 (clamped), 1 (clamped),
    // 1/2; centroid at u = 1/2.
    let corners_in_uv = [
        DVec2::new(0.0, 0.0),
        DVec2::new(1.0, 0.0),
        DVec2::new(0.5, 0.9),
    ];
    let expected = (DVec2::new(-1.0, 0.0)
        + DVec2::new(1.0, 1.0)
        + DVec2::new(0.0, 0.5)
        + 3.0 * DVec2::new(0.0, 0.5))
        / 6.0;
    assert!((map.triangle_value(corners_in_uv) - expected).length() < 1e-12);
}

#[test]
fn direction_from_fn_stores_the_given_vectors() {
    let map = DirectionMap::from_fn(2, 2, |point_in_uv| point_in_uv - DVec2::splat(0.5));
    // Top-left pixel centre (1/4, 3/4).
    assert_eq!(map.values()[0], [-0.25, 0.25]);
    assert_eq!(map.values()[3], [0.25, -0.25]);
}

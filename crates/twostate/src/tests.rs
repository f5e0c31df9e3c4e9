use super::*;
use glam::{DMat3, DQuat, DVec2};

/// A flat `cols × rows` grid over `[0, width] × [0, height]` in the XY
/// plane, `u = x / width`, `v = y / height`.
fn grid(cols: usize, rows: usize, width: f64, height: f64) -> Mesh {
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for r in 0..=rows {
        for c in 0..=cols {
            let (u, v) = (c as f64 / cols as f64, r as f64 / rows as f64);
            positions.push(DVec3::new(u * width, v * height, 0.0));
            uvs.push(DVec2::new(u, v));
        }
    }
    let at = |c: usize, r: usize| (r * (cols + 1) + c) as u32;
    let mut triangles = Vec::new();
    for r in 0..rows {
        for c in 0..cols {
            triangles.push([at(c, r), at(c + 1, r), at(c + 1, r + 1)]);
            triangles.push([at(c, r), at(c + 1, r + 1), at(c, r + 1)]);
        }
    }
    Mesh {
        positions,
        uvs,
        triangles,
    }
}

/// The bottom row (`v = 0`): where the organ is attached.
fn base_of(mesh: &Mesh) -> Vec<u32> {
    (0..mesh.uvs.len() as u32)
        .filter(|&i| mesh.uvs[i as usize].y == 0.0)
        .collect()
}

fn max_distance(a: &[DVec3], b: &[DVec3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| p.distance(*q))
        .fold(0.0, f64::max)
}

#[test]
fn an_affine_change_is_extracted_exactly_per_cell() {
    let bud = grid(6, 9, 3.0, 8.0);
    let turn = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 0.5).normalize(), 0.9);
    // Across (u = x) ×1.3, along (v = y) ×0.8, no shear.
    let stretch = DMat3::from_diagonal(DVec3::new(1.3, 0.8, 1.0));
    let a = DMat3::from_quat(turn) * stretch;
    let offset = DVec3::new(0.4, -1.0, 2.0);
    let open: Vec<DVec3> = bud.positions.iter().map(|p| a * *p + offset).collect();
    let cells = cell_growth(&bud, &open).unwrap();
    assert_eq!(cells.len(), bud.triangles.len());
    for (t, cell) in cells.iter().enumerate() {
        assert!(
            (cell.adaxial - 0.8).abs() < 1e-12,
            "cell {t}: {}",
            cell.adaxial
        );
        assert!(
            (cell.abaxial - 1.3).abs() < 1e-12,
            "cell {t}: {}",
            cell.abaxial
        );
        let want = if turn.w < 0.0 { -turn } else { turn };
        assert!(cell.direction.abs_diff_eq(want, 1e-12), "cell {t}");
        // The whole transform maps every bud edge onto the open edge.
        let f = cell.transform(1.0, 1.0);
        let tri = bud.triangles[t].map(|i| i as usize);
        for (i, j) in [(0, 1), (1, 2), (2, 0)] {
            let bud_edge = bud.positions[tri[j]] - bud.positions[tri[i]];
            let open_edge = open[tri[j]] - open[tri[i]];
            assert!((f * bud_edge - open_edge).length() < 1e-12, "cell {t}");
        }
        // No change at the start of the way.
        assert!(cell.transform(0.0, 0.0).abs_diff_eq(DMat3::IDENTITY, 1e-12));
    }
}

#[test]
fn a_sheared_change_is_met_exactly_though_the_ellipse_cannot_show_it() {
    let bud = grid(4, 5, 2.0, 5.0);
    let shear = DMat3::from_cols(
        DVec3::new(1.1, 0.0, 0.0),
        DVec3::new(0.35, 1.4, 0.0),
        DVec3::Z,
    );
    let open: Vec<DVec3> = bud.positions.iter().map(|p| shear * *p).collect();
    let two = TwoState::new(&bud, &open, &base_of(&bud)).unwrap();
    for cell in two.cells() {
        let off_diagonal = cell.in_plane.y_axis.x.abs() + cell.in_plane.x_axis.y.abs();
        assert!(off_diagonal > 0.1, "shear kept off the diagonal");
    }
    assert!(max_distance(&two.shape_at(two.growth.duration), &open) < 1e-9);
    assert!(max_distance(&two.shape_at(0.0), &bud.positions) < 1e-12);
}

#[test]
fn a_curled_open_shape_is_reached_at_the_end_and_the_bud_at_the_start() {
    let bud = grid(8, 12, 4.0, 10.0);
    // The sheet rolled about a line parallel to x: bending, no stretch.
    let radius = 4.0;
    let open: Vec<DVec3> = bud
        .positions
        .iter()
        .map(|p| {
            let angle = p.y / radius;
            DVec3::new(p.x, radius * angle.sin(), radius * (1.0 - angle.cos()))
        })
        .collect();
    let mut two = TwoState::new(&bud, &open, &base_of(&bud)).unwrap();
    two.growth.duration = 40.0;
    assert!(max_distance(&two.shape_at(40.0), &open) < 1e-9);
    assert!(max_distance(&two.shape_at(0.0), &bud.positions) < 1e-12);
    // Bending alone: every cell keeps its ratios at 1 (up to the chords).
    for cell in two.cells() {
        assert!((cell.abaxial - 1.0).abs() < 1e-9);
        assert!((cell.adaxial - 1.0).abs() < 0.01);
    }
    // On the way, each cell turns by the slerp fraction of its own turn:
    // the sheet rolled on a cylinder of radius / fraction (up to the
    // chords' shortening, under 0.2 % here).
    two.velocity = VelocityCurve::Points(vec![[0.0, 0.0], [1.0, 1.0]]);
    for fraction in [0.3_f64, 0.6] {
        let r = radius / fraction;
        let want: Vec<DVec3> = bud
            .positions
            .iter()
            .map(|p| DVec3::new(p.x, r * (p.y / r).sin(), r * (1.0 - (p.y / r).cos())))
            .collect();
        let got = two.shape_at(40.0 * fraction);
        assert!(
            max_distance(&got, &want) < 0.01,
            "fraction {fraction}: {}",
            max_distance(&got, &want)
        );
    }
}

#[test]
fn an_organ_turning_about_its_base_turns_by_the_slerp_fraction() {
    let bud = grid(5, 7, 2.0, 6.0);
    // A turn about the x axis, which runs through the base row (y = 0).
    let angle = 1.1;
    let turn = DQuat::from_rotation_x(angle);
    let open: Vec<DVec3> = bud.positions.iter().map(|p| turn * *p).collect();
    let mut two = TwoState::new(&bud, &open, &base_of(&bud)).unwrap();
    two.velocity = VelocityCurve::Points(vec![[0.0, 0.0], [1.0, 1.0]]);
    for fraction in [0.25, 0.5, 0.8] {
        let partial = DQuat::from_rotation_x(angle * fraction);
        let want: Vec<DVec3> = bud.positions.iter().map(|p| partial * *p).collect();
        let got = two.shape_at(fraction * two.growth.duration);
        assert!(max_distance(&got, &want) < 1e-9, "fraction {fraction}");
    }
}

#[test]
fn bad_pairs_are_refused_with_what_is_wrong() {
    let bud = grid(3, 3, 1.0, 1.0);
    let base = base_of(&bud);
    let short = &bud.positions[..5];
    assert_eq!(
        TwoState::new(&bud, short, &base).unwrap_err(),
        TwoStateError::DifferentVertexCount { bud: 16, open: 5 }
    );
    let mut nan = bud.positions.clone();
    nan[7].y = f64::NAN;
    assert_eq!(
        TwoState::new(&bud, &nan, &base).unwrap_err(),
        TwoStateError::NotFinite {
            vertex: 7,
            state: "open state"
        }
    );
    assert_eq!(
        TwoState::new(&bud, &bud.positions, &[]).unwrap_err(),
        TwoStateError::NoBase
    );
    assert!(matches!(
        TwoState::new(&bud, &bud.positions, &[99]).unwrap_err(),
        TwoStateError::BaseOutOfRange { index: 99, .. }
    ));
    let mut collapsed = bud.positions.clone();
    collapsed[5] = collapsed[0];
    collapsed[1] = collapsed[0];
    assert!(matches!(
        TwoState::new(&bud, &collapsed, &base).unwrap_err(),
        TwoStateError::FlatTriangle {
            state: "open state",
            ..
        }
    ));
    let mut flipped = bud.clone();
    flipped.triangles[4].swap(1, 2);
    assert_eq!(
        TwoState::from_meshes(&bud, &flipped, &base).unwrap_err(),
        TwoStateError::DifferentTriangles { triangle: 4 }
    );
    // A second piece that no base particle holds.
    let mut two_pieces = bud.clone();
    let n = two_pieces.positions.len() as u32;
    two_pieces.positions.extend([
        DVec3::new(5.0, 0.0, 0.0),
        DVec3::new(6.0, 0.0, 0.0),
        DVec3::new(5.0, 1.0, 0.0),
    ]);
    two_pieces.uvs.extend([DVec2::ZERO, DVec2::X, DVec2::Y]);
    two_pieces.triangles.push([n, n + 1, n + 2]);
    let err = TwoState::new(&two_pieces, &two_pieces.positions, &base).unwrap_err();
    assert!(matches!(err, TwoStateError::Unattached(_)), "{err}");
}

//! The measurements (`anthesis_sim::measure`) on surfaces whose curvature,
//! stretch, lengths and contact are known in closed form.

use std::collections::HashMap;
use std::f64::consts::PI;

use anthesis_mesh::Mesh;
use anthesis_mesh::generate::{flat_sheet, parametric_grid};
use anthesis_sim::measure::{
    OrganLayout, QUANTITIES, angle_defects_and_areas, boundary_vertices, contact_vertices,
    measure_keyframe, nan_median, principal_stretches, vertex_curvatures,
};
use glam::DVec3;

/// An icosphere of `radius`: the icosahedron split `levels` times, its
/// triangles counter-clockwise seen from outside.
fn icosphere(radius: f64, levels: usize) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut points: Vec<DVec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
    .collect();
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut middle: HashMap<(u32, u32), u32> = HashMap::new();
        let mut mid = |a: u32, b: u32, points: &mut Vec<DVec3>| {
            *middle.entry((a.min(b), a.max(b))).or_insert_with(|| {
                points.push((points[a as usize] + points[b as usize]).normalize());
                points.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(faces.len() * 4);
        for [a, b, c] in faces {
            let (ab, bc, ca) = (
                mid(a, b, &mut points),
                mid(b, c, &mut points),
                mid(c, a, &mut points),
            );
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    (points.iter().map(|p| *p * radius).collect(), faces)
}

fn interior(values: &[f64]) -> impl Iterator<Item = f64> + '_ {
    values.iter().copied().filter(|v| !v.is_nan())
}

#[test]
fn a_sphere_has_h_one_over_r_and_k_one_over_r_squared() {
    let radius = 2.0;
    let (x, f) = icosphere(radius, 4);
    let closed = vec![false; x.len()];
    let c = vertex_curvatures(&x, &f, &closed);
    for h in &c.mean {
        assert!((h - 1.0 / radius).abs() < 0.02 / radius, "H = {h}");
    }
    for k in &c.gaussian {
        assert!(
            (k - 1.0 / radius.powi(2)).abs() < 0.05 / radius.powi(2),
            "K = {k}"
        );
    }
    // The other winding flips H only.
    let reversed: Vec<[u32; 3]> = f.iter().map(|&[a, b, c]| [a, c, b]).collect();
    let r = vertex_curvatures(&x, &reversed, &closed);
    for i in 0..x.len() {
        assert!((r.mean[i] + c.mean[i]).abs() < 1e-12);
        assert!((r.gaussian[i] - c.gaussian[i]).abs() < 1e-12);
    }
}

#[test]
fn the_angle_defects_of_a_closed_surface_sum_to_4_pi_and_the_areas_tile_it() {
    // Descartes: exact on any closed genus-0 mesh, however bumpy.
    let (x, f) = icosphere(1.0, 2);
    let x: Vec<DVec3> = x
        .iter()
        .map(|p| *p * (1.0 + 0.2 * (5.0 * p.x).sin()))
        .collect();
    let (defect, area) = angle_defects_and_areas(&x, &f);
    assert!((defect.iter().sum::<f64>() - 4.0 * PI).abs() < 1e-9);
    let total: f64 = f
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| x[i as usize]);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum();
    assert!((area.iter().sum::<f64>() - total).abs() < 1e-12 * total);
}

#[test]
fn a_saddle_has_k_minus_4a2_and_h_zero_at_its_centre() {
    let a = 0.5;
    let mesh = parametric_grid(41, 41, |uv| {
        let (x, y) = (2.0 * uv.x - 1.0, 2.0 * uv.y - 1.0);
        DVec3::new(x, y, a * (x * x - y * y))
    });
    let boundary = boundary_vertices(&mesh.triangles, mesh.vertex_count());
    let c = vertex_curvatures(&mesh.positions, &mesh.triangles, &boundary);
    let centre = 20 * 41 + 20;
    assert!(
        (c.gaussian[centre] + 4.0 * a * a).abs() < 0.03 * 4.0 * a * a,
        "K = {}",
        c.gaussian[centre]
    );
    assert!(c.mean[centre].abs() < 1e-9, "H = {}", c.mean[centre]);
    // The rim is left out, the rest is negative.
    assert!(c.gaussian[0].is_nan() && c.mean[0].is_nan());
    assert!(interior(&c.gaussian).all(|k| k < 0.0));
}

#[test]
fn a_cylinder_has_k_zero_and_h_one_over_2r() {
    let r = 1.5;
    // Half a cylinder around the Z axis, 60 columns round, 30 rows high.
    let mesh = parametric_grid(61, 31, |uv| {
        let angle = PI * uv.x;
        DVec3::new(r * angle.cos(), r * angle.sin(), 3.0 * uv.y)
    });
    let boundary = boundary_vertices(&mesh.triangles, mesh.vertex_count());
    let c = vertex_curvatures(&mesh.positions, &mesh.triangles, &boundary);
    let mut count = 0;
    for k in interior(&c.gaussian) {
        assert!(k.abs() < 2e-3 / (r * r), "K = {k}");
        count += 1;
    }
    assert_eq!(count, 59 * 29);
    // d/du x d/dv points outwards, so H is positive: 1/(2r).
    for h in interior(&c.mean) {
        assert!((h - 0.5 / r).abs() < 0.01 / r, "H = {h}");
    }
}

#[test]
fn a_scaled_and_a_sheared_sheet_have_their_known_stretches() {
    let sheet = flat_sheet(2.0, 1.0, 9, 5);
    let scaled: Vec<DVec3> = sheet
        .positions
        .iter()
        .map(|p| DVec3::new(0.8 * p.x, 1.4 * p.y, 0.0))
        .collect();
    for s in principal_stretches(&sheet.positions, &scaled, &sheet.triangles) {
        assert!(
            (s[0] - 1.4).abs() < 1e-12 && (s[1] - 0.8).abs() < 1e-12,
            "{s:?}"
        );
    }
    // Shear x += g y, then turned and lifted out of the plane: the
    // singular values of [[1, g], [0, 1]].
    let g = 0.6;
    let turn = glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 0.7);
    let sheared: Vec<DVec3> = sheet
        .positions
        .iter()
        .map(|p| turn * DVec3::new(p.x + g * p.y, p.y, 0.0) + DVec3::new(3.0, -2.0, 5.0))
        .collect();
    let root = (g * g * (g * g + 4.0)).sqrt();
    let major = ((2.0 + g * g + root) / 2.0).sqrt();
    let minor = ((2.0 + g * g - root) / 2.0).sqrt();
    assert!(
        (major * minor - 1.0).abs() < 1e-12,
        "a shear keeps the area"
    );
    for s in principal_stretches(&sheet.positions, &sheared, &sheet.triangles) {
        assert!(
            (s[0] - major).abs() < 1e-12 && (s[1] - minor).abs() < 1e-12,
            "{s:?}"
        );
    }
}

fn moved(mesh: &Mesh, by: DVec3) -> Vec<DVec3> {
    mesh.positions.iter().map(|p| *p + by).collect()
}

/// The contact areas of two `width` x 1 sheets of `columns` x `rows`
/// vertices, the second moved 1 along X and `gap` up, and of a third far
/// away, against `parts` too.
fn overlapping_sheets(columns: usize, rows: usize, gap: f64, parts: &[Mesh]) -> Vec<f64> {
    let sheet = flat_sheet(2.0, 1.0, columns, rows);
    let a = sheet.positions.clone();
    let b = moved(&sheet, DVec3::new(1.0, 0.0, gap));
    let far = moved(&sheet, DVec3::new(0.0, 0.0, 5.0));
    let layout = OrganLayout::new(&sheet);
    let layouts = [layout.clone(), layout.clone(), layout];
    let now = [a, b, far];
    let surfaces: Vec<(&[DVec3], &[[u32; 3]])> = parts
        .iter()
        .map(|p| (p.positions.as_slice(), p.triangles.as_slice()))
        .collect();
    measure_keyframe(&layouts, &now, &now, &surfaces, 0.02)
        .iter()
        .map(|m| {
            assert!((m.summary.area - 2.0).abs() < 1e-12);
            m.summary.contact_area
        })
        .collect()
}

#[test]
fn two_sheets_overlapping_by_one_square_touch_over_it() {
    // Two 2 x 1 sheets, the second moved 1 along X and 0.005 up: they
    // overlap over [0, 1] x [0, 1], area 1. The contact area is the
    // vertices' areas, so it meets the overlap within the vertices along
    // its edge: half a column of the grid (spacing h) either side.
    for (columns, rows, h) in [(21, 11, 0.1), (41, 21, 0.05), (81, 41, 0.025)] {
        let areas = overlapping_sheets(columns, rows, 0.005, &[]);
        for area in &areas[..2] {
            assert!(
                (area - 1.0).abs() <= 0.5 * h + 1e-12,
                "{area} with spacing {h}"
            );
        }
        assert_eq!(areas[2], 0.0);
    }
    // Further apart than the distance: no contact.
    let areas = overlapping_sheets(21, 11, 0.05, &[]);
    assert!(areas.iter().all(|&a| a == 0.0));
    // A part touching the far sheet over all of it: its whole area.
    let mut part = flat_sheet(2.0, 1.0, 5, 3);
    part.positions.iter_mut().for_each(|p| p.z = 5.01);
    let areas = overlapping_sheets(21, 11, 0.05, &[part]);
    assert_eq!(areas[..2], [0.0, 0.0]);
    assert!((areas[2] - 2.0).abs() < 1e-12);
}

#[test]
fn contact_vertices_are_those_within_the_distance() {
    let sheet = flat_sheet(2.0, 1.0, 21, 11);
    let a = sheet.positions.clone();
    let b = moved(&sheet, DVec3::new(1.0, 0.0, 0.005));
    let t = sheet.triangles.as_slice();
    let contact = contact_vertices(&[(&a, t), (&b, t)], &[], 0.02);
    for (p, touching) in a.iter().zip(&contact[0]) {
        // x from -1 to 1; the other sheet covers x from 0 to 2.
        assert_eq!(*touching, p.x >= -1e-12, "{p}");
    }
}

#[test]
fn a_sheet_has_its_midrib_and_margin_lengths_and_they_scale() {
    // u across (X), v along (Y): the midrib is the sheet's height, the
    // margin both sides and the tip (the base, v = 0, left out).
    let (w, h) = (1.2, 3.0);
    let sheet = flat_sheet(w, h, 7, 13);
    let layout = OrganLayout::new(&sheet);
    let bud = vec![sheet.positions.clone()];
    let m = &measure_keyframe(std::slice::from_ref(&layout), &bud, &bud, &[], 0.01)[0];
    assert!((m.summary.midrib_length - h).abs() < 1e-12);
    assert!((m.summary.margin_length - (2.0 * h + w)).abs() < 1e-12);
    assert!((m.summary.stretch_major_mean - 1.0).abs() < 1e-12);
    assert_eq!(m.summary.contact_area, 0.0);
    assert_eq!(m.summary.gaussian_curvature_median, 0.0);

    let grown = vec![sheet.positions.iter().map(|p| 1.5 * *p).collect::<Vec<_>>()];
    let m = &measure_keyframe(std::slice::from_ref(&layout), &bud, &grown, &[], 0.01)[0];
    assert!((m.summary.midrib_length - 1.5 * h).abs() < 1e-12);
    assert!((m.summary.margin_length - 1.5 * (2.0 * h + w)).abs() < 1e-12);
    assert!((m.summary.stretch_major_mean - 1.5).abs() < 1e-12);
    assert!((m.summary.stretch_minor_mean - 1.5).abs() < 1e-12);
    assert!(
        m.vertex_stretches
            .iter()
            .all(|s| (s[0] - 1.5).abs() < 1e-12)
    );
    assert!((m.summary.area - 2.25 * w * h).abs() < 1e-12);
}

#[test]
fn a_bent_petal_midrib_follows_the_uv_line() {
    // A quarter circle of radius 2 as the midrib: length π.
    let mesh = parametric_grid(5, 41, |uv| {
        let angle = 0.5 * PI * uv.y;
        DVec3::new(uv.x - 0.5, 2.0 * angle.sin(), 2.0 * (1.0 - angle.cos()))
    });
    let layout = OrganLayout::new(&mesh);
    let x = vec![mesh.positions.clone()];
    let m = &measure_keyframe(std::slice::from_ref(&layout), &x, &x, &[], 0.01)[0];
    // The polyline through chords of the 40 rows: within their sagitta.
    assert!(
        (m.summary.midrib_length - PI).abs() < 2e-3,
        "{}",
        m.summary.midrib_length
    );
    // A cylinder of radius 2 bent along v: H = 1/4 in magnitude, K = 0.
    assert!((m.summary.mean_curvature_median.abs() - 0.25).abs() < 0.01);
    assert!(m.summary.gaussian_curvature_median.abs() < 1e-3);
}

#[test]
fn medians_and_the_table_units() {
    assert_eq!(nan_median(&[3.0, f64::NAN, 1.0, 2.0]), 2.0);
    assert_eq!(nan_median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
    assert!(nan_median(&[f64::NAN]).is_nan());
    let unit = |name: &str| {
        QUANTITIES
            .iter()
            .find(|q| q.name == name)
            .map(|q| q.unit("mm"))
    };
    assert_eq!(unit("area").as_deref(), Some("mm^2"));
    assert_eq!(unit("gaussian_curvature_mean").as_deref(), Some("1/mm^2"));
    assert_eq!(unit("mean_curvature_median").as_deref(), Some("1/mm"));
    assert_eq!(unit("midrib_length").as_deref(), Some("mm"));
    assert_eq!(unit("stretch_major_mean").as_deref(), Some("1"));
    let summary = anthesis_sim::measure::Summary {
        area: 2.0,
        gaussian_curvature_mean: 0.5,
        ..Default::default()
    };
    let area = QUANTITIES[0];
    assert_eq!(area.value(&summary, 1.8), 2.0 * 1.8 * 1.8);
    assert_eq!(QUANTITIES[4].value(&summary, 2.0), 0.125);
}

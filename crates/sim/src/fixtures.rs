//! Small generated flowers for tests and benchmarks (not the default lily,
//! which is built from the bud builder). Compiled only for this crate's
//! tests and with the `fixtures` feature, which the crates whose tests,
//! examples and benches use them turn on from their dev-dependencies.

use anthesis_flower::{
    BaseRegion, Flower, JointRamp, Organ, Overlap, Placement, Project, SimulationSettings, Template,
};
use anthesis_maps::{GrowthMaps, KeyedMaps, MapKey, ScalarMap};
use std::f64::consts::PI;

use anthesis_mesh::{Mesh, generate};
use glam::DVec3;

/// Distance between the inner and the outer ring of a [`whorl`]: about one
/// mean edge, so overlapping margins are close but apart in the bud.
const RING_GAP: f64 = 1.3;

/// A petal template of about `columns x rows` particles (mean edge about
/// 1.3 for the lily-sized 14 x 28), cupped and slightly incurved, growing
/// with a midrib that reflexes early and a lamina that widens later, in two
/// time keys.
///
/// The base region is `v <= 0.05`, widened on coarse meshes to hold at
/// least two rows of particles: a single row lies along the joint axis, so
/// shape matching could not hold the joint angle. Nothing grows in the
/// base region.
pub fn petal_template(name: &str, columns: usize, rows: usize) -> Template {
    let length = 1.3 * rows as f64;
    let width = 1.3 * columns as f64;
    let mesh = generate::test_petal(length, width, columns, rows);
    template_with_mesh(name, mesh, rows)
}

/// Like [`petal_template`], but the bud is bent around the flower axis: with
/// its base at distance `ring_radius` from the axis (and no joint angle),
/// every particle lies on a surface of revolution about the axis whose
/// radius shrinks towards the tip. Organs of different rings are then
/// nested and cannot cut through each other in the bud.
pub fn ring_petal_template(name: &str, columns: usize, rows: usize, ring_radius: f64) -> Template {
    let length = 1.3 * rows as f64;
    let width = 1.3 * columns as f64;
    let mesh = generate::parametric_grid(columns, rows, |uv| {
        let half_width = 0.5 * width * (0.25 + 0.75 * (PI * uv.y).sin().powf(0.7));
        // Arc length across equals the flat petal's width; u runs towards -x
        // as in `test_petal`, so the normals face the axis.
        let angle_in_ring = -(uv.x - 0.5) * 2.0 * half_width / ring_radius;
        let radius = ring_radius - 0.08 * length * uv.y * uv.y;
        DVec3::new(
            radius * angle_in_ring.sin(),
            uv.y * length,
            radius * angle_in_ring.cos() - ring_radius,
        )
    });
    template_with_mesh(name, mesh, rows)
}

/// Growth maps and material of the test petal around `mesh` (a grid of
/// `rows` rows).
fn template_with_mesh(name: &str, mesh: Mesh, rows: usize) -> Template {
    let row_spacing_in_v = 1.0 / rows.saturating_sub(1).max(1) as f64;
    let base_v_max = (1.01 * row_spacing_in_v).max(0.05);
    let midrib = |u: f64| (-((u - 0.5) / 0.12).powi(2)).exp();
    let above_base = |v: f64| ((v - base_v_max) / 0.1).clamp(0.0, 1.0);
    let early = GrowthMaps {
        e_growth: ScalarMap::from_fn(32, 32, |uv| (0.6 * above_base(uv.y)) as f32),
        w_growth: ScalarMap::from_fn(32, 32, |uv| (0.3 * above_base(uv.y)) as f32),
        e_growth_in: ScalarMap::from_fn(32, 32, |uv| {
            ((0.6 + 0.12 * midrib(uv.x) + 0.03) * above_base(uv.y)) as f32
        }),
        w_growth_in: ScalarMap::from_fn(32, 32, |uv| (0.35 * above_base(uv.y)) as f32),
        ..GrowthMaps::uniform()
    };
    let late = GrowthMaps {
        e_growth_in: ScalarMap::from_fn(32, 32, |uv| (0.62 * above_base(uv.y)) as f32),
        w_growth: ScalarMap::from_fn(32, 32, |uv| (0.4 * above_base(uv.y)) as f32),
        w_growth_in: ScalarMap::from_fn(32, 32, |uv| (0.45 * above_base(uv.y)) as f32),
        ..early.clone()
    };
    #[allow(
        clippy::expect_used,
        reason = "two literal keys at distinct steps cannot fail"
    )]
    let maps = KeyedMaps::new(
        vec![
            MapKey {
                dg: None,
                step: 40,
                maps: early,
            },
            MapKey {
                dg: None,
                step: 50,
                maps: late,
            },
        ],
        anthesis_maps::Blend::Linear,
    )
    .expect("two keys at distinct steps");
    Template {
        name: name.to_string(),
        mesh,
        maps,
        dg: 0.003,
        thickness: 0.2,
        stretch_stiffness: 20.0,
        bend_stiffness: 20.0,
        base_region: BaseRegion {
            v_max: base_v_max,
            ..BaseRegion::default()
        },
        joint_schedule: vec![JointRamp {
            from_step: 0,
            to_step: 60,
            angle_deg: 23.0,
        }],
        colour: [0.95, 0.55, 0.35, 1.0],
        colouring: None,
        two_state: None,
        source: None,
        vein: None,
    }
}

/// `organs` organs in a whorl, alternating an inner ring of petals (even
/// indices) and an outer ring of sepals (odd indices) like a lily: each
/// organ of `columns x rows` particles spans a little more than its share of
/// its ring, so the margins of neighbours overlap, the petal's inside the
/// sepal's, and each such pair gets an overlap rule (from three organs on).
/// The bud is closed (joint angle 0) and opens by the template's joint
/// schedule and growth.
pub fn whorl(organs: usize, columns: usize, rows: usize, keyframes: u32) -> Project {
    let width = 1.3 * columns as f64;
    let per_ring = organs.div_ceil(2).max(1);
    // Half the angle an organ spans at its widest: 30 % more than its share
    // of the ring, and never wrapped more than a lily petal.
    let half_span = (0.65 * PI / per_ring as f64).min(55f64.to_radians());
    let inner_radius = 0.5 * width / half_span;
    let outer_radius = inner_radius + RING_GAP;
    let mut templates = vec![ring_petal_template("petal", columns, rows, inner_radius)];
    if organs >= 2 {
        let mut sepal = ring_petal_template("sepal", columns, rows, outer_radius);
        sepal.colour = [0.6, 0.75, 0.35, 1.0];
        templates.push(sepal);
    }
    let organs_list: Vec<Organ> = (0..organs)
        .map(|i| {
            let inner = i % 2 == 0;
            let azimuth_deg = 360.0 * i as f64 / organs as f64;
            let radius = if inner { inner_radius } else { outer_radius };
            let a = azimuth_deg.to_radians();
            Organ {
                name: format!("{}-{}", if inner { "petal" } else { "sepal" }, i / 2 + 1),
                template: if inner { 0 } else { 1 },
                placement: Placement {
                    position: DVec3::new(radius * a.sin(), 0.0, radius * a.cos()),
                    azimuth_deg,
                    joint_angle_deg: 0.0,
                    orientation: glam::DQuat::IDENTITY,
                },
            }
        })
        .collect();
    let overlaps = if organs >= 3 {
        (0..organs)
            .filter(|i| i % 2 == 0)
            .flat_map(|i| [(i, (i + 1) % organs), (i, (i + organs - 1) % organs)])
            // With an odd count the last petal neighbours the first petal,
            // which is in the same ring: no rule.
            .filter(|&(_, outer)| outer % 2 == 1)
            .map(|(inner, outer)| Overlap { inner, outer })
            .collect()
    } else {
        Vec::new()
    };
    Project {
        name: format!("test whorl of {organs}"),
        flower: Flower {
            templates,
            organs: organs_list,
            overlaps,
            structure: None,
            parts: Vec::new(),
            unit: None,
        },
        settings: SimulationSettings {
            keyframes,
            ..SimulationSettings::default()
        },
    }
}

/// A stroke on time key `key` of `template` with the app's default brush
/// (set towards 0.8 at half strength, radius 0.08, mirrored about the
/// midrib): inner growth along the midrib from v = 0.7 to 0.9, near the tip,
/// the reflex a user paints on the lily's late key. Dabs are a quarter of
/// the radius apart; a uniform map becomes a 64 x 64 raster first.
pub fn stroke_near_tip(project: &mut Project, template: usize, key: usize) {
    use anthesis_maps::brush::{Brush, dab_scalar, ensure_scalar_raster};
    let map = &mut project.flower.templates[template].maps.keys_mut()[key]
        .maps
        .e_growth_in;
    if map.size() == (1, 1) {
        ensure_scalar_raster(map, (64, 64));
    }
    let brush = Brush::default();
    let dabs = (0.2 / (0.25 * brush.radius_in_uv)).ceil() as u32;
    for i in 0..=dabs {
        let v = 0.7 + 0.2 * f64::from(i) / f64::from(dabs);
        dab_scalar(map, &brush, glam::DVec2::new(0.5, v), 0.0);
    }
}

/// Two petals at the same azimuth, one inside the other (bases 1.5 apart,
/// so that attachment never presses the bases together), whose
/// joint schedules drive the inner one through the outer one (20 degrees
/// against 10 over `keyframes` steps). With `overlap`, the flower says the
/// first lies inside the second.
pub fn inner_driven_into_outer(keyframes: u32, overlap: bool) -> Project {
    inner_driven_into_outer_by(keyframes, overlap, 20.0)
}

/// [`inner_driven_into_outer`] with the inner petal's joint driven by
/// `inner_drive_deg` (the outer one's still by 10 degrees): the larger the
/// drive, the deeper the inner organ is pushed into the outer one.
pub fn inner_driven_into_outer_by(keyframes: u32, overlap: bool, inner_drive_deg: f64) -> Project {
    let ramp = |angle_deg: f64| {
        vec![JointRamp {
            from_step: 0,
            to_step: keyframes,
            angle_deg,
        }]
    };
    let mut inner = petal_template("inner petal", 8, 14);
    inner.joint_schedule = ramp(inner_drive_deg);
    let mut outer = petal_template("outer petal", 8, 14);
    outer.joint_schedule = ramp(10.0);
    let organ =
        |name: &str, template: usize, distance_from_axis: f64, joint_angle_deg: f64| Organ {
            name: name.to_string(),
            template,
            placement: Placement {
                position: DVec3::new(0.0, 0.0, distance_from_axis),
                azimuth_deg: 0.0,
                joint_angle_deg,
                orientation: glam::DQuat::IDENTITY,
            },
        };
    Project {
        name: "inner driven into outer".into(),
        flower: Flower {
            templates: vec![inner, outer],
            organs: vec![organ("inner", 0, 0.5, 12.0), organ("outer", 1, 2.0, 18.0)],
            overlaps: if overlap {
                vec![Overlap { inner: 0, outer: 1 }]
            } else {
                Vec::new()
            },
            structure: None,
            parts: Vec::new(),
            unit: None,
        },
        settings: SimulationSettings {
            keyframes,
            ..SimulationSettings::default()
        },
    }
}

//! Small generated flowers for tests and benchmarks (not the default lily,
//! which is built from the bud builder).

use anthesis_flower::{
    BaseRegion, Flower, JointRamp, Organ, Overlap, Placement, Project, SimulationSettings, Template,
};
use anthesis_maps::{GrowthMaps, KeyedMaps, MapKey, ScalarMap};
use anthesis_mesh::generate;
use glam::DVec3;

/// A petal template of about `columns x rows` particles (mean edge about
/// 1.3 for the lily-sized 14 x 28), growing with a midrib that reflexes
/// early and a lamina that widens later, in two time keys.
///
/// The base region is `v <= 0.05`, widened on coarse meshes to hold at
/// least two rows of particles: a single row lies along the joint axis, so
/// shape matching could not hold the joint angle. Nothing grows in the
/// base region.
pub fn petal_template(name: &str, columns: usize, rows: usize) -> Template {
    let length = 1.3 * rows as f64;
    let width = 1.3 * columns as f64;
    let mesh = generate::test_petal(length, width, columns, rows);
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
    let maps = KeyedMaps::new(
        vec![
            MapKey {
                step: 40,
                maps: early,
            },
            MapKey {
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
            degrees: 23.0,
        }],
        color: [0.95, 0.55, 0.35, 1.0],
    }
}

/// `organs` petals of one template (`columns x rows` particles) in a whorl,
/// alternating inner and outer so neighbours overlap like a lily's petals
/// and sepals (overlap rules between neighbours from three organs on).
pub fn whorl(organs: usize, columns: usize, rows: usize, keyframes: u32) -> Project {
    let template = petal_template("petal", columns, rows);
    let organs_list: Vec<Organ> = (0..organs)
        .map(|i| {
            let inner = i % 2 == 0;
            Organ {
                name: format!("{}-{}", if inner { "petal" } else { "sepal" }, i / 2 + 1),
                template: 0,
                placement: Placement {
                    position: DVec3::new(0.0, 0.0, if inner { 1.0 } else { 2.0 }),
                    azimuth_deg: 360.0 * i as f64 / organs as f64,
                    joint_angle_deg: if inner { 12.0 } else { 18.0 },
                },
            }
        })
        .map(|mut o| {
            let a = o.placement.azimuth_deg.to_radians();
            let r = o.placement.position.z;
            o.placement.position = DVec3::new(r * a.sin(), 0.0, r * a.cos());
            o
        })
        .collect();
    let overlaps = if organs >= 3 {
        (0..organs)
            .filter(|i| i % 2 == 0)
            .flat_map(|i| [(i, (i + 1) % organs), (i, (i + organs - 1) % organs)])
            .filter(|(a, b)| a != b)
            .map(|(inner, outer)| Overlap { inner, outer })
            .collect()
    } else {
        Vec::new()
    };
    Project {
        name: format!("test whorl of {organs}"),
        flower: Flower {
            templates: vec![template],
            organs: organs_list,
            overlaps,
        },
        settings: SimulationSettings {
            keyframes,
            ..SimulationSettings::default()
        },
    }
}

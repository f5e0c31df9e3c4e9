//! Self-contact (issue 35): an organ's particles are kept out of its own
//! surface beyond their neighbourhood, so a strip painted to fold onto
//! itself rests on itself instead of passing through.

use anthesis_flower::{
    BaseRegion, Flower, Organ, Placement, Project, SimulationSettings, Template,
};
use anthesis_maps::{GrowthMaps, KeyedMaps, MapKey, ScalarMap};
use anthesis_mesh::{Mesh, generate};
use anthesis_sim::{Keyframe, Selection, Simulation};
use glam::DVec3;

/// A straight strip `rows` particles long whose inner layer grows along it
/// in the band `band` of `v` (and whose outer layer does not grow): the
/// band bends outwards ever more, at `dg` a step, so the strip folds there
/// and its upper half swings down onto its lower half.
fn folded(rows: usize, keyframes: u32, band: (f64, f64), dg: f64) -> Project {
    let length = 1.0 * rows as f64;
    let mut mesh = generate::flat_sheet(6.0, length, 7, rows);
    // Inner side towards -Z: triangles wound around -Z.
    for t in &mut mesh.triangles {
        t.swap(1, 2);
    }
    let maps = GrowthMaps {
        e_growth_in: ScalarMap::from_fn(64, 64, |uv| {
            if uv.y > band.0 && uv.y < band.1 {
                1.0
            } else {
                0.0
            }
        }),
        ..GrowthMaps::uniform()
    };
    #[allow(clippy::expect_used, reason = "one key")]
    let maps = KeyedMaps::new(
        vec![MapKey {
            dg: None,
            step: 0,
            maps,
        }],
        anthesis_maps::Blend::Linear,
    )
    .expect("one key");
    let template = Template {
        name: "strip".into(),
        mesh,
        maps,
        dg,
        thickness: 0.2,
        stretch_stiffness: 20.0,
        bend_stiffness: 20.0,
        base_region: BaseRegion {
            v_max: 0.06,
            ..BaseRegion::default()
        },
        joint_schedule: Vec::new(),
        colour: [1.0; 4],
        colouring: None,
        two_state: None,
        source: None,
        vein: None,
    };
    Project {
        name: "scroll".into(),
        flower: Flower {
            templates: vec![template],
            organs: vec![Organ {
                name: "strip".into(),
                template: 0,
                placement: Placement {
                    position: DVec3::ZERO,
                    azimuth_deg: 0.0,
                    joint_angle_deg: 0.0,
                    orientation: glam::DQuat::IDENTITY,
                },
            }],
            overlaps: Vec::new(),
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

/// How far the strip's midline turns from base to tip, in degrees, summed
/// over its rows (the angle between successive segments of the column
/// nearest the middle, in the plane the strip rolls in).
fn turned_deg(mesh: &Mesh, positions: &[DVec3]) -> f64 {
    let mut midline: Vec<(f64, DVec3)> = mesh
        .uvs
        .iter()
        .zip(positions)
        .filter(|(uv, _)| (uv.x - 0.5).abs() < 1e-9)
        .map(|(uv, p)| (uv.y, *p))
        .collect();
    midline.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut total = 0.0;
    for w in midline.windows(3) {
        let (a, b) = (w[1].1 - w[0].1, w[2].1 - w[1].1);
        let (a, b) = (glam::DVec2::new(a.y, a.z), glam::DVec2::new(b.y, b.z));
        total += a.angle_to(b);
    }
    total.to_degrees().abs()
}

#[test]
fn a_strip_folded_onto_itself_rests_on_itself_at_the_collision_offset() {
    // Without self-contact the upper half passes through the lower one
    // from keyframe 40 (23 crossing triangle pairs in every keyframe after,
    // the fold turning on to 294 degrees by keyframe 60).
    let project = folded(40, 48, (0.45, 0.55), 0.004);
    let mesh = project.flower.templates[0].mesh.clone();
    let offset = project.settings.collision_offset;
    let mut sim = Simulation::new(&project, &Selection::All).expect("valid");
    let mut keyframes: Vec<Keyframe> = vec![sim.bud()];
    while !sim.finished() {
        // A crossing would stop the run here.
        let k = sim
            .step(&|| false, &mut |_| {})
            .unwrap_or_else(|e| panic!("{e}"));
        keyframes.push(k);
    }
    assert!(sim.self_contact_count() > 0);
    // No two of its triangles cross, in any keyframe (every pair tested).
    for k in &keyframes {
        let at = Mesh {
            positions: k.positions_in_world[0].clone(),
            ..mesh.clone()
        };
        assert_eq!(
            anthesis_bud::self_intersections(&at),
            Vec::<[usize; 2]>::new(),
            "keyframe {}",
            k.index
        );
    }
    // The upper half came down onto the lower one (folded past a right
    // angle, by more than 150 degrees) and rests on it: its particles come
    // within a few collision offsets of the lower half's, never nearer
    // than half of one.
    let gap = |p: &[DVec3]| {
        let half = |upper: bool| {
            p.iter()
                .zip(&mesh.uvs)
                .filter(move |(_, uv)| if upper { uv.y > 0.7 } else { uv.y < 0.3 })
                .map(|(x, _)| *x)
        };
        half(true)
            .flat_map(|a| half(false).map(move |b| a.distance(b)))
            .fold(f64::INFINITY, f64::min)
    };
    let folded_by = turned_deg(&mesh, &keyframes[40].positions_in_world[0]);
    assert!(folded_by > 150.0, "folded by {folded_by:.0} degrees");
    let gaps: Vec<f64> = keyframes
        .iter()
        .map(|k| gap(&k.positions_in_world[0]))
        .collect();
    let closest = gaps.iter().copied().fold(f64::INFINITY, f64::min);
    assert!(
        closest >= 0.5 * offset && closest <= 3.0 * offset,
        "closest {closest:.4} against an offset of {offset}"
    );
}

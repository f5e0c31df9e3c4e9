//! The empty starting point of a new flower: one whorl of five simple
//! petals, each a slightly cupped, rounded blade with uniform growth maps
//! (the whole petal lengthens and broadens alike, its inner side a little
//! more along it, so it opens outwards), arranged by a `[structure]` whorl
//! so that the app's Flower panel can change the count, add whorls or
//! replace it by a spiral or an L-system. Nothing about it is tuned to a
//! real species: it is there to be painted.

use anthesis_flower::structure::{Structure, Whorl};
use anthesis_flower::{Flower, JointRamp, Project, SimulationSettings, Template};
use anthesis_maps::{DirectionMap, GrowthMaps, KeyedMaps, ScalarMap};
use glam::DVec2;

use crate::arrangement::nested_whorls;
use crate::buds::RingOrgan;
use crate::flowers::{EDGE_SCALE, GardenError, base_region};

/// The folder name of the five-petal flower under `assets/flowers/`.
pub const FIVE_PETAL_NAME: &str = "five-petal";

/// Mean edge of the simple petal's mesh, in project units, before any
/// `edge_scale` (Eustoma's: some 150 particles per petal at the
/// default [`EDGE_SCALE`]).
pub const SIMPLE_PETAL_EDGE: f64 = 2.0;

/// The simple petal in the bud: a blade 22 long leaning out at about 23°
/// from the axis, widest a little above the middle, with a rounded top;
/// narrow enough that five of them side by side do not overlap (each
/// spans less than ±36° about the axis).
pub fn simple_petal_bud() -> RingOrgan {
    RingOrgan {
        midrib: [
            DVec2::new(4.0, 0.0),
            DVec2::new(6.5, 6.5),
            DVec2::new(9.5, 13.5),
            DVec2::new(12.5, 20.0),
        ],
        half_width: [1.3, 3.4, 4.2, 2.4],
        offset: 0.0,
        contortion: 0.0,
        // 0.35 rounded the top more, but the remesher then folded a
        // triangle of it in the UV layout when a resolution remeshed the
        // petal at 1.5 or 0.6 times its edge (a test remeshes every
        // shipped template so).
        top_rounding: 0.1,
    }
}

/// The simple petal's growth, the same everywhere on it: along the growth
/// direction (`e`), across it (`w`), and how much the inner side outgrows
/// the base along it (the petal bends outwards as it grows).
const SIMPLE_E: f32 = 0.5;
const SIMPLE_W: f32 = 0.4;
const SIMPLE_E_IN_EXCESS: f32 = 0.015;

/// The simple petal's joint: +20° over steps 1–50.
pub const SIMPLE_JOINT: JointRamp = JointRamp {
    from_step: 0,
    to_step: 50,
    angle_deg: 20.0,
};

/// A soft pink (linear RGBA; sRGB about 240, 190, 205).
pub const SIMPLE_PINK: [f32; 4] = [0.87, 0.52, 0.61, 1.0];

/// Uniform growth maps: one key, constant maps (the brush turns a constant
/// map into a raster when it is first painted).
pub fn simple_petal_maps() -> KeyedMaps {
    let maps = GrowthMaps {
        e_growth: ScalarMap::constant(SIMPLE_E),
        w_growth: ScalarMap::constant(SIMPLE_W),
        e_growth_in: ScalarMap::constant(SIMPLE_E + SIMPLE_E_IN_EXCESS),
        w_growth_in: ScalarMap::constant(SIMPLE_W),
        stretch: ScalarMap::constant(1.0),
        bend: ScalarMap::constant(1.0),
        direction: DirectionMap::constant(DVec2::Y),
    };
    KeyedMaps::single(maps)
}

/// The simple petal template named `name`, meshed at `edge_scale` times
/// [`SIMPLE_PETAL_EDGE`], with Eustoma's material (Table 1) and
/// [`simple_petal_maps`].
pub fn simple_petal_template(name: &str, edge_scale: f64) -> Result<Template, GardenError> {
    let organ = "simple petal";
    let mesh = simple_petal_bud()
        .build(SIMPLE_PETAL_EDGE * edge_scale)
        .map_err(|error| GardenError::Bud { organ, error })?;
    Ok(simple_template_of_mesh(name, mesh))
}

/// A template named `name` of `mesh` (made in the app: an imported OBJ, a
/// Bézier petal) with what the simple petal has besides its shape:
/// [`simple_petal_maps`], Eustoma's material, the joint ramp and colour;
/// its base particles those with `v <= 0.05` (at least two rows).
pub fn simple_template_of_mesh(name: &str, mesh: anthesis_mesh::Mesh) -> Template {
    Template {
        name: name.to_string(),
        base_region: base_region(&mesh, 0.05),
        mesh,
        maps: simple_petal_maps(),
        dg: crate::flowers::EUSTOMA_DG,
        thickness: crate::flowers::EUSTOMA_THICKNESS,
        stretch_stiffness: crate::flowers::EUSTOMA_STIFFNESS,
        bend_stiffness: crate::flowers::EUSTOMA_STIFFNESS,
        joint_schedule: vec![SIMPLE_JOINT],
        colour: SIMPLE_PINK,
        colouring: None,
        two_state: None,
        source: None,
        vein: None,
    }
}

/// The whorl of `count` simple petals of template `template`, from azimuth
/// `offset_deg`.
pub fn simple_whorl(name: &str, template: usize, count: usize, offset_deg: f64) -> Whorl {
    let bud = simple_petal_bud();
    let base = bud.base_in_meridian();
    Whorl {
        name: name.to_string(),
        template,
        count,
        offset_deg,
        radius: base.x,
        height: base.y,
        joint_angle_deg: 0.0,
        half_span_deg: bud.half_span_deg(),
    }
}

/// The empty flower: one whorl of five simple petals, no parts.
pub fn five_petal() -> Result<Project, GardenError> {
    five_petal_at(EDGE_SCALE)
}

pub(crate) fn five_petal_at(edge_scale: f64) -> Result<Project, GardenError> {
    let whorls = vec![simple_whorl("petal", 0, 5, 0.0)];
    let arrangement = nested_whorls(&whorls);
    Ok(Project {
        name: "Five petals".to_string(),
        flower: Flower {
            templates: vec![simple_petal_template("petal", edge_scale)?],
            organs: arrangement.organs,
            overlaps: arrangement.overlaps,
            structure: Some(Structure::Whorls {
                whorls,
                contorted: false,
            }),
            parts: Vec::new(),
            // Petals about 2 cm long.
            unit: anthesis_flower::Unit::millimetres(1.0),
        },
        settings: SimulationSettings::default(),
    })
}

/// The five-petal flower with its petal replaced by a wide sketched one,
/// as a user draws it in the window's sketch editor (what
/// `app/tests/xvfb-sketch-petal.sh` drew before issue 40): outline strokes
/// through (∓1, 0), (∓4, 5), (∓6, 10), (∓5, 15), (∓2, 18.5), the vein
/// along x = 0 up to 19 and one cross-section sagging towards the base
/// from (-6.5, 10.8) through (0, 8.6) to (6.5, 10.8), each stroke through
/// its points six mouse moves a segment, applied at the template's own
/// mean edge (the Shape section's remesh edge). Each petal spans more than
/// a fifth of the circle, so neighbours of the one whorl meet as they open
/// (issue 35).
pub fn five_petal_wide_sketch() -> Result<Project, GardenError> {
    five_petal_of_strokes(
        &[-1.0, 0.0, -4.0, 5.0, -6.0, 10.0, -5.0, 15.0, -2.0, 18.5],
        &[1.0, 0.0, 4.0, 5.0, 6.0, 10.0, 5.0, 15.0, 2.0, 18.5],
        &[0.0, 0.0, 0.0, 6.0, 0.0, 12.0, 0.0, 19.0],
        &[-6.5, 10.8, -3.0, 9.2, 0.0, 8.6, 3.0, 9.2, 6.5, 10.8],
    )
}

/// The width factor of [`five_petal_sketch`] the window's sketch test
/// (`app/tests/xvfb-sketch-petal.sh`) draws: a half width of 2.4 on a
/// length of 19. Its five-petal flower has no crossing in the bud and
/// opens to its last keyframe without one (`crates/garden/tests/stress.rs`);
/// 0.42 is the widest that does (0.43 crosses in the bud), so the few
/// hundredths below leave room for the window's strokes, which land on
/// whole pixels.
pub const SKETCH_WIDTH_THAT_FITS: f64 = 0.4;

/// [`five_petal_wide_sketch`]'s petal scaled across by `width`: every
/// stroke point's x times `width`, and the cross-section's sag below its
/// ends (8.6 at the vein, 10.8 at the margins) too, so the petal keeps its
/// rounded outline and its cup's shape (the margins raised in proportion
/// to the width); the vein and the length unchanged.
pub fn five_petal_sketch(width: f64) -> Result<Project, GardenError> {
    let across = |points: &[f64]| -> Vec<f64> {
        points
            .chunks(2)
            .flat_map(|p| [p[0] * width, p[1]])
            .collect()
    };
    let section: Vec<f64> = across(&[-6.5, 10.8, -3.0, 9.2, 0.0, 8.6, 3.0, 9.2, 6.5, 10.8])
        .chunks(2)
        .flat_map(|p| [p[0], 10.8 - (10.8 - p[1]) * width])
        .collect();
    five_petal_of_strokes(
        &across(&[-1.0, 0.0, -4.0, 5.0, -6.0, 10.0, -5.0, 15.0, -2.0, 18.5]),
        &across(&[1.0, 0.0, 4.0, 5.0, 6.0, 10.0, 5.0, 15.0, 2.0, 18.5]),
        &[0.0, 0.0, 0.0, 6.0, 0.0, 12.0, 0.0, 19.0],
        &section,
    )
}

/// The five-petal flower with its petal sketched by strokes through the
/// corners `left`, `right`, `vein` and `section` (x, y pairs), six mouse
/// moves a corner-to-corner segment, applied at the template's own mean
/// edge.
fn five_petal_of_strokes(
    left: &[f64],
    right: &[f64],
    vein: &[f64],
    section: &[f64],
) -> Result<Project, GardenError> {
    let stroke = |points: &[f64]| -> Vec<DVec2> {
        let corners: Vec<DVec2> = points.chunks(2).map(|p| DVec2::new(p[0], p[1])).collect();
        let mut out = vec![corners[0]];
        for pair in corners.windows(2) {
            for s in 1..=6 {
                out.push(pair[0] + (pair[1] - pair[0]) * (f64::from(s) / 6.0));
            }
        }
        out
    };
    let sketch = anthesis_bud::PetalSketch {
        left: stroke(left),
        right: stroke(right),
        vein: stroke(vein),
        sections: vec![stroke(section)],
    }
    .sorted();
    let sketch_error = |e: &dyn std::fmt::Display| GardenError::Sketch(e.to_string());
    let petal = sketch.build().map_err(|e| sketch_error(&e))?;
    let mut project = five_petal()?;
    let edge = anthesis_bud::quality(&project.flower.templates[0].mesh).mean_edge;
    let bud = anthesis_bud::build_organ(&petal.surface, &anthesis_bud::RemeshOptions::new(edge))
        .map_err(|e| sketch_error(&e))?;
    project.flower = project
        .flower
        .with_shape(
            0,
            bud.mesh,
            anthesis_flower::TemplateSource::Sketch { sketch, edge },
        )
        .map_err(|e| sketch_error(&e))?;
    Ok(project)
}

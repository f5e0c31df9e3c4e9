//! The apple flower of Qin and Chen 2006 §3–§4 (issue 13 item 3):
//! the seed's own L-system (3) places a stem, and six segments of calyx,
//! petal and stamen on its end; the calyx and the petal are its Bézier
//! surfaces (§4: the calyx two bicubic patches joined with C⁰ continuity,
//! the petal one), here shaped as a closed bud that the growth maps open.
//!
//! Decided where the seed is silent:
//!
//! - **The L-system** is the seed's text but for the axiom's `/(154) &(72)`,
//!   which the seed says are "set for observation with an appropriate angle
//!   at the computer screen": in Anthesis the camera does that, and the
//!   flower's axis stays the world's +Y. `units` = 0.08 maps the seed's
//!   lengths (a stem of `lenA` = 500, lines 20 wide) onto the scale the
//!   growth parameters are tuned at (the paper's petals are about 45 long):
//!   a stem 40 long, stamens of two lines 8 long and 1.6 wide. The axiom
//!   also sets the colour of the lines B draws (`;(r, g, b)`, an L-Py
//!   symbol the seed does not use): the stamens are a pale yellow, the stem
//!   keeps the default green. The productions are the seed's, line for line.
//! - **The surfaces** are drawn in the turtle's frame, as the seed's `~c`
//!   and `~p` are: their control nets start a little out from the turtle
//!   (which stands on the axis at the stem's end), so the six petals and six
//!   calyx lobes sit around the stamens instead of on top of them. The seed
//!   prints its nets only as figures; these are designed to close over the
//!   stamens: each petal a cupped, clawed blade whose top turns in over the
//!   bud's apex, each calyx a segment of the cup under the petals (S1) with a
//!   pointed lobe hugging the petal (S2).
//! - **Six segments, not five**: the seed's L-system has six (a real apple
//!   flower has five), and calyx and petal of a segment share a direction,
//!   so each petal lies inside the calyx lobe of its own segment and its
//!   neighbours'.

use anthesis_bud::{BezierPatch, RemeshOptions, Surface, build_organ};
use anthesis_flower::structure::Structure;
use anthesis_flower::{Colouring, Flower, Project, SimulationSettings, Template};
use anthesis_maps::{GrowthMaps, KeyedMaps, MapError};
use glam::{DVec2, DVec3};

use crate::flowers::{GardenError, base_region, keyed};
use crate::paint::{Painting, above_base, colour_map, midrib_band, smoothstep};

/// The seed's L-system (3), without the axiom's viewing turns, with a
/// colour for the lines drawn after the stem (see the module
/// documentation) and names for the tubes `A` and `S` draw (`stem`,
/// `stamen-1` … `stamen-18` in the exports and `anthesis info`).
pub const APPLE_LSYSTEM: &str = "\
initial line width = 20
line width increment = 5
lenA = 500
lenF = 100
ω : #A!;(0.93, 0.82, 0.45)B
p1: B → D/(60)D/(60)D/(60)D/(60)D/(60)D
p2: D → [C][P][S]
p3: A → F(lenA)
p4: C → ~c
p5: P → ~p
p6: S → F(lenF)[-(18)F(lenF)][+(18)F(lenF)]
name A = stem
name S = stamen
";

/// Derivation steps: three rewrite the axiom down to `~c`, `~p` and `F`.
pub const APPLE_STEPS: u32 = 3;

/// Project units per unit of the seed's L-system.
pub const APPLE_UNITS: f64 = 0.08;

/// The stem's height (the seed's `lenA`, in project units): where the
/// organs sit.
pub const APPLE_STEM: f64 = 500.0 * APPLE_UNITS;

/// Growth scale: twice the paper's flowers', since an apple petal broadens
/// from a narrow bud petal to a round blade.
pub const APPLE_DG: f64 = 0.006;
/// Thickness of petal and calyx.
pub const APPLE_THICKNESS: f64 = 0.12;
/// Stretch and bend stiffness scale.
pub const APPLE_STIFFNESS: f64 = 10.0;
/// Mean edge of the petal mesh.
pub const APPLE_PETAL_EDGE: f64 = 0.8;
/// Mean edge of the calyx mesh.
pub const APPLE_CALYX_EDGE: f64 = 0.7;

/// Apple blossom white, a little warm (linear RGBA).
pub const APPLE_WHITE: [f32; 4] = [0.92, 0.88, 0.86, 1.0];
/// The pink of the petals' backs and margins, strongest in the bud.
pub const APPLE_PINK: [f32; 4] = [0.80, 0.22, 0.36, 1.0];
/// The calyx: a grey green.
pub const APPLE_CALYX_GREEN: [f32; 4] = [0.22, 0.36, 0.12, 1.0];

/// A point of a bud row: `rho` from the axis, at `height`, at angle `phi`
/// about the axis from the template's +Z (`u` runs along −X, so the `u = 0`
/// margin is at negative `phi`).
fn on_ring(rho: f64, height: f64, phi: f64) -> DVec3 {
    DVec3::new(-rho * phi.sin(), height, rho * phi.cos())
}

/// The four control points of a cubic Bézier close to the arc of radius
/// `rho` at `height` from angle `-half` to `half` (the standard
/// `4/3 tan(θ/4)` handles).
fn arc_row(rho: f64, height: f64, half: f64) -> [DVec3; 4] {
    let k = 4.0 / 3.0 * (half / 2.0).tan();
    let tangent = |phi: f64| DVec3::new(-rho * phi.cos(), 0.0, -rho * phi.sin());
    let (a, b) = (on_ring(rho, height, -half), on_ring(rho, height, half));
    [a, a + k * tangent(-half), b - k * tangent(half), b]
}

/// A patch whose rows are arcs about the axis: row `j` at `(rho, height)` =
/// `rows[j].0`, spanning `±rows[j].1` radians.
fn ring_patch(rows: [(DVec2, f64); 4]) -> BezierPatch {
    BezierPatch::new(rows.map(|(at, half)| arc_row(at.x, at.y, half)))
}

/// The petal's control net (seed §4, one bicubic patch) in the closed bud:
/// a claw 1.1 wide leaving the axis at 1.8, a blade widest (±27°, under
/// the 30° that would touch its neighbours) at mid-height, and a rounded
/// top turned in over the stamens at 17.5.
pub fn apple_petal_net() -> BezierPatch {
    ring_patch([
        (DVec2::new(1.8, 0.0), 0.3),
        (DVec2::new(8.0, 3.5), 0.47),
        (DVec2::new(9.5, 15.5), 0.47),
        (DVec2::new(2.6, 18.5), 0.36),
    ])
}

/// How far the calyx lies outside the petal in the bud.
const CALYX_GAP: f64 = 0.9;

/// The calyx's two control nets (seed §4: S1 and S2, joined with C⁰
/// continuity along S1's top row, which is S2's bottom row): S1 a segment
/// of the cup under the petals, S2 a pointed lobe up their outside.
pub fn apple_calyx_nets() -> [BezierPatch; 2] {
    let joint = (DVec2::new(6.2, 2.6), 0.46);
    let s1 = ring_patch([
        (DVec2::new(1.8 + CALYX_GAP, -0.6), 0.36),
        (DVec2::new(4.0, -0.4), 0.43),
        (DVec2::new(5.4, 1.0), 0.47),
        joint,
    ]);
    let s2 = ring_patch([
        joint,
        (DVec2::new(8.8, 5.5), 0.36),
        (DVec2::new(10.0, 8.5), 0.14),
        (DVec2::new(9.6, 10.5), 0.0),
    ]);
    [s1, s2]
}

/// The calyx as one surface over the unit square: S1 for `v` up to 0.35,
/// S2 above (so the lobe, the longer part, gets more of the UV square).
struct Calyx([BezierPatch; 2]);

/// Where S1 ends in the calyx's `v`.
const CALYX_JOIN_V: f64 = 0.35;

impl Surface for Calyx {
    fn point(&self, uv: DVec2) -> DVec3 {
        if uv.y <= CALYX_JOIN_V {
            self.0[0].point(DVec2::new(uv.x, uv.y / CALYX_JOIN_V))
        } else {
            self.0[1].point(DVec2::new(
                uv.x,
                (uv.y - CALYX_JOIN_V) / (1.0 - CALYX_JOIN_V),
            ))
        }
    }
}

/// The apple petal's growth maps: regions by `v`, early maps to step 40 and
/// late ones from 60, blended between (found by simulating and looking at
/// the flower: a saucer of cupped petals, the claws about 65° from the
/// axis, the blades about level).
///
/// - The claw and the lower blade: early, the inner side outgrows the outer
///   (by 0.2), so the petal bends out of the bud from its base; late they
///   grow alike and the petal stays where it got to;
/// - the blade broadens much more than it lengthens (w-growth 0.9 against
///   e-growth 0.25–0.35): the narrow bud petal becomes a round blade; its
///   inner side broadens a little more (0.04–0.05), which undoes most of
///   the bud's cupping across (more rolls the margins back);
/// - the top, turned in over the apex in the bud: early its outer side
///   grows a little more, so it unrolls;
/// - the claw is twice as stiff as the blade.
pub fn apple_petal_maps() -> Result<KeyedMaps, MapError> {
    let grows = |uv: DVec2| above_base(uv.y, 0.05, 0.05);
    let lower = |v: f64| 1.0 - smoothstep(0.15, 0.45, v);
    let top = |v: f64| smoothstep(0.7, 0.95, v);
    let stiffness = |uv: DVec2| 1.0 - 0.5 * smoothstep(0.1, 0.5, uv.y);
    let direction = |uv: DVec2| DVec2::new(0.5 * (uv.x - 0.5) * uv.y, 1.0);
    let key = |bend: f64, unroll: f64, flatten: f64| -> GrowthMaps {
        let e = |uv: DVec2| grows(uv) * (0.25 + 0.1 * lower(uv.y));
        let e_in = |uv: DVec2| {
            let v = uv.y;
            e(uv) + grows(uv) * (bend * lower(v) - unroll * top(v))
        };
        let w = |uv: DVec2| grows(uv) * (0.3 + 0.62 * smoothstep(0.1, 0.5, uv.y));
        let w_in = |uv: DVec2| w(uv) + grows(uv) * flatten * smoothstep(0.2, 0.6, uv.y);
        Painting {
            e_growth: &e,
            w_growth: &w,
            e_growth_in: &e_in,
            w_growth_in: &w_in,
            stretch: &stiffness,
            bend: &stiffness,
            direction: &direction,
        }
        .paint()
    };
    keyed(vec![(40, key(0.2, 0.05, 0.04)), (60, key(0.0, 0.0, 0.05))])
}

/// The calyx's maps: the cup (S1) hardly grows; the lobe lengthens and its
/// inner side outgrows the outer, so the lobes turn out and down as the
/// petals open.
pub fn apple_calyx_maps() -> Result<KeyedMaps, MapError> {
    let lobe = |v: f64| smoothstep(CALYX_JOIN_V - 0.05, CALYX_JOIN_V + 0.1, v);
    let grows = |uv: DVec2| above_base(uv.y, 0.05, 0.05);
    let stiffness = |uv: DVec2| 1.0 - 0.4 * lobe(uv.y);
    let direction = |_: DVec2| DVec2::Y;
    let key = |bend: f64| -> GrowthMaps {
        let e = |uv: DVec2| grows(uv) * (0.1 + 0.3 * lobe(uv.y));
        let e_in = |uv: DVec2| e(uv) + grows(uv) * bend * lobe(uv.y);
        let w = |uv: DVec2| grows(uv) * (0.1 + 0.2 * lobe(uv.y));
        Painting {
            e_growth: &e,
            w_growth: &w,
            e_growth_in: &e_in,
            w_growth_in: &w,
            stretch: &stiffness,
            bend: &stiffness,
            direction: &direction,
        }
        .paint()
    };
    keyed(vec![(40, key(0.15)), (60, key(0.0))])
}

/// How much of the pink shows on a petal: along the margins and over the
/// top, fading towards the white centre; the claw stays white.
pub fn apple_blush(uv: DVec2) -> f64 {
    let margin = 1.0 - midrib_band(uv.x, 0.5);
    let rim = smoothstep(0.55, 0.95, margin.max(smoothstep(0.7, 1.0, uv.y)));
    0.55 * rim * smoothstep(0.2, 0.5, uv.y)
}

/// A template of `mesh` with the apple's material.
fn apple_template(
    name: &str,
    mesh: anthesis_mesh::Mesh,
    maps: KeyedMaps,
    colour: [f32; 4],
) -> Template {
    Template {
        name: name.to_string(),
        base_region: base_region(&mesh, 0.05),
        mesh,
        maps,
        dg: APPLE_DG,
        thickness: APPLE_THICKNESS,
        stretch_stiffness: APPLE_STIFFNESS,
        bend_stiffness: APPLE_STIFFNESS,
        joint_schedule: Vec::new(),
        colour,
        colouring: None,
        two_state: None,
        source: None,
        vein: None,
    }
}

/// The petal template: [`apple_petal_net`] meshed at `edge`.
pub fn apple_petal_template(edge: f64) -> Result<Template, GardenError> {
    let organ = "apple petal";
    let bud = build_organ(&apple_petal_net(), &RemeshOptions::new(edge))
        .map_err(|error| GardenError::Bud { organ, error })?;
    let maps = apple_petal_maps().map_err(|error| GardenError::Maps { organ, error })?;
    let mut petal = apple_template("petal", bud.mesh, maps, APPLE_WHITE);
    petal.colouring = Some(Colouring {
        second_colour: APPLE_PINK,
        mix: colour_map(apple_blush),
        layers: Vec::new(),
    });
    Ok(petal)
}

/// The calyx template: [`apple_calyx_nets`] meshed at `edge`.
pub fn apple_calyx_template(edge: f64) -> Result<Template, GardenError> {
    let organ = "apple calyx";
    let bud = build_organ(&Calyx(apple_calyx_nets()), &RemeshOptions::new(edge))
        .map_err(|error| GardenError::Bud { organ, error })?;
    let maps = apple_calyx_maps().map_err(|error| GardenError::Maps { organ, error })?;
    Ok(apple_template("calyx", bud.mesh, maps, APPLE_CALYX_GREEN))
}

/// The apple's solver tolerance, a hundredth of the default. Its six calyx
/// and petal segments are alike, but where calyx and petal press together
/// the opening depends sharply on how far the contacts hold them apart
/// (a thousandth of an edge more moves it 2 % of an organ's size), and at
/// the default tolerance the rounding that differs from segment to segment
/// grew into segments up to 10 % of an organ apart by the last keyframe;
/// at 1e-7 they stay alike, for 8 % more Newton iterations.
const APPLE_TOLERANCE: f64 = 1e-7;

/// The apple flower with its meshes at `edge_scale` times the default
/// edges (1 for the built-in project).
pub fn apple_at(edge_scale: f64) -> Result<Project, GardenError> {
    let templates = vec![
        apple_calyx_template(APPLE_CALYX_EDGE * edge_scale)?,
        apple_petal_template(APPLE_PETAL_EDGE * edge_scale)?,
    ];
    let structure = Structure::LSystem {
        text: APPLE_LSYSTEM.to_string(),
        steps: APPLE_STEPS,
        surfaces: [('c', 0), ('p', 1)].into_iter().collect(),
        units: APPLE_UNITS,
    };
    let arrangement = structure
        .arrange(&templates)
        .map_err(|e| GardenError::Arrangement(format!("the apple's L-system: {e}")))?;
    let mut settings = SimulationSettings::default();
    settings.solver.relative_tolerance = APPLE_TOLERANCE;
    Ok(Project {
        name: "Apple blossom".to_string(),
        flower: Flower {
            templates,
            organs: arrangement.organs,
            overlaps: arrangement.overlaps,
            structure: Some(structure),
            parts: crate::parts::apple_parts(APPLE_STEM),
            // Petals about 2.5 cm long when open (about 21 units).
            unit: anthesis_flower::Unit::millimetres(1.2),
        },
        settings,
    })
}

/// The apple flower (`builtin:apple`).
pub fn apple() -> Result<Project, GardenError> {
    apple_at(1.0)
}

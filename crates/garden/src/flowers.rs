//! The default projects: the Asiatic lily (paper §6.1) and three
//! cultivars of *Eustoma grandiflorum* grown from one bud (§6.2), with the
//! parameters of Table 1.

use anthesis_bud::BudError;
use anthesis_flower::{
    BaseRegion, ColourLayer, Colouring, Flower, JointRamp, Project, SimulationSettings, Template,
};
use anthesis_maps::{Blend, GrowthMaps, KeyedMaps, MapError, MapKey};
use anthesis_mesh::Mesh;
use glam::DVec2;

use crate::arrangement::{Whorl, contorted_whorl, nested_whorls};
use crate::buds::RingOrgan;
use crate::paint::{Painting, above_base, colour_map, midrib_band, smoothstep, spots};

/// Why a default flower could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GardenError {
    /// An organ's bud mesh could not be built (e.g. an `edge_scale` too
    /// small or too large for the organ).
    #[error("the {organ} bud: {error}")]
    Bud {
        /// Which organ, e.g. "petal" or "sepal".
        organ: &'static str,
        /// Why the remesher refused.
        error: BudError,
    },
    /// An organ's painted growth maps could not be built.
    #[error("the {organ} maps: {error}")]
    Maps {
        /// Which organ, e.g. "petal" or "sepal".
        organ: &'static str,
        /// What is wrong with the maps.
        error: MapError,
    },
    /// The organs cannot be arranged with the overlap rules the flower
    /// needs (e.g. Eustoma petals too narrow to overlap their neighbours);
    /// the message says which organs and why.
    #[error("{0}")]
    Arrangement(String),
    /// A sketched petal could not be built, meshed or used.
    #[error("the sketched petal: {0}")]
    Sketch(String),
}

/// The names of the default flowers (folder names under `assets/flowers/`):
/// the paper's four, the seed's apple flower, the empty five-petal
/// starting point, the lily's bloom and decay and the lily opened by edge
/// growth.
pub const FLOWER_NAMES: [&str; 8] = [
    "lily",
    "eustoma-mellow-yellow",
    "eustoma-maite-lady",
    "eustoma-pinocchio",
    "apple",
    crate::five_petal::FIVE_PETAL_NAME,
    "lily-decay",
    crate::edge::LILY_EDGE_NAME,
];

/// Builds the default flower called `name` (one of [`FLOWER_NAMES`]).
pub fn flower(name: &str) -> Option<Result<Project, GardenError>> {
    if name == crate::edge::LILY_EDGE_NAME {
        // Finer than the others: it resolves its thin sheet.
        return Some(crate::edge::lily_edge());
    }
    flower_at_resolution(name, EDGE_SCALE)
}

/// The default flowers' mean edges, as a fraction of the paper's (Table 1):
/// fine enough that every flower's final shape lies within 5 % (tip
/// distance over midrib length) of the same flower at four times the
/// particles (README, refinement table). At the paper's own meshes the
/// lily's midrib band is only about four triangles wide and its tip lands
/// 9 % away; at 0.7 of them, 5.6 %; at 0.6, 2.4 %.
pub const EDGE_SCALE: f64 = 0.6;

/// Builds the default flower called `name` with every bud remeshed at
/// `edge_scale` times the paper's mean edge (Table 1; the default flowers
/// use [`EDGE_SCALE`], and half of it gives about four times their
/// particles): the same bud surfaces and the same maps, so the runs differ
/// only in resolution (used by the refinement study).
pub fn flower_at_resolution(name: &str, edge_scale: f64) -> Option<Result<Project, GardenError>> {
    Some(match name {
        "lily" => lily_at(edge_scale),
        "eustoma-mellow-yellow" => eustoma_at(Cultivar::MellowYellow, edge_scale),
        "eustoma-maite-lady" => eustoma_at(Cultivar::MaiteLady, edge_scale),
        "eustoma-pinocchio" => eustoma_at(Cultivar::Pinocchio, edge_scale),
        crate::five_petal::FIVE_PETAL_NAME => crate::five_petal::five_petal_at(edge_scale),
        "apple" => crate::apple::apple_at(edge_scale / EDGE_SCALE),
        "lily-decay" => crate::decay::lily_decay_at(edge_scale),
        crate::edge::LILY_EDGE_NAME => {
            crate::edge::lily_edge_of(crate::edge::LilyEdge::MARGIN, edge_scale)
        }
        _ => return None,
    })
}

// ---------------------------------------------------------------------------
// Lily

/// Table 1: the lily's growth scale, thickness and stiffness.
pub const LILY_DG: f64 = 0.003;
/// Table 1: the lily's thickness (distance of the imaginary inner surface),
/// in the project's length units.
pub const LILY_THICKNESS: f64 = 0.2;
/// Table 1: the lily's stiffness, used for both the stretch (`Ks`) and
/// the bend (`Kb`) scale of its templates.
pub const LILY_STIFFNESS: f64 = 20.0;
/// Table 1: mean edge of the lily's petal and sepal meshes.
pub const LILY_PETAL_EDGE: f64 = 1.3;
/// Table 1: mean edge of the lily's sepal mesh, in the project's length
/// units (before any `edge_scale`).
pub const LILY_SEPAL_EDGE: f64 = 1.4;
/// Distance between the petal and sepal surfaces in the bud.
pub const LILY_SEPAL_GAP: f64 = 1.2;

/// The lily's inner tepal (petal) in the closed bud: 44 high, widest
/// (about 15) a little below the middle, pointed, its tip near the axis.
pub fn lily_petal_bud() -> RingOrgan {
    RingOrgan {
        midrib: [
            DVec2::new(2.0, 0.0),
            DVec2::new(11.0, 8.0),
            DVec2::new(10.0, 34.0),
            DVec2::new(0.9, 44.0),
        ],
        half_width: [1.0, 10.2, 9.6, 0.0],
        offset: 0.0,
        contortion: 0.0,
        top_rounding: 0.0,
    }
}

/// The lily's outer tepal (sepal): the petal's profile pushed out by
/// [`LILY_SEPAL_GAP`], a little narrower, so it is longer around the
/// outside of the bud and narrower.
pub fn lily_sepal_bud() -> RingOrgan {
    RingOrgan {
        half_width: [0.8, 8.8, 9.3, 0.0],
        offset: LILY_SEPAL_GAP,
        ..lily_petal_bud()
    }
}

/// Half the width of the lily's midrib band, in `u`.
pub(crate) const LILY_MIDRIB_HALF_WIDTH: f64 = 0.12;

/// Where the lily's maps change: the attachment (`v` up to this) does not
/// grow.
pub(crate) const LILY_BASE_V: f64 = 0.06;

/// How much e-growth-in exceeds e-growth on the lily's tepals (negative:
/// the outer side grows more).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LilyExcess {
    /// On the midrib, early (steps 1–40); late it is 0.
    pub midrib_early: f64,
    /// On the lamina, early.
    pub lamina_early: f64,
    /// On the lamina, late (steps 50–100).
    pub lamina_late: f64,
    /// On the bottom region, early; late it is 0.
    pub bottom_early: f64,
}

impl LilyExcess {
    /// The petal's.
    pub const PETAL: LilyExcess = LilyExcess {
        midrib_early: 0.5,
        lamina_early: 0.08,
        lamina_late: 0.01,
        bottom_early: -0.4,
    };
    /// The sepal's: a little less on the blade, since the narrower, less
    /// cupped sepal bends back more easily; with the petal's excess it ends
    /// 40° further reflexed while the paper has them open alike.
    pub const SEPAL: LilyExcess = LilyExcess {
        midrib_early: 0.45,
        lamina_early: 0.05,
        lamina_late: 0.005,
        bottom_early: -0.4,
    };

    /// The control of the paper's Fig. 13: the midrib grows like the lamina
    /// beside it.
    pub fn without_midrib_warping(self) -> LilyExcess {
        LilyExcess {
            midrib_early: self.lamina_early,
            ..self
        }
    }
}

/// The lily's growth maps (paper §6.1, Fig. 2), painted alike for petals
/// and sepals ("the opening behavior of a sepal is almost the same as that
/// of a petal") but for how much the inner side outgrows the base
/// ([`LilyExcess`]):
///
/// - three regions: the *midrib* (a band around `u = 0.5`), the *bottom*
///   (`v` below about 0.15) and the *lamina* (the rest);
/// - e-growth elongates midrib and lamina equally, the bottom less;
/// - early (steps 1–40) e-growth-in exceeds e-growth strongly on the midrib
///   ("the midrib reflexes strongly and pulls the lamina behind") and
///   slightly on the lamina; late (50–100) they are equal on the midrib
///   ("the midrib gradually stops warping") and the lamina keeps a slight
///   excess; linear blend in between;
/// - early, the bottom region's outer side grows more than its inner one,
///   so the tepals' claws turn back up around the pistil and stamens while
///   the joint (+23° over steps 1–60) tilts them out: the flower keeps a
///   cupped base while the blades reflex;
/// - w-growth and w-growth-in are slightly larger on the lamina;
/// - direction along the parallel venation, fanning a little to the
///   margins; the midrib is stiffer than the lamina.
///
/// The maps are clamped to `[0, 1]`, so the midrib's early inner growth
/// (`E + midrib_early`) is at most 1: e-growth is 0.5 to leave it room.
pub fn lily_maps(excess: LilyExcess) -> Result<KeyedMaps, MapError> {
    const E: f64 = 0.5;
    const E_BOTTOM: f64 = 0.4;
    const W_MIDRIB: f64 = 0.15;
    const W_LAMINA: f64 = 0.3;
    const W_IN_EXCESS: f64 = 0.12;
    let midrib = |uv: DVec2| midrib_band(uv.x, LILY_MIDRIB_HALF_WIDTH);
    let bottom = |uv: DVec2| 1.0 - smoothstep(0.1, 0.2, uv.y);
    let grows = |uv: DVec2| above_base(uv.y, LILY_BASE_V, 0.04);
    let e = move |uv: DVec2| grows(uv) * (E + (E_BOTTOM - E) * bottom(uv));
    let w = move |uv: DVec2| {
        grows(uv)
            * (W_MIDRIB + (W_LAMINA - W_MIDRIB) * (1.0 - midrib(uv)))
            * (1.0 - 0.5 * bottom(uv))
    };
    let w_in =
        move |uv: DVec2| w(uv) + grows(uv) * (1.0 - bottom(uv)) * W_IN_EXCESS * (1.0 - midrib(uv));
    let e_in = move |uv: DVec2, midrib_excess: f64, lamina_excess: f64, bottom_excess: f64| {
        let m = midrib(uv);
        let blade = midrib_excess * m + lamina_excess * (1.0 - m);
        e(uv) + grows(uv) * (blade * (1.0 - bottom(uv)) + bottom_excess * bottom(uv))
    };
    let e_in_early = move |uv: DVec2| {
        e_in(
            uv,
            excess.midrib_early,
            excess.lamina_early,
            excess.bottom_early,
        )
    };
    let e_in_late = move |uv: DVec2| e_in(uv, 0.0, excess.lamina_late, 0.0);
    let stiffness = move |uv: DVec2| 0.3 + (1.0 - 0.3) * midrib(uv);
    let direction = |uv: DVec2| DVec2::new(0.15 * (uv.x - 0.5) * uv.y, 1.0);
    let key = |e_in: &dyn Fn(DVec2) -> f64| {
        Painting {
            e_growth: &e,
            w_growth: &w,
            e_growth_in: e_in,
            w_growth_in: &w_in,
            stretch: &stiffness,
            bend: &stiffness,
            direction: &direction,
        }
        .paint()
    };
    keyed(vec![(40, key(&e_in_early)), (50, key(&e_in_late))])
}

pub(crate) fn keyed(keys: Vec<(u32, GrowthMaps)>) -> Result<KeyedMaps, MapError> {
    KeyedMaps::new(
        keys.into_iter()
            .map(|(step, maps)| MapKey {
                dg: None,
                step,
                maps,
            })
            .collect(),
        Blend::Linear,
    )
}

/// A base region of `v <= v_max`, widened to hold at least two rows of
/// particles of `mesh` (one row lies along the joint axis and could not
/// hold the joint angle).
pub(crate) fn base_region(mesh: &Mesh, v_max: f64) -> BaseRegion {
    let mut vs: Vec<f64> = mesh.uvs.iter().map(|uv| uv.y).collect();
    vs.sort_by(f64::total_cmp);
    vs.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    let second_row = vs.get(1).copied().unwrap_or(v_max);
    BaseRegion {
        v_max: v_max.max(second_row + 1e-6),
        ..BaseRegion::default()
    }
}

/// What a template is made of, besides its name.
struct TemplateSpec {
    /// Names the organ in errors.
    organ: &'static str,
    bud: RingOrgan,
    edge: f64,
    dg: f64,
    thickness: f64,
    stiffness: f64,
    base_v: f64,
    joint: JointRamp,
    colour: [f32; 4],
}

fn template(
    name: &str,
    spec: &TemplateSpec,
    maps: Result<KeyedMaps, MapError>,
) -> Result<Template, GardenError> {
    let organ = spec.organ;
    let mesh = spec
        .bud
        .build(spec.edge)
        .map_err(|error| GardenError::Bud { organ, error })?;
    let maps = maps.map_err(|error| GardenError::Maps { organ, error })?;
    Ok(Template {
        name: name.to_string(),
        base_region: base_region(&mesh, spec.base_v),
        mesh,
        maps,
        dg: spec.dg,
        thickness: spec.thickness,
        stretch_stiffness: spec.stiffness,
        bend_stiffness: spec.stiffness,
        joint_schedule: vec![spec.joint],
        colour: spec.colour,
        colouring: None,
        two_state: None,
        source: None,
        vein: None,
    })
}

/// The lily's joint: +23° over steps 1–60 (paper §6.1).
pub const LILY_JOINT: JointRamp = JointRamp {
    from_step: 0,
    to_step: 60,
    angle_deg: 23.0,
};

fn lily_spec(organ: &'static str, bud: RingOrgan, edge: f64, colour: [f32; 4]) -> TemplateSpec {
    TemplateSpec {
        organ,
        bud,
        edge,
        dg: LILY_DG,
        thickness: LILY_THICKNESS,
        stiffness: LILY_STIFFNESS,
        base_v: LILY_BASE_V,
        joint: LILY_JOINT,
        colour,
    }
}

/// The lily petal template: [`lily_petal_bud`] meshed at `edge_scale`
/// times Table 1's edge 1.3 ([`EDGE_SCALE`] for the shipped lily: about
/// 2.6 times the paper's 388 particles), [`lily_maps`], Table 1's material.
fn lily_petal_template_at(edge_scale: f64) -> Result<Template, GardenError> {
    let spec = lily_spec(
        "lily petal",
        lily_petal_bud(),
        LILY_PETAL_EDGE * edge_scale,
        LILY_WHITE,
    );
    let mut petal = template("petal", &spec, lily_maps(LilyExcess::PETAL))?;
    petal.colouring = Some(lily_colouring(7, 26));
    Ok(petal)
}

/// The lily's tepals: a warm white (linear RGBA; sRGB about 247, 245, 238).
pub const LILY_WHITE: [f32; 4] = [0.93, 0.91, 0.855, 1.0];
/// The lily's throat: a greenish yellow (sRGB about 190, 205, 90).
pub const LILY_THROAT: [f32; 4] = [0.515, 0.61, 0.1, 1.0];
/// The lily's spots: crimson (sRGB about 150, 15, 40).
pub const LILY_CRIMSON: [f32; 4] = [0.305, 0.005, 0.021, 1.0];

/// How much of the throat colour shows on a lily tepal: all of it at the
/// base, along the midrib (wider at the base), fading out by a third of
/// the length, and a faint streak up the midrib to about half way.
pub fn lily_throat(uv: DVec2) -> f64 {
    let (u, v) = (uv.x, uv.y);
    let base = (1.0 - smoothstep(0.04, 0.34, v)) * midrib_band(u, 0.16 + 0.22 * (1.0 - v));
    let streak = 0.45 * midrib_band(u, 0.035) * (1.0 - smoothstep(0.25, 0.55, v));
    base.max(streak)
}

/// A lily tepal's colours: [`LILY_WHITE`], the greenish-yellow throat
/// ([`lily_throat`]) and `count` small crimson spots (pseudo-random from
/// `seed`) on the inner half, between the throat and the middle, nearer
/// the midrib than the margins.
fn lily_colouring(seed: u64, count: usize) -> Colouring {
    // The tepal is about three times longer than wide: spots three times
    // wider in u than in v are round on it.
    let spotted = spots(seed, count, (0.14, 0.5), 0.2, 0.011, 3.0);
    Colouring {
        second_colour: LILY_THROAT,
        mix: colour_map(lily_throat),
        layers: vec![ColourLayer {
            colour: LILY_CRIMSON,
            mix: colour_map(spotted),
            // The spots are inside the flower only.
            side: anthesis_flower::Side::Inner,
        }],
    }
}

/// The lily sepal template: [`lily_sepal_bud`] meshed at `edge_scale`
/// times Table 1's edge 1.4 ([`EDGE_SCALE`] for the shipped lily: about
/// 2.6 times the paper's 323 particles), the petal's maps.
fn lily_sepal_template_at(edge_scale: f64) -> Result<Template, GardenError> {
    let spec = lily_spec(
        "lily sepal",
        lily_sepal_bud(),
        LILY_SEPAL_EDGE * edge_scale,
        LILY_WHITE,
    );
    let mut sepal = template("sepal", &spec, lily_maps(LilyExcess::SEPAL))?;
    // The outer tepals: the same colours, fewer spots.
    sepal.colouring = Some(lily_colouring(11, 18));
    Ok(sepal)
}

/// The whorls of a bud of `organs` of shape `bud`, `count` of them from
/// azimuth `offset_deg`.
fn ring_whorl(
    name: &str,
    template: usize,
    bud: &RingOrgan,
    count: usize,
    offset_deg: f64,
) -> Whorl {
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

/// The Asiatic lily: three petals inside three sepals.
pub fn lily() -> Result<Project, GardenError> {
    lily_at(EDGE_SCALE)
}

pub(crate) fn lily_at(edge_scale: f64) -> Result<Project, GardenError> {
    let templates = vec![
        lily_petal_template_at(edge_scale)?,
        lily_sepal_template_at(edge_scale)?,
    ];
    let arrangement = nested_whorls(&[
        ring_whorl("petal", 0, &lily_petal_bud(), 3, 0.0),
        ring_whorl("sepal", 1, &lily_sepal_bud(), 3, 60.0),
    ]);
    Ok(Project {
        name: "Asiatic lily".to_string(),
        flower: Flower {
            templates,
            organs: arrangement.organs,
            overlaps: arrangement.overlaps,
            structure: None,
            parts: crate::parts::lily_parts(),
            // Tepals about 9 cm long when open (about 50 units).
            unit: anthesis_flower::Unit::millimetres(1.8),
        },
        settings: SimulationSettings::default(),
    })
}

// ---------------------------------------------------------------------------
// Eustoma

/// The three cultivars of paper §6.2.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cultivar {
    /// Bell group.
    MellowYellow,
    /// Funnel group.
    MaiteLady,
    /// Shallow-ball group.
    Pinocchio,
}

impl Cultivar {
    /// The three cultivars, in the paper's order.
    pub const ALL: [Cultivar; 3] = [
        Cultivar::MellowYellow,
        Cultivar::MaiteLady,
        Cultivar::Pinocchio,
    ];

    /// The project's name, e.g. `Eustoma 'Mellow Yellow'`.
    pub fn project_name(self) -> &'static str {
        match self {
            Cultivar::MellowYellow => "Eustoma 'Mellow Yellow'",
            Cultivar::MaiteLady => "Eustoma 'Maite Lady'",
            Cultivar::Pinocchio => "Eustoma 'Pinocchio'",
        }
    }

    /// The project's folder under `assets/flowers/`, e.g.
    /// `eustoma-mellow-yellow` (one of [`FLOWER_NAMES`]).
    pub fn folder_name(self) -> &'static str {
        match self {
            Cultivar::MellowYellow => "eustoma-mellow-yellow",
            Cultivar::MaiteLady => "eustoma-maite-lady",
            Cultivar::Pinocchio => "eustoma-pinocchio",
        }
    }

    fn colour(self) -> [f32; 4] {
        match self {
            Cultivar::MellowYellow => [0.97, 0.9, 0.5, 1.0],
            // White with a purple picotee rim.
            Cultivar::MaiteLady => [0.9, 0.88, 0.91, 1.0],
            Cultivar::Pinocchio => [0.62, 0.42, 0.82, 1.0],
        }
    }

    /// The cultivar's colour map: Mellow Yellow's cream-yellow petals turn
    /// lime green towards the base; Maite Lady's white petals have a purple
    /// picotee margin over their upper half; Pinocchio's violet petals
    /// deepen to a dark purple blush from the base.
    pub fn colouring(self) -> Colouring {
        match self {
            Cultivar::MellowYellow => Colouring {
                // sRGB about 165, 200, 60.
                second_colour: [0.376, 0.578, 0.045, 1.0],
                mix: colour_map(|uv| 0.85 * (1.0 - smoothstep(0.05, 0.4, uv.y))),
                layers: Vec::new(),
            },
            Cultivar::MaiteLady => Colouring {
                // sRGB about 150, 40, 140.
                second_colour: [0.305, 0.021, 0.262, 1.0],
                mix: colour_map(eustoma_picotee),
                layers: Vec::new(),
            },
            Cultivar::Pinocchio => Colouring {
                // sRGB about 80, 20, 110.
                second_colour: [0.08, 0.007, 0.155, 1.0],
                mix: colour_map(|uv| 1.0 - smoothstep(0.04, 0.45, uv.y)),
                layers: Vec::new(),
            },
        }
    }
}

/// A picotee rim on an Eustoma petal: the margin (`u` near 0 or 1) and the
/// rounded top (`v` near 1) of the upper half, about a tenth of the half
/// width wide, with a soft inner edge that feathers along the veins.
pub fn eustoma_picotee(uv: DVec2) -> f64 {
    let (u, v) = (uv.x, uv.y);
    let to_margin = u.min(1.0 - u).min(0.5 * (1.0 - v));
    let feather = 0.012 * (1.0 + (u * 60.0).sin());
    let rim = 1.0 - smoothstep(0.035, 0.075 + feather, to_margin);
    rim * smoothstep(0.35, 0.6, v)
}

/// Table 1: Eustoma's growth scale, thickness, stiffness and mean edge.
pub const EUSTOMA_DG: f64 = 0.003;
/// Table 1: Eustoma's thickness, in the project's length units.
pub const EUSTOMA_THICKNESS: f64 = 0.1;
/// Table 1: Eustoma's stiffness, used for both the stretch and the bend
/// scale of its petals.
pub const EUSTOMA_STIFFNESS: f64 = 10.0;
/// Table 1: mean edge of Eustoma's petal mesh, in the project's length
/// units (before any `edge_scale`).
pub const EUSTOMA_EDGE: f64 = 2.0;
/// How much further out each petal's left margin lies than its right one:
/// enough that where neighbours overlap in the bud they lie about 2.6
/// thicknesses apart, wrapped around each other as in a real contorted bud
/// (with more, the petals never meet and collisions never act).
pub const EUSTOMA_CONTORTION: f64 = 0.6;

/// The Eustoma petal of the closed, contorted bud shared by the three
/// cultivars: a narrow claw, an obovate blade widest at about two thirds of
/// its length, a rounded top turned in over the bud's apex.
pub fn eustoma_petal_bud() -> RingOrgan {
    RingOrgan {
        midrib: [
            DVec2::new(1.8, 0.0),
            DVec2::new(12.0, 9.6),
            DVec2::new(16.2, 33.6),
            DVec2::new(4.2, 44.4),
        ],
        half_width: [1.5, 7.2, 16.8, 4.8],
        offset: 0.0,
        contortion: EUSTOMA_CONTORTION,
        top_rounding: 0.2,
    }
}

const EUSTOMA_BASE_V: f64 = 0.05;

/// The Eustoma joint: +15° over steps 1–50 (paper §6.2).
pub const EUSTOMA_JOINT: JointRamp = JointRamp {
    from_step: 0,
    to_step: 50,
    angle_deg: 15.0,
};

/// Lower, middle and upper regions of an Eustoma petal (weights that sum
/// to 1), by `v`.
fn eustoma_regions(v: f64) -> [f64; 3] {
    let upper = smoothstep(0.55, 0.75, v);
    let lower = 1.0 - smoothstep(0.25, 0.45, v);
    [lower, 1.0 - lower - upper, upper]
}

/// One cultivar's growth: per stage (early, late) and per region (lower,
/// middle, upper), the e-growth, the w-growth and how much the inner side
/// outgrows the base along (e-growth-in excess) and across (w-growth-in
/// excess) the growth direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EustomaGrowth {
    /// E-growth map value, `[stage][region]`, stages early and late,
    /// regions lower, middle and upper.
    pub e: [[f64; 3]; 2],
    /// How much the e-growth-in map exceeds `e`, `[stage][region]`.
    pub e_in_excess: [[f64; 3]; 2],
    /// W-growth map value, `[stage][region]`.
    pub w: [[f64; 3]; 2],
    /// How much the w-growth-in map exceeds `w`, `[stage][region]`.
    pub w_in_excess: [[f64; 3]; 2],
    /// How much the growth direction fans out towards the margins.
    pub fan: f64,
    /// Stretch and bend stiffness of the upper region, relative to the
    /// lower one.
    pub top_stiffness: f64,
}

/// The growth of `cultivar` (see [`eustoma_maps_of`]).
pub fn eustoma_growth(cultivar: Cultivar) -> EustomaGrowth {
    match cultivar {
        // Bell: growth is larger late, when the inner upper region expands
        // more than the outer and the inner middle a little more: the tips
        // flare out and reflex without rolling up, while the lower part
        // stays a tube. The petals broaden almost as fast as they lengthen,
        // so the tube keeps its contorted overlap.
        Cultivar::MellowYellow => EustomaGrowth {
            e: [[0.3, 0.3, 0.3], [0.6, 0.6, 0.7]],
            e_in_excess: [[0.0, 0.02, 0.06], [0.0, 0.06, 0.14]],
            w: [[0.9; 3], [0.8; 3]],
            w_in_excess: [[0.0, 0.0, 0.05], [0.0, 0.0, 0.15]],
            fan: 0.0,
            top_stiffness: 0.5,
        },
        // Funnel: growth larger early, a small inner excess above the
        // lower region that undoes the bud's inward curl: the
        // petal straightens (late, w-growth-in excess across flattens it a
        // little). The petals broaden as fast as the maps allow early, so
        // they stay wrapped around each other and press on their
        // neighbours: the corolla opens as a narrow cone of overlapping
        // petals, not a saucer. In the lower region the outer side grows
        // a little more (a difference well within the paper's "no
        // significant differences"): held only where they overlap, not
        // past a neighbour's margin, the petals would otherwise tilt out
        // to a 37° cone. Veins fan out more.
        Cultivar::MaiteLady => EustomaGrowth {
            e: [[0.7, 0.7, 0.7], [0.3, 0.3, 0.3]],
            e_in_excess: [[-0.02, 0.05, 0.1], [-0.01, 0.016, 0.03]],
            w: [[1.0; 3], [0.6; 3]],
            // Early the width growth is at the maps' maximum (1), which
            // the inner side cannot exceed.
            w_in_excess: [[0.0; 3], [0.03; 3]],
            fan: 0.6,
            top_stiffness: 0.5,
        },
        // Shallow ball: uniform growth, but the inner lower regions
        // elongate more than the outer (the paper: inner lower and middle,
        // not significantly): the base opens wide. No inner excess across
        // (the petal stays cupped) and in the upper region the outer side
        // grows a little more (a difference well within "not significant"),
        // so the cupped tips keep turning in and up: a shallow bowl of
        // spoon-shaped petals (base about 69° from the axis, tips back to
        // upright) rather than a flat saucer.
        Cultivar::Pinocchio => EustomaGrowth {
            e: [[0.5, 0.5, 0.5], [0.5, 0.5, 0.5]],
            e_in_excess: [[0.06, 0.0, -0.04], [0.02, 0.0, -0.04]],
            w: [[0.8; 3], [0.8; 3]],
            w_in_excess: [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0]],
            fan: 0.0,
            top_stiffness: 0.5,
        },
    }
}

/// The growth maps painted from `growth`, one cultivar's
/// ([`eustoma_growth`]; paper §6.2, Fig. 16): regions by `v`
/// (lower, middle, upper) with each cultivar's observations, early maps up
/// to step 40 and late maps from step 60, blended in between (Fig. 16's
/// caption); the same stretch and bend maps for all three (the bottom
/// harder than the top); direction along the venation, Maite Lady's
/// fanning out more than the others'.
pub fn eustoma_maps_of(growth: &EustomaGrowth) -> Result<KeyedMaps, MapError> {
    let grows = |uv: DVec2| above_base(uv.y, EUSTOMA_BASE_V, 0.05);
    let by_region = |values: [f64; 3], v: f64| {
        let r = eustoma_regions(v);
        r[0] * values[0] + r[1] * values[1] + r[2] * values[2]
    };
    let top = growth.top_stiffness;
    let stiffness = move |uv: DVec2| 1.0 - (1.0 - top) * smoothstep(0.2, 0.8, uv.y);
    let fan = growth.fan;
    let direction = move |uv: DVec2| DVec2::new(fan * (uv.x - 0.5) * uv.y, 1.0);
    let mut keys = Vec::new();
    for (stage, step) in [(0, 40), (1, 60)] {
        let e = |uv: DVec2| grows(uv) * by_region(growth.e[stage], uv.y);
        let e_in = |uv: DVec2| e(uv) + grows(uv) * by_region(growth.e_in_excess[stage], uv.y);
        let w = |uv: DVec2| grows(uv) * by_region(growth.w[stage], uv.y);
        let w_in = |uv: DVec2| w(uv) + grows(uv) * by_region(growth.w_in_excess[stage], uv.y);
        let maps = Painting {
            e_growth: &e,
            w_growth: &w,
            e_growth_in: &e_in,
            w_growth_in: &w_in,
            stretch: &stiffness,
            bend: &stiffness,
            direction: &direction,
        }
        .paint();
        keys.push((step, maps));
    }
    keyed(keys)
}

/// The Eustoma petal template of `cultivar` with `growth`: `bud` meshed
/// at `edge_scale` times Table 1's edge 2.0 ([`EDGE_SCALE`] for the
/// shipped Eustoma, with [`eustoma_petal_bud`]: about 2.6 times the
/// paper's 261 particles), the maps painted from `growth`, Table 1's
/// material.
fn eustoma_petal_template_of(
    cultivar: Cultivar,
    growth: &EustomaGrowth,
    bud: &RingOrgan,
    edge_scale: f64,
) -> Result<Template, GardenError> {
    let spec = TemplateSpec {
        organ: "Eustoma petal",
        bud: *bud,
        edge: EUSTOMA_EDGE * edge_scale,
        dg: EUSTOMA_DG,
        thickness: EUSTOMA_THICKNESS,
        stiffness: EUSTOMA_STIFFNESS,
        base_v: EUSTOMA_BASE_V,
        joint: EUSTOMA_JOINT,
        colour: cultivar.colour(),
    };
    let mut petal = template("petal", &spec, eustoma_maps_of(growth))?;
    petal.colouring = Some(cultivar.colouring());
    Ok(petal)
}

/// One Eustoma cultivar: five contorted petals, each one's right side
/// beneath its neighbour.
pub fn eustoma(cultivar: Cultivar) -> Result<Project, GardenError> {
    eustoma_at(cultivar, EDGE_SCALE)
}

fn eustoma_at(cultivar: Cultivar, edge_scale: f64) -> Result<Project, GardenError> {
    eustoma_of(
        cultivar,
        &eustoma_growth(cultivar),
        &eustoma_petal_bud(),
        edge_scale,
    )
}

/// An Eustoma of five contorted petals of shape `bud` growing by `growth`,
/// meshed at `edge_scale` times Table 1's edge, named and coloured as
/// `cultivar`: the default cultivars are this with [`eustoma_growth`] and
/// [`eustoma_petal_bud`]; other values are for exploring the maps.
pub fn eustoma_of(
    cultivar: Cultivar,
    growth: &EustomaGrowth,
    bud: &RingOrgan,
    edge_scale: f64,
) -> Result<Project, GardenError> {
    let arrangement = contorted_whorl(&ring_whorl("petal", 0, bud, 5, 0.0)).ok_or_else(|| {
        GardenError::Arrangement(format!(
            "the Eustoma petals span ±{:.0}° each: five of them must overlap their neighbours \
             and no more",
            bud.half_span_deg()
        ))
    })?;
    Ok(Project {
        name: cultivar.project_name().to_string(),
        flower: Flower {
            templates: vec![eustoma_petal_template_of(
                cultivar, growth, bud, edge_scale,
            )?],
            organs: arrangement.organs,
            overlaps: arrangement.overlaps,
            structure: None,
            parts: crate::parts::eustoma_parts(),
            // Petals about 5 cm long when open (about 50 units).
            unit: anthesis_flower::Unit::millimetres(1.0),
        },
        settings: SimulationSettings::default(),
    })
}

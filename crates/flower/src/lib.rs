//! A flower: organ templates (mesh, growth maps, parameters), organs placed
//! on the receptacle, and which organ lies inside which (for collisions).
//! The project file format that stores all this is in [`project`].

#![warn(missing_docs)]

mod colour;
pub mod edit;
pub mod parts;
pub mod project;
mod receptacle;
pub mod remesh_cache;
pub mod resolution;
pub mod scale;
pub mod sketched_bud;
pub mod structure;
pub mod unit;

pub use colour::{
    COLOUR_PAINT_SIZE, ColourLayer, Colouring, DEFAULT_SECOND_COLOUR, MAX_BAKED_SIDE, Side, srgb8,
    srgb8_to_linear,
};
pub use receptacle::{RECEPTACLE_COLOUR, receptacle_for, receptacle_mesh};
pub use resolution::Resolution;
pub use unit::{Unit, UnitError};

use anthesis_maps::KeyedMaps;
use anthesis_mesh::Mesh;
use anthesis_physics::SolverSettings;
use anthesis_physics::{BendBase, LengthBase, Model};
use glam::{DQuat, DVec3};

/// Everything an organ type needs: its bud mesh (in the template frame, see
/// ARCHITECTURE.md), its growth maps over time and its material constants.
#[derive(Debug, Clone, PartialEq)]
pub struct Template {
    /// Unique name among the project's templates; organs refer to it in the
    /// project file.
    pub name: String,
    /// The organ's bud shape in the template frame, lengths in the
    /// project's units, UVs across (`u`) and along (`v`) the organ.
    pub mesh: Mesh,
    /// The growth maps over the mesh's UV square at their key times;
    /// every map of a template has the same size.
    pub maps: KeyedMaps,
    /// Maximum growth per step: rate = 1 + dg * map value (paper eq. 2).
    /// Negative values shrink (decay, wilting).
    pub dg: f64,
    /// Distance of the imaginary inner surface (paper §4.2); must be > 0.
    pub thickness: f64,
    /// Ks: stretch stiffness scale (paper §5.1).
    pub stretch_stiffness: f64,
    /// Kb: bend stiffness scale (paper §5.1).
    pub bend_stiffness: f64,
    /// Which particles attach the organ to the receptacle.
    pub base_region: BaseRegion,
    /// How the joint angle changes over the steps.
    pub joint_schedule: Vec<JointRamp>,
    /// Display and export colour, linear RGBA in [0, 1]: the base colour
    /// when the template has a [`Colouring`].
    pub colour: [f32; 4],
    /// A second colour painted over `color` with a mix map ([`Colouring`]);
    /// `None`: the organ is `color` all over.
    pub colouring: Option<Colouring>,
    /// `Some`: the template's organs are not grown but animated from the
    /// bud (`mesh`) to an open shape by the two-state blossom
    /// (`anthesis-twostate`); the maps, `dg` and stiffness are then unused.
    pub two_state: Option<TwoStateAnimation>,
    /// How the mesh was made in the app, kept so the shape can be edited
    /// again (`[templates.source]`, project version 7); `None`: a mesh
    /// only (an OBJ, a built-in flower's bud).
    pub source: Option<TemplateSource>,
    /// The primary vein the bud was sketched with (issue 14 item 7,
    /// `[templates.vein]`, project version 8): the mesh is bent so its
    /// midrib follows it, and a shape made again from `source` is bent
    /// the same way ([`Template::shaped`]). `None`: the mesh as made.
    pub vein: Option<anthesis_bud::Vein>,
}

impl Template {
    /// `mesh`, a new shape for this template made from its source (a
    /// control net, a sketch), bent along the template's vein when it has
    /// one, so a bud drawn with a stroke keeps its pose when its petal is
    /// reshaped.
    pub fn shaped(
        &self,
        mesh: anthesis_mesh::Mesh,
    ) -> Result<anthesis_mesh::Mesh, anthesis_bud::BudError> {
        match &self.vein {
            Some(vein) => anthesis_bud::bend_along_vein(&mesh, vein),
            None => Ok(mesh),
        }
    }
}

/// How a template's mesh was made, when it was made from something that
/// can be edited again.
// One per template, so the Bézier net's 384 bytes inline cost nothing;
// boxing it would change every use of the net.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq)]
pub enum TemplateSource {
    /// A bicubic Bézier patch (its control net, rows from the base to the
    /// tip, columns across) meshed at mean edge `edge`.
    Bezier {
        /// The control net.
        net: anthesis_bud::BezierPatch,
        /// The mean edge it was meshed at.
        edge: f64,
    },
    /// A sketched petal (the floral blossom paper §3.1): its
    /// outline, vein and cross-section strokes as drawn, meshed at mean
    /// edge `edge` (`kind = "sketch"`, project version 8).
    Sketch {
        /// The strokes.
        sketch: anthesis_bud::PetalSketch,
        /// The mean edge it was meshed at.
        edge: f64,
    },
    /// A PDE sweep surface (Chaudhry et al. §IV, eq. 12): margins,
    /// across-tangents and `k_s/k_b`, meshed at mean edge `edge` (the app's
    /// PDE petal editor, or a fitted scan; project version 8).
    Pde {
        /// The surface.
        sweep: anthesis_bud::PdeSweep,
        /// The mean edge it was meshed at.
        edge: f64,
    },
}

impl TemplateSource {
    /// The same source, meshed at mean edge `edge` (a template remeshed
    /// in the Shape section).
    pub fn with_edge(&self, edge: f64) -> TemplateSource {
        let mut source = self.clone();
        match &mut source {
            TemplateSource::Bezier { edge: e, .. }
            | TemplateSource::Sketch { edge: e, .. }
            | TemplateSource::Pde { edge: e, .. } => *e = edge,
        }
        source
    }
}

/// A two-state animation (the floral blossom paper §4): the
/// template's organs go from the bud (the template mesh) to `open` along
/// the growth function G(t; g, T) and the velocity curve, instead of
/// growing. Organs of such a template are kinematic in a run: placed like
/// any organ, obstacles to the growing organs, never pushed by them.
#[derive(Debug, Clone, PartialEq)]
pub struct TwoStateAnimation {
    /// The open shape: the template mesh's vertices moved (same order,
    /// triangles and UVs), in the template frame and the project's units.
    pub open: Vec<DVec3>,
    /// `g` and `T` of eq. (4); `T` (`duration`) is in keyframes.
    pub growth: anthesis_twostate::GrowthFunction,
    /// How the cells' growth directions turn over time.
    pub velocity: anthesis_twostate::VelocityCurve,
}

impl TwoStateAnimation {
    /// An animation to `open` reaching it at keyframe `keyframes` (g = 6,
    /// the velocity curve following the growth function).
    pub fn new(open: Vec<DVec3>, keyframes: u32) -> TwoStateAnimation {
        TwoStateAnimation {
            open,
            growth: anthesis_twostate::GrowthFunction {
                g: 6.0,
                duration: f64::from(keyframes.max(1)),
            },
            velocity: anthesis_twostate::VelocityCurve::FollowGrowth,
        }
    }

    /// The open shape as a mesh: `bud`'s triangles and UVs at `open`.
    pub fn open_mesh(&self, bud: &Mesh) -> Mesh {
        Mesh {
            positions: self.open.clone(),
            uvs: bud.uvs.clone(),
            triangles: bud.triangles.clone(),
        }
    }
}

/// The fewest base particles that attach an organ: a project whose
/// template has fewer is refused on loading, and so is a resolution whose
/// remeshed template would have fewer ([`resolution::remesh_template`]).
pub const MIN_BASE_PARTICLES: usize = 3;

/// The base particles: those whose UV lies in this region.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaseRegion {
    /// Particles with `v <= v_max` are base particles.
    pub v_max: f64,
    /// Lower limit across: particles need `u >= u_min` (0 = no limit).
    pub u_min: f64,
    /// Upper limit across: particles need `u <= u_max` (1 = no limit).
    pub u_max: f64,
}

impl Default for BaseRegion {
    fn default() -> Self {
        BaseRegion {
            v_max: 0.05,
            u_min: 0.0,
            u_max: 1.0,
        }
    }
}

impl BaseRegion {
    /// Whether a particle at `uv` (the mesh's UV square) is a base particle.
    pub fn contains(&self, uv: glam::DVec2) -> bool {
        uv.y <= self.v_max && uv.x >= self.u_min && uv.x <= self.u_max
    }

    /// Indices of the base particles of `mesh`.
    pub fn particles(&self, mesh: &Mesh) -> Vec<u32> {
        (0..mesh.uvs.len() as u32)
            .filter(|&i| self.contains(mesh.uvs[i as usize]))
            .collect()
    }
}

/// The joint angle grows by `angle_deg` spread evenly over steps
/// `from_step + 1 ..= to_step` (the paper's lily: 23° over steps 1–60, i.e.
/// `from_step = 0, to_step = 60`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointRamp {
    /// The step after which the ramp starts (it adds nothing up to here).
    pub from_step: u32,
    /// The step at which the ramp has added all of `angle_deg` (and holds).
    pub to_step: u32,
    /// What the ramp adds to the joint angle, in degrees (`degrees` in the
    /// project file).
    pub angle_deg: f64,
}

/// The joint angle added by the schedule after `step` steps, in radians.
pub fn joint_angle_after(schedule: &[JointRamp], step: u32) -> f64 {
    schedule
        .iter()
        .map(|ramp| {
            let span = ramp.to_step.saturating_sub(ramp.from_step).max(1);
            let done =
                step.clamp(ramp.from_step, ramp.to_step.max(ramp.from_step)) - ramp.from_step;
            ramp.angle_deg * f64::from(done) / f64::from(span)
        })
        .sum::<f64>()
        .to_radians()
}

/// Where an organ sits on the receptacle. The template frame is tilted by
/// the joint angle about its joint axis (the template's +X), turned by
/// `orientation` (the identity for organs on a receptacle; any frame for
/// organs an L-system places), then by `azimuth_deg` about the flower axis
/// (+Y), and moved to `position`. A positive joint angle tilts the organ
/// outwards.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// Where the template's origin (the organ's base) goes, in the world
    /// frame and the project's units.
    pub position: DVec3,
    /// Turn about the flower axis (+Y), in degrees; 0 opens towards +Z.
    pub azimuth_deg: f64,
    /// Initial tilt about the joint axis, in degrees (positive outwards);
    /// the template's joint schedule adds to it over time.
    pub joint_angle_deg: f64,
    /// The organ's frame before the azimuth turn: a unit quaternion taking
    /// template axes to the frame the organ grows in (identity: upright,
    /// facing +Z).
    pub orientation: DQuat,
}

impl Placement {
    /// The joint axis in the world frame (unit length).
    pub fn joint_axis(&self) -> DVec3 {
        (DQuat::from_rotation_y(self.azimuth_deg.to_radians()) * self.orientation * DVec3::X)
            .normalize()
    }

    /// World position of a template-frame point with `extra_joint` radians
    /// added to the initial joint angle.
    pub fn world_from_template(&self, point_in_template: DVec3, extra_joint: f64) -> DVec3 {
        let rotation = DQuat::from_rotation_y(self.azimuth_deg.to_radians())
            * self.orientation
            * DQuat::from_rotation_x(self.joint_angle_deg.to_radians() + extra_joint);
        self.position + rotation * point_in_template
    }

    /// The template-frame point that [`Placement::world_from_template`]
    /// with the same `extra_joint` puts at `point_in_world` (e.g. a
    /// simulated keyframe taken back as a template's open shape).
    pub fn template_from_world(&self, point_in_world: DVec3, extra_joint: f64) -> DVec3 {
        let rotation = DQuat::from_rotation_y(self.azimuth_deg.to_radians())
            * self.orientation
            * DQuat::from_rotation_x(self.joint_angle_deg.to_radians() + extra_joint);
        rotation.inverse() * (point_in_world - self.position)
    }
}

/// One organ: an instance of a template on the receptacle.
#[derive(Debug, Clone, PartialEq)]
pub struct Organ {
    /// Unique name among the project's organs (shown in the app, used in
    /// exports and in overlaps).
    pub name: String,
    /// Index into [`Flower::templates`].
    pub template: usize,
    /// Where and how the organ sits on the receptacle.
    pub placement: Placement,
}

/// `inner` lies inside `outer` (nearer the flower axis) where they overlap:
/// each particle of `inner` near `outer` must stay on `outer`'s inner side,
/// and each particle of `outer` near `inner` on `inner`'s outer side.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Overlap {
    /// Index into [`Flower::organs`] of the organ nearer the axis.
    pub inner: usize,
    /// Index into [`Flower::organs`] of the organ farther from the axis.
    pub outer: usize,
}

/// A flower: organ types, the organs placed on the receptacle and which
/// organ lies inside which.
#[derive(Debug, Clone, PartialEq)]
pub struct Flower {
    /// The organ types; organs refer to them by index.
    pub templates: Vec<Template>,
    /// The organs, each an instance of a template.
    pub organs: Vec<Organ>,
    /// Pairs of organs kept apart by collision handling.
    pub overlaps: Vec<Overlap>,
    /// Where the first organs and overlap rules came from, when the project
    /// describes them by whorls, a spiral or an L-system: `organs` and
    /// `overlaps` start with what [`structure::Structure::arrange`] makes
    /// (saved as the structure, not one by one); the rest are listed.
    pub structure: Option<structure::Structure>,
    /// The organs that do not grow (stamens, pistils, the pedicel, the
    /// receptacle): shown, exported, and obstacles to the growing organs
    /// (see [`parts`]).
    pub parts: Vec<parts::Part>,
    /// What one of its lengths is in the real world (`unit = "1.8 mm"` in
    /// the project file); `None` where the project does not say, which
    /// exports take as one metre, as they did before projects said. Only
    /// what leaves the program is scaled by it (see [`unit`]).
    pub unit: Option<Unit>,
}

impl Flower {
    /// The template of organ `organ` (an index into [`Flower::organs`]).
    /// Panics if either index is out of range.
    pub fn template_of(&self, organ: usize) -> &Template {
        &self.templates[self.organs[organ].template]
    }

    /// The index of the organ named `name`, if there is one.
    pub fn organ_index(&self, name: &str) -> Option<usize> {
        self.organs.iter().position(|o| o.name == name)
    }
}

/// The most keyframes a run may have. The paper uses 100; every keyframe
/// is kept in memory (positions of every particle) and exported, so a run
/// of a billion keyframes asked for 40 GB before it started.
pub const MAX_KEYFRAMES: u32 = 10_000;

/// How a project is simulated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimulationSettings {
    /// Number of keyframes after the bud (paper: N = 100), 1 to
    /// [`MAX_KEYFRAMES`].
    pub keyframes: u32,
    /// How each step's energy minimisation converges (tolerance, iteration
    /// limit).
    pub solver: SolverSettings,
    /// Distance a colliding particle is pushed past its neighbour (paper:
    /// 0.01).
    pub collision_offset: f64,
    /// The discretisation of growth and mechanics.
    pub model: Model,
    /// Which angle a hinge's growth starts from.
    pub bend_base: BendBase,
    /// Which triangle grows into the new rest lengths: the current shape
    /// (the paper; the default) or the rest triangle, so that the rest state
    /// accumulates the growth (`lengths_from = "rest"` in the file).
    pub length_base: LengthBase,
    /// The meshes as built, or every template remeshed at one mean edge
    /// ([`resolution`]; the project keeps the meshes as built).
    pub resolution: Resolution,
}

impl Default for SimulationSettings {
    fn default() -> Self {
        SimulationSettings {
            keyframes: 100,
            solver: SolverSettings::default(),
            collision_offset: 0.01,
            model: Model::default(),
            bend_base: BendBase::default(),
            length_base: LengthBase::default(),
            resolution: Resolution::AsBuilt,
        }
    }
}

/// A whole project: a flower and how to simulate it.
#[derive(Debug, Clone, PartialEq)]
pub struct Project {
    /// The project's name as shown to the user and written in exports.
    pub name: String,
    /// What grows.
    pub flower: Flower,
    /// How it is simulated.
    pub settings: SimulationSettings,
}

/// A template for tests: `mesh` with uniform maps, dg 0.01, thickness
/// 0.2, stiffness scales 20, no joint schedule, white.
#[cfg(test)]
pub(crate) fn test_template(name: &str, mesh: Mesh) -> Template {
    Template {
        name: name.to_string(),
        mesh,
        maps: KeyedMaps::single(anthesis_maps::GrowthMaps::uniform()),
        dg: 0.01,
        thickness: 0.2,
        stretch_stiffness: 20.0,
        bend_stiffness: 20.0,
        base_region: BaseRegion::default(),
        joint_schedule: Vec::new(),
        colour: [1.0; 4],
        colouring: None,
        two_state: None,
        source: None,
        vein: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joint_schedule_ramps_linearly_and_holds() {
        let lily = [JointRamp {
            from_step: 0,
            to_step: 60,
            angle_deg: 23.0,
        }];
        assert_eq!(joint_angle_after(&lily, 0), 0.0);
        assert!((joint_angle_after(&lily, 30) - 11.5f64.to_radians()).abs() < 1e-12);
        assert!((joint_angle_after(&lily, 60) - 23f64.to_radians()).abs() < 1e-12);
        assert!((joint_angle_after(&lily, 100) - 23f64.to_radians()).abs() < 1e-12);
    }

    #[test]
    fn positive_joint_angle_tilts_outwards() {
        let placement = Placement {
            position: DVec3::new(0.0, 0.0, 1.0),
            azimuth_deg: 0.0,
            joint_angle_deg: 10.0,
            orientation: glam::DQuat::IDENTITY,
        };
        let tip = placement.world_from_template(DVec3::Y, 0.0);
        // Outwards from the axis at azimuth 0 is +Z.
        assert!(tip.z > 1.0 && tip.y > 0.9);
        let turned = Placement {
            azimuth_deg: 90.0,
            ..placement
        };
        assert!((turned.joint_axis() - DVec3::new(0.0, 0.0, -1.0)).length() < 1e-12);
        let tip = turned.world_from_template(DVec3::Y, 0.0);
        assert!(tip.x > 0.1, "azimuth 90 opens towards +X, got {tip}");
        // And back.
        let p = DVec3::new(0.3, 2.0, -0.4);
        let there = turned.world_from_template(p, 0.2);
        assert!((turned.template_from_world(there, 0.2) - p).length() < 1e-12);
    }
}

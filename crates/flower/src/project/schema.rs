//! The file structures, as serde reads and writes them, and their
//! conversions from and to the plain parts of a [`Project`](crate::Project).

use std::fmt;

use anthesis_maps::{Blend, MapKind};
use anthesis_physics::{BendBase, LengthBase, Model, SolverSettings};
use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::{Deserialize, Serialize, Serializer};

use crate::{BaseRegion, JointRamp, Resolution, SimulationSettings};

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ProjectFile {
    pub(super) format: String,
    pub(super) version: u32,
    pub(super) name: String,
    /// Version 9: what one length is in the real world (`"1.8 mm"`, see
    /// [`crate::Unit`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) unit: Option<String>,
    #[serde(default)]
    pub(super) simulation: SimulationFile,
    #[serde(default)]
    pub(super) templates: Vec<TemplateFile>,
    #[serde(default)]
    pub(super) organs: Vec<OrganFile>,
    #[serde(default)]
    pub(super) overlaps: Vec<OverlapFile>,
    /// Version 4: organs placed by whorls, a spiral or an L-system.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) structure: Option<StructureFile>,
    /// Version 5: organs that do not grow.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub(super) parts: Vec<super::parts::PartFile>,
}

/// `[structure]`: where the first organs come from.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct StructureFile {
    pub(super) kind: StructureKind,
    /// `kind = "whorls"`: one contorted whorl instead of nested ones.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub(super) contorted: bool,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub(super) whorls: Vec<WhorlFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) spiral: Option<SpiralFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) lsystem: Option<LSystemFile>,
}

#[derive(Serialize, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub(super) enum StructureKind {
    Whorls,
    Spiral,
    Lsystem,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct WhorlFile {
    pub(super) name: String,
    pub(super) template: String,
    pub(super) count: usize,
    #[serde(default)]
    pub(super) offset_deg: f64,
    pub(super) radius: f64,
    #[serde(default)]
    pub(super) height: f64,
    #[serde(default)]
    pub(super) joint_angle_deg: f64,
    pub(super) half_span_deg: f64,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SpiralFile {
    pub(super) name: String,
    pub(super) template: String,
    pub(super) count: usize,
    #[serde(default = "golden_angle")]
    pub(super) divergence_deg: f64,
    pub(super) first_radius: f64,
    #[serde(default)]
    pub(super) first_height: f64,
    #[serde(default)]
    pub(super) radius_step: f64,
    #[serde(default)]
    pub(super) height_step: f64,
    #[serde(default)]
    pub(super) joint_angle_deg: f64,
    pub(super) half_span_deg: f64,
}

fn golden_angle() -> f64 {
    crate::structure::GOLDEN_ANGLE_DEG
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LSystemFile {
    pub(super) steps: u32,
    pub(super) text: String,
    /// Surface letter → template name.
    pub(super) surfaces: std::collections::BTreeMap<String, String>,
    /// Project length units per turtle unit; absent means 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) units: Option<f64>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(super) struct SimulationFile {
    pub(super) keyframes: u32,
    pub(super) relative_tolerance: f64,
    pub(super) max_iterations: u32,
    pub(super) collision_offset: f64,
    /// Absent in version 1 files, which were made with the paper's model.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) model: Option<ModelFile>,
    pub(super) bend_from: BendFromFile,
    /// Version 10; absent: `shape` (every file before).
    #[serde(skip_serializing_if = "LengthsFromFile::is_shape")]
    pub(super) lengths_from: LengthsFromFile,
    /// Absent: the meshes as built (every file before version 3).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) mean_edge: Option<f64>,
}

/// [`Model`] in the file.
#[derive(Serialize, Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
pub(super) enum ModelFile {
    Consistent,
    Paper,
}

/// [`BendBase`] in the file.
#[derive(Serialize, Deserialize, Clone, Copy, Default)]
#[serde(rename_all = "snake_case")]
pub(super) enum BendFromFile {
    #[default]
    Dihedral,
    RestAngle,
}

/// [`LengthBase`] in the file.
#[derive(Serialize, Deserialize, Clone, Copy, Default, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub(super) enum LengthsFromFile {
    #[default]
    Shape,
    Rest,
}

impl LengthsFromFile {
    fn is_shape(&self) -> bool {
        *self == LengthsFromFile::Shape
    }
}

impl Default for SimulationFile {
    /// What a missing field means; `model` is left to the format version.
    fn default() -> Self {
        SimulationFile {
            model: None,
            ..SimulationFile::from(&SimulationSettings::default())
        }
    }
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TemplateFile {
    pub(super) name: String,
    pub(super) mesh: String,
    pub(super) dg: f64,
    pub(super) thickness: f64,
    pub(super) stretch_stiffness: f64,
    pub(super) bend_stiffness: f64,
    #[serde(rename = "color", default = "opaque_white")]
    pub(super) colour: [f32; 4],
    /// Version 5: the colour a colour map paints over `color`; with
    /// `colour_map`, or neither.
    #[serde(
        rename = "second_color",
        default,
        skip_serializing_if = "Option::is_none"
    )]
    pub(super) second_colour: Option<[f32; 4]>,
    /// Version 5: how much of `second_color` shows (a PNG like the growth
    /// maps, or a number).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) colour_map: Option<ScalarEntry>,
    /// Version 5: further colours painted over, in order (needs the two
    /// above).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub(super) colour_layers: Vec<ColourLayerFile>,
    #[serde(default)]
    pub(super) blend: BlendFile,
    #[serde(default)]
    pub(super) base_region: BaseRegionFile,
    #[serde(default)]
    pub(super) joint_schedule: Vec<JointRampFile>,
    /// Version 7: animated from two shapes instead of grown.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) two_state: Option<TwoStateFile>,
    /// Version 7: how the mesh was made (`[templates.source]`), to edit it
    /// again.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) source: Option<SourceFile>,
    /// Version 8: the primary vein the bud was sketched with
    /// (`[templates.vein]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) vein: Option<VeinFile>,
    pub(super) keys: Vec<KeyFile>,
}

/// `[templates.source]`: `kind = "bezier"`, its 16 control points `net`
/// (rows from the base to the tip, four points across each) and the mean
/// `edge` it was meshed at; or `kind = "sketch"`, the strokes `left`,
/// `right`, `vein` and `sections` of a sketched petal and its `edge`.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields, tag = "kind", rename_all = "lowercase")]
pub(super) enum SourceFile {
    Bezier {
        net: Vec<[f64; 3]>,
        edge: f64,
    },
    /// Version 8: a sketched petal's strokes as drawn, `[x, y]` points in
    /// the sketch plane (the template frame's base plane).
    Sketch {
        left: Vec<[f64; 2]>,
        right: Vec<[f64; 2]>,
        vein: Vec<[f64; 2]>,
        #[serde(default)]
        sections: Vec<Vec<[f64; 2]>>,
        edge: f64,
    },
    /// Version 8: a PDE sweep, its margins and across-tangents four Bézier
    /// control points each (base to tip), `k_s/k_b` and the edge.
    Pde {
        margin0: Vec<[f64; 3]>,
        margin1: Vec<[f64; 3]>,
        tangent0: Vec<[f64; 3]>,
        tangent1: Vec<[f64; 3]>,
        #[serde(default)]
        stretch_to_bend: f64,
        edge: f64,
    },
}

/// `[templates.vein]`: the midrib's path in the template frame's `y`–`z`
/// plane, `[y, z]` points from the base (version 8).
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct VeinFile {
    pub(super) points: Vec<[f64; 2]>,
}

/// `[templates.two_state]`: the open shape and the timing of a template
/// animated by the two-state blossom (version 7).
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TwoStateFile {
    /// An OBJ with the template mesh's vertices (same order) and triangles.
    pub(super) open_mesh: String,
    /// The growth rate g of eq. (4) (6 ends at the open shape).
    #[serde(default = "default_g")]
    pub(super) g: f64,
    /// T of eq. (4), in keyframes.
    pub(super) duration: f64,
    /// The velocity curve's `[time / T, fraction]` points; absent: it
    /// follows the growth function.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) velocity: Option<Vec<[f64; 2]>>,
}

fn default_g() -> f64 {
    6.0
}

/// `[[templates.colour_layers]]`: a colour and where it shows.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ColourLayerFile {
    #[serde(rename = "color")]
    pub(super) colour: [f32; 4],
    pub(super) map: ScalarEntry,
    /// Version 9: the side it is painted on (absent: both).
    #[serde(default, skip_serializing_if = "SideFile::is_both")]
    pub(super) side: SideFile,
}

/// [`crate::Side`] in the file.
#[derive(Serialize, Deserialize, Clone, Copy, Default, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub(super) enum SideFile {
    #[default]
    Both,
    Inner,
    Outer,
}

impl SideFile {
    fn is_both(&self) -> bool {
        *self == SideFile::Both
    }
}

impl From<SideFile> for crate::Side {
    fn from(side: SideFile) -> Self {
        match side {
            SideFile::Both => crate::Side::Both,
            SideFile::Inner => crate::Side::Inner,
            SideFile::Outer => crate::Side::Outer,
        }
    }
}

impl From<crate::Side> for SideFile {
    fn from(side: crate::Side) -> Self {
        match side {
            crate::Side::Both => SideFile::Both,
            crate::Side::Inner => SideFile::Inner,
            crate::Side::Outer => SideFile::Outer,
        }
    }
}

fn opaque_white() -> [f32; 4] {
    [1.0; 4]
}

/// Like [`Blend`], but refusing unknown fields.
#[derive(Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub(super) enum BlendFile {
    #[default]
    Linear,
    Smooth,
    Logistic {
        #[serde(default = "default_steepness")]
        steepness: f64,
    },
}

fn default_steepness() -> f64 {
    Blend::DEFAULT_STEEPNESS
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(super) struct BaseRegionFile {
    pub(super) v_max: f64,
    pub(super) u_min: f64,
    pub(super) u_max: f64,
}

impl Default for BaseRegionFile {
    fn default() -> Self {
        let region = BaseRegion::default();
        BaseRegionFile {
            v_max: region.v_max,
            u_min: region.u_min,
            u_max: region.u_max,
        }
    }
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct JointRampFile {
    pub(super) from_step: u32,
    pub(super) to_step: u32,
    pub(super) degrees: f64,
}

#[derive(Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct KeyFile {
    pub(super) step: u32,
    /// This key's growth scale in place of the template's (version 6).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) dg: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) e_growth: Option<ScalarEntry>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) w_growth: Option<ScalarEntry>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) e_growth_in: Option<ScalarEntry>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) w_growth_in: Option<ScalarEntry>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) stretch: Option<ScalarEntry>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) bend: Option<ScalarEntry>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) direction: Option<DirectionEntry>,
}

impl KeyFile {
    /// The entry of one scalar map: the one place that pairs field and kind.
    pub(super) fn scalar_mut(&mut self, kind: MapKind) -> &mut Option<ScalarEntry> {
        match kind {
            MapKind::EGrowth => &mut self.e_growth,
            MapKind::WGrowth => &mut self.w_growth,
            MapKind::EGrowthIn => &mut self.e_growth_in,
            MapKind::WGrowthIn => &mut self.w_growth_in,
            MapKind::Stretch => &mut self.stretch,
            MapKind::Bend => &mut self.bend,
        }
    }
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct OrganFile {
    pub(super) name: String,
    pub(super) template: String,
    #[serde(default)]
    pub(super) position: [f64; 3],
    #[serde(default)]
    pub(super) azimuth_deg: f64,
    #[serde(default)]
    pub(super) joint_angle_deg: f64,
    /// Version 4: a unit quaternion `[x, y, z, w]`, absent for upright.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) orientation: Option<[f64; 4]>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct OverlapFile {
    pub(super) inner: String,
    pub(super) outer: String,
}

/// A scalar map entry: a number or a PNG path.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum ScalarEntry {
    Constant(f32),
    File(String),
}

/// A direction map entry: a `[u, v]` pair or a PNG path.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum DirectionEntry {
    Constant([f32; 2]),
    File(String),
}

impl Serialize for ScalarEntry {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            ScalarEntry::Constant(value) => serializer.serialize_f32(*value),
            ScalarEntry::File(path) => serializer.serialize_str(path),
        }
    }
}

impl Serialize for DirectionEntry {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            DirectionEntry::Constant(pair) => pair.serialize(serializer),
            DirectionEntry::File(path) => serializer.serialize_str(path),
        }
    }
}

impl<'de> Deserialize<'de> for ScalarEntry {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(ScalarEntryVisitor)
    }
}

impl<'de> Deserialize<'de> for DirectionEntry {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(DirectionEntryVisitor)
    }
}

pub(super) struct ScalarEntryVisitor;

impl Visitor<'_> for ScalarEntryVisitor {
    type Value = ScalarEntry;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number (a constant map) or the path of a PNG file")
    }

    fn visit_f64<E: de::Error>(self, value: f64) -> Result<ScalarEntry, E> {
        Ok(ScalarEntry::Constant(value as f32))
    }

    fn visit_i64<E: de::Error>(self, value: i64) -> Result<ScalarEntry, E> {
        Ok(ScalarEntry::Constant(value as f32))
    }

    fn visit_u64<E: de::Error>(self, value: u64) -> Result<ScalarEntry, E> {
        Ok(ScalarEntry::Constant(value as f32))
    }

    fn visit_str<E: de::Error>(self, path: &str) -> Result<ScalarEntry, E> {
        Ok(ScalarEntry::File(path.to_string()))
    }
}

pub(super) struct DirectionEntryVisitor;

impl<'de> Visitor<'de> for DirectionEntryVisitor {
    type Value = DirectionEntry;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a [u, v] pair of numbers (a constant direction) or the path of a PNG file")
    }

    fn visit_str<E: de::Error>(self, path: &str) -> Result<DirectionEntry, E> {
        Ok(DirectionEntry::File(path.to_string()))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<DirectionEntry, A::Error> {
        let mut pair = [0.0f32; 2];
        for (index, component) in pair.iter_mut().enumerate() {
            let value: f64 = seq
                .next_element()?
                .ok_or_else(|| de::Error::invalid_length(index, &self))?;
            *component = value as f32;
        }
        if seq.next_element::<de::IgnoredAny>()?.is_some() {
            return Err(de::Error::invalid_length(3, &self));
        }
        Ok(DirectionEntry::Constant(pair))
    }
}

impl From<&SimulationSettings> for SimulationFile {
    fn from(settings: &SimulationSettings) -> Self {
        SimulationFile {
            keyframes: settings.keyframes,
            relative_tolerance: settings.solver.relative_tolerance,
            max_iterations: settings.solver.max_iterations,
            collision_offset: settings.collision_offset,
            model: Some(match settings.model {
                Model::Consistent => ModelFile::Consistent,
                Model::Paper => ModelFile::Paper,
            }),
            bend_from: match settings.bend_base {
                BendBase::Dihedral => BendFromFile::Dihedral,
                BendBase::RestAngle => BendFromFile::RestAngle,
            },
            lengths_from: match settings.length_base {
                LengthBase::Shape => LengthsFromFile::Shape,
                LengthBase::Rest => LengthsFromFile::Rest,
            },
            mean_edge: settings.resolution.mean_edge(),
        }
    }
}

impl SimulationFile {
    /// The settings this table describes in a file of format `version`: a
    /// version 1 file names no model and was made with the paper's.
    pub(super) fn settings(&self, version: u32) -> SimulationSettings {
        let model = match (self.model, version) {
            (Some(ModelFile::Consistent), _) => Model::Consistent,
            (Some(ModelFile::Paper), _) | (None, 1) => Model::Paper,
            (None, _) => Model::default(),
        };
        SimulationSettings {
            model,
            bend_base: match self.bend_from {
                BendFromFile::Dihedral => BendBase::Dihedral,
                BendFromFile::RestAngle => BendBase::RestAngle,
            },
            length_base: match self.lengths_from {
                LengthsFromFile::Shape => LengthBase::Shape,
                LengthsFromFile::Rest => LengthBase::Rest,
            },
            ..SimulationSettings::from(self)
        }
    }
}

impl From<&SimulationFile> for SimulationSettings {
    fn from(file: &SimulationFile) -> Self {
        SimulationSettings {
            keyframes: file.keyframes,
            solver: SolverSettings {
                relative_tolerance: file.relative_tolerance,
                max_iterations: file.max_iterations,
            },
            collision_offset: file.collision_offset,
            resolution: match file.mean_edge {
                Some(edge) => Resolution::MeanEdge(edge),
                None => Resolution::AsBuilt,
            },
            ..SimulationSettings::default()
        }
    }
}

impl From<Blend> for BlendFile {
    fn from(blend: Blend) -> Self {
        match blend {
            Blend::Linear => BlendFile::Linear,
            Blend::Smooth => BlendFile::Smooth,
            Blend::Logistic { steepness } => BlendFile::Logistic { steepness },
        }
    }
}

impl From<&BlendFile> for Blend {
    fn from(file: &BlendFile) -> Self {
        match *file {
            BlendFile::Linear => Blend::Linear,
            BlendFile::Smooth => Blend::Smooth,
            BlendFile::Logistic { steepness } => Blend::Logistic { steepness },
        }
    }
}

impl From<&JointRamp> for JointRampFile {
    fn from(ramp: &JointRamp) -> Self {
        JointRampFile {
            from_step: ramp.from_step,
            to_step: ramp.to_step,
            degrees: ramp.angle_deg,
        }
    }
}

impl From<&JointRampFile> for JointRamp {
    fn from(file: &JointRampFile) -> Self {
        JointRamp {
            from_step: file.from_step,
            to_step: file.to_step,
            angle_deg: file.degrees,
        }
    }
}

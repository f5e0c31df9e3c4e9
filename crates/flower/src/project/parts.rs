//! `[[parts]]` (version 5): the organs that do not grow, one flat table per
//! part with the keys its kind uses (see [`crate::parts`]).

use serde::{Deserialize, Serialize};

use super::schema::JointRampFile;
use crate::parts::{Part, PartShape, Tube, default_colours};

/// One `[[parts]]` entry.
#[derive(Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct PartFile {
    pub(super) name: String,
    pub(super) kind: String,
    #[serde(default = "one")]
    pub(super) count: u32,
    #[serde(default)]
    pub(super) ring_radius: f64,
    #[serde(default)]
    pub(super) height: f64,
    #[serde(default)]
    pub(super) offset_deg: f64,
    #[serde(default)]
    pub(super) angle_deg: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) length: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) radius: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) curvature_deg: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) anther_length: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) anther_radius: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) anther_tilt_deg: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) stigma_radius: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) stigma_lobes: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) ovary_length: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) ovary_radius: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) depth: Option<f64>,
    #[serde(rename = "color", default, skip_serializing_if = "Option::is_none")]
    pub(super) colour: Option<[f32; 4]>,
    #[serde(
        rename = "head_color",
        default,
        skip_serializing_if = "Option::is_none"
    )]
    pub(super) head_colour: Option<[f32; 4]>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub(super) schedule: Vec<JointRampFile>,
}

fn one() -> u32 {
    1
}

/// The kinds a file may name.
pub(super) const KINDS: [&str; 4] = ["stamen", "pistil", "pedicel", "receptacle"];

impl PartFile {
    /// The part this entry describes, or a message naming the part and
    /// the key that is missing or does not belong to its kind.
    pub(super) fn part(&self) -> Result<Part, String> {
        let name = &self.name;
        let kind = self.kind.as_str();
        if !KINDS.contains(&kind) {
            return Err(format!(
                "part \"{name}\": kind must be one of {}, not \"{kind}\"",
                KINDS.join(", ")
            ));
        }
        let optional: [(&str, bool, &[&str]); 11] = [
            (
                "length",
                self.length.is_some(),
                &["stamen", "pistil", "pedicel"],
            ),
            ("radius", self.radius.is_some(), &KINDS),
            (
                "curvature_deg",
                self.curvature_deg.is_some(),
                &["stamen", "pistil", "pedicel"],
            ),
            ("anther_length", self.anther_length.is_some(), &["stamen"]),
            ("anther_radius", self.anther_radius.is_some(), &["stamen"]),
            (
                "anther_tilt_deg",
                self.anther_tilt_deg.is_some(),
                &["stamen"],
            ),
            ("stigma_radius", self.stigma_radius.is_some(), &["pistil"]),
            ("stigma_lobes", self.stigma_lobes.is_some(), &["pistil"]),
            ("ovary_length", self.ovary_length.is_some(), &["pistil"]),
            ("ovary_radius", self.ovary_radius.is_some(), &["pistil"]),
            ("depth", self.depth.is_some(), &["receptacle"]),
        ];
        for (key, given, kinds) in optional {
            if given && !kinds.contains(&kind) {
                return Err(format!(
                    "{kind} \"{name}\": `{key}` is not a setting of a {kind}"
                ));
            }
        }
        if self.head_colour.is_some() && !matches!(kind, "stamen" | "pistil") {
            return Err(format!(
                "{kind} \"{name}\": `head_color` is for the anther of a stamen or the stigma of a pistil"
            ));
        }
        let need = |key: &str, value: Option<f64>| {
            value.ok_or_else(|| format!("{kind} \"{name}\": `{key}` is missing"))
        };
        let tube = || -> Result<Tube, String> {
            Ok(Tube {
                length: need("length", self.length)?,
                radius: need("radius", self.radius)?,
                curvature_deg: self.curvature_deg.unwrap_or(0.0),
            })
        };
        let shape = match kind {
            "stamen" => PartShape::Stamen {
                filament: tube()?,
                anther_length: need("anther_length", self.anther_length)?,
                anther_radius: need("anther_radius", self.anther_radius)?,
                anther_tilt_deg: self.anther_tilt_deg.unwrap_or(0.0),
            },
            "pistil" => PartShape::Pistil {
                style: tube()?,
                stigma_radius: need("stigma_radius", self.stigma_radius)?,
                stigma_lobes: self.stigma_lobes.unwrap_or(1),
                ovary_length: self.ovary_length.unwrap_or(0.0),
                ovary_radius: self.ovary_radius.unwrap_or(0.0),
            },
            "pedicel" => PartShape::Pedicel { stalk: tube()? },
            _ => PartShape::Receptacle {
                radius: need("radius", self.radius)?,
                depth: need("depth", self.depth)?,
            },
        };
        let (colour, head_colour) = default_colours(&shape);
        let colour = self.colour.unwrap_or(colour);
        // A part without a head keeps its one colour there too.
        let head_colour = match shape {
            PartShape::Stamen { .. } | PartShape::Pistil { .. } => {
                self.head_colour.unwrap_or(head_colour)
            }
            _ => colour,
        };
        let part = Part {
            name: name.clone(),
            shape,
            count: self.count,
            ring_radius: self.ring_radius,
            height: self.height,
            offset_deg: self.offset_deg,
            angle_deg: self.angle_deg,
            schedule: self.schedule.iter().map(Into::into).collect(),
            colour,
            head_colour,
        };
        part.check()?;
        Ok(part)
    }
}

impl From<&Part> for PartFile {
    fn from(part: &Part) -> PartFile {
        let mut file = PartFile {
            name: part.name.clone(),
            kind: part.shape.kind().to_string(),
            count: part.count,
            ring_radius: part.ring_radius,
            height: part.height,
            offset_deg: part.offset_deg,
            angle_deg: part.angle_deg,
            colour: Some(part.colour),
            schedule: part.schedule.iter().map(Into::into).collect(),
            ..PartFile::default()
        };
        let mut tube = |tube: &Tube| {
            file.length = Some(tube.length);
            file.radius = Some(tube.radius);
            file.curvature_deg = Some(tube.curvature_deg);
        };
        match part.shape {
            PartShape::Stamen {
                filament,
                anther_length,
                anther_radius,
                anther_tilt_deg,
            } => {
                tube(&filament);
                file.anther_length = Some(anther_length);
                file.anther_radius = Some(anther_radius);
                file.anther_tilt_deg = Some(anther_tilt_deg);
                file.head_colour = Some(part.head_colour);
            }
            PartShape::Pistil {
                style,
                stigma_radius,
                stigma_lobes,
                ovary_length,
                ovary_radius,
            } => {
                tube(&style);
                file.stigma_radius = Some(stigma_radius);
                file.stigma_lobes = Some(stigma_lobes);
                file.ovary_length = Some(ovary_length);
                file.ovary_radius = Some(ovary_radius);
                file.head_colour = Some(part.head_colour);
            }
            PartShape::Pedicel { stalk } => tube(&stalk),
            PartShape::Receptacle { radius, depth } => {
                file.radius = Some(radius);
                file.depth = Some(depth);
            }
        }
        file
    }
}

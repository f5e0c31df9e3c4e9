//! Organs that do not grow: stamens (a filament tube and an anther),
//! pistils (a style tube, a stigma of one or more lobes, optionally an
//! ovary), the pedicel (the stem below the receptacle) and the receptacle
//! itself. Their meshes are generated from a few parameters a user edits;
//! they are rigid, or turn about their joint axis by a schedule like the
//! joint schedule of petals. Growing organs treat every part but the
//! receptacle as an obstacle (`anthesis-sim`), and every view and export
//! shows them ([`part_pieces`] is the one list they all draw).
//!
//! A part is placed like an organ ([`Placement`], the template frame of
//! ARCHITECTURE.md: base at the origin, along +Y, curving outwards towards
//! +Z) and repeated `count` times around the flower axis. Its meshes are
//! closed surfaces wound counter-clockwise around the outward normal, so
//! "outside" is well defined for collisions; UVs: `u` around the part
//! (no seam vertices: `u` in `[0, 1)`), `v` from the base (0) to the tip (1).

use std::f64::consts::{PI, TAU};

use anthesis_mesh::Mesh;
use glam::{DQuat, DVec2, DVec3};

use crate::{Flower, JointRamp, Placement, RECEPTACLE_COLOUR, joint_angle_after, receptacle_for};

/// Vertices around a tube or a head.
const AROUND: usize = 10;
/// Rings of a head between its poles.
const HEAD_RINGS: usize = 7;
/// The most rings along a tube: a gently curved tube needs few, and every
/// vertex of a part is stored in every export (the lily's six stamens at
/// one ring per 1.5 edges around took 6,000 vertices, a tenth of the
/// .glb's size budget).
const MAX_TUBE_RINGS: usize = 25;
/// The most instances of one part.
pub const MAX_PART_COUNT: u32 = 64;
/// The most lobes of a stigma.
pub const MAX_STIGMA_LOBES: u32 = 8;
/// Where the body ends and the head starts in `v`.
const HEAD_V: f64 = 0.8;

/// A tube along an arc in the template frame's Y–Z plane: it leaves the
/// origin along +Y and turns towards +Z by `curvature_deg` over its length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tube {
    /// Length along its centre line, in the project's units.
    pub length: f64,
    /// Radius.
    pub radius: f64,
    /// How far the tube turns outwards over its length, in degrees
    /// (negative: inwards).
    pub curvature_deg: f64,
}

impl Tube {
    /// The centre line at arc length `s`: the point and the unit tangent.
    pub fn centre_at(&self, s: f64) -> (DVec3, DVec3) {
        let turn = self.curvature_deg.to_radians();
        let phi = turn * s / self.length;
        let tangent = DVec3::new(0.0, phi.cos(), phi.sin());
        if turn.abs() < 1e-9 {
            return (DVec3::new(0.0, s, 0.0), tangent);
        }
        let bend_radius = self.length / turn;
        let point = DVec3::new(
            0.0,
            bend_radius * phi.sin(),
            bend_radius * (1.0 - phi.cos()),
        );
        (point, tangent)
    }
}

/// What a part is, with the parameters of its shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PartShape {
    /// A filament with an anther at its tip.
    Stamen {
        /// The filament.
        filament: Tube,
        /// The anther's length (along its long axis).
        anther_length: f64,
        /// The anther's radius across.
        anther_radius: f64,
        /// The anther's long axis turned from the filament's tip tangent
        /// towards the outside, in degrees: 0 continues the filament, 90
        /// lies across it (a lily's versatile anther).
        anther_tilt_deg: f64,
    },
    /// A style with a stigma at its tip and optionally an ovary at its base.
    Pistil {
        /// The style.
        style: Tube,
        /// The size of the stigma (the radius of one lobe's reach).
        stigma_radius: f64,
        /// Lobes of the stigma (a lily's has three); 1 is a round knob.
        stigma_lobes: u32,
        /// The ovary's length along the axis; 0 for none.
        ovary_length: f64,
        /// The ovary's radius; 0 for none.
        ovary_radius: f64,
    },
    /// The stem below the receptacle, pointing down.
    Pedicel {
        /// The stem.
        stalk: Tube,
    },
    /// The receptacle the organs sit on (replaces the one sized
    /// automatically, [`receptacle_for`]).
    Receptacle {
        /// Its radius where the organs sit.
        radius: f64,
        /// How far it reaches down below them.
        depth: f64,
    },
}

impl PartShape {
    /// The kind's name as project files and messages write it.
    pub fn kind(&self) -> &'static str {
        match self {
            PartShape::Stamen { .. } => "stamen",
            PartShape::Pistil { .. } => "pistil",
            PartShape::Pedicel { .. } => "pedicel",
            PartShape::Receptacle { .. } => "receptacle",
        }
    }
}

/// A part of the flower that does not grow, repeated `count` times around
/// the axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// Unique among the project's parts and organs; instances are named
    /// `NAME-1`, `NAME-2`, … (just `NAME` when `count` is 1).
    pub name: String,
    /// What it is and its shape's parameters.
    pub shape: PartShape,
    /// Instances around the flower axis, 1 to [`MAX_PART_COUNT`].
    pub count: u32,
    /// Distance of each instance's base from the flower axis.
    pub ring_radius: f64,
    /// Height of the bases (the organs sit at 0).
    pub height: f64,
    /// Azimuth of the first instance, in degrees (0 faces +Z).
    pub offset_deg: f64,
    /// Initial tilt outwards about the joint axis, in degrees.
    pub angle_deg: f64,
    /// How the tilt changes over the steps (as a template's joint
    /// schedule).
    pub schedule: Vec<JointRamp>,
    /// Colour of the tube (filament, style, stem, receptacle), linear RGBA.
    pub colour: [f32; 4],
    /// Colour of the head (anther, stigma), linear RGBA.
    pub head_colour: [f32; 4],
}

/// The name of instance `k` (from 0) of a part named `name` repeated
/// `count` times: `NAME-1`, `NAME-2`, …, or just `NAME` alone.
pub fn instance_name(name: &str, count: u32, k: u32) -> String {
    if count == 1 {
        name.to_string()
    } else {
        format!("{name}-{}", k + 1)
    }
}

/// The colours a part of this shape gets unless told otherwise (linear
/// RGBA, body and head): a pale filament with a pollen-orange anther, a
/// pale green style and stigma, a stem green.
pub fn default_colours(shape: &PartShape) -> ([f32; 4], [f32; 4]) {
    const PALE: [f32; 4] = [0.80, 0.82, 0.60, 1.0];
    const POLLEN: [f32; 4] = [0.55, 0.18, 0.03, 1.0];
    const STYLE: [f32; 4] = [0.62, 0.72, 0.40, 1.0];
    match shape {
        PartShape::Stamen { .. } => (PALE, POLLEN),
        PartShape::Pistil { .. } => (STYLE, STYLE),
        PartShape::Pedicel { .. } | PartShape::Receptacle { .. } => {
            (RECEPTACLE_COLOUR, RECEPTACLE_COLOUR)
        }
    }
}

/// One mesh of a part instance as views and exports draw it: the body
/// (tube, ovary) or the head (anther, stigma).
#[derive(Debug, Clone, PartialEq)]
pub struct PartPiece {
    /// Track and node name: the instance's name, `-anther` or `-stigma`
    /// added for a head.
    pub name: String,
    /// The mesh in the part's own frame.
    pub mesh: Mesh,
    /// Linear RGBA.
    pub colour: [f32; 4],
    /// Where the instance sits.
    pub placement: Placement,
    /// Its schedule (empty: it does not move).
    pub schedule: Vec<JointRamp>,
}

impl PartPiece {
    /// The rigid motion that places the piece's mesh at `step`: world =
    /// translation + rotation · local.
    pub fn pose(&self, step: u32) -> (DVec3, DQuat) {
        pose(&self.placement, &self.schedule, step)
    }

    /// The mesh's positions in the world frame at `step`.
    pub fn positions_at(&self, step: u32) -> Vec<DVec3> {
        let (translation, rotation) = self.pose(step);
        self.mesh
            .positions
            .iter()
            .map(|&p| translation + rotation * p)
            .collect()
    }

    /// Whether the piece moves over the run.
    pub fn moves(&self) -> bool {
        self.schedule.iter().any(|r| r.angle_deg != 0.0)
    }
}

/// The rigid motion of a part placed at `placement` with `schedule`, at
/// `step`.
pub fn pose(placement: &Placement, schedule: &[JointRamp], step: u32) -> (DVec3, DQuat) {
    let extra = joint_angle_after(schedule, step);
    let rotation = DQuat::from_rotation_y(placement.azimuth_deg.to_radians())
        * placement.orientation
        * DQuat::from_rotation_x(placement.joint_angle_deg.to_radians() + extra);
    (placement.position, rotation)
}

impl Part {
    /// Where each instance sits, in order.
    pub fn placements(&self) -> Vec<Placement> {
        (0..self.count)
            .map(|k| {
                let azimuth_deg = self.offset_deg + 360.0 * f64::from(k) / f64::from(self.count);
                let a = azimuth_deg.to_radians();
                let orientation = match self.shape {
                    // The stem points down from the receptacle.
                    PartShape::Pedicel { .. } => DQuat::from_rotation_x(PI),
                    _ => DQuat::IDENTITY,
                };
                Placement {
                    position: DVec3::new(
                        self.ring_radius * a.sin(),
                        self.height,
                        self.ring_radius * a.cos(),
                    ),
                    azimuth_deg,
                    joint_angle_deg: self.angle_deg,
                    orientation,
                }
            })
            .collect()
    }

    /// The name of instance `k` (from 0).
    pub fn instance_name(&self, k: u32) -> String {
        instance_name(&self.name, self.count, k)
    }

    /// Whether growing organs are kept out of it (every part but the
    /// receptacle, where the organs are attached).
    pub fn is_obstacle(&self) -> bool {
        !matches!(self.shape, PartShape::Receptacle { .. })
    }

    /// The body and head meshes in the part's own frame, each with its
    /// colour and the suffix its piece names get ("" for the body).
    pub fn meshes(&self) -> Vec<(Mesh, [f32; 4], &'static str)> {
        match self.shape {
            PartShape::Stamen {
                filament,
                anther_length,
                anther_radius,
                anther_tilt_deg,
            } => {
                let (tip, tangent) = filament.centre_at(filament.length);
                let turn = anther_tilt_deg.to_radians();
                let axis = DQuat::from_rotation_x(turn) * tangent;
                let half = 0.5 * anther_length;
                let along = axis.dot(tangent);
                let reach = (half * half * along * along
                    + anther_radius * anther_radius * (1.0 - along * along))
                    .sqrt();
                // The anther touches the filament's tip, sunk a little into it.
                let centre = tip + tangent * (reach - 0.5 * filament.radius.min(reach));
                let mut anther = Mesh::default();
                head(
                    &mut anther,
                    centre,
                    axis,
                    half,
                    anther_radius,
                    (HEAD_V, 1.0),
                );
                vec![
                    (tube_mesh(&filament, (0.0, HEAD_V)), self.colour, ""),
                    (anther, self.head_colour, "-anther"),
                ]
            }
            PartShape::Pistil {
                style,
                stigma_radius,
                stigma_lobes,
                ovary_length,
                ovary_radius,
            } => {
                let mut body = tube_mesh(&style, (0.0, HEAD_V));
                if ovary_length > 0.0 && ovary_radius > 0.0 {
                    let half = 0.5 * ovary_length;
                    head(
                        &mut body,
                        DVec3::new(0.0, half, 0.0),
                        DVec3::Y,
                        half,
                        ovary_radius,
                        (0.0, 0.2),
                    );
                }
                let (tip, tangent) = style.centre_at(style.length);
                let mut stigma = Mesh::default();
                if stigma_lobes <= 1 {
                    let centre = tip + tangent * (0.8 * stigma_radius);
                    head(
                        &mut stigma,
                        centre,
                        tangent,
                        stigma_radius,
                        stigma_radius,
                        (HEAD_V, 1.0),
                    );
                } else {
                    let side = DVec3::X;
                    let other = side.cross(tangent);
                    for k in 0..stigma_lobes {
                        let a = TAU * f64::from(k) / f64::from(stigma_lobes);
                        let out = side * a.cos() + other * a.sin();
                        let axis = (tangent + out).normalize();
                        let centre =
                            tip + tangent * (0.5 * stigma_radius) + out * (0.5 * stigma_radius);
                        head(
                            &mut stigma,
                            centre,
                            axis,
                            0.7 * stigma_radius,
                            0.4 * stigma_radius,
                            (HEAD_V, 1.0),
                        );
                    }
                }
                vec![
                    (body, self.colour, ""),
                    (stigma, self.head_colour, "-stigma"),
                ]
            }
            PartShape::Pedicel { stalk } => vec![(tube_mesh(&stalk, (0.0, 1.0)), self.colour, "")],
            PartShape::Receptacle { radius, depth } => {
                vec![(crate::receptacle_mesh(radius, depth), self.colour, "")]
            }
        }
    }

    /// Checks the parameters; the message names the part and what is wrong.
    pub fn check(&self) -> Result<(), String> {
        let name = &self.name;
        let kind = self.shape.kind();
        let positive = |what: &str, x: f64| {
            if x.is_finite() && x > 0.0 {
                Ok(())
            } else {
                Err(format!(
                    "{kind} \"{name}\": {what} must be a positive number, not {x}"
                ))
            }
        };
        let not_negative = |what: &str, x: f64| {
            if x.is_finite() && x >= 0.0 {
                Ok(())
            } else {
                Err(format!(
                    "{kind} \"{name}\": {what} must be 0 or more, not {x}"
                ))
            }
        };
        let tube = |what: &str, tube: &Tube| -> Result<(), String> {
            positive(&format!("the {what}'s length"), tube.length)?;
            positive(&format!("the {what}'s radius"), tube.radius)?;
            if !(tube.curvature_deg.is_finite() && tube.curvature_deg.abs() <= 360.0) {
                return Err(format!(
                    "{kind} \"{name}\": the {what}'s curvature must be between -360 and 360 degrees, not {}",
                    tube.curvature_deg
                ));
            }
            if tube.radius * 2.0 > tube.length {
                return Err(format!(
                    "{kind} \"{name}\": the {what} is wider ({}) than it is long ({})",
                    2.0 * tube.radius,
                    tube.length
                ));
            }
            Ok(())
        };
        match self.shape {
            PartShape::Stamen {
                filament,
                anther_length,
                anther_radius,
                anther_tilt_deg,
            } => {
                tube("filament", &filament)?;
                positive("anther_length", anther_length)?;
                positive("anther_radius", anther_radius)?;
                if !anther_tilt_deg.is_finite() {
                    return Err(format!(
                        "{kind} \"{name}\": anther_tilt_deg must be a number"
                    ));
                }
            }
            PartShape::Pistil {
                style,
                stigma_radius,
                stigma_lobes,
                ovary_length,
                ovary_radius,
            } => {
                tube("style", &style)?;
                positive("stigma_radius", stigma_radius)?;
                if !(1..=MAX_STIGMA_LOBES).contains(&stigma_lobes) {
                    return Err(format!(
                        "{kind} \"{name}\": stigma_lobes must be 1 to {MAX_STIGMA_LOBES}, not {stigma_lobes}"
                    ));
                }
                not_negative("ovary_length", ovary_length)?;
                not_negative("ovary_radius", ovary_radius)?;
            }
            PartShape::Pedicel { stalk } => tube("stalk", &stalk)?,
            PartShape::Receptacle { radius, depth } => {
                positive("radius", radius)?;
                positive("depth", depth)?;
                if self.count != 1 {
                    return Err(format!(
                        "{kind} \"{name}\": a flower has one receptacle, not {}",
                        self.count
                    ));
                }
            }
        }
        if !(1..=MAX_PART_COUNT).contains(&self.count) {
            return Err(format!(
                "{kind} \"{name}\": count must be 1 to {MAX_PART_COUNT}, not {}",
                self.count
            ));
        }
        not_negative("ring_radius", self.ring_radius)?;
        for (what, x) in [
            ("height", self.height),
            ("offset_deg", self.offset_deg),
            ("angle_deg", self.angle_deg),
        ] {
            if !x.is_finite() {
                return Err(format!(
                    "{kind} \"{name}\": {what} must be a number, not {x}"
                ));
            }
        }
        for ramp in &self.schedule {
            if ramp.from_step > ramp.to_step || !ramp.angle_deg.is_finite() {
                return Err(format!(
                    "{kind} \"{name}\": a schedule ramp must go forwards (from_step {} to_step {}) by a finite angle",
                    ramp.from_step, ramp.to_step
                ));
            }
        }
        for (what, colour) in [("color", self.colour), ("head_color", self.head_colour)] {
            if colour.iter().any(|c| !(0.0..=1.0).contains(c)) {
                return Err(format!(
                    "{kind} \"{name}\": {what} components must be between 0 and 1, not {colour:?}"
                ));
            }
        }
        Ok(())
    }
}

/// Every piece the views and exports draw besides the growing organs: the
/// receptacle (the flower's receptacle part, or one sized to the organs by
/// [`receptacle_for`] when it has none), then each part instance's body and
/// head, part by part.
pub fn part_pieces(flower: &Flower) -> Vec<PartPiece> {
    let mut pieces = Vec::new();
    let has_receptacle = flower
        .parts
        .iter()
        .any(|p| matches!(p.shape, PartShape::Receptacle { .. }));
    if !has_receptacle {
        pieces.push(PartPiece {
            name: "receptacle".to_string(),
            mesh: receptacle_for(flower),
            colour: RECEPTACLE_COLOUR,
            placement: Placement {
                position: DVec3::ZERO,
                azimuth_deg: 0.0,
                joint_angle_deg: 0.0,
                orientation: DQuat::IDENTITY,
            },
            schedule: Vec::new(),
        });
    }
    for part in &flower.parts {
        let meshes = part.meshes();
        for (k, placement) in part.placements().into_iter().enumerate() {
            let name = part.instance_name(k as u32);
            for (mesh, colour, suffix) in &meshes {
                pieces.push(PartPiece {
                    name: format!("{name}{suffix}"),
                    mesh: mesh.clone(),
                    colour: *colour,
                    placement,
                    schedule: part.schedule.clone(),
                });
            }
        }
    }
    pieces.extend(segment_pieces(flower));
    pieces
}

/// One line per piece of [`part_pieces`], as `anthesis info` lists them
/// after the organs: `part NAME VERTICES TRIANGLES`.
pub fn part_lines(flower: &Flower) -> Vec<String> {
    part_pieces(flower)
        .iter()
        .map(|piece| {
            format!(
                "part {} {} {}",
                piece.name,
                piece.mesh.vertex_count(),
                piece.mesh.triangle_count()
            )
        })
        .collect()
}

/// The tubes the flower's L-system draws with `F` (see
/// [`crate::structure::Structure::tubes`]), named after what drew them
/// (`stem`, `stamen-3`, …; a name an organ or a part already has gets
/// `-2`, `-3`, … until it is free), in the word's order, in the colour `;`
/// set (the stem's colour by default); they do not move.
fn segment_pieces(flower: &Flower) -> Vec<PartPiece> {
    let Some(structure) = &flower.structure else {
        return Vec::new();
    };
    let mut taken: std::collections::BTreeSet<String> =
        flower.organs.iter().map(|o| o.name.clone()).collect();
    taken.insert("receptacle".to_owned());
    for part in &flower.parts {
        let suffixes: Vec<&str> = part.meshes().into_iter().map(|(_, _, s)| s).collect();
        for k in 0..part.placements().len() {
            let name = part.instance_name(k as u32);
            for suffix in &suffixes {
                taken.insert(format!("{name}{suffix}"));
            }
        }
    }
    structure
        .tubes()
        .into_iter()
        .map(|(name, segment)| {
            let mut unique = name.clone();
            let mut n = 2;
            while taken.contains(&unique) {
                unique = format!("{name}-{n}");
                n += 1;
            }
            taken.insert(unique.clone());
            let along = segment.end - segment.start;
            let tube = Tube {
                length: along.length(),
                radius: 0.5 * segment.width,
                curvature_deg: 0.0,
            };
            PartPiece {
                name: unique,
                mesh: tube_mesh(&tube, (0.0, 1.0)),
                colour: segment.colour.unwrap_or(RECEPTACLE_COLOUR),
                placement: Placement {
                    position: segment.start,
                    azimuth_deg: 0.0,
                    joint_angle_deg: 0.0,
                    orientation: DQuat::from_rotation_arc(DVec3::Y, along / tube.length),
                },
                schedule: Vec::new(),
            }
        })
        .collect()
}

/// The surfaces growing organs are kept out of: one per closed component
/// of each part instance (a filament, its anther, each stigma lobe) and
/// one per tube an L-system's `F` draws, so
/// that where components overlap, "outside" of each is still its own
/// surface's outside.
pub fn obstacles(flower: &Flower) -> Vec<PartPiece> {
    let mut out = Vec::new();
    for part in flower.parts.iter().filter(|p| p.is_obstacle()) {
        let components: Vec<Mesh> = part
            .meshes()
            .iter()
            .flat_map(|(mesh, _, _)| components(mesh))
            .collect();
        for (k, placement) in part.placements().into_iter().enumerate() {
            for mesh in &components {
                out.push(PartPiece {
                    name: part.instance_name(k as u32),
                    mesh: mesh.clone(),
                    colour: part.colour,
                    placement,
                    schedule: part.schedule.clone(),
                });
            }
        }
    }
    out.extend(segment_pieces(flower));
    out
}

/// The connected pieces of `mesh` (triangles sharing vertices), each with
/// its own vertices, in the order of their first triangle.
fn components(mesh: &Mesh) -> Vec<Mesh> {
    let n = mesh.positions.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for t in &mesh.triangles {
        for k in 1..3 {
            let (a, b) = (
                root(&mut parent, t[0] as usize),
                root(&mut parent, t[k] as usize),
            );
            parent[a] = b;
        }
    }
    let mut pieces: Vec<(usize, Mesh, Vec<Option<u32>>)> = Vec::new();
    for t in &mesh.triangles {
        let r = root(&mut parent, t[0] as usize);
        let index = match pieces.iter().position(|(root, _, _)| *root == r) {
            Some(i) => i,
            None => {
                pieces.push((r, Mesh::default(), vec![None; n]));
                pieces.len() - 1
            }
        };
        let (_, piece, map) = &mut pieces[index];
        let tri = t.map(|v| {
            *map[v as usize].get_or_insert_with(|| {
                piece.positions.push(mesh.positions[v as usize]);
                piece.uvs.push(mesh.uvs[v as usize]);
                piece.positions.len() as u32 - 1
            })
        });
        piece.triangles.push(tri);
    }
    pieces.into_iter().map(|(_, mesh, _)| mesh).collect()
}

/// A ring of a swept surface: its centre, two unit vectors spanning it
/// (with `e1 × e2` pointing back along the sweep) and its radius along
/// each.
struct Ring {
    centre: DVec3,
    e1: DVec3,
    e2: DVec3,
    radius: f64,
    v: f64,
}

/// Appends a closed swept surface: the rings in order, closed by a pole
/// before the first and after the last.
fn sweep(mesh: &mut Mesh, rings: &[Ring], start: (DVec3, f64), end: (DVec3, f64)) {
    let base = mesh.positions.len() as u32;
    mesh.positions.push(start.0);
    mesh.uvs.push(DVec2::new(0.5, start.1));
    for ring in rings {
        for k in 0..AROUND {
            let a = TAU * k as f64 / AROUND as f64;
            mesh.positions
                .push(ring.centre + ring.radius * (a.cos() * ring.e1 + a.sin() * ring.e2));
            mesh.uvs.push(DVec2::new(k as f64 / AROUND as f64, ring.v));
        }
    }
    let last = mesh.positions.len() as u32;
    mesh.positions.push(end.0);
    mesh.uvs.push(DVec2::new(0.5, end.1));
    let at = |i: usize, k: usize| base + 1 + (i * AROUND + k % AROUND) as u32;
    for k in 0..AROUND {
        mesh.triangles.push([base, at(0, k), at(0, k + 1)]);
        mesh.triangles
            .push([last, at(rings.len() - 1, k + 1), at(rings.len() - 1, k)]);
    }
    for i in 0..rings.len() - 1 {
        for k in 0..AROUND {
            mesh.triangles.push([at(i, k), at(i + 1, k), at(i, k + 1)]);
            mesh.triangles
                .push([at(i + 1, k), at(i + 1, k + 1), at(i, k + 1)]);
        }
    }
}

/// A closed tube (flat ends), `v` spread over `v_range` along it.
fn tube_mesh(tube: &Tube, v_range: (f64, f64)) -> Mesh {
    let around_edge = TAU * tube.radius / AROUND as f64;
    let rings = ((tube.length / (1.5 * around_edge)).ceil() as usize).clamp(2, MAX_TUBE_RINGS);
    let v_at = |s: f64| v_range.0 + (v_range.1 - v_range.0) * s / tube.length;
    let rings: Vec<Ring> = (0..rings)
        .map(|i| {
            let s = tube.length * i as f64 / (rings - 1) as f64;
            let (centre, tangent) = tube.centre_at(s);
            Ring {
                centre,
                e1: DVec3::X,
                e2: DVec3::X.cross(tangent),
                radius: tube.radius,
                v: v_at(s),
            }
        })
        .collect();
    let (tip, _) = tube.centre_at(tube.length);
    let mut mesh = Mesh::default();
    sweep(
        &mut mesh,
        &rings,
        (DVec3::ZERO, v_range.0),
        (tip, v_range.1),
    );
    mesh
}

/// Appends an ellipsoid: semi-axis `half` along the unit `axis`, `radius`
/// across it.
fn head(mesh: &mut Mesh, centre: DVec3, axis: DVec3, half: f64, radius: f64, v_range: (f64, f64)) {
    let e1 = axis.any_orthonormal_vector();
    let e2 = e1.cross(axis);
    let rings: Vec<Ring> = (1..=HEAD_RINGS)
        .map(|i| {
            let theta = PI * i as f64 / (HEAD_RINGS + 1) as f64;
            Ring {
                centre: centre - axis * (half * theta.cos()),
                e1,
                e2,
                radius: radius * theta.sin(),
                v: v_range.0 + (v_range.1 - v_range.0) * theta / PI,
            }
        })
        .collect();
    sweep(
        mesh,
        &rings,
        (centre - axis * half, v_range.0),
        (centre + axis * half, v_range.1),
    );
}

#[cfg(test)]
mod tests;

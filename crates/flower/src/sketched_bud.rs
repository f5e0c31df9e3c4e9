//! The sketched bud (the floral blossom paper §3.2, issue 14 item
//! 7): one curved stroke in a side view is the initial primary vein of a
//! petal, and the bud is that petal instanced around the axis, at the
//! golden angle or where the flower's arrangement puts its organs, each
//! with its midrib along a copy of the curve.
//!
//! The template is bent once ([`anthesis_bud::bend_along_vein`]) and keeps
//! the vein, so its organs (which are the template placed at their
//! azimuths) all follow copies of the curve. The organs' bases go where the
//! stroke starts, and their initial joint angle is zero, so the bud is the
//! drawing.
//!
//! Copies of one curve at the same distance from the axis cross where
//! their petals are wide enough to overlap. A spiral nests its later
//! petals inside the earlier ones (each this much nearer the axis and this
//! much lower, like a rose bud): the smallest such step from a short list
//! that leaves no two organs crossing is chosen, and the bud says which two
//! organs still cross when none does (the app then says so and does not
//! apply it: the simulation needs a bud whose surfaces do not cross).

use anthesis_bud::{SideStroke, bend_along_vein, find_self_intersection};
use anthesis_mesh::Mesh;

use crate::Flower;
use crate::edit::EditError;
use crate::structure::{GOLDEN_ANGLE_DEG, Spiral, Structure};

/// Where the petals of a sketched bud go.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BudPlacement {
    /// Where the flower's arrangement puts the template's organs (their
    /// azimuths), with their bases moved to the stroke's base. An
    /// L-system's organs stay where its turtle puts them.
    Arrangement,
    /// A phyllotactic spiral of `count` petals 137.5° apart, replacing the
    /// flower's organs (it must have no organs of other templates).
    GoldenSpiral {
        /// How many petals.
        count: usize,
    },
}

/// A flower whose bud was sketched.
#[derive(Debug, Clone)]
pub struct SketchedBud {
    /// The flower: the template bent along the vein, the organs placed.
    pub flower: Flower,
    /// How much nearer the axis, and lower, each later petal of a spiral
    /// sits (0 for [`BudPlacement::Arrangement`]).
    pub radius_step: f64,
    /// Two organs (or one organ with itself) whose surfaces cross in the
    /// bud, if any do: the simulation needs a bud without crossings.
    pub crossing: Option<(String, String)>,
}

/// See [`first_crossing`]: radians and project units per organ.
const GENERAL_POSITION: f64 = 3e-6;

/// Radius steps tried for a spiral, as multiples of the petal's thickness
/// (the distance the collision handling keeps).
const STEPS_IN_THICKNESS: [f64; 8] = [0.0, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0];

impl Flower {
    /// The flower with template `template`'s bud drawn by `stroke` (see
    /// the module documentation).
    pub fn with_sketched_bud(
        &self,
        template: usize,
        stroke: &SideStroke,
        placement: BudPlacement,
    ) -> Result<SketchedBud, EditError> {
        let old = self.templates.get(template).ok_or(EditError::Missing {
            what: "template",
            index: template,
        })?;
        let mesh = bend_along_vein(&old.mesh, &stroke.vein).map_err(EditError::Shape)?;
        let mut bent = self.clone();
        bent.templates[template].mesh = mesh;
        bent.templates[template].vein = Some(stroke.vein.clone());
        let (r0, h0) = (stroke.base.x, stroke.base.y);
        let half_span = half_span_deg(&bent.templates[template].mesh, r0);
        match placement {
            BudPlacement::Arrangement => {
                let flower = bent.placed_at(template, r0, h0, half_span)?;
                let crossing = first_crossing(&flower);
                Ok(SketchedBud {
                    flower,
                    radius_step: 0.0,
                    crossing,
                })
            }
            BudPlacement::GoldenSpiral { count } => {
                if let Some(other) = self.organs.iter().find(|o| o.template != template) {
                    return Err(EditError::OtherOrgans(other.name.clone()));
                }
                let count = count.max(1);
                let thickness = bent.templates[template].thickness;
                let mut last = None;
                for step in STEPS_IN_THICKNESS.map(|k| k * thickness) {
                    if r0 - step * (count - 1) as f64 <= 0.0 && step > 0.0 {
                        break;
                    }
                    let spiral = Spiral {
                        name: bent.templates[template].name.clone(),
                        template,
                        count,
                        divergence_deg: GOLDEN_ANGLE_DEG,
                        first_radius: r0,
                        first_height: h0,
                        radius_step: step,
                        height_step: -step,
                        joint_angle_deg: 0.0,
                        half_span_deg: half_span,
                    };
                    let flower = bent.arranged_by(Structure::Spiral(spiral))?;
                    let crossing = first_crossing(&flower);
                    let done = crossing.is_none();
                    last = Some(SketchedBud {
                        flower,
                        radius_step: step,
                        crossing,
                    });
                    if done {
                        break;
                    }
                }
                last.ok_or(EditError::NoOrgans)
            }
        }
    }

    /// The flower whose template `template` opens from its bud to the
    /// petal bent along `open` (§3.2's opened flower: a free-form stroke
    /// "treated as the terminal form of the primary vein"), by the
    /// two-state blossom, reaching it at keyframe `keyframes`: the organs
    /// then no longer grow from their maps but go from one shape to the
    /// other ([`crate::TwoStateAnimation`]). Also which organs cross in the
    /// open flower, if any do.
    pub fn with_sketched_opening(
        &self,
        template: usize,
        open: &anthesis_bud::Vein,
        keyframes: u32,
    ) -> Result<(Flower, Option<(String, String)>), EditError> {
        let bud = self.templates.get(template).ok_or(EditError::Missing {
            what: "template",
            index: template,
        })?;
        let opened = bend_along_vein(&bud.mesh, open).map_err(EditError::Shape)?;
        let mut flower = self.clone();
        flower.templates[template].two_state = Some(crate::TwoStateAnimation::new(
            opened.positions.clone(),
            keyframes,
        ));
        let mut open_flower = flower.clone();
        open_flower.templates[template].mesh = opened;
        let crossing = first_crossing(&open_flower);
        Ok((flower, crossing))
    }

    /// The flower with template `template`'s organs based at distance `r`
    /// from the axis and height `h`, joint angle zero, spanning `half_span`
    /// degrees either side (whorls, a spiral, listed organs; an L-system's
    /// organs stay where it puts them).
    fn placed_at(
        &self,
        template: usize,
        r: f64,
        h: f64,
        half_span: f64,
    ) -> Result<Flower, EditError> {
        let mut flower = self.clone();
        let made = flower.made_organ_count();
        for organ in flower.organs.iter_mut().skip(made) {
            if organ.template == template && organ.placement.orientation == glam::DQuat::IDENTITY {
                organ.placement =
                    crate::structure::whorl::placement(organ.placement.azimuth_deg, r, h, 0.0);
            }
        }
        let structure = match flower.structure.clone() {
            Some(Structure::Whorls {
                mut whorls,
                contorted,
            }) => {
                for whorl in whorls.iter_mut().filter(|w| w.template == template) {
                    whorl.radius = r;
                    whorl.height = h;
                    whorl.joint_angle_deg = 0.0;
                    whorl.half_span_deg = half_span;
                }
                Some(Structure::Whorls { whorls, contorted })
            }
            Some(Structure::Spiral(mut spiral)) if spiral.template == template => {
                spiral.first_radius = r;
                spiral.first_height = h;
                spiral.joint_angle_deg = 0.0;
                spiral.half_span_deg = half_span;
                Some(Structure::Spiral(spiral))
            }
            other => other,
        };
        flower.with_structure(structure)
    }
}

/// Half the angle about the axis that the template `mesh` covers when its
/// base sits `r` from the axis facing away from it, in degrees, with a
/// fifth more for good measure (the overlap rules pair organs whose spans
/// meet); 179° at most.
fn half_span_deg(mesh: &Mesh, r: f64) -> f64 {
    let widest = mesh
        .positions
        .iter()
        .map(|p| p.x.abs().atan2(r + p.z).to_degrees())
        .fold(0.0, f64::max);
    (1.2 * widest).clamp(1.0, 179.0)
}

/// The first two organs of `flower` (by name) whose surfaces cross in the
/// bud, or an organ that crosses itself (named twice).
pub fn first_crossing(flower: &Flower) -> Option<(String, String)> {
    let mut merged = Mesh {
        positions: Vec::new(),
        uvs: Vec::new(),
        triangles: Vec::new(),
    };
    let mut first_triangle = Vec::with_capacity(flower.organs.len());
    for (k, organ) in flower.organs.iter().enumerate() {
        // Organs of one template have their rows of vertices at the same
        // heights, and neighbours in a whorl are mirror images: where they
        // cross, the edges of one meet the other exactly on its edges,
        // which the crossing test does not count. A turn and a lift of a
        // few millionths, different for each organ, put them in general
        // position.
        let jitter = GENERAL_POSITION * (k + 1) as f64;
        let turn = glam::DQuat::from_rotation_y(jitter);
        let lift = glam::DVec3::Y * jitter;
        let mesh = &flower.templates[organ.template].mesh;
        let offset = merged.positions.len() as u32;
        first_triangle.push(merged.triangles.len());
        merged.positions.extend(
            mesh.positions
                .iter()
                .map(|p| turn * organ.placement.world_from_template(*p, 0.0) + lift),
        );
        merged.uvs.extend_from_slice(&mesh.uvs);
        merged
            .triangles
            .extend(mesh.triangles.iter().map(|t| t.map(|i| i + offset)));
    }
    let [a, b] = find_self_intersection(&merged)?;
    let organ_of = |t: usize| first_triangle.partition_point(|&first| first <= t) - 1;
    let name = |t: usize| flower.organs[organ_of(t)].name.clone();
    Some((name(a), name(b)))
}

#[cfg(test)]
mod tests;

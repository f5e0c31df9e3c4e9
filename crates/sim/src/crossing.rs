//! The check that ends every keyframe: no triangle of an organ crosses
//! another organ's, a part's (stamens, pistils, the pedicel, an L-system's
//! tubes: every part but the receptacle, where organs are attached) or its
//! own beyond the triangles sharing a corner with it. Contacts act on
//! particles, so a surface can still pass between another's particles, or
//! an organ through itself where nothing keeps it out (issue 35): such a
//! keyframe is not a valid result, and the run stops there with
//! [`SimError::Crossed`](crate::SimError::Crossed) naming the organs, the
//! keyframe and where on their UVs, or, where the caller chose
//! [`OnCrossing::Warn`], goes on and keeps what it found
//! ([`Simulation::crossings`](crate::Simulation::crossings)).
//!
//! The search is `anthesis_mesh::crossing`'s bounding volume hierarchies
//! over every triangle of the keyframe (built in the run's first check,
//! refitted after), parts against parts not tested (they overlap by
//! design, a stamen's anther on its filament).

use std::fmt;

use glam::DVec2;

/// What a run does when a keyframe has crossing triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum OnCrossing {
    /// Stop with [`SimError::Crossed`](crate::SimError::Crossed); the
    /// keyframes before it stay good.
    #[default]
    Stop,
    /// Keep the keyframe and go on; what was found is kept as a warning
    /// ([`Simulation::crossings`](crate::Simulation::crossings)).
    Warn,
    /// Do not look. For a preview whose converged run looks: the window's
    /// proxy (a coarse mesh can cross where the converged one does not, and
    /// the search is a quarter of a 180-particle proxy's time).
    Skip,
}

/// One side of a crossing: where on an organ, or which part.
#[derive(Debug, Clone, PartialEq)]
pub enum Crossed {
    /// A simulated organ, at a point of its UV layout.
    Organ {
        /// The organ's index among the simulated organs (keyframe order).
        index: usize,
        /// Its name.
        name: String,
        /// Where on it: `u` across, `v` from base to tip.
        uv: DVec2,
    },
    /// A part (its piece's name).
    Part {
        /// The piece's name.
        name: String,
    },
}

impl Crossed {
    /// The organ's or part's name.
    pub fn name(&self) -> &str {
        match self {
            Crossed::Organ { name, .. } | Crossed::Part { name } => name,
        }
    }
}

impl fmt::Display for Crossed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Crossed::Organ { name, uv, .. } => {
                write!(f, "`{name}` at uv ({:.2}, {:.2})", uv.x, uv.y)
            }
            Crossed::Part { name } => write!(f, "the part `{name}`"),
        }
    }
}

/// What the check found in one keyframe.
#[derive(Debug, Clone, PartialEq)]
pub struct Crossings {
    /// The keyframe.
    pub keyframe: u32,
    /// How many pairs of triangles cross.
    pub pairs: usize,
    /// Per pair of organs (or organ and part) that cross, in the order
    /// their first crossing was found, where it is and how many pairs of
    /// triangles cross between them; an organ crossing itself is a pair of
    /// the same organ.
    pub between: Vec<(Crossed, Crossed, usize)>,
    /// The simulated organs taking part in some crossing (their indices,
    /// ascending): those a view outlines.
    pub organs: Vec<usize>,
    /// Whether some of these organs already cross each other (or
    /// themselves) in the bud, keyframe 0: contacts keep each organ on the
    /// side it starts on, so nothing parts organs that start through each
    /// other; the bud must change (set only at keyframe 1).
    pub from_bud: bool,
}

impl fmt::Display for Crossings {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let Some((a, b, count)) = self.between.first() else {
            return write!(f, "keyframe {}: no crossing", self.keyframe);
        };
        let what = if a.name() == b.name() {
            format!("{a} passes through itself at uv {}", uv_of(b))
        } else {
            format!("{a} passes through {b}")
        };
        write!(
            f,
            "keyframe {}: {what} ({count} crossing triangle pair{})",
            self.keyframe,
            if *count == 1 { "" } else { "s" }
        )?;
        let rest: Vec<String> = self.between[1..]
            .iter()
            .map(|(a, b, n)| {
                if a.name() == b.name() {
                    format!("`{}` itself ({n})", a.name())
                } else {
                    format!("`{}` and `{}` ({n})", a.name(), b.name())
                }
            })
            .collect();
        if !rest.is_empty() {
            write!(f, "; also {}", rest.join(", "))?;
        }
        if self.from_bud {
            write!(
                f,
                ". They cross already in the bud, and contacts keep each organ on the side \
                 it starts on, so nothing can part them: make the organs narrower, or place \
                 them farther apart (a whorl sets its organs side by side around the \
                 receptacle, not overlapping in turn)"
            )?;
        }
        Ok(())
    }
}

/// The UV of an organ's side, for the second half of a self-crossing.
fn uv_of(side: &Crossed) -> String {
    match side {
        Crossed::Organ { uv, .. } => format!("({:.2}, {:.2})", uv.x, uv.y),
        Crossed::Part { .. } => String::new(),
    }
}

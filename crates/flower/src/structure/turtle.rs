//! The turtle interpretation of Qin and Chen 2006 §2: a derived
//! word read from left to right moves a turtle (position P, heading H,
//! left L, up U with H × L = U), draws `F` segments as tubes of the current
//! width and places the surfaces `~X` at its position and frame.
//!
//! One symbol beyond the seed's §2, since its lines are all one colour: as
//! in L-Py and cpfg, `;` sets the colour the following lines are drawn in
//! (part of the turtle's state, so `[` and `]` save and restore it):
//! `;(r, g, b)` a linear RGB colour with components in `[0, 1]`, `;` alone
//! the default (the stem's green).

use glam::{DMat3, DVec3};

use super::lsystem::{LSystem, Module};

/// Where a `~X(s)` puts its surface.
#[derive(Debug, Clone, PartialEq)]
pub struct PlacedSurface {
    /// The surface's letter (the `X` of `~X`).
    pub surface: char,
    /// The turtle's position.
    pub position: DVec3,
    /// The turtle's heading H, left L and up U, as the columns of a
    /// rotation (H, L, U).
    pub frame: DMat3,
    /// The scale `s` (default: the constant `scale`, else 1).
    pub scale: f64,
}

impl PlacedSurface {
    /// The rotation taking an organ template's frame (base at the origin,
    /// growing along +Y, inner side −Z, joint axis +X) to the world at the
    /// turtle's frame: template +Y onto H, +X onto −L, +Z onto U. At the
    /// turtle's start (H = +Y, L = −X, U = +Z) it is the identity.
    pub fn template_rotation(&self) -> DMat3 {
        DMat3::from_cols(-self.frame.y_axis, self.frame.x_axis, self.frame.z_axis)
    }
}

/// A segment drawn by `F`: a tube from `start` to `end`.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// Where the turtle was.
    pub start: DVec3,
    /// Where it moved to.
    pub end: DVec3,
    /// The line width when it was drawn.
    pub width: f64,
    /// The colour `;(r, g, b)` set (linear RGBA, opaque), or `None` for the
    /// default.
    pub colour: Option<[f32; 4]>,
    /// Where its `F` is in the word (an index), to tell what drew it.
    pub module: usize,
}

/// What a word draws.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Drawing {
    /// The surfaces, in the word's order.
    pub surfaces: Vec<PlacedSurface>,
    /// The `F` segments, in the word's order.
    pub segments: Vec<Segment>,
}

/// The defaults for parameterless symbols, from the L-system's constants.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Defaults {
    /// Turning angle in degrees (`angle`, default 90).
    pub angle_deg: f64,
    /// Step length of `F` and `f` (`step`, default 1).
    pub step: f64,
    /// Line width at the start (`initial line width` or `width`, default 1).
    pub width: f64,
    /// What `#` adds and `!` takes away (`line width increment` or `width
    /// increment`, default 1).
    pub width_increment: f64,
    /// Scale of `~X` (`scale`, default 1).
    pub scale: f64,
}

impl Defaults {
    /// The defaults an L-system's constants give.
    pub fn of(system: &LSystem) -> Defaults {
        let get = |names: &[&str], default: f64| {
            names
                .iter()
                .find_map(|n| system.constant(n))
                .unwrap_or(default)
        };
        Defaults {
            angle_deg: get(&["angle"], 90.0),
            step: get(&["step"], 1.0),
            width: get(&["initial line width", "width"], 1.0),
            width_increment: get(&["line width increment", "width increment"], 1.0),
            scale: get(&["scale"], 1.0),
        }
    }
}

/// `R_U(α)` of eq. (1.2). As printed there (and in *The Algorithmic Beauty
/// of Plants*), `[H L U] R_U(α)` turns the heading away from L for a
/// positive α; Anthesis keeps the equations exactly, so an L-system reads
/// the same here as in the paper.
pub fn r_u(alpha: f64) -> DMat3 {
    let (s, c) = alpha.sin_cos();
    DMat3::from_cols(
        DVec3::new(c, -s, 0.0),
        DVec3::new(s, c, 0.0),
        DVec3::new(0.0, 0.0, 1.0),
    )
}

/// `R_L(α)` of eq. (1.3).
pub fn r_l(alpha: f64) -> DMat3 {
    let (s, c) = alpha.sin_cos();
    DMat3::from_cols(
        DVec3::new(c, 0.0, s),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(-s, 0.0, c),
    )
}

/// `R_H(α)` of eq. (1.4).
pub fn r_h(alpha: f64) -> DMat3 {
    let (s, c) = alpha.sin_cos();
    DMat3::from_cols(
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, c, s),
        DVec3::new(0.0, -s, c),
    )
}

#[derive(Debug, Clone, Copy)]
struct State {
    position: DVec3,
    /// Columns H, L, U.
    frame: DMat3,
    width: f64,
    colour: Option<[f32; 4]>,
}

/// The colour `;(r, g, b)` sets: the three components clamped to `[0, 1]`
/// (a NaN to 0), opaque; `None` (the default colour) with fewer than three.
fn line_colour(params: &[f64]) -> Option<[f32; 4]> {
    let channel = |x: f64| {
        if x.is_nan() {
            0.0
        } else {
            x.clamp(0.0, 1.0) as f32
        }
    };
    match params {
        [r, g, b, ..] => Some([channel(*r), channel(*g), channel(*b), 1.0]),
        _ => None,
    }
}

/// Interprets `word`: the turtle starts at the origin with H = +Y,
/// L = −X (so U = H × L = +Z) and the default width; a symbol's first
/// parameter is used, or the default when it has none. A `]` without its
/// `[` is ignored (the turtle stays where it is); symbols the turtle does
/// not know (module letters left after the derivation) do nothing.
pub fn interpret(word: &[Module], defaults: &Defaults) -> Drawing {
    let mut state = State {
        position: DVec3::ZERO,
        frame: DMat3::from_cols(DVec3::Y, -DVec3::X, DVec3::Z),
        width: defaults.width,
        colour: None,
    };
    let mut stack = Vec::new();
    let mut drawing = Drawing::default();
    for (index, module) in word.iter().enumerate() {
        let first = module.params.first().copied();
        let angle = || first.unwrap_or(defaults.angle_deg).to_radians();
        // [H' L' U'] = [H L U] R (eq. 1.1).
        let mut turn = |r: DMat3| state.frame *= r;
        match module.symbol.as_str() {
            "F" => {
                let end = state.position + state.frame.x_axis * first.unwrap_or(defaults.step);
                drawing.segments.push(Segment {
                    start: state.position,
                    end,
                    width: state.width,
                    colour: state.colour,
                    module: index,
                });
                state.position = end;
            }
            "f" => state.position += state.frame.x_axis * first.unwrap_or(defaults.step),
            "+" => turn(r_u(angle())),
            "-" => turn(r_u(-angle())),
            "&" => turn(r_l(angle())),
            "^" => turn(r_l(-angle())),
            "/" => turn(r_h(angle())),
            "\\" => turn(r_h(-angle())),
            "[" => stack.push(state),
            "]" => {
                if let Some(saved) = stack.pop() {
                    state = saved;
                }
            }
            "#" => {
                state.width = first.unwrap_or(state.width + defaults.width_increment);
            }
            "!" => {
                state.width = first.unwrap_or(state.width - defaults.width_increment);
            }
            ";" => state.colour = line_colour(&module.params),
            symbol => {
                if let Some(letter) = symbol.strip_prefix('~').and_then(|l| l.chars().next()) {
                    drawing.surfaces.push(PlacedSurface {
                        surface: letter,
                        position: state.position,
                        frame: state.frame,
                        scale: first.unwrap_or(defaults.scale),
                    });
                }
            }
        }
    }
    drawing
}

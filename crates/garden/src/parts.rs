//! The stamens, pistils, receptacles and stems of the built-in flowers
//! (issue 13 item 4), sized to fit inside their buds: a bud's tepals wrap
//! the axis at the radius given by the bud meshes (lily: 2 at the base, 8
//! at mid-height, closing at 44; Eustoma: 1.8, 11.8, 44), so the stamens
//! and the pistil stand upright in the bud and the stamens spread as the
//! flower opens, like a joint schedule.

use anthesis_flower::JointRamp;
use anthesis_flower::parts::{Part, PartShape, Tube};

/// A part with the settings every built-in one shares.
fn part(name: &str, shape: PartShape, count: u32, colour: [f32; 4], head: [f32; 4]) -> Part {
    Part {
        name: name.to_string(),
        shape,
        count,
        ring_radius: 0.0,
        height: 0.0,
        offset_deg: 0.0,
        angle_deg: 0.0,
        schedule: Vec::new(),
        colour,
        head_colour: head,
    }
}

/// The receptacle under the organs and the stem below it.
fn stem(radius: f64, depth: f64, stem_radius: f64, length: f64, colour: [f32; 4]) -> [Part; 2] {
    let receptacle = part(
        "receptacle",
        PartShape::Receptacle { radius, depth },
        1,
        colour,
        colour,
    );
    let mut pedicel = part(
        "pedicel",
        PartShape::Pedicel {
            stalk: Tube {
                length,
                radius: stem_radius,
                curvature_deg: -12.0,
            },
        },
        1,
        colour,
        colour,
    );
    // It starts inside the receptacle's lower half.
    pedicel.height = -0.8 * depth;
    [receptacle, pedicel]
}

/// The lily's: six stamens with versatile anthers (lying across the
/// filament tip, clear of the tepals in the bud) that spread from 3° to 33°
/// over steps 20–80, a pistil
/// with a long ovary and a three-lobed stigma, a receptacle and a stem.
pub fn lily_parts() -> Vec<Part> {
    const STEM: [f32; 4] = [0.30, 0.47, 0.16, 1.0];
    let [receptacle, pedicel] = stem(3.2, 2.4, 0.9, 30.0, STEM);
    let mut stamens = part(
        "stamen",
        PartShape::Stamen {
            filament: Tube {
                length: 27.0,
                radius: 0.22,
                curvature_deg: 6.0,
            },
            anther_length: 4.0,
            anther_radius: 0.55,
            anther_tilt_deg: 90.0,
        },
        6,
        [0.90, 0.62, 0.30, 1.0],
        [0.30, 0.06, 0.02, 1.0],
    );
    stamens.ring_radius = 0.9;
    stamens.height = 0.4;
    stamens.offset_deg = 30.0;
    stamens.angle_deg = 3.0;
    stamens.schedule = vec![JointRamp {
        from_step: 20,
        to_step: 80,
        angle_deg: 30.0,
    }];
    let mut pistil = part(
        "pistil",
        PartShape::Pistil {
            style: Tube {
                length: 30.0,
                radius: 0.35,
                curvature_deg: 6.0,
            },
            stigma_radius: 1.1,
            stigma_lobes: 3,
            ovary_length: 8.0,
            ovary_radius: 0.95,
        },
        1,
        [0.62, 0.66, 0.30, 1.0],
        [0.55, 0.20, 0.08, 1.0],
    );
    pistil.height = 0.3;
    vec![receptacle, pedicel, stamens, pistil]
}

/// An Eustoma's: five stamens with anthers along the filament tip that
/// spread from 3° to 18° over steps 30–90, a pistil with a two-lobed
/// stigma, a receptacle and a stem.
pub fn eustoma_parts() -> Vec<Part> {
    const STEM: [f32; 4] = [0.33, 0.50, 0.22, 1.0];
    let [receptacle, pedicel] = stem(2.6, 2.0, 0.8, 28.0, STEM);
    let mut stamens = part(
        "stamen",
        PartShape::Stamen {
            filament: Tube {
                length: 18.0,
                radius: 0.25,
                curvature_deg: 8.0,
            },
            anther_length: 3.2,
            anther_radius: 0.6,
            anther_tilt_deg: 0.0,
        },
        5,
        [0.88, 0.88, 0.72, 1.0],
        [0.85, 0.62, 0.10, 1.0],
    );
    stamens.ring_radius = 0.8;
    stamens.height = 0.3;
    stamens.offset_deg = 36.0;
    stamens.angle_deg = 3.0;
    stamens.schedule = vec![JointRamp {
        from_step: 30,
        to_step: 90,
        angle_deg: 15.0,
    }];
    let mut pistil = part(
        "pistil",
        PartShape::Pistil {
            style: Tube {
                length: 22.0,
                radius: 0.3,
                curvature_deg: 0.0,
            },
            stigma_radius: 1.0,
            stigma_lobes: 2,
            ovary_length: 7.0,
            ovary_radius: 1.1,
        },
        1,
        [0.70, 0.78, 0.50, 1.0],
        [0.80, 0.80, 0.55, 1.0],
    );
    pistil.height = 0.3;
    vec![receptacle, pedicel, stamens, pistil]
}

/// The apple flower's: only a receptacle at the top of its stem (`height`),
/// since the seed's L-system draws the stem and the stamens itself (its
/// `F` lines become tubes).
pub fn apple_parts(height: f64) -> Vec<Part> {
    const GREEN: [f32; 4] = [0.30, 0.45, 0.16, 1.0];
    let mut receptacle = part(
        "receptacle",
        PartShape::Receptacle {
            radius: 2.2,
            depth: 2.6,
        },
        1,
        GREEN,
        GREEN,
    );
    receptacle.height = height;
    vec![receptacle]
}

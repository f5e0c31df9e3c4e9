//! What every view draws besides the growing organs: the flower's parts
//! (the receptacle, stamens, pistils, the stem) at a keyframe time, the
//! same pieces [`anthesis_export::flower_tracks`] exports.

use anthesis_export::KeyframeBlend;
use anthesis_flower::Flower;
use anthesis_flower::parts::{PartPiece, part_pieces};
use anthesis_render::OrganMesh;

/// The parts of `flower` at `time_in_keyframes` (0 the bud; between two
/// keyframes the positions blend as [`KeyframeBlend`] places them, as the
/// timeline and the exports blend organs), each in its colour.
pub fn part_meshes(flower: &Flower, time_in_keyframes: f64) -> Vec<OrganMesh> {
    let pieces = part_pieces(flower);
    pieces
        .iter()
        .map(|piece| piece_mesh(piece, time_in_keyframes))
        .collect()
}

/// One piece of [`part_pieces`] at `time_in_keyframes`, as
/// [`part_meshes`] draws it.
pub fn piece_mesh(piece: &PartPiece, time_in_keyframes: f64) -> OrganMesh {
    let time = if time_in_keyframes.is_finite() {
        time_in_keyframes
    } else {
        0.0
    };
    // A part's schedule is defined at every step, so its sequence of
    // keyframes is as long as a step count can be.
    let positions = match KeyframeBlend::at(u32::MAX as usize, time) {
        Some(blend) if blend.fraction > 0.0 && piece.moves() => blend.positions(
            &piece.positions_at(blend.below as u32),
            &piece.positions_at(blend.above as u32),
        ),
        Some(blend) => piece.positions_at(blend.below as u32),
        None => piece.positions_at(0),
    };
    OrganMesh::from_positions(&positions, &piece.mesh.triangles, piece.colour)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_blend_between_keyframes_and_the_receptacle_is_always_there() {
        let mut project = anthesis_sim::fixtures::whorl(1, 4, 6, 10);
        let meshes = part_meshes(&project.flower, 3.5);
        assert_eq!(meshes.len(), 1, "the receptacle alone");
        project.flower.parts = vec![anthesis_flower::parts::Part {
            name: "pistil".into(),
            shape: anthesis_flower::parts::PartShape::Pedicel {
                stalk: anthesis_flower::parts::Tube {
                    length: 5.0,
                    radius: 0.2,
                    curvature_deg: 0.0,
                },
            },
            count: 1,
            ring_radius: 0.0,
            height: 0.0,
            offset_deg: 0.0,
            angle_deg: 0.0,
            schedule: vec![anthesis_flower::JointRamp {
                from_step: 0,
                to_step: 10,
                angle_deg: 20.0,
            }],
            colour: [0.2, 0.5, 0.2, 1.0],
            head_colour: [0.2, 0.5, 0.2, 1.0],
        }];
        let at = |t: f64| {
            part_meshes(&project.flower, t)[1]
                .positions_in_world
                .clone()
        };
        let (three, four, between) = (at(3.0), at(4.0), at(3.5));
        for ((a, b), m) in three.iter().zip(&four).zip(&between) {
            for k in 0..3 {
                assert!((0.5 * (a[k] + b[k]) - m[k]).abs() < 1e-5);
            }
        }
        assert_ne!(three, four);
    }
}

//! Building [`Track`]s: from the keyframes of a simulation, which hands out
//! the positions of every organ keyframe by keyframe, and from a mesh that
//! does not move; [`flower_tracks`] is the one rule every export of a
//! flower follows (the desktop's and the command line's).

use anthesis_flower::{Flower, RECEPTACLE_COLOR, receptacle_for};
use anthesis_mesh::Mesh;
use glam::{DVec2, DVec3};

use crate::Track;

/// What a [`Track`] keeps through a whole run: the name, the triangulation,
/// the UV layout and the colour of one organ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackLook<'a> {
    /// The organ's name.
    pub name: &'a str,
    /// Vertex indices, three per triangle.
    pub triangles: &'a [[u32; 3]],
    /// One UV per vertex.
    pub uvs: &'a [DVec2],
    /// Linear RGBA in `[0, 1]`.
    pub base_color: [f32; 4],
}

impl<'a> TrackLook<'a> {
    /// The look of one organ.
    pub fn new(
        name: &'a str,
        triangles: &'a [[u32; 3]],
        uvs: &'a [DVec2],
        base_color: [f32; 4],
    ) -> TrackLook<'a> {
        TrackLook {
            name,
            triangles,
            uvs,
            base_color,
        }
    }
}

impl Track {
    /// A track that does not move (the receptacle): `mesh` as it is, as the
    /// only keyframe.
    pub fn still(name: impl Into<String>, mesh: Mesh, base_color: [f32; 4]) -> Track {
        Track {
            name: name.into(),
            triangles: mesh.triangles,
            uvs: mesh.uvs,
            base_color,
            keyframes: vec![mesh.positions],
            base_color_png: None,
        }
    }
}

/// One track per organ, from keyframes in the order a simulation hands them
/// out: each item of `keyframes` holds the positions (world frame) of every
/// organ at one keyframe, organ `i`'s at index `i`, and the `i`-th item of
/// `looks` is what organ `i` looks like. A keyframe that holds fewer organs
/// than `looks` adds nothing to the tracks of the missing ones.
pub fn organ_tracks<'a, 'k>(
    looks: impl IntoIterator<Item = TrackLook<'a>>,
    keyframes: impl IntoIterator<Item = &'k [Vec<DVec3>]>,
) -> Vec<Track> {
    let mut tracks: Vec<Track> = looks
        .into_iter()
        .map(|look| Track {
            name: look.name.to_string(),
            triangles: look.triangles.to_vec(),
            uvs: look.uvs.to_vec(),
            base_color: look.base_color,
            keyframes: Vec::new(),
            base_color_png: None,
        })
        .collect();
    for organs in keyframes {
        for (track, positions) in tracks.iter_mut().zip(organs) {
            track.keyframes.push(positions.clone());
        }
    }
    tracks
}

/// What an export of `flower` holds: one track per simulated organ (`organs`
/// are indices into `flower.organs`, in the order the keyframes hold their
/// positions), named after the organ and drawn with its template's mesh,
/// UVs and colour, followed by the receptacle the organs sit on
/// ([`receptacle_for`]) as a still track named `receptacle`.
///
/// `keyframes` are as [`organ_tracks`] takes them: keyframe 0 (the bud)
/// first. Without keyframes there is nothing to export: no tracks.
pub fn flower_tracks<'k>(
    flower: &Flower,
    organs: &[usize],
    keyframes: impl IntoIterator<Item = &'k [Vec<DVec3>]>,
) -> Vec<Track> {
    let mut keyframes = keyframes.into_iter().peekable();
    if keyframes.peek().is_none() {
        return Vec::new();
    }
    let looks = organs.iter().map(|&organ| {
        let template = flower.template_of(organ);
        TrackLook::new(
            &flower.organs[organ].name,
            &template.mesh.triangles,
            &template.mesh.uvs,
            template.color,
        )
    });
    let mut tracks = organ_tracks(looks, keyframes);
    tracks.push(Track::still(
        "receptacle",
        receptacle_for(flower),
        RECEPTACLE_COLOR,
    ));
    tracks
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn organ_tracks_gather_each_organs_positions_keyframe_by_keyframe() {
        let triangle = [[0, 1, 2]];
        let uvs = [DVec2::ZERO, DVec2::X, DVec2::Y];
        let looks = [
            TrackLook::new("sepal", &triangle, &uvs, [1.0, 0.0, 0.0, 1.0]),
            TrackLook::new("petal", &triangle, &uvs, [0.0, 0.0, 1.0, 1.0]),
        ];
        // Keyframe k moves organ i to x = 10 k + i.
        let at = |k: u32, i: u32| vec![DVec3::new(f64::from(10 * k + i), 0.0, 0.0); 3];
        let keyframes: Vec<Vec<Vec<DVec3>>> = (0..3).map(|k| vec![at(k, 0), at(k, 1)]).collect();

        let tracks = organ_tracks(looks, keyframes.iter().map(Vec::as_slice));

        assert_eq!(tracks.len(), 2);
        assert_eq!(tracks[1].name, "petal");
        assert_eq!(tracks[1].triangles, triangle);
        assert_eq!(tracks[1].uvs, uvs);
        assert_eq!(tracks[1].base_color, [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(tracks[1].base_color_png, None);
        assert_eq!(tracks[0].keyframes, vec![at(0, 0), at(1, 0), at(2, 0)]);
        assert_eq!(tracks[1].keyframes, vec![at(0, 1), at(1, 1), at(2, 1)]);
    }

    #[test]
    fn a_still_track_is_its_mesh_as_one_keyframe() {
        let mesh = anthesis_mesh::generate::flat_sheet(2.0, 1.0, 3, 2);
        let track = Track::still("receptacle", mesh.clone(), [0.5; 4]);
        assert_eq!(track.name, "receptacle");
        assert_eq!(track.triangles, mesh.triangles);
        assert_eq!(track.uvs, mesh.uvs);
        assert_eq!(track.keyframes, vec![mesh.positions]);
        assert_eq!(track.base_color, [0.5; 4]);
    }
}

//! Building [`Track`]s: from the keyframes of a simulation, which hands out
//! the positions of every organ keyframe by keyframe, and from a mesh that
//! does not move; [`flower_tracks`] is the one rule every export of a
//! flower follows (the desktop's and the command line's), with its organs
//! at the simulated resolution or as finer render meshes driven by the
//! simulated ones (Loop subdivision, [`check_render_level`]).

use anthesis_flower::Flower;
use anthesis_flower::parts::{PartPiece, part_pieces};
use anthesis_mesh::Mesh;
use anthesis_mesh::Subdivision;
use anthesis_mesh::subdivide::subdivided_counts;
use glam::{DVec2, DVec3};

use crate::{ExportError, Pose, RigidMotion, Track, TrackProblem};

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
    pub base_colour: [f32; 4],
}

impl<'a> TrackLook<'a> {
    /// The look of one organ.
    pub fn new(
        name: &'a str,
        triangles: &'a [[u32; 3]],
        uvs: &'a [DVec2],
        base_colour: [f32; 4],
    ) -> TrackLook<'a> {
        TrackLook {
            name,
            triangles,
            uvs,
            base_colour,
        }
    }
}

impl Track {
    /// A track that does not move (the receptacle): `mesh` as it is, as the
    /// only keyframe.
    pub fn still(name: impl Into<String>, mesh: Mesh, base_colour: [f32; 4]) -> Track {
        Track {
            name: name.into(),
            triangles: mesh.triangles,
            uvs: mesh.uvs,
            base_colour,
            keyframes: vec![mesh.positions],
            base_colour_png: None,
            rigid: None,
            unit: anthesis_flower::Unit::METRE,
            outer_colour_png: None,
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
            base_colour: look.base_colour,
            keyframes: Vec::new(),
            base_colour_png: None,
            rigid: None,
            unit: anthesis_flower::Unit::METRE,
            outer_colour_png: None,
        })
        .collect();
    for organs in keyframes {
        for (track, positions) in tracks.iter_mut().zip(organs) {
            track.keyframes.push(positions.clone());
        }
    }
    tracks
}

/// The most render positions (render vertices per keyframe times the
/// keyframes, over every subdivided organ) an export may build: about
/// 1.2 GB of positions in memory and as much again in a dense .glb. A finer
/// render level is refused with [`ExportError::TooFine`] before anything is
/// built.
pub const MAX_RENDER_POSITIONS: u64 = 50_000_000;

/// The render vertices per keyframe of `flower`'s `organs` at render
/// subdivision `level` (see [`anthesis_mesh::subdivide`]), checked against
/// [`MAX_RENDER_POSITIONS`] for `keyframe_count` keyframes (the bud
/// included). For checking a command line before a long simulation; level
/// 0 (the simulated meshes) always passes.
pub fn check_render_level(
    flower: &Flower,
    organs: &[usize],
    keyframe_count: usize,
    level: u32,
) -> Result<u64, ExportError> {
    let per_keyframe = |level: u32| -> u64 {
        organs
            .iter()
            .map(|&organ| {
                let mesh = &flower.template_of(organ).mesh;
                let edges = edge_count(&mesh.triangles);
                subdivided_counts(
                    mesh.vertex_count() as u64,
                    edges,
                    mesh.triangle_count() as u64,
                    level,
                )
                .0
            })
            .fold(0, u64::saturating_add)
    };
    let vertices = per_keyframe(level);
    let positions = vertices.saturating_mul(keyframe_count as u64);
    if level == 0 || positions <= MAX_RENDER_POSITIONS {
        return Ok(vertices);
    }
    let finest = (1..level)
        .rev()
        .find(|&l| per_keyframe(l).saturating_mul(keyframe_count as u64) <= MAX_RENDER_POSITIONS);
    Err(ExportError::TooFine {
        level,
        vertices,
        positions,
        keyframes: keyframe_count,
        limit: MAX_RENDER_POSITIONS,
        finest,
    })
}

/// The number of distinct edges of `triangles`.
fn edge_count(triangles: &[[u32; 3]]) -> u64 {
    let mut edges: Vec<(u32, u32)> = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges.len() as u64
}

/// What an export of `flower` holds: one track per simulated organ (`organs`
/// are indices into `flower.organs`, in the order the keyframes hold their
/// positions), named after the organ and drawn with its template's mesh,
/// UVs and colour (a template with a colour map: its baked PNG as the
/// base-colour texture, [`crate::colour_png`], and a white base colour),
/// followed by the flower's parts
/// ([`anthesis_flower::parts::part_pieces`]: the receptacle the organs sit
/// on, named `receptacle`, then every stamen, pistil and stem piece), each
/// still or, where its schedule turns it, rigid ([`part_track`]).
///
/// `keyframes` are as [`organ_tracks`] takes them: keyframe 0 (the bud)
/// first. Without keyframes there is nothing to export: no tracks. Every
/// track's [`Track::unit`] is the flower's (one metre where it states none).
///
/// `render_level` above 0 exports each organ as its render mesh
/// ([`Track::subdivided`]): the simulated mesh after that many levels of
/// Loop subdivision, built once per organ and applied to every keyframe,
/// about four times the vertices per level, with the template's UVs
/// interpolated linearly so the painted maps land as on the simulated mesh. The parts, which are not simulated, are exported as
/// they are. Fails when the level is too fine ([`check_render_level`]) or an
/// organ's mesh cannot be subdivided.
pub fn flower_tracks<'k>(
    flower: &Flower,
    organs: &[usize],
    keyframes: impl IntoIterator<Item = &'k [Vec<DVec3>]>,
    render_level: u32,
) -> Result<Vec<Track>, ExportError> {
    let keyframes: Vec<&[Vec<DVec3>]> = keyframes.into_iter().collect();
    if keyframes.is_empty() {
        return Ok(Vec::new());
    }
    check_render_level(flower, organs, keyframes.len(), render_level)?;
    let looks = organs.iter().map(|&organ| {
        let template = flower.template_of(organ);
        TrackLook::new(
            &flower.organs[organ].name,
            &template.mesh.triangles,
            &template.mesh.uvs,
            template.colour,
        )
    });
    let count = keyframes.len();
    let mut tracks = organ_tracks(looks, keyframes);
    crate::colour::paint_tracks(&mut tracks, flower, organs)?;
    if render_level > 0 {
        tracks = tracks
            .iter()
            .enumerate()
            .map(|(i, track)| {
                track.subdivided(render_level).map_err(|error| match error {
                    ExportError::InvalidTrack { name, problem, .. } => ExportError::InvalidTrack {
                        track: i,
                        name,
                        problem,
                    },
                    other => other,
                })
            })
            .collect::<Result<_, _>>()?;
    }
    tracks.extend(
        part_pieces(flower)
            .iter()
            .map(|piece| part_track(piece, count)),
    );
    let unit = flower.unit.unwrap_or_default();
    for track in &mut tracks {
        track.unit = unit;
    }
    Ok(tracks)
}

/// The track of a part's piece over `keyframe_count` keyframes: still
/// where it does not move, rigid (its own mesh and a pose per keyframe)
/// where its schedule turns it.
pub fn part_track(piece: &PartPiece, keyframe_count: usize) -> Track {
    if !piece.moves() || keyframe_count < 2 {
        let mesh = Mesh {
            positions: piece.positions_at(0),
            ..piece.mesh.clone()
        };
        return Track::still(piece.name.clone(), mesh, piece.colour);
    }
    let poses: Vec<Pose> = (0..keyframe_count as u32)
        .map(|step| {
            let (translation, rotation) = piece.pose(step);
            Pose {
                translation,
                rotation,
            }
        })
        .collect();
    let keyframes = poses
        .iter()
        .map(|pose| {
            piece
                .mesh
                .positions
                .iter()
                .map(|&p| pose.translation + pose.rotation * p)
                .collect()
        })
        .collect();
    Track {
        name: piece.name.clone(),
        triangles: piece.mesh.triangles.clone(),
        uvs: piece.mesh.uvs.clone(),
        base_colour: piece.colour,
        keyframes,
        base_colour_png: None,
        rigid: Some(RigidMotion {
            local: piece.mesh.positions.clone(),
            poses,
        }),
        unit: anthesis_flower::Unit::METRE,
        outer_colour_png: None,
    }
}

impl Track {
    /// The track's render mesh: its mesh after `level` levels of Loop
    /// subdivision ([`Subdivision`]: the rim a crease, rim corners sharper
    /// than [`anthesis_mesh::subdivide::CORNER_ANGLE`] in keyframe 0 kept,
    /// UVs interpolated linearly), built once and applied to every
    /// keyframe. Fails on a mesh that is not a manifold, consistently
    /// oriented surface, one whose render mesh would have more than
    /// [`anthesis_mesh::subdivide::MAX_SUBDIVIDED_VERTICES`], or a keyframe
    /// with another vertex count than keyframe 0 (reported as track 0: the
    /// caller knows the track's index).
    pub fn subdivided(&self, level: u32) -> Result<Track, ExportError> {
        let Some(first) = self.keyframes.first() else {
            return Ok(self.clone());
        };
        let mesh = Mesh {
            positions: first.clone(),
            uvs: self.uvs.clone(),
            triangles: self.triangles.clone(),
        };
        let subdivision =
            Subdivision::new(&mesh, level).map_err(|error| ExportError::Subdivision {
                organ: self.name.clone(),
                error,
            })?;
        let mut keyframes = Vec::with_capacity(self.keyframes.len());
        for (keyframe, coarse) in self.keyframes.iter().enumerate() {
            if coarse.len() != first.len() {
                return Err(ExportError::InvalidTrack {
                    track: 0,
                    name: self.name.clone(),
                    problem: TrackProblem::KeyframeVertexCount {
                        keyframe,
                        expected: first.len(),
                        found: coarse.len(),
                    },
                });
            }
            keyframes.push(subdivision.apply(coarse));
        }
        Ok(Track {
            name: self.name.clone(),
            triangles: subdivision.triangles().to_vec(),
            uvs: subdivision.uvs().to_vec(),
            base_colour: self.base_colour,
            keyframes,
            base_colour_png: self.base_colour_png.clone(),
            rigid: None,
            unit: self.unit,
            outer_colour_png: self.outer_colour_png.clone(),
        })
    }
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
        assert_eq!(tracks[1].base_colour, [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(tracks[1].base_colour_png, None);
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
        assert_eq!(track.base_colour, [0.5; 4]);
    }

    /// A petal bending outwards over three keyframes.
    fn bending_petal() -> Track {
        let petal = anthesis_mesh::generate::test_petal(10.0, 4.0, 9, 17);
        let keyframes = (0..3)
            .map(|k| {
                let bend = 0.02 * f64::from(k);
                petal
                    .positions
                    .iter()
                    .map(|p| DVec3::new(p.x, p.y, p.z + bend * p.y * p.y))
                    .collect()
            })
            .collect();
        Track {
            name: "petal".into(),
            triangles: petal.triangles,
            uvs: petal.uvs,
            base_colour: [0.9, 0.8, 0.9, 1.0],
            keyframes,
            base_colour_png: None,
            rigid: None,
            unit: anthesis_flower::Unit::METRE,
            outer_colour_png: None,
        }
    }

    #[test]
    fn a_subdivided_track_is_every_keyframe_through_one_subdivision() {
        let track = bending_petal();
        assert_eq!(track.subdivided(0).expect("level 0"), track);
        let fine = track.subdivided(2).expect("subdivides");
        let bud = Mesh {
            positions: track.keyframes[0].clone(),
            uvs: track.uvs.clone(),
            triangles: track.triangles.clone(),
        };
        let subdivision = Subdivision::new(&bud, 2).expect("subdivides");
        assert_eq!(fine.name, track.name);
        assert_eq!(fine.base_colour, track.base_colour);
        assert_eq!(fine.triangles, subdivision.triangles());
        assert_eq!(fine.uvs, subdivision.uvs());
        assert_eq!(fine.triangles.len(), 16 * track.triangles.len());
        assert_eq!(fine.keyframes.len(), 3);
        for (coarse, fine) in track.keyframes.iter().zip(&fine.keyframes) {
            assert_eq!(*fine, subdivision.apply(coarse));
        }
        // The simulated particles keep their indices.
        assert_eq!(fine.keyframes[2].len(), subdivision.vertex_count());
    }

    #[test]
    fn bad_tracks_are_refused_with_the_reason() {
        let mut track = bending_petal();
        track.keyframes[2].pop();
        let error = track.subdivided(1).expect_err("a short keyframe");
        assert!(
            matches!(
                &error,
                ExportError::InvalidTrack {
                    problem: TrackProblem::KeyframeVertexCount { keyframe: 2, .. },
                    ..
                }
            ),
            "{error}"
        );
        let mut track = bending_petal();
        track.triangles.push(track.triangles[0]);
        let error = track.subdivided(1).expect_err("a repeated triangle");
        assert!(error.to_string().contains("petal"), "{error}");
        let error = bending_petal().subdivided(9).expect_err("too fine");
        assert!(
            error.to_string().contains("choose a lower level"),
            "{error}"
        );
    }
}

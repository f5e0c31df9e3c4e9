//! The default flowers of Anthesis (Ijiri et al. 2008, §6): the Asiatic
//! lily and three cultivars of *Eustoma grandiflorum* grown from one bud,
//! with everything they are made of:
//!
//! - [`buds`]: bud organs shaped around the flower axis ([`buds::RingOrgan`]),
//!   remeshed by `anthesis-bud`;
//! - [`arrangement`]: whorls, contorted whorls and phyllotactic spirals on
//!   the receptacle, with the overlap rules collisions need;
//! - [`paint`]: growth maps painted as functions of UV;
//! - [`flowers`]: the four projects of the paper ([`flowers::lily`],
//!   [`flowers::eustoma`]);
//! - [`apple`]: the apple flower of Qin and Chen 2006 §3–§4, placed
//!   by the seed's own L-system;
//! - [`decay`]: the lily, bloom and decay (negative growth in late keys);
//! - [`edge`]: the lily opened by excess growth at its tepals' margins
//!   (Liang and Mahadevan 2011), `lily-edge`;
//! - [`five_petal`]: the empty starting point, one whorl of five simple
//!   petals with uniform maps;
//! - [`retime`]: the same opening in another number of keyframes (the
//!   time step of a convergence study);
//! - [`shape`]: numeric shape descriptors (opening angles, turning,
//!   cupping, corolla profile) that tests use to check each flower's
//!   character;
//! - [`builtin`]: the committed projects of `assets/flowers/`, embedded in
//!   the binary.
//!
//! The projects under `assets/flowers/` are written by
//! `cargo run -p anthesis-garden --bin make-flowers` and a test checks that
//! they equal what the builders here make.

#![warn(missing_docs)]

pub use anthesis_flower::structure::whorl as arrangement;
pub mod apple;
pub mod buds;
pub mod decay;
pub mod edge;
pub mod five_petal;
pub mod flowers;
pub mod paint;
pub mod parts;
pub mod retime;
pub mod shape;

use std::io;

use anthesis_flower::Project;
use anthesis_flower::project::{ProjectError, parse_project};

pub use flowers::{Cultivar, FLOWER_NAMES, GardenError};

/// The organs of `project`'s flower at `positions` (one list per organ, in
/// the flower's order, as a keyframe holds them) as one mesh, with the
/// organ of each of its triangles: to look for organs passing through
/// each other (`anthesis_bud::self_intersections`).
pub fn flower_mesh(
    project: &Project,
    positions: &[Vec<glam::DVec3>],
) -> (anthesis_mesh::Mesh, Vec<usize>) {
    let mut mesh = anthesis_mesh::Mesh::default();
    let mut organ_of_triangle = Vec::new();
    for (i, organ) in positions.iter().enumerate() {
        let template = &project.flower.template_of(i).mesh;
        let first = mesh.positions.len() as u32;
        mesh.positions.extend(organ);
        mesh.uvs.extend(&template.uvs);
        mesh.triangles
            .extend(template.triangles.iter().map(|t| t.map(|v| v + first)));
        organ_of_triangle.extend(std::iter::repeat_n(i, template.triangles.len()));
    }
    (mesh, organ_of_triangle)
}

/// One embedded file: its path inside its flower's folder and its bytes.
type EmbeddedFile = (&'static str, &'static [u8]);

include!(concat!(env!("OUT_DIR"), "/builtin_files.rs"));

/// The file name of flower `name`'s project inside its folder.
pub fn project_file_name(name: &str) -> String {
    format!("{name}.anthesis.toml")
}

/// The names of the flowers embedded in this build (the folders under
/// `assets/flowers/` when it was compiled).
pub fn builtin_names() -> Vec<&'static str> {
    BUILTIN_FILES.iter().map(|(name, _)| *name).collect()
}

/// The embedded project `name` (e.g. `"lily"`), read from the files that
/// were committed under `assets/flowers/<name>/` when this binary was built;
/// `None` for a name that is not built in. The files are checked by the same
/// rules as any project file.
pub fn builtin(name: &str) -> Option<Result<Project, ProjectError>> {
    let (_, files) = BUILTIN_FILES.iter().find(|(n, _)| *n == name)?;
    let file = |path: &str| -> Option<&'static [u8]> {
        files
            .iter()
            .find(|(p, _)| *p == path)
            .map(|(_, bytes)| *bytes)
    };
    let toml_name = project_file_name(name);
    let Some(toml) = file(&toml_name) else {
        return Some(Err(ProjectError::Io {
            path: toml_name.into(),
            message: "the embedded flower has no project file".to_string(),
        }));
    };
    let text = match std::str::from_utf8(toml) {
        Ok(text) => text,
        Err(_) => {
            return Some(Err(ProjectError::Syntax {
                path: toml_name.into(),
                message: "the file is not UTF-8 text".to_string(),
            }));
        }
    };
    let read = |path: &str| -> Result<Vec<u8>, io::Error> {
        let normalised = path.trim_start_matches("./");
        file(normalised).map(<[u8]>::to_vec).ok_or_else(|| {
            io::Error::new(
                io::ErrorKind::NotFound,
                format!("{path} is not among the embedded files of `{name}`"),
            )
        })
    };
    Some(parse_project(text, &read))
}

/// The embedded Asiatic lily (see [`builtin`]).
pub fn builtin_lily() -> Result<Project, ProjectError> {
    builtin("lily").unwrap_or_else(|| {
        Err(ProjectError::Io {
            path: project_file_name("lily").into(),
            message: "this build has no embedded lily (assets/flowers/lily was missing)"
                .to_string(),
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flower_mesh_holds_every_organ_with_its_triangles_renumbered() {
        let project = match flowers::flower("five-petal") {
            Some(Ok(project)) => project,
            other => panic!("the five-petal flower builds: {:?}", other.map(|r| r.err())),
        };
        let organs = project.flower.organs.len();
        // Each organ moved up by its index, so the mesh's positions say whose they are.
        let positions: Vec<Vec<glam::DVec3>> = (0..organs)
            .map(|i| {
                let mesh = &project.flower.template_of(i).mesh;
                mesh.positions
                    .iter()
                    .map(|p| *p + glam::DVec3::Y * i as f64)
                    .collect()
            })
            .collect();
        let (mesh, organ_of) = flower_mesh(&project, &positions);
        let sizes: Vec<(usize, usize)> = (0..organs)
            .map(|i| {
                let m = &project.flower.template_of(i).mesh;
                (m.vertex_count(), m.triangle_count())
            })
            .collect();
        assert_eq!(
            mesh.positions.len(),
            sizes.iter().map(|s| s.0).sum::<usize>()
        );
        assert_eq!(mesh.uvs.len(), mesh.positions.len());
        assert_eq!(organ_of.len(), mesh.triangles.len());
        let (mut first_vertex, mut first_triangle) = (0, 0);
        for (i, &(vertices, triangles)) in sizes.iter().enumerate() {
            let template = &project.flower.template_of(i).mesh;
            for (k, t) in template.triangles.iter().enumerate() {
                let whole = mesh.triangles[first_triangle + k];
                assert_eq!(whole, t.map(|v| v + first_vertex as u32));
                assert_eq!(organ_of[first_triangle + k], i);
                assert_eq!(
                    mesh.positions[whole[0] as usize],
                    positions[i][t[0] as usize]
                );
            }
            first_vertex += vertices;
            first_triangle += triangles;
        }
    }
}

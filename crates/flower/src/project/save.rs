//! Saving: a [`Project`] into the TOML text and the mesh and map files.

use std::collections::HashSet;
use std::path::Path;

use anthesis_maps::{BitDepth, MapKind, ScalarMap};

use super::check::{SizeCheck, check_project};
use super::error::{ProjectError, map_error};
use super::schema::{
    BaseRegionFile, BlendFile, ColourLayerFile, DirectionEntry, JointRampFile, KeyFile,
    LSystemFile, OrganFile, OverlapFile, ProjectFile, ScalarEntry, SimulationFile, SourceFile,
    SpiralFile, StructureFile, StructureKind, TemplateFile, TwoStateFile, VeinFile, WhorlFile,
};
use super::{FORMAT_NAME, FORMAT_VERSION, MAP_FOLDER, MESH_FOLDER};
use crate::structure::{Arrangement, Structure};
use crate::{Project, Resolution, Template};
use anthesis_twostate::VelocityCurve;

/// The files of a saved project: the TOML text and the meshes and maps, by
/// path relative to the project file.
pub(super) struct SavePlan {
    pub(super) toml: String,
    pub(super) files: Vec<(String, Vec<u8>)>,
}

/// Checks `project` and encodes every file [`save_project`] writes.
/// `folder` is where relative paths are shown from in errors.
pub(super) fn plan_save(
    project: &Project,
    path: &Path,
    folder: &Path,
) -> Result<SavePlan, ProjectError> {
    check_project(project, path)?;
    let flower = &project.flower;
    let mut files = Vec::new();
    let stems = file_stems(flower.templates.iter().map(|t| t.name.as_str()));
    let mut templates = Vec::with_capacity(flower.templates.len());
    for (template, stem) in flower.templates.iter().zip(&stems) {
        templates.push(template_file(template, stem, folder, &mut files)?);
    }
    // Organs and rules the structure makes are saved as the structure.
    let (structure, derived) = structure_file(project, path)?;
    let organs = flower.organs[derived.organs.len()..]
        .iter()
        .map(|organ| OrganFile {
            name: organ.name.clone(),
            template: flower.templates[organ.template].name.clone(),
            position: organ.placement.position.to_array(),
            azimuth_deg: organ.placement.azimuth_deg,
            joint_angle_deg: organ.placement.joint_angle_deg,
            orientation: (organ.placement.orientation != glam::DQuat::IDENTITY)
                .then(|| organ.placement.orientation.to_array()),
        })
        .collect();
    let overlaps = flower
        .overlaps
        .iter()
        .filter(|overlap| !derived.overlaps.contains(overlap))
        .map(|overlap| OverlapFile {
            inner: flower.organs[overlap.inner].name.clone(),
            outer: flower.organs[overlap.outer].name.clone(),
        })
        .collect();
    let file = ProjectFile {
        format: FORMAT_NAME.to_string(),
        version: file_version(project),
        name: project.name.clone(),
        unit: flower.unit.map(|unit| unit.to_string()),
        simulation: SimulationFile::from(&project.settings),
        templates,
        organs,
        overlaps,
        structure,
        parts: flower.parts.iter().map(Into::into).collect(),
    };
    let body = toml::to_string(&file).map_err(|error| ProjectError::Invalid {
        path: path.to_path_buf(),
        message: format!("cannot write the project as TOML: {error}"),
    })?;
    let toml = format!(
        "# Anthesis project. Meshes are OBJ files in {MESH_FOLDER}/, painted maps 16-bit PNG \
         files in {MAP_FOLDER}/.\n{body}"
    );
    Ok(SavePlan { toml, files })
}

/// The format version a file of `project` needs: the oldest that holds
/// everything it sets, so a project that sets nothing new stays readable by
/// older builds and saves byte for byte as before (version 3 added
/// `mean_edge`, version 4 `[structure]` and organ orientations, version 5
/// `[[parts]]`, colour maps, version 6 a key's own `dg`, version 7
/// `[templates.two_state]` and `[templates.source]`, version 8
/// `[templates.vein]` and a sketched or PDE petal's `[templates.source]`,
/// version 9 the project's `unit` and a colour layer's `side`, version 10
/// `lengths_from`).
fn file_version(project: &Project) -> u32 {
    let flower = &project.flower;
    if project.settings.length_base != anthesis_physics::LengthBase::Shape {
        return FORMAT_VERSION;
    }
    let one_sided = |t: &Template| {
        t.colouring
            .as_ref()
            .is_some_and(|c| c.layers.iter().any(|l| l.side != crate::Side::Both))
    };
    if flower.unit.is_some() || flower.templates.iter().any(one_sided) {
        return 9;
    }
    if flower.templates.iter().any(|t| {
        t.vein.is_some()
            || matches!(
                t.source,
                Some(crate::TemplateSource::Sketch { .. } | crate::TemplateSource::Pde { .. })
            )
    }) {
        return 8;
    }
    if flower
        .templates
        .iter()
        .any(|t| t.two_state.is_some() || t.source.is_some())
    {
        return 7;
    }
    let key_dg = flower
        .templates
        .iter()
        .any(|t| t.maps.keys().iter().any(|k| k.dg.is_some()));
    if key_dg {
        return 6;
    }
    if !flower.parts.is_empty() {
        return 5;
    }
    let placed = flower.structure.is_some()
        || flower
            .organs
            .iter()
            .any(|o| o.placement.orientation != glam::DQuat::IDENTITY);
    if flower.templates.iter().any(|t| t.colouring.is_some()) {
        return 5;
    }
    match (placed, project.settings.resolution) {
        (true, _) => 4,
        (false, Resolution::AsBuilt) => 2,
        (false, Resolution::MeanEdge(_)) => 3,
    }
}

/// The file entries of `template`'s colouring (second colour, its map and
/// further layers); adds their raster maps to `files`.
fn colouring_entries(
    template: &Template,
    stem: &str,
    folder: &Path,
    files: &mut Vec<(String, Vec<u8>)>,
) -> Result<ColouringEntries, ProjectError> {
    let Some(colouring) = &template.colouring else {
        return Ok((None, None, Vec::new()));
    };
    let mut layers = Vec::with_capacity(colouring.layers.len());
    for (i, layer) in colouring.layers.iter().enumerate() {
        layers.push(ColourLayerFile {
            colour: layer.colour,
            map: colour_map_entry(
                &layer.mix,
                &format!("{stem}-colour-{}", i + 2),
                folder,
                files,
            )?,
            side: layer.side.into(),
        });
    }
    Ok((
        Some(colouring.second_colour),
        Some(colour_map_entry(
            &colouring.mix,
            &format!("{stem}-colour"),
            folder,
            files,
        )?),
        layers,
    ))
}

/// A template's `second_color`, `colour_map` and `colour_layers` entries.
type ColouringEntries = (Option<[f32; 4]>, Option<ScalarEntry>, Vec<ColourLayerFile>);

/// The file entry of one template; adds its mesh and raster maps to `files`.
pub(super) fn template_file(
    template: &Template,
    stem: &str,
    folder: &Path,
    files: &mut Vec<(String, Vec<u8>)>,
) -> Result<TemplateFile, ProjectError> {
    let mesh_relative = format!("{MESH_FOLDER}/{stem}.obj");
    anthesis_mesh::validate(&template.mesh).map_err(|error| ProjectError::Mesh {
        path: folder.join(&mesh_relative),
        error,
    })?;
    files.push((
        mesh_relative.clone(),
        anthesis_mesh::obj_string(&template.mesh).into_bytes(),
    ));

    let keys = key_files(template, stem, folder, files)?;
    let (second_colour, colour_map, colour_layers) =
        colouring_entries(template, stem, folder, files)?;

    let two_state = two_state_file(template, stem, files);
    let region = &template.base_region;
    Ok(TemplateFile {
        name: template.name.clone(),
        mesh: mesh_relative,
        dg: template.dg,
        thickness: template.thickness,
        stretch_stiffness: template.stretch_stiffness,
        bend_stiffness: template.bend_stiffness,
        colour: template.colour,
        second_colour,
        colour_map,
        colour_layers,
        blend: BlendFile::from(template.maps.blend),
        base_region: BaseRegionFile {
            v_max: region.v_max,
            u_min: region.u_min,
            u_max: region.u_max,
        },
        joint_schedule: template
            .joint_schedule
            .iter()
            .map(JointRampFile::from)
            .collect(),
        two_state,
        source: template.source.as_ref().map(source_file),
        vein: template.vein.as_ref().map(|vein| VeinFile {
            points: vein.points().iter().map(|p| p.to_array()).collect(),
        }),
        keys,
    })
}

/// The map keys' entries: constants as numbers, other maps as 16-bit PNG
/// files added to `files` (all raster maps of one size, values in range).
fn key_files(
    template: &Template,
    stem: &str,
    folder: &Path,
    files: &mut Vec<(String, Vec<u8>)>,
) -> Result<Vec<KeyFile>, ProjectError> {
    let mut size = SizeCheck::default();
    let mut keys = Vec::with_capacity(template.maps.keys().len());
    for key in template.maps.keys() {
        let mut key_file = KeyFile {
            step: key.step,
            dg: key.dg,
            ..KeyFile::default()
        };
        let map_relative =
            |map_name: &str| format!("{MAP_FOLDER}/{stem}-step{}-{map_name}.png", key.step);
        for kind in MapKind::ALL {
            let map = key.maps.scalar(kind);
            let entry = if map.size() == (1, 1) {
                ScalarEntry::Constant(map.values()[0])
            } else {
                let relative = map_relative(kind.name());
                let path = folder.join(&relative);
                size.add(&path, map.size());
                if let Some(value) = map.values().iter().find(|v| !(0.0..=1.0).contains(*v)) {
                    return Err(out_of_range(&path, kind.name(), *value, "0 to 1"));
                }
                let bytes = map
                    .to_png_bytes(BitDepth::Sixteen)
                    .map_err(|error| map_error(&path, error))?;
                files.push((relative.clone(), bytes));
                ScalarEntry::File(relative)
            };
            *key_file.scalar_mut(kind) = Some(entry);
        }
        let direction = &key.maps.direction;
        let entry = if direction.size() == (1, 1) {
            DirectionEntry::Constant(direction.values()[0])
        } else {
            let relative = map_relative(anthesis_maps::DIRECTION_MAP_NAME);
            let path = folder.join(&relative);
            size.add(&path, direction.size());
            let components = direction.values().iter().flatten();
            if let Some(value) = components.into_iter().find(|v| !(-1.0..=1.0).contains(*v)) {
                return Err(out_of_range(&path, "direction", *value, "-1 to 1"));
            }
            let bytes = direction
                .to_png_bytes(BitDepth::Sixteen)
                .map_err(|error| map_error(&path, error))?;
            files.push((relative.clone(), bytes));
            DirectionEntry::File(relative)
        };
        key_file.direction = Some(entry);
        keys.push(key_file);
    }
    size.finish()?;
    Ok(keys)
}

/// The two-state animation's entry, its open shape saved as a mesh added
/// to `files`.
fn two_state_file(
    template: &Template,
    stem: &str,
    files: &mut Vec<(String, Vec<u8>)>,
) -> Option<TwoStateFile> {
    template.two_state.as_ref().map(|animation| {
        // A stem never holds a dot, so no template's files clash with this.
        let open_mesh = format!("{MESH_FOLDER}/{stem}.open.obj");
        files.push((
            open_mesh.clone(),
            anthesis_mesh::obj_string(&animation.open_mesh(&template.mesh)).into_bytes(),
        ));
        TwoStateFile {
            open_mesh,
            g: animation.growth.g,
            duration: animation.growth.duration,
            velocity: match &animation.velocity {
                VelocityCurve::FollowGrowth => None,
                VelocityCurve::Points(points) => Some(points.clone()),
            },
        }
    })
}

/// The entry of the shape a template was made from.
fn source_file(source: &crate::TemplateSource) -> SourceFile {
    match source {
        crate::TemplateSource::Bezier { net, edge } => SourceFile::Bezier {
            net: net.control.iter().flatten().map(|p| p.to_array()).collect(),
            edge: *edge,
        },
        crate::TemplateSource::Sketch { sketch, edge } => {
            let points = |s: &[glam::DVec2]| s.iter().map(|p| p.to_array()).collect();
            SourceFile::Sketch {
                left: points(&sketch.left),
                right: points(&sketch.right),
                vein: points(&sketch.vein),
                sections: sketch.sections.iter().map(|s| points(s)).collect(),
                edge: *edge,
            }
        }
        crate::TemplateSource::Pde { sweep, edge } => {
            let points =
                |c: &anthesis_bud::BezierCurve| c.control.iter().map(|p| p.to_array()).collect();
            SourceFile::Pde {
                margin0: points(&sweep.curve0),
                margin1: points(&sweep.curve1),
                tangent0: points(&sweep.tangent0),
                tangent1: points(&sweep.tangent1),
                stretch_to_bend: sweep.stretch_to_bend(),
                edge: *edge,
            }
        }
    }
}

/// The entry of a colour map saved as `maps/<name>.png` (16-bit, as the
/// growth maps, added to `files`), or a number for a constant.
fn colour_map_entry(
    mix: &ScalarMap,
    name: &str,
    folder: &Path,
    files: &mut Vec<(String, Vec<u8>)>,
) -> Result<ScalarEntry, ProjectError> {
    if mix.size() == (1, 1) {
        return Ok(ScalarEntry::Constant(mix.values()[0]));
    }
    let relative = format!("{MAP_FOLDER}/{name}.png");
    let path = folder.join(&relative);
    if let Some(value) = mix.values().iter().find(|v| !(0.0..=1.0).contains(*v)) {
        return Err(out_of_range(&path, "colour", *value, "0 to 1"));
    }
    let bytes = mix
        .to_png_bytes(BitDepth::Sixteen)
        .map_err(|error| map_error(&path, error))?;
    files.push((relative.clone(), bytes));
    Ok(ScalarEntry::File(relative))
}

pub(super) fn out_of_range(path: &Path, map_name: &str, value: f32, range: &str) -> ProjectError {
    ProjectError::Invalid {
        path: path.to_path_buf(),
        message: format!(
            "the {map_name} map holds {value}, but a PNG map holds values from {range}; \
             the project was not saved"
        ),
    }
}

/// One file-name stem per template: the name in lower case with everything
/// but ASCII letters, digits, `-` and `_` replaced by `_`, made unique by
/// appending `-2`, `-3`, ….
pub(super) fn file_stems<'a>(names: impl Iterator<Item = &'a str>) -> Vec<String> {
    let mut used = HashSet::new();
    names
        .map(|name| {
            let mut base: String = name
                .chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                        c.to_ascii_lowercase()
                    } else {
                        '_'
                    }
                })
                .collect();
            if base.is_empty() {
                base = "template".to_string();
            }
            let mut stem = base.clone();
            let mut number = 2;
            while !used.insert(stem.clone()) {
                stem = format!("{base}-{number}");
                number += 1;
            }
            stem
        })
        .collect()
}

/// Writes one file of a saved project with [`anthesis_files::write_atomic`],
/// creating its folder (the project's folder, `meshes/` or `maps/`) first.
pub(super) fn write_file(path: &Path, bytes: &[u8]) -> Result<(), ProjectError> {
    anthesis_files::create_folder(&anthesis_files::folder_of(path), path)?;
    Ok(anthesis_files::write_atomic(path, bytes)?)
}

/// The `[structure]` entry of `project`, and what it makes (nothing when
/// the project has no structure).
fn structure_file(
    project: &Project,
    path: &Path,
) -> Result<(Option<StructureFile>, Arrangement), ProjectError> {
    let flower = &project.flower;
    let Some(structure) = &flower.structure else {
        return Ok((None, Arrangement::default()));
    };
    let derived = structure
        .arrange(&flower.templates)
        .map_err(|error| ProjectError::Invalid {
            path: path.to_path_buf(),
            message: error.to_string(),
        })?;
    let name = |t: usize| flower.templates[t].name.clone();
    let file = match structure {
        Structure::Whorls { whorls, contorted } => StructureFile {
            kind: StructureKind::Whorls,
            contorted: *contorted,
            whorls: whorls
                .iter()
                .map(|w| WhorlFile {
                    name: w.name.clone(),
                    template: name(w.template),
                    count: w.count,
                    offset_deg: w.offset_deg,
                    radius: w.radius,
                    height: w.height,
                    joint_angle_deg: w.joint_angle_deg,
                    half_span_deg: w.half_span_deg,
                })
                .collect(),
            spiral: None,
            lsystem: None,
        },
        Structure::Spiral(s) => StructureFile {
            kind: StructureKind::Spiral,
            contorted: false,
            whorls: Vec::new(),
            spiral: Some(SpiralFile {
                name: s.name.clone(),
                template: name(s.template),
                count: s.count,
                divergence_deg: s.divergence_deg,
                first_radius: s.first_radius,
                first_height: s.first_height,
                radius_step: s.radius_step,
                height_step: s.height_step,
                joint_angle_deg: s.joint_angle_deg,
                half_span_deg: s.half_span_deg,
            }),
            lsystem: None,
        },
        Structure::LSystem {
            text,
            steps,
            surfaces,
            units,
        } => StructureFile {
            kind: StructureKind::Lsystem,
            contorted: false,
            whorls: Vec::new(),
            spiral: None,
            lsystem: Some(LSystemFile {
                steps: *steps,
                text: text.clone(),
                surfaces: surfaces
                    .iter()
                    .map(|(letter, &t)| (letter.to_string(), name(t)))
                    .collect(),
                units: (*units != 1.0).then_some(*units),
            }),
        },
    };
    Ok((Some(file), derived))
}

#[cfg(test)]
mod tests {
    use std::fs;

    use anthesis_files::WriteError;

    use super::*;

    #[test]
    fn stems_are_file_safe_lower_case_and_unique() {
        let names = ["Petal", "petal", "Outer sepal/2", "", "ünï", "petal-2"];
        let stems = file_stems(names.into_iter());
        assert_eq!(
            stems,
            [
                "petal",
                "petal-2",
                "outer_sepal_2",
                "template",
                "_n_",
                "petal-2-2"
            ]
        );
    }

    #[test]
    fn a_file_is_written_into_a_new_folder_and_leaves_no_temporary() {
        let folder = tempfile::tempdir().expect("temp dir");
        let path = folder.path().join("sub").join("a.txt");
        write_file(&path, b"old").expect("first write");
        write_file(&path, b"new contents").expect("second write");
        assert_eq!(fs::read(&path).expect("read"), b"new contents");
        let entries: Vec<_> = fs::read_dir(folder.path().join("sub"))
            .expect("list")
            .map(|entry| entry.expect("entry").file_name())
            .collect();
        assert_eq!(entries, ["a.txt"]);
    }

    #[test]
    fn a_file_in_place_of_the_folder_is_named() {
        let folder = tempfile::tempdir().expect("temp dir");
        let blocker = folder.path().join("blocker");
        fs::write(&blocker, b"a file, not a folder").expect("write");
        let path = blocker.join("a.txt");
        let error = write_file(&path, b"x").expect_err("parent is a file");
        assert!(
            matches!(&error, ProjectError::Write(WriteError::NotAFolder { folder, .. }) if *folder == blocker),
            "{error:?}"
        );
        assert!(error.to_string().contains("blocker"), "{error}");
    }
}

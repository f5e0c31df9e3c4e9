//! Loading: the TOML text and the files it names into a [`Project`].

use std::collections::HashSet;
use std::io;
use std::path::{Path, PathBuf};

use anthesis_maps::{Blend, DirectionMap, GrowthMaps, KeyedMaps, MapKey, MapKind, ScalarMap};
use anthesis_mesh::{Mesh, MeshError};
use glam::{DVec2, DVec3};

use super::check::{SizeCheck, check_project, check_unique};
use super::error::{ProjectError, io_error, map_error};
use super::schema::{DirectionEntry, ProjectFile, ScalarEntry, TemplateFile};
use super::{FORMAT_NAME, FORMAT_VERSION};
use crate::{
    BaseRegion, Flower, JointRamp, Organ, Overlap, Placement, Project, SimulationSettings, Template,
};

pub(super) struct Loader<'a> {
    /// The project file, for messages.
    pub(super) project_path: &'a Path,
    /// What relative paths are shown relative to in messages.
    pub(super) folder: &'a Path,
    pub(super) files: &'a dyn Fn(&str) -> Result<Vec<u8>, io::Error>,
}

impl Loader<'_> {
    pub(super) fn load(&self, text: &str) -> Result<Project, ProjectError> {
        // The header first, leniently: a newer version may have fields this
        // build does not know, and its error should say so.
        let table: toml::Table = toml::from_str(text).map_err(|error| self.syntax(&error))?;
        check_header(&table, self.project_path)?;
        let file: ProjectFile = toml::from_str(text).map_err(|error| self.syntax(&error))?;
        let project = self.project(file)?;
        check_project(&project, self.project_path)?;
        Ok(project)
    }

    fn syntax(&self, error: &toml::de::Error) -> ProjectError {
        ProjectError::Syntax {
            path: self.project_path.to_path_buf(),
            message: error.to_string().trim_end().to_string(),
        }
    }

    fn invalid(&self, message: String) -> ProjectError {
        ProjectError::Invalid {
            path: self.project_path.to_path_buf(),
            message,
        }
    }

    fn project(&self, file: ProjectFile) -> Result<Project, ProjectError> {
        let path = self.project_path;
        check_unique(
            file.templates.iter().map(|t| t.name.as_str()),
            "template",
            path,
        )?;
        check_unique(file.organs.iter().map(|o| o.name.as_str()), "organ", path)?;
        let templates = file
            .templates
            .into_iter()
            .map(|template| self.template(template))
            .collect::<Result<Vec<_>, _>>()?;
        let organs = file
            .organs
            .iter()
            .map(|organ| {
                let template = templates
                    .iter()
                    .position(|t| t.name == organ.template)
                    .ok_or_else(|| ProjectError::UnknownTemplate {
                        path: path.to_path_buf(),
                        organ: organ.name.clone(),
                        template: organ.template.clone(),
                    })?;
                Ok(Organ {
                    name: organ.name.clone(),
                    template,
                    placement: Placement {
                        position: DVec3::from_array(organ.position),
                        azimuth_deg: organ.azimuth_deg,
                        joint_angle_deg: organ.joint_angle_deg,
                    },
                })
            })
            .collect::<Result<Vec<_>, ProjectError>>()?;
        let organ_index = |name: &str| {
            organs
                .iter()
                .position(|organ| organ.name == name)
                .ok_or_else(|| ProjectError::UnknownOrgan {
                    path: path.to_path_buf(),
                    name: name.to_string(),
                })
        };
        let overlaps = file
            .overlaps
            .iter()
            .map(|overlap| {
                Ok(Overlap {
                    inner: organ_index(&overlap.inner)?,
                    outer: organ_index(&overlap.outer)?,
                })
            })
            .collect::<Result<Vec<_>, ProjectError>>()?;
        Ok(Project {
            name: file.name,
            flower: Flower {
                templates,
                organs,
                overlaps,
            },
            settings: SimulationSettings::from(&file.simulation),
        })
    }

    fn template(&self, file: TemplateFile) -> Result<Template, ProjectError> {
        let name = &file.name;
        if file.keys.is_empty() {
            return Err(self.invalid(format!(
                "template \"{name}\" has no map keys; it needs at least one [[templates.keys]]"
            )));
        }
        let mut steps = HashSet::new();
        if let Some(key) = file.keys.iter().find(|key| !steps.insert(key.step)) {
            return Err(self.invalid(format!(
                "template \"{name}\" has two map keys at step {}; each key needs its own step",
                key.step
            )));
        }
        let mesh = self.mesh(&file.mesh)?;
        let mut size = SizeCheck::default();
        let mut keys = Vec::with_capacity(file.keys.len());
        for mut key in file.keys {
            let mut maps = GrowthMaps::uniform();
            for kind in MapKind::ALL {
                if let Some(entry) = key.scalar_mut(kind).take() {
                    *maps.scalar_mut(kind) = self.scalar_map(entry, &mut size)?;
                }
            }
            if let Some(entry) = key.direction.take() {
                maps.direction = self.direction_map(entry, &mut size)?;
            }
            keys.push(MapKey {
                step: key.step,
                maps,
            });
        }
        let maps = KeyedMaps::new(keys, Blend::from(&file.blend))
            .map_err(|error| self.invalid(format!("template \"{name}\": {error}")))?;
        Ok(Template {
            name: file.name,
            mesh,
            maps,
            dg: file.dg,
            thickness: file.thickness,
            stretch_stiffness: file.stretch_stiffness,
            bend_stiffness: file.bend_stiffness,
            base_region: BaseRegion {
                v_max: file.base_region.v_max,
                u_min: file.base_region.u_min,
                u_max: file.base_region.u_max,
            },
            joint_schedule: file.joint_schedule.iter().map(JointRamp::from).collect(),
            color: file.color,
        })
    }

    /// The bytes of a file named in the project, and the path to show for it.
    fn read(&self, relative: &str) -> Result<(Vec<u8>, PathBuf), ProjectError> {
        let path = self.folder.join(relative);
        match (self.files)(relative) {
            Ok(bytes) => Ok((bytes, path)),
            Err(error) => Err(io_error(&path, "cannot read", &error)),
        }
    }

    fn mesh(&self, relative: &str) -> Result<Mesh, ProjectError> {
        let (bytes, path) = self.read(relative)?;
        let parsed = match String::from_utf8(bytes) {
            Ok(text) => anthesis_mesh::parse_obj(&text),
            Err(_) => Err(MeshError::Io("the file is not UTF-8 text".to_string())),
        };
        parsed.map_err(|error| ProjectError::Mesh { path, error })
    }

    fn scalar_map(
        &self,
        entry: ScalarEntry,
        size: &mut SizeCheck,
    ) -> Result<ScalarMap, ProjectError> {
        match entry {
            ScalarEntry::Constant(value) => Ok(ScalarMap::constant(value)),
            ScalarEntry::File(relative) => {
                let (bytes, path) = self.read(&relative)?;
                let map =
                    ScalarMap::from_png_bytes(&bytes).map_err(|error| map_error(&path, error))?;
                size.check(&path, map.size())?;
                Ok(map)
            }
        }
    }

    fn direction_map(
        &self,
        entry: DirectionEntry,
        size: &mut SizeCheck,
    ) -> Result<DirectionMap, ProjectError> {
        match entry {
            DirectionEntry::Constant([u, v]) => Ok(DirectionMap::constant(DVec2::new(
                f64::from(u),
                f64::from(v),
            ))),
            DirectionEntry::File(relative) => {
                let (bytes, path) = self.read(&relative)?;
                let map = DirectionMap::from_png_bytes(&bytes)
                    .map_err(|error| map_error(&path, error))?;
                size.check(&path, map.size())?;
                Ok(map)
            }
        }
    }
}

/// Checks `format` and `version` in the parsed TOML table.
pub(super) fn check_header(table: &toml::Table, path: &Path) -> Result<(), ProjectError> {
    match table.get("format") {
        Some(toml::Value::String(format)) if format == FORMAT_NAME => {}
        found => {
            return Err(ProjectError::WrongFormat {
                path: path.to_path_buf(),
                found: found.map_or_else(|| "missing".to_string(), |value| value.to_string()),
            });
        }
    }
    let invalid = |message: String| ProjectError::Invalid {
        path: path.to_path_buf(),
        message,
    };
    match table.get("version") {
        Some(toml::Value::Integer(version)) if *version > i64::from(FORMAT_VERSION) => {
            Err(ProjectError::NewerVersion {
                path: path.to_path_buf(),
                found: *version,
                supported: FORMAT_VERSION,
            })
        }
        Some(toml::Value::Integer(version)) if *version >= 1 => Ok(()),
        Some(toml::Value::Integer(version)) => Err(invalid(format!(
            "format version {version} does not exist; versions start at 1"
        ))),
        Some(other) => Err(invalid(format!(
            "`version` must be a whole number, found {other}"
        ))),
        None => Err(invalid(format!(
            "the file has no `version`; write `version = {FORMAT_VERSION}` after `format`"
        ))),
    }
}

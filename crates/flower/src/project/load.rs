//! Loading: the TOML text and the files it names into a [`Project`].

use std::cell::RefCell;
use std::collections::HashSet;
use std::path::{Path, PathBuf};

use anthesis_files::FileError;

use anthesis_maps::{Blend, DirectionMap, GrowthMaps, KeyedMaps, MapKey, MapKind, ScalarMap};
use anthesis_mesh::{Mesh, MeshError};
use glam::{DQuat, DVec2, DVec3};

use super::check::{SizeCheck, check_names, check_project, check_unique};
use super::error::{ProjectError, map_error};
use super::schema::{
    BlendFile, ColourLayerFile, DirectionEntry, KeyFile, OrganFile, OverlapFile, ProjectFile,
    ScalarEntry, SourceFile, StructureFile, StructureKind, TemplateFile, TwoStateFile, VeinFile,
};
use super::{FORMAT_NAME, FORMAT_VERSION};
use crate::structure::{Arrangement, Spiral, Structure, Whorl};
use crate::{
    BaseRegion, ColourLayer, Colouring, Flower, JointRamp, Organ, Overlap, Placement, Project,
    Template, TwoStateAnimation, Unit,
};
use anthesis_twostate::{GrowthFunction, VelocityCurve};

/// The largest project file read, in bytes; a project file names its
/// meshes and maps, so even a garden of templates is a few kilobytes.
pub const MAX_PROJECT_BYTES: u64 = 16 << 20;

/// The longest path a project may name, in characters.
const MAX_PATH_CHARS: usize = 1024;

/// How much of a file's content a message quotes.
const QUOTED_CHARS: usize = 60;

/// What kind of file a project names, for its size limit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum FileKind {
    Mesh,
    Map,
}

impl FileKind {
    pub(super) fn limit(self) -> u64 {
        match self {
            FileKind::Mesh => anthesis_mesh::obj::MAX_OBJ_BYTES,
            FileKind::Map => anthesis_maps::MAX_PNG_BYTES,
        }
    }

    pub(super) fn what(self) -> &'static str {
        match self {
            FileKind::Mesh => "an OBJ mesh",
            FileKind::Map => "a PNG map",
        }
    }
}

/// Reads a file named in a project, given the path as written there.
pub(super) type ReadFile<'a> = &'a dyn Fn(&str, FileKind) -> Result<Vec<u8>, FileError>;

pub(super) struct Loader<'a> {
    /// The project file, for messages.
    pub(super) project_path: &'a Path,
    /// What relative paths are shown relative to in messages.
    pub(super) folder: &'a Path,
    pub(super) files: ReadFile<'a>,
    /// Warnings met on the way (e.g. OBJ statements read past), each
    /// naming its file.
    pub(super) warnings: RefCell<Vec<String>>,
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

    /// `[structure]` with template names resolved; the part its `kind`
    /// names must be there.
    fn structure(
        &self,
        file: &StructureFile,
        templates: &[Template],
    ) -> Result<Structure, ProjectError> {
        let template = |name: &str, what: &str| {
            templates
                .iter()
                .position(|t| t.name == name)
                .ok_or_else(|| {
                    self.invalid(format!(
                    "[structure] {what} uses template \"{name}\", which the project does not have"
                ))
                })
        };
        match file.kind {
            StructureKind::Whorls => {
                if file.whorls.is_empty() {
                    return Err(self.invalid(
                        "[structure] kind = \"whorls\" needs at least one [[structure.whorls]]"
                            .to_owned(),
                    ));
                }
                let whorls = file
                    .whorls
                    .iter()
                    .map(|w| {
                        Ok(Whorl {
                            name: w.name.clone(),
                            template: template(&w.template, &format!("whorl \"{}\"", w.name))?,
                            count: w.count,
                            offset_deg: w.offset_deg,
                            radius: w.radius,
                            height: w.height,
                            joint_angle_deg: w.joint_angle_deg,
                            half_span_deg: w.half_span_deg,
                        })
                    })
                    .collect::<Result<Vec<_>, ProjectError>>()?;
                Ok(Structure::Whorls {
                    whorls,
                    contorted: file.contorted,
                })
            }
            StructureKind::Spiral => {
                let s = file.spiral.as_ref().ok_or_else(|| {
                    self.invalid(
                        "[structure] kind = \"spiral\" needs a [structure.spiral] table".to_owned(),
                    )
                })?;
                Ok(Structure::Spiral(Spiral {
                    name: s.name.clone(),
                    template: template(&s.template, "spiral")?,
                    count: s.count,
                    divergence_deg: s.divergence_deg,
                    first_radius: s.first_radius,
                    first_height: s.first_height,
                    radius_step: s.radius_step,
                    height_step: s.height_step,
                    joint_angle_deg: s.joint_angle_deg,
                    half_span_deg: s.half_span_deg,
                }))
            }
            StructureKind::Lsystem => {
                let l = file.lsystem.as_ref().ok_or_else(|| {
                    self.invalid(
                        "[structure] kind = \"lsystem\" needs a [structure.lsystem] table"
                            .to_owned(),
                    )
                })?;
                let mut surfaces = std::collections::BTreeMap::new();
                for (letter, name) in &l.surfaces {
                    let mut chars = letter.chars();
                    let (Some(c), None) = (chars.next(), chars.next()) else {
                        return Err(self.invalid(format!(
                            "[structure.lsystem.surfaces]: `{letter}` is not one letter"
                        )));
                    };
                    surfaces.insert(c, template(name, &format!("surface `{letter}`"))?);
                }
                let units = l.units.unwrap_or(1.0);
                if !(units.is_finite() && units > 0.0) {
                    return Err(self.invalid(format!(
                        "[structure.lsystem] units must be a positive number, got {units}"
                    )));
                }
                Ok(Structure::LSystem {
                    text: l.text.clone(),
                    steps: l.steps,
                    surfaces,
                    units,
                })
            }
        }
    }

    fn syntax(&self, error: &toml::de::Error) -> ProjectError {
        ProjectError::Syntax {
            path: self.project_path.to_path_buf(),
            message: shorten_lines(error.to_string().trim_end()),
        }
    }

    fn invalid(&self, message: String) -> ProjectError {
        ProjectError::Invalid {
            path: self.project_path.to_path_buf(),
            message,
        }
    }

    /// The project from its parsed file: templates read, the structure's
    /// organs and overlaps derived, the listed ones added after them.
    fn project(&self, file: ProjectFile) -> Result<Project, ProjectError> {
        let path = self.project_path;
        // Names are quoted in the messages below: check them first.
        check_names(
            file.templates.iter().map(|t| t.name.as_str()),
            file.organs.iter().map(|o| o.name.as_str()),
            path,
        )?;
        check_unique(
            file.templates.iter().map(|t| t.name.as_str()),
            "template",
            path,
        )?;
        let templates = file
            .templates
            .into_iter()
            .map(|template| self.template(template))
            .collect::<Result<Vec<_>, _>>()?;
        let structure = match &file.structure {
            Some(structure) => Some(self.structure(structure, &templates)?),
            None => None,
        };
        let derived = match &structure {
            Some(s) => s
                .arrange(&templates)
                .map_err(|error| self.invalid(error.to_string()))?,
            None => Arrangement::default(),
        };
        check_unique(
            derived
                .organs
                .iter()
                .map(|o| o.name.as_str())
                .chain(file.organs.iter().map(|o| o.name.as_str())),
            "organ",
            path,
        )?;
        let mut organs = derived.organs;
        for organ in &file.organs {
            organs.push(self.organ(organ, &templates)?);
        }
        let overlaps = self.overlaps(derived.overlaps, &organs, &file.overlaps)?;
        let parts = file
            .parts
            .iter()
            .map(|part| part.part().map_err(|message| self.invalid(message)))
            .collect::<Result<Vec<_>, _>>()?;
        let unit = self.unit(file.unit.as_deref())?;
        Ok(Project {
            name: file.name,
            flower: Flower {
                templates,
                organs,
                overlaps,
                structure,
                parts,
                unit,
            },
            settings: file.simulation.settings(file.version),
        })
    }

    /// An organ listed in `[[organs]]`: the template it names, and its
    /// placement with the orientation made a unit quaternion.
    fn organ(&self, organ: &OrganFile, templates: &[Template]) -> Result<Organ, ProjectError> {
        let path = self.project_path;
        let template = templates
            .iter()
            .position(|t| t.name == organ.template)
            .ok_or_else(|| ProjectError::UnknownTemplate {
                path: path.to_path_buf(),
                organ: organ.name.clone(),
                template: organ.template.clone(),
            })?;
        let orientation = match organ.orientation {
            None => DQuat::IDENTITY,
            Some(q) => {
                let q = DQuat::from_array(q);
                if !q.is_finite() || q.length() < 1e-9 {
                    return Err(self.invalid(format!(
                        "organ \"{}\": orientation must be a rotation (a non-zero quaternion [x, y, z, w])",
                        organ.name
                    )));
                }
                q.normalize()
            }
        };
        Ok(Organ {
            name: organ.name.clone(),
            template,
            placement: Placement {
                position: DVec3::from_array(organ.position),
                azimuth_deg: organ.azimuth_deg,
                joint_angle_deg: organ.joint_angle_deg,
                orientation,
            },
        })
    }

    /// The overlap rules: the derived ones, then the listed ones, which
    /// override a derived rule for the same pair of organs.
    fn overlaps(
        &self,
        derived: Vec<Overlap>,
        organs: &[Organ],
        listed_files: &[OverlapFile],
    ) -> Result<Vec<Overlap>, ProjectError> {
        let path = self.project_path;
        let organ_index = |name: &str| {
            organs
                .iter()
                .position(|organ| organ.name == name)
                .ok_or_else(|| ProjectError::UnknownOrgan {
                    path: path.to_path_buf(),
                    name: name.to_string(),
                })
        };
        // Listed rules come after the derived ones and override a derived
        // rule for the same pair of organs.
        // Two listed rules for one pair the opposite way round are refused
        // naming both (the later silently won).
        let mut overlaps = derived;
        let mut listed_at: std::collections::HashMap<(usize, usize), usize> = Default::default();
        for (k, overlap) in listed_files.iter().enumerate() {
            let listed = Overlap {
                inner: organ_index(&overlap.inner)?,
                outer: organ_index(&overlap.outer)?,
            };
            if let Some(&earlier) = listed_at.get(&(listed.outer, listed.inner)) {
                return Err(self.invalid(format!(
                    "[[overlaps]] {} puts \"{}\" inside \"{}\", but [[overlaps]] {} puts \"{}\" inside \"{}\"; keep one of them",
                    earlier + 1, overlap.outer, overlap.inner, k + 1, overlap.inner, overlap.outer
                )));
            }
            listed_at.entry((listed.inner, listed.outer)).or_insert(k);
        }
        let mut listed_rules: Vec<(usize, Overlap)> = listed_at
            .iter()
            .map(|(&(inner, outer), &k)| (k, Overlap { inner, outer }))
            .collect();
        listed_rules.sort_by_key(|(k, _)| *k);
        overlaps.retain(|o| !listed_at.contains_key(&(o.outer, o.inner)));
        let made: std::collections::HashSet<(usize, usize)> =
            overlaps.iter().map(|o| (o.inner, o.outer)).collect();
        overlaps.extend(
            listed_rules
                .into_iter()
                .map(|(_, o)| o)
                .filter(|o| !made.contains(&(o.inner, o.outer))),
        );
        Ok(overlaps)
    }

    /// The project's `unit`, if it states one (one that does not keeps the
    /// meaning every project had before units: one unit is one metre in
    /// the exports; see [`crate::unit::unstated_note`]).
    fn unit(&self, text: Option<&str>) -> Result<Option<Unit>, ProjectError> {
        text.map(|text| Unit::parse(text).map_err(|error| self.invalid(format!("unit: {error}"))))
            .transpose()
    }

    /// A template's colouring from its file entries: none, or a second
    /// colour with its map and further layers, each on both sides or one.
    fn colouring(
        &self,
        name: &str,
        second_colour: Option<[f32; 4]>,
        colour_map: Option<ScalarEntry>,
        colour_layers: Vec<ColourLayerFile>,
    ) -> Result<Option<Colouring>, ProjectError> {
        match (second_colour, colour_map) {
            (None, None) if colour_layers.is_empty() => Ok(None),
            (Some(second_colour), Some(entry)) => {
                // Colour maps have sizes of their own (they are not simulated).
                let mix = self.scalar_map(
                    entry,
                    &format!("template \"{name}\": colour_map"),
                    &mut SizeCheck::default(),
                )?;
                let mut layers = Vec::with_capacity(colour_layers.len());
                for (i, layer) in colour_layers.into_iter().enumerate() {
                    layers.push(ColourLayer {
                        colour: layer.colour,
                        mix: self.scalar_map(
                            layer.map,
                            &format!("template \"{name}\": colour layer {}", i + 1),
                            &mut SizeCheck::default(),
                        )?,
                        side: layer.side.into(),
                    });
                }
                Ok(Some(Colouring {
                    second_colour,
                    mix,
                    layers,
                }))
            }
            _ => Err(self.invalid(format!(
                "template \"{name}\" has one of second_color and colour_map (or colour \
                 layers without them); a colour map needs both (the colour it paints, \
                 and where)"
            ))),
        }
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
        let mesh = self.mesh(&file.mesh, name)?;
        let maps = self.keyed_maps(name, file.keys, &file.blend)?;
        let colouring = self.colouring(
            name,
            file.second_colour,
            file.colour_map,
            file.colour_layers,
        )?;
        let two_state = match file.two_state {
            None => None,
            Some(two) => Some(self.two_state(two, &mesh, name)?),
        };
        let source = self.source(name, file.source)?;
        let vein = self.vein(name, file.vein)?;
        let template = Template {
            vein,
            two_state,
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
            colour: file.colour,
            colouring,
            source,
        };
        self.note_uv_layout(&template);
        Ok(template)
    }

    /// A template's map keys: each key's scalar and direction maps read
    /// (all raster maps of one size), blended as the file says.
    fn keyed_maps(
        &self,
        name: &str,
        file_keys: Vec<KeyFile>,
        blend: &BlendFile,
    ) -> Result<KeyedMaps, ProjectError> {
        let mut size = SizeCheck::default();
        let mut keys = Vec::with_capacity(file_keys.len());
        for mut key in file_keys {
            let mut maps = GrowthMaps::uniform();
            let step = key.step;
            let entry_name = |map: &str| format!("template \"{name}\", key {step}: {map}");
            for kind in MapKind::ALL {
                if let Some(entry) = key.scalar_mut(kind).take() {
                    *maps.scalar_mut(kind) =
                        self.scalar_map(entry, &entry_name(kind.name()), &mut size)?;
                }
            }
            if let Some(entry) = key.direction.take() {
                maps.direction = self.direction_map(
                    entry,
                    &entry_name(anthesis_maps::DIRECTION_MAP_NAME),
                    &mut size,
                )?;
            }
            keys.push(MapKey {
                step: key.step,
                maps,
                dg: key.dg,
            });
        }
        size.finish()?;
        KeyedMaps::new(keys, Blend::from(blend))
            .map_err(|error| self.invalid(format!("template \"{name}\": {error}")))
    }

    /// A template's `[templates.source]`, the shape it was made from, if
    /// any: a Bézier net, a sketched petal or a PDE sweep, checked.
    fn source(
        &self,
        name: &str,
        source: Option<SourceFile>,
    ) -> Result<Option<crate::TemplateSource>, ProjectError> {
        let source = match source {
            None => None,
            Some(SourceFile::Bezier { net, edge }) => {
                let points: Vec<glam::DVec3> = net.iter().map(|p| glam::DVec3::from(*p)).collect();
                if points.len() != 16 || !points.iter().all(|p| p.is_finite()) {
                    return Err(self.invalid(format!(
                        "template \"{name}\": a Bézier source's net needs 16 finite points \
                         [x, y, z] (four rows of four, base to tip), found {}",
                        points.len()
                    )));
                }
                if !(edge.is_finite() && edge > 0.0) {
                    return Err(self.invalid(format!(
                        "template \"{name}\": a Bézier source's edge must be a positive number, \
                         found {edge}"
                    )));
                }
                let mut control = [[glam::DVec3::ZERO; 4]; 4];
                for (k, p) in points.into_iter().enumerate() {
                    control[k / 4][k % 4] = p;
                }
                Some(crate::TemplateSource::Bezier {
                    net: anthesis_bud::BezierPatch::new(control),
                    edge,
                })
            }
            Some(SourceFile::Sketch {
                left,
                right,
                vein,
                sections,
                edge,
            }) => Some(self.sketch_source(name, [left, right, vein], sections, edge)?),
            Some(SourceFile::Pde {
                margin0,
                margin1,
                tangent0,
                tangent1,
                stretch_to_bend,
                edge,
            }) => {
                // The checks and messages of `anthesis bud --pde`'s file.
                let sweep = anthesis_bud::formats::pde_sweep(
                    [&margin0, &margin1, &tangent0, &tangent1],
                    stretch_to_bend,
                )
                .map_err(|e| self.invalid(format!("template \"{name}\": a PDE source's {e}")))?;
                if !(edge.is_finite() && edge > 0.0) {
                    return Err(self.invalid(format!(
                        "template \"{name}\": a PDE source's edge must be a positive number, \
                         found {edge}"
                    )));
                }
                Some(crate::TemplateSource::Pde { sweep, edge })
            }
        };
        Ok(source)
    }

    /// A template's `[templates.vein]`, if any.
    fn vein(
        &self,
        name: &str,
        vein: Option<VeinFile>,
    ) -> Result<Option<anthesis_bud::Vein>, ProjectError> {
        let vein = match vein {
            None => None,
            Some(vein) => {
                let points: Vec<glam::DVec2> =
                    vein.points.iter().map(|p| glam::DVec2::from(*p)).collect();
                Some(anthesis_bud::Vein::from_points(&points).map_err(|e| {
                    self.invalid(format!("template \"{name}\": [templates.vein]: {e}"))
                })?)
            }
        };
        Ok(vein)
    }

    /// Warnings for a UV layout from another tool that loads but is read
    /// otherwise than its author meant.
    fn note_uv_layout(&self, template: &Template) {
        let notes = [
            super::check::uv_outside_unit_square(&template.mesh),
            super::check::base_not_at_base(template),
        ];
        for note in notes.into_iter().flatten() {
            self.warnings
                .borrow_mut()
                .push(format!("template \"{}\": {note}", template.name));
        }
    }

    /// A sketched petal's `[templates.source]`: every stroke at least two
    /// finite points, a positive edge, and strokes that make a petal.
    fn sketch_source(
        &self,
        name: &str,
        [left, right, vein]: [Vec<[f64; 2]>; 3],
        sections: Vec<Vec<[f64; 2]>>,
        edge: f64,
    ) -> Result<crate::TemplateSource, ProjectError> {
        let stroke = |points: Vec<[f64; 2]>, what: &str| {
            if points.len() < 2 || !points.iter().flatten().all(|v| v.is_finite()) {
                return Err(self.invalid(format!(
                    "template \"{name}\": a sketch source's {what} needs at least two finite \
                     points [x, y], found {} point(s){}",
                    points.len(),
                    if points.iter().flatten().all(|v| v.is_finite()) {
                        ""
                    } else {
                        " with a number that is not finite"
                    }
                )));
            }
            Ok(points
                .into_iter()
                .map(glam::DVec2::from)
                .collect::<Vec<_>>())
        };
        if !(edge.is_finite() && edge > 0.0) {
            return Err(self.invalid(format!(
                "template \"{name}\": a sketch source's edge must be a positive number, found \
                 {edge}"
            )));
        }
        let sketch = anthesis_bud::PetalSketch {
            left: stroke(left, "left")?,
            right: stroke(right, "right")?,
            vein: stroke(vein, "vein")?,
            sections: sections
                .into_iter()
                .enumerate()
                .map(|(k, s)| stroke(s, &format!("cross-section {}", k + 1)))
                .collect::<Result<_, _>>()?,
        };
        if let Err(e) = sketch.build() {
            return Err(self.invalid(format!(
                "template \"{name}\": its sketch makes no petal: {e}"
            )));
        }
        Ok(crate::TemplateSource::Sketch { sketch, edge })
    }

    /// The bytes of a file named in the project, and the path to show for
    /// it. `entry` says where the project names it, e.g. `template
    /// "petal": mesh`, for a path that is refused.
    fn read(
        &self,
        relative: &str,
        kind: FileKind,
        entry: &str,
    ) -> Result<(Vec<u8>, PathBuf), ProjectError> {
        let refused = |reason: String| {
            self.invalid(format!(
                "{entry} = \"{}\" is refused: {reason}",
                anthesis_files::excerpt(relative, QUOTED_CHARS)
            ))
        };
        if relative.chars().count() > MAX_PATH_CHARS {
            return Err(refused(format!(
                "the path is longer than {MAX_PATH_CHARS} characters"
            )));
        }
        let path = self.folder.join(relative);
        match (self.files)(relative, kind) {
            Ok(bytes) => Ok((bytes, path)),
            Err(
                error @ (FileError::EmptyPath
                | FileError::Absolute
                | FileError::ClimbsOut
                | FileError::LinksOut),
            ) => Err(refused(error.to_string())),
            Err(error) => Err(ProjectError::Io {
                path,
                message: error.to_string(),
            }),
        }
    }

    /// `[templates.two_state]`: its open mesh read and checked against the
    /// template's `bud` (same vertices and triangles), its numbers checked.
    fn two_state(
        &self,
        file: TwoStateFile,
        bud: &Mesh,
        template: &str,
    ) -> Result<TwoStateAnimation, ProjectError> {
        let (open, path) = self.mesh_entry(
            &file.open_mesh,
            &format!("template \"{template}\": two_state.open_mesh"),
        )?;
        let shown = path.display();
        let invalid = |message: String| {
            self.invalid(format!(
                "template \"{template}\": the open shape {shown} {message}"
            ))
        };
        if open.positions.len() != bud.positions.len() {
            return Err(invalid(format!(
                "has {} vertices but the template mesh has {}; it must be the template mesh \
                 moved (same vertices in the same order)",
                open.positions.len(),
                bud.positions.len()
            )));
        }
        if let Some(t) = (0..bud.triangles.len().max(open.triangles.len()))
            .find(|&t| bud.triangles.get(t) != open.triangles.get(t))
        {
            return Err(invalid(format!(
                "differs from the template mesh at triangle {} ({} triangles against {}); it \
                 must have the template mesh's triangles in the same order",
                t + 1,
                open.triangles.len(),
                bud.triangles.len()
            )));
        }
        let velocity = match file.velocity {
            None => VelocityCurve::FollowGrowth,
            Some(points) => VelocityCurve::Points(points),
        };
        Ok(TwoStateAnimation {
            open: open.positions,
            growth: GrowthFunction {
                g: file.g,
                duration: file.duration,
            },
            velocity,
        })
    }

    /// A template's mesh. One whose triangles wind so that its inner side
    /// faces +Z on average loads, with a warning: the winding decides the
    /// inner side, so its organs would bend the other way than the template
    /// frame's (−Z inner) and a mesh from another tool gives no other sign.
    fn mesh(&self, relative: &str, template: &str) -> Result<Mesh, ProjectError> {
        let (mesh, path) = self.mesh_entry(relative, &format!("template \"{template}\": mesh"))?;
        if anthesis_bud::inner_side_faces_minus_z(&mesh) == Some(false) {
            self.warnings.borrow_mut().push(format!(
                "{}: template \"{template}\": the triangles wind so that the inner side faces +Z, \
                 away from the flower's axis (the template frame's inner side is -Z), so its \
                 organs bend the other way; if the petal should open outwards, reverse the \
                 faces' winding (or \"Flip inner side\" in the Flower panel's Shape section)",
                path.display()
            ));
        }
        Ok(mesh)
    }

    /// A mesh named at `entry`, and the path shown for it.
    fn mesh_entry(&self, relative: &str, entry: &str) -> Result<(Mesh, PathBuf), ProjectError> {
        let (bytes, path) = self.read(relative, FileKind::Mesh, entry)?;
        let parsed = match String::from_utf8(bytes) {
            Ok(text) => anthesis_mesh::parse_obj_file(&text),
            Err(_) => Err(MeshError::Io("the file is not UTF-8 text".to_string())),
        };
        let file = parsed.map_err(|error| ProjectError::Mesh {
            path: path.clone(),
            error,
        })?;
        let mut warnings = self.warnings.borrow_mut();
        for warning in file.warnings {
            warnings.push(format!("{}: {warning}", path.display()));
        }
        Ok((file.mesh, path))
    }

    fn scalar_map(
        &self,
        entry: ScalarEntry,
        entry_name: &str,
        size: &mut SizeCheck,
    ) -> Result<ScalarMap, ProjectError> {
        match entry {
            ScalarEntry::Constant(value) => Ok(ScalarMap::constant(value)),
            ScalarEntry::File(relative) => {
                let (bytes, path) = self.read(&relative, FileKind::Map, entry_name)?;
                let map =
                    ScalarMap::from_png_bytes(&bytes).map_err(|error| map_error(&path, error))?;
                size.add(&path, map.size());
                Ok(map)
            }
        }
    }

    fn direction_map(
        &self,
        entry: DirectionEntry,
        entry_name: &str,
        size: &mut SizeCheck,
    ) -> Result<DirectionMap, ProjectError> {
        match entry {
            DirectionEntry::Constant([u, v]) => Ok(DirectionMap::constant(DVec2::new(
                f64::from(u),
                f64::from(v),
            ))),
            DirectionEntry::File(relative) => {
                let (bytes, path) = self.read(&relative, FileKind::Map, entry_name)?;
                let map = DirectionMap::from_png_bytes(&bytes)
                    .map_err(|error| map_error(&path, error))?;
                size.add(&path, map.size());
                Ok(map)
            }
        }
    }
}

/// A TOML reader's message with each line cut to 120 characters and its
/// control characters escaped: it quotes the offending line of the file,
/// which may be anything.
fn shorten_lines(message: &str) -> String {
    message
        .lines()
        .map(|line| {
            if line.chars().count() > 120 || line.chars().any(char::is_control) {
                anthesis_files::excerpt(line, 120)
            } else {
                line.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Checks `format` and `version` in the parsed TOML table.
pub(super) fn check_header(table: &toml::Table, path: &Path) -> Result<(), ProjectError> {
    match table.get("format") {
        Some(toml::Value::String(format)) if format == FORMAT_NAME => {}
        found => {
            return Err(ProjectError::WrongFormat {
                path: path.to_path_buf(),
                found: found.map_or_else(
                    || "missing".to_string(),
                    |value| anthesis_files::excerpt(&value.to_string(), QUOTED_CHARS),
                ),
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
            "`version` must be a whole number, found {}",
            anthesis_files::excerpt(&other.to_string(), QUOTED_CHARS)
        ))),
        None => Err(invalid(format!(
            "the file has no `version`; write `version = {FORMAT_VERSION}` after `format`"
        ))),
    }
}

//! `anthesis._anthesis`: the engine for Python (issue 41).
//!
//! A thin layer over the engine crates that calls the same functions as
//! the `anthesis` command line (`app/src/cli/`), so a run from Python is
//! the same bits as `anthesis simulate`. Arrays go in and come out as
//! numpy arrays; lengths are in the project's units, angles in degrees.
//! The Python package `anthesis` (python/anthesis/) re-exports this module
//! and holds the type stubs.

use std::error::Error as StdError;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use anthesis_export::{Encoding, GlbOptions, Timing, UsdOptions};
use anthesis_flower::{MAX_KEYFRAMES, Project, Resolution};
use anthesis_maps::{DirectionMap, MapKind, ScalarMap};
use anthesis_physics::{BendBase, LengthBase};
use anthesis_sim::crossing::OnCrossing;
use anthesis_sim::memory::KeyframeCost;
use anthesis_sim::{KeyframeStats, Selection, SimError, Simulation};
use glam::DVec3;
use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyArrayDyn, PyArrayMethods};
use pyo3::exceptions::{PyIndexError, PyKeyError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

pyo3::create_exception!(
    _anthesis,
    AnthesisError,
    pyo3::exceptions::PyException,
    "Base class of the errors the engine reports."
);
pyo3::create_exception!(
    _anthesis,
    ProjectError,
    AnthesisError,
    "A project that cannot be loaded, checked or saved (the message names the file)."
);
pyo3::create_exception!(
    _anthesis,
    SimulationError,
    AnthesisError,
    "A run that stopped: a step failed to converge, organs crossed, or too little memory."
);
pyo3::create_exception!(
    _anthesis,
    Cancelled,
    AnthesisError,
    "The run was cancelled through the `cancel` argument of `Project.simulate`."
);
pyo3::create_exception!(
    _anthesis,
    FitError,
    AnthesisError,
    "A fit that could not start or go on (a bad target, a failed simulation)."
);
pyo3::create_exception!(
    _anthesis,
    ExportError,
    AnthesisError,
    "An export (.glb, .usda, .usdc, OBJ folder) that could not be written."
);
pyo3::create_exception!(
    _anthesis,
    RenderError,
    AnthesisError,
    "A picture that could not be rendered (no Vulkan driver, a size too large)."
);

/// `error` and its causes as one line, as the command line prints them
/// (anyhow's `{:#}`).
fn message(error: &dyn StdError) -> String {
    let mut text = error.to_string();
    let mut source = error.source();
    while let Some(cause) = source {
        let cause_text = cause.to_string();
        if !text.contains(&cause_text) {
            text.push_str(": ");
            text.push_str(&cause_text);
        }
        source = cause.source();
    }
    text
}

fn project_error(error: &dyn StdError) -> PyErr {
    ProjectError::new_err(message(error))
}

fn simulation_error(error: &dyn StdError) -> PyErr {
    SimulationError::new_err(message(error))
}

/// The names of the flowers built into this package (`load("builtin:NAME")`).
#[pyfunction]
fn builtins() -> Vec<&'static str> {
    anthesis_garden::builtin_names()
}

/// The map names, in the order the project files list them: six scalar
/// maps and `direction`.
#[pyfunction]
fn map_names() -> Vec<&'static str> {
    MapKind::ALL
        .iter()
        .map(|kind| kind.name())
        .chain(std::iter::once(anthesis_maps::DIRECTION_MAP_NAME))
        .collect()
}

/// Loads a project as `anthesis simulate PROJECT` does: a project file
/// (`*.anthesis.toml`), its folder, or `builtin:NAME`.
#[pyfunction]
fn load(py: Python<'_>, source: &Bound<'_, PyAny>) -> PyResult<PyProject> {
    let text: PathBuf = source.extract().map_err(|_| {
        PyTypeError::new_err("load() takes a path (str or os.PathLike) or \"builtin:NAME\"")
    })?;
    if let Some(name) = text.to_str().and_then(|p| p.strip_prefix("builtin:")) {
        return match anthesis_garden::builtin(name) {
            Some(Ok(project)) => Ok(PyProject {
                project,
                source: format!("builtin:{name}"),
            }),
            Some(Err(error)) => Err(ProjectError::new_err(format!(
                "the built-in flower does not load: {}",
                message(&error)
            ))),
            None => Err(ProjectError::new_err(format!(
                "no built-in flower `{name}` (there are: {})",
                anthesis_garden::builtin_names().join(", ")
            ))),
        };
    }
    let loaded = anthesis_flower::project::load_project_with_warnings(&text).map_err(|error| {
        ProjectError::new_err(format!("cannot open project: {}", message(&error)))
    })?;
    if !loaded.warnings.is_empty() {
        let warnings = py.import("warnings")?;
        for warning in &loaded.warnings {
            warnings.call_method1("warn", (warning.as_str(),))?;
        }
    }
    if let Some(mismatch) = anthesis_flower::scale::check_flower(&loaded.project.flower).first() {
        return Err(ProjectError::new_err(mismatch.to_string()));
    }
    Ok(PyProject {
        project: loaded.project,
        source: text.display().to_string(),
    })
}

/// A float64 numpy array of two dimensions.
type Floats2<'py> = Bound<'py, PyArray2<f64>>;

/// A flower project: its organs, templates, growth maps and parameters.
/// Changes are checked by the rules a project file obeys.
#[pyclass(name = "Project", module = "anthesis")]
#[derive(Clone)]
struct PyProject {
    project: Project,
    source: String,
}

/// A template parameter or simulation setting, by name.
#[derive(Clone, Copy)]
enum Parameter {
    Dg,
    Thickness,
    StretchStiffness,
    BendStiffness,
    Keyframes,
    RelativeTolerance,
    MaxIterations,
    CollisionOffset,
    MeanEdge,
    LengthsFrom,
    BendFrom,
}

const TEMPLATE_PARAMETERS: [(&str, Parameter); 4] = [
    ("dg", Parameter::Dg),
    ("thickness", Parameter::Thickness),
    ("stretch_stiffness", Parameter::StretchStiffness),
    ("bend_stiffness", Parameter::BendStiffness),
];

const SIMULATION_PARAMETERS: [(&str, Parameter); 7] = [
    ("keyframes", Parameter::Keyframes),
    ("relative_tolerance", Parameter::RelativeTolerance),
    ("max_iterations", Parameter::MaxIterations),
    ("collision_offset", Parameter::CollisionOffset),
    ("mean_edge", Parameter::MeanEdge),
    ("lengths_from", Parameter::LengthsFrom),
    ("bend_from", Parameter::BendFrom),
];

/// `lengths_from`'s values, as in the project file's [simulation].
const LENGTHS_FROM: [(&str, LengthBase); 2] =
    [("shape", LengthBase::Shape), ("rest", LengthBase::Rest)];

/// `bend_from`'s values, as in the project file's [simulation].
const BEND_FROM: [(&str, BendBase); 2] = [
    ("dihedral", BendBase::Dihedral),
    ("rest_angle", BendBase::RestAngle),
];

/// The file's name of `value` in `choices`.
fn choice_name<T: PartialEq>(choices: &[(&'static str, T)], value: &T) -> &'static str {
    choices
        .iter()
        .find(|(_, v)| v == value)
        .map_or("", |(name, _)| *name)
}

/// The value `value` (a string) names in `choices`, or a TypeError or
/// ValueError that lists the choices.
fn choice<T: Copy>(name: &str, choices: &[(&str, T)], value: &Bound<'_, PyAny>) -> PyResult<T> {
    let names = choices
        .iter()
        .map(|(n, _)| format!("\"{n}\""))
        .collect::<Vec<_>>()
        .join(" or ");
    let text: String = value
        .extract()
        .map_err(|_| PyTypeError::new_err(format!("`{name}` takes a string: {names}")))?;
    choices
        .iter()
        .find(|(n, _)| *n == text)
        .map(|(_, v)| *v)
        .ok_or_else(|| PyValueError::new_err(format!("`{name}` must be {names}, got \"{text}\"")))
}

fn parameter_names(list: &[(&str, Parameter)]) -> String {
    list.iter()
        .map(|(name, _)| *name)
        .collect::<Vec<_>>()
        .join(", ")
}

impl PyProject {
    fn template_index(&self, template: &str) -> PyResult<usize> {
        let templates = &self.project.flower.templates;
        templates
            .iter()
            .position(|t| t.name == template)
            .ok_or_else(|| {
                let names: Vec<&str> = templates.iter().map(|t| t.name.as_str()).collect();
                PyKeyError::new_err(format!(
                    "no template named `{template}` (templates: {})",
                    names.join(", ")
                ))
            })
    }

    fn key_index(&self, template: usize, key: usize) -> PyResult<usize> {
        let keys = self.project.flower.templates[template].maps.keys().len();
        if key >= keys {
            return Err(PyIndexError::new_err(format!(
                "template `{}` has {keys} map key(s); key {key} does not exist",
                self.project.flower.templates[template].name
            )));
        }
        Ok(key)
    }

    /// Applies `edit` to a copy, checks the copy as a project file is
    /// checked, and keeps it only if it passes.
    fn edit(&mut self, edit: impl FnOnce(&mut Project) -> PyResult<()>) -> PyResult<()> {
        let mut changed = self.project.clone();
        edit(&mut changed)?;
        anthesis_flower::project::check(&changed).map_err(|error| {
            PyValueError::new_err(match &error {
                anthesis_flower::project::ProjectError::Invalid { message, .. } => message.clone(),
                other => message(other),
            })
        })?;
        self.project = changed;
        Ok(())
    }
}

/// `array` as a float64 numpy array (any numeric array-like).
fn as_f64_array<'py>(array: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let numpy = array.py().import("numpy")?;
    let converted = numpy
        .call_method1("asarray", (array, "float64"))
        .map_err(|_| PyTypeError::new_err("expected an array of numbers"))?;
    Ok(converted.cast_into::<PyArrayDyn<f64>>()?)
}

#[pymethods]
impl PyProject {
    /// The project's name.
    #[getter]
    fn name(&self) -> String {
        self.project.name.clone()
    }

    /// Where the project was loaded from (a path or `builtin:NAME`).
    #[getter]
    fn source(&self) -> String {
        self.source.clone()
    }

    /// The organs' names, in project order.
    #[getter]
    fn organs(&self) -> Vec<String> {
        self.project
            .flower
            .organs
            .iter()
            .map(|o| o.name.clone())
            .collect()
    }

    /// The templates' names, in project order.
    #[getter]
    fn templates(&self) -> Vec<String> {
        self.project
            .flower
            .templates
            .iter()
            .map(|t| t.name.clone())
            .collect()
    }

    /// The name of the template organ `organ` is an instance of.
    fn template_of(&self, organ: &str) -> PyResult<String> {
        let flower = &self.project.flower;
        match flower.organ_index(organ) {
            Some(i) => Ok(flower.template_of(i).name.clone()),
            None => Err(PyKeyError::new_err(format!(
                "no organ named `{organ}` (organs: {})",
                self.organs().join(", ")
            ))),
        }
    }

    /// The key steps of a template's maps (one entry per key; most
    /// templates have one key, at step 0).
    fn map_keys(&self, template: &str) -> PyResult<Vec<u32>> {
        let t = self.template_index(template)?;
        Ok(self.project.flower.templates[t]
            .maps
            .keys()
            .iter()
            .map(|k| k.step)
            .collect())
    }

    /// The bud mesh of a template in the template frame: positions
    /// [n, 3] (project units), faces [m, 3] (vertex indices) and UVs [n, 2].
    fn mesh<'py>(
        &self,
        py: Python<'py>,
        template: &str,
    ) -> PyResult<(Floats2<'py>, Bound<'py, PyArray2<u32>>, Floats2<'py>)> {
        let t = self.template_index(template)?;
        let mesh = &self.project.flower.templates[t].mesh;
        Ok((
            points_array(py, &mesh.positions),
            faces_array(py, &mesh.triangles),
            uv_array(py, &mesh.uvs),
        ))
    }

    /// A growth map as a float32 array in image order: `map[row, column]`,
    /// row 0 at the organ's tip (v = 1), the last row at its base (v = 0),
    /// column 0 at u = 0. Scalar maps are [h, w] with values in [0, 1];
    /// `direction` is [h, w, 2] (u and v components in [-1, 1]). A 1x1 map
    /// is a constant.
    #[pyo3(signature = (template, name, key = 0))]
    fn get_map<'py>(
        &self,
        py: Python<'py>,
        template: &str,
        name: &str,
        key: usize,
    ) -> PyResult<Bound<'py, PyAny>> {
        let t = self.template_index(template)?;
        let key = self.key_index(t, key)?;
        let maps = &self.project.flower.templates[t].maps.keys()[key].maps;
        if name == anthesis_maps::DIRECTION_MAP_NAME {
            let raster = &maps.direction;
            let (w, h) = raster.size();
            let values: Vec<f32> = raster.values().iter().flatten().copied().collect();
            let array = Array3::from_shape_vec((h as usize, w as usize, 2), values)
                .map_err(|e| PyValueError::new_err(e.to_string()))?;
            return Ok(array.into_pyarray(py).into_any());
        }
        let kind = map_kind(name)?;
        let raster = maps.scalar(kind);
        let (w, h) = raster.size();
        let array = Array2::from_shape_vec((h as usize, w as usize), raster.values().to_vec())
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok(array.into_pyarray(py).into_any())
    }

    /// Replaces a growth map (see `get_map` for the layout). The array must
    /// be [h, w] ([h, w, 2] for `direction`), of the size of the
    /// template's other maps unless they are all constants (a 1x1 array is
    /// a constant and fits any size); scalar values in [0, 1], direction
    /// components in [-1, 1].
    #[pyo3(signature = (template, name, values, key = 0))]
    fn set_map(
        &mut self,
        template: &str,
        name: &str,
        values: &Bound<'_, PyAny>,
        key: usize,
    ) -> PyResult<()> {
        let t = self.template_index(template)?;
        let key = self.key_index(t, key)?;
        let array = as_f64_array(values)?;
        let readonly = array.readonly();
        let view = readonly.as_array();
        let shape = view.shape().to_vec();
        let direction = name == anthesis_maps::DIRECTION_MAP_NAME;
        let kind = if direction {
            None
        } else {
            Some(map_kind(name)?)
        };
        let wanted = if direction { "[h, w, 2]" } else { "[h, w]" };
        let shape_ok = if direction {
            shape.len() == 3 && shape[2] == 2
        } else {
            shape.len() == 2
        };
        if !shape_ok || shape[0] == 0 || shape[1] == 0 {
            return Err(PyValueError::new_err(format!(
                "map `{name}` must be an array of shape {wanted} with h, w >= 1, got shape {shape:?}"
            )));
        }
        let max_side = anthesis_maps::MAX_MAP_SIDE as usize;
        if shape[0] > max_side || shape[1] > max_side {
            return Err(PyValueError::new_err(format!(
                "map `{name}` is {}x{} pixels; at most {max_side} a side",
                shape[1], shape[0]
            )));
        }
        let (lo, hi) = if direction { (-1.0, 1.0) } else { (0.0, 1.0) };
        if let Some(bad) = view
            .iter()
            .find(|v| !(v.is_finite() && (lo..=hi).contains(*v)))
        {
            return Err(PyValueError::new_err(format!(
                "map `{name}` holds {bad}; its values must lie in [{lo}, {hi}]"
            )));
        }
        let (h, w) = (shape[0] as u32, shape[1] as u32);
        let flat: Vec<f64> = view.iter().copied().collect();
        let template_name = self.project.flower.templates[t].name.clone();
        self.edit(|project| {
            let maps = &mut project.flower.templates[t].maps.keys_mut()[key].maps;
            match kind {
                None => {
                    let pairs = flat.chunks_exact(2).map(|c| [c[0] as f32, c[1] as f32]);
                    maps.direction = DirectionMap::new(w, h, pairs.collect())
                        .map_err(|e| PyValueError::new_err(message(&e)))?;
                }
                Some(kind) => {
                    *maps.scalar_mut(kind) =
                        ScalarMap::new(w, h, flat.iter().map(|v| *v as f32).collect())
                            .map_err(|e| PyValueError::new_err(message(&e)))?;
                }
            }
            let sizes = project.flower.templates[t]
                .maps
                .keys()
                .iter()
                .flat_map(|k| {
                    MapKind::ALL
                        .iter()
                        .map(|&kind| k.maps.scalar(kind).size())
                        .chain(std::iter::once(k.maps.direction.size()))
                        .collect::<Vec<_>>()
                })
                .filter(|size| *size != (1, 1))
                .collect::<Vec<_>>();
            if let Some(other) = sizes.iter().find(|size| **size != (w, h))
                && (w, h) != (1, 1)
            {
                return Err(PyValueError::new_err(format!(
                    "template `{template_name}` has maps of {}x{} pixels (w x h), so map \
                     `{name}` must be [{}, {}] (or [1, 1], a constant), got [{h}, {w}]",
                    other.0, other.1, other.1, other.0
                )));
            }
            Ok(())
        })
    }

    /// The UV coordinates of the pixel centres of a map, as two arrays of
    /// the map's [h, w] shape: `u, v = project.map_grid(...)`, so a map can
    /// be computed as a function of u and v.
    #[pyo3(signature = (template, name, key = 0))]
    fn map_grid<'py>(
        &self,
        py: Python<'py>,
        template: &str,
        name: &str,
        key: usize,
    ) -> PyResult<(Floats2<'py>, Floats2<'py>)> {
        let t = self.template_index(template)?;
        let key = self.key_index(t, key)?;
        let maps = &self.project.flower.templates[t].maps.keys()[key].maps;
        let (w, h) = if name == anthesis_maps::DIRECTION_MAP_NAME {
            maps.direction.size()
        } else {
            maps.scalar(map_kind(name)?).size()
        };
        let mut u = Array2::<f64>::zeros((h as usize, w as usize));
        let mut v = Array2::<f64>::zeros((h as usize, w as usize));
        for y in 0..h {
            for x in 0..w {
                // The crate's convention: u = (x + ½) / w, v = 1 − (y + ½) / h.
                u[(y as usize, x as usize)] = (f64::from(x) + 0.5) / f64::from(w);
                v[(y as usize, x as usize)] = 1.0 - (f64::from(y) + 0.5) / f64::from(h);
            }
        }
        Ok((u.into_pyarray(py), v.into_pyarray(py)))
    }

    /// A parameter: with `template`, one of dg, thickness,
    /// stretch_stiffness, bend_stiffness (as in the project file's
    /// [[templates]]); without, one of keyframes, relative_tolerance,
    /// max_iterations, collision_offset, mean_edge, lengths_from, bend_from
    /// ([simulation]; mean_edge is None for the meshes as built).
    ///
    /// lengths_from is "shape" (the paper's rule: each step grows every
    /// triangle as it is now, so growth the shape could not take is
    /// forgotten) or "rest" (each step grows every triangle's rest triangle,
    /// so the rest state accumulates the growth; builtin:lily-edge);
    /// bend_from is "dihedral" (a hinge's growth adds to its current
    /// dihedral angle) or "rest_angle" (to its rest angle).
    #[pyo3(signature = (name, template = None))]
    fn get_parameter(
        &self,
        py: Python<'_>,
        name: &str,
        template: Option<&str>,
    ) -> PyResult<Py<PyAny>> {
        let parameter = parameter(name, template)?;
        let settings = &self.project.settings;
        let value =
            |v: f64| -> PyResult<Py<PyAny>> { Ok(v.into_pyobject(py)?.into_any().unbind()) };
        match (parameter, template) {
            (Parameter::Keyframes, _) => {
                Ok(settings.keyframes.into_pyobject(py)?.into_any().unbind())
            }
            (Parameter::MaxIterations, _) => Ok(settings
                .solver
                .max_iterations
                .into_pyobject(py)?
                .into_any()
                .unbind()),
            (Parameter::RelativeTolerance, _) => value(settings.solver.relative_tolerance),
            (Parameter::CollisionOffset, _) => value(settings.collision_offset),
            (Parameter::MeanEdge, _) => match settings.resolution.mean_edge() {
                Some(edge) => value(edge),
                None => Ok(py.None()),
            },
            (Parameter::LengthsFrom, _) => Ok(choice_name(&LENGTHS_FROM, &settings.length_base)
                .into_pyobject(py)?
                .into_any()
                .unbind()),
            (Parameter::BendFrom, _) => Ok(choice_name(&BEND_FROM, &settings.bend_base)
                .into_pyobject(py)?
                .into_any()
                .unbind()),
            (p, Some(template)) => {
                let t = &self.project.flower.templates[self.template_index(template)?];
                value(match p {
                    Parameter::Dg => t.dg,
                    Parameter::Thickness => t.thickness,
                    Parameter::StretchStiffness => t.stretch_stiffness,
                    _ => t.bend_stiffness,
                })
            }
            (_, None) => Err(PyValueError::new_err(format!(
                "`{name}` is a template parameter: give template="
            ))),
        }
    }

    /// Sets a parameter (names and values as in `get_parameter`: numbers,
    /// None for mean_edge, strings for lengths_from and bend_from), checked
    /// by the rules of the project file: a ValueError (a value out of range
    /// or not one of the choices) or TypeError (a value of the wrong kind)
    /// says what is wrong and nothing changes.
    #[pyo3(signature = (name, value, template = None))]
    fn set_parameter(
        &mut self,
        name: &str,
        value: &Bound<'_, PyAny>,
        template: Option<&str>,
    ) -> PyResult<()> {
        let parameter = parameter(name, template)?;
        let t = match template {
            Some(template) => Some(self.template_index(template)?),
            None => None,
        };
        let count = |value: &Bound<'_, PyAny>| -> PyResult<u32> {
            let number: f64 = value
                .extract()
                .map_err(|_| PyTypeError::new_err(format!("`{name}` takes a whole number")))?;
            if !(number.fract() == 0.0 && (0.0..=f64::from(u32::MAX)).contains(&number)) {
                return Err(PyValueError::new_err(format!(
                    "`{name}` takes a whole number of 0 or more, got {number}"
                )));
            }
            Ok(number as u32)
        };
        let real = |value: &Bound<'_, PyAny>| -> PyResult<f64> {
            value
                .extract()
                .map_err(|_| PyTypeError::new_err(format!("`{name}` takes a number")))
        };
        match parameter {
            Parameter::Keyframes => {
                let n = count(value)?;
                if n > MAX_KEYFRAMES {
                    return Err(PyValueError::new_err(format!(
                        "keyframes {n} is more than the limit of {MAX_KEYFRAMES}"
                    )));
                }
                self.edit(|p| {
                    p.settings.keyframes = n;
                    Ok(())
                })
            }
            Parameter::MaxIterations => {
                let n = count(value)?;
                self.edit(|p| {
                    p.settings.solver.max_iterations = n;
                    Ok(())
                })
            }
            Parameter::MeanEdge => {
                let resolution = if value.is_none() {
                    Resolution::AsBuilt
                } else {
                    Resolution::MeanEdge(real(value)?)
                };
                self.edit(|p| {
                    p.settings.resolution = resolution;
                    Ok(())
                })
            }
            Parameter::RelativeTolerance => {
                let v = real(value)?;
                self.edit(|p| {
                    p.settings.solver.relative_tolerance = v;
                    Ok(())
                })
            }
            Parameter::CollisionOffset => {
                let v = real(value)?;
                self.edit(|p| {
                    p.settings.collision_offset = v;
                    Ok(())
                })
            }
            Parameter::LengthsFrom => {
                let base = choice(name, &LENGTHS_FROM, value)?;
                self.edit(|p| {
                    p.settings.length_base = base;
                    Ok(())
                })
            }
            Parameter::BendFrom => {
                let base = choice(name, &BEND_FROM, value)?;
                self.edit(|p| {
                    p.settings.bend_base = base;
                    Ok(())
                })
            }
            template_parameter => {
                let v = real(value)?;
                let Some(t) = t else {
                    return Err(PyValueError::new_err(format!(
                        "`{name}` is a template parameter: give template="
                    )));
                };
                self.edit(|p| {
                    let template = &mut p.flower.templates[t];
                    match template_parameter {
                        Parameter::Dg => template.dg = v,
                        Parameter::Thickness => template.thickness = v,
                        Parameter::StretchStiffness => template.stretch_stiffness = v,
                        _ => template.bend_stiffness = v,
                    }
                    Ok(())
                })
            }
        }
    }

    /// Every parameter as a dict: the simulation settings without
    /// `template`, a template's parameters with it.
    #[pyo3(signature = (template = None))]
    fn parameters<'py>(
        &self,
        py: Python<'py>,
        template: Option<&str>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        let list: &[(&str, Parameter)] = match template {
            Some(_) => &TEMPLATE_PARAMETERS,
            None => &SIMULATION_PARAMETERS,
        };
        for (name, _) in list {
            dict.set_item(name, self.get_parameter(py, name, template)?)?;
        }
        Ok(dict)
    }

    /// An independent copy (edits to one do not change the other).
    fn copy(&self) -> PyProject {
        self.clone()
    }

    fn __copy__(&self) -> PyProject {
        self.clone()
    }

    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> PyProject {
        self.clone()
    }

    /// Saves the project as `path` (`*.anthesis.toml`) with its meshes and
    /// PNG maps beside it, as the app saves.
    fn save(&self, path: PathBuf) -> PyResult<()> {
        anthesis_flower::project::save_project(&self.project, &path)
            .map_err(|error| project_error(&error))
    }

    /// Simulates the project as `anthesis simulate` does and returns every
    /// keyframe (0 is the bud). `keyframes` overrides the project's count,
    /// `organ` simulates one organ alone (no collisions). `progress` is
    /// called as progress(keyframe, total) after each keyframe; `cancel` is
    /// a threading.Event (or a callable returning True) polled between
    /// solver iterations: when set the run raises Cancelled. A run that
    /// stops (Cancelled, SimulationError, an error in `progress`) carries
    /// the keyframes computed before the stop as the exception's `result`
    /// attribute. The GIL is released while the engine runs. Same inputs,
    /// same bits.
    #[pyo3(signature = (keyframes = None, organ = None, progress = None, cancel = None, allow_crossings = false))]
    fn simulate(
        &self,
        py: Python<'_>,
        keyframes: Option<u32>,
        organ: Option<&str>,
        progress: Option<Py<PyAny>>,
        cancel: Option<Py<PyAny>>,
        allow_crossings: bool,
    ) -> PyResult<PyRunResult> {
        let mut project = self.project.clone();
        if let Some(n) = keyframes {
            if n == 0 {
                return Err(PyValueError::new_err("keyframes must be at least 1"));
            }
            if n > MAX_KEYFRAMES {
                return Err(PyValueError::new_err(format!(
                    "keyframes {n} is more than the limit of {MAX_KEYFRAMES}"
                )));
            }
            project.settings.keyframes = n;
        }
        let selection = match organ {
            None => Selection::All,
            Some(name) => match project.flower.organ_index(name) {
                Some(i) => Selection::Only(i),
                None => {
                    return Err(PyKeyError::new_err(format!(
                        "no organ named `{name}` (organs: {})",
                        self.organs().join(", ")
                    )));
                }
            },
        };
        let cancel = cancel_function(py, cancel)?;
        let python_error: Mutex<Option<PyErr>> = Mutex::new(None);
        let outcome = py.detach(|| {
            run(
                project,
                selection,
                allow_crossings,
                cancel.as_ref(),
                progress.as_ref(),
                &python_error,
            )
        });
        if let Some(error) = python_error.lock().ok().and_then(|mut e| e.take()) {
            return Err(error);
        }
        match outcome {
            Ok(data) => Ok(PyRunResult {
                data: Arc::new(data),
            }),
            Err(Stopped { error, partial }) => {
                // The keyframes computed before the stop, on the exception.
                if let Some(data) = partial {
                    let result = Py::new(
                        py,
                        PyRunResult {
                            data: Arc::new(*data),
                        },
                    )?;
                    error.value(py).setattr("result", result)?;
                }
                Err(error)
            }
        }
    }

    /// Simulates and writes the run, as `anthesis simulate --out PATH`:
    /// .glb, .usda or .usdc by extension, any other path a folder of one
    /// OBJ per keyframe (see `Result.export`). Returns the run.
    #[pyo3(signature = (path, keyframes = None, organ = None, fps = 24.0, subdivide = 0, normals = true, progress = None, cancel = None))]
    #[allow(clippy::too_many_arguments)]
    fn export(
        &self,
        py: Python<'_>,
        path: PathBuf,
        keyframes: Option<u32>,
        organ: Option<&str>,
        fps: f64,
        subdivide: u32,
        normals: bool,
        progress: Option<Py<PyAny>>,
        cancel: Option<Py<PyAny>>,
    ) -> PyResult<PyRunResult> {
        let result = self.simulate(py, keyframes, organ, progress, cancel, false)?;
        result.export(py, path, fps, subdivide, normals)?;
        Ok(result)
    }

    /// Fits the growth maps of `organ`'s template to a target open shape,
    /// as `anthesis fit` does: `target` is an OBJ whose object named like
    /// the organ (or its only object) is a surface of any triangulation,
    /// in the project's world frame and units (`register=True`: anywhere,
    /// laid on the organ first; `register_scale=True`: in other units
    /// too). Returns the fitted project (this one with the template's maps
    /// replaced; every organ of that template takes them) and a report:
    /// distances as fractions of the organ's length (`rms`, `max`,
    /// `guess_rms`, figured by simulating the fitted project), `reached`,
    /// `stopped`, `iterations`, `simulations`, `seconds`, `verdict`.
    /// `progress(iteration, rms, max)` hears of every iteration; `cancel`
    /// as in `simulate`. The GIL is released while it runs.
    #[pyo3(signature = (organ, target, *, register = false, register_scale = false, flip_inner_side = false, keys = 1, nodes = (3, 4), direction_nodes = (3, 2), max_seconds = 100.0, max_iterations = 30, progress = None, cancel = None))]
    #[allow(clippy::too_many_arguments)]
    fn fit<'py>(
        &self,
        py: Python<'py>,
        organ: &str,
        target: PathBuf,
        register: bool,
        register_scale: bool,
        flip_inner_side: bool,
        keys: u32,
        nodes: (usize, usize),
        direction_nodes: (usize, usize),
        max_seconds: f64,
        max_iterations: u32,
        progress: Option<Py<PyAny>>,
        cancel: Option<Py<PyAny>>,
    ) -> PyResult<(PyProject, Bound<'py, PyDict>)> {
        if !(max_seconds.is_finite() && max_seconds > 0.0) {
            return Err(PyValueError::new_err(format!(
                "max_seconds must be a positive number, got {max_seconds}"
            )));
        }
        if nodes.0 == 0 || nodes.1 == 0 {
            return Err(PyValueError::new_err(
                "nodes needs at least one node each way, e.g. (1, 3)",
            ));
        }
        if keys == 0 {
            return Err(PyValueError::new_err("keys must be at least 1"));
        }
        let Some(organ_index) = self.project.flower.organ_index(organ) else {
            return Err(PyKeyError::new_err(format!(
                "no organ named `{organ}` (organs: {})",
                self.organs().join(", ")
            )));
        };
        if keys > self.project.settings.keyframes + 1 {
            return Err(PyValueError::new_err(format!(
                "keys {keys} is more than the run's {} keyframes and the bud",
                self.project.settings.keyframes
            )));
        }
        let cancel = cancel_function(py, cancel)?;
        let settings = anthesis_fit::FitSettings {
            growth_nodes: anthesis_fit::Grid {
                nodes_u: nodes.0,
                nodes_v: nodes.1,
            },
            direction_nodes: anthesis_fit::Grid {
                nodes_u: direction_nodes.0,
                nodes_v: direction_nodes.1,
            },
            keys,
            max_iterations,
            max_seconds,
            refine_placement: register || register_scale,
            ..anthesis_fit::FitSettings::default()
        };
        let python_error: Mutex<Option<PyErr>> = Mutex::new(None);
        let project = self.project.clone();
        let outcome = py.detach(|| {
            let keep = |error: PyErr| {
                if let Ok(mut slot) = python_error.lock()
                    && slot.is_none()
                {
                    *slot = Some(error);
                }
            };
            let stopped = || python_error.lock().map(|e| e.is_some()).unwrap_or(true);
            let cancelled = || -> bool {
                if stopped() {
                    return true;
                }
                let Some(cancel) = cancel.as_ref() else {
                    return false;
                };
                Python::attach(
                    |py| match cancel.call0(py).and_then(|v| v.bind(py).is_truthy()) {
                        Ok(set) => set,
                        Err(error) => {
                            keep(error);
                            true
                        }
                    },
                )
            };
            let fit_error = |error: &dyn StdError| FitError::new_err(message(error));
            let resolved =
                anthesis_flower::resolution::resolve(&project).map_err(|e| project_error(&e))?;
            let text = anthesis_files::read_regular_text(
                &target,
                anthesis_mesh::obj::MAX_OBJ_BYTES,
                "an OBJ mesh",
            )
            .map_err(|e| {
                FitError::new_err(format!(
                    "cannot read the target {}: {}",
                    target.display(),
                    message(&e)
                ))
            })?;
            let mesh = &resolved.flower.template_of(organ_index).mesh;
            let mut shape = anthesis_fit::read_target(&text, organ, mesh).map_err(|e| {
                FitError::new_err(format!("target {}: {}", target.display(), message(&e)))
            })?;
            if flip_inner_side {
                shape = shape.flipped();
            }
            let registered = if register || register_scale {
                Some(
                    anthesis_fit::register_target(
                        &resolved,
                        organ_index,
                        &shape,
                        register_scale,
                        &cancelled,
                    )
                    .map_err(|e| fit_error(&e))?,
                )
            } else {
                None
            };
            let placement = registered
                .as_ref()
                .map_or(anthesis_fit::Similarity::IDENTITY, |r| {
                    r.registration.placement
                });
            let mut result = anthesis_fit::fit(
                &resolved,
                organ_index,
                &shape,
                placement,
                &settings,
                &mut |p| {
                    if let Some(progress) = progress.as_ref()
                        && let Err(error) = Python::attach(|py| {
                            progress.call1(py, (p.iteration, p.rms, p.max)).map(drop)
                        })
                    {
                        keep(error);
                    }
                },
                &cancelled,
            )
            .map_err(|e| fit_error(&e))?;
            // The project as it was, with the template's maps replaced
            // (they live in UV, so they apply at its own resolution), and
            // the figures of that project simulated, as the command line
            // reports them.
            let mut fitted = project.clone();
            let template = fitted.flower.organs[organ_index].template;
            fitted.flower.templates[template].maps = result.maps.clone();
            let written =
                anthesis_flower::resolution::resolve(&fitted).map_err(|e| project_error(&e))?;
            let final_shape = anthesis_fit::simulate_final(
                &written,
                organ_index,
                written.flower.template_of(organ_index).maps.clone(),
                &cancelled,
            )
            .map_err(|e| simulation_error(&e))?;
            (result.rms, result.max) = anthesis_fit::distances(
                &final_shape,
                &written.flower.template_of(organ_index).mesh.triangles,
                &shape,
                result.placement,
                result.length,
            );
            Ok::<_, PyErr>((fitted, result, registered.map(|r| r.describe())))
        });
        if let Some(error) = python_error.lock().ok().and_then(|mut e| e.take()) {
            return Err(error);
        }
        let (fitted, result, registration) = outcome?;
        let report = PyDict::new(py);
        report.set_item("organ", organ)?;
        report.set_item("organ_length", result.length)?;
        report.set_item("guess_rms", result.guess_rms)?;
        report.set_item("rms", result.rms)?;
        report.set_item("max", result.max)?;
        report.set_item("reached", result.reached())?;
        report.set_item("stopped", result.stop.name())?;
        report.set_item("iterations", result.iterations)?;
        report.set_item("simulations", result.simulations)?;
        report.set_item("seconds", result.seconds)?;
        report.set_item("parameters", result.parameters.len())?;
        report.set_item("registration", registration)?;
        report.set_item("verdict", result.verdict())?;
        Ok((
            PyProject {
                project: fitted,
                source: format!("{} (fitted)", self.source),
            },
            report,
        ))
    }

    fn __repr__(&self) -> String {
        format!(
            "<anthesis.Project '{}' from {}: {} organs, {} templates>",
            self.project.name,
            self.source,
            self.project.flower.organs.len(),
            self.project.flower.templates.len()
        )
    }
}

/// `cancel` as a function to call: a threading.Event's `is_set`, or the
/// callable itself.
fn cancel_function(py: Python<'_>, cancel: Option<Py<PyAny>>) -> PyResult<Option<Py<PyAny>>> {
    let Some(object) = cancel else {
        return Ok(None);
    };
    let bound = object.bind(py);
    if bound.hasattr("is_set")? {
        Ok(Some(bound.getattr("is_set")?.unbind()))
    } else if bound.is_callable() {
        Ok(Some(object))
    } else {
        Err(PyTypeError::new_err(
            "cancel must be a threading.Event or a callable returning a bool",
        ))
    }
}

fn map_kind(name: &str) -> PyResult<MapKind> {
    MapKind::from_name(name).ok_or_else(|| {
        PyKeyError::new_err(format!(
            "no map named `{name}` (maps: {})",
            map_names().join(", ")
        ))
    })
}

fn parameter(name: &str, template: Option<&str>) -> PyResult<Parameter> {
    let (list, other, kind) = match template {
        Some(_) => (
            &TEMPLATE_PARAMETERS[..],
            &SIMULATION_PARAMETERS[..],
            "template parameter",
        ),
        None => (
            &SIMULATION_PARAMETERS[..],
            &TEMPLATE_PARAMETERS[..],
            "simulation setting",
        ),
    };
    if let Some((_, p)) = list.iter().find(|(n, _)| *n == name) {
        return Ok(*p);
    }
    let hint = if other.iter().any(|(n, _)| *n == name) {
        match template {
            Some(_) => format!(" (`{name}` is a simulation setting: leave template out)"),
            None => format!(" (`{name}` is a template parameter: give template=)"),
        }
    } else {
        String::new()
    };
    Err(PyKeyError::new_err(format!(
        "no {kind} named `{name}` ({kind}s: {}){hint}",
        parameter_names(list)
    )))
}

/// A finished run: the project as simulated (at its resolution) and every
/// keyframe.
struct RunData {
    project: Project,
    organs: Vec<usize>,
    /// Keyframe 0 (the bud) first; per keyframe, one position list per
    /// simulated organ.
    frames: Vec<Vec<Vec<DVec3>>>,
    stats: Vec<KeyframeStats>,
}

/// Why a run stopped, and the keyframes computed before (the bud
/// included), kept as the command line keeps them.
struct Stopped {
    error: PyErr,
    partial: Option<Box<RunData>>,
}

impl From<PyErr> for Stopped {
    fn from(error: PyErr) -> Stopped {
        Stopped {
            error,
            partial: None,
        }
    }
}

/// The run of `anthesis simulate` (app/src/cli/simulate.rs): the same
/// checks, the same resolution and the same stepping, with Python's
/// progress and cancellation instead of the terminal's.
fn run(
    project: Project,
    selection: Selection,
    allow_crossings: bool,
    cancel: Option<&Py<PyAny>>,
    progress: Option<&Py<PyAny>>,
    python_error: &Mutex<Option<PyErr>>,
) -> Result<RunData, Stopped> {
    anthesis_sim::memory::check_run(&project, &selection, KeyframeCost::Kept)
        .map_err(|e| simulation_error(&e))?;
    let project = anthesis_flower::resolution::resolve(&project).map_err(|e| project_error(&e))?;
    anthesis_sim::memory::check_run(&project, &selection, KeyframeCost::Kept)
        .map_err(|e| simulation_error(&e))?;
    let mut sim = Simulation::new(&project, &selection).map_err(|e| simulation_error(&e))?;
    if allow_crossings {
        sim.on_crossing(OnCrossing::Warn);
    }
    let keep = |error: PyErr| {
        if let Ok(mut slot) = python_error.lock()
            && slot.is_none()
        {
            *slot = Some(error);
        }
    };
    let cancelled = || -> bool {
        let Some(cancel) = cancel else {
            return false;
        };
        Python::attach(
            |py| match cancel.call0(py).and_then(|v| v.bind(py).is_truthy()) {
                Ok(set) => set,
                Err(error) => {
                    keep(error);
                    true
                }
            },
        )
    };
    let organs = selection.organs(project.flower.organs.len());
    let total = sim.keyframe_count();
    let mut frames = vec![sim.bud().positions_in_world];
    let mut stats = vec![sim.bud().stats];
    let mut failure = None;
    while !sim.finished() {
        let done = frames.len() - 1;
        if cancelled() {
            failure = Some(Cancelled::new_err(format!(
                "cancelled after keyframe {done} of {total}"
            )));
            break;
        }
        let keyframe = match sim.step(&cancelled, &mut |_| {}) {
            Ok(keyframe) => keyframe,
            Err(SimError::Cancelled) => {
                failure = Some(Cancelled::new_err(format!(
                    "cancelled after keyframe {done} of {total}"
                )));
                break;
            }
            Err(error @ SimError::Crossed(_)) => {
                failure = Some(SimulationError::new_err(format!(
                    "the run stopped where organs cross (allow_crossings=True goes on): {}",
                    message(&error)
                )));
                break;
            }
            Err(error) => {
                failure = Some(simulation_error(&error));
                break;
            }
        };
        let index = keyframe.index;
        stats.push(keyframe.stats);
        frames.push(keyframe.positions_in_world);
        if let Some(progress) = progress
            && let Err(error) = Python::attach(|py| progress.call1(py, (index, total)).map(drop))
        {
            failure = Some(error);
            break;
        }
    }
    let data = RunData {
        project,
        organs,
        frames,
        stats,
    };
    match failure {
        None => Ok(data),
        Some(error) => Err(Stopped {
            error,
            partial: Some(Box::new(data)),
        }),
    }
}

fn points_array<'py>(py: Python<'py>, points: &[DVec3]) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = points.iter().flat_map(|p| p.to_array()).collect();
    Array2::from_shape_vec((points.len(), 3), flat)
        .unwrap_or_else(|_| Array2::zeros((0, 3)))
        .into_pyarray(py)
}

fn faces_array<'py>(py: Python<'py>, faces: &[[u32; 3]]) -> Bound<'py, PyArray2<u32>> {
    let flat: Vec<u32> = faces.iter().flatten().copied().collect();
    Array2::from_shape_vec((faces.len(), 3), flat)
        .unwrap_or_else(|_| Array2::zeros((0, 3)))
        .into_pyarray(py)
}

fn uv_array<'py>(py: Python<'py>, uvs: &[glam::DVec2]) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = uvs.iter().flat_map(|p| p.to_array()).collect();
    Array2::from_shape_vec((uvs.len(), 2), flat)
        .unwrap_or_else(|_| Array2::zeros((0, 2)))
        .into_pyarray(py)
}

/// The keyframes of a run. Positions are in the world frame, in the
/// project's units; keyframe 0 is the bud.
#[pyclass(name = "Result", module = "anthesis", frozen)]
struct PyRunResult {
    data: Arc<RunData>,
}

impl PyRunResult {
    /// The position of organ `organ` (a name or an index into `organs`)
    /// among the simulated organs.
    fn slot(&self, organ: &Bound<'_, PyAny>) -> PyResult<usize> {
        let data = &self.data;
        let names: Vec<&str> = data
            .organs
            .iter()
            .map(|&i| data.project.flower.organs[i].name.as_str())
            .collect();
        if let Ok(name) = organ.extract::<String>() {
            return names.iter().position(|n| *n == name).ok_or_else(|| {
                PyKeyError::new_err(format!(
                    "no simulated organ named `{name}` (organs: {})",
                    names.join(", ")
                ))
            });
        }
        let index: usize = organ
            .extract()
            .map_err(|_| PyTypeError::new_err("organ is a name or an index"))?;
        if index >= names.len() {
            return Err(PyIndexError::new_err(format!(
                "organ index {index} is out of range: {} organs were simulated",
                names.len()
            )));
        }
        Ok(index)
    }
}

#[pymethods]
impl PyRunResult {
    /// The simulated organs' names, in the order of the keyframes.
    #[getter]
    fn organs(&self) -> Vec<String> {
        self.data
            .organs
            .iter()
            .map(|&i| self.data.project.flower.organs[i].name.clone())
            .collect()
    }

    /// The number of keyframes computed after the bud.
    #[getter]
    fn keyframes(&self) -> usize {
        self.data.frames.len() - 1
    }

    /// An organ's positions over the run: float64 [keyframes + 1, n, 3],
    /// world frame, project units; [0] is the bud.
    fn positions<'py>(
        &self,
        py: Python<'py>,
        organ: &Bound<'_, PyAny>,
    ) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let slot = self.slot(organ)?;
        let frames = &self.data.frames;
        let n = frames[0][slot].len();
        let flat: Vec<f64> = frames
            .iter()
            .flat_map(|frame| frame[slot].iter().flat_map(|p| p.to_array()))
            .collect();
        let array = Array3::from_shape_vec((frames.len(), n, 3), flat)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok(array.into_pyarray(py))
    }

    /// An organ's triangles: uint32 [m, 3], indices into its positions,
    /// counter-clockwise seen from the outer side.
    fn faces<'py>(
        &self,
        py: Python<'py>,
        organ: &Bound<'_, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let slot = self.slot(organ)?;
        let template = self.data.project.flower.template_of(self.data.organs[slot]);
        Ok(faces_array(py, &template.mesh.triangles))
    }

    /// An organ's UVs: float64 [n, 2] (u across, v from the base to the tip).
    fn uvs<'py>(
        &self,
        py: Python<'py>,
        organ: &Bound<'_, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let slot = self.slot(organ)?;
        let template = self.data.project.flower.template_of(self.data.organs[slot]);
        Ok(uv_array(py, &template.mesh.uvs))
    }

    /// Every measurement of one organ over the run
    /// (`anthesis_sim::measure`, as `anthesis measure` writes them), in
    /// project units: per vertex `mean_curvature`, `gaussian_curvature`
    /// (NaN on the rim), `vertex_stretches` [k + 1, n, 2], `contact` (bool:
    /// within the contact distance of another organ or a part); per
    /// triangle `principal_stretches` [k + 1, m, 2]; per
    /// keyframe the summaries `area`, `mean_curvature_median`,
    /// `mean_curvature_mean`, `gaussian_curvature_median` (also
    /// `median_gaussian`), `gaussian_curvature_mean`,
    /// `stretch_major_mean`, `stretch_minor_mean`, `midrib_length`,
    /// `margin_length`, `contact_area`.
    #[pyo3(signature = (organ, base_v = 0.05, contact_distance = None))]
    fn measures<'py>(
        &self,
        py: Python<'py>,
        organ: &Bound<'_, PyAny>,
        base_v: f64,
        contact_distance: Option<f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        use anthesis_sim::measure::{self as m, OrganLayout};
        let slot = self.slot(organ)?;
        if !(0.0..=1.0).contains(&base_v) {
            return Err(PyValueError::new_err(format!(
                "base_v must be from 0 to 1, got {base_v}"
            )));
        }
        let distance = contact_distance.unwrap_or_else(|| {
            m::default_contact_distance(self.data.project.settings.collision_offset)
        });
        if !(distance >= 0.0 && distance.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "contact_distance must be 0 or more (and finite), got {distance}"
            )));
        }
        let data = Arc::clone(&self.data);
        let measures: Vec<m::OrganMeasure> = py.detach(move || {
            let flower = &data.project.flower;
            let layouts: Vec<OrganLayout> = data
                .organs
                .iter()
                .map(|&i| OrganLayout::with_margin_base(&flower.template_of(i).mesh, base_v))
                .collect();
            // The parts (receptacle, stamens, pistils, stem) at a keyframe.
            let pieces = anthesis_flower::parts::part_pieces(flower);
            let at = |k: usize| -> Vec<Vec<DVec3>> {
                let step = u32::try_from(k).unwrap_or(u32::MAX);
                pieces.iter().map(|p| p.positions_at(step)).collect()
            };
            data.frames
                .iter()
                .enumerate()
                .map(|(frame_index, frame)| {
                    let surfaces: Vec<(&[DVec3], &[[u32; 3]])> = layouts
                        .iter()
                        .zip(frame)
                        .map(|(l, x)| (x.as_slice(), l.triangles()))
                        .collect();
                    let parts_at = at(frame_index);
                    let parts: Vec<m::Surface<'_>> = pieces
                        .iter()
                        .zip(&parts_at)
                        .map(|(p, x)| (x.as_slice(), p.mesh.triangles.as_slice()))
                        .collect();
                    let contact = m::contact_vertices_of(&surfaces, &parts, slot, distance);
                    m::measure_organ(&layouts[slot], &data.frames[0][slot], &frame[slot], contact)
                })
                .collect()
        });
        let k = measures.len();
        let n = measures.first().map_or(0, |f| f.mean_curvature.len());
        let t = measures.first().map_or(0, |f| f.stretches.len());
        let shape_error = |e: numpy::ndarray::ShapeError| PyValueError::new_err(e.to_string());
        let per = |get: &dyn Fn(&m::OrganMeasure) -> Vec<f64>, width: usize| {
            let flat: Vec<f64> = measures.iter().flat_map(get).collect();
            Array2::from_shape_vec((k, width), flat).map_err(shape_error)
        };
        let dict = PyDict::new(py);
        dict.set_item(
            "mean_curvature",
            per(&|f| f.mean_curvature.clone(), n)?.into_pyarray(py),
        )?;
        dict.set_item(
            "gaussian_curvature",
            per(&|f| f.gaussian_curvature.clone(), n)?.into_pyarray(py),
        )?;
        let contact: Vec<bool> = measures.iter().flat_map(|f| f.contact.clone()).collect();
        dict.set_item(
            "contact",
            Array2::from_shape_vec((k, n), contact)
                .map_err(shape_error)?
                .into_pyarray(py),
        )?;
        for (name, width, get) in [
            (
                "principal_stretches",
                t,
                (|f: &m::OrganMeasure| f.stretches.clone())
                    as fn(&m::OrganMeasure) -> Vec<[f64; 2]>,
            ),
            ("vertex_stretches", n, |f| f.vertex_stretches.clone()),
        ] {
            let flat: Vec<f64> = measures
                .iter()
                .flat_map(|f| get(f).into_iter().flatten())
                .collect();
            let array = Array3::from_shape_vec((k, width, 2), flat).map_err(shape_error)?;
            dict.set_item(name, array.into_pyarray(py))?;
        }
        for q in &m::QUANTITIES {
            let values: Vec<f64> = measures.iter().map(|f| (q.get)(&f.summary)).collect();
            dict.set_item(q.name, vector(py, values))?;
        }
        let median: Vec<f64> = measures
            .iter()
            .map(|f| f.summary.gaussian_curvature_median)
            .collect();
        dict.set_item("median_gaussian", vector(py, median))?;
        Ok(dict)
    }

    /// Per keyframe statistics as float64 or int arrays of length
    /// keyframes + 1: energy (total elastic energy), iterations (Newton
    /// iterations), relative_gradient, contact_particles,
    /// pushed_particles, seconds (wall time, the only entry that differs
    /// between runs).
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let stats = &self.data.stats;
        let dict = PyDict::new(py);
        let floats = |f: fn(&KeyframeStats) -> f64| -> Bound<'py, PyArray1<f64>> {
            Array1::from_iter(stats.iter().map(f)).into_pyarray(py)
        };
        let counts = |f: fn(&KeyframeStats) -> u32| -> Bound<'py, PyArray1<u32>> {
            Array1::from_iter(stats.iter().map(f)).into_pyarray(py)
        };
        dict.set_item("energy", floats(|s| s.energy))?;
        dict.set_item("relative_gradient", floats(|s| s.relative_gradient))?;
        dict.set_item("seconds", floats(|s| s.seconds))?;
        dict.set_item("iterations", counts(|s| s.iterations))?;
        dict.set_item("contact_particles", counts(|s| s.contact_particles))?;
        dict.set_item("pushed_particles", counts(|s| s.pushed_particles))?;
        Ok(dict)
    }

    /// Writes the run as `anthesis simulate --out` does, by the path's
    /// extension: .glb (animated glTF), .usda or .usdc (USD layer), any
    /// other path a folder of one OBJ per keyframe (created when missing).
    /// `fps`: keyframes per second of the animation; `subdivide`: levels
    /// of Loop subdivision of the render meshes (0 = as simulated).
    #[pyo3(signature = (path, fps = 24.0, subdivide = 0, normals = true))]
    fn export(
        &self,
        py: Python<'_>,
        path: PathBuf,
        fps: f64,
        subdivide: u32,
        normals: bool,
    ) -> PyResult<()> {
        if !(fps > 0.0 && fps.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "fps must be a positive number, got {fps}"
            )));
        }
        let data = Arc::clone(&self.data);
        py.detach(move || export(&data, &path, fps, subdivide, normals))
    }

    /// Renders keyframe `keyframe` offscreen (wgpu; lavapipe without a
    /// GPU) as the command line's `anthesis render` frames it: uint8
    /// [height, width, 4] RGBA. Organs are drawn in their templates' painted
    /// colour maps (or colours), with the parts that do not grow, as
    /// `anthesis render` draws them.
    #[pyo3(signature = (keyframe = None, width = 640, height = 480, azimuth = 30.0, elevation = 20.0))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        keyframe: Option<usize>,
        width: u32,
        height: u32,
        azimuth: f64,
        elevation: f64,
    ) -> PyResult<Bound<'py, PyArray3<u8>>> {
        let last = self.data.frames.len() - 1;
        let keyframe = keyframe.unwrap_or(last);
        if keyframe > last {
            return Err(PyIndexError::new_err(format!(
                "keyframe {keyframe} is past the end of the run (0 to {last})"
            )));
        }
        if width == 0 || height == 0 {
            return Err(PyValueError::new_err("width and height must be at least 1"));
        }
        if !azimuth.is_finite() || !(-90.0..=90.0).contains(&elevation) {
            return Err(PyValueError::new_err(
                "azimuth must be finite and elevation between -90 and 90 degrees",
            ));
        }
        let data = Arc::clone(&self.data);
        let picture =
            py.detach(move || render(&data, keyframe, width, height, azimuth, elevation))?;
        let array = Array3::from_shape_vec((height as usize, width as usize, 4), picture)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok(array.into_pyarray(py))
    }

    fn __len__(&self) -> usize {
        self.data.frames.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "<anthesis.Result: {} keyframes of {} organ(s)>",
            self.data.frames.len() - 1,
            self.data.organs.len()
        )
    }
}

fn export(data: &RunData, path: &Path, fps: f64, subdivide: u32, normals: bool) -> PyResult<()> {
    let failed = |error: &dyn StdError| {
        ExportError::new_err(format!(
            "cannot write {}: {}",
            path.display(),
            message(error)
        ))
    };
    let tracks = anthesis_export::flower_tracks(
        &data.project.flower,
        &data.organs,
        data.frames.iter().map(Vec::as_slice),
        subdivide,
    )
    .map_err(|e| failed(&e))?;
    let timing = Timing::FramesPerSecond(fps);
    let glb = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    if glb {
        anthesis_files::check_destination(path).map_err(|e| failed(&e))?;
        let options = GlbOptions {
            timing,
            max_morph_targets: anthesis_export::DEFAULT_MAX_MORPH_TARGETS,
            normals,
            encoding: Encoding::Dense,
        };
        options.check(data.frames.len()).map_err(|e| failed(&e))?;
        anthesis_export::write_glb(path, &tracks, &options, &mut |_| {}).map_err(|e| failed(&e))
    } else if anthesis_export::is_usd_path(path) {
        anthesis_export::check_usd_destination(path).map_err(|e| failed(&e))?;
        let options = UsdOptions { timing, normals };
        anthesis_export::write_usd(path, &tracks, &options, &mut |_| {}).map_err(|e| failed(&e))
    } else {
        if path.exists() && !path.is_dir() {
            return Err(ExportError::new_err(format!(
                "{} must be a .glb, .usda or .usdc file or a folder for OBJ files",
                path.display()
            )));
        }
        if !path.is_dir() {
            std::fs::create_dir(path).map_err(|e| failed(&e))?;
        }
        anthesis_export::write_obj_sequence(path, &tracks)
            .map(drop)
            .map_err(|e| failed(&e))
    }
}

fn render(
    data: &RunData,
    keyframe: usize,
    width: u32,
    height: u32,
    azimuth: f64,
    elevation: f64,
) -> PyResult<Vec<u8>> {
    let failed = |error: &dyn StdError| RenderError::new_err(message(error));
    let mut renderer = anthesis_render::OffscreenRenderer::new().map_err(|e| failed(&e))?;
    let max_side = renderer.device().limits().max_texture_dimension_2d;
    if width > max_side || height > max_side {
        return Err(RenderError::new_err(format!(
            "{width}x{height} is too large: this GPU renders at most {max_side} pixels a side"
        )));
    }
    let flower = &data.project.flower;
    // What `anthesis render` draws (app/src/look.rs, app/src/parts.rs):
    // each organ in its template's colour, or white times the template's
    // baked colour map (both sides in an atlas when they differ), and the
    // parts (receptacle, stamens, pistils, stem) at the keyframe.
    let mut organs: Vec<anthesis_render::OrganMesh> = data.frames[keyframe]
        .iter()
        .zip(&data.organs)
        .map(|(positions, &organ)| {
            let template = flower.template_of(organ);
            if template.colouring.is_none() {
                return anthesis_render::OrganMesh::from_positions(
                    positions,
                    &template.mesh.triangles,
                    template.colour,
                );
            }
            let mesh = anthesis_render::OrganMesh::from_positions(
                positions,
                &template.mesh.triangles,
                [1.0; 4],
            );
            let uvs = template
                .mesh
                .uvs
                .iter()
                .map(|uv| uv.as_vec2().to_array())
                .collect();
            let (width, height) = template.colour_image_size();
            if template.is_two_sided() {
                mesh.with_two_sided_texture(uvs, Arc::new(template.colour_atlas(width, height)))
            } else {
                mesh.with_texture(uvs, Arc::new(template.colour_image(width, height)))
            }
        })
        .collect();
    let step = u32::try_from(keyframe).unwrap_or(u32::MAX);
    for piece in anthesis_flower::parts::part_pieces(flower) {
        organs.push(anthesis_render::OrganMesh::from_positions(
            &piece.positions_at(step),
            &piece.mesh.triangles,
            piece.colour,
        ));
    }
    // Framed as `anthesis render --frames KEYFRAME` frames it.
    let Some((lo, hi)) = anthesis_render::organs_bounds_in_world(&organs) else {
        return Err(RenderError::new_err(
            "there is nothing to render: the organs have no vertices",
        ));
    };
    let camera = anthesis_render::Camera::framing(lo, hi, azimuth, elevation);
    let picture = renderer
        .render(&organs, &camera, width, height)
        .map_err(|e| failed(&e))?;
    Ok(picture.into_raw())
}

/// `positions` as points: float64 [n, 3] (measure.py makes it so).
fn points_in(positions: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<DVec3>> {
    let array: numpy::PyReadonlyArray2<f64> = positions
        .extract()
        .map_err(|_| PyValueError::new_err(format!("{what} must be a float64 array [n, 3]")))?;
    let view = array.as_array();
    if view.ncols() != 3 {
        return Err(PyValueError::new_err(format!(
            "{what} must be [n, 3], got {:?}",
            view.shape()
        )));
    }
    Ok(view
        .rows()
        .into_iter()
        .map(|r| DVec3::new(r[0], r[1], r[2]))
        .collect())
}

/// `faces` as triangles of `n` vertices: int64 [m, 3], each index in 0..n.
fn faces_in(faces: &Bound<'_, PyAny>, n: usize) -> PyResult<Vec<[u32; 3]>> {
    let array: numpy::PyReadonlyArray2<i64> = faces
        .extract()
        .map_err(|_| PyValueError::new_err("faces must be an int64 array [m, 3]"))?;
    let view = array.as_array();
    if view.ncols() != 3 {
        return Err(PyValueError::new_err(format!(
            "faces must be [m, 3], got {:?}",
            view.shape()
        )));
    }
    view.rows()
        .into_iter()
        .map(|r| {
            let mut t = [0u32; 3];
            for k in 0..3 {
                t[k] = u32::try_from(r[k])
                    .ok()
                    .filter(|&i| (i as usize) < n)
                    .ok_or_else(|| {
                        PyValueError::new_err(format!(
                            "faces index {} is out of range for {n} vertices",
                            r[k]
                        ))
                    })?;
            }
            Ok(t)
        })
        .collect()
}

/// `uvs` as float64 [n, 2].
fn uvs_in(uvs: &Bound<'_, PyAny>, n: usize) -> PyResult<Vec<glam::DVec2>> {
    let array: numpy::PyReadonlyArray2<f64> = uvs
        .extract()
        .map_err(|_| PyValueError::new_err("uvs must be a float64 array [n, 2]"))?;
    let view = array.as_array();
    if view.ncols() != 2 || view.nrows() != n {
        return Err(PyValueError::new_err(format!(
            "uvs must be [{n}, 2], got {:?}",
            view.shape()
        )));
    }
    Ok(view
        .rows()
        .into_iter()
        .map(|r| glam::DVec2::new(r[0], r[1]))
        .collect())
}

fn vector<'py>(py: Python<'py>, values: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    Array1::from_vec(values).into_pyarray(py)
}

fn pairs<'py>(py: Python<'py>, values: &[[f64; 2]]) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = values.iter().flatten().copied().collect();
    Array2::from_shape_vec((values.len(), 2), flat)
        .unwrap_or_else(|_| Array2::zeros((0, 2)))
        .into_pyarray(py)
}

/// Mean and Gaussian curvature per vertex (H [n], K [n]), NaN on the rim
/// (`anthesis_sim::measure::vertex_curvatures`).
#[pyfunction]
fn measure_curvatures<'py>(
    py: Python<'py>,
    positions: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>)> {
    let x = points_in(positions, "positions")?;
    let f = faces_in(faces, x.len())?;
    let c = py.detach(|| {
        let boundary = anthesis_sim::measure::boundary_vertices(&f, x.len());
        anthesis_sim::measure::vertex_curvatures(&x, &f, &boundary)
    });
    Ok((vector(py, c.mean), vector(py, c.gaussian)))
}

/// Per vertex the angle defect (radians) and the mixed Voronoi area.
#[pyfunction]
fn measure_angle_defects<'py>(
    py: Python<'py>,
    positions: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>)> {
    let x = points_in(positions, "positions")?;
    let f = faces_in(faces, x.len())?;
    let (defect, area) = py.detach(|| anthesis_sim::measure::angle_defects_and_areas(&x, &f));
    Ok((vector(py, defect), vector(py, area)))
}

/// Whether each of `n` vertices lies on an edge of one triangle only.
#[pyfunction]
fn measure_boundary<'py>(
    py: Python<'py>,
    faces: &Bound<'py, PyAny>,
    n: usize,
) -> PyResult<Bound<'py, PyArray1<bool>>> {
    let f = faces_in(faces, n)?;
    Ok(Array1::from_vec(anthesis_sim::measure::boundary_vertices(&f, n)).into_pyarray(py))
}

/// Principal stretches per triangle from `rest` to `current`: [m, 2],
/// largest first.
#[pyfunction]
fn measure_stretches<'py>(
    py: Python<'py>,
    rest: &Bound<'py, PyAny>,
    current: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let x0 = points_in(rest, "rest")?;
    let x1 = points_in(current, "current")?;
    if x0.len() != x1.len() {
        return Err(PyValueError::new_err(format!(
            "rest and current must have as many points, got {} and {}",
            x0.len(),
            x1.len()
        )));
    }
    let f = faces_in(faces, x0.len())?;
    let s = py.detach(|| anthesis_sim::measure::principal_stretches(&x0, &x1, &f));
    Ok(pairs(py, &s))
}

/// The length of the midrib (u = 0.5, v from 0 to 1, `samples` points).
#[pyfunction]
fn measure_midrib(
    py: Python<'_>,
    positions: &Bound<'_, PyAny>,
    faces: &Bound<'_, PyAny>,
    uvs: &Bound<'_, PyAny>,
    samples: usize,
) -> PyResult<f64> {
    let x = points_in(positions, "positions")?;
    let f = faces_in(faces, x.len())?;
    let uv = uvs_in(uvs, x.len())?;
    Ok(py.detach(|| anthesis_sim::measure::UvPath::midrib(&uv, &f, samples).length(&x, &f)))
}

/// The length of the margin: rim edges with an end above v = `base_v`.
#[pyfunction]
fn measure_margin(
    positions: &Bound<'_, PyAny>,
    faces: &Bound<'_, PyAny>,
    uvs: &Bound<'_, PyAny>,
    base_v: f64,
) -> PyResult<f64> {
    let x = points_in(positions, "positions")?;
    let f = faces_in(faces, x.len())?;
    let uv = uvs_in(uvs, x.len())?;
    let edges = anthesis_sim::measure::margin_edges(&uv, &f, base_v);
    Ok(anthesis_sim::measure::edges_length(&x, &edges))
}

/// The engine of Anthesis for Python; use the `anthesis` package.
#[pymodule]
fn _anthesis(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(builtins, m)?)?;
    m.add_function(wrap_pyfunction!(map_names, m)?)?;
    m.add_function(wrap_pyfunction!(measure_curvatures, m)?)?;
    m.add_function(wrap_pyfunction!(measure_angle_defects, m)?)?;
    m.add_function(wrap_pyfunction!(measure_boundary, m)?)?;
    m.add_function(wrap_pyfunction!(measure_stretches, m)?)?;
    m.add_function(wrap_pyfunction!(measure_midrib, m)?)?;
    m.add_function(wrap_pyfunction!(measure_margin, m)?)?;
    m.add_class::<PyProject>()?;
    m.add_class::<PyRunResult>()?;
    m.add("AnthesisError", py.get_type::<AnthesisError>())?;
    m.add("ProjectError", py.get_type::<ProjectError>())?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    m.add("Cancelled", py.get_type::<Cancelled>())?;
    m.add("ExportError", py.get_type::<ExportError>())?;
    m.add("FitError", py.get_type::<FitError>())?;
    m.add("RenderError", py.get_type::<RenderError>())?;
    m.add("MAX_KEYFRAMES", MAX_KEYFRAMES)?;
    Ok(())
}

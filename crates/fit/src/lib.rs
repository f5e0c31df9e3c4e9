//! Growth maps fitted to a target: "which maps make it open like this?"
//!
//! Given a project, one of its organs and a target shape of that organ (its
//! template's vertices in the same order, in world coordinates as
//! `anthesis simulate --out FOLDER/` writes them), [`fit`] finds growth
//! maps (e-growth, w-growth, their inner versions and the growth direction,
//! at one or more time keys) whose growth simulation ends at the target.
//!
//! # Method
//!
//! - **Basis.** Each map is a sum of bilinear hat functions on a coarse
//!   grid of nodes over the UV square (default 3 across × 4 from base to
//!   tip for the four growth maps, 3 × 2 for the direction's angle from
//!   +v), per time key ([`basis`]). The fitted maps are these fields
//!   rasterised at the template's map size and quantised as a 16-bit PNG
//!   stores them, so the saved project simulates to the reported shape.
//! - **First guess** in closed form from the target's stretches and
//!   curvature changes relative to the bud ([`guess`]).
//! - **Optimisation**: Levenberg–Marquardt with box bounds (growth maps in
//!   [0, 1], the angle within ±[`basis::MAX_ANGLE`]) on the residual
//!   *simulated final positions − target positions*, all particles, in the
//!   world frame (the base is attached to the receptacle by the simulation
//!   itself, so no rigid alignment is made). The Jacobian is by forward
//!   forward finite differences (step 0.001), one simulation per
//!   parameter, run in parallel (rayon), on a run of half the keyframes at
//!   twice the growth per step ([`FitSettings::coarse`]: half the cost,
//!   derivatives of a shape 0.6 % of the length from the full run's);
//!   between Jacobians it is kept current by Broyden's rank-one updates
//!   from the full run's residuals, and taken afresh when a step gains
//!   little, if it can end within the time allowed. Each iteration tries
//!   two damping values at once (one per core).
//! - Residuals are always those of the project's own run (its keyframe
//!   count, resolution, solver, parts): the final shape depends on the
//!   number of keyframes, so the result is judged on the full run.

#![warn(missing_docs)]

pub mod basis;
mod dense;
pub mod guess;

use std::time::Instant;

use anthesis_flower::Project;
use anthesis_maps::{KeyedMaps, MapError};
use anthesis_mesh::Mesh;
use anthesis_sim::{Selection, SimError, Simulation};
use glam::DVec3;
use rayon::prelude::*;

pub use basis::{Grid, Layout};

/// How a fit runs.
#[derive(Debug, Clone, PartialEq)]
pub struct FitSettings {
    /// The hat grid of the four growth maps.
    pub growth_nodes: Grid,
    /// The hat grid of the direction's angle (0 × 0: the direction stays
    /// +v, base to tip).
    pub direction_nodes: Grid,
    /// Time keys, spread evenly over the run (1: the same maps throughout).
    pub keys: u32,
    /// Levenberg–Marquardt iterations at most.
    pub max_iterations: u32,
    /// Stop once the RMS distance is below this fraction of the organ's
    /// length.
    pub goal_rms: f64,
    /// Stop starting new iterations after this many seconds, and start no
    /// fresh Jacobian (after the first) that would end later.
    pub max_seconds: f64,
    /// The finite-difference step of a growth map value (the angle's is
    /// the same in radians).
    pub step: f64,
    /// The Jacobian is taken on a run of 1/`coarse` the keyframes with
    /// `coarse` times the growth per step (the joint schedule and the time
    /// keys at 1/`coarse` their steps), when that leaves at least
    /// [`MIN_COARSE_KEYFRAMES`]: about `coarse` times cheaper, and near
    /// enough the full run's derivatives (Eustoma, halved: final shapes
    /// 0.6 % of the length apart). Residuals are always the full run's,
    /// and Broyden's updates carry the Jacobian towards the full run's.
    /// 1: the full run throughout.
    pub coarse: u32,
}

/// The fewest keyframes a coarse Jacobian run may have.
pub const MIN_COARSE_KEYFRAMES: u32 = 20;

impl Default for FitSettings {
    fn default() -> Self {
        FitSettings {
            growth_nodes: Grid {
                nodes_u: 3,
                nodes_v: 4,
            },
            direction_nodes: Grid {
                nodes_u: 3,
                nodes_v: 2,
            },
            keys: 1,
            max_iterations: 30,
            goal_rms: 0.002,
            max_seconds: 50.0,
            step: 0.001,
            coarse: 2,
        }
    }
}

/// Why a fit could not run. A target the bud cannot reach is not an error:
/// the fit returns its best maps and how far they end from the target.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// The organ named does not exist.
    #[error("no organ `{0}` in the project")]
    NoSuchOrgan(String),
    /// The target has another number of vertices than the organ's mesh.
    #[error(
        "the target has {found} vertices but organ `{organ}` has {expected} (at the project's \
         resolution): the target must be this organ's mesh, vertices in the same order, as \
         `anthesis simulate --organ {organ} --out FOLDER/` writes it"
    )]
    VertexCount {
        /// The organ's name.
        organ: String,
        /// Its particles.
        expected: usize,
        /// The target's vertices.
        found: usize,
    },
    /// The target has the organ's vertex count but other triangles.
    #[error(
        "the target's faces are not organ `{organ}`'s triangles: it is another mesh with as many \
         vertices; the target must be this organ's mesh, as `anthesis simulate --organ {organ} \
         --out FOLDER/` writes it"
    )]
    Connectivity {
        /// The organ's name.
        organ: String,
    },
    /// A target coordinate is NaN or infinite.
    #[error("target vertex {vertex} (from 1) has a coordinate that is not a finite number")]
    NotFinite {
        /// The vertex, counted from 1 as in the OBJ file.
        vertex: usize,
    },
    /// The target cannot be read.
    #[error("cannot read the target: {0}")]
    Target(String),
    /// The organ cannot be simulated at all (even without growth).
    #[error(transparent)]
    Simulation(#[from] SimError),
    /// Maps could not be built.
    #[error(transparent)]
    Maps(#[from] MapError),
    /// The caller cancelled the fit.
    #[error("the fit was cancelled")]
    Cancelled,
}

/// Progress of a running fit, reported after each iteration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitProgress {
    /// Iterations done (0: the first guess).
    pub iteration: u32,
    /// RMS distance to the target, as a fraction of the organ's length.
    pub rms: f64,
    /// Largest distance, as a fraction of the organ's length.
    pub max: f64,
    /// Simulations run so far.
    pub simulations: usize,
    /// Seconds since the fit started.
    pub seconds: f64,
}

/// A fit's result: the maps and how close they come.
#[derive(Debug, Clone)]
pub struct Fit {
    /// The fitted maps (stretch and bend as the template had them).
    pub maps: KeyedMaps,
    /// The basis coefficients of the maps.
    pub parameters: Vec<f64>,
    /// The organ's length the distances are fractions of: the largest
    /// distance of a target vertex from the centroid of the target's base
    /// particles.
    pub length: f64,
    /// RMS distance of the closed-form guess's simulation from the target,
    /// as a fraction of the length.
    pub guess_rms: f64,
    /// RMS distance between the fitted maps' final shape and the target,
    /// as a fraction of the length.
    pub rms: f64,
    /// Largest distance, as a fraction of the length.
    pub max: f64,
    /// Levenberg–Marquardt iterations done.
    pub iterations: u32,
    /// Growth simulations run.
    pub simulations: usize,
    /// Wall time in seconds.
    pub seconds: f64,
    /// The final shape of the fitted maps.
    pub shape: Vec<DVec3>,
}

/// The RMS fraction of the length above which a fit is reported as not
/// reaching its target.
pub const REACHED_RMS: f64 = 0.02;

impl Fit {
    /// Whether the fitted shape is within [`REACHED_RMS`] of the target.
    pub fn reached(&self) -> bool {
        self.rms <= REACHED_RMS
    }

    /// A one-line verdict for people: how close the fit came, and when the
    /// target was not reached, that these are the closest maps found.
    pub fn verdict(&self) -> String {
        let figures = format!(
            "RMS {:.2} %, max {:.2} % of the organ's length {:.3} ({} iterations, {} simulations, \
             {:.1} s)",
            100.0 * self.rms,
            100.0 * self.max,
            self.length,
            self.iterations,
            self.simulations,
            self.seconds
        );
        if self.reached() {
            format!("fitted: {figures}")
        } else {
            format!(
                "the bud cannot be grown to this target with these maps: the best fit found ends \
                 at {figures}"
            )
        }
    }
}

/// The target positions of the organ named `name`, whose mesh (at the
/// resolution it is simulated at) is `mesh`, from OBJ text: the object
/// called `name`, or the only object, with as many vertices as the mesh,
/// every coordinate finite, and, if it has faces, the mesh's triangles (in
/// any order, each with its winding).
pub fn read_target(text: &str, name: &str, mesh: &Mesh) -> Result<Vec<DVec3>, FitError> {
    let object = anthesis_mesh::obj::object_text(text, Some(name))
        .or_else(|named| anthesis_mesh::obj::object_text(text, None).map_err(|_| named))
        .map_err(|e| FitError::Target(e.to_string()))?;
    let positions = vertex_lines(&object)?;
    check_target(&positions, name, mesh.vertex_count())?;
    let faces = face_lines(&object)?;
    if !faces.is_empty() && !same_triangles(&faces, &mesh.triangles) {
        return Err(FitError::Connectivity {
            organ: name.to_string(),
        });
    }
    Ok(positions)
}

/// The faces of OBJ text whose face indices count from 1 (as
/// `object_text` renumbers them), as vertex indices from 0.
fn face_lines(text: &str) -> Result<Vec<Vec<u32>>, FitError> {
    let mut faces = Vec::new();
    for (number, line) in text.lines().enumerate() {
        let Some(rest) = line.trim_start().strip_prefix("f ") else {
            continue;
        };
        let corners = rest
            .split_whitespace()
            .map(|corner| {
                corner
                    .split('/')
                    .next()
                    .and_then(|i| i.parse::<u32>().ok())
                    .and_then(|i| i.checked_sub(1))
                    .ok_or_else(|| {
                        FitError::Target(format!("line {}: bad face corner `{corner}`", number + 1))
                    })
            })
            .collect::<Result<Vec<u32>, _>>()?;
        faces.push(corners);
    }
    Ok(faces)
}

/// Whether `faces` are the triangles `triangles`, in any order, each
/// starting at any corner but with the same winding.
fn same_triangles(faces: &[Vec<u32>], triangles: &[[u32; 3]]) -> bool {
    if faces.len() != triangles.len() || faces.iter().any(|f| f.len() != 3) {
        return false;
    }
    let canonical = |t: [u32; 3]| {
        let first = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
        [t[first], t[(first + 1) % 3], t[(first + 2) % 3]]
    };
    let mut a: Vec<[u32; 3]> = faces
        .iter()
        .map(|f| canonical([f[0], f[1], f[2]]))
        .collect();
    let mut b: Vec<[u32; 3]> = triangles.iter().map(|&t| canonical(t)).collect();
    a.sort_unstable();
    b.sort_unstable();
    a == b
}

/// The `v` statements of OBJ text, read here (not by the mesh parser) so
/// that a NaN is named as such.
fn vertex_lines(text: &str) -> Result<Vec<DVec3>, FitError> {
    let mut positions = Vec::new();
    for (number, line) in text.lines().enumerate() {
        let Some(rest) = line.trim_start().strip_prefix("v ") else {
            continue;
        };
        let values: Vec<f64> = rest
            .split_whitespace()
            .take(3)
            .map(|word| word.parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|e| FitError::Target(format!("line {}: {e}", number + 1)))?;
        if values.len() < 3 {
            return Err(FitError::Target(format!(
                "line {}: a vertex needs three coordinates",
                number + 1
            )));
        }
        positions.push(DVec3::new(values[0], values[1], values[2]));
    }
    Ok(positions)
}

/// Checks a target against the organ: vertex count and finite coordinates.
pub fn check_target(target: &[DVec3], name: &str, expected: usize) -> Result<(), FitError> {
    if target.len() != expected {
        return Err(FitError::VertexCount {
            organ: name.to_string(),
            expected,
            found: target.len(),
        });
    }
    if let Some(vertex) = target.iter().position(|p| !p.is_finite()) {
        return Err(FitError::NotFinite { vertex: vertex + 1 });
    }
    Ok(())
}

/// The final positions (world frame) of organ `organ` of `project` with
/// its template's maps replaced by `maps`, simulated alone.
pub fn simulate_final(
    project: &Project,
    organ: usize,
    maps: KeyedMaps,
    cancel: &(dyn Fn() -> bool + Sync),
) -> Result<Vec<DVec3>, SimError> {
    let mut project = project.clone();
    let template = project
        .flower
        .organs
        .get(organ)
        .ok_or(SimError::NoSuchOrgan(organ))?
        .template;
    project.flower.templates[template].maps = maps;
    let mut sim = Simulation::new(&project, &Selection::Only(organ))?;
    let mut last = sim.bud();
    while !sim.finished() {
        last = sim.step(cancel, &mut |_| {})?;
    }
    Ok(last
        .positions_in_world
        .into_iter()
        .next()
        .unwrap_or_default())
}

/// RMS and largest distance between `shape` and `target`, as fractions of
/// `length`.
pub fn distances(shape: &[DVec3], target: &[DVec3], length: f64) -> (f64, f64) {
    let n = shape.len().max(1) as f64;
    let (sum, max) = shape
        .iter()
        .zip(target)
        .map(|(a, b)| a.distance_squared(*b))
        .fold((0.0, 0.0f64), |(s, m), d| (s + d, m.max(d)));
    ((sum / n).sqrt() / length, max.sqrt() / length)
}

/// What a fit works on.
struct Problem<'a> {
    project: &'a Project,
    /// The coarse run the Jacobian is taken on, and its layout (the same
    /// parameters, keys at its steps).
    coarse: Option<(Project, Layout)>,
    organ: usize,
    layout: Layout,
    size: (u32, u32),
    target: &'a [DVec3],
    length: f64,
    cancel: &'a (dyn Fn() -> bool + Sync),
}

impl Problem<'_> {
    fn maps(&self, p: &[f64]) -> Result<KeyedMaps, MapError> {
        let template = self.project.flower.template_of(self.organ);
        self.layout.maps(p, self.size, &template.maps)
    }

    /// The residual of parameters `p`: simulated minus target, x y z per
    /// particle; `None` when the simulation fails (a blow-up counts as a
    /// step too far, not as an error of the fit).
    fn residual(&self, p: &[f64]) -> Result<Option<Vec<f64>>, FitError> {
        self.residual_of(p, false)
    }

    /// [`Problem::residual`] of the full run, or of the coarse run when
    /// `coarse` and there is one.
    fn residual_of(&self, p: &[f64], coarse: bool) -> Result<Option<Vec<f64>>, FitError> {
        let (project, layout) = match &self.coarse {
            Some((project, layout)) if coarse => (project, layout),
            _ => (self.project, &self.layout),
        };
        let template = project.flower.template_of(self.organ);
        let maps = layout.maps(p, self.size, &template.maps)?;
        match simulate_final(project, self.organ, maps, self.cancel) {
            Ok(shape) => Ok(Some(
                shape
                    .iter()
                    .zip(self.target)
                    .flat_map(|(a, b)| (*a - *b).to_array())
                    .collect(),
            )),
            Err(SimError::Cancelled) => Err(FitError::Cancelled),
            Err(_) => Ok(None),
        }
    }

    /// RMS and largest distance of residual `r`, as fractions of the length.
    fn distances(&self, r: &[f64]) -> (f64, f64) {
        let n = (r.len() / 3).max(1) as f64;
        let mut sum = 0.0;
        let mut max = 0.0f64;
        for d in r.chunks_exact(3) {
            let squared = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            sum += squared;
            max = max.max(squared.sqrt());
        }
        ((sum / n).sqrt() / self.length, max / self.length)
    }
}

fn cost(r: &[f64]) -> f64 {
    r.iter().map(|x| x * x).sum()
}

/// Fits the growth maps of organ `organ` of `project` (at the resolution it
/// is simulated at, see `anthesis_flower::resolution::resolve`) to
/// `target`. `progress` hears of every iteration; `cancel` is polled inside
/// the simulations.
pub fn fit(
    project: &Project,
    organ: usize,
    target: &[DVec3],
    settings: &FitSettings,
    progress: &mut dyn FnMut(FitProgress),
    cancel: &(dyn Fn() -> bool + Sync),
) -> Result<Fit, FitError> {
    let started = Instant::now();
    let flower = &project.flower;
    let Some(organ_def) = flower.organs.get(organ) else {
        return Err(FitError::NoSuchOrgan(format!("#{organ}")));
    };
    let template = flower.template_of(organ);
    check_target(target, &organ_def.name, template.mesh.vertex_count())?;
    let topology = anthesis_mesh::validate(&template.mesh).map_err(|error| SimError::BadMesh {
        template: template.name.clone(),
        error,
    })?;
    let bud = Simulation::new(project, &Selection::Only(organ))?.bud();
    let bud_positions = bud
        .positions_in_world
        .into_iter()
        .next()
        .unwrap_or_default();

    let base = template.base_region.particles(&template.mesh);
    let base_centre = if base.is_empty() {
        DVec3::ZERO
    } else {
        base.iter().map(|&b| target[b as usize]).sum::<DVec3>() / base.len() as f64
    };
    let length = target
        .iter()
        .map(|p| p.distance(base_centre))
        .fold(0.0, f64::max)
        .max(1e-12);

    let layout = Layout {
        growth: settings.growth_nodes,
        direction: settings.direction_nodes,
        key_steps: basis::key_steps(settings.keys, project.settings.keyframes),
    };
    let size = template.maps.raster_size().unwrap_or((64, 64));
    let coarse = coarse_run(project, organ, &layout, settings.coarse);
    let problem = Problem {
        project,
        coarse,
        organ,
        layout,
        size,
        target,
        length,
        cancel,
    };
    let mut simulations = 0usize;
    let report = |iteration: u32, r: &[f64], simulations: usize| {
        let (rms, max) = problem.distances(r);
        FitProgress {
            iteration,
            rms,
            max,
            simulations,
            seconds: started.elapsed().as_secs_f64(),
        }
    };

    // The first guess, or no growth when its simulation fails.
    let organ_guess = guess::Organ {
        mesh: &template.mesh,
        topology: &topology,
        bud: &bud_positions,
        dg: template.dg,
        thickness: template.thickness,
        steps: project.settings.keyframes,
    };
    let mut p = guess::guess(&organ_guess, target, &problem.layout);
    simulations += 1;
    let mut r = match problem.residual(&p)? {
        Some(r) => r,
        None => {
            p.iter_mut().for_each(|x| *x = 0.0);
            simulations += 1;
            problem
                .residual(&p)?
                .ok_or_else(|| FitError::Target("the organ cannot be simulated".into()))?
        }
    };
    let guess_rms = problem.distances(&r).0;
    progress(report(0, &r, simulations));

    let n = p.len();
    let rows = r.len();
    let mut jacobian: Option<Vec<f64>> = None; // column-major, rows x n
    let mut fresh = false;
    let mut jacobian_seconds: Option<f64> = None;
    let mut mu = 0.0;
    let mut iterations = 0;
    while iterations < settings.max_iterations
        && problem.distances(&r).0 > settings.goal_rms
        && started.elapsed().as_secs_f64() < settings.max_seconds
    {
        let j = match jacobian.take() {
            Some(j) => j,
            None => {
                // A fresh Jacobian is the dearest part; after the first,
                // only when it can end within the time allowed.
                let elapsed = started.elapsed().as_secs_f64();
                if jacobian_seconds.is_some_and(|s| elapsed + s > settings.max_seconds) {
                    break;
                }
                let (j, runs) = finite_differences(&problem, &p, &r, settings.step)?;
                jacobian_seconds = Some(started.elapsed().as_secs_f64() - elapsed);
                simulations += runs;
                fresh = true;
                j
            }
        };
        // Normal equations.
        let mut jtj = vec![0.0; n * n];
        let mut jtr = vec![0.0; n];
        for a in 0..n {
            let ca = &j[a * rows..(a + 1) * rows];
            jtr[a] = ca.iter().zip(&r).map(|(x, y)| x * y).sum();
            for b in a..n {
                let cb = &j[b * rows..(b + 1) * rows];
                let dot: f64 = ca.iter().zip(cb).map(|(x, y)| x * y).sum();
                jtj[a * n + b] = dot;
                jtj[b * n + a] = dot;
            }
        }
        let max_diag = (0..n).map(|i| jtj[i * n + i]).fold(0.0, f64::max);
        if mu == 0.0 {
            mu = 1e-3;
        }
        let floor = 1e-9 * max_diag.max(1e-300);
        let step_for = |damping: f64| -> Option<Vec<f64>> {
            let mut a = jtj.clone();
            for i in 0..n {
                a[i * n + i] += damping * jtj[i * n + i].max(floor);
            }
            let delta = dense::solve(n, a, jtr.iter().map(|g| -g).collect())?;
            let mut q: Vec<f64> = p.iter().zip(&delta).map(|(a, b)| a + b).collect();
            guess::clamp(&problem.layout, &mut q);
            Some(q)
        };
        let dampings = [mu, 10.0 * mu];
        let candidates: Vec<(f64, Vec<f64>)> = dampings
            .iter()
            .filter_map(|&d| step_for(d).map(|q| (d, q)))
            .collect();
        let tried: Vec<(f64, Vec<f64>, Option<Vec<f64>>)> = candidates
            .into_par_iter()
            .map(|(d, q)| problem.residual(&q).map(|res| (d, q, res)))
            .collect::<Result<_, _>>()?;
        simulations += tried.len();
        let now = cost(&r);
        let best = tried
            .into_iter()
            .filter_map(|(d, q, res)| res.map(|res| (cost(&res), d, q, res)))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        iterations += 1;
        match best {
            Some((c, d, q, res)) if c < now => {
                // Broyden's update of the Jacobian with the step taken.
                let dp: Vec<f64> = q.iter().zip(&p).map(|(a, b)| a - b).collect();
                let dp2: f64 = dp.iter().map(|x| x * x).sum();
                let mut j = j;
                if dp2 > 0.0 {
                    let mut predicted = vec![0.0; rows];
                    for (col, step) in dp.iter().enumerate() {
                        if *step != 0.0 {
                            for (pr, jv) in
                                predicted.iter_mut().zip(&j[col * rows..(col + 1) * rows])
                            {
                                *pr += jv * step;
                            }
                        }
                    }
                    let miss: Vec<f64> = (0..rows).map(|i| res[i] - r[i] - predicted[i]).collect();
                    for (col, step) in dp.iter().enumerate() {
                        if *step != 0.0 {
                            let f = step / dp2;
                            for (jv, m) in j[col * rows..(col + 1) * rows].iter_mut().zip(&miss) {
                                *jv += m * f;
                            }
                        }
                    }
                }
                let gain = 1.0 - c / now;
                mu = if d == mu { mu / 3.0 } else { d };
                p = q;
                r = res;
                // A poor gain on an updated Jacobian: take a fresh one.
                jacobian = if gain < 0.05 && !fresh { None } else { Some(j) };
                fresh = false;
                if gain < 1e-4 && jacobian.is_some() {
                    break;
                }
            }
            _ => {
                mu *= 100.0;
                if fresh {
                    // A fresh Jacobian and still no descent: try harder
                    // damping once more before giving up.
                    if mu > 1e8 {
                        break;
                    }
                    jacobian = Some(j);
                } else {
                    jacobian = None;
                }
            }
        }
        progress(report(iterations, &r, simulations));
    }

    let (rms, max) = problem.distances(&r);
    let maps = problem.maps(&p)?;
    let shape = r
        .chunks_exact(3)
        .zip(target)
        .map(|(d, t)| *t + DVec3::new(d[0], d[1], d[2]))
        .collect();
    Ok(Fit {
        maps,
        parameters: p,
        length,
        guess_rms,
        rms,
        max,
        iterations,
        simulations,
        seconds: started.elapsed().as_secs_f64(),
        shape,
    })
}

/// The Jacobian of the residual at `p` (residual `r`) by forward
/// differences, on the coarse run if there is one, column-major; a column whose step leaves the bounds steps
/// the other way, and one whose simulation fails is left zero. Returns the
/// simulations run.
fn finite_differences(
    problem: &Problem<'_>,
    p: &[f64],
    r: &[f64],
    step: f64,
) -> Result<(Vec<f64>, usize), FitError> {
    let n = p.len();
    let coarse = problem.coarse.is_some();
    // The differences are taken from the run they are made with.
    let base = if coarse {
        problem.residual_of(p, true)?
    } else {
        Some(r.to_vec())
    };
    let Some(base) = base else {
        return Ok((vec![0.0; n * r.len()], 1));
    };
    let columns: Vec<Vec<f64>> = (0..n)
        .into_par_iter()
        .map(|i| {
            let (_, hi) = Layout::bounds(problem.layout.field_of(i));
            let h = if p[i] + step > hi { -step } else { step };
            let mut q = p.to_vec();
            q[i] += h;
            Ok(match problem.residual_of(&q, coarse)? {
                Some(res) => res.iter().zip(&base).map(|(a, b)| (a - b) / h).collect(),
                None => vec![0.0; r.len()],
            })
        })
        .collect::<Result<_, FitError>>()?;
    Ok((columns.concat(), n + usize::from(coarse)))
}

/// The coarse run of `project` for the Jacobian (see
/// [`FitSettings::coarse`]): `None` when `factor` is 1 or would leave too
/// few keyframes.
fn coarse_run(
    project: &Project,
    organ: usize,
    layout: &Layout,
    factor: u32,
) -> Option<(Project, Layout)> {
    let keyframes = project.settings.keyframes;
    if factor <= 1 || keyframes / factor < MIN_COARSE_KEYFRAMES {
        return None;
    }
    let shrink = |step: u32| (f64::from(step) / f64::from(factor)).round() as u32;
    let mut coarse = project.clone();
    coarse.settings.keyframes = keyframes / factor;
    let index = coarse.flower.organs[organ].template;
    let template = &mut coarse.flower.templates[index];
    template.dg *= f64::from(factor);
    for ramp in &mut template.joint_schedule {
        ramp.from_step = shrink(ramp.from_step);
        ramp.to_step = shrink(ramp.to_step);
    }
    // The template's own keys only lend their stiffness maps; keys that
    // would share a step keep the first.
    let mut keys = template.maps.keys().to_vec();
    for key in &mut keys {
        key.step = shrink(key.step);
    }
    keys.dedup_by_key(|key| key.step);
    template.maps = KeyedMaps::new(keys, template.maps.blend).ok()?;
    let mut steps: Vec<u32> = layout.key_steps.iter().map(|&s| shrink(s)).collect();
    steps.dedup();
    if steps.len() != layout.key_steps.len() {
        return None;
    }
    let layout = Layout {
        key_steps: steps,
        ..layout.clone()
    };
    Some((coarse, layout))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The gradient of the fit's cost, `2 Jᵀ r` with the Jacobian the fit
    /// uses (forward differences on the coarse run), against central
    /// differences of the cost of the full run (issue 15 item 6).
    #[test]
    fn the_fits_gradient_agrees_with_central_differences_of_the_full_run() {
        let keyframes = 40;
        let mut project = anthesis_sim::fixtures::whorl(1, 6, 10, keyframes);
        project.flower.templates[0].dg = 0.01;
        let layout = Layout {
            growth: Grid {
                nodes_u: 1,
                nodes_v: 2,
            },
            direction: Grid {
                nodes_u: 0,
                nodes_v: 0,
            },
            key_steps: basis::key_steps(1, keyframes),
        };
        let size = (32, 32);
        let template = project.flower.template_of(0);
        let maps_of = |p: &[f64]| layout.maps(p, size, &template.maps).expect("maps");
        // The target: the organ grown from other maps than the point the
        // gradient is taken at, so the residual is not zero.
        let known = [0.2, 0.8, 0.5, 0.3, 0.35, 0.95, 0.5, 0.45];
        let target = simulate_final(&project, 0, maps_of(&known), &|| false).expect("target");
        let coarse = coarse_run(&project, 0, &layout, FitSettings::default().coarse);
        assert!(coarse.is_some(), "40 keyframes have a coarse run");
        let problem = Problem {
            project: &project,
            coarse,
            organ: 0,
            layout: layout.clone(),
            size,
            target: &target,
            length: 1.0,
            cancel: &|| false,
        };
        let p = [0.3, 0.6, 0.45, 0.4, 0.4, 0.8, 0.5, 0.5];
        let r = problem.residual(&p).expect("runs").expect("simulates");
        let (jacobian, _) =
            finite_differences(&problem, &p, &r, FitSettings::default().step).expect("runs");
        let rows = r.len();
        let fits: Vec<f64> = (0..p.len())
            .map(|i| {
                2.0 * (0..rows)
                    .map(|k| jacobian[i * rows + k] * r[k])
                    .sum::<f64>()
            })
            .collect();
        let h = 1e-4;
        let central: Vec<f64> = (0..p.len())
            .map(|i| {
                let at = |d: f64| {
                    let mut q = p.to_vec();
                    q[i] += d;
                    cost(&problem.residual(&q).expect("runs").expect("simulates"))
                };
                (at(h) - at(-h)) / (2.0 * h)
            })
            .collect();
        let dot: f64 = fits.iter().zip(&central).map(|(a, b)| a * b).sum();
        let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let cosine = dot / (norm(&fits) * norm(&central));
        let relative = fits
            .iter()
            .zip(&central)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt()
            / norm(&central);
        // Measured: cosine 0.99984, relative difference 2.5 % (the coarse
        // run's final shapes lie within a few tenths of a per cent of the
        // full run's).
        assert!(
            cosine > 0.999 && relative < 0.06,
            "cosine {cosine:.4}, relative difference {relative:.3}\nfit's {fits:?}\ncentral {central:?}"
        );
    }

    #[test]
    fn the_coarse_run_takes_half_the_steps_at_twice_the_growth() {
        let project = anthesis_sim::fixtures::whorl(1, 6, 10, 40);
        let layout = Layout {
            growth: Grid {
                nodes_u: 1,
                nodes_v: 2,
            },
            direction: Grid {
                nodes_u: 0,
                nodes_v: 0,
            },
            key_steps: basis::key_steps(3, 40),
        };
        let (coarse, coarse_layout) = coarse_run(&project, 0, &layout, 2).expect("40 halve to 20");
        assert_eq!(coarse.settings.keyframes, 20);
        let (before, after) = (&project.flower.templates[0], &coarse.flower.templates[0]);
        assert_eq!(after.dg, 2.0 * before.dg);
        assert_eq!(coarse_layout.key_steps, vec![0, 10, 20]);
        let steps = |t: &anthesis_flower::Template| -> Vec<u32> {
            t.maps.keys().iter().map(|k| k.step).collect()
        };
        assert_eq!(steps(before), vec![40, 50]);
        assert_eq!(steps(after), vec![20, 25]);
        assert_eq!(
            after.joint_schedule[0].to_step,
            before.joint_schedule[0].to_step / 2
        );
        // Too few keyframes left: the full run throughout.
        assert!(coarse_run(&project, 0, &layout, 4).is_none());
        assert!(coarse_run(&project, 0, &layout, 1).is_none());
    }
}

//! Growth maps fitted to a target: "which maps make it open like this?"
//!
//! Given a project, one of its organs and a target shape of that organ (a
//! triangle mesh of any triangulation: the organ simulated at another
//! resolution, a model from another program, a scan; with or without
//! UVs), [`fit`] finds growth maps (e-growth, w-growth, their inner
//! versions and the growth direction, at one or more time keys) whose
//! growth simulation ends on the target's surface. A target in its own
//! frame is first put on the organ by [`register_target`].
//!
//! # Method
//!
//! - **Distance.** Between surfaces, both ways ([`surface`]): every organ
//!   particle to its nearest point on the target's triangles and every
//!   target vertex to its nearest point on the organ's, each side weighted
//!   by area; the RMS is the root of the two sides' mean squares, the
//!   largest distance the largest of any vertex. Reported as fractions of
//!   the organ's length (the farthest target vertex from the organ's base).
//! - **Basis.** Each map is a sum of bilinear hat functions on a coarse
//!   grid of nodes over the UV square (default 3 across × 4 from base to
//!   tip for the four growth maps, 3 × 2 for the direction's angle from
//!   +v), per time key ([`basis`]). The fitted maps are these fields
//!   rasterised at the template's map size and quantised as a 16-bit PNG
//!   stores them, so the saved project simulates to the reported shape.
//! - **First guess** in closed form from the target's stretches and
//!   curvature changes relative to the bud ([`guess`]), the target read at
//!   each particle's UV when it has a UV layout, else at the point nearest
//!   the organ's current final shape; the project's own maps, put in the
//!   basis by least squares, are simulated alongside, and the nearer of
//!   the two starts.
//! - **Optimisation**: Levenberg–Marquardt with box bounds (growth maps in
//!   [0, 1], the angle within ±[`basis::MAX_ANGLE`]) on the surface
//!   residuals, whose correspondences (nearest points) are found afresh at
//!   every shape the fit accepts (non-rigid ICP). The Jacobian of the
//!   simulated positions is by forward finite differences (step 0.001),
//!   one simulation per parameter, run in parallel (rayon), on a run of
//!   half the keyframes at twice the growth per step
//!   ([`FitSettings::coarse`]: half the cost, derivatives of a shape 0.6 %
//!   of the length from the full run's); between Jacobians it is kept
//!   current by Broyden's rank-one updates from the full run's shapes, and
//!   taken afresh when a step gains little, if it can end within the time
//!   allowed. Each iteration tries two damping values at once (one per
//!   core). A registered target's rigid placement is refined by a few ICP
//!   steps after each accepted step (kept when it lowers the distance).
//! - Distances are always those of the project's own run (its keyframe
//!   count, resolution, solver, parts): the final shape depends on the
//!   number of keyframes, so the result is judged on the full run.
//! - **Limits.** `max_seconds` bounds the whole fit from its start: every
//!   simulation (the Jacobian's too) stops when it passes, and the fit
//!   returns the best maps so far saying it was stopped ([`Stop`]); only a
//!   first guess that cannot be simulated once within it is an error.

#![warn(missing_docs)]

pub mod basis;
mod dense;
pub mod guess;
pub mod register;
pub mod surface;

use std::time::{Duration, Instant};

use anthesis_flower::Project;
use anthesis_maps::{KeyedMaps, MapError};
use anthesis_mesh::Mesh;
use anthesis_sim::{Selection, SimError, Simulation};
use glam::{DVec2, DVec3};
use rayon::prelude::*;

pub use basis::{Grid, Layout};
pub use register::Registration;
pub use surface::{Apart, Similarity, Surface};

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
    /// Stop once the RMS surface distance is below this fraction of the
    /// organ's length.
    pub goal_rms: f64,
    /// The whole fit's time, in seconds, from its start to its result: the
    /// simulation running when it passes stops, and the best maps so far
    /// are returned ([`Stop::Seconds`]). No fresh Jacobian (after the
    /// first) is started that would end later.
    pub max_seconds: f64,
    /// The finite-difference step of a growth map value (the angle's is
    /// the same in radians).
    pub step: f64,
    /// The Jacobian is taken on a run of 1/`coarse` the keyframes with
    /// `coarse` times the growth per step (the joint schedule and the time
    /// keys at 1/`coarse` their steps), when that leaves at least
    /// [`MIN_COARSE_KEYFRAMES`]: about `coarse` times cheaper, and near
    /// enough the full run's derivatives (Eustoma, halved: final shapes
    /// 0.6 % of the length apart). Distances are always the full run's,
    /// and Broyden's updates carry the Jacobian towards the full run's.
    /// 1: the full run throughout.
    pub coarse: u32,
    /// Refine the target's placement (rigidly, its scale held) as the fit
    /// goes: for a registered target, whose first placement was found
    /// against the organ's shape before the fit.
    pub refine_placement: bool,
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
            max_seconds: 100.0,
            step: 0.001,
            coarse: 2,
            refine_placement: false,
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
    /// The target has no faces, and is not the organ's own vertices either.
    #[error(
        "the target has {found} vertices and no faces: a target is a surface (an OBJ with \
         faces); bare vertices are read only as organ `{organ}`'s {expected} particles in order"
    )]
    NoFaces {
        /// The organ's name.
        organ: String,
        /// Its particles.
        expected: usize,
        /// The target's vertices.
        found: usize,
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
    /// Not even the first guess could be simulated in the time allowed.
    #[error(
        "the time allowed ({seconds} s) ended before the first guess was simulated once; allow \
         more (one simulation of this organ took longer)"
    )]
    OutOfTime {
        /// The time allowed.
        seconds: f64,
    },
    /// The caller cancelled the fit.
    #[error("the fit was cancelled")]
    Cancelled,
}

/// A target surface read for a fit: any triangulation, in its own frame.
#[derive(Debug, Clone)]
pub struct Target {
    /// The surface (positions in the target's own frame and units).
    pub surface: Surface,
    /// A UV per vertex, when the target has a UV layout over the unit
    /// square (the same convention as the organ's: used for the first
    /// guess only).
    pub uvs: Option<Vec<DVec2>>,
    /// What reading it said (vertices joined, statements read past).
    pub warnings: Vec<String>,
}

impl Target {
    /// The target's vertices.
    pub fn vertex_count(&self) -> usize {
        self.surface.positions.len()
    }

    /// The target with its faces wound the other way: its inner side (the
    /// one its faces wind counter-clockwise around, as an organ's do) the
    /// other side, for a target exported the other way round. Only the
    /// registration reads the winding.
    pub fn flipped(self) -> Target {
        let triangles = self
            .surface
            .triangles
            .iter()
            .map(|&[a, b, c]| [a, c, b])
            .collect();
        Target {
            surface: Surface::new(self.surface.positions, triangles),
            ..self
        }
    }
}

/// Progress of a running fit, reported after each iteration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitProgress {
    /// Iterations done (0: the first guess).
    pub iteration: u32,
    /// RMS surface distance to the target, as a fraction of the organ's
    /// length.
    pub rms: f64,
    /// Largest distance, as a fraction of the organ's length.
    pub max: f64,
    /// Simulations run so far.
    pub simulations: usize,
    /// Seconds since the fit started.
    pub seconds: f64,
}

/// Why a fit stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// The RMS went below the goal.
    Goal,
    /// No step lowers the distance any more: as close as these maps get.
    Converged,
    /// The iteration limit was reached while steps still gained.
    Iterations,
    /// The time limit was reached.
    Seconds,
}

impl Stop {
    /// Whether a limit stopped the fit (it might have come closer).
    pub fn by_limit(self) -> bool {
        matches!(self, Stop::Iterations | Stop::Seconds)
    }

    /// A short name (the JSON report's `stopped`).
    pub fn name(self) -> &'static str {
        match self {
            Stop::Goal => "goal",
            Stop::Converged => "converged",
            Stop::Iterations => "max-iterations",
            Stop::Seconds => "max-seconds",
        }
    }
}

/// A fit's result: the maps and how close they come.
#[derive(Debug, Clone)]
pub struct Fit {
    /// The fitted maps (stretch and bend as the template had them).
    pub maps: KeyedMaps,
    /// The basis coefficients of the maps.
    pub parameters: Vec<f64>,
    /// The organ's length the distances are fractions of: the largest
    /// distance of a target vertex (placed) from the centroid of the
    /// organ's base particles.
    pub length: f64,
    /// RMS surface distance of the first guess's simulation from the
    /// target, as a fraction of the length (the nearer of the closed-form
    /// guess and the project's own maps in the fit's basis).
    pub guess_rms: f64,
    /// RMS surface distance between the fitted maps' final shape and the
    /// target, as a fraction of the length.
    pub rms: f64,
    /// Largest distance, as a fraction of the length.
    pub max: f64,
    /// Levenberg–Marquardt iterations done.
    pub iterations: u32,
    /// Growth simulations run.
    pub simulations: usize,
    /// Wall time in seconds.
    pub seconds: f64,
    /// Why it stopped.
    pub stop: Stop,
    /// The iteration limit it ran with.
    pub max_iterations: u32,
    /// The time limit it ran with.
    pub max_seconds: f64,
    /// Where the target was put at the end (the placement given, refined
    /// when asked).
    pub placement: Similarity,
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

    /// A one-line verdict for people: how close the fit came, why it
    /// stopped, and when the target was not reached, whether the bud
    /// cannot reach it or a limit stopped the fit first.
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
        let limit = match self.stop {
            Stop::Iterations => format!("the iteration limit ({})", self.max_iterations),
            Stop::Seconds => format!("the time limit ({} s)", self.max_seconds),
            Stop::Goal | Stop::Converged => String::new(),
        };
        match (self.reached(), self.stop.by_limit()) {
            (true, false) => format!("fitted: {figures}"),
            (true, true) => format!("fitted: {figures}; stopped by {limit}"),
            (false, true) => format!(
                "stopped by {limit} before the fit converged: the best maps so far end at \
                 {figures}; more iterations or time may come closer"
            ),
            (false, false) => format!(
                "the bud cannot be grown to this target with these maps: the best fit found ends \
                 at {figures}"
            ),
        }
    }
}

/// The target for the organ named `name`, whose mesh (at the resolution it
/// is simulated at) is `mesh`, from OBJ text: the object called `name`, or
/// the only object; any triangulation (polygons are triangulated, vertices
/// at one place joined), every coordinate finite. Bare vertices without
/// faces are read as the organ's own particles in order (as older
/// versions took targets), and refused otherwise.
pub fn read_target(text: &str, name: &str, mesh: &Mesh) -> Result<Target, FitError> {
    let object = anthesis_mesh::obj::object_text(text, Some(name))
        .or_else(|named| anthesis_mesh::obj::object_text(text, None).map_err(|_| named))
        .map_err(|e| FitError::Target(e.to_string()))?;
    let positions = vertex_lines(&object)?;
    if let Some(vertex) = positions.iter().position(|p| !p.is_finite()) {
        return Err(FitError::NotFinite { vertex: vertex + 1 });
    }
    let has_faces = object
        .lines()
        .any(|line| line.trim_start().starts_with("f "));
    if !has_faces {
        if positions.len() != mesh.vertex_count() {
            return Err(FitError::NoFaces {
                organ: name.to_string(),
                expected: mesh.vertex_count(),
                found: positions.len(),
            });
        }
        return Ok(Target {
            surface: Surface::new(positions, mesh.triangles.clone()),
            uvs: Some(mesh.uvs.clone()),
            warnings: Vec::new(),
        });
    }
    // One clean surface, or else (a scan with stray pieces, a non-manifold
    // edge) its triangles as they are, said in a warning: distances do
    // not need a manifold.
    let (shape, unclean) = match anthesis_mesh::obj::parse_obj_shape(&object) {
        Ok(shape) => (shape, None),
        Err(error) => (
            anthesis_mesh::obj::parse_obj_triangles(&object)
                .map_err(|e| FitError::Target(e.to_string()))?,
            Some(error),
        ),
    };
    let mut warnings: Vec<String> = shape.warnings.iter().map(|w| w.to_string()).collect();
    let mut shape = shape.mesh;
    if let Some(error) = unclean {
        let before = shape.triangles.len();
        shape.triangles.retain(|t| {
            let [a, b, c] = t.map(|v| shape.positions[v as usize]);
            (b - a).cross(c - a).length_squared() > 0.0
        });
        warnings.push(format!(
            "the target is not one clean surface ({error}); its triangles are measured as they \
             are{}",
            match before - shape.triangles.len() {
                0 => String::new(),
                n => format!(", but for {n} without area"),
            }
        ));
        if shape.triangles.is_empty() {
            return Err(FitError::Target(
                "the target has no triangle with an area".into(),
            ));
        }
    }
    // The UV layout, where the file has one per vertex within the unit
    // square and the same vertices as the shape read.
    let uvs = anthesis_mesh::obj::parse_obj_unvalidated(&object)
        .ok()
        .filter(|with_uvs| {
            with_uvs.positions == shape.positions
                && with_uvs
                    .uvs
                    .iter()
                    .all(|uv| (0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y))
                && with_uvs.uvs.iter().any(|uv| *uv != DVec2::ZERO)
        })
        .map(|with_uvs| with_uvs.uvs);
    Ok(Target {
        surface: Surface::new(shape.positions, shape.triangles),
        uvs,
        warnings,
    })
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

/// RMS and largest surface distance between the organ's `shape` (on its
/// mesh's `triangles`) and `target` put where `placement` says, as
/// fractions of `length` (see [`surface`]).
pub fn distances(
    shape: &[DVec3],
    triangles: &[[u32; 3]],
    target: &Target,
    placement: Similarity,
    length: f64,
) -> (f64, f64) {
    let apart = surface::compare(
        shape,
        triangles,
        &surface::Placed {
            surface: &target.surface,
            placement,
        },
        &target.surface.vertex_weights(),
        None,
    );
    (apart.rms() / length, apart.max / length)
}

/// The organ's length for `target` at `placement`: the farthest placed
/// target vertex from the centroid of the organ's base particles in the
/// bud (where the receptacle holds them).
pub fn organ_length(
    project: &Project,
    organ: usize,
    target: &Target,
    placement: Similarity,
) -> Result<f64, FitError> {
    let bud = bud_positions(project, organ)?;
    let base_centre = base_centre(project, organ, &bud);
    Ok(target
        .surface
        .positions
        .iter()
        .map(|&x| placement.apply(x).distance(base_centre))
        .fold(0.0, f64::max)
        .max(1e-12))
}

fn bud_positions(project: &Project, organ: usize) -> Result<Vec<DVec3>, FitError> {
    if organ >= project.flower.organs.len() {
        return Err(FitError::NoSuchOrgan(format!("#{organ}")));
    }
    Ok(Simulation::new(project, &Selection::Only(organ))?
        .bud()
        .positions_in_world
        .into_iter()
        .next()
        .unwrap_or_default())
}

fn base_centre(project: &Project, organ: usize, bud: &[DVec3]) -> DVec3 {
    let template = project.flower.template_of(organ);
    let base = template.base_region.particles(&template.mesh);
    if base.is_empty() {
        DVec3::ZERO
    } else {
        base.iter().map(|&b| bud[b as usize]).sum::<DVec3>() / base.len() as f64
    }
}

/// A target put on the organ before a fit, and how near it then is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Registered {
    /// The registration.
    pub registration: Registration,
    /// RMS surface distance to the organ's current shape, as a fraction
    /// of the organ's length (with the target placed).
    pub rms: f64,
    /// Largest distance, likewise.
    pub max: f64,
    /// The organ's length (see [`Fit::length`]).
    pub length: f64,
}

impl Registered {
    /// One line for people: the motion found and how near it puts the
    /// target.
    pub fn describe(&self) -> String {
        let placement = self.registration.placement;
        let (axis, angle) = placement.rotation.to_axis_angle();
        let t = placement.translation;
        format!(
            "registered: turned {:.1}° about ({:.3}, {:.3}, {:.3}), scaled {:.4}, moved by \
             ({:.4}, {:.4}, {:.4}); the target is then RMS {:.2} %, max {:.2} % of the organ's \
             length {:.3} from the organ's current shape",
            angle.to_degrees(),
            axis.x,
            axis.y,
            axis.z,
            placement.scale,
            t.x,
            t.y,
            t.z,
            100.0 * self.rms,
            100.0 * self.max,
            self.length
        )
    }
}

/// Registers `target` (in its own frame) on organ `organ`'s current shape
/// (its final shape with the project's maps), its base on the organ's base
/// ([`register`]); with `scale` a uniform scale too.
pub fn register_target(
    project: &Project,
    organ: usize,
    target: &Target,
    scale: bool,
    cancel: &(dyn Fn() -> bool + Sync),
) -> Result<Registered, FitError> {
    if organ >= project.flower.organs.len() {
        return Err(FitError::NoSuchOrgan(format!("#{organ}")));
    }
    let template = project.flower.template_of(organ);
    let current =
        simulate_final(project, organ, template.maps.clone(), cancel).map_err(|e| match e {
            SimError::Cancelled => FitError::Cancelled,
            other => FitError::Simulation(other),
        })?;
    let base = template.base_region.particles(&template.mesh);
    let registration = register::register(
        &target.surface,
        &current,
        &template.mesh.triangles,
        &base,
        scale,
    );
    let length = organ_length(project, organ, target, registration.placement)?;
    let (rms, max) = distances(
        &current,
        &template.mesh.triangles,
        target,
        registration.placement,
        length,
    );
    Ok(Registered {
        registration,
        rms,
        max,
        length,
    })
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

/// A step tried: its damping, parameters and final shape (`None`: the
/// simulation blew up).
type Tried = (f64, Vec<f64>, Option<Vec<DVec3>>);

/// What stopped a simulation of the fit other than a blow-up.
enum Halt {
    /// The caller cancelled.
    Cancelled,
    /// The fit's time ran out.
    OutOfTime,
    /// Maps could not be built.
    Failed(FitError),
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
    triangles: &'a [[u32; 3]],
    target: &'a Target,
    target_weights: Vec<f64>,
    length: f64,
    deadline: Instant,
    cancel: &'a (dyn Fn() -> bool + Sync),
}

impl<'a> Problem<'a> {
    /// The problem of fitting organ `organ` of `project` to `target` with
    /// `settings`: the basis's layout, the map size, the coarse run.
    fn new(
        project: &'a Project,
        organ: usize,
        target: &'a Target,
        settings: &FitSettings,
        length: f64,
        deadline: Instant,
        cancel: &'a (dyn Fn() -> bool + Sync),
    ) -> Problem<'a> {
        let template = project.flower.template_of(organ);
        let layout = Layout {
            growth: settings.growth_nodes,
            direction: settings.direction_nodes,
            key_steps: basis::key_steps(settings.keys, project.settings.keyframes),
        };
        let size = template.maps.raster_size().unwrap_or((64, 64));
        let coarse = coarse_run(project, organ, &layout, settings.coarse);
        Problem {
            project,
            coarse,
            organ,
            layout,
            size,
            triangles: &template.mesh.triangles,
            target,
            target_weights: target.surface.vertex_weights(),
            length,
            deadline,
            cancel,
        }
    }
}

impl Problem<'_> {
    fn maps(&self, p: &[f64]) -> Result<KeyedMaps, MapError> {
        let template = self.project.flower.template_of(self.organ);
        self.layout.maps(p, self.size, &template.maps)
    }

    /// The final shape of parameters `p` on the full run, or on the coarse
    /// run when `coarse` and there is one; `None` when the simulation
    /// fails (a blow-up counts as a step too far, not as an error of the
    /// fit).
    fn shape(&self, p: &[f64], coarse: bool) -> Result<Option<Vec<DVec3>>, Halt> {
        let (project, layout) = match &self.coarse {
            Some((project, layout)) if coarse => (project, layout),
            _ => (self.project, &self.layout),
        };
        let template = project.flower.template_of(self.organ);
        let maps = layout
            .maps(p, self.size, &template.maps)
            .map_err(|e| Halt::Failed(e.into()))?;
        let stop = || (self.cancel)() || Instant::now() >= self.deadline;
        match simulate_final(project, self.organ, maps, &stop) {
            Ok(shape) => Ok(Some(shape)),
            Err(SimError::Cancelled) if (self.cancel)() => Err(Halt::Cancelled),
            Err(SimError::Cancelled) => Err(Halt::OutOfTime),
            Err(_) => Ok(None),
        }
    }

    /// How far shape `s` is from the target placed at `placement`, and the
    /// Gauss–Newton rows there when asked.
    fn measure(
        &self,
        s: &[DVec3],
        placement: Similarity,
        rows: Option<&mut Vec<surface::Row>>,
    ) -> Apart {
        surface::compare(
            s,
            self.triangles,
            &surface::Placed {
                surface: &self.target.surface,
                placement,
            },
            &self.target_weights,
            rows,
        )
    }

    /// RMS and largest distance as fractions of the length.
    fn fractions(&self, apart: &Apart) -> (f64, f64) {
        (apart.rms() / self.length, apart.max / self.length)
    }

    fn seconds_left(&self) -> f64 {
        self.deadline
            .saturating_duration_since(Instant::now())
            .as_secs_f64()
    }
}

/// The target's positions at the organ's particles, for the first guess:
/// read at each particle's UV on the target's UV layout when it has one,
/// else the target's points nearest the organ's shape `current`.
fn target_at_particles(
    target: &Target,
    placement: Similarity,
    mesh: &Mesh,
    current: impl FnOnce() -> Option<Vec<DVec3>>,
) -> Option<Vec<DVec3>> {
    let placed = surface::Placed {
        surface: &target.surface,
        placement,
    };
    if let Some(uvs) = &target.uvs {
        let layout = Surface::new(
            uvs.iter().map(|uv| DVec3::new(uv.x, uv.y, 0.0)).collect(),
            target.surface.triangles.clone(),
        );
        return mesh
            .uvs
            .iter()
            .map(|uv| {
                let near = layout.nearest(DVec3::new(uv.x, uv.y, 0.0))?;
                let corners = target.surface.triangles[near.triangle as usize];
                Some(
                    (0..3)
                        .map(|k| {
                            near.weights[k]
                                * placement.apply(target.surface.positions[corners[k] as usize])
                        })
                        .sum(),
                )
            })
            .collect();
    }
    current()?
        .iter()
        .map(|&p| placed.nearest(p).map(|near| near.point))
        .collect()
}

/// Fits the growth maps of organ `organ` of `project` (at the resolution it
/// is simulated at, see `anthesis_flower::resolution::resolve`) to
/// `target`, put in the world where `placement` says (the identity for a
/// target already in the project's frame, or [`register_target`]'s).
/// `progress` hears of every iteration; `cancel` is polled inside the
/// simulations.
///
/// The phases (private functions of this file): the inputs checked
/// (`check_inputs`), the start chosen (`start`), then Levenberg–Marquardt
/// iterations (`Iterate`: a Jacobian, fresh or updated, `jacobian`; two
/// damped steps tried, `step`; the better kept, `accept`, or the damping
/// raised, `reject`) until a [`Stop`].
pub fn fit(
    project: &Project,
    organ: usize,
    target: &Target,
    placement: Similarity,
    settings: &FitSettings,
    progress: &mut dyn FnMut(FitProgress),
    cancel: &(dyn Fn() -> bool + Sync),
) -> Result<Fit, FitError> {
    let started = Instant::now();
    let deadline = started + Duration::from_secs_f64(settings.max_seconds.clamp(0.0, 1e9));
    let topology = check_inputs(project, organ, target)?;
    let template = project.flower.template_of(organ);
    let bud_positions = bud_positions(project, organ)?;
    let base_particles = template.base_region.particles(&template.mesh);
    let length = organ_length(project, organ, target, placement)?;

    let problem = Problem::new(project, organ, target, settings, length, deadline, cancel);
    let report = |iteration: u32, apart: &Apart, simulations: usize| {
        let (rms, max) = problem.fractions(apart);
        FitProgress {
            iteration,
            rms,
            max,
            simulations,
            seconds: started.elapsed().as_secs_f64(),
        }
    };

    let (p, s, simulations) = start(
        &problem,
        placement,
        &topology,
        &bud_positions,
        settings.max_seconds,
    )?;
    let apart = problem.measure(&s, placement, None);
    let guess_rms = problem.fractions(&apart).0;
    let mut state = Iterate {
        p,
        s,
        apart,
        placement,
        jacobian: None,
        fresh: false,
        jacobian_seconds: None,
        mu: 0.0,
        iterations: 0,
        simulations,
    };
    progress(report(0, &state.apart, state.simulations));

    let stop = loop {
        if let Some(stop) = state.done(&problem, settings) {
            break stop;
        }
        let j = match state.jacobian(&problem, settings.step) {
            Ok(j) => j,
            Err(Exit::Stop(stop)) => break stop,
            Err(Exit::Failed(e)) => return Err(e),
        };
        let converged = match state.step(&problem, settings, j, &base_particles) {
            Ok(converged) => converged,
            Err(Exit::Stop(stop)) => break stop,
            Err(Exit::Failed(e)) => return Err(e),
        };
        progress(report(state.iterations, &state.apart, state.simulations));
        if converged {
            break Stop::Converged;
        }
    };

    let Iterate {
        p,
        s,
        apart,
        placement,
        iterations,
        simulations,
        ..
    } = state;
    let (rms, max) = problem.fractions(&apart);
    let maps = problem.maps(&p)?;
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
        stop,
        max_iterations: settings.max_iterations,
        max_seconds: settings.max_seconds,
        placement,
        shape: s,
    })
}

/// The fit's inputs checked: the organ exists, the target has triangles
/// and finite positions, the organ's template mesh is valid (its topology
/// returned, for the first guess).
fn check_inputs(
    project: &Project,
    organ: usize,
    target: &Target,
) -> Result<anthesis_mesh::Topology, FitError> {
    let flower = &project.flower;
    if flower.organs.get(organ).is_none() {
        return Err(FitError::NoSuchOrgan(format!("#{organ}")));
    }
    let template = flower.template_of(organ);
    if target.surface.triangles.is_empty() {
        return Err(FitError::Target("the target has no triangles".into()));
    }
    if let Some(vertex) = target.surface.positions.iter().position(|p| !p.is_finite()) {
        return Err(FitError::NotFinite { vertex: vertex + 1 });
    }
    let topology = anthesis_mesh::validate(&template.mesh).map_err(|error| SimError::BadMesh {
        template: template.name.clone(),
        error,
    })?;
    Ok(topology)
}

/// What a stopped simulation before the iterations means for the fit:
/// each is an error (only the first guess must simulate within the time).
fn halt_error(halt: Halt, max_seconds: f64) -> FitError {
    match halt {
        Halt::Cancelled => FitError::Cancelled,
        Halt::OutOfTime => FitError::OutOfTime {
            seconds: max_seconds,
        },
        Halt::Failed(e) => e,
    }
}

/// The start of the iterations: the closed-form first guess (no growth
/// when the target cannot be read at the particles) and the project's own
/// maps in the basis, simulated at once; the nearer wins, no growth if
/// neither simulates. Returns the parameters, their final shape and the
/// simulations run.
fn start(
    problem: &Problem<'_>,
    placement: Similarity,
    topology: &anthesis_mesh::Topology,
    bud_positions: &[DVec3],
    max_seconds: f64,
) -> Result<(Vec<f64>, Vec<DVec3>, usize), FitError> {
    let Problem {
        project,
        organ,
        target,
        deadline,
        cancel,
        ..
    } = *problem;
    let template = project.flower.template_of(organ);
    let mut simulations = 0usize;
    let first_error = |halt: Halt| halt_error(halt, max_seconds);

    // The first guess, or no growth when its simulation fails.
    let mut guess_sims = 0;
    let at_particles = target_at_particles(target, placement, &template.mesh, || {
        guess_sims += 1;
        let stop = || cancel() || Instant::now() >= deadline;
        simulate_final(project, organ, template.maps.clone(), &stop).ok()
    });
    simulations += guess_sims;
    let organ_guess = guess::Organ {
        mesh: &template.mesh,
        topology,
        bud: bud_positions,
        dg: template.dg,
        thickness: template.thickness,
        steps: project.settings.keyframes,
    };
    let guessed = match &at_particles {
        Some(at) => guess::guess(&organ_guess, at, &problem.layout),
        None => vec![0.0; problem.layout.len()],
    };
    // Two starts, simulated at once: the closed-form guess and the
    // project's own maps in the basis (better where the guess's
    // correspondences are poor, as for a target without UVs); the nearer
    // wins, no growth if neither simulates.
    let own = guess::from_maps(&problem.layout, &template.maps);
    let (first, second) = rayon::join(
        || problem.shape(&guessed, false),
        || problem.shape(&own, false),
    );
    simulations += 2;
    let mut starts = Vec::new();
    for (q, shape) in [(guessed, first), (own, second)] {
        if let Some(shape) = shape.map_err(first_error)? {
            let cost = problem.measure(&shape, placement, None).cost();
            starts.push((cost, q, shape));
        }
    }
    let (p, s) = match starts.into_iter().min_by(|a, b| a.0.total_cmp(&b.0)) {
        Some((_, q, shape)) => (q, shape),
        None => {
            let none = vec![0.0; problem.layout.len()];
            simulations += 1;
            let shape = problem
                .shape(&none, false)
                .map_err(first_error)?
                .ok_or_else(|| FitError::Target("the organ cannot be simulated".into()))?;
            (none, shape)
        }
    };
    Ok((p, s, simulations))
}

/// Why the iterations end early: a [`Stop`] (the best so far returned), or
/// an error (cancelled, maps that cannot be built).
enum Exit {
    Stop(Stop),
    Failed(FitError),
}

impl From<Halt> for Exit {
    /// A simulation stopped inside the iterations: out of time stops the
    /// fit with its best so far.
    fn from(halt: Halt) -> Self {
        match halt {
            Halt::OutOfTime => Exit::Stop(Stop::Seconds),
            Halt::Cancelled => Exit::Failed(FitError::Cancelled),
            Halt::Failed(e) => Exit::Failed(e),
        }
    }
}

/// The state of the Levenberg–Marquardt iterations.
struct Iterate {
    /// The parameters accepted last.
    p: Vec<f64>,
    /// Their final shape on the full run.
    s: Vec<DVec3>,
    /// How far `s` is from the target.
    apart: Apart,
    /// Where the target is placed (refined as the fit goes).
    placement: Similarity,
    /// The Jacobian of the positions kept for the next step, column-major,
    /// positions x parameters.
    jacobian: Option<Vec<f64>>,
    /// Whether the Jacobian in use was taken afresh (not updated).
    fresh: bool,
    /// How long the last fresh Jacobian took.
    jacobian_seconds: Option<f64>,
    /// The damping.
    mu: f64,
    iterations: u32,
    simulations: usize,
}

impl Iterate {
    /// The stop before an iteration: the goal reached, no iterations or
    /// time left.
    fn done(&self, problem: &Problem<'_>, settings: &FitSettings) -> Option<Stop> {
        if problem.fractions(&self.apart).0 <= settings.goal_rms {
            return Some(Stop::Goal);
        }
        if self.iterations >= settings.max_iterations {
            return Some(Stop::Iterations);
        }
        if problem.seconds_left() <= 0.0 {
            return Some(Stop::Seconds);
        }
        None
    }

    /// The Jacobian of this iteration: the one kept, or a fresh one by
    /// finite differences (the dearest part; after the first, only when
    /// it can end within the time allowed).
    fn jacobian(&mut self, problem: &Problem<'_>, step: f64) -> Result<Vec<f64>, Exit> {
        if let Some(j) = self.jacobian.take() {
            return Ok(j);
        }
        if self
            .jacobian_seconds
            .is_some_and(|t| t > problem.seconds_left())
        {
            return Err(Exit::Stop(Stop::Seconds));
        }
        let before = Instant::now();
        let (j, runs) = finite_differences(problem, &self.p, &self.s, step)?;
        self.jacobian_seconds = Some(before.elapsed().as_secs_f64());
        self.simulations += runs;
        self.fresh = true;
        Ok(j)
    }

    /// One iteration with the positions' Jacobian `j`: two damped steps
    /// simulated at once, the better kept if it lowers the distance.
    /// Returns whether the fit converged.
    fn step(
        &mut self,
        problem: &Problem<'_>,
        settings: &FitSettings,
        j: Vec<f64>,
        base_particles: &[u32],
    ) -> Result<bool, Exit> {
        let (jtj, jtr) = normal_equations(problem, &self.s, self.placement, &j, self.p.len());
        if self.mu == 0.0 {
            self.mu = 1e-3;
        }
        let candidates = damped_steps(&problem.layout, &self.p, &jtj, &jtr, self.mu);
        let tried: Vec<Tried> = candidates
            .into_par_iter()
            .map(|(d, q)| problem.shape(&q, false).map(|shape| (d, q, shape)))
            .collect::<Result<_, Halt>>()?;
        self.simulations += tried.len();
        let now = self.apart.cost();
        let placement = self.placement;
        let best = tried
            .into_iter()
            .filter_map(|(d, q, shape)| {
                shape.map(|shape| {
                    let a = problem.measure(&shape, placement, None);
                    (a, d, q, shape)
                })
            })
            .min_by(|a, b| a.0.cost().total_cmp(&b.0.cost()));
        self.iterations += 1;
        Ok(match best {
            Some((a, d, q, shape)) if a.cost() < now => {
                let accepted = Accepted {
                    apart: a,
                    damping: d,
                    p: q,
                    shape,
                };
                self.accept(problem, settings, j, accepted, now, base_particles)
            }
            _ => self.reject(j),
        })
    }

    /// A step that lowered the distance (from `now`) taken: the Jacobian
    /// updated by Broyden, the damping lowered, the placement refined when
    /// asked. Returns whether the fit converged (almost no gain on a
    /// Jacobian kept).
    fn accept(
        &mut self,
        problem: &Problem<'_>,
        settings: &FitSettings,
        mut j: Vec<f64>,
        step: Accepted,
        now: f64,
        base_particles: &[u32],
    ) -> bool {
        let Accepted {
            apart: a,
            damping: d,
            p: q,
            shape,
        } = step;
        broyden_update(&mut j, &q, &self.p, &shape, &self.s);
        let gain = 1.0 - a.cost() / now;
        self.mu = if d == self.mu { self.mu / 3.0 } else { d };
        self.p = q;
        self.s = shape;
        self.apart = a;
        if settings.refine_placement {
            let refined = register::refine(
                &problem.target.surface,
                &self.s,
                problem.triangles,
                base_particles,
                self.placement,
                3,
            );
            let moved = problem.measure(&self.s, refined, None);
            if moved.cost() < self.apart.cost() {
                self.placement = refined;
                self.apart = moved;
            }
        }
        // A poor gain on an updated Jacobian: take a fresh one.
        self.jacobian = if gain < 0.05 && !self.fresh {
            None
        } else {
            Some(j)
        };
        self.fresh = false;
        gain < 1e-4 && self.jacobian.is_some()
    }

    /// No step lowered the distance: the damping raised a hundredfold and
    /// the Jacobian `j` kept if fresh (dropped if updated). Returns whether
    /// the fit converged (a fresh Jacobian and damping past 1e8).
    fn reject(&mut self, j: Vec<f64>) -> bool {
        self.mu *= 100.0;
        if self.fresh {
            // A fresh Jacobian and still no descent: try harder
            // damping once more before giving up.
            self.jacobian = Some(j);
            self.mu > 1e8
        } else {
            self.jacobian = None;
            false
        }
    }
}

/// A step that lowered the distance: how far its shape is, its damping,
/// parameters and shape.
struct Accepted {
    apart: Apart,
    damping: f64,
    p: Vec<f64>,
    shape: Vec<DVec3>,
}

/// The Gauss–Newton normal equations at shape `s`: the residual rows made
/// there (against the target at `placement`), their Jacobian through the
/// positions' `j` (column-major, positions x `n`), and JᵀJ (row-major
/// `n` x `n`) with Jᵀr.
fn normal_equations(
    problem: &Problem<'_>,
    s: &[DVec3],
    placement: Similarity,
    j: &[f64],
    n: usize,
) -> (Vec<f64>, Vec<f64>) {
    let positions = 3 * s.len();
    // The residual rows at the shape now, and their Jacobian through
    // the positions'.
    let mut rows = Vec::new();
    problem.measure(s, placement, Some(&mut rows));
    let r: Vec<f64> = rows.iter().map(|row| row.value(s)).collect();
    let m = rows.len();
    let mut jr = vec![0.0; m * n]; // column-major, m x n
    for (col, column) in j.chunks_exact(positions).enumerate() {
        let out = &mut jr[col * m..(col + 1) * m];
        for (value, row) in out.iter_mut().zip(&rows) {
            *value = (0..3)
                .map(|k| {
                    let i = 3 * row.particles[k] as usize;
                    row.weights[k]
                        * DVec3::new(column[i], column[i + 1], column[i + 2]).dot(row.direction)
                })
                .sum();
        }
    }
    // Normal equations.
    let mut jtj = vec![0.0; n * n];
    let mut jtr = vec![0.0; n];
    for a in 0..n {
        let ca = &jr[a * m..(a + 1) * m];
        jtr[a] = ca.iter().zip(&r).map(|(x, y)| x * y).sum();
        for b in a..n {
            let cb = &jr[b * m..(b + 1) * m];
            let dot: f64 = ca.iter().zip(cb).map(|(x, y)| x * y).sum();
            jtj[a * n + b] = dot;
            jtj[b * n + a] = dot;
        }
    }
    (jtj, jtr)
}

/// The steps from `p` at damping `mu` and ten times it (Marquardt's
/// scaling by the diagonal, floored), clamped to the bounds; a damping
/// whose system cannot be solved gives none.
fn damped_steps(
    layout: &Layout,
    p: &[f64],
    jtj: &[f64],
    jtr: &[f64],
    mu: f64,
) -> Vec<(f64, Vec<f64>)> {
    let n = p.len();
    let max_diag = (0..n).map(|i| jtj[i * n + i]).fold(0.0, f64::max);
    let floor = 1e-9 * max_diag.max(1e-300);
    let step_for = |damping: f64| -> Option<Vec<f64>> {
        let mut a = jtj.to_vec();
        for i in 0..n {
            a[i * n + i] += damping * jtj[i * n + i].max(floor);
        }
        let delta = dense::solve(n, a, jtr.iter().map(|g| -g).collect())?;
        let mut q: Vec<f64> = p.iter().zip(&delta).map(|(a, b)| a + b).collect();
        guess::clamp(layout, &mut q);
        Some(q)
    };
    let dampings = [mu, 10.0 * mu];
    dampings
        .iter()
        .filter_map(|&d| step_for(d).map(|q| (d, q)))
        .collect()
}

/// Broyden's rank-one update of the positions' Jacobian `j` (column-major)
/// with the step from `p` to `q`, which moved shape `s` to `shape`.
fn broyden_update(j: &mut [f64], q: &[f64], p: &[f64], shape: &[DVec3], s: &[DVec3]) {
    let positions = 3 * s.len();
    let dp: Vec<f64> = q.iter().zip(p).map(|(a, b)| a - b).collect();
    let dp2: f64 = dp.iter().map(|x| x * x).sum();
    if dp2 > 0.0 {
        let mut predicted = vec![0.0; positions];
        for (col, step) in dp.iter().enumerate() {
            if *step != 0.0 {
                for (pr, jv) in predicted
                    .iter_mut()
                    .zip(&j[col * positions..(col + 1) * positions])
                {
                    *pr += jv * step;
                }
            }
        }
        let moved: Vec<f64> = shape
            .iter()
            .zip(s)
            .flat_map(|(a, b)| (*a - *b).to_array())
            .collect();
        let miss: Vec<f64> = (0..positions).map(|i| moved[i] - predicted[i]).collect();
        for (col, step) in dp.iter().enumerate() {
            if *step != 0.0 {
                let f = step / dp2;
                for (jv, m) in j[col * positions..(col + 1) * positions]
                    .iter_mut()
                    .zip(&miss)
                {
                    *jv += m * f;
                }
            }
        }
    }
}

/// The Jacobian of the final positions at `p` (whose full run's shape is
/// `s`) by forward differences, on the coarse run if there is one,
/// column-major; a column whose step leaves the bounds steps the other
/// way, and one whose simulation fails is left zero. Returns the
/// simulations run.
fn finite_differences(
    problem: &Problem<'_>,
    p: &[f64],
    s: &[DVec3],
    step: f64,
) -> Result<(Vec<f64>, usize), Halt> {
    let n = p.len();
    let rows = 3 * s.len();
    let coarse = problem.coarse.is_some();
    // The differences are taken from the run they are made with.
    let base = if coarse {
        problem.shape(p, true)?
    } else {
        Some(s.to_vec())
    };
    let Some(base) = base else {
        return Ok((vec![0.0; n * rows], 1));
    };
    let columns: Vec<Vec<f64>> = (0..n)
        .into_par_iter()
        .map(|i| {
            let (_, hi) = Layout::bounds(problem.layout.field_of(i));
            let h = if p[i] + step > hi { -step } else { step };
            let mut q = p.to_vec();
            q[i] += h;
            Ok(match problem.shape(&q, coarse)? {
                Some(shape) => shape
                    .iter()
                    .zip(&base)
                    .flat_map(|(a, b)| ((*a - *b) / h).to_array())
                    .collect(),
                None => vec![0.0; rows],
            })
        })
        .collect::<Result<_, Halt>>()?;
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
    /// uses (forward differences of the positions on the coarse run, through
    /// the surface rows), against central differences of the surface cost
    /// of the full run (issue 15 item 6; issue 36: surface distances).
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
        let template = project.flower.template_of(0).clone();
        let maps_of = |p: &[f64]| layout.maps(p, size, &template.maps).expect("maps");
        // The target: the organ grown from other maps than the point the
        // gradient is taken at, so the residual is not zero.
        let known = [0.2, 0.8, 0.5, 0.3, 0.35, 0.95, 0.5, 0.45];
        let shape = simulate_final(&project, 0, maps_of(&known), &|| false).expect("target");
        let target = Target {
            surface: Surface::new(shape, template.mesh.triangles.clone()),
            uvs: None,
            warnings: Vec::new(),
        };
        let coarse = coarse_run(&project, 0, &layout, FitSettings::default().coarse);
        assert!(coarse.is_some(), "40 keyframes have a coarse run");
        let problem = Problem {
            project: &project,
            coarse,
            organ: 0,
            layout: layout.clone(),
            size,
            triangles: &template.mesh.triangles,
            target: &target,
            target_weights: target.surface.vertex_weights(),
            length: 1.0,
            deadline: Instant::now() + Duration::from_secs(3600),
            cancel: &|| false,
        };
        let shape_of = |p: &[f64]| -> Vec<DVec3> {
            match problem.shape(p, false) {
                Ok(Some(s)) => s,
                _ => panic!("simulates"),
            }
        };
        let p = [0.3, 0.6, 0.45, 0.4, 0.4, 0.8, 0.5, 0.5];
        let s = shape_of(&p);
        let Ok((jacobian, _)) = finite_differences(&problem, &p, &s, FitSettings::default().step)
        else {
            panic!("runs");
        };
        let mut rows = Vec::new();
        problem.measure(&s, Similarity::IDENTITY, Some(&mut rows));
        let positions = 3 * s.len();
        let fits: Vec<f64> = (0..p.len())
            .map(|i| {
                let column = &jacobian[i * positions..(i + 1) * positions];
                2.0 * rows
                    .iter()
                    .map(|row| {
                        let d: f64 = (0..3)
                            .map(|k| {
                                let at = 3 * row.particles[k] as usize;
                                row.weights[k]
                                    * DVec3::new(column[at], column[at + 1], column[at + 2])
                                        .dot(row.direction)
                            })
                            .sum();
                        d * row.value(&s)
                    })
                    .sum::<f64>()
            })
            .collect();
        let h = 1e-4;
        let central: Vec<f64> = (0..p.len())
            .map(|i| {
                let at = |d: f64| {
                    let mut q = p.to_vec();
                    q[i] += d;
                    problem
                        .measure(&shape_of(&q), Similarity::IDENTITY, None)
                        .cost()
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
        // Measured (positions in the same order): cosine 0.99984, relative
        // difference 2.5 % (the coarse run's final shapes lie within a few
        // tenths of a per cent of the full run's).
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

//! One organ in a running simulation: its growth maps sampled once per time
//! key, its elastic state, solver and attachment.

use crate::collide::{Locality, Surface};
use anthesis_flower::{Organ, Placement, Template, joint_angle_after};
use anthesis_maps::{KeySchedule, ScalarMap};
use anthesis_mesh::nearest::TriangleRings;
use anthesis_mesh::{Mesh, Topology};
use anthesis_physics::elastic::edge_areas_into;
use anthesis_physics::membrane::EdgeSmoothedMembrane;
use anthesis_physics::shape_match::match_shape;
use anthesis_physics::solver::same_bits;
use anthesis_physics::{
    Contact, Elastic, GrowthModel, GrowthRates, Model, NewtonSolver, RegionalGrowth, SolverError,
    SolverSettings, StepReport,
};
use anthesis_twostate::TwoState;
use std::collections::VecDeque;
use std::sync::{Arc, OnceLock};

use glam::{DQuat, DVec2, DVec3};

use crate::SimError;

/// Stiffness map values are clamped to at least this, so a black stiffness
/// map cannot make the system singular.
const MIN_STIFFNESS_MAP: f64 = 0.01;
/// Stiffness, relative to the mean spring stiffness, of the springs that
/// hold each base particle where the receptacle and the joint schedule put
/// it, during minimisation. The elastic energy does not see rigid motions:
/// without these springs a contact pushed the whole organ away in a Newton
/// step, shape matching put it back, and the keyframe cycled instead of
/// converging. Shape matching (paper §5.3) carries the organ to the new
/// joint angle when a keyframe starts and removes, when it ends, the little
/// rigid slip the springs allow; snapping the organ after every iteration
/// jolted it against its frozen contacts and kept keyframes from settling.
const ANCHOR_FACTOR: f64 = 1000.0;
/// Contact penalty stiffness relative to the mean spring stiffness.
const CONTACT_STIFFNESS_FACTOR: f64 = 1000.0;
/// Rings of triangles around the base region where rim contacts do not act
/// (see `OrganSim::near_base`).
const NEAR_BASE_RINGS: usize = 3;

/// A time key's maps, sampled where the simulation needs them: growth values
/// per triangle (paper eq. 1) and stiffness values per edge (mean of the
/// edge's triangles' values). UVs never change, so this is done once.
struct SampledKey {
    e: Vec<f64>,
    w: Vec<f64>,
    e_in: Vec<f64>,
    w_in: Vec<f64>,
    direction: Vec<DVec2>,
    stretch: Vec<f64>,
    bend: Vec<f64>,
}

impl SampledKey {
    fn new(maps: &anthesis_maps::GrowthMaps, mesh: &Mesh, topology: &Topology) -> SampledKey {
        let per_triangle = |map: &ScalarMap| -> Vec<f64> {
            (0..mesh.triangles.len())
                .map(|t| map.triangle_value(mesh.triangle_uvs(t)))
                .collect()
        };
        // An edge's stiffness is the mean of its triangles' values (eq. 1,
        // as for growth), not of its two particles': sampled at the
        // particles, a narrow stiff band (the lily's midrib) took a
        // different share of the hinges at each resolution (tip 18 % off at
        // the paper's mesh against 4x the particles, 12 % this way).
        let per_edge = |map: &ScalarMap| -> Vec<f64> {
            let value = per_triangle(map);
            topology
                .edges
                .iter()
                .map(|e| {
                    let mean = match e.right {
                        Some(r) => {
                            0.5 * (value[e.left.triangle as usize] + value[r.triangle as usize])
                        }
                        None => value[e.left.triangle as usize],
                    };
                    mean.max(MIN_STIFFNESS_MAP)
                })
                .collect()
        };
        SampledKey {
            e: per_triangle(&maps.e_growth),
            w: per_triangle(&maps.w_growth),
            e_in: per_triangle(&maps.e_growth_in),
            w_in: per_triangle(&maps.w_growth_in),
            direction: (0..mesh.triangles.len())
                .map(|t| maps.direction.triangle_value(mesh.triangle_uvs(t)))
                .collect(),
            stretch: per_edge(&maps.stretch),
            bend: per_edge(&maps.bend),
        }
    }
}

/// The growth scale of each of `template`'s keys: the key's own `dg`, else
/// the template's.
fn key_growth_scales(template: &Template) -> Vec<f64> {
    template
        .maps
        .keys()
        .iter()
        .map(|k| k.dg.unwrap_or(template.dg))
        .collect()
}

/// How [`OrganSim::settle`] ended.
pub(crate) enum Settle {
    Converged,
    NotConverged,
    Cancelled,
    /// The solver failed at the iteration after the last gradient.
    Failed(SolverError),
}

/// What [`OrganSim::settle`] did: the relative gradient at the start of
/// each iteration (the last one where it converged), and how it ended.
pub(crate) struct Settled {
    pub gradients: Vec<f64>,
    pub outcome: Settle,
}

pub(crate) struct OrganSim {
    pub name: String,
    pub colour: [f32; 4],
    /// Bud mesh in the template frame (UVs and triangles are used as is).
    pub mesh: Mesh,
    topology: Topology,
    /// Bud positions on the receptacle (keyframe 0).
    pub initial: Vec<DVec3>,
    /// Current world positions.
    pub positions: Vec<DVec3>,
    pub mean_edge: f64,
    /// The mean edge of the bud mesh: the length scale of the consistent
    /// model's stiffness (see `anthesis_physics::model`).
    bud_edge: f64,
    /// Whether each particle is a base particle.
    pub is_base: Vec<bool>,
    /// The triangles around each particle and the ring beyond them, where
    /// collisions look for the nearest point of this organ's surface.
    rings: TriangleRings,
    /// Whether each particle is on the organ's rim.
    rim: Vec<bool>,
    /// The organ's rim edges, each `[low, high]` (rim contacts, issue 35).
    rim_edges: Vec<[u32; 2]>,
    /// The base particles and those sharing a triangle with one: no edge
    /// with an end here gets a rim contact (attachment places the base,
    /// and turned through a neighbour's base the edges next to it were
    /// crushed).
    near_base: Vec<bool>,
    placement: Placement,
    schedule: Vec<anthesis_flower::JointRamp>,
    base: Vec<u32>,
    /// When each sampled key holds; the maps themselves stay with the
    /// template (a copy per organ cost 4 GB for 16k maps).
    key_schedule: KeySchedule,
    keys: Vec<SampledKey>,
    /// Each key's growth scale: its own `dg`, else the template's.
    key_dg: Vec<f64>,
    model: Model,
    growth_model: GrowthModel,
    /// The membrane's Lamé parameter per edge (consistent model).
    modulus: Vec<f64>,
    /// Each triangle's and each edge's area at the last growth step
    /// (buffers kept from step to step).
    triangle_areas: Vec<f64>,
    edge_areas: Vec<f64>,
    stretch_stiffness: f64,
    bend_stiffness: f64,
    elastic: Elastic,
    growth: RegionalGrowth,
    solver: NewtonSolver,
    rates: Vec<GrowthRates>,
    rotation_guess: DQuat,
    base_current: Vec<DVec3>,
    base_target: Vec<DVec3>,
    /// Positions at the end of the last (up to) three keyframes, oldest
    /// first, for [`OrganSim::predict`]; shared with the saved states.
    history: VecDeque<Arc<Vec<DVec3>>>,
    /// The vertex normals of the last of `history`, made on first use:
    /// every contact search of a keyframe (three to five) asks for them.
    previous_normals: OnceLock<Vec<DVec3>>,
    /// The current positions as [`OrganSim::save`] stored them, so the next
    /// keyframe's history shares them instead of copying.
    saved: Option<Arc<Vec<DVec3>>>,
    /// The elastic energy of the shape the solver converged at, if the
    /// last [`OrganSim::attach`] moved the organ from there to
    /// `attached_positions` (see [`OrganSim::energy`]).
    settled: Option<f64>,
    attached_positions: Vec<DVec3>,
    /// Per particle, its UV scaled to lengths of the bud (see
    /// [`OrganSim::locality`]).
    scaled_uv: Vec<DVec2>,
    /// `Some` for an organ of a two-state template: kinematic, its shape at
    /// each keyframe the two-state in-between (template frame), placed;
    /// not grown, not solved, never pushed (see [`OrganSim::is_kinematic`]).
    two_state: Option<TwoState>,
}

/// What an organ carries from the end of one keyframe into the next: with
/// the project's inputs for the later steps, all a run needs to go on from
/// there (the solver keeps nothing across keyframes, and growth recomputes
/// stiffness, rates and the membrane from these).
#[derive(Clone)]
pub(crate) struct OrganState {
    positions: Arc<Vec<DVec3>>,
    rest_lengths: Vec<f64>,
    rest_angles: Vec<f64>,
    rotation_guess: DQuat,
    history: VecDeque<Arc<Vec<DVec3>>>,
}

impl OrganState {
    /// Bytes this state holds beyond what earlier states share with it.
    pub fn bytes(&self) -> usize {
        std::mem::size_of::<DVec3>() * self.positions.len()
            + std::mem::size_of::<f64>() * (self.rest_lengths.len() + self.rest_angles.len())
    }
}

impl OrganSim {
    pub fn new(
        organ: &Organ,
        template: &Template,
        settings: &anthesis_flower::SimulationSettings,
    ) -> Result<OrganSim, SimError> {
        let bad = |message: String| SimError::BadTemplate {
            template: template.name.clone(),
            message,
        };
        let topology =
            anthesis_mesh::validate(&template.mesh).map_err(|error| SimError::BadMesh {
                template: template.name.clone(),
                error,
            })?;
        // The same rules as loading and `anthesis info`.
        if let Some(problem) = template.problem() {
            return Err(bad(problem));
        }
        let base = template.base_region.particles(&template.mesh);
        let initial: Vec<DVec3> = template
            .mesh
            .positions
            .iter()
            .map(|p| organ.placement.world_from_template(*p, 0.0))
            .collect();
        let mut elastic = Elastic::at_rest(&initial, &topology);
        if settings.model.smoothed_membrane() {
            elastic.membrane = Some(EdgeSmoothedMembrane::new(
                &template.mesh.triangles,
                &topology,
            ));
        }
        let mean_edge =
            elastic.rest_lengths.iter().sum::<f64>() / elastic.rest_lengths.len().max(1) as f64;
        let solver = NewtonSolver::new(initial.len(), &elastic).map_err(|e| bad(e.to_string()))?;
        let keys = template
            .maps
            .keys()
            .iter()
            .map(|k| SampledKey::new(&k.maps, &template.mesh, &topology))
            .collect();
        let key_dg = key_growth_scales(template);
        let two_state = match &template.two_state {
            None => None,
            Some(animation) => {
                let mut two = TwoState::new(&template.mesh, &animation.open, &base)
                    .map_err(|e| bad(format!("two_state: {e}")))?;
                two.growth = animation.growth;
                two.velocity = animation.velocity.clone();
                Some(two)
            }
        };
        let mut sim = OrganSim {
            two_state,
            name: organ.name.clone(),
            colour: template.colour,
            mesh: template.mesh.clone(),
            positions: initial.clone(),
            initial,
            mean_edge,
            bud_edge: mean_edge,
            is_base: (0..template.mesh.vertex_count() as u32)
                .map(|i| base.contains(&i))
                .collect(),
            rings: TriangleRings::new(&template.mesh.triangles, template.mesh.vertex_count()),
            rim: topology.boundary_vertices(template.mesh.vertex_count()),
            rim_edges: crate::collide::rim_edges(&template.mesh.triangles),
            near_base: {
                let mut near = vec![false; template.mesh.vertex_count()];
                base.iter().for_each(|&k| near[k as usize] = true);
                for _ in 0..NEAR_BASE_RINGS {
                    let before = near.clone();
                    for t in &template.mesh.triangles {
                        if t.iter().any(|&k| before[k as usize]) {
                            t.iter().for_each(|&k| near[k as usize] = true);
                        }
                    }
                }
                near
            },
            placement: organ.placement,
            schedule: template.joint_schedule.clone(),
            base_current: Vec::with_capacity(base.len()),
            base_target: Vec::with_capacity(base.len()),
            base,
            key_schedule: template.maps.schedule(),
            keys,
            key_dg,
            model: settings.model,
            growth_model: GrowthModel {
                thickness: template.thickness,
                bend_rule: settings.model.bend_rule(),
                bend_base: settings.bend_base,
                length_base: settings.length_base,
            },
            modulus: Vec::new(),
            triangle_areas: Vec::new(),
            edge_areas: Vec::new(),
            stretch_stiffness: template.stretch_stiffness,
            bend_stiffness: template.bend_stiffness,
            elastic,
            growth: RegionalGrowth::default(),
            solver,
            rates: Vec::new(),
            rotation_guess: DQuat::IDENTITY,
            history: VecDeque::with_capacity(3),
            previous_normals: OnceLock::new(),
            saved: None,
            settled: None,
            attached_positions: Vec::new(),
            scaled_uv: scaled_uvs(&template.mesh, &topology),
            topology,
        };
        sim.update_stiffness(0);
        Ok(sim)
    }

    /// Regional growth for `step`: new rest lengths, rest angles and
    /// stiffness from the current shape and the maps blended at `step`;
    /// then the keyframe's start (see [`OrganSim::predict`]), attached to
    /// the receptacle at `step`.
    pub fn grow(&mut self, step: u32) {
        if self.two_state.is_some() {
            self.move_to(step);
            return;
        }
        self.mean_edge = self.elastic.rest_lengths.iter().sum::<f64>()
            / self.elastic.rest_lengths.len().max(1) as f64;
        let weights = self.key_schedule.weights_at(f64::from(step));
        // Each key's growth values times its growth scale, blended: a key
        // with its own (negative) dg shrinks the organ as it takes over.
        let keys = weights.map(|(k, w)| (&self.keys[k], w * self.key_dg[k], w));
        self.rates.clear();
        self.rates.extend((0..self.mesh.triangles.len()).map(|t| {
            let blend = |values: fn(&SampledKey) -> &Vec<f64>| -> f64 {
                keys.iter()
                    .map(|&(key, scale, _)| scale * values(key)[t])
                    .sum()
            };
            GrowthRates {
                e: 1.0 + blend(|k| &k.e),
                w: 1.0 + blend(|k| &k.w),
                e_in: 1.0 + blend(|k| &k.e_in),
                w_in: 1.0 + blend(|k| &k.w_in),
                direction_in_uv: keys.iter().map(|&(key, _, w)| key.direction[t] * w).sum(),
            }
        }));
        self.growth.grow(
            &self.positions,
            &self.mesh.uvs,
            &self.mesh.triangles,
            &self.topology,
            &self.rates,
            &self.growth_model,
            &mut self.elastic.rest_lengths,
            &mut self.elastic.rest_angles,
        );
        self.update_stiffness(step);
        self.solver.begin_keyframe();
        self.predict(step);
    }

    /// Whether this organ is kinematic (a two-state template): its
    /// positions are set by [`OrganSim::grow`] and nothing else moves them.
    /// Growing organs get contacts against it as against any organ, it
    /// gets none (it never gives way), like the parts in `obstacle.rs`.
    pub fn is_kinematic(&self) -> bool {
        self.two_state.is_some()
    }

    /// A kinematic organ's shape at `step`: the two-state in-between at
    /// time `step` (keyframes), placed by the placement and the joint
    /// schedule like any organ.
    fn move_to(&mut self, step: u32) {
        let Some(two) = &self.two_state else {
            return;
        };
        let extra = joint_angle_after(&self.schedule, step);
        self.positions = two
            .shape_at(f64::from(step))
            .into_iter()
            .map(|p| self.placement.world_from_template(p, extra))
            .collect();
        let (sum, count) = self
            .topology
            .edges
            .iter()
            .map(|e| {
                let [a, b] = e.vertices;
                self.positions[a as usize].distance(self.positions[b as usize])
            })
            .fold((0.0, 0usize), |(s, n), d| (s + d, n + 1));
        if count > 0 {
            self.mean_edge = sum / count as f64;
        }
    }

    /// Starts the keyframe from the shape extrapolated through the last
    /// three keyframes (quadratic; linear after the first), not from the
    /// last keyframe: growth is smooth from step to step, so the
    /// extrapolated shape lies much nearer the new minimum and Newton needs
    /// fewer iterations and factorisations (measured on the benchmark
    /// fixtures: 371 -> 162 iterations for one petal). The minimum it
    /// converges to meets the same tolerance; the difference to starting from
    /// the last keyframe is of the size a tenfold tighter tolerance makes.
    /// A prediction that has more energy than the last keyframe's shape (a
    /// snap-through extrapolated too far, a collapsed triangle) is dropped.
    /// Either start is then attached ([`OrganSim::attach`]); the prediction
    /// is weighed where it will be attached, so that the solver's first
    /// step, which starts there, takes its energy and gradient from this
    /// evaluation ([`NewtonSolver::evaluate_start`]; the elastic energy
    /// does not see the rigid motion).
    fn predict(&mut self, step: u32) {
        let latest = self
            .saved
            .take()
            .unwrap_or_else(|| Arc::new(self.positions.clone()));
        if self.history.len() == 3 {
            self.history.pop_front();
        }
        self.history.push_back(latest);
        self.previous_normals = OnceLock::new();
        let h = &self.history;
        let predicted: Vec<DVec3> = match h.len() {
            3 => (0..self.positions.len())
                .map(|i| 3.0 * h[2][i] - 3.0 * h[1][i] + h[0][i])
                .collect(),
            2 => (0..self.positions.len())
                .map(|i| 2.0 * h[1][i] - h[0][i])
                .collect(),
            _ => {
                self.attach(step);
                return;
            }
        };
        // Elastic energy only: the anchors still hold last keyframe's
        // targets.
        let now = self.elastic.elastic_energy(&self.positions);
        let (attached, rotation) = self.attached(predicted, step);
        let guess = self.solver.evaluate_start(&self.elastic, &attached);
        if guess <= now {
            self.positions = attached;
            self.rotation_guess = rotation;
            self.settled = None;
        } else {
            self.attach(step);
        }
    }

    fn update_stiffness(&mut self, step: u32) {
        let weights = self.key_schedule.weights_at(f64::from(step.max(1)));
        edge_areas_into(
            &self.positions,
            &self.mesh.triangles,
            &self.topology,
            &mut self.triangle_areas,
            &mut self.edge_areas,
        );
        self.modulus.resize(self.edge_areas.len(), 0.0);
        for (e, area) in self.edge_areas.iter().enumerate() {
            let stretch: f64 = weights
                .iter()
                .map(|&(k, w)| w * self.keys[k].stretch[e])
                .sum();
            let bend: f64 = weights.iter().map(|&(k, w)| w * self.keys[k].bend[e]).sum();
            self.elastic.stretch_stiffness[e] = area * self.stretch_stiffness * stretch;
            self.elastic.bend_stiffness[e] = self.model.hinge_stiffness(
                self.bend_stiffness * bend,
                self.elastic.rest_lengths[e],
                *area,
                self.bud_edge,
            );
            self.modulus[e] =
                Model::membrane_modulus(self.stretch_stiffness * stretch, self.bud_edge);
        }
        let mean_ks = self.elastic.stretch_stiffness.iter().sum::<f64>()
            / self.elastic.stretch_stiffness.len().max(1) as f64;
        if let Some(m) = &mut self.elastic.membrane {
            m.update(&self.elastic.rest_lengths, &self.modulus);
        }
        self.elastic.contact_stiffness = CONTACT_STIFFNESS_FACTOR * mean_ks;
        self.elastic.anchor_stiffness = ANCHOR_FACTOR * mean_ks;
    }

    /// This organ's surface as collisions see it, with its unit normals.
    pub fn surface<'a>(&'a self, normals: &'a [DVec3]) -> Surface<'a> {
        Surface {
            positions: &self.positions,
            normals,
            triangles: &self.mesh.triangles,
            rings: &self.rings,
            rim: &self.rim,
            mean_edge: self.mean_edge,
        }
    }

    /// The organ's rim edges, each `[low, high]`, sorted.
    pub fn rim_edges(&self) -> &[[u32; 2]] {
        &self.rim_edges
    }

    /// Whether each particle is a base particle or shares a triangle with
    /// one (no rim contacts there).
    pub fn near_base(&self) -> &[bool] {
        &self.near_base
    }

    /// Which of this organ's particles are each other's neighbourhood,
    /// where self-contact does not act: those less than
    /// [`SELF_CONTACT_LOCAL`] bud edges apart in the UV layout scaled to
    /// the bud's lengths (growth stretches distances and the mean edge
    /// alike, so this stays about that many edges along the surface).
    pub fn locality(&self) -> Locality<'_> {
        Locality {
            uv: &self.scaled_uv,
            local: SELF_CONTACT_LOCAL * self.bud_edge,
        }
    }

    /// Positions at the end of the last keyframe (during a step: before
    /// it; the bud before the first), if the organ has been grown.
    pub fn previous(&self) -> Option<&[DVec3]> {
        self.history.back().map(|p| p.as_slice())
    }

    /// The vertex normals of [`OrganSim::previous`].
    pub fn previous_normals(&self) -> Option<&[DVec3]> {
        let previous = self.previous()?;
        Some(
            self.previous_normals
                .get_or_init(|| anthesis_mesh::vertex_normals(previous, &self.mesh.triangles)),
        )
    }

    /// One Newton iteration with the base held where the receptacle and the
    /// joint schedule put it.
    pub fn iterate(
        &mut self,
        step: u32,
        contacts: &[Contact],
        settings: &SolverSettings,
    ) -> Result<StepReport, SolverError> {
        if self.is_kinematic() {
            return Ok(StepReport {
                energy_before: 0.0,
                energy_after: 0.0,
                relative_gradient: 0.0,
                converged: true,
                step_fraction: 0.0,
            });
        }
        self.hold_base(step);
        self.solver
            .step(&self.elastic, contacts, &mut self.positions, settings)
    }

    /// Newton iterations against the fixed `contacts` until this organ
    /// converges, fails, has taken `settings.max_iterations`, or `cancel`
    /// says stop (polled before each iteration).
    pub fn settle(
        &mut self,
        step: u32,
        contacts: &[Contact],
        settings: &SolverSettings,
        cancel: &(dyn Fn() -> bool + Sync),
    ) -> Settled {
        let mut gradients = Vec::new();
        for _ in 0..settings.max_iterations {
            if cancel() {
                return Settled {
                    gradients,
                    outcome: Settle::Cancelled,
                };
            }
            match self.iterate(step, contacts, settings) {
                Err(error) => {
                    return Settled {
                        gradients,
                        outcome: Settle::Failed(error),
                    };
                }
                Ok(report) => {
                    gradients.push(report.relative_gradient);
                    if report.converged {
                        return Settled {
                            gradients,
                            outcome: Settle::Converged,
                        };
                    }
                }
            }
        }
        Settled {
            gradients,
            outcome: Settle::NotConverged,
        }
    }

    /// Anchors each base particle where the receptacle and the joint
    /// schedule put it at `step` (see ANCHOR_FACTOR).
    fn hold_base(&mut self, step: u32) {
        let extra = joint_angle_after(&self.schedule, step);
        self.elastic.anchors.clear();
        for &b in &self.base {
            let target = self
                .placement
                .world_from_template(self.mesh.positions[b as usize], extra);
            self.elastic.anchors.push((b, target));
        }
    }

    /// Applies to the whole organ the rigid motion that best carries its
    /// base particles onto their places on the receptacle at `step`.
    pub fn attach(&mut self, step: u32) {
        if self.is_kinematic() {
            return;
        }
        self.settled = self.solver.converged_elastic_energy(&self.positions);
        let positions = std::mem::take(&mut self.positions);
        (self.positions, self.rotation_guess) = self.attached(positions, step);
        self.attached_positions.clone_from(&self.positions);
    }

    /// `positions` moved as [`OrganSim::attach`] moves the organ's, with
    /// the rotation found (the next rotation guess).
    fn attached(&mut self, mut positions: Vec<DVec3>, step: u32) -> (Vec<DVec3>, DQuat) {
        let extra = joint_angle_after(&self.schedule, step);
        self.base_current.clear();
        self.base_target.clear();
        for &b in &self.base {
            self.base_current.push(positions[b as usize]);
            self.base_target.push(
                self.placement
                    .world_from_template(self.mesh.positions[b as usize], extra),
            );
        }
        let transform = match_shape(&self.base_current, &self.base_target, self.rotation_guess);
        for p in &mut positions {
            *p = transform.apply(*p);
        }
        (positions, transform.rotation)
    }

    pub fn factorisations(&self) -> u64 {
        self.solver.factorisations()
    }

    /// Takes the time keys, joint schedule and colour of `new`, an edit of
    /// `old` (the template this organ was made from or last took) with the
    /// same mesh. Keys whose maps are unchanged keep their samples.
    pub fn take_maps(&mut self, old: &Template, new: &Template) {
        let mut kept: Vec<Option<SampledKey>> = std::mem::take(&mut self.keys)
            .into_iter()
            .map(Some)
            .collect();
        let old_keys = old.maps.keys();
        self.keys = new
            .maps
            .keys()
            .iter()
            .map(|key| {
                old_keys
                    .iter()
                    .position(|o| o.maps == key.maps)
                    .and_then(|i| kept.get_mut(i).and_then(Option::take))
                    .unwrap_or_else(|| SampledKey::new(&key.maps, &self.mesh, &self.topology))
            })
            .collect();
        self.key_dg = key_growth_scales(new);
        self.key_schedule = new.maps.schedule();
        self.schedule.clone_from(&new.joint_schedule);
        self.colour = new.colour;
    }

    /// The state a later run can go on from (see [`OrganState`]).
    pub fn save(&mut self) -> OrganState {
        let positions = Arc::new(self.positions.clone());
        self.saved = Some(Arc::clone(&positions));
        OrganState {
            positions,
            rest_lengths: self.elastic.rest_lengths.clone(),
            rest_angles: self.elastic.rest_angles.clone(),
            rotation_guess: self.rotation_guess,
            history: self.history.clone(),
        }
    }

    /// Puts this organ back in `state`, saved by [`OrganSim::save`] from an
    /// organ of the same mesh.
    pub fn restore(&mut self, state: &OrganState) {
        self.settled = None;
        self.positions.clone_from(&state.positions);
        self.saved = Some(Arc::clone(&state.positions));
        self.elastic.rest_lengths.clone_from(&state.rest_lengths);
        self.elastic.rest_angles.clone_from(&state.rest_angles);
        self.rotation_guess = state.rotation_guess;
        self.history.clone_from(&state.history);
        self.previous_normals = OnceLock::new();
    }

    /// The elastic energy (0 for a kinematic organ, which has none: its
    /// shape is given, not solved).
    pub fn energy(&self) -> f64 {
        if self.is_kinematic() {
            return 0.0;
        }
        match self.settled {
            // Where the organ was attached from the shape its solver
            // converged at (the end of a keyframe), the elastic part is
            // the solver's (attaching moves the organ rigidly, which the
            // elastic energy does not see; the two differ by rounding).
            Some(elastic) if same_bits(&self.positions, &self.attached_positions) => self
                .elastic
                .add_penalty_energy(&self.positions, &[], elastic),
            _ => self.elastic.energy(&self.positions, &[]),
        }
    }

    /// An energy below which changes are noise: a billionth of the energy of
    /// all edges at 100 % strain.
    pub fn energy_floor(&self) -> f64 {
        let full: f64 = self
            .elastic
            .stretch_stiffness
            .iter()
            .zip(&self.elastic.rest_lengths)
            .map(|(k, l)| 0.5 * k * l * l)
            .sum();
        1e-9 * full
    }

    pub fn relative_gradient(&mut self, contacts: &[Contact]) -> f64 {
        if self.is_kinematic() {
            return 0.0;
        }
        self.solver
            .relative_gradient(&self.elastic, contacts, &self.positions)
    }
}

/// How far apart along the surface, in bud edges, two particles of one
/// organ must be for self-contact to hold them apart: beyond the reach of
/// a contact search (two mean edges) and of the triangles searched around
/// the nearest particle (two rings), so a surface is never held off
/// itself where it is merely curved.
pub const SELF_CONTACT_LOCAL: f64 = 6.0;

/// Each particle's UV scaled by the lengths the bud gives a unit of `u`
/// and of `v` (least squares over the edges: |edge|² ≈ a Δu² + b Δv²), so
/// that distances between UVs are about distances along the bud's surface.
fn scaled_uvs(mesh: &Mesh, topology: &Topology) -> Vec<DVec2> {
    let (mut uuuu, mut uuvv, mut vvvv, mut lu, mut lv, mut ll, mut uv2) =
        (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for e in &topology.edges {
        let [a, b] = e.vertices.map(|v| v as usize);
        let d = mesh.uvs[a] - mesh.uvs[b];
        let (u2, v2) = (d.x * d.x, d.y * d.y);
        let l2 = mesh.positions[a].distance_squared(mesh.positions[b]);
        uuuu += u2 * u2;
        uuvv += u2 * v2;
        vvvv += v2 * v2;
        lu += l2 * u2;
        lv += l2 * v2;
        ll += l2;
        uv2 += u2 + v2;
    }
    let det = uuuu * vvvv - uuvv * uuvv;
    let (a, b) = if det > 1e-12 * uuuu * vvvv {
        ((lu * vvvv - lv * uuvv) / det, (lv * uuuu - lu * uuvv) / det)
    } else {
        (0.0, 0.0)
    };
    let (a, b) = if a > 0.0 && b > 0.0 {
        (a, b)
    } else {
        let isotropic = if uv2 > 0.0 { ll / uv2 } else { 1.0 };
        (isotropic, isotropic)
    };
    let scale = DVec2::new(a.sqrt(), b.sqrt());
    mesh.uvs.iter().map(|uv| *uv * scale).collect()
}

#[cfg(test)]
mod tests {
    use crate::fixtures::whorl;
    use crate::{Selection, Simulation};
    use anthesis_physics::solver::same_bits;

    #[test]
    fn a_settled_organs_energy_is_its_solvers_up_to_rounding() {
        // Organs that end their keyframes where their solvers converged,
        // attached: the elastic part is reused, to rounding.
        let project = whorl(4, 6, 10, 6);
        let mut sim = Simulation::new(&project, &Selection::All).expect("valid");
        let (mut reused, mut evaluated) = (0, 0);
        for _ in 0..6 {
            let keyframe = sim.step(&|| false, &mut |_| {}).expect("a keyframe");
            let mut sum = 0.0;
            for organ in &sim.organs {
                let full = organ.elastic.energy(&organ.positions, &[]);
                let energy = organ.energy();
                assert!(
                    (energy - full).abs() <= 1e-12 * full.abs(),
                    "{energy} against {full}"
                );
                if organ.settled.is_some() && same_bits(&organ.positions, &organ.attached_positions)
                {
                    reused += 1;
                } else {
                    assert_eq!(energy.to_bits(), full.to_bits());
                    evaluated += 1;
                }
                sum += energy;
            }
            assert_eq!(keyframe.stats.energy.to_bits(), sum.to_bits());
        }
        assert_eq!((reused, evaluated), (24, 0));
        // A particle moved since (a push-back): evaluated again.
        let organ = &mut sim.organs[0];
        organ.positions[3].z += 1e-3;
        let full = organ.elastic.energy(&organ.positions, &[]);
        assert_eq!(organ.energy().to_bits(), full.to_bits());
    }
}

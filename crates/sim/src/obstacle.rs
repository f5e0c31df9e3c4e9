//! The parts growing organs are kept out of (stamens, pistils, the pedicel:
//! [`anthesis_flower::parts::obstacles`]). They do not grow and are not
//! solved: each keyframe puts them where their schedule says, and every
//! organ particle near one gets a contact that keeps it outside (the parts
//! are closed surfaces with outward normals, so no overlap order is
//! needed). Like organ contacts they act on particles: a part thinner
//! than an organ's edges can pass between its particles.

use anthesis_flower::parts::PartPiece;
use anthesis_mesh::nearest::TriangleRings;
use glam::DVec3;

use crate::collide::{Surface, Tracker};

/// One obstacle at the pose of one step.
pub(crate) struct ObstacleSim {
    source: PartPiece,
    /// Which step the positions are for.
    step: Option<u32>,
    positions: Vec<DVec3>,
    /// Outward unit normals (the side organs belong on).
    normals: Vec<DVec3>,
    rings: TriangleRings,
    rim: Vec<bool>,
    mean_edge: f64,
    tracker: Tracker,
    /// Bounds of the positions, grown by the tracker's reach.
    lo: DVec3,
    hi: DVec3,
}

impl ObstacleSim {
    pub(crate) fn new(source: PartPiece) -> ObstacleSim {
        let mesh = &source.mesh;
        let rings = TriangleRings::new(&mesh.triangles, mesh.vertex_count());
        let (sum, count) = mesh
            .triangles
            .iter()
            .flat_map(|t| {
                [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]
                    .map(|(a, b)| mesh.positions[a as usize].distance(mesh.positions[b as usize]))
            })
            .fold((0.0, 0usize), |(s, n), d| (s + d, n + 1));
        let mean_edge = if count > 0 { sum / count as f64 } else { 1.0 };
        let rim = vec![false; mesh.vertex_count()];
        ObstacleSim {
            source,
            step: None,
            positions: Vec::new(),
            normals: Vec::new(),
            rings,
            rim,
            mean_edge,
            tracker: Tracker::new(&[], 1.0),
            lo: DVec3::ZERO,
            hi: DVec3::ZERO,
        }
    }

    /// Puts the obstacle where its schedule has it at `step`.
    pub(crate) fn move_to(&mut self, step: u32) {
        if self.step == Some(step) {
            return;
        }
        self.step = Some(step);
        self.positions = self.source.positions_at(step);
        self.normals = anthesis_mesh::vertex_normals(&self.positions, &self.source.mesh.triangles);
        let reach = self.reach();
        self.tracker = Tracker::new(&self.positions, reach);
        let (lo, hi) = self.positions.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        self.lo = lo - DVec3::splat(reach);
        self.hi = hi + DVec3::splat(reach);
    }

    /// Takes `piece`, this part edited: the same shape and place (an edit
    /// that changes them starts the run over, see `resume`), perhaps
    /// another schedule from a later step on, name or colour. With another
    /// schedule it is put again at the next step, where a run from the bud
    /// has it.
    pub(crate) fn take(&mut self, piece: PartPiece) {
        if piece.schedule != self.source.schedule {
            self.step = None;
        }
        self.source = piece;
    }

    /// How far from its nearest vertex a particle is looked at.
    fn reach(&self) -> f64 {
        2.0 * self.mean_edge
    }

    /// Whether `p` lies in the obstacle's box grown by the reach: only
    /// such particles can get a contact.
    pub(crate) fn reaches(&self, p: DVec3) -> bool {
        p.cmpge(self.lo).all() && p.cmple(self.hi).all()
    }

    pub(crate) fn surface(&self) -> Surface<'_> {
        Surface {
            positions: &self.positions,
            normals: &self.normals,
            triangles: &self.source.mesh.triangles,
            rings: &self.rings,
            rim: &self.rim,
            mean_edge: self.mean_edge,
        }
    }

    /// The piece's name (a part instance's, `-anther` or `-stigma` added
    /// for a head).
    pub(crate) fn name(&self) -> &str {
        &self.source.name
    }

    pub(crate) fn tracker(&self) -> &Tracker {
        &self.tracker
    }
}

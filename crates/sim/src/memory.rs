//! How much memory a run needs, estimated from the organs' sizes before it
//! starts, so that a run too large for the machine is refused with a
//! message instead of being killed by the kernel part way (a flower with a
//! 2-million-triangle mesh was killed at 23.8 GB with no message).
//!
//! The model is fitted to peak resident memory (`/usr/bin/time -v`,
//! "Maximum resident set size") of one-organ runs of the generated petal,
//! 702 to 128,522 triangles, on the 2-core Debian 12 machine (release
//! build; `examples/memory_probe.rs` says how):
//!
//! | triangles | measured | model |
//! | ---: | ---: | ---: |
//! | 702 | 5.9 MiB | 6.0 MiB |
//! | 2,970 | 13.8 MiB | 13.7 MiB |
//! | 7,832 | 33.3 MiB | 33.4 MiB |
//! | 16,002 | 71.4 MiB | 70.2 MiB |
//! | 31,862 | 143.0 MiB | 148.0 MiB |
//! | 64,770 | 325.0 MiB | 322.6 MiB |
//! | 128,522 | 693.8 MiB | 686.0 MiB |
//! | 260,610 (not fitted) | 1497.6 MiB | 1491.6 MiB |
//!
//! Each organ holds its own solver (4 organs of 7,832 triangles took
//! 122.6 MiB, 2 of 31,862 took 283.1 MiB: the organs add up), and the
//! sparse Cholesky factor of a surface mesh fills in like `n log n`, so an
//! organ of `t` triangles takes `t (a + b log2 t)` bytes; `a` and `b` are
//! the least-squares fit (weighted by 1 / measured) of the first seven
//! rows; the last, twice the largest fitted size, was measured afterwards
//! as a check (0.4 % off).
//! Keyframes kept cost a measured number of bytes per particle and
//! keyframe that depends on what is written (see [`KeyframeCost`]).

use std::fmt;

use anthesis_files::human_bytes;
use anthesis_flower::Project;

use crate::Selection;

/// Bytes per triangle of an organ's solver, constant part (fitted).
const SOLVER_BYTES_PER_TRIANGLE: f64 = -1458.9;
/// Bytes per triangle of an organ's solver, times `log2` of the organ's
/// triangle count (fitted).
const SOLVER_BYTES_PER_TRIANGLE_LOG2: f64 = 413.7;
/// What a run takes besides its organs: the program, its threads, the
/// project (fitted; the command line measured 7 MiB more, see
/// [`KeyframeCost`]).
const BASE_BYTES: f64 = 4.5 * 1024.0 * 1024.0;

/// Bytes each kept keyframe costs per particle, by what the run keeps them
/// for. Measured with `anthesis simulate` on one organ of 4,050 particles,
/// 1 and 80 keyframes (peak RSS difference over 79 keyframes): keeping
/// them only took 27 bytes per particle and keyframe, writing a .glb 115,
/// OBJ files 48, a .usda 356. Rounded up here.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KeyframeCost {
    /// Kept as positions (statistics only).
    Kept,
    /// Kept as positions with the state each keyframe ends in, so an edit
    /// goes on from the first keyframe it changes (the app's runs; see
    /// [`crate::Simulation::keep_checkpoints`]).
    Editable,
    /// Written to a .glb.
    Glb,
    /// Written as OBJ files.
    Obj,
    /// Written to a USD text layer.
    Usd,
}

impl KeyframeCost {
    fn bytes_per_particle(self) -> u64 {
        match self {
            KeyframeCost::Kept => 32,
            // The checkpoint holds the positions (24 bytes) and two
            // numbers per edge, about three edges per particle (48 bytes);
            // tested against what a run keeps.
            KeyframeCost::Editable => 32 + 80,
            KeyframeCost::Glb => 128,
            KeyframeCost::Obj => 64,
            KeyframeCost::Usd => 384,
        }
    }
}

/// The memory a run is expected to need at its peak.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MemoryEstimate {
    /// Triangles of the simulated organs, added up.
    pub triangles: u64,
    /// The organs' solvers and state.
    pub solver_bytes: u64,
    /// The keyframes kept, the bud included.
    pub keyframes: u64,
    /// The memory those keyframes take, in bytes.
    pub keyframe_bytes: u64,
    /// Everything: the two above and the program itself.
    pub bytes: u64,
}

impl fmt::Display for MemoryEstimate {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "about {} ({} for the solver of {} triangles, {} for {} keyframes)",
            human_bytes(self.bytes),
            human_bytes(self.solver_bytes),
            self.triangles,
            human_bytes(self.keyframe_bytes),
            self.keyframes
        )
    }
}

/// The memory a run of the organs of `project` in `selection` needs, with
/// its keyframes kept as `cost` says; at the project's resolution (the
/// remeshed meshes' sizes predicted from their areas when the project sets
/// a mean edge and has not been resolved yet).
pub fn estimate(project: &Project, selection: &Selection, cost: KeyframeCost) -> MemoryEstimate {
    let flower = &project.flower;
    let mut solver_bytes = 0u64;
    let mut triangles = 0u64;
    let mut particles = 0u64;
    for organ in selection.organs(flower.organs.len()) {
        if organ >= flower.organs.len() {
            continue;
        }
        // A project not yet resolved to its resolution counts the meshes it
        // will be remeshed into (`anthesis_flower::resolution`), so that a
        // too-fine edge is refused before anything is remeshed.
        let mesh = &flower.template_of(organ).mesh;
        let (organ_particles, organ_triangles) = match project.settings.resolution.mean_edge() {
            Some(edge) => anthesis_flower::resolution::predicted_size(mesh, edge),
            None => (mesh.vertex_count(), mesh.triangle_count()),
        };
        solver_bytes = solver_bytes.saturating_add(organ_solver_bytes(organ_triangles));
        triangles += organ_triangles as u64;
        particles += organ_particles as u64;
    }
    let keyframes = u64::from(project.settings.keyframes) + 1;
    let keyframe_bytes = keyframes
        .saturating_mul(particles)
        .saturating_mul(cost.bytes_per_particle());
    MemoryEstimate {
        triangles,
        solver_bytes,
        keyframes,
        keyframe_bytes,
        bytes: (BASE_BYTES as u64)
            .saturating_add(solver_bytes)
            .saturating_add(keyframe_bytes),
    }
}

/// The solver's bytes for one organ of `triangles` triangles.
fn organ_solver_bytes(triangles: usize) -> u64 {
    let t = triangles as f64;
    let per_triangle =
        SOLVER_BYTES_PER_TRIANGLE + SOLVER_BYTES_PER_TRIANGLE_LOG2 * t.max(1.0).log2();
    // The fit holds from 702 triangles up; below, the base dominates.
    (t * per_triangle.max(0.0)) as u64
}

/// Memory the system can give a new run now: `MemAvailable` of
/// `/proc/meminfo` (Linux), or `None` where that cannot be read.
pub fn available_bytes() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    parse_mem_available(&meminfo)
}

fn parse_mem_available(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line
        .trim_start_matches("MemAvailable:")
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kib.saturating_mul(1024))
}

/// The environment variable that caps the memory a run may take, in MiB
/// (for machines shared with other work); the system's available memory
/// caps it anyway.
pub const LIMIT_VARIABLE: &str = "ANTHESIS_MEMORY_LIMIT_MIB";

/// Why a run may not start.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum MemoryError {
    /// The run's estimated peak memory is more than the memory allowed.
    #[error(transparent)]
    TooLarge(#[from] TooLarge),
    /// [`LIMIT_VARIABLE`] is set but is not a whole number of MiB above 0;
    /// holds an escaped excerpt of its value.
    #[error("{LIMIT_VARIABLE} must be a whole number of MiB above 0, found {0}")]
    BadLimit(String),
}

/// The memory a new run may take: what the system has available now,
/// capped by [`LIMIT_VARIABLE`]; `None` when neither is known.
pub fn allowed_bytes() -> Result<Option<u64>, MemoryError> {
    let limit = match std::env::var(LIMIT_VARIABLE) {
        Ok(text) => Some(
            text.trim()
                .parse::<u64>()
                .ok()
                .filter(|&mib| mib > 0)
                .ok_or_else(|| MemoryError::BadLimit(anthesis_files::excerpt(&text, 40)))?
                .saturating_mul(1 << 20),
        ),
        Err(_) => None,
    };
    Ok([available_bytes(), limit].into_iter().flatten().min())
}

/// Refuses, before anything is built, a run of `project` whose estimated
/// peak memory is more than [`allowed_bytes`]: the kernel would kill it
/// part way. The one check the command line and the window apply.
pub fn check_run(
    project: &Project,
    selection: &Selection,
    cost: KeyframeCost,
) -> Result<(), MemoryError> {
    if let Some(allowed) = allowed_bytes()? {
        check(estimate(project, selection, cost), allowed)?;
    }
    Ok(())
}

/// A run that would not fit in memory.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "this run needs {estimate}, but only {} of memory is available; simulate fewer organs \
     (one organ alone) or keyframes, or use a coarser mesh",
    human_bytes(*.available)
)]
pub struct TooLarge {
    /// What the run is expected to need.
    pub estimate: MemoryEstimate,
    /// The memory allowed, in bytes (available now, capped by
    /// [`LIMIT_VARIABLE`]).
    pub available: u64,
}

/// Refuses a run whose estimate exceeds `available` bytes.
pub fn check(estimate: MemoryEstimate, available: u64) -> Result<(), TooLarge> {
    if estimate.bytes > available {
        return Err(TooLarge {
            estimate,
            available,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::whorl;

    #[test]
    fn the_model_matches_the_measurements_it_was_fitted_to() {
        // (triangles, measured peak in KiB): the table of the module notes.
        let measured = [
            (702, 6084),
            (2970, 14112),
            (7832, 34124),
            (16002, 73120),
            (31862, 146420),
            (64770, 332848),
            (128522, 710424),
            // Measured after the fit, twice the largest fitted size.
            (260610, 1533500),
        ];
        for (triangles, kib) in measured {
            let model = BASE_BYTES + organ_solver_bytes(triangles) as f64;
            let measured = f64::from(kib) * 1024.0;
            let error = (model - measured) / measured;
            assert!(error.abs() < 0.05, "{triangles} triangles: {error:+.3}");
        }
    }

    #[test]
    fn the_editable_cost_covers_what_checkpoints_hold() {
        let project = whorl(2, 12, 20, 6);
        let mut sim = crate::Simulation::new(&project, &Selection::All).expect("valid");
        sim.keep_checkpoints();
        while !sim.finished() {
            sim.step(&|| false, &mut |_| {}).expect("steps");
        }
        let particles: usize = (0..2)
            .map(|i| project.flower.template_of(i).mesh.vertex_count())
            .sum();
        let per_particle = sim.checkpoint_bytes() as f64 / (particles as f64 * 7.0);
        let allowed = (KeyframeCost::Editable.bytes_per_particle()
            - KeyframeCost::Kept.bytes_per_particle()) as f64;
        assert!(
            per_particle <= allowed && per_particle > 0.75 * allowed,
            "checkpoints hold {per_particle:.1} bytes per particle and keyframe, the estimate {allowed}"
        );
    }

    #[test]
    fn organs_and_keyframes_add_up() {
        let one = whorl(1, 28, 14, 10);
        let four = whorl(4, 28, 14, 10);
        let a = estimate(&one, &Selection::All, KeyframeCost::Kept);
        let b = estimate(&four, &Selection::All, KeyframeCost::Kept);
        assert_eq!(b.triangles, 4 * a.triangles);
        assert_eq!(b.solver_bytes, 4 * a.solver_bytes);
        assert_eq!(b.keyframe_bytes, 4 * a.keyframe_bytes);
        assert_eq!(a.keyframes, 11);
        assert_eq!(a.keyframe_bytes, 11 * 392 * 32);
        // One organ of four costs what one organ alone does.
        let only = estimate(&four, &Selection::Only(2), KeyframeCost::Kept);
        assert_eq!(only.solver_bytes, a.solver_bytes);
        // A .usda keeps more per keyframe than a .glb.
        let glb = estimate(&one, &Selection::All, KeyframeCost::Glb);
        let usd = estimate(&one, &Selection::All, KeyframeCost::Usd);
        assert!(usd.keyframe_bytes > glb.keyframe_bytes);
    }

    #[test]
    fn a_run_larger_than_the_memory_is_refused_with_the_numbers() {
        let project = whorl(2, 28, 14, 10);
        let estimate = estimate(&project, &Selection::All, KeyframeCost::Glb);
        assert_eq!(check(estimate, estimate.bytes), Ok(()));
        let error = check(estimate, estimate.bytes - 1).expect_err("too large");
        let message = error.to_string();
        assert!(message.starts_with("this run needs about "), "{message}");
        assert!(
            message.contains(&format!("solver of {} triangles", estimate.triangles)),
            "{message}"
        );
        assert!(message.contains("for 11 keyframes"), "{message}");
        assert!(message.contains("of memory is available"), "{message}");
    }

    #[test]
    fn a_mean_edge_counts_the_meshes_it_will_make() {
        use anthesis_flower::Resolution;
        let mut project = whorl(1, 28, 14, 10);
        let built = estimate(&project, &Selection::All, KeyframeCost::Kept);
        let edge = anthesis_bud::quality(&project.flower.templates[0].mesh).mean_edge / 2.0;
        project.settings.resolution = Resolution::MeanEdge(edge);
        let predicted = estimate(&project, &Selection::All, KeyframeCost::Kept);
        let resolved = anthesis_flower::resolution::resolve(&project).expect("remeshes");
        let actual = estimate(&resolved, &Selection::All, KeyframeCost::Kept);
        // The prediction is what the remesh makes, and half the edge
        // predicts four times the triangles.
        assert_ne!(predicted.triangles, built.triangles);
        project.settings.resolution = Resolution::MeanEdge(edge / 2.0);
        let finer = estimate(&project, &Selection::All, KeyframeCost::Kept);
        let ratio = finer.triangles as f64 / predicted.triangles as f64;
        assert!((ratio - 4.0).abs() < 0.2, "{ratio}");
        let off = predicted.triangles.abs_diff(actual.triangles) as f64 / actual.triangles as f64;
        // Within 30 % (the remeshed mean edge is within 10 % of the one
        // asked for, and triangles go as its inverse square; this small
        // petal has much outline); the run is checked again on the
        // remeshed meshes before it starts, so the prediction only has to
        // stop an edge that is far too fine before it is remeshed.
        assert!(off < 0.3, "predicted {predicted}, remeshed {actual}");
        // An edge that would make millions of particles is refused by the
        // estimate alone, before anything is remeshed.
        project.settings.resolution = Resolution::MeanEdge(edge / 200.0);
        let huge = estimate(&project, &Selection::All, KeyframeCost::Kept);
        assert!(huge.triangles > 10_000_000, "{huge}");
        assert!(check(huge, 8 << 30).is_err());
    }

    #[test]
    fn mem_available_is_read_in_bytes() {
        let meminfo = "MemTotal:       24557440 kB\nMemFree:         1000 kB\n\
                       MemAvailable:   20000000 kB\nBuffers: 1 kB\n";
        assert_eq!(parse_mem_available(meminfo), Some(20_000_000 * 1024));
        assert_eq!(parse_mem_available("MemTotal: 1 kB\n"), None);
        // This machine says something.
        assert!(available_bytes().is_some_and(|bytes| bytes > 0));
    }
}

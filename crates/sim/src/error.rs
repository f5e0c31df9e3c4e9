//! Why a run stops early, in words a painter can act on.

use anthesis_mesh::MeshError;
use anthesis_physics::SolverError;

use crate::crossing::Crossings;

/// Why a run stopped early. Each names the keyframe and organ involved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// A template's mesh fails validation, so the run does not start.
    #[error("template `{template}` has a bad mesh: {error}")]
    BadMesh {
        /// The template's name.
        template: String,
        /// What is wrong with its mesh.
        error: MeshError,
    },
    /// A template's parameters are out of range (e.g. a thickness of 0),
    /// or its solver could not be set up; the run does not start.
    #[error("template `{template}`: {message}")]
    BadTemplate {
        /// The template's name.
        template: String,
        /// Which value is wrong, or why the solver could not be set up.
        message: String,
    },
    /// A single organ was asked to be simulated by an index the project
    /// does not have.
    #[error("organ index {0} does not exist")]
    NoSuchOrgan(usize),
    /// The energy minimisation of one organ failed (see [`SolverError`]).
    #[error(
        "keyframe {keyframe}, organ `{organ}`: the solver diverged: {error}{}",
        held_against_note(held_against)
    )]
    Diverged {
        /// The keyframe being computed.
        keyframe: u32,
        /// The organ's name.
        organ: String,
        /// How the solver failed.
        error: SolverError,
        /// What the organ was held off in that keyframe (see
        /// [`held_against_note`]).
        held_against: Vec<String>,
    },
    /// An organ's energy became non-finite or rose more than a
    /// million-fold from the previous keyframe: growth too strong for the
    /// mesh or its stiffness.
    #[error(
        "keyframe {keyframe}, organ `{organ}`: the energy blew up to {energy:.3e} (from {previous:.3e}){}",
        held_against_note(held_against)
    )]
    EnergyBlowUp {
        /// The keyframe being computed.
        keyframe: u32,
        /// The organ's name.
        organ: String,
        /// Its elastic energy at this keyframe.
        energy: f64,
        /// Its elastic energy at the previous keyframe.
        previous: f64,
        /// What the organ was held off in that keyframe (see
        /// [`held_against_note`]).
        held_against: Vec<String>,
    },
    /// The organs did not settle within the solver's iteration limit
    /// (`max_iterations` per contact round); a higher limit or a looser
    /// tolerance may help.
    #[error(
        "keyframe {keyframe}, organ `{organ}`: not converged after {iterations} iterations (relative gradient {relative_gradient:.3e}){}",
        held_against_note(held_against)
    )]
    NotConverged {
        /// The keyframe being computed.
        keyframe: u32,
        /// The organ furthest from converging.
        organ: String,
        /// The Newton iterations taken in the keyframe, over all contact
        /// rounds.
        iterations: u32,
        /// That organ's relative gradient when the limit was reached (see
        /// [`KeyframeStats::relative_gradient`]).
        relative_gradient: f64,
        /// What the organ was held off in that keyframe (see
        /// [`held_against_note`]).
        held_against: Vec<String>,
    },
    /// Triangles of the keyframe cross: an organ passes through another,
    /// a part or itself (see [`crossing`]). The organs are left where that
    /// keyframe put them; the keyframes before it stay good.
    #[error("{0}; the keyframes before it are kept")]
    Crossed(Box<Crossings>),
    /// A bug: the simulation panicked. Caught so the worker and the
    /// command line survive it and keep what was computed before.
    #[error("{}", describe_panic(*.run, *.keyframe, .message))]
    Panicked {
        /// The worker's run, when the worker caught it.
        run: Option<u64>,
        /// The keyframe being computed, if the panic came from a step.
        keyframe: Option<u32>,
        /// The panic's message.
        message: String,
    },
    /// The caller asked the step to stop (a newer run replaced it); not a
    /// failure, and the keyframes before are kept.
    #[error("cancelled")]
    Cancelled,
}

/// What a run that stopped at an organ adds about what held it: a
/// painter whose petal curls around a sepal, or is pressed onto a stamen,
/// should learn which neighbours to look at. The contacts keep each organ
/// on its side of the others (the overlap order) and outside the parts; an
/// organ grown around another, or caught between neighbours and a part,
/// cannot be, and the solver then stops there.
pub fn held_against_note(held_against: &[String]) -> String {
    const CAUGHT: &str = ": organs grown around or caught between each other can stop a run";
    match held_against {
        [] => String::new(),
        [one] => format!("; it was against {one} there{CAUGHT}"),
        [init @ .., last] => format!(
            "; it was against {} and {last} there{CAUGHT}",
            init.join(", ")
        ),
    }
}

fn describe_panic(run: Option<u64>, keyframe: Option<u32>, message: &str) -> String {
    let place = match (run, keyframe) {
        (Some(run), Some(keyframe)) => format!("run {run}, keyframe {keyframe}"),
        (Some(run), None) => format!("run {run}, before its first keyframe"),
        (None, Some(keyframe)) => format!("keyframe {keyframe}"),
        (None, None) => "the simulation".to_string(),
    };
    format!(
        "{place}: internal error, the simulation stopped (a bug in Anthesis; please report it): {message}"
    )
}

/// The text of a caught panic's payload (`panic!` gives a `&str` or a
/// `String`).
pub fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(text) = payload.downcast_ref::<&str>() {
        (*text).to_string()
    } else if let Some(text) = payload.downcast_ref::<String>() {
        text.clone()
    } else {
        "a panic without a message".to_string()
    }
}

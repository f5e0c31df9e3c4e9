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
        "keyframe {keyframe}, organ `{organ}`: the solver diverged: {error}{}{}",
        held_against_note(held_against),
        values_note(values)
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
        /// The organ's template values outside the range the solver is
        /// made for (see [`values_out_of_range`]).
        values: Vec<String>,
    },
    /// An organ's energy became non-finite or rose more than a
    /// million-fold from the previous keyframe: growth too strong for the
    /// mesh or its stiffness.
    #[error(
        "keyframe {keyframe}, organ `{organ}`: the energy blew up to {energy:.3e} (from {previous:.3e}){}{}",
        held_against_note(held_against),
        values_note(values)
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
        /// The organ's template values outside the range the solver is
        /// made for (see [`values_out_of_range`]).
        values: Vec<String>,
    },
    /// The organs did not settle within the solver's iteration limit
    /// (`max_iterations` per contact round); a higher limit or a looser
    /// tolerance may help.
    #[error(
        "keyframe {keyframe}, organ `{organ}`: not converged after {iterations} iterations (relative gradient {relative_gradient:.3e}){}{}",
        held_against_note(held_against),
        values_note(values)
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
        /// The organ's template values outside the range the solver is
        /// made for (see [`values_out_of_range`]).
        values: Vec<String>,
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

/// What a run that stopped at an organ adds about the values the user
/// chose for its template that lie outside the range the solver is made
/// for (see [`values_out_of_range`]): a painter who typed a thickness of
/// 0.001 should learn that it, not the solver, is the cause.
pub fn values_note(values: &[String]) -> String {
    if values.is_empty() {
        String::new()
    } else {
        format!("; {}", values.join("; "))
    }
}

/// How many times the stretch stiffness the bend stiffness may be for a
/// run known to settle: on the test whorl (one petal, 20 keyframes, Ks =
/// Kb = 20 as shipped) runs settle at Kb/Ks up to 3,000 and stop "not
/// converged" at 10,000 and 20,000; a smaller Kb/Ks (down to 1/20,000)
/// settles. The shipped flowers have Kb = Ks.
pub const MAX_BEND_OVER_STRETCH: f64 = 3000.0;

/// The values of `template` outside the range runs are known to settle
/// in, each said with that range, for a failure at one of its organs.
///
/// The thickness is measured against the organ's length, as the
/// plausible-organ table of [`anthesis_flower::scale::LENGTH_IN_THICKNESSES`]
/// does (real petals and sepals are 10 to 2,000 thicknesses long; the
/// paper's lily and *Eustoma* 220 and 442): a petal thinner than that bends
/// under almost no force (on the test whorl: settles at 1,990 thicknesses
/// long, passes through itself at 4,000 and 20,000, diverges at 100,000).
/// The bend stiffness is measured against the stretch stiffness
/// ([`MAX_BEND_OVER_STRETCH`]).
pub fn values_out_of_range(template: &anthesis_flower::Template) -> Vec<String> {
    let mut said = Vec::new();
    let plausible = anthesis_flower::scale::LENGTH_IN_THICKNESSES;
    let length = anthesis_flower::scale::organ_length(&template.mesh);
    let thickness = template.thickness;
    let in_thicknesses = length / thickness;
    if in_thicknesses.is_finite() && in_thicknesses > 0.0 && !plausible.contains(&in_thicknesses) {
        let (side, how) = if in_thicknesses > *plausible.end() {
            ("below", "a petal this thin bends under almost no force and")
        } else {
            ("above", "a petal this thick for its length")
        };
        said.push(format!(
            "thickness {} of `{}` is {side} the range where the solver converges ({} to {} for \
             its mesh {} long: real petals and sepals are {} to {} thicknesses long, this one \
             is {}); {how} may not settle or may pass through itself",
            significant(thickness),
            template.name,
            significant(length / plausible.end()),
            significant(length / plausible.start()),
            significant(length),
            plausible.start(),
            grouped(*plausible.end()),
            grouped(in_thicknesses),
        ));
    }
    let (ks, kb) = (template.stretch_stiffness, template.bend_stiffness);
    let ratio = kb / ks;
    if ratio.is_finite() && ratio > MAX_BEND_OVER_STRETCH {
        said.push(format!(
            "Kb {} of `{}` is {} times its Ks {}, above the range where the solver converges \
             (Kb up to {} times Ks; the shipped flowers have Kb = Ks): raise Ks or lower Kb",
            significant(kb),
            template.name,
            grouped(ratio),
            significant(ks),
            grouped(MAX_BEND_OVER_STRETCH),
        ));
    }
    said
}

/// `x` to three significant digits, without an exponent for the sizes a
/// project holds (0.00221, 4.42, 1,230).
fn significant(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return x.to_string();
    }
    let magnitude = x.abs().log10().floor() as i32;
    if magnitude >= 3 {
        return grouped(x);
    }
    let decimals = (2 - magnitude).max(0) as usize;
    let text = format!("{x:.decimals$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

/// `x` rounded to a whole number, in groups of three digits (4,400).
fn grouped(x: f64) -> String {
    let digits = format!("{:.0}", x.abs());
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    if x < 0.0 { format!("-{out}") } else { out }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_said_to_three_significant_digits() {
        assert_eq!(significant(0.0022123), "0.00221");
        assert_eq!(significant(4.4), "4.4");
        assert_eq!(significant(0.44), "0.44");
        assert_eq!(significant(22.26), "22.3");
        assert_eq!(significant(4400.0), "4,400");
        assert_eq!(grouped(1_234_567.0), "1,234,567");
    }

    #[test]
    fn a_thickness_outside_the_plausible_organ_range_is_named_with_its_range() {
        let mut project = crate::fixtures::whorl(2, 8, 14, 3);
        let template = &mut project.flower.templates[0];
        let length = anthesis_flower::scale::organ_length(&template.mesh);
        // Within 10 to 2,000 thicknesses: nothing said.
        template.thickness = length / 300.0;
        assert_eq!(values_out_of_range(template), Vec::<String>::new());
        template.thickness = length / 1999.0;
        assert_eq!(values_out_of_range(template), Vec::<String>::new());
        // 4,000 thicknesses long: too thin, with the range for its length.
        template.thickness = length / 4000.0;
        let said = values_out_of_range(template);
        assert_eq!(said.len(), 1);
        let expected_range = format!(
            "({} to {} for its mesh {} long",
            significant(length / 2000.0),
            significant(length / 10.0),
            significant(length)
        );
        assert!(
            said[0].starts_with(&format!(
                "thickness {} of `{}` is below the range where the solver converges {expected_range}",
                significant(length / 4000.0),
                template.name
            )),
            "{said:?}"
        );
        assert!(said[0].contains("this one is 4,000"), "{said:?}");
        // 5 thicknesses long: too thick.
        template.thickness = length / 5.0;
        let said = values_out_of_range(template);
        assert!(said[0].contains("is above the range"), "{said:?}");
        // A bend stiffness far above the stretch stiffness.
        template.thickness = length / 300.0;
        template.stretch_stiffness = 0.001;
        template.bend_stiffness = 20.0;
        assert_eq!(
            values_out_of_range(template),
            [format!(
                "Kb 20 of `{}` is 20,000 times its Ks 0.001, above the range where the solver \
                 converges (Kb up to 3,000 times Ks; the shipped flowers have Kb = Ks): raise Ks \
                 or lower Kb",
                template.name
            )]
        );
        template.stretch_stiffness = 20.0 / 3000.0;
        assert_eq!(values_out_of_range(template), Vec::<String>::new());
        // A thickness of 0 has its own error before a run.
        template.thickness = 0.0;
        assert_eq!(values_out_of_range(template), Vec::<String>::new());
    }
}

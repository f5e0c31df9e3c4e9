//! Faults forced on purpose, for tests only. Compiled into the crate's own
//! tests and, through the `fault-hook` feature, into builds that ask for it
//! (the app enables it from its dev-dependencies, so `cargo test` builds an
//! `anthesis` binary that can fail on demand; `cargo build` and releases do
//! not contain this module).

/// The environment variable a `fault-hook` build reads when a simulation
/// is built, e.g. `ANTHESIS_TEST_FAULT=panic-at-keyframe:3`.
pub const ENV: &str = "ANTHESIS_TEST_FAULT";

/// A failure to force.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fault {
    /// A panic inside the organs' parallel growth of this keyframe.
    PanicAtKeyframe(u32),
    /// A panic in the worker's job before the simulation is built.
    PanicBeforeStart,
}

impl Fault {
    /// `panic-at-keyframe:N` or `panic-before-start`.
    pub fn parse(text: &str) -> Option<Fault> {
        match text.trim() {
            "panic-before-start" => Some(Fault::PanicBeforeStart),
            other => {
                let n = other.strip_prefix("panic-at-keyframe:")?;
                n.parse().ok().map(Fault::PanicAtKeyframe)
            }
        }
    }

    /// The fault named by [`ENV`], if any.
    #[cfg(feature = "fault-hook")]
    pub fn from_env() -> Option<Fault> {
        Fault::parse(&std::env::var(ENV).ok()?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faults_are_named_as_documented() {
        assert_eq!(
            Fault::parse("panic-at-keyframe:3"),
            Some(Fault::PanicAtKeyframe(3))
        );
        assert_eq!(
            Fault::parse("panic-before-start"),
            Some(Fault::PanicBeforeStart)
        );
        assert_eq!(Fault::parse("panic-at-keyframe:x"), None);
        assert_eq!(Fault::parse(""), None);
    }
}

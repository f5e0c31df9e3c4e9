//! Reproducible random numbers for the tests: a 64-bit linear congruential
//! generator (Knuth's MMIX constants), the same values on every machine and
//! no dependency for a few jittered meshes and random hinges.

/// The generator's state; `TestRng(seed)` starts a sequence.
pub(crate) struct TestRng(pub(crate) u64);

impl TestRng {
    /// The next value, uniform in [-0.5, 0.5).
    pub(crate) fn centred(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    }
}

//! A seeded mutator for fuzzing the command line's readers of files from
//! others (the `pde-blossom` JSON surfaces, the `blossom` open-state OBJ)
//! in unit tests, without a fuzzing engine: valid inputs with random
//! edits (numbers replaced by troublesome values, characters deleted,
//! pieces doubled, the text cut short).
//!
//! `cargo test` runs a fixed slice of [`CI_CASES`] seeded cases per reader;
//! for a long run give each a time budget (fresh seeds, printed):
//!
//! ```text
//! ANTHESIS_FUZZ_SECONDS=600 cargo test -p anthesis-app --lib fuzz_ -- --nocapture --test-threads 1
//! ```

use std::time::{Duration, Instant};

/// Cases per reader in a plain `cargo test`.
pub const CI_CASES: u64 = 300;

/// Values that break readers of numbers.
const TROUBLE: &[&str] = &[
    "NaN",
    "nan",
    "inf",
    "-inf",
    "1e309",
    "1e308",
    "-1e308",
    "1e-320",
    "0",
    "-0",
    "-1",
    "1e30",
    "",
    "\"\"",
    "[]",
    "{}",
    "null",
    "true",
    "[[0,0,0]]",
    "[0,0]",
    "99999999999999999999",
];

/// xorshift64*: small, seeded, the same cases every time for one seed.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed.max(1))
    }

    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// `text` with one to four random edits.
pub fn mutate(text: &str, rng: &mut Rng) -> String {
    let mut chars: Vec<char> = text.chars().collect();
    for _ in 0..=rng.below(4) {
        let n = chars.len();
        match rng.below(5) {
            // A number (a run of digits, signs, dots, e) replaced.
            0 | 1 => {
                let numeric = |c: char| c.is_ascii_digit() || "-+.eE".contains(c);
                let starts: Vec<usize> = (0..n)
                    .filter(|&i| numeric(chars[i]) && (i == 0 || !numeric(chars[i - 1])))
                    .collect();
                if let Some(&start) = starts.get(rng.below(starts.len())) {
                    let end = (start..n).find(|&i| !numeric(chars[i])).unwrap_or(n);
                    let with = TROUBLE[rng.below(TROUBLE.len())];
                    chars.splice(start..end, with.chars());
                }
            }
            2 if n > 0 => {
                let at = rng.below(n);
                let len = 1 + rng.below(8).min(n - at - 1);
                chars.drain(at..at + len);
            }
            3 if n > 0 => {
                let at = rng.below(n);
                let len = 1 + rng.below(40).min(n - at - 1);
                let piece: Vec<char> = chars[at..at + len].to_vec();
                let to = rng.below(n + 1);
                chars.splice(to..to, piece);
            }
            _ => chars.truncate(rng.below(n + 1)),
        }
    }
    chars.into_iter().collect()
}

/// Runs `check` on [`CI_CASES`] seeded cases, or on fresh seeds until
/// `ANTHESIS_FUZZ_SECONDS` have passed; returns how many it ran.
pub fn run(name: &str, mut check: impl FnMut(&mut Rng)) -> u64 {
    let budget = std::env::var("ANTHESIS_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .map(Duration::from_secs_f64);
    let started = Instant::now();
    let seed = match budget {
        None => 38,
        Some(_) => started.elapsed().as_nanos() as u64 ^ u64::from(std::process::id()) << 32,
    };
    let mut rng = Rng::new(seed);
    let mut cases = 0;
    loop {
        check(&mut rng);
        cases += 1;
        let done = match budget {
            None => cases >= CI_CASES,
            Some(budget) => started.elapsed() >= budget,
        };
        if done {
            break;
        }
    }
    eprintln!(
        "fuzz {name}: {cases} cases in {:.1} s (seed {seed})",
        started.elapsed().as_secs_f64()
    );
    cases
}

//! Fuzzing the readers of files from strangers: the OBJ reader, the
//! PNG map reader, the project loader and the L-system parser (with its
//! derivation, turtle and overlap rules). Inputs are real files of the
//! shipped flowers with random edits (lines deleted, doubled, swapped or
//! cut, tokens replaced by troublesome values, bytes changed; PNG chunks
//! edited with their checksums fixed so the edit reaches the decoder) and
//! inputs generated from scratch (OBJ statements, PNGs of every format).
//!
//! Every case must end in a valid result or a typed error whose message is
//! short, with short lines and no control characters; a panic, a result that breaks
//! the reader's own promises or an over-long message fails the test, and
//! proptest shrinks the input to a small one.
//!
//! `cargo test` runs a fixed, seeded slice ([`CI_CASES`] cases per reader,
//! a few seconds). For a long run, give each reader a time budget:
//!
//! ```text
//! ANTHESIS_FUZZ_SECONDS=600 cargo test -p anthesis-flower \
//!     --test fuzz_parsers -- --nocapture --test-threads 1
//! ```
//!
//! Each test then prints how many cases it ran and the random seed; a
//! failure writes the shrunk input to `target/tmp/fuzz-NAME-failure.txt`.

use std::collections::HashMap;
use std::fmt::Debug;
use std::hash::{BuildHasher, RandomState};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use anthesis_flower::MAX_KEYFRAMES;
use anthesis_flower::project::parse_project;
use anthesis_maps::{DirectionMap, ScalarMap};
use anthesis_mesh::obj::parse_obj_file;
use proptest::prelude::*;
use proptest::sample::Index;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestError, TestRng, TestRunner};

/// Cases per reader in a plain `cargo test`.
const CI_CASES: u32 = 1000;

/// Longest error message accepted, in characters: a message names the file,
/// the line and what is wrong, and quotes at most a short excerpt.
const MAX_MESSAGE_CHARS: usize = 800;
/// Longest line of a message: file contents are quoted as excerpts of at
/// most 120 characters.
const MAX_LINE_CHARS: usize = 300;

/// Longest time one case may take: the readers have size limits, so no
/// input of the sizes made here may stall them.
const MAX_CASE_TIME: Duration = Duration::from_secs(5);

// ---------------------------------------------------------------- harness

/// Runs `check` on inputs drawn from `strategy`: [`CI_CASES`] seeded cases,
/// or batches with fresh seeds until `ANTHESIS_FUZZ_SECONDS` have passed.
fn fuzz<S>(name: &str, strategy: S, check: impl Fn(S::Value) -> Result<Outcome, TestCaseError>)
where
    S: Strategy,
    S::Value: Debug,
{
    let budget = std::env::var("ANTHESIS_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .map(Duration::from_secs_f64);
    let config = Config {
        cases: CI_CASES,
        failure_persistence: None,
        max_shrink_iters: 4096,
        ..Config::default()
    };
    let accepted = AtomicU64::new(0);
    let timed_check = |value: S::Value| {
        let started = Instant::now();
        let outcome = check(value)?;
        let took = started.elapsed();
        prop_assert!(took < MAX_CASE_TIME, "one case took {took:?}");
        if outcome == Outcome::Accepted {
            accepted.fetch_add(1, Ordering::Relaxed);
        }
        Ok(())
    };
    let started = Instant::now();
    let mut cases = 0u64;
    loop {
        let seed: [u8; 32] = match budget {
            // The CI slice is the same every time.
            None => [7; 32],
            Some(_) => fresh_seed(),
        };
        let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &seed);
        let mut runner = TestRunner::new_with_rng(config.clone(), rng);
        if let Err(error) = runner.run(&strategy, timed_check) {
            fail(name, &seed, error);
        }
        cases += u64::from(config.cases);
        if budget.is_none_or(|budget| started.elapsed() >= budget) {
            break;
        }
    }
    eprintln!(
        "fuzz {name}: {cases} cases in {:.1} s, {} accepted, the rest refused with a clean error",
        started.elapsed().as_secs_f64(),
        accepted.load(Ordering::Relaxed)
    );
}

/// How a reader answered a case that passed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Outcome {
    /// A valid result.
    Accepted,
    /// A clean error.
    Refused,
}

fn fresh_seed() -> [u8; 32] {
    let mut seed = [0; 32];
    for chunk in seed.chunks_mut(8) {
        let random = RandomState::new().hash_one(Instant::now());
        chunk.copy_from_slice(&random.to_le_bytes());
    }
    seed
}

fn fail<T: Debug>(name: &str, seed: &[u8; 32], error: TestError<T>) -> ! {
    let TestError::Fail(reason, input) = error else {
        panic!("fuzz {name}: {error}");
    };
    let input = format!("{input:#?}");
    let file = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("fuzz-{name}-failure.txt"));
    let saved = std::fs::write(&file, &input).is_ok();
    let shown: String = input.chars().take(3000).collect();
    panic!(
        "fuzz {name} failed (seed {seed:?}): {reason}\nshrunk input{}:\n{shown}",
        if saved {
            format!(" (whole in {})", file.display())
        } else {
            String::new()
        }
    );
}

/// A reader's error: short, nothing a terminal would act on. TOML syntax
/// errors quote the offending line under the message, so line breaks are
/// allowed (the command line folds them into one line); each line is short.
fn check_message(message: &str) -> Result<(), TestCaseError> {
    prop_assert!(
        message.chars().count() <= MAX_MESSAGE_CHARS,
        "message of {} characters: {message}",
        message.chars().count()
    );
    prop_assert!(
        !message.chars().any(|c| c.is_control() && c != '\n'),
        "control character in the message: {message:?}"
    );
    prop_assert!(
        message
            .lines()
            .all(|line| line.chars().count() <= MAX_LINE_CHARS),
        "over-long line in the message: {message:?}"
    );
    Ok(())
}

fn refused(message: &str) -> Result<Outcome, TestCaseError> {
    check_message(message).map(|()| Outcome::Refused)
}

// ------------------------------------------------------------ edits of text

/// Values that broke readers before or often do: non-numbers, overflow,
/// signs, huge indices, odd characters, paths out of the folder.
const TROUBLE: &[&str] = &[
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e309",
    "1e30",
    "-1e30",
    "1e-320",
    "-0",
    "0",
    "-1",
    "-2",
    "1",
    "3",
    "0.5",
    "4294967295",
    "4294967296",
    "18446744073709551616",
    "-9223372036854775809",
    "99999999",
    "1/",
    "/1",
    "1//",
    "1/2/3/4",
    "0/0/0",
    "-1/-1",
    "",
    " ",
    "\u{feff}",
    "\0",
    "\r",
    "\t",
    "\u{1b}[2J",
    "é",
    "\u{202e}",
    "#",
    "\\",
    "\"",
    "'",
    "[",
    "]]",
    "{",
    "=",
    "==",
    "true",
    "[]",
    "{}",
    "\"\"",
    "\"../../../../etc/passwd\"",
    "\"/etc/hostname\"",
    "\"/dev/zero\"",
    "\"maps/missing.png\"",
    "\"meshes/petal.obj\"",
    "\"maps/petal-step40-direction.png\"",
    "\"maps/petal-step40-stretch.png\"",
    "[[templates]]",
    "[[organs]]",
    "[simulation]",
    "v",
    "vt",
    "f",
    "l",
    "p",
    "o",
    "g",
    "s",
    "vn",
    "mtllib",
    "usemtl",
];

/// One edit of a text file, by lines and whitespace-separated tokens.
#[derive(Debug, Clone)]
enum TextEdit {
    DeleteLine(Index),
    DuplicateLine {
        from: Index,
        to: Index,
    },
    SwapLines(Index, Index),
    /// Replaces a token of a line by a troublesome value.
    ReplaceToken {
        line: Index,
        token: Index,
        with: &'static str,
    },
    InsertLine {
        at: Index,
        text: String,
    },
    /// Cuts the file there, as a crash mid-write would.
    Truncate(Index),
}

fn trouble() -> impl Strategy<Value = &'static str> {
    proptest::sample::select(TROUBLE)
}

fn text_edit() -> impl Strategy<Value = TextEdit> {
    prop_oneof![
        1 => any::<Index>().prop_map(TextEdit::DeleteLine),
        1 => (any::<Index>(), any::<Index>()).prop_map(|(from, to)| TextEdit::DuplicateLine { from, to }),
        1 => (any::<Index>(), any::<Index>()).prop_map(|(a, b)| TextEdit::SwapLines(a, b)),
        4 => (any::<Index>(), any::<Index>(), trouble())
            .prop_map(|(line, token, with)| TextEdit::ReplaceToken { line, token, with }),
        1 => (any::<Index>(), proptest::collection::vec(trouble(), 1..5))
            .prop_map(|(at, words)| TextEdit::InsertLine { at, text: words.join(" ") }),
        1 => any::<Index>().prop_map(TextEdit::Truncate),
    ]
}

fn apply_text_edits(text: &str, edits: &[TextEdit]) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut cut_at = None;
    for edit in edits {
        if lines.is_empty() {
            lines.push(String::new());
        }
        let n = lines.len();
        match edit {
            TextEdit::DeleteLine(i) => {
                lines.remove(i.index(n));
            }
            TextEdit::DuplicateLine { from, to } => {
                let line = lines[from.index(n)].clone();
                lines.insert(to.index(n + 1), line);
            }
            TextEdit::SwapLines(a, b) => lines.swap(a.index(n), b.index(n)),
            TextEdit::ReplaceToken { line, token, with } => {
                let line = &mut lines[line.index(n)];
                let mut tokens: Vec<&str> = line.split(' ').collect();
                let t = token.index(tokens.len());
                tokens[t] = with;
                *line = tokens.join(" ");
            }
            TextEdit::InsertLine { at, text } => lines.insert(at.index(n + 1), text.clone()),
            TextEdit::Truncate(at) => cut_at = Some(*at),
        }
    }
    let mut joined = lines.join("\n");
    if let Some(at) = cut_at {
        let mut cut = at.index(joined.len() + 1);
        while !joined.is_char_boundary(cut) {
            cut -= 1;
        }
        joined.truncate(cut);
    }
    joined
}

// -------------------------------------------------------------------- OBJ

fn asset(relative: &str) -> Vec<u8> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets/flowers")
        .join(relative);
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Real OBJ files to edit: a small generated petal (fast, so most cases
/// use it) and the shipped lily sepal.
fn obj_seeds() -> Vec<String> {
    let small =
        anthesis_mesh::obj::obj_string(&anthesis_mesh::generate::test_petal(1.0, 0.4, 4, 5));
    let sepal = String::from_utf8(asset("lily/meshes/sepal.obj")).expect("UTF-8");
    vec![small.clone(), small.clone(), small, sepal]
}

/// OBJ text made from scratch: either a few statements of each kind with
/// small (often wrong) indices and troublesome numbers, or a small grid of
/// random size, shape and scale (valid) with a few edits.
fn generated_obj() -> impl Strategy<Value = String> {
    let number = prop_oneof![
        3 => (-2.0f64..2.0).prop_map(|x| format!("{x}")),
        1 => trouble().prop_map(str::to_string),
    ];
    let index = prop_oneof![
        4 => (1i64..8).prop_map(|i| i.to_string()),
        1 => (-8i64..1).prop_map(|i| i.to_string()),
        1 => trouble().prop_map(str::to_string),
    ];
    let corner = prop_oneof![
        (index.clone(), index.clone()).prop_map(|(v, t)| format!("{v}/{t}")),
        (index.clone(), index.clone(), index.clone()).prop_map(|(v, t, n)| format!("{v}/{t}/{n}")),
        index.clone(),
    ];
    let statement = prop_oneof![
        3 => proptest::collection::vec(number.clone(), 3..5).prop_map(|c| format!("v {}", c.join(" "))),
        3 => proptest::collection::vec(number.clone(), 2..4).prop_map(|c| format!("vt {}", c.join(" "))),
        3 => proptest::collection::vec(corner, 2..6).prop_map(|c| format!("f {}", c.join(" "))),
        1 => proptest::collection::vec(index, 1..4).prop_map(|c| format!("l {}", c.join(" "))),
        1 => trouble().prop_map(|word| format!("{word} x")),
    ];
    let statements = proptest::collection::vec(statement, 0..40).prop_map(|lines| lines.join("\n"));
    let scale = prop_oneof![
        Just(1.0),
        Just(1e-6),
        Just(1e6),
        Just(1e-300),
        Just(1e300),
        0.01f64..100.0
    ];
    let grid = (
        2usize..8,
        2usize..8,
        scale,
        -1.0f64..1.0,
        proptest::collection::vec(text_edit(), 0..3),
    )
        .prop_map(|(columns, rows, scale, curl, edits)| {
            let mesh = anthesis_mesh::generate::parametric_grid(columns, rows, |uv| {
                glam::DVec3::new(uv.x, uv.y, curl * uv.x * uv.y) * scale
            });
            apply_text_edits(&anthesis_mesh::obj::obj_string(&mesh), &edits)
        });
    prop_oneof![statements, grid]
}

fn check_obj(text: &str) -> Result<Outcome, TestCaseError> {
    match parse_obj_file(text) {
        Ok(file) => {
            let mesh = &file.mesh;
            prop_assert!(mesh.positions.iter().all(|p| p.is_finite()));
            prop_assert!(mesh.uvs.iter().all(|uv| uv.is_finite()));
            prop_assert_eq!(mesh.positions.len(), mesh.uvs.len());
            prop_assert!(
                mesh.triangles
                    .iter()
                    .flatten()
                    .all(|&v| (v as usize) < mesh.positions.len())
            );
            // What the reader accepted, the validator accepts.
            prop_assert!(anthesis_mesh::validate(mesh).is_ok());
            for warning in &file.warnings {
                check_message(&warning.to_string())?;
            }
            Ok(Outcome::Accepted)
        }
        Err(error) => refused(&error.to_string()),
    }
}

#[test]
fn obj_reader_edited_real_files() {
    let seeds = obj_seeds();
    let strategy = (any::<Index>(), proptest::collection::vec(text_edit(), 1..6));
    fuzz("obj-edited", strategy, |(seed, edits)| {
        check_obj(&apply_text_edits(&seeds[seed.index(seeds.len())], &edits))
    });
}

#[test]
fn obj_reader_generated_statements() {
    fuzz("obj-generated", generated_obj(), |text| check_obj(&text));
}

// -------------------------------------------------------------------- PNG

/// Real PNG maps to edit: grey (8- and 16-bit) and RGB direction maps.
fn png_seeds() -> Vec<Vec<u8>> {
    [
        "lily/maps/petal-step40-e_growth.png",
        "lily/maps/petal-step40-w_growth.png",
        "lily/maps/petal-step40-direction.png",
        "eustoma-pinocchio/maps/petal-step40-bend.png",
    ]
    .into_iter()
    .map(asset)
    .collect()
}

/// One edit of PNG bytes. Chunk edits fix the chunk's checksum, so they
/// reach the decoder instead of stopping at the CRC check.
#[derive(Debug, Clone)]
enum PngEdit {
    SetByte {
        at: Index,
        value: u8,
    },
    Insert {
        at: Index,
        bytes: Vec<u8>,
    },
    Delete {
        at: Index,
        len: u8,
    },
    Truncate(Index),
    /// Overwrites 1 to 4 bytes inside a chunk's data (for IHDR: width,
    /// height, bit depth, colour type, interlacing) and fixes its CRC.
    ChunkData {
        chunk: Index,
        at: Index,
        value: u32,
        len: u8,
    },
    /// Repeats a whole chunk (a second IHDR, IDAT or IEND).
    RepeatChunk(Index),
}

fn png_edit() -> impl Strategy<Value = PngEdit> {
    let value = prop_oneof![
        any::<u32>(),
        Just(0u32),
        Just(u32::MAX),
        Just(0x7fff_ffff),
        Just(4096),
        Just(4097),
        Just(65536),
        (0u32..20),
    ];
    prop_oneof![
        1 => (any::<Index>(), any::<u8>()).prop_map(|(at, value)| PngEdit::SetByte { at, value }),
        1 => (any::<Index>(), proptest::collection::vec(any::<u8>(), 1..16))
            .prop_map(|(at, bytes)| PngEdit::Insert { at, bytes }),
        1 => (any::<Index>(), any::<u8>()).prop_map(|(at, len)| PngEdit::Delete { at, len }),
        1 => any::<Index>().prop_map(PngEdit::Truncate),
        4 => (any::<Index>(), any::<Index>(), value, 1u8..5)
            .prop_map(|(chunk, at, value, len)| PngEdit::ChunkData { chunk, at, value, len }),
        1 => any::<Index>().prop_map(PngEdit::RepeatChunk),
    ]
}

/// Byte ranges of the chunks of a PNG: (start of the length field, data
/// length). Stops at the first chunk that runs past the end.
fn chunks(png: &[u8]) -> Vec<(usize, usize)> {
    let mut found = Vec::new();
    let mut at = 8;
    while at + 12 <= png.len() {
        let len = u32::from_be_bytes([png[at], png[at + 1], png[at + 2], png[at + 3]]) as usize;
        if at + 12 + len > png.len() {
            break;
        }
        found.push((at, len));
        at += 12 + len;
    }
    found
}

fn apply_png_edits(png: &[u8], edits: &[PngEdit]) -> Vec<u8> {
    let mut bytes = png.to_vec();
    for edit in edits {
        let n = bytes.len().max(1);
        match edit {
            PngEdit::SetByte { at, value } => {
                if !bytes.is_empty() {
                    bytes[at.index(n)] = *value;
                }
            }
            PngEdit::Insert { at, bytes: new } => {
                let at = at.index(bytes.len() + 1);
                bytes.splice(at..at, new.iter().copied());
            }
            PngEdit::Delete { at, len } => {
                let start = at.index(n).min(bytes.len());
                let end = (start + usize::from(*len)).min(bytes.len());
                bytes.drain(start..end);
            }
            PngEdit::Truncate(at) => bytes.truncate(at.index(bytes.len() + 1)),
            PngEdit::ChunkData {
                chunk,
                at,
                value,
                len,
            } => {
                let found = chunks(&bytes);
                if found.is_empty() {
                    continue;
                }
                let (start, data_len) = found[chunk.index(found.len())];
                let len = usize::from(*len).min(data_len);
                if len == 0 {
                    continue;
                }
                let offset = start + 8 + at.index(data_len - len + 1);
                bytes[offset..offset + len].copy_from_slice(&value.to_be_bytes()[4 - len..]);
                let crc = crc32fast::hash(&bytes[start + 4..start + 8 + data_len]);
                bytes[start + 8 + data_len..start + 12 + data_len]
                    .copy_from_slice(&crc.to_be_bytes());
            }
            PngEdit::RepeatChunk(chunk) => {
                let found = chunks(&bytes);
                if found.is_empty() {
                    continue;
                }
                let (start, data_len) = found[chunk.index(found.len())];
                let whole = bytes[start..start + 12 + data_len].to_vec();
                bytes.splice(start..start, whole);
            }
        }
    }
    bytes
}

/// PNGs of every colour type and depth the encoder writes, small, with
/// random pixels.
fn generated_png() -> impl Strategy<Value = Vec<u8>> {
    use image::ExtendedColorType as C;
    let kind = proptest::sample::select(vec![
        (C::L8, 1usize),
        (C::La8, 2),
        (C::Rgb8, 3),
        (C::Rgba8, 4),
        (C::L16, 2),
        (C::La16, 4),
        (C::Rgb16, 6),
        (C::Rgba16, 8),
    ]);
    (kind, 1u32..24, 1u32..24, any::<u64>()).prop_map(|((colour, bytes_per_pixel), w, h, seed)| {
        use image::ImageEncoder;
        let mut state = seed;
        let pixels: Vec<u8> = (0..(w * h) as usize * bytes_per_pixel)
            .map(|_| {
                // A small LCG: pixel noise needs no quality.
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 56) as u8
            })
            .collect();
        let mut png = Vec::new();
        image::codecs::png::PngEncoder::new(&mut png)
            .write_image(&pixels, w, h, colour)
            .expect("the encoder writes what it offers");
        png
    })
}

fn check_png(bytes: &[u8]) -> Result<Outcome, TestCaseError> {
    let mut outcome = Outcome::Refused;
    match ScalarMap::from_png_bytes(bytes) {
        Ok(map) => {
            prop_assert!(map.width() as usize * map.height() as usize == map.values().len());
            prop_assert!(map.width() <= anthesis_maps::MAX_MAP_SIDE);
            prop_assert!(map.height() <= anthesis_maps::MAX_MAP_SIDE);
            prop_assert!(map.values().iter().all(|v| (0.0..=1.0).contains(v)));
            outcome = Outcome::Accepted;
        }
        Err(error) => check_message(&error.to_string())?,
    }
    match DirectionMap::from_png_bytes(bytes) {
        Ok(map) => {
            prop_assert!(map.width() as usize * map.height() as usize == map.values().len());
            prop_assert!(
                map.values()
                    .iter()
                    .flatten()
                    .all(|c| (-1.0..=1.0).contains(c))
            );
            outcome = Outcome::Accepted;
        }
        Err(error) => check_message(&error.to_string())?,
    }
    Ok(outcome)
}

#[test]
fn png_reader_edited_real_maps() {
    let seeds = png_seeds();
    let strategy = (any::<Index>(), proptest::collection::vec(png_edit(), 1..5));
    fuzz("png-edited", strategy, |(seed, edits)| {
        check_png(&apply_png_edits(&seeds[seed.index(seeds.len())], &edits))
    });
}

#[test]
fn png_reader_generated_images_with_edits() {
    let strategy = (generated_png(), proptest::collection::vec(png_edit(), 0..3));
    fuzz("png-generated", strategy, |(png, edits)| {
        check_png(&apply_png_edits(&png, &edits))
    });
}

// ---------------------------------------------------------------- project

/// A shipped flower: its project text and every file beside it, by the
/// path the project writes. The meshes are swapped for a small petal so a
/// case takes milliseconds; the text edits are what is fuzzed here.
struct Flower {
    text: String,
    files: HashMap<String, Vec<u8>>,
}

fn flower(name: &str) -> Flower {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets/flowers")
        .join(name);
    let small =
        anthesis_mesh::obj::obj_string(&anthesis_mesh::generate::test_petal(4.0, 1.5, 4, 6));
    let mut files = HashMap::new();
    for sub in ["maps", "meshes"] {
        for entry in std::fs::read_dir(folder.join(sub)).expect("asset folder") {
            let path = entry.expect("entry").path();
            let relative = format!(
                "{sub}/{}",
                path.file_name().expect("a name").to_string_lossy()
            );
            let bytes = if relative.ends_with(".obj") {
                small.clone().into_bytes()
            } else {
                std::fs::read(&path).expect("read")
            };
            files.insert(relative, bytes);
        }
    }
    Flower {
        text: std::fs::read_to_string(folder.join(format!("{name}.anthesis.toml")))
            .expect("project"),
        files,
    }
}

fn check_project(flower: &Flower, text: &str) -> Result<Outcome, TestCaseError> {
    let files = |relative: &str| {
        flower
            .files
            .get(relative)
            .cloned()
            .ok_or_else(|| std::io::Error::from(std::io::ErrorKind::NotFound))
    };
    match parse_project(text, &files) {
        Ok(project) => {
            let flower = &project.flower;
            prop_assert!(!flower.organs.is_empty());
            prop_assert!(!flower.templates.is_empty());
            prop_assert!((1..=MAX_KEYFRAMES).contains(&project.settings.keyframes));
            for i in 0..flower.organs.len() {
                let template = flower.template_of(i);
                prop_assert_eq!(template.problem(), None);
                prop_assert!(anthesis_mesh::validate(&template.mesh).is_ok());
            }
            for overlap in &flower.overlaps {
                prop_assert!(overlap.inner < flower.organs.len());
                prop_assert!(overlap.outer < flower.organs.len());
            }
            Ok(Outcome::Accepted)
        }
        Err(error) => refused(&error.to_string()),
    }
}

#[test]
fn project_loader_edited_real_projects() {
    let flowers = [flower("lily"), flower("eustoma-pinocchio")];
    // The shipped projects themselves load.
    for f in &flowers {
        assert_eq!(check_project(f, &f.text).ok(), Some(Outcome::Accepted));
    }
    let strategy = (any::<Index>(), proptest::collection::vec(text_edit(), 1..4));
    fuzz("project-edited", strategy, |(which, edits)| {
        let f = &flowers[which.index(flowers.len())];
        check_project(f, &apply_text_edits(&f.text, &edits))
    });
}

/// Found by the fuzzer: a tiny number (1e-320) was written out whole, 322
/// characters, in the base region's message.
#[test]
fn regression_a_tiny_number_is_shown_short() {
    let lily = flower("lily");
    let text = lily.text.replacen("u_max = 1.0", "u_max = 1e-320", 1);
    let files = |relative: &str| {
        lily.files
            .get(relative)
            .cloned()
            .ok_or_else(|| std::io::Error::from(std::io::ErrorKind::NotFound))
    };
    let message = parse_project(&text, &files)
        .expect_err("no particle lies in so thin a base region")
        .to_string();
    assert!(message.contains("u from 0 to 1e-320) holds"), "{message}");
}

// --------------------------------------------------------------- L-system

/// Real L-systems to edit: the apple's (as the project ships it) and
/// small ones using parameters, brackets and every turtle symbol.
fn lsystem_seeds() -> Vec<String> {
    let apple = String::from_utf8(asset("apple/apple.anthesis.toml")).expect("utf-8");
    let start = apple.find("text = \"\"\"\n").expect("the apple's L-system") + 11;
    let end = start + apple[start..].find("\"\"\"").expect("its end");
    vec![
        apple[start..end].to_owned(),
        "angle = 30\nstep = 2\naxiom: A(1)\nA(x) -> F(x) [+(x*10) ~p] [-(x * 10) ~s] A(x / 2 + 0.5)"
            .to_owned(),
        "ω: X\nX -> F [& ~p] [^ ~s] / (137.5) X\nF -> F F".to_owned(),
        "width = 3\naxiom: !(2) ;(0.2, 0.5, 0.1) F(3) [\\(45) ~p] #(1) ~s".to_owned(),
    ]
}

/// Pieces that break L-system parsers: operators, brackets, nesting,
/// numbers that are not finite, huge counts of steps and modules.
const LSYSTEM_TROUBLE: &[&str] = &[
    "(",
    ")",
    "((((((((((",
    "))))",
    "->",
    "→",
    "~",
    "~p",
    "~s",
    "~q",
    "~(",
    "A(x)",
    "A(x,y)",
    "A(",
    "0/0",
    "1/0",
    "-1/0",
    "1e308*10",
    "x/0",
    "x*x*x*x",
    "axiom:",
    "ω:",
    "A -> A A",
    "A -> A A A A A A A A",
    "X -> X X",
    "[",
    "]",
    "]]]",
    "[[[",
    "+(0/0)",
    "/(1e309)",
    "F(-1e30)",
    ";(2, -1, 0.5)",
    ";(0/0, 0, 0)",
    "!(0/0)",
    "#(-5)",
    "angle = nan",
    "step = inf",
    "lenA = 1e308",
    "=",
    ":",
    ",",
    "--",
    "- -",
    "*",
    "/",
    "\\",
];

fn lsystem_edit() -> impl Strategy<Value = TextEdit> {
    prop_oneof![
        3 => text_edit(),
        4 => (any::<Index>(), any::<Index>(), proptest::sample::select(LSYSTEM_TROUBLE))
            .prop_map(|(line, token, with)| TextEdit::ReplaceToken { line, token, with }),
        2 => (any::<Index>(), proptest::collection::vec(proptest::sample::select(LSYSTEM_TROUBLE), 1..4))
            .prop_map(|(at, words)| TextEdit::InsertLine { at, text: words.join(" ") }),
    ]
}

fn check_lsystem(text: &str, steps: u32) -> Result<Outcome, TestCaseError> {
    use anthesis_flower::structure::Structure;
    let templates = lsystem_templates();
    let structure = Structure::LSystem {
        text: text.to_owned(),
        steps,
        surfaces: [('p', 0), ('s', 1), ('c', 0)].into_iter().collect(),
        units: 0.08,
    };
    match structure.arrange(templates) {
        Ok(arrangement) => {
            let n = arrangement.organs.len();
            prop_assert!(n <= anthesis_flower::structure::MAX_STRUCTURE_ORGANS);
            prop_assert!(
                arrangement.overlaps.len() <= anthesis_flower::structure::MAX_OVERLAP_RULES
            );
            for organ in &arrangement.organs {
                prop_assert!(organ.placement.position.is_finite(), "{organ:?}");
                prop_assert!(organ.placement.orientation.is_finite(), "{organ:?}");
            }
            for overlap in &arrangement.overlaps {
                prop_assert!(
                    overlap.inner < n && overlap.outer < n && overlap.inner != overlap.outer
                );
            }
            for segment in structure.segments() {
                prop_assert!(segment.start.is_finite() && segment.end.is_finite());
            }
            Ok(Outcome::Accepted)
        }
        Err(error) => refused(&error.to_string()),
    }
}

/// Two templates for the surfaces `p` and `s` (the lily's, with a small
/// mesh), made once.
fn lsystem_templates() -> &'static [anthesis_flower::Template] {
    static TEMPLATES: std::sync::OnceLock<Vec<anthesis_flower::Template>> =
        std::sync::OnceLock::new();
    TEMPLATES.get_or_init(|| {
        let lily = flower("lily");
        let files = |relative: &str| {
            lily.files
                .get(relative)
                .cloned()
                .ok_or_else(|| std::io::Error::from(std::io::ErrorKind::NotFound))
        };
        parse_project(&lily.text, &files)
            .expect("the lily loads")
            .flower
            .templates
    })
}

#[test]
fn lsystem_parser_edited_real_systems() {
    let seeds = lsystem_seeds();
    // The seeds themselves make organs.
    for seed in &seeds {
        assert_eq!(
            check_lsystem(seed, 3).ok(),
            Some(Outcome::Accepted),
            "{seed}"
        );
    }
    let strategy = (
        any::<Index>(),
        proptest::collection::vec(lsystem_edit(), 1..5),
        0u32..12,
    );
    fuzz("lsystem-edited", strategy, |(seed, edits, steps)| {
        check_lsystem(
            &apply_text_edits(&seeds[seed.index(seeds.len())], &edits),
            steps,
        )
    });
}

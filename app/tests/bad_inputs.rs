//! The bad-input catalogue: every bad file and argument named in issue 17
//! and in DESIGN.md §6, given to the `anthesis` binary the way a user would,
//! each with the message it must get. Every case must end within
//! [`MAX_SECONDS`] (a FIFO or `/dev/zero` once hung or filled the memory),
//! with exit code 1 (an error, not a panic's 101 or a kill) and a last
//! stderr line `error: …` holding the expected fragment.
//!
//! Each case starts from a fresh copy of a valid two-organ project
//! (`whorl.anthesis.toml`, meshes in `meshes/`, 32x32 maps in `maps/`).

use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;

use anthesis_app::desktop::params::grouped;
use common::text;

/// Longest time a bad input may take to be refused.
const MAX_SECONDS: u64 = 60;

const PROJECT: &str = "whorl.anthesis.toml";
const PETAL: &str = "meshes/petal.obj";
const MAP: &str = "maps/petal-step40-e_growth.png";

/// A valid project in `dir`.
fn valid_project(dir: &Path) {
    let project = anthesis_sim::fixtures::whorl(2, 8, 14, 3);
    anthesis_flower::project::save_project(&project, &dir.join(PROJECT)).expect("save");
}

fn read(dir: &Path, relative: &str) -> String {
    std::fs::read_to_string(dir.join(relative)).expect("read")
}

fn write(dir: &Path, relative: &str, bytes: impl AsRef<[u8]>) {
    std::fs::write(dir.join(relative), bytes).expect("write");
}

/// Replaces the first `from` in the file by `to`.
fn replace(dir: &Path, relative: &str, from: &str, to: &str) {
    let text = read(dir, relative);
    assert!(text.contains(from), "`{from}` not in {relative}");
    write(dir, relative, text.replacen(from, to, 1));
}

/// The petal OBJ with `change` applied to each of its lines.
fn edit_petal(dir: &Path, mut change: impl FnMut(usize, &str) -> Option<String>) {
    let text = read(dir, PETAL);
    let lines: Vec<String> = text
        .lines()
        .enumerate()
        .filter_map(|(i, line)| change(i, line))
        .collect();
    write(dir, PETAL, lines.join("\n") + "\n");
}

fn run_command(tool: &str, args: &[&str]) {
    let status = Command::new(tool).args(args).status().expect(tool);
    assert!(status.success(), "{tool} {args:?}");
}

fn project(dir: &Path) -> String {
    dir.join(PROJECT).display().to_string()
}

fn info(dir: &Path) -> Vec<String> {
    vec!["info".into(), project(dir)]
}

fn simulate(dir: &Path, more: &[&str]) -> Vec<String> {
    let mut args = vec!["simulate".to_string(), project(dir)];
    args.extend(more.iter().map(|s| s.to_string()));
    args
}

fn in_dir(dir: &Path, relative: &str) -> String {
    dir.join(relative).display().to_string()
}

/// A 16-bit grey PNG of `width` x `height` with every pixel `value`.
fn grey_png(width: u32, height: u32, value: u16) -> Vec<u8> {
    anthesis_maps::ScalarMap::new(
        width,
        height,
        vec![f32::from(value) / 65535.0; (width * height) as usize],
    )
    .expect("a map")
    .to_png_bytes(anthesis_maps::BitDepth::Sixteen)
    .expect("encode")
}

/// A PNG whose header claims `side` x `side` pixels (the pixel data is
/// one row: the header alone must stop it).
fn huge_png_header(side: u32) -> Vec<u8> {
    let mut png = grey_png(1, 1, 0);
    png[16..20].copy_from_slice(&side.to_be_bytes());
    png[20..24].copy_from_slice(&side.to_be_bytes());
    let crc = crc32(&png[12..29]);
    png[29..33].copy_from_slice(&crc.to_be_bytes());
    png
}

/// CRC-32 as PNG chunks use it (bitwise; a few dozen bytes here).
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = u32::MAX;
    for &byte in bytes {
        crc ^= u32::from(byte);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

struct Case {
    name: &'static str,
    /// Breaks the valid project in the folder and returns the arguments.
    prepare: fn(&Path) -> Vec<String>,
    /// What the error line must say.
    expect: &'static str,
    /// Environment of the run.
    env: &'static [(&'static str, &'static str)],
}

macro_rules! case {
    ($name:expr, $prepare:expr, $expect:expr) => {
        case!($name, $prepare, $expect, &[])
    };
    ($name:expr, $prepare:expr, $expect:expr, $env:expr) => {
        Case {
            name: $name,
            prepare: $prepare,
            expect: $expect,
            env: $env,
        }
    };
}

fn catalogue() -> Vec<Case> {
    vec![
        // ---------------------------------------------------- meshes (OBJ)
        case!(
            "mesh without texture coordinates",
            |d| {
                edit_petal(d, |_, l| {
                    if l.starts_with("vt ") {
                        None
                    } else if let Some(face) = l.strip_prefix("f ") {
                        let corners: Vec<&str> = face
                            .split(' ')
                            .map(|c| c.split('/').next().unwrap_or(c))
                            .collect();
                        Some(format!("f {}", corners.join(" ")))
                    } else {
                        Some(l.to_string())
                    }
                });
                info(d)
            },
            "OBJ has no texture coordinates (vt)"
        ),
        case!(
            "non-manifold edge (three triangles on one edge)",
            |d| {
                // A new vertex and a third triangle on the inner edge 1-10.
                let text = read(d, PETAL);
                let new = text.lines().filter(|l| l.starts_with("v ")).count() + 1;
                let uv = text.lines().filter(|l| l.starts_with("vt ")).count() + 1;
                write(
                    d,
                    PETAL,
                    text + &format!("v 0 1 5\nvt 0.5 0.5\nf 10/10 1/1 {new}/{uv}\n"),
                );
                info(d)
            },
            "edge 1-10 is shared by 3 triangles (non-manifold; at most 2 allowed)"
        ),
        case!(
            "triangle using one vertex twice",
            |d| {
                replace(d, PETAL, "f 1/1/1 2/2/2 10/10/10", "f 1/1/1 2/2/2 2/2/2");
                info(d)
            },
            "OBJ line 338: triangle 1 uses vertex 2 twice"
        ),
        case!(
            "zero-area triangle (two corners at one place)",
            |d| {
                let text = read(d, PETAL);
                let first = text
                    .lines()
                    .find(|l| l.starts_with("v "))
                    .expect("a vertex");
                let mut count = 0;
                edit_petal(d, |_, l| {
                    if l.starts_with("v ") {
                        count += 1;
                        if count == 10 {
                            return Some(first.to_string());
                        }
                    }
                    Some(l.to_string())
                });
                info(d)
            },
            "OBJ line 338: triangle 1 has zero area in 3D"
        ),
        case!(
            "flipped triangle",
            |d| {
                replace(d, PETAL, "f 1/1/1 2/2/2 10/10/10", "f 2/2/2 1/1/1 10/10/10");
                info(d)
            },
            "OBJ line 339: triangles 1 and 2 have opposite orientations across edge 1-10"
        ),
        case!(
            "NaN coordinate",
            |d| {
                edit_petal(d, |i, l| {
                    Some(if i == 1 { "v nan 0 0".into() } else { l.into() })
                });
                info(d)
            },
            "OBJ line 2: vertex 1 has a non-finite coordinate (NaN or infinite)"
        ),
        case!(
            "coordinate of 1e30",
            |d| {
                edit_petal(d, |i, l| {
                    Some(if i == 1 {
                        "v 1e30 0 0".into()
                    } else {
                        l.into()
                    })
                });
                info(d)
            },
            "vertex 1 has a coordinate of 1e30, out of range"
        ),
        case!(
            "truncated OBJ",
            |d| {
                let text = read(d, PETAL);
                let cut = text.find("\nf ").expect("faces") + 6;
                write(d, PETAL, &text[..cut]);
                info(d)
            },
            "meshes/petal.obj: OBJ line 338: a face needs at least 3 corners, found 1"
        ),
        case!(
            "empty OBJ",
            |d| {
                write(d, PETAL, "");
                info(d)
            },
            "the OBJ file is empty"
        ),
        case!(
            "mesh that is a named pipe",
            |d| {
                std::fs::remove_file(d.join(PETAL)).expect("remove");
                run_command("mkfifo", &[&in_dir(d, PETAL)]);
                info(d)
            },
            "petal.obj: it is a named pipe (FIFO), not a regular file"
        ),
        case!(
            "mesh with more vertices than the limit",
            |d| {
                let mut file = std::fs::File::create(d.join(PETAL)).expect("create");
                let line = b"v 0 0 0\n";
                let block: Vec<u8> = line.repeat(10_000);
                for _ in 0..101 {
                    file.write_all(&block).expect("write");
                }
                info(d)
            },
            "OBJ line 1000001: more than 1000000 vertices"
        ),
        case!(
            "mesh file larger than the limit",
            |d| {
                // Sparse: no disk is used.
                let file = std::fs::File::create(d.join(PETAL)).expect("create");
                file.set_len(300 << 20).expect("grow");
                info(d)
            },
            "it is 300 MiB (314572800 bytes), more than the limit of 256 MiB for an OBJ mesh"
        ),
        case!(
            "mesh in another unit (x100)",
            |d| {
                edit_petal(d, |_, l| {
                    Some(match l.strip_prefix("v ") {
                        Some(xyz) => {
                            let scaled: Vec<String> = xyz
                                .split(' ')
                                .map(|c| (c.parse::<f64>().expect("number") * 100.0).to_string())
                                .collect();
                            format!("v {}", scaled.join(" "))
                        }
                        None => l.to_string(),
                    })
                });
                simulate(d, &[])
            },
            "perhaps made in millimetres for a project in centimetres"
        ),
        // ------------------------------------------------------- maps (PNG)
        case!(
            "garbage PNG",
            |d| {
                write(d, MAP, "this is not a picture");
                info(d)
            },
            "e_growth.png: not a PNG image: the data is text"
        ),
        case!(
            "truncated PNG",
            |d| {
                let bytes = std::fs::read(d.join(MAP)).expect("read");
                write(d, MAP, &bytes[..bytes.len() / 2]);
                info(d)
            },
            "petal-step40-e_growth.png: corrupt or truncated PNG"
        ),
        case!(
            "map of the wrong size",
            |d| {
                write(d, "maps/petal-step40-w_growth.png", grey_png(5, 5, 30000));
                info(d)
            },
            "petal-step40-w_growth.png: the map is 5x5 pixels but the template's other maps are 32x32"
        ),
        case!(
            "map of 16384 x 16384 pixels",
            |d| {
                write(d, MAP, huge_png_header(16384));
                info(d)
            },
            "the map is 16384x16384 pixels, more than the limit of 4096x4096"
        ),
        case!(
            "map that links to /dev/zero",
            |d| {
                std::fs::remove_file(d.join(MAP)).expect("remove");
                std::os::unix::fs::symlink("/dev/zero", d.join(MAP)).expect("link");
                info(d)
            },
            "is refused: the path leads outside the project's folder through a symbolic link"
        ),
        case!(
            "map that is a named pipe",
            |d| {
                std::fs::remove_file(d.join(MAP)).expect("remove");
                run_command("mkfifo", &[&in_dir(d, MAP)]);
                info(d)
            },
            "e_growth.png: it is a named pipe (FIFO), not a regular file"
        ),
        case!(
            "negative growth constant (e_growth = -5)",
            |d| {
                replace(
                    d,
                    PROJECT,
                    "e_growth = \"maps/petal-step40-e_growth.png\"",
                    "e_growth = -5.0",
                );
                info(d)
            },
            "the e_growth map holds -5; map values must be 0 or more"
        ),
        // ------------------------------------------------------- project file
        case!(
            "project cut inside a string",
            |d| {
                let text = read(d, PROJECT);
                let cut = text.find("name = \"").expect("a name") + 9;
                write(d, PROJECT, &text[..cut]);
                info(d)
            },
            "TOML parse error at line 4, column 10"
        ),
        case!(
            "project cut right after its header",
            |d| {
                let text = read(d, PROJECT);
                let cut = text.find("\n[simulation]").expect("a section");
                write(d, PROJECT, &text[..cut]);
                info(d)
            },
            "the project defines no templates ([[templates]]); is the file cut short?"
        ),
        case!(
            "project without organs",
            |d| {
                let text = read(d, PROJECT);
                let cut = text.find("\n[[organs]]").expect("organs");
                write(d, PROJECT, &text[..cut]);
                info(d)
            },
            "the project has no organs ([[organs]]); is the file cut short?"
        ),
        case!(
            "project from a newer version",
            |d| {
                replace(d, PROJECT, "version = 2", "version = 99");
                info(d)
            },
            "was written by a newer Anthesis (format version 99; this build reads up to 9)"
        ),
        case!(
            "NaN parameter",
            |d| {
                replace(d, PROJECT, "thickness = 0.2", "thickness = nan");
                info(d)
            },
            "template \"petal\": thickness must be greater than 0, found NaN"
        ),
        case!(
            "zero parameter",
            |d| {
                replace(d, PROJECT, "thickness = 0.2", "thickness = 0.0");
                info(d)
            },
            "template \"petal\": thickness must be greater than 0, found 0"
        ),
        case!(
            "dg = -1",
            |d| {
                replace(d, PROJECT, "dg = 0.003", "dg = -1.0");
                info(d)
            },
            "dg must be a number greater than -1"
        ),
        case!(
            "mesh path climbing out of the folder",
            |d| {
                replace(
                    d,
                    PROJECT,
                    "\"meshes/petal.obj\"",
                    "\"../../../../etc/passwd\"",
                );
                info(d)
            },
            "mesh = \"../../../../etc/passwd\" is refused: the path leaves the project's folder"
        ),
        case!(
            "absolute mesh path",
            |d| {
                replace(d, PROJECT, "\"meshes/petal.obj\"", "\"/etc/hostname\"");
                info(d)
            },
            "mesh = \"/etc/hostname\" is refused: the path is absolute"
        ),
        case!(
            "a billion keyframes in the file",
            |d| {
                replace(d, PROJECT, "keyframes = 3", "keyframes = 1000000000");
                simulate(d, &[])
            },
            "simulation: keyframes is 1000000000, more than the limit of 10000"
        ),
        case!(
            "organ of a template that does not exist",
            |d| {
                replace(d, PROJECT, "template = \"petal\"", "template = \"tulip\"");
                info(d)
            },
            "organ \"petal-1\" uses template \"tulip\", which the project does not define"
        ),
        case!(
            "project path that does not exist",
            |d| vec!["info".into(), in_dir(d, "missing.anthesis.toml")],
            "missing.anthesis.toml: it does not exist"
        ),
        case!(
            "project folder without a project file",
            |d| {
                let folder = d.join("no-project");
                std::fs::create_dir_all(&folder).expect("mkdir");
                vec!["info".into(), folder.display().to_string()]
            },
            "no-project: the folder holds no project file (*.anthesis.toml)"
        ),
        case!(
            "project path that is a device",
            |_| vec!["info".into(), "/dev/zero".into()],
            "/dev/zero: it is a character device (like /dev/zero), not a regular file"
        ),
        // ------------------------------------------------ arguments, outputs
        case!(
            "a billion keyframes asked for",
            |d| simulate(d, &["--keyframes", "1000000000"]),
            "--keyframes 1000000000 is more than the limit of 10000"
        ),
        case!(
            "zero keyframes asked for",
            |d| simulate(d, &["--keyframes", "0"]),
            "--keyframes must be at least 1"
        ),
        case!(
            "an organ that does not exist",
            |d| simulate(d, &["--organ", "nobody"]),
            "no organ named `nobody` (organs: petal-1, sepal-1)"
        ),
        case!(
            ".glb into a missing folder",
            |d| simulate(d, &["--out", "/no/such/folder/x.glb"]),
            "cannot write /no/such/folder/x.glb: the folder /no does not exist"
        ),
        case!(
            "statistics into a missing folder",
            |d| {
                let stats = in_dir(d, "no/such/stats.json");
                simulate(d, &["--stats", &stats])
            },
            "stats.json: the folder"
        ),
        case!(
            "--fps 1e-300",
            |d| {
                let out = in_dir(d, "x.glb");
                simulate(d, &["--out", &out, "--fps", "1e-300"])
            },
            "too close together or too far apart in time"
        ),
        case!(
            "--max-targets 0",
            |d| {
                let out = in_dir(d, "x.glb");
                simulate(d, &["--out", &out, "--max-targets", "0"])
            },
            "an animation needs at least one morph target per mesh"
        ),
        case!(
            "output where nothing can be written",
            |d| simulate(d, &["--out", "/proc/x.glb"]),
            "cannot write /proc/x.glb: No such file or directory (os error 2)"
        ),
        case!(
            "output onto a block device",
            |d| {
                let disk = in_dir(d, "disk.glb");
                run_command("mknod", &[&disk, "b", "7", "200"]);
                simulate(d, &["--out", &disk])
            },
            "disk.glb: it is a block device (a disk), not a file, and is left as it is"
        ),
        // ------------------------------------------------------------ memory
        case!(
            "a run larger than the memory it may use",
            |d| simulate(d, &[]),
            "of 364 triangles, 28 KiB for 4 keyframes), but only 1 MiB of memory is available",
            &[("ANTHESIS_MEMORY_LIMIT_MIB", "1")]
        ),
        case!(
            "a memory limit that is not a number",
            |d| simulate(d, &[]),
            "ANTHESIS_MEMORY_LIMIT_MIB must be a whole number of MiB above 0, found lots",
            &[("ANTHESIS_MEMORY_LIMIT_MIB", "lots")]
        ),
        // -------------------------------------------------------- resolution
        case!(
            "a mean edge that would make millions of particles",
            |d| simulate(d, &["--edge", "0.0001"]),
            "of memory is available; simulate fewer organs (one organ alone) or keyframes, or use a coarser mesh",
            &[("ANTHESIS_MEMORY_LIMIT_MIB", "4096")]
        ),
        case!(
            "a mean edge too long for a template",
            |d| simulate(d, &["--edge", "50"]),
            "template \"petal\" cannot be remeshed at mean edge 50: target edge 50 is too large for this organ"
        ),
        case!(
            "a mean edge in the file that is not a length",
            |d| {
                replace(
                    d,
                    PROJECT,
                    "[simulation]\n",
                    "[simulation]\nmean_edge = -1.0\n",
                );
                info(d)
            },
            "simulation: mean_edge must be a positive length, found -1"
        ),
        // ------------------------------------------------------------ solver
        case!(
            "a solver that does not converge",
            |d| {
                replace(d, PROJECT, "max_iterations = 50", "max_iterations = 1");
                simulate(d, &[])
            },
            "error: keyframe 1, organ `sepal-1`: not converged after 1 iterations"
        ),
    ]
}

/// Runs the binary, killing it after [`MAX_SECONDS`].
fn run_bounded(args: &[String], env: &[(&str, &str)]) -> (Option<i32>, String, Duration) {
    let started = Instant::now();
    let mut child = common::command()
        .args(args)
        .envs(env.iter().copied())
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    loop {
        if let Some(status) = child.try_wait().expect("wait") {
            let output = child.wait_with_output().expect("output");
            return (status.code(), text(&output.stderr), started.elapsed());
        }
        if started.elapsed() > Duration::from_secs(MAX_SECONDS) {
            let _ = child.kill();
            let _ = child.wait();
            return (
                None,
                "(killed: it did not finish)".into(),
                started.elapsed(),
            );
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[test]
fn every_bad_input_gets_its_message_and_exit_code_1() {
    let mut failures = Vec::new();
    let discover = std::env::var_os("ANTHESIS_CATALOGUE_PRINT").is_some();
    for case in catalogue() {
        let dir = tempfile::tempdir().expect("tempdir");
        valid_project(dir.path());
        let args = (case.prepare)(dir.path());
        let expected = case.expect;
        let (code, stderr, took) = run_bounded(&args, case.env);
        let last = stderr.trim_end().lines().last().unwrap_or("").to_string();
        if discover {
            eprintln!(
                "{:<45} {code:?} {:.2}s {last}",
                case.name,
                took.as_secs_f64()
            );
        }
        let problem = if code != Some(1) {
            Some(format!("exit code {code:?}"))
        } else if !last.starts_with("error: ") {
            Some("no `error:` line".to_string())
        } else if !last.contains(expected) {
            Some(format!("expected `{expected}`"))
        } else if stderr.contains("panicked") {
            Some("a panic".to_string())
        } else if stderr.contains("root:") {
            Some("echoes /etc/passwd".to_string())
        } else {
            None
        };
        if let Some(problem) = problem {
            failures.push(format!("{}: {problem}; stderr:\n{stderr}", case.name));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn the_readme_lists_the_limits_the_code_enforces() {
    let readme =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../README.md"))
            .expect("README");
    let mib = |bytes: u64| format!("{} MiB", bytes >> 20);
    let lengths = anthesis_flower::scale::LENGTH_IN_THICKNESSES;
    let rows = [
        format!(
            "| Project file | {} |",
            mib(anthesis_flower::project::MAX_PROJECT_BYTES)
        ),
        format!(
            "| OBJ mesh file | {} |",
            mib(anthesis_mesh::obj::MAX_OBJ_BYTES)
        ),
        format!(
            "| Vertices per mesh | {} |",
            grouped(anthesis_mesh::obj::MAX_VERTICES as u64)
        ),
        format!(
            "| Triangles per mesh | {} |",
            grouped(anthesis_mesh::obj::MAX_TRIANGLES as u64)
        ),
        format!(
            "| Texture coordinates (`vt`) per mesh | {} |",
            grouped(anthesis_mesh::obj::MAX_TEXCOORDS as u64)
        ),
        format!(
            "| Mesh coordinates | within ±{:e} |",
            anthesis_mesh::validate::MAX_COORDINATE
        ),
        format!(
            "| Organ length | {} to {} times the template's thickness |",
            lengths.start(),
            lengths.end()
        ),
        format!("| PNG map file | {} |", mib(anthesis_maps::MAX_PNG_BYTES)),
        format!(
            "| Map width and height | {} pixels each |",
            anthesis_maps::MAX_MAP_SIDE
        ),
        format!(
            "| Keyframes of a run | {} |",
            grouped(u64::from(anthesis_flower::MAX_KEYFRAMES))
        ),
        format!(
            "| Render vertices per subdivided organ (`--subdivide`) | {} |",
            grouped(anthesis_mesh::subdivide::MAX_SUBDIVIDED_VERTICES)
        ),
        format!(
            "| Render positions of an export (render vertices × keyframes) | {} |",
            grouped(anthesis_export::MAX_RENDER_POSITIONS)
        ),
        format!(
            "| Template and organ names | {} characters |",
            anthesis_flower::project::MAX_NAME_CHARS
        ),
    ];
    for row in rows {
        assert!(readme.contains(&row), "README lacks the row `{row}`");
    }
}

//! The bad-input catalogue: every bad file and argument named in issue 17
//! and in the project's design brief, given to the `anthesis` binary the way a user would,
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
    /// The exit code: 1 for an error, 2 for a command line clap refuses
    /// (its usage line follows the error).
    code: i32,
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
            code: 1,
        }
    };
}

/// A case of a command line clap refuses (exit code 2).
macro_rules! usage_case {
    ($name:expr, $prepare:expr, $expect:expr) => {
        Case {
            name: $name,
            prepare: $prepare,
            expect: $expect,
            env: &[],
            code: 2,
        }
    };
}

/// The built-in five-petal flower written to `dir/fp` (a project with a
/// `[structure]` of one whorl), its structure replaced by `structure`;
/// returns `info` on it.
fn five_petal_with_structure(dir: &Path, structure: &str) -> Vec<String> {
    let folder = dir.join("fp");
    let status = common::command()
        .args(["new", "--from", "five-petal"])
        .arg(&folder)
        .stderr(Stdio::null())
        .status()
        .expect("the binary runs");
    assert!(status.success(), "new --from five-petal");
    let file = folder.join("five-petal.anthesis.toml");
    let text = std::fs::read_to_string(&file).expect("read");
    let cut = text.find("[structure]").expect("a structure");
    std::fs::write(&file, format!("{}{structure}\n", &text[..cut])).expect("write");
    vec!["info".into(), file.display().to_string()]
}

/// `[structure]` of an L-system placing surface `p` as the template
/// `petal`, derived `steps` times (`text` with `\n` escapes for TOML).
fn lsystem(text: &str, steps: u32) -> String {
    format!(
        "[structure]\nkind = \"lsystem\"\n[structure.lsystem]\nsteps = {steps}\n\
         text = \"{text}\"\nsurfaces = {{ p = \"petal\" }}"
    )
}

/// `bud.json` (the lily petal's PDE sweep) and `open.json` (`edit` applied
/// to its JSON) in `dir`; returns `pde-blossom bud.json open.json` and
/// `more`.
fn pde_pair(dir: &Path, edit: fn(&mut serde_json::Value), more: &[&str]) -> Vec<String> {
    let bud = in_dir(dir, "bud.json");
    let status = common::command()
        .args(["bud", "--example", "lily-petal", "--save-surface", &bud])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .expect("the binary runs");
    assert!(status.success(), "bud --save-surface");
    let mut open: serde_json::Value = serde_json::from_str(&read(dir, "bud.json")).expect("json");
    edit(&mut open);
    write(dir, "open.json", open.to_string());
    let mut args = vec!["pde-blossom".to_string(), bud, in_dir(dir, "open.json")];
    args.extend(more.iter().map(|s| s.to_string()));
    args
}

/// The open state as the bud (a valid pair).
fn same(_: &mut serde_json::Value) {}

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
            // The version this build reads is checked in the flower crate's
            // project tests; here, that the command says it in one line.
            "was written by a newer Anthesis (format version 99; this build reads up to "
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
            "--keyframes must be a whole number from 1 to 10,000, got 1000000000"
        ),
        case!(
            "zero keyframes asked for",
            |d| simulate(d, &["--keyframes", "0"]),
            "--keyframes must be a whole number from 1 to 10,000, got 0"
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
            "a mean edge finer than the memory allows",
            |d| simulate(d, &["--edge", "0.04"]),
            "of memory is available; simulate fewer organs (one organ alone) or keyframes, or use a coarser mesh",
            &[("ANTHESIS_MEMORY_LIMIT_MIB", "16")]
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
        // ------------------------------------- counts and sizes (issue 38)
        case!(
            "an L-system placing more organs than the limit",
            |d| five_petal_with_structure(d, &lsystem("axiom: ~p f(10)\\n~p -> ~p f(10) ~p", 14)),
            "the structure makes 16384 organs; at most 10000 are allowed"
        ),
        case!(
            "an L-system piling thousands of organs on one spot",
            |d| five_petal_with_structure(d, &lsystem("axiom: ~p\\n~p -> ~p ~p", 13)),
            "the structure's organs meet in more than 1000000 pairs (overlap rules)"
        ),
        case!(
            "a whorl of a billion organs",
            |d| five_petal_with_structure(
                d,
                "[structure]\nkind = \"whorls\"\n[[structure.whorls]]\nname = \"petal\"\n\
                 template = \"petal\"\ncount = 1000000000\nradius = 4.0\nhalf_span_deg = 25.0"
            ),
            "the structure makes 1000000000 organs; at most 10000 are allowed"
        ),
        case!(
            "an L-system angle of 0/0",
            |d| five_petal_with_structure(d, &lsystem("axiom: +(0/0) ~p", 0)),
            "L-system line 1, column 10: `0/0` is NaN, not a finite number"
        ),
        case!(
            "a mean edge that would make a trillion particles",
            |d| simulate(d, &["--edge", "1e-9"]),
            "--edge 0.000000001 would remesh template \"petal\" into about"
        ),
        case!(
            "info at a mean edge past the particle limit",
            |d| {
                let mut args = info(d);
                args.extend(["--edge".to_string(), "1e-9".to_string()]);
                args
            },
            "more than the limit of 200,000 per template; give a mean edge of at least"
        ),
        case!(
            "a negative keyframe count",
            |d| simulate(d, &["--keyframes", "-5"]),
            "--keyframes must be a whole number from 1 to 10,000, got -5"
        ),
        usage_case!(
            "a negative mean edge",
            |d| simulate(d, &["--edge", "-1"]),
            "`-1` is not a mean edge length: give a positive number in project units, or as-built"
        ),
        case!(
            "a frame rate of 0",
            |d| simulate(d, &["--fps", "0"]),
            "--fps must be a number of keyframes per second above 0 (and finite), got 0"
        ),
        case!(
            "a negative frame rate",
            |d| simulate(d, &["--fps", "-1"]),
            "--fps must be a number of keyframes per second above 0 (and finite), got -1"
        ),
        case!(
            "a frame rate that is not a number",
            |d| simulate(d, &["--fps", "NaN"]),
            "--fps must be a number of keyframes per second above 0 (and finite), got NaN"
        ),
        case!(
            "a GIF frame rate of 0",
            |d| {
                let gif = in_dir(d, "a.gif");
                let mut args = vec!["render".to_string(), project(d)];
                args.extend(["--animation".into(), gif, "--fps".into(), "0".into()]);
                args
            },
            "--fps must be from 0.0016 to 50 frames per second for a GIF"
        ),
        case!(
            "an unknown subcommand",
            |_| vec!["grow".to_string()],
            "`grow` is not a subcommand (they are: info, simulate, render, bud, import-scan, blossom, pde-blossom, fit, measure, new)"
        ),
        case!(
            "blossom with a billion keyframes",
            |d| vec![
                "blossom".into(),
                in_dir(d, PETAL),
                in_dir(d, PETAL),
                "--keyframes".into(),
                "1000000000".into()
            ],
            "--keyframes must be a whole number from 1 to 10,000, got 1000000000"
        ),
        case!(
            "pde-blossom with a billion keyframes",
            |d| pde_pair(d, same, &["--keyframes", "1000000000"]),
            "--keyframes must be a whole number from 1 to 10,000, got 1000000000"
        ),
        case!(
            "pde-blossom with a negative keyframe count",
            |d| pde_pair(d, same, &["--keyframes", "-5"]),
            "--keyframes must be a whole number from 1 to 10,000, got -5"
        ),
        case!(
            "pde-blossom with no nodes",
            |d| pde_pair(d, same, &["--nodes", "0"]),
            "--nodes must be a whole number from 4 to 1,024, got 0"
        ),
        case!(
            "pde-blossom with a hundred million nodes",
            |d| pde_pair(d, same, &["--nodes", "100000000"]),
            "--nodes must be a whole number from 4 to 1,024, got 100000000"
        ),
        case!(
            "pde-blossom with a hundred million rows",
            |d| pde_pair(d, same, &["--rows", "100000000"]),
            "--rows must be a whole number from 1 to 1,024, got 100000000"
        ),
        case!(
            "pde-blossom with rows x nodes x keyframes past the limit",
            |d| pde_pair(d, same, &["--rows", "1000", "--nodes", "1000"]),
            "is 100,200,100 node-steps, more than the limit of 10,000,000"
        ),
        // ------------------------------ silent wrong results (issue 38)
        case!(
            "new --from into a folder holding the user's own petal",
            |d| {
                let folder = d.join("mine");
                std::fs::create_dir_all(folder.join("meshes")).expect("mkdir");
                std::fs::write(folder.join("meshes/petal.obj"), "my own petal\n").expect("write");
                vec![
                    "new".into(),
                    "--from".into(),
                    "lily".into(),
                    folder.display().to_string(),
                ]
            },
            "meshes/petal.obj already exists; `new` writes only files it creates"
        ),
        case!(
            "pde-blossom with the open state's margins swapped",
            |d| pde_pair(
                d,
                |open| {
                    let swap = |open: &mut serde_json::Value, a: &str, b: &str| {
                        let first = open[a].take();
                        open[a] = open[b].take();
                        open[b] = first;
                    };
                    swap(open, "margin0", "margin1");
                    swap(open, "tangent0", "tangent1");
                },
                &[]
            ),
            "the open state's margins are the other way round from the bud's"
        ),
        case!(
            "two [[overlaps]] entries that contradict each other",
            |d| {
                let mut args = five_petal_with_structure(
                    d,
                    "[structure]\nkind = \"whorls\"\n[[structure.whorls]]\nname = \"petal\"\n\
                     template = \"petal\"\ncount = 5\nradius = 4.0\nhalf_span_deg = 25.0",
                );
                let file = std::path::PathBuf::from(args.pop().expect("the project"));
                let text = std::fs::read_to_string(&file).expect("read");
                let text = text.replacen(
                    "overlaps = []",
                    "overlaps = [{ inner = \"petal-1\", outer = \"petal-2\" }, \
                     { inner = \"petal-2\", outer = \"petal-1\" }]",
                    1,
                );
                std::fs::write(&file, text).expect("write");
                args.push(file.display().to_string());
                args
            },
            "[[overlaps]] 1 puts \"petal-1\" inside \"petal-2\", but [[overlaps]] 2 puts \"petal-2\" inside \"petal-1\"; keep one of them"
        ),
        case!(
            "pde-blossom reading /dev/zero as a surface",
            |d| {
                let mut args = pde_pair(d, same, &[]);
                args[1] = "/dev/zero".into();
                args
            },
            "cannot read PDE sweep surface /dev/zero: it is a character device"
        ),
        case!(
            "pde-blossom with a control point at 1e308 (found by fuzzing)",
            |d| pde_pair(
                d,
                |open| open["margin0"][1][1] = serde_json::json!(-1e308),
                &[]
            ),
            "coordinates must be finite and within ±1e6"
        ),
        // ------------------------------ issue 38 leftovers, issue 40 item 3
        case!(
            "pde-blossom with an edge of 1e-9 (a saturated vertex count once)",
            |d| pde_pair(d, same, &["--edge", "1e-9"]),
            "--edge 0.000000001 would mesh the bud (area 510.0258) into about 5.89e20 vertices; a \
             mesh may have at most 200,000 (the largest organ the solver and the exports handle, \
             as `anthesis info` lists): use --edge 0.0554 or longer"
        ),
        case!(
            "a thickness of 0.001 on a petal 18.2 long (issue 40: the run stopped without a word about it)",
            |d| {
                replace(d, PROJECT, "thickness = 0.2", "thickness = 0.001");
                simulate(d, &[])
            },
            "its mesh is 18.2 long, 18200 times its thickness 0.001, but organs are 10 to 2000 \
             thicknesses long"
        ),
        case!(
            "a stretch stiffness 20,000 times below the bend stiffness",
            |d| {
                replace(
                    d,
                    PROJECT,
                    "stretch_stiffness = 20.0",
                    "stretch_stiffness = 0.001",
                );
                replace(d, PROJECT, "keyframes = 3", "keyframes = 20");
                simulate(d, &[])
            },
            "; Kb 20 of `petal` is 20,000 times its Ks 0.001, above the range where the solver \
             converges (Kb up to 3,000 times Ks; the shipped flowers have Kb = Ks): raise Ks or \
             lower Kb"
        ),
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
        // The last error line (clap's usage lines follow its error).
        let last = stderr
            .lines()
            .rev()
            .find(|line| line.starts_with("error: "))
            .unwrap_or("")
            .to_string();
        if discover {
            eprintln!(
                "{:<45} {code:?} {:.2}s {last}",
                case.name,
                took.as_secs_f64()
            );
        }
        let problem = if code != Some(case.code) {
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
        format!(
            "| Particles per remeshed template (`--edge`, `mean_edge`) | {} |",
            grouped(anthesis_flower::resolution::MAX_PARTICLES_PER_TEMPLATE as u64)
        ),
        format!(
            "| Organs a structure makes (whorls, spiral, L-system `~X`) | {} |",
            grouped(anthesis_flower::structure::MAX_STRUCTURE_ORGANS as u64)
        ),
        format!(
            "| Overlap rules a structure makes | {} |",
            grouped(anthesis_flower::structure::MAX_OVERLAP_RULES as u64)
        ),
        format!(
            "| L-system derived word | {} modules, {} derivation steps |",
            grouped(anthesis_flower::structure::lsystem::MAX_MODULES as u64),
            anthesis_flower::structure::lsystem::MAX_STEPS
        ),
        format!(
            "| L-system parameter expression | {} terms |",
            anthesis_flower::structure::lsystem::MAX_EXPRESSION_TERMS
        ),
        format!(
            "| `blossom` and `pde-blossom` keyframes | 1 to {} |",
            grouped(u64::from(anthesis_flower::MAX_KEYFRAMES))
        ),
        format!(
            "| `pde-blossom --nodes` | 4 to {} |",
            grouped(anthesis_app::cli::pde_blossom::MAX_NODES as u64)
        ),
        format!(
            "| `pde-blossom --rows` | 1 to {} |",
            grouped(anthesis_app::cli::pde_blossom::MAX_ROWS as u64)
        ),
        format!(
            "| `pde-blossom` (rows + 1) × (nodes + 1) × keyframes | {} |",
            grouped(anthesis_app::cli::pde_blossom::MAX_NODE_STEPS as u64)
        ),
    ];
    for row in rows {
        assert!(readme.contains(&row), "README lacks the row `{row}`");
    }
}

/// The binary run on the valid project with its standard streams as given.
fn run_with_streams(dir: &Path, args: &[String], stdout: Stdio, stderr: Stdio) -> (i32, String) {
    let output = common::command()
        .args(args)
        .current_dir(dir)
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::null())
        .stdout(stdout)
        .stderr(stderr)
        .output()
        .expect("the binary runs");
    (output.status.code().unwrap_or(-1), text(&output.stderr))
}

fn dev_full() -> Stdio {
    Stdio::from(std::fs::File::create("/dev/full").expect("/dev/full"))
}

#[test]
fn a_full_standard_error_loses_no_result_and_panics_nowhere() {
    // Issue 38: any command with `2>/dev/full` panicked (exit 101); a
    // successful `simulate --out x.glb` panicked at its last line and
    // wrote no .glb.
    let dir = tempfile::tempdir().expect("tempdir");
    valid_project(dir.path());
    let glb = in_dir(dir.path(), "x.glb");
    let args = simulate(dir.path(), &["--keyframes", "1", "--out", &glb]);
    let (code, _) = run_with_streams(dir.path(), &args, Stdio::null(), dev_full());
    assert_eq!(code, 1, "a message that could not be said is an error");
    let bytes = std::fs::read(&glb).expect("the .glb is written");
    assert!(bytes.starts_with(b"glTF"), "a .glb");
    // A failing command as well: exit 1, not a panic's 101.
    let (code, _) = run_with_streams(
        dir.path(),
        &["info".into(), in_dir(dir.path(), "missing.anthesis.toml")],
        Stdio::null(),
        dev_full(),
    );
    assert_eq!(code, 1);
}

#[test]
fn a_full_or_closed_standard_output_is_an_error_naming_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    valid_project(dir.path());
    let (code, stderr) =
        run_with_streams(dir.path(), &info(dir.path()), dev_full(), Stdio::piped());
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("error: cannot write to standard output: No space left on device"),
        "{stderr}"
    );
    // `info >&-` exited 0 having written nothing.
    let output = Command::new("sh")
        .args([
            "-c",
            "exec \"$0\" \"$@\" >&-",
            env!("CARGO_BIN_EXE_anthesis"),
        ])
        .args(info(dir.path()))
        .env("ANTHESIS_CACHE_DIR", "")
        .output()
        .expect("sh runs");
    let stderr = text(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("error: cannot write to standard output: it is closed"),
        "{stderr}"
    );
}

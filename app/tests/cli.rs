//! The `anthesis` binary end to end: a project on disk in, a one-line
//! answer or files out, and a non-zero exit with one line on bad input.

use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
#[path = "cli/measure.rs"]
mod measure;

use common::{anthesis, one_line_error, text};

fn saved_whorl(dir: &Path, organs: usize, keyframes: u32) -> PathBuf {
    let project = anthesis_sim::fixtures::whorl(organs, 8, 14, keyframes);
    let path = dir.join("whorl.anthesis.toml");
    anthesis_flower::project::save_project(&project, &path).expect("save");
    path
}

#[test]
fn info_prints_one_line_per_organ_with_counts() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = saved_whorl(dir.path(), 2, 3);
    let out = anthesis(&["info", path.to_str().expect("utf-8")]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(
        lines[..2],
        ["petal-1 petal 112 182 293", "sepal-1 sepal 112 182 293"]
    );
    // Then its parts (the receptacle it sits on), then the size, in units:
    // the fixture does not say what its unit is.
    assert!(lines[2].starts_with("part receptacle "), "{stdout}");
    assert!(
        lines[3..].iter().all(|l| l.starts_with("size ")),
        "{stdout}"
    );
    assert!(
        lines[3].contains("units") && lines[3].contains("one metre"),
        "{stdout}"
    );
}

#[test]
fn a_project_without_a_unit_loads_as_before_with_a_note_on_stderr() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = saved_whorl(dir.path(), 1, 3);
    let note = "note: the project does not say what its unit is, so one unit is taken as one metre";
    let how = "add e.g. `unit = \"1 mm\"` after its `name = …` line in the project file";
    // `info` says it in its size line (not again on stderr) ...
    let out = anthesis(&["info", path.to_str().expect("utf-8")]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        !text(&out.stderr).contains("note:"),
        "{}",
        text(&out.stderr)
    );
    // Sizes stay in units: the old meaning.
    let stdout = text(&out.stdout);
    assert!(
        stdout.contains(" units tall") && stdout.contains(how),
        "{stdout}"
    );
    // ... other commands once they have succeeded, on stderr.
    let glb = dir.path().join("flower.glb");
    let out = anthesis(&[
        "simulate",
        path.to_str().expect("utf-8"),
        "--out",
        glb.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stderr = text(&out.stderr);
    assert_eq!(
        stderr.lines().filter(|l| l.starts_with(note)).count(),
        1,
        "{stderr}"
    );
    assert!(stderr.contains(how), "{stderr}");
    // A command that fails says only its error, in one line.
    let out = anthesis(&[
        "simulate",
        path.to_str().expect("utf-8"),
        "--organ",
        "nobody",
    ]);
    assert!(!out.status.success());
    assert_eq!(
        text(&out.stderr).lines().count(),
        1,
        "{}",
        text(&out.stderr)
    );
    // A project that states its unit opens without it.
    let mut project = anthesis_flower::project::load_project(&path).expect("loads");
    project.flower.unit = anthesis_flower::Unit::millimetres(1.0);
    anthesis_flower::project::save_project(&project, &path).expect("save");
    let out = anthesis(&["info", path.to_str().expect("utf-8")]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stderr = text(&out.stderr);
    assert!(!stderr.contains("note:"), "{stderr}");
    assert!(
        text(&out.stdout).contains("(one unit is 1 mm)"),
        "{}",
        text(&out.stdout)
    );
}

#[test]
fn what_loading_reads_past_is_said_and_the_command_goes_on() {
    // A mesh from another tool with Blender's loose edges (`l`): read
    // past with a warning naming the file and line, which the command line
    // dropped.
    let dir = tempfile::tempdir().expect("tempdir");
    let path = saved_whorl(dir.path(), 2, 3);
    let obj = dir.path().join("meshes/petal.obj");
    let mut mesh = std::fs::read_to_string(&obj).expect("mesh");
    mesh.push_str("l 1 2\n");
    std::fs::write(&obj, mesh).expect("write");
    let out = anthesis(&["info", path.to_str().expect("utf-8")]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let organ_lines = text(&out.stdout)
        .lines()
        .filter(|l| !l.starts_with("size ") && !l.starts_with("part "))
        .count();
    assert_eq!(organ_lines, 2);
    let stderr = text(&out.stderr);
    let warnings: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("warning: "))
        .collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    assert!(
        warnings[0].contains("meshes/petal.obj: OBJ line")
            && warnings[0].contains("1 line (`l`) statement ignored"),
        "{stderr}"
    );
}

#[test]
fn edge_remeshes_what_info_counts_and_what_simulate_runs() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = saved_whorl(dir.path(), 2, 2);
    let p = path.to_str().expect("utf-8");
    let particles = |args: &[&str]| -> Vec<usize> {
        let out = anthesis(args);
        assert!(out.status.success(), "{}", text(&out.stderr));
        text(&out.stdout)
            .lines()
            .filter(|l| !l.starts_with("size ") && !l.starts_with("part "))
            .map(|l| {
                l.split(' ')
                    .nth(2)
                    .expect("particles")
                    .parse()
                    .expect("a count")
            })
            .collect()
    };
    let built = particles(&["info", p]);
    assert_eq!(particles(&["info", p, "--edge", "as-built"]), built);
    let project = anthesis_flower::project::load_project(&path).expect("loads");
    let edge = anthesis_bud::quality(&project.flower.templates[0].mesh).mean_edge;
    let fine = particles(&["info", p, "--edge", &format!("{}", edge / 2.0)]);
    // Half the edge, about four times the particles.
    for (f, b) in fine.iter().zip(&built) {
        assert!(*f > 3 * b && *f < 5 * b, "{fine:?} vs {built:?}");
    }
    // The project's own setting, and --edge over it.
    let text_file = std::fs::read_to_string(&path).expect("read");
    let set = text_file.replacen(
        "[simulation]\n",
        &format!("[simulation]\nmean_edge = {}\n", edge / 2.0),
        1,
    );
    std::fs::write(&path, set).expect("write");
    assert_eq!(particles(&["info", p]), fine);
    assert_eq!(particles(&["info", p, "--edge", "as-built"]), built);
    // A run at that resolution writes keyframes of the remeshed size.
    let stats = dir.path().join("stats.json");
    let out = anthesis(&[
        "simulate",
        p,
        "--organ",
        "petal-1",
        "--stats",
        stats.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    // Not a length: a usage error that says what --edge takes.
    let out = anthesis(&["info", p, "--edge", "0"]);
    assert!(!out.status.success());
    assert!(
        text(&out.stderr).contains("`0` is not a mean edge length"),
        "{}",
        text(&out.stderr)
    );
}

/// The entries of a remesh cache folder, sorted, with their bytes.
fn cache_entries(folder: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut entries: Vec<(PathBuf, Vec<u8>)> = std::fs::read_dir(folder)
        .map(|listing| {
            listing
                .map(|e| e.expect("entry").path())
                .map(|path| {
                    let bytes = std::fs::read(&path).expect("readable");
                    (path, bytes)
                })
                .collect()
        })
        .unwrap_or_default();
    entries.sort();
    entries
}

#[test]
fn remeshes_are_cached_and_a_damaged_or_unwritable_cache_never_stops_a_run() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = saved_whorl(dir.path(), 2, 2);
    let p = path.to_str().expect("utf-8");
    let project = anthesis_flower::project::load_project(&path).expect("loads");
    let edge = format!(
        "{}",
        anthesis_bud::quality(&project.flower.templates[0].mesh).mean_edge / 1.5
    );
    let root = dir.path().join("cache");
    let run = |root: &Path, args: &[&str]| {
        let out = common::command()
            .env("ANTHESIS_CACHE_DIR", root)
            .args(args)
            .output()
            .expect("the binary runs");
        assert!(out.status.success(), "{args:?}: {}", text(&out.stderr));
        (text(&out.stdout), text(&out.stderr))
    };
    let uncached = anthesis(&["info", p, "--edge", &edge]);
    let counts = text(&uncached.stdout);
    // The first run remeshes both templates and keeps them.
    assert_eq!(
        run(&root, &["info", p, "--edge", &edge]),
        (counts.clone(), String::new())
    );
    let folder = root.join("remesh");
    let kept = cache_entries(&folder);
    assert_eq!(kept.len(), 2, "{kept:?}");
    // The next reads them: the same answer, the same entries.
    assert_eq!(run(&root, &["info", p, "--edge", &edge]).0, counts);
    assert_eq!(cache_entries(&folder), kept);
    // A run from the cache is the run from a fresh remesh, bit for bit.
    let glb = |name: &str| dir.path().join(name);
    for (name, no_cache) in [("cached.glb", false), ("fresh.glb", true)] {
        let out = glb(name);
        let mut args = vec![
            "simulate",
            p,
            "--edge",
            &edge,
            "--organ",
            "petal-1",
            "--keyframes",
            "2",
            "--out",
            out.to_str().expect("utf-8"),
        ];
        if no_cache {
            args.push("--no-cache");
        }
        run(&root, &args);
    }
    assert!(
        std::fs::read(glb("cached.glb")).expect("written")
            == std::fs::read(glb("fresh.glb")).expect("written"),
        "the cached run's file differs from the fresh run's"
    );
    // Damaged entries are misses, said nowhere, and written anew.
    std::fs::write(&kept[0].0, &kept[0].1[..kept[0].1.len() / 3]).expect("truncated");
    std::fs::write(&kept[1].0, b"not a cache entry at all").expect("overwritten");
    assert_eq!(
        run(&root, &["info", p, "--edge", &edge]),
        (counts.clone(), String::new())
    );
    assert_eq!(cache_entries(&folder), kept);
    // --no-cache and an empty ANTHESIS_CACHE_DIR write nothing.
    let unused = dir.path().join("unused");
    run(&unused, &["info", p, "--edge", &edge, "--no-cache"]);
    assert!(!unused.exists());
    // A cache that cannot be written: the answer, and one warning.
    let file = dir.path().join("a-file");
    std::fs::write(&file, b"x").expect("written");
    let (stdout, stderr) = run(&file, &["info", p, "--edge", &edge]);
    assert_eq!(stdout, counts);
    let warnings: Vec<&str> = stderr.lines().collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    assert!(
        warnings[0].starts_with("warning: the cache in ")
            && warnings[0].contains("cannot be written, working without it"),
        "{stderr}"
    );
}

#[test]
fn simulate_writes_stats_json_and_a_glb() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = saved_whorl(dir.path(), 2, 4);
    let stats = dir.path().join("stats.json");
    let glb = dir.path().join("out.glb");
    let out = anthesis(&[
        "simulate",
        path.to_str().expect("utf-8"),
        "--keyframes",
        "5",
        "--stats",
        stats.to_str().expect("utf-8"),
        "--out",
        glb.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&stats).expect("stats")).expect("json");
    let keyframes = json["keyframes"].as_array().expect("keyframes array");
    assert_eq!(keyframes.len(), 5);
    for (i, k) in keyframes.iter().enumerate() {
        assert_eq!(k["index"], i + 1);
        for field in ["energy", "iterations", "relative_gradient", "seconds"] {
            assert!(k[field].is_number(), "keyframe {i} lacks {field}");
        }
    }
    let bytes = std::fs::read(&glb).expect("glb written");
    assert_eq!(&bytes[..4], b"glTF");
    // The receptacle rides along as a static mesh.
    assert!(String::from_utf8_lossy(&bytes).contains("\"receptacle\""));
    // And the Khronos validator accepts the file (installed by .ci/run:
    // `npm ci --prefix tests/gltf-validator`).
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/gltf-validator/validate.mjs");
    let report = Command::new("node").arg(&script).arg(&glb).output().expect(
        "node runs the glTF validator (install node and run `npm ci --prefix tests/gltf-validator`)",
    );
    assert!(
        report.status.success(),
        "validator failed: {}",
        text(&report.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&report.stdout).expect("validator JSON");
    assert_eq!(report["issues"]["numErrors"], 0, "{report:#}");
    assert_eq!(report["issues"]["numWarnings"], 0, "{report:#}");
}

#[test]
fn simulate_writes_usd_layers_as_text_and_binary() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = saved_whorl(dir.path(), 2, 4);
    let simulate_to = |file: &std::path::Path| {
        let out = anthesis(&[
            "simulate",
            path.to_str().expect("utf-8"),
            "--fps",
            "12",
            "--out",
            file.to_str().expect("utf-8"),
        ]);
        assert!(out.status.success(), "{}", text(&out.stderr));
    };
    let usda = dir.path().join("flower.usda");
    simulate_to(&usda);
    // Pixar's USD reads such layers back in anthesis-export's tests; here
    // the command line's choices show in the text.
    let layer = std::fs::read_to_string(&usda).expect("usda written");
    assert!(layer.starts_with("#usda 1.0"), "{}", &layer[..80]);
    for line in [
        "endTimeCode = 4",
        "timeCodesPerSecond = 12",
        "def Mesh \"petal_1\"",
        "def Mesh \"sepal_1\"",
        "def Mesh \"receptacle\"",
        "normal3f[] normals.timeSamples",
    ] {
        assert!(layer.contains(line), "no `{line}` in the layer");
    }
    // The last keyframe (4) is sampled in each of the two organs' points,
    // normals and extent.
    assert_eq!(layer.matches("\n            4.0: [(").count(), 2 * 3);
    assert_eq!(layer.matches("\n            5.0: [(").count(), 0);

    // `--out FILE.usdc` writes the binary crate form, which Pixar's USD
    // (the pinned usd-core of anthesis-export's USD tests) opens with every
    // mesh, every keyframe and the command line's frame rate.
    let usdc = dir.path().join("flower.usdc");
    simulate_to(&usdc);
    let bytes = std::fs::read(&usdc).expect("usdc written");
    assert!(bytes.starts_with(b"PXR-USDC"), "not a crate file");

    let usd = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/usd");
    let python = usd.join(".venv/bin/python");
    let read = std::process::Command::new(&python)
        .arg(usd.join("read_stage.py"))
        .arg(&usdc)
        .output()
        .unwrap_or_else(|e| {
            panic!(
                "cannot run {} ({e}): run `python3 -m venv tests/usd/.venv && \
                 tests/usd/.venv/bin/pip install -r tests/usd/requirements.txt` (.ci/run does)",
                python.display()
            )
        });
    assert!(read.status.success(), "{}", text(&read.stderr));
    let report: serde_json::Value = serde_json::from_slice(&read.stdout).expect("report");
    assert_eq!(report["file_format"], "usdc");
    assert_eq!(report["end_time_code"], 4.0);
    assert_eq!(report["time_codes_per_second"], 12.0);
    assert_eq!(report["validation_findings"], serde_json::json!([]));
    let meshes = report["meshes"].as_array().expect("meshes");
    let paths: Vec<&str> = meshes.iter().filter_map(|m| m["path"].as_str()).collect();
    assert_eq!(
        paths,
        ["/flower/petal_1", "/flower/sepal_1", "/flower/receptacle"]
    );
    for mesh in &meshes[..2] {
        assert_eq!(
            mesh["point_times"],
            serde_json::json!([0.0, 1.0, 2.0, 3.0, 4.0])
        );
        assert_eq!(mesh["points"].as_array().map(Vec::len), Some(5));
    }
}

#[test]
fn simulate_one_organ_and_obj_output() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = saved_whorl(dir.path(), 2, 2);
    // A missing folder whose parent exists is created.
    let objs = dir.path().join("objs");
    let out = anthesis(&[
        "simulate",
        path.to_str().expect("utf-8"),
        "--organ",
        "sepal-1",
        "--out",
        objs.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let count = std::fs::read_dir(&objs).expect("list").count();
    assert_eq!(count, 3, "bud + 2 keyframes");
    let first = std::fs::read_dir(&objs)
        .expect("list")
        .next()
        .expect("a file")
        .expect("entry")
        .path();
    let obj = std::fs::read_to_string(first).expect("read");
    assert!(obj.contains("o sepal-1") && !obj.contains("petal-1"));
}

#[test]
fn bad_input_gives_one_line_and_a_non_zero_exit() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = saved_whorl(dir.path(), 1, 2);
    let p = path.to_str().expect("utf-8");
    let missing = dir.path().join("nope.anthesis.toml");
    let truncated = dir.path().join("cut.anthesis.toml");
    let full = std::fs::read_to_string(&path).expect("read");
    // Cut inside a quoted string, as a crash mid-write would.
    let cut = full.find("name = \"").expect("a name") + 9;
    std::fs::write(&truncated, &full[..cut]).expect("write");
    let cases: Vec<Vec<String>> = vec![
        vec!["info".into(), missing.display().to_string()],
        vec!["info".into(), truncated.display().to_string()],
        vec![
            "simulate".into(),
            p.into(),
            "--organ".into(),
            "nobody".into(),
        ],
        vec![
            "simulate".into(),
            p.into(),
            "--keyframes".into(),
            "0".into(),
        ],
        vec![
            "simulate".into(),
            p.into(),
            "--out".into(),
            "/no/such/folder/x.glb".into(),
        ],
        vec![
            "simulate".into(),
            p.into(),
            "--out".into(),
            "/no/such/folder/x.usda".into(),
        ],
    ];
    for args in cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        one_line_error(&args);
    }
    // Every output argument and limit is checked before the simulation
    // starts (stderr has no "simulated" line), each with its own message.
    let glb = dir.path().join("flower.glb");
    let glb = glb.to_str().expect("utf-8");
    let missing_stats = dir.path().join("no/such/stats.json");
    let early: Vec<(Vec<&str>, String)> = vec![
        (
            vec![p, "--keyframes", "1000000000"],
            "--keyframes must be a whole number from 1 to 10,000, got 1000000000".into(),
        ),
        (
            vec![
                p,
                "--stats",
                missing_stats.to_str().expect("utf-8"),
                "--out",
                glb,
            ],
            format!(
                "the folder {} does not exist",
                dir.path().join("no").display()
            ),
        ),
        (
            vec![p, "--out", glb, "--fps", "1e-300"],
            "too close together or too far apart in time".into(),
        ),
        (
            vec![p, "--out", glb, "--max-targets", "0"],
            "morph target".into(),
        ),
    ];
    for (args, expected) in early {
        let mut all = vec!["simulate"];
        all.extend(&args);
        let out = one_line_error(&all);
        let stderr = text(&out.stderr);
        assert!(stderr.contains(&expected), "{args:?}: {stderr}");
        assert!(!stderr.contains("simulated"), "{args:?} ran: {stderr}");
    }
    assert!(!Path::new(glb).exists());

    let out = anthesis(&["simulate"]);
    assert_eq!(
        out.status.code(),
        Some(2),
        "a missing argument is a usage error"
    );
}

#[test]
fn without_a_subcommand_it_opens_the_window_or_says_why_not() {
    // No display here: the window cannot open, and that is one clear line.
    let out = common::command()
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET")
        .output()
        .expect("the binary runs");
    assert!(!out.status.success());
    let stderr = text(&out.stderr);
    let ours: Vec<&str> = stderr
        .lines()
        .filter(|l| !l.contains("XDG_RUNTIME_DIR"))
        .collect();
    assert_eq!(ours.len(), 1, "{stderr}");
    assert!(
        ours[0].starts_with("error: cannot open the window"),
        "{stderr}"
    );
}

#[test]
fn the_built_in_lily_needs_no_files() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = common::command()
        .args(["info", "builtin:lily"])
        .current_dir(dir.path())
        .output()
        .expect("the binary runs");
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let lines: Vec<&str> = stdout
        .lines()
        .filter(|l| !l.starts_with("size ") && !l.starts_with("part "))
        .collect();
    assert_eq!(lines.len(), 6, "{stdout}");
    assert_eq!(
        lines
            .iter()
            .filter(|l| l.split(' ').nth(1) == Some("petal"))
            .count(),
        3
    );
    assert_eq!(
        lines
            .iter()
            .filter(|l| l.split(' ').nth(1) == Some("sepal"))
            .count(),
        3
    );
    let out = anthesis(&["info", "builtin:tulip"]);
    assert!(!out.status.success());
    let stderr = text(&out.stderr);
    assert!(stderr.contains("no built-in flower `tulip`"), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1);
}

#[test]
fn a_project_the_window_cannot_open_is_refused_before_any_window() {
    // No display is needed: the project is loaded before the window opens,
    // and a bad one ends there with one line naming it.
    for (arg, says) in [
        // The message lists the flowers there are.
        (
            "builtin:tulip",
            &["no built-in flower `tulip`", "apple"][..],
        ),
        ("/no/such/folder", &["/no/such/folder"][..]),
    ] {
        let out = common::command()
            .arg(arg)
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .expect("runs");
        assert!(!out.status.success(), "{arg}");
        let stderr = text(&out.stderr);
        for said in says {
            assert!(stderr.contains(said), "{arg}: {stderr}");
        }
        assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    }
}

#[test]
fn a_mesh_in_another_unit_is_named_before_the_run() {
    // The whorl's petal mesh made in another unit: ×100 on the mesh alone
    // (thickness and positions as they were).
    let dir = tempfile::tempdir().expect("tempdir");
    let mut project = anthesis_sim::fixtures::whorl(1, 8, 14, 2);
    for p in &mut project.flower.templates[0].mesh.positions {
        *p *= 100.0;
    }
    let path = dir.path().join("mm.anthesis.toml");
    anthesis_flower::project::save_project(&project, &path).expect("save");
    let p = path.to_str().expect("utf-8");
    for command in ["info", "simulate"] {
        let out = one_line_error(&[command, p]);
        let stderr = text(&out.stderr);
        assert!(
            stderr.contains("times too large, perhaps made in")
                && stderr.contains("Scale the mesh"),
            "{command}: {stderr}"
        );
        assert!(!stderr.contains("simulated"), "{stderr}");
    }
}

#[test]
fn a_fleshy_petal_in_another_unit_is_named_by_where_it_sits() {
    // The lily with fleshy petals (thickness 2: 22 thicknesses long), its
    // petal mesh then made in millimetres (×10: 220 thicknesses, a
    // plausible organ): only where the petals sit shows the unit.
    let dir = tempfile::tempdir().expect("tempdir");
    let mut project = anthesis_garden::builtin_lily().expect("lily");
    let petal = project
        .flower
        .templates
        .iter()
        .position(|t| t.name == "petal")
        .expect("a petal template");
    project.flower.templates[petal].thickness = 2.0;
    let fleshy = dir.path().join("fleshy.anthesis.toml");
    anthesis_flower::project::save_project(&project, &fleshy).expect("save");
    for p in &mut project.flower.templates[petal].mesh.positions {
        *p *= 10.0;
    }
    // Its own folder: a project's meshes are saved beside it.
    let other = tempfile::tempdir().expect("tempdir");
    let millimetres = other.path().join("mm.anthesis.toml");
    anthesis_flower::project::save_project(&project, &millimetres).expect("save");

    let out = anthesis(&["info", fleshy.to_str().expect("utf-8")]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    for command in ["info", "simulate"] {
        let out = one_line_error(&[command, millimetres.to_str().expect("utf-8")]);
        let stderr = text(&out.stderr);
        assert!(
            stderr.contains("template \"petal\": organ petal-1's base is")
                && stderr.contains("10 times too large, perhaps made in millimetres")
                && stderr.contains("Scale the mesh by 0.1"),
            "{command}: {stderr}"
        );
    }
}

#[test]
fn a_reader_that_stops_reading_ends_the_output_quietly() {
    // `anthesis info builtin:lily | head -1`: the pipe's reader is gone
    // before the first line is written.
    let mut child = common::command()
        .args(["info", "builtin:lily"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("the binary runs");
    drop(child.stdout.take());
    let out = child.wait_with_output().expect("the binary ends");
    let stderr = text(&out.stderr);
    assert!(out.status.success(), "{:?}: {stderr}", out.status);
    assert!(stderr.is_empty(), "nothing on stderr, got: {stderr}");
}

/// The number of keyframes in a .glb written by `simulate`: the length of
/// the animation's time track.
fn glb_keyframe_count(bytes: &[u8]) -> u64 {
    assert_eq!(&bytes[..4], b"glTF");
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().expect("4 bytes")) as usize;
    let json: serde_json::Value =
        serde_json::from_slice(&bytes[20..20 + json_len]).expect("glTF JSON");
    let input = json["animations"][0]["samplers"][0]["input"]
        .as_u64()
        .expect("an animated file");
    json["accessors"][input as usize]["count"]
        .as_u64()
        .expect("a time track")
}

#[test]
fn a_step_that_fails_part_way_keeps_the_keyframes_before_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = saved_whorl(dir.path(), 2, 6);
    let glb = dir.path().join("kept.glb");
    // A panic inside keyframe 4 (the test-only hook of crates/sim/src/fault.rs;
    // a bug, the worst way a step can fail).
    let out = common::command()
        .args([
            "simulate",
            path.to_str().expect("utf-8"),
            "--out",
            glb.to_str().expect("utf-8"),
        ])
        .env("ANTHESIS_TEST_FAULT", "panic-at-keyframe:4")
        .env("RUST_BACKTRACE", "0")
        .output()
        .expect("the binary runs");
    assert!(!out.status.success());
    let stderr = text(&out.stderr);
    let last = stderr.trim_end().lines().last().expect("an error line");
    assert_eq!(
        last,
        format!(
            "error: the keyframes before it were written to {} (keyframes 0 to 3): keyframe 4: \
             internal error, the simulation stopped (a bug in Anthesis; please report it): \
             forced fault at keyframe 4 (test hook)",
            glb.display()
        )
    );
    let bytes = std::fs::read(&glb).expect("the file was written");
    assert_eq!(
        glb_keyframe_count(&bytes),
        4,
        "the bud and keyframes 1 to 3"
    );

    // Without the fault the same project writes all seven keyframes, so the
    // count above is the failure's doing.
    let whole = dir.path().join("whole.glb");
    let out = anthesis(&[
        "simulate",
        path.to_str().expect("utf-8"),
        "--out",
        whole.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(
        glb_keyframe_count(&std::fs::read(&whole).expect("written")),
        7
    );
}

/// The Khronos validator's report on `glb`, asserting no errors and no
/// warnings.
fn validated(glb: &Path) -> serde_json::Value {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/gltf-validator/validate.mjs");
    let report = Command::new("node").arg(&script).arg(glb).output().expect(
        "node runs the glTF validator (install node and run `npm ci --prefix tests/gltf-validator`)",
    );
    assert!(
        report.status.success(),
        "validator failed: {}",
        text(&report.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&report.stdout).expect("validator JSON");
    assert_eq!(report["issues"]["numErrors"], 0, "{report:#}");
    assert_eq!(report["issues"]["numWarnings"], 0, "{report:#}");
    report
}

/// `app/tests/fixtures/stranger`: a flower written by hand from the format
/// documentation with files as other tools write them (see its README).
fn stranger_flower() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/stranger")
}

/// The triangles an OBJ's faces make (a polygon of n corners makes n - 2)
/// and its distinct `v` statements used by faces.
fn obj_counts(path: &Path) -> (usize, usize) {
    let text = std::fs::read_to_string(path).expect("obj");
    let mut used = std::collections::BTreeSet::new();
    let mut triangles = 0;
    for line in text.lines() {
        if let Some(corners) = line.strip_prefix("f ") {
            let corners: Vec<&str> = corners.split_whitespace().collect();
            triangles += corners.len() - 2;
            for corner in corners {
                used.insert(corner.split('/').next().expect("v").to_string());
            }
        }
    }
    (used.len(), triangles)
}

#[test]
fn a_flower_made_elsewhere_loads_with_every_particle_and_triangle_of_its_files() {
    let folder = stranger_flower();
    // What makes it a stranger's: CRLF, n-gons, split vt, vn.
    let toml = std::fs::read(folder.join("stranger.anthesis.toml")).expect("project");
    assert!(toml.windows(2).any(|w| w == b"\r\n"));
    let broad = std::fs::read_to_string(folder.join("geo/broad.obj")).expect("obj");
    assert!(broad.contains("\r\nvn ") && broad.contains("\r\ng "));
    assert!(
        broad
            .lines()
            .any(|l| l.starts_with("f ") && l.split_whitespace().count() == 7),
        "a hexagon"
    );
    let out = anthesis(&["info", folder.to_str().expect("utf-8")]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (narrow_v, narrow_t) = obj_counts(&folder.join("geo/narrow.obj"));
    let (broad_v, broad_t) = obj_counts(&folder.join("geo/broad.obj"));
    // The organ lines (parts and sizes follow).
    let lines: Vec<String> = text(&out.stdout)
        .lines()
        .filter(|l| !l.starts_with("size ") && !l.starts_with("part "))
        .map(str::to_owned)
        .collect();
    assert_eq!(lines.len(), 9, "{lines:?}");
    for line in &lines {
        let words: Vec<&str> = line.split(' ').collect();
        let (particles, triangles) = match words[0].split('-').next() {
            Some("inner") => (narrow_v, narrow_t),
            Some("outer") => (broad_v, broad_t),
            other => panic!("{other:?} in {line}"),
        };
        assert_eq!(
            words[words.len() - 3..words.len() - 1],
            [particles.to_string(), triangles.to_string()],
            "{line}"
        );
    }
}

#[test]
fn a_flower_made_elsewhere_exports_smooth_and_finer_runs_that_validate() {
    let folder = stranger_flower();
    let f = folder.to_str().expect("utf-8");
    let dir = tempfile::tempdir().expect("tempdir");
    let mut vertices = Vec::new();
    for (name, args) in [
        ("as built", vec![]),
        ("smooth", vec!["--subdivide", "1"]),
        ("fine", vec!["--edge", "1.5"]),
    ] {
        let glb = dir.path().join(format!("{name}.glb"));
        let mut all = vec!["simulate", f, "--out", glb.to_str().expect("utf-8")];
        all.extend(args);
        let out = anthesis(&all);
        assert!(out.status.success(), "{name}: {}", text(&out.stderr));
        let info = &validated(&glb)["info"];
        // Nine organs and the receptacle; the two templates' colour maps
        // as textures.
        assert_eq!(info["drawCallCount"], 10, "{name}: {info:#}");
        let images = info["resources"]
            .as_array()
            .expect("resources")
            .iter()
            .filter(|r| {
                r["pointer"]
                    .as_str()
                    .is_some_and(|p| p.starts_with("/images/"))
            })
            .count();
        assert_eq!(images, 2, "{name}: {info:#}");
        vertices.push(info["totalVertexCount"].as_u64().expect("vertices"));
    }
    assert!(
        vertices[1] > 2 * vertices[0] && vertices[2] > vertices[0],
        "{vertices:?}"
    );
}

#[test]
fn simulate_subdivide_exports_smooth_render_meshes() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = saved_whorl(dir.path(), 2, 3);
    let receptacle =
        anthesis_flower::receptacle_for(&anthesis_sim::fixtures::whorl(2, 8, 14, 3).flower)
            .vertex_count();
    // Each organ: 112 particles, 293 edges, 182 triangles; one level adds a
    // vertex per edge (405), the second 2·293 + 3·182 more (1,537).
    for (level, per_organ) in [("0", 112), ("1", 405), ("2", 1537)] {
        for encoding in ["dense", "meshopt"] {
            let glb = dir.path().join(format!("level-{level}-{encoding}.glb"));
            let out = anthesis(&[
                "simulate",
                path.to_str().expect("utf-8"),
                "--subdivide",
                level,
                "--encoding",
                encoding,
                "--out",
                glb.to_str().expect("utf-8"),
            ]);
            assert!(out.status.success(), "{}", text(&out.stderr));
            let report = validated(&glb);
            assert_eq!(
                report["info"]["totalVertexCount"],
                2 * per_organ + receptacle,
                "level {level}, {encoding}"
            );
        }
    }
    // OBJ per keyframe: the same render meshes.
    let objs = dir.path().join("objs");
    let out = anthesis(&[
        "simulate",
        path.to_str().expect("utf-8"),
        "--subdivide",
        "2",
        "--out",
        objs.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let mut files: Vec<PathBuf> = std::fs::read_dir(&objs)
        .expect("folder")
        .map(|e| e.expect("entry").path())
        .collect();
    files.sort();
    assert_eq!(files.len(), 4, "the bud and three keyframes");
    let obj = std::fs::read_to_string(&files[3]).expect("obj");
    let vertices = obj.lines().filter(|l| l.starts_with("v ")).count();
    assert_eq!(vertices, 2 * 1537 + receptacle);
    let triangles = obj.lines().filter(|l| l.starts_with("f ")).count();
    assert_eq!(
        triangles,
        2 * 16 * 182
            + anthesis_flower::receptacle_for(&anthesis_sim::fixtures::whorl(2, 8, 14, 3).flower)
                .triangle_count()
    );
}

#[test]
fn a_render_level_too_fine_is_refused_with_the_vertex_count_before_the_run() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = saved_whorl(dir.path(), 2, 3);
    let glb = dir.path().join("fine.glb");
    let stats = dir.path().join("stats.json");
    let out = one_line_error(&[
        "simulate",
        path.to_str().expect("utf-8"),
        "--subdivide",
        "9",
        "--stats",
        stats.to_str().expect("utf-8"),
        "--out",
        glb.to_str().expect("utf-8"),
    ]);
    let stderr = text(&out.stderr);
    // 2 organs at level 9 and 4 keyframes: the count and the finest level
    // that fits are named.
    assert!(stderr.contains("render subdivision level 9"), "{stderr}");
    assert!(stderr.contains("render vertices per keyframe"), "{stderr}");
    assert!(stderr.contains("the finest that fits"), "{stderr}");
    // Refused from the counts before the run: no statistics, no file.
    assert!(!glb.exists());
    assert!(!stats.exists());
}

#[test]
fn blossom_animates_a_simulated_petal_from_its_bud_to_its_open_state() {
    let dir = tempfile::tempdir().expect("tempdir");
    let frames = dir.path().join("frames");
    let out = anthesis(&[
        "simulate",
        "builtin:lily",
        "--organ",
        "petal-1",
        "--keyframes",
        "12",
        "--out",
        frames.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (bud, open) = (
        frames.join("keyframe_0000.obj"),
        frames.join("keyframe_0012.obj"),
    );
    let (bud, open) = (bud.to_str().expect("utf-8"), open.to_str().expect("utf-8"));
    let two = dir.path().join("two");
    let out = anthesis(&[
        "blossom",
        bud,
        open,
        "--object",
        "petal-1",
        "--keyframes",
        "8",
        "--out",
        two.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    // The last keyframe written is the open state, point for point.
    let last = std::fs::read_to_string(two.join("keyframe_0008.obj")).expect("written");
    let want = std::fs::read_to_string(frames.join("keyframe_0012.obj")).expect("read");
    let points = |obj: &str| -> Vec<[f64; 3]> {
        let petal = anthesis_mesh::obj::object_text(obj, Some("petal-1")).expect("petal-1");
        anthesis_mesh::parse_obj(&petal)
            .expect("parses")
            .positions
            .iter()
            .map(|p| p.to_array())
            .collect()
    };
    let (got, want) = (points(&last), points(&want));
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(&want) {
        for k in 0..3 {
            assert!((g[k] - w[k]).abs() < 1e-6, "{g:?} vs {w:?}");
        }
    }
    assert_eq!(std::fs::read_dir(&two).expect("list").count(), 9);
    assert!(text(&out.stdout).contains("cells"), "{}", text(&out.stdout));

    // Without --object the two-organ files are refused, naming the objects.
    let err = text(&one_line_error(&["blossom", bud, open]).stderr);
    assert!(err.contains("petal-1, receptacle"), "{err}");
    // Shapes of different meshes are refused.
    let sheet = |name: &str, cells: usize| {
        let path = dir.path().join(name);
        let mesh = anthesis_mesh::generate::flat_sheet(1.0, 1.0, cells, cells);
        std::fs::write(&path, anthesis_mesh::obj_string(&mesh)).expect("write");
        path.to_str().expect("utf-8").to_owned()
    };
    let (small, large) = (sheet("small.obj", 2), sheet("large.obj", 3));
    let err = text(&one_line_error(&["blossom", &small, &large]).stderr);
    assert!(err.contains("must be the same mesh"), "{err}");
}

#[test]
fn pde_blossom_in_betweens_a_swept_petal_and_meets_its_open_state() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = |name: &str| dir.path().join(name).to_str().expect("utf-8").to_owned();
    let out = anthesis(&[
        "bud",
        "--example",
        "lily-petal",
        "--save-surface",
        &path("bud.json"),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    // The open state: every control point (and tangent) turned back about
    // the base's x axis, more towards the tip.
    let bud: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path("bud.json")).expect("read"))
            .expect("json");
    let mut open = bud.clone();
    for key in ["margin0", "margin1", "tangent0", "tangent1"] {
        for (k, p) in open[key]
            .as_array_mut()
            .expect("points")
            .iter_mut()
            .enumerate()
        {
            let a = 0.5 * k as f64 / 3.0;
            let (y, z) = (p[1].as_f64().expect("y"), p[2].as_f64().expect("z"));
            p[1] = serde_json::json!(a.cos() * y - a.sin() * z);
            p[2] = serde_json::json!(a.sin() * y + a.cos() * z);
        }
    }
    std::fs::write(path("open.json"), open.to_string()).expect("write");
    let out = anthesis(&[
        "pde-blossom",
        &path("bud.json"),
        &path("open.json"),
        "--keyframes",
        "20",
        "--out",
        &path("frames"),
        "--report",
        &path("report.json"),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path("report.json")).expect("report"))
            .expect("json");
    assert!(
        report["final_error"].as_f64().expect("error") <= 1e-6,
        "{report}"
    );
    assert!(report["corrections"].as_u64().is_some(), "{report}");
    assert!(text(&out.stdout).contains("force corrections (eq. 21)"));
    assert_eq!(std::fs::read_dir(path("frames")).expect("list").count(), 21);
    // The first keyframe is the bud, the last has moved by the turn.
    let points = |frame: u32| -> Vec<glam::DVec3> {
        let obj =
            std::fs::read_to_string(dir.path().join(format!("frames/keyframe_{frame:04}.obj")))
                .expect("frame");
        anthesis_mesh::parse_obj(&obj).expect("parses").positions
    };
    let (first, last) = (points(0), points(20));
    let tip = first
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.y.total_cmp(&b.1.y))
        .map(|(i, _)| i)
        .expect("points");
    let moved = first[tip].distance(last[tip]);
    assert!(moved > 5.0, "the tip moved {moved}");
    // Two surfaces that are not PDE sweeps are refused, naming the file.
    std::fs::write(path("bad.json"), "{}").expect("write");
    let err = text(&one_line_error(&["pde-blossom", &path("bud.json"), &path("bad.json")]).stderr);
    assert!(err.contains("bad.json"), "{err}");
}

#[test]
fn a_project_folder_works_where_a_project_file_is_expected() {
    let lily = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/flowers/lily");
    let folder = anthesis(&["info", lily.to_str().expect("utf-8")]);
    assert!(folder.status.success(), "{}", text(&folder.stderr));
    let file = anthesis(&[
        "info",
        lily.join("lily.anthesis.toml").to_str().expect("utf-8"),
    ]);
    assert_eq!(text(&folder.stdout), text(&file.stdout));
    assert!(text(&folder.stdout).starts_with("petal-1 petal "));
    let empty = tempfile::tempdir().expect("tempdir");
    let err = text(&one_line_error(&["info", empty.path().to_str().expect("utf-8")]).stderr);
    assert!(err.contains("holds no project file"), "{err}");
}

/// The lily's folder copied to `dir`, its listed organs and rules replaced
/// by `structure` (TOML text).
fn lily_with_structure(dir: &Path, structure: &str) -> PathBuf {
    let lily = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/flowers/lily");
    for sub in ["maps", "meshes"] {
        std::fs::create_dir_all(dir.join(sub)).expect("mkdir");
        for entry in std::fs::read_dir(lily.join(sub)).expect("list") {
            let path = entry.expect("entry").path();
            std::fs::copy(&path, dir.join(sub).join(path.file_name().expect("name")))
                .expect("copy");
        }
    }
    let text = std::fs::read_to_string(lily.join("lily.anthesis.toml")).expect("read");
    let head = &text[..text.find("[[organs]]").expect("organs")];
    let head = head.replacen("version = 2", "version = 4", 1);
    let path = dir.join("lily.anthesis.toml");
    std::fs::write(&path, format!("{head}{structure}")).expect("write");
    path
}

#[test]
fn organs_placed_by_whorls_or_an_lsystem_load_and_simulate() {
    let dir = tempfile::tempdir().expect("tempdir");
    let whorls = lily_with_structure(
        &dir.path().join("whorls"),
        "[structure]\nkind = \"whorls\"\n\n\
         [[structure.whorls]]\nname = \"petal\"\ntemplate = \"petal\"\ncount = 3\nradius = 2.0\nhalf_span_deg = 50.0\n\n\
         [[structure.whorls]]\nname = \"sepal\"\ntemplate = \"sepal\"\ncount = 3\noffset_deg = 60.0\n\
         radius = 2.8\nheight = -0.9\nhalf_span_deg = 45.0\n",
    );
    let w = whorls.to_str().expect("utf-8");
    let out = anthesis(&["info", w]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let names: Vec<String> = text(&out.stdout)
        .lines()
        .filter(|l| !l.starts_with("size ") && !l.starts_with("part "))
        .map(|l| l.split(' ').next().expect("name").to_owned())
        .collect();
    assert_eq!(
        names,
        [
            "petal-1", "petal-2", "petal-3", "sepal-1", "sepal-2", "sepal-3"
        ]
    );
    let out = anthesis(&["simulate", w, "--keyframes", "2"]);
    assert!(out.status.success(), "{}", text(&out.stderr));

    // The same flower by an L-system: each segment rolled by / about the
    // heading (the flower axis), then pitched down by & to move out by f
    // and back up by ^, so each organ stands upright facing away from the
    // axis; sepals first, so they lie outside the petals.
    let lsystem = lily_with_structure(
        &dir.path().join("lsystem"),
        "[structure]\nkind = \"lsystem\"\n\n[structure.lsystem]\nsteps = 2\n\
         surfaces = { p = \"petal\", s = \"sepal\" }\n\
         text = \"\"\"\naxiom: B\nB -> D /(120) D /(120) D\n\
         D -> /(60) [ &(90) f(2.8) ^(90) f(-0.9) ~s ] \\\\(60) [ &(90) f(2) ^(90) ~p ]\n\"\"\"\n",
    );
    let l = lsystem.to_str().expect("utf-8");
    let out = anthesis(&["info", l]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let by_lsystem: Vec<String> = text(&out.stdout)
        .lines()
        .filter(|l| !l.starts_with("size ") && !l.starts_with("part "))
        .map(str::to_owned)
        .collect();
    assert_eq!(by_lsystem.len(), 6);
    // The organs are where the whorls put them: same names, bases, tips and
    // joint axes.
    let by_whorls = anthesis_flower::project::load_project(&whorls).expect("loads");
    let by_lsystem = anthesis_flower::project::load_project(&lsystem).expect("loads");
    for organ in &by_whorls.flower.organs {
        let i = by_lsystem
            .flower
            .organ_index(&organ.name)
            .expect("same names");
        let other = &by_lsystem.flower.organs[i].placement;
        for p in [glam::DVec3::ZERO, glam::DVec3::Y, glam::DVec3::Z] {
            let (a, b) = (
                organ.placement.world_from_template(p, 0.3),
                other.world_from_template(p, 0.3),
            );
            assert!((a - b).length() < 1e-9, "{}: {a} vs {b}", organ.name);
        }
    }
    // And the same overlap rules: each petal inside the two sepals beside it.
    let rules = |p: &anthesis_flower::Project| {
        let name = |i: usize| p.flower.organs[i].name.clone();
        let mut rules: Vec<(String, String)> = p
            .flower
            .overlaps
            .iter()
            .map(|o| (name(o.inner), name(o.outer)))
            .collect();
        rules.sort();
        rules
    };
    assert_eq!(rules(&by_lsystem), rules(&by_whorls));
    assert_eq!(rules(&by_whorls).len(), 6);
    let out = anthesis(&["simulate", l, "--keyframes", "2"]);
    assert!(out.status.success(), "{}", text(&out.stderr));

    // A syntax error in the L-system names the project, the line and column.
    let broken = lily_with_structure(
        &dir.path().join("broken"),
        "[structure]\nkind = \"lsystem\"\n\n[structure.lsystem]\nsteps = 1\n\
         surfaces = { p = \"petal\" }\ntext = \"axiom: ~p(\"\n",
    );
    let err = text(&one_line_error(&["info", broken.to_str().expect("utf-8")]).stderr);
    assert!(err.contains("L-system line 1, column 11"), "{err}");
}

#[test]
fn new_writes_a_built_in_flower_as_a_project_folder_and_never_overwrites() {
    let dir = tempfile::tempdir().expect("tempdir");
    let folder = dir.path().join("my-lily");
    let f = folder.to_str().expect("utf-8");
    let out = anthesis(&["new", "--from", "lily", f]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let written = anthesis_flower::project::load_project(&folder).expect("the folder opens");
    let builtin = anthesis_garden::builtin("lily")
        .expect("lily")
        .expect("loads");
    assert_eq!(written, builtin);
    // A second time into the same folder is refused, the project kept.
    let before = std::fs::read(folder.join("lily.anthesis.toml")).expect("read");
    let err = text(&one_line_error(&["new", "--from", "eustoma-pinocchio", f]).stderr);
    assert!(err.contains("already holds a project"), "{err}");
    assert_eq!(
        std::fs::read(folder.join("lily.anthesis.toml")).expect("read"),
        before
    );
    let err = text(&one_line_error(&["new", "--from", "tulip", f]).stderr);
    assert!(err.contains("no built-in flower `tulip`"), "{err}");
    // The empty starting point: one whorl of five simple petals.
    let five = dir.path().join("five");
    let out = anthesis(&["new", "--from", "five-petal", five.to_str().expect("utf-8")]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let written = anthesis_flower::project::load_project(&five).expect("the folder opens");
    assert_eq!(written.flower.organs.len(), 5);
    assert_eq!(
        written,
        anthesis_garden::builtin("five-petal")
            .expect("built in")
            .expect("loads")
    );
}

#[test]
fn fit_finds_maps_for_a_simulated_open_shape_and_refuses_bad_targets() {
    let dir = tempfile::tempdir().expect("tempdir");
    // One small petal that grows visibly in eight keyframes.
    let mut project = anthesis_sim::fixtures::whorl(1, 6, 10, 8);
    project.flower.templates[0].dg = 0.03;
    let path = dir.path().join("petal.anthesis.toml");
    anthesis_flower::project::save_project(&project, &path).expect("save");
    let path = path.to_str().expect("utf-8");
    let frames = dir.path().join("frames");
    let frames_arg = frames.to_str().expect("utf-8");
    let out = anthesis(&["simulate", path, "--organ", "petal-1", "--out", frames_arg]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let open = frames.join("keyframe_0008.obj");
    let open = open.to_str().expect("utf-8");

    let fitted = dir.path().join("fitted");
    let report = dir.path().join("fit.json");
    let fit_args = |target: &str, out: &str| -> Vec<String> {
        [
            "fit",
            path,
            "--organ",
            "petal-1",
            "--target",
            target,
            "--nodes",
            "1x3",
            "--direction-nodes",
            "0x0",
            "--out",
            out,
            "--report",
            report.to_str().expect("utf-8"),
        ]
        .map(str::to_owned)
        .to_vec()
    };
    let args = fit_args(open, fitted.to_str().expect("utf-8"));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = anthesis(&args);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).starts_with("fitted: RMS"),
        "{}",
        text(&out.stdout)
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("report")).expect("JSON");
    let rms = json["rms"].as_f64().expect("rms");
    let max = json["max"].as_f64().expect("max");
    assert!(
        rms > 0.0 && rms < 0.02 && max >= rms && max < 0.05,
        "{json}"
    );
    assert!(json["guess_rms"].as_f64().expect("guess") > rms, "{json}");
    assert_eq!(json["parameters"], 12);
    assert!(json["iterations"].as_u64().expect("iterations") >= 1);
    assert!(json["seconds"].as_f64().expect("seconds") > 0.0);
    assert_eq!(json["reached"], true);

    // The fitted project simulates like any other, to the reported shape.
    let refit = dir.path().join("refit");
    let out = anthesis(&[
        "simulate",
        fitted.to_str().expect("utf-8"),
        "--organ",
        "petal-1",
        "--out",
        refit.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let points = |file: &Path| -> Vec<glam::DVec3> {
        let obj = std::fs::read_to_string(file).expect("read");
        let petal = anthesis_mesh::obj::object_text(&obj, Some("petal-1")).expect("petal-1");
        anthesis_mesh::parse_obj(&petal).expect("parses").positions
    };
    let (got, want) = (
        points(&refit.join("keyframe_0008.obj")),
        std::fs::read_to_string(frames.join("keyframe_0008.obj")).expect("read"),
    );
    let length = json["organ_length"].as_f64().expect("length");
    let mesh = &project.flower.template_of(0).mesh;
    let target = anthesis_fit::read_target(&want, "petal-1", mesh).expect("the target");
    let (surface_rms, _) = anthesis_fit::distances(
        &got,
        &mesh.triangles,
        &target,
        anthesis_fit::Similarity::IDENTITY,
        length,
    );
    // The OBJ files round positions to their printed digits.
    assert!(
        (surface_rms - rms).abs() < 1e-6 * (1.0 + rms),
        "{surface_rms} {json}"
    );
    assert_eq!(json["target_vertices"], mesh.vertex_count());
    assert!(json["stopped"].is_string(), "{json}");
    // Nothing of the staging folder is left beside the result.
    let leftovers = |folder: &Path| -> Vec<String> {
        std::fs::read_dir(folder)
            .expect("read")
            .filter_map(Result::ok)
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|name| name.starts_with(".anthesis-fit"))
            .collect()
    };
    assert!(leftovers(dir.path()).is_empty());

    // An existing fit is not overwritten.
    let err = text(&one_line_error(&args).stderr);
    assert!(err.contains("already holds a project"), "{err}");
    // A NaN, a target without faces, outputs that cannot be: one clear
    // line each, before any fit.
    let new_out = dir.path().join("fitted-2");
    let nan = dir.path().join("nan.obj");
    let text_obj = want.clone();
    let mut replaced = false;
    let with_nan: String = text_obj
        .lines()
        .map(|line| {
            if !replaced && line.starts_with("v ") {
                replaced = true;
                "v 0 nan 0".to_owned()
            } else {
                line.to_owned()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(&nan, with_nan).expect("write");
    let args = fit_args(
        nan.to_str().expect("utf-8"),
        new_out.to_str().expect("utf-8"),
    );
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let err = text(&one_line_error(&args).stderr);
    assert!(
        err.contains("target vertex 1 (from 1) has a coordinate that is not a finite number"),
        "{err}"
    );
    let bare = dir.path().join("bare.obj");
    std::fs::write(&bare, "v 0 0 0\nv 1 0 0\nv 0 1 0\n").expect("write");
    let args = fit_args(
        bare.to_str().expect("utf-8"),
        new_out.to_str().expect("utf-8"),
    );
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let err = text(&one_line_error(&args).stderr);
    assert!(err.contains("3 vertices and no faces"), "{err}");
    // --out inside a file, and a folder with something in it.
    let file = dir.path().join("a-file");
    std::fs::write(&file, "x").expect("write");
    let busy = dir.path().join("busy");
    std::fs::create_dir(&busy).expect("mkdir");
    std::fs::write(busy.join("notes.txt"), "mine").expect("write");
    for (out, says) in [
        (file.join("fitted"), "does not exist"),
        (busy.clone(), "is not empty"),
    ] {
        let args = fit_args(open, out.to_str().expect("utf-8"));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let err = text(&one_line_error(&args).stderr);
        assert!(err.contains(says), "{err}");
    }
    assert_eq!(
        std::fs::read_to_string(busy.join("notes.txt")).expect("kept"),
        "mine"
    );
    assert!(!new_out.exists());
    assert!(leftovers(dir.path()).is_empty());

    // No iteration allowed: the closest maps so far are written, and the
    // fit says the limit stopped it, not that the bud cannot get there.
    let mut args = fit_args(open, new_out.to_str().expect("utf-8"));
    args.extend(["--max-iterations", "0"].map(str::to_owned));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = anthesis(&args);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let said = text(&out.stdout);
    assert!(said.contains("the iteration limit (0)"), "{said}");
    assert!(!said.contains("cannot be grown"), "{said}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("report")).expect("JSON");
    assert_eq!(json["stopped"], "max-iterations");
    assert!(new_out.join("petal.anthesis.toml").is_file());
}

#[test]
fn fit_registers_a_scan_of_another_mesh_and_fits_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut project = anthesis_sim::fixtures::whorl(1, 6, 10, 8);
    project.flower.templates[0].dg = 0.03;
    let path = dir.path().join("petal.anthesis.toml");
    anthesis_flower::project::save_project(&project, &path).expect("save");
    // The scan: the open petal simulated at a finer mesh, its vertices
    // shuffled, as quads where two triangles make one, without UVs,
    // turned and moved far from the flower.
    let mesh = &project.flower.template_of(0).mesh;
    let edge = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
            a.distance(b) + b.distance(c) + c.distance(a)
        })
        .sum::<f64>()
        / (3 * mesh.triangles.len()) as f64;
    let mut fine = project.clone();
    fine.settings.resolution = anthesis_flower::resolution::Resolution::MeanEdge(0.7 * edge);
    let fine = anthesis_flower::resolution::resolve(&fine).expect("remeshes");
    let fine_mesh = &fine.flower.template_of(0).mesh;
    let shape =
        anthesis_fit::simulate_final(&fine, 0, fine.flower.template_of(0).maps.clone(), &|| false)
            .expect("simulates");
    let turn = glam::DQuat::from_axis_angle(glam::DVec3::new(0.2, 1.0, -0.6).normalize(), 1.9);
    let n = shape.len();
    let order: Vec<usize> = (0..n).map(|i| (i * 53 + 7) % n).collect();
    let mut new_index = vec![0usize; n];
    for (new, &old) in order.iter().enumerate() {
        new_index[old] = new + 1;
    }
    let mut obj = String::from("o scan\n");
    for &old in &order {
        let p = turn * shape[old] + glam::DVec3::new(50.0, 20.0, -30.0);
        obj.push_str(&format!("v {} {} {}\n", p.x, p.y, p.z));
    }
    for t in &fine_mesh.triangles {
        let [a, b, c] = t.map(|v| new_index[v as usize]);
        obj.push_str(&format!("f {a} {b} {c}\n"));
    }
    let scan = dir.path().join("scan.obj");
    std::fs::write(&scan, obj).expect("write");
    let fitted = dir.path().join("fitted");
    let report = dir.path().join("fit.json");
    let out = anthesis(&[
        "fit",
        path.to_str().expect("utf-8"),
        "--organ",
        "petal-1",
        "--target",
        scan.to_str().expect("utf-8"),
        "--register",
        "--nodes",
        "1x3",
        "--direction-nodes",
        "0x0",
        "--out",
        fitted.to_str().expect("utf-8"),
        "--report",
        report.to_str().expect("utf-8"),
    ]);
    let err = text(&out.stderr);
    assert!(out.status.success(), "{err}");
    // The registration is said before the fit's iterations.
    let registered = err.find("registered: turned").expect("registration said");
    let first = err.find("iteration 0").expect("iterations said");
    assert!(registered < first, "{err}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("report")).expect("JSON");
    assert_eq!(json["target_vertices"], n);
    assert_eq!(json["target_has_uvs"], false);
    // The turn undone: 1.9 rad, about 109°.
    let angle = json["registration"]["angle_deg"].as_f64().expect("angle");
    assert!((angle - 1.9f64.to_degrees()).abs() < 3.0, "{json}");
    assert_eq!(json["registration"]["scale"], 1.0);
    let rms = json["rms"].as_f64().expect("rms");
    assert!(rms < 0.02, "{json}");

    // The same scan in units ten times smaller (millimetres against
    // centimetres): --register-scale finds the scale too.
    let scaled: String = std::fs::read_to_string(&scan)
        .expect("read")
        .lines()
        .map(|line| match line.strip_prefix("v ") {
            Some(rest) => {
                let v: Vec<f64> = rest
                    .split_whitespace()
                    .map(|w| w.parse().expect("number"))
                    .collect();
                format!("v {} {} {}\n", 10.0 * v[0], 10.0 * v[1], 10.0 * v[2])
            }
            None => format!("{line}\n"),
        })
        .collect();
    let scan_mm = dir.path().join("scan-mm.obj");
    std::fs::write(&scan_mm, scaled).expect("write");
    let fitted_mm = dir.path().join("fitted-mm");
    let out = anthesis(&[
        "fit",
        path.to_str().expect("utf-8"),
        "--organ",
        "petal-1",
        "--target",
        scan_mm.to_str().expect("utf-8"),
        "--register-scale",
        "--nodes",
        "1x3",
        "--direction-nodes",
        "0x0",
        "--max-iterations",
        "1",
        "--out",
        fitted_mm.to_str().expect("utf-8"),
        "--report",
        report.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("report")).expect("JSON");
    let scale = json["registration"]["scale"].as_f64().expect("scale");
    assert!((scale - 0.1).abs() < 0.002, "{json}");
}

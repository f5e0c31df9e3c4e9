//! `anthesis bud` end to end: a surface in, an OBJ and one quality line
//! out; refused surfaces and bad files give one line and a non-zero exit.

use std::collections::HashMap;
use std::path::Path;

mod common;

use common::{anthesis, one_line_error, text};

fn utf8(path: &Path) -> &str {
    path.to_str().expect("utf-8 path")
}

/// The `key=value` pairs of the quality line (which must be the only line).
fn quality(stdout: &str) -> HashMap<String, f64> {
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 1, "one quality line expected: {stdout}");
    lines[0]
        .split_whitespace()
        .map(|pair| {
            let (key, value) = pair.split_once('=').expect("key=value");
            (key.to_string(), value.parse().expect("a number"))
        })
        .collect()
}

#[test]
fn example_petal_is_written_as_an_obj_with_the_printed_counts() {
    let dir = tempfile::tempdir().expect("tempdir");
    let obj = dir.path().join("petal.obj");
    let out = anthesis(&[
        "bud",
        "--example",
        "lily-petal",
        "--edge",
        "1.3",
        "--out",
        utf8(&obj),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let q = quality(&text(&out.stdout));
    for key in [
        "vertices",
        "triangles",
        "edges",
        "mean_edge",
        "edge_spread",
        "min_angle_deg",
    ] {
        assert!(q.contains_key(key), "{key} missing from {q:?}");
    }
    let mesh = anthesis_mesh::load_obj(&obj).expect("the OBJ loads and validates");
    let topology = anthesis_mesh::validate(&mesh).expect("valid");
    assert_eq!(mesh.vertex_count() as f64, q["vertices"]);
    assert_eq!(mesh.triangle_count() as f64, q["triangles"]);
    assert_eq!(topology.edges.len() as f64, q["edges"]);
    assert_eq!(mesh.uvs.len(), mesh.vertex_count(), "UVs are written");
    // The paper's lily petal at edge 1.3 has 388 vertices.
    assert!((250.0..600.0).contains(&q["vertices"]), "{q:?}");
    assert!((q["mean_edge"] - 1.3).abs() < 0.2, "{q:?}");
    assert!(
        q["min_angle_deg"] >= 20.0 && q["edge_spread"] < 0.3,
        "{q:?}"
    );
}

#[test]
fn surfaces_saved_as_json_mesh_the_same_from_bezier_and_pde_files() {
    let dir = tempfile::tempdir().expect("tempdir");
    for (example, edge, format) in [
        ("lily-petal", "1.3", "--pde"),
        ("eustoma-petal", "2.0", "--bezier"),
    ] {
        let json = dir.path().join(format!("{example}.json"));
        let from_example = anthesis(&["bud", "--example", example, "--save-surface", utf8(&json)]);
        assert!(
            from_example.status.success(),
            "{}",
            text(&from_example.stderr)
        );
        let obj = dir.path().join(format!("{example}.obj"));
        let from_file = anthesis(&[
            "bud",
            format,
            utf8(&json),
            "--edge",
            edge,
            "--out",
            utf8(&obj),
        ]);
        assert!(from_file.status.success(), "{}", text(&from_file.stderr));
        assert_eq!(
            text(&from_example.stdout),
            text(&from_file.stdout),
            "{example}: the example's default edge and its saved surface give the same mesh"
        );
        let mesh = anthesis_mesh::load_obj(&obj).expect("loads");
        assert_eq!(
            mesh.vertex_count() as f64,
            quality(&text(&from_file.stdout))["vertices"]
        );
    }
}

#[test]
fn help_documents_both_file_formats() {
    let out = anthesis(&["bud", "--help"]);
    assert!(out.status.success());
    let help = text(&out.stdout);
    for needle in [
        "--example <EXAMPLE>",
        "lily-petal",
        "\"control\"",
        "\"margin0\"",
        "\"tangent1\"",
        "stretch_to_bend",
    ] {
        assert!(help.contains(needle), "`{needle}` missing from:\n{help}");
    }
}

#[test]
fn bad_surfaces_and_files_give_one_line_and_a_non_zero_exit() {
    let dir = tempfile::tempdir().expect("tempdir");
    let write = |name: &str, json: &str| {
        let path = dir.path().join(name);
        std::fs::write(&path, json).expect("write");
        path.display().to_string()
    };
    let flat_row = "[[1,0,0],[0.3,0,0],[-0.3,0,0],[-1,0,0]]";
    let truncated = write("cut.json", "{\"control\": [[[1, 0, 0], [0.3");
    let three_rows = write(
        "three.json",
        &format!("{{\"control\": [{flat_row}, {flat_row}, {flat_row}]}}"),
    );
    let short_row = write(
        "short.json",
        &format!("{{\"control\": [{flat_row}, [[1,0,0]], {flat_row}, {flat_row}]}}"),
    );
    let unknown_field = write(
        "unknown.json",
        &format!(
            "{{\"control\": [{flat_row}, {flat_row}, {flat_row}, {flat_row}], \"colour\": 1}}"
        ),
    );
    // All four rows at the base: no length from base to tip.
    let no_length = write(
        "point.json",
        &format!("{{\"control\": [{flat_row}, {flat_row}, {flat_row}, {flat_row}]}}"),
    );
    let curve = "[[1,0,0],[1,5,0],[1,10,0],[1,15,0]]";
    let other = "[[-1,0,0],[-1,5,0],[-1,10,0],[-1,15,0]]";
    let across = "[[-2,0,0],[-2,0,0],[-2,0,0],[-2,0,0]]";
    let no_tangent1 = write(
        "pde-missing.json",
        &format!("{{\"margin0\": {curve}, \"margin1\": {other}, \"tangent0\": {across}}}"),
    );
    let stiff = write(
        "pde-stiff.json",
        &format!(
            "{{\"margin0\": {curve}, \"margin1\": {other}, \"tangent0\": {across}, \"tangent1\": {across}, \"stretch_to_bend\": 500}}"
        ),
    );
    let missing = dir.path().join("nope.json").display().to_string();
    let no_folder = dir.path().join("no/such/x.obj").display().to_string();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--bezier", &truncated, "--edge", "1"], "line 1"),
        (vec!["--bezier", &three_rows, "--edge", "1"], "4 rows"),
        (vec!["--bezier", &short_row, "--edge", "1"], "row 2 of"),
        (vec!["--bezier", &unknown_field, "--edge", "1"], "colour"),
        (vec!["--bezier", &no_length, "--edge", "1"], "no length"),
        (vec!["--pde", &no_tangent1, "--edge", "1"], "tangent1"),
        (vec!["--pde", &stiff, "--edge", "1"], "stretch_to_bend"),
        (vec!["--bezier", &missing, "--edge", "1"], "nope.json"),
        (
            vec!["--example", "lily-petal", "--edge", "40"],
            "too large for this organ",
        ),
        (vec!["--example", "lily-petal", "--edge", "0"], "positive"),
        (
            vec!["--example", "lily-petal", "--min-angle", "70"],
            "--min-angle",
        ),
        (
            vec!["--example", "lily-petal", "--out", &no_folder],
            "does not exist",
        ),
    ];
    for (args, expected) in cases {
        let args: Vec<&str> = std::iter::once("bud").chain(args).collect();
        let out = one_line_error(&args);
        let stderr = text(&out.stderr);
        assert!(
            stderr.contains(expected),
            "{args:?}: `{expected}` missing from {stderr}"
        );
        assert!(out.stdout.is_empty(), "{args:?} printed a quality line");
    }
    // A file surface has no default edge length: a usage error.
    let out = anthesis(&["bud", "--pde", &stiff]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
}

/// `anthesis import-scan`: the lily petal remeshed coarser (another
/// triangulation), written without UVs and moved, is fitted back and
/// meshed; the round trip through `anthesis bud --pde` gives the same mesh.
#[test]
fn a_scanned_petal_is_fitted_and_meshed_from_the_command_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let lily = anthesis_mesh::load_obj(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/flowers/lily/meshes/petal.obj"),
    )
    .expect("lily petal");
    let scan = anthesis_bud::remesh_mesh(&lily, &anthesis_bud::RemeshOptions::new(1.7))
        .expect("remeshes")
        .mesh;
    let mut obj = String::new();
    for p in &scan.positions {
        obj.push_str(&format!("v {} {} {}\n", -p.y, p.x + 3.0, p.z));
    }
    for t in &scan.triangles {
        obj.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
    }
    let scan_path = dir.path().join("scan.obj");
    std::fs::write(&scan_path, obj).expect("write");
    let (out, report, surface) = (
        dir.path().join("petal.obj"),
        dir.path().join("report.json"),
        dir.path().join("petal.json"),
    );
    let run = anthesis(&[
        "import-scan",
        utf8(&scan_path),
        "--out",
        utf8(&out),
        "--edge",
        "1.3",
        "--report",
        utf8(&report),
        "--save-surface",
        utf8(&surface),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let numbers = quality(&text(&run.stdout));
    assert!(
        numbers["rms"] < 0.02 && numbers["max"] < 0.05,
        "{numbers:?}"
    );
    assert!(numbers["min_angle_deg"] >= 20.0, "{numbers:?}");
    let mesh = anthesis_mesh::load_obj(&out).expect("a template mesh with UVs");
    assert_eq!(mesh.vertex_count() as f64, numbers["vertices"]);
    assert_eq!(anthesis_bud::inner_side_faces_minus_z(&mesh), Some(true));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("report")).expect("json");
    assert_eq!(json["pointed_tip"], serde_json::Value::Bool(true));
    assert!((json["scan_to_surface_rms"].as_f64().expect("rms") - numbers["rms"]).abs() < 1e-5);
    // The saved surface meshes to the same petal.
    let again = dir.path().join("again.obj");
    let run = anthesis(&[
        "bud",
        "--pde",
        utf8(&surface),
        "--edge",
        "1.3",
        "--out",
        utf8(&again),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    assert_eq!(
        anthesis_mesh::load_obj(&again)
            .expect("again")
            .positions
            .len(),
        mesh.vertex_count()
    );

    // A scan with a hole is refused in one line naming the loops.
    let mut holed = String::new();
    for p in &scan.positions {
        holed.push_str(&format!("v {} {} {}\n", p.x, p.y, p.z));
    }
    let boundary = anthesis_mesh::Topology::build(&scan)
        .expect("topology")
        .boundary_vertices(scan.vertex_count());
    let inner = (0..scan.vertex_count())
        .find(|&v| {
            !boundary[v]
                && scan
                    .triangles
                    .iter()
                    .filter(|t| t.contains(&(v as u32)))
                    .all(|t| t.iter().all(|&w| !boundary[w as usize]))
        })
        .expect("an inner vertex");
    for t in scan
        .triangles
        .iter()
        .filter(|t| !t.contains(&(inner as u32)))
    {
        holed.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
    }
    let holed_path = dir.path().join("holed.obj");
    std::fs::write(&holed_path, holed).expect("write");
    let refused = one_line_error(&["import-scan", utf8(&holed_path), "--out", utf8(&out)]);
    let message = text(&refused.stderr);
    assert!(message.contains("2 boundary loops"), "{message}");
}

//! `anthesis measure`: the table's rows, units and options on a small whorl.

use std::path::{Path, PathBuf};

use super::common::{anthesis, text};

/// The whorl fixture saved in `dir` as `name`, stating `unit` if given.
fn whorl_with_unit(dir: &Path, name: &str, unit: Option<&str>) -> PathBuf {
    let mut project = anthesis_sim::fixtures::whorl(4, 8, 14, 3);
    project.flower.unit = unit.map(|u| anthesis_flower::Unit::parse(u).expect("a unit"));
    let path = dir.join(format!("{name}.anthesis.toml"));
    anthesis_flower::project::save_project(&project, &path).expect("save");
    path
}

/// The table `anthesis measure ARGS --out` wrote: its header and rows.
fn measure(dir: &Path, args: &[&str]) -> (Vec<String>, Vec<Vec<String>>) {
    let out = dir.join("table.csv");
    let mut all = vec!["measure"];
    all.extend_from_slice(args);
    all.extend(["--out", out.to_str().expect("utf-8")]);
    let run = anthesis(&all);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let table = std::fs::read_to_string(&out).expect("written");
    let mut lines = table
        .lines()
        .map(|l| l.split(',').map(str::to_string).collect());
    let header = lines.next().expect("a header");
    (header, lines.collect())
}

fn number(row: &[String], column: usize) -> f64 {
    row[column].parse().expect("a number")
}

#[test]
fn measure_writes_a_row_per_keyframe_and_organ_in_the_projects_unit() {
    let dir = tempfile::tempdir().expect("tempdir");
    let plain = whorl_with_unit(dir.path(), "plain", None);
    let in_mm = whorl_with_unit(dir.path(), "in-mm", Some("2 mm"));
    let (header, rows) = measure(dir.path(), &[plain.to_str().expect("utf-8")]);
    let (header_mm, rows_mm) = measure(dir.path(), &[in_mm.to_str().expect("utf-8")]);
    assert_eq!(header[..3], ["keyframe", "organ", "template"]);
    let column = |name: &str| {
        header
            .iter()
            .position(|h| h.starts_with(&format!("{name} [")))
            .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
    };
    assert_eq!(header[column("midrib_length")], "midrib_length [unit]");
    assert_eq!(header_mm[column("midrib_length")], "midrib_length [mm]");
    assert_eq!(header_mm[column("contact_area")], "contact_area [mm^2]");
    assert_eq!(
        header_mm[column("gaussian_curvature_median")],
        "gaussian_curvature_median [1/mm^2]"
    );
    // The bud and 3 keyframes, 4 organs each.
    assert_eq!(rows.len(), 16);
    assert_eq!(rows[0][..3], ["0", "petal-1", "petal"]);
    assert_eq!(rows[15][..3], ["3", "sepal-2", "sepal"]);
    // The same run; the real unit scales lengths by 2, areas by 4,
    // curvatures by 1/2 and 1/4, and leaves stretches as they are.
    for (row, row_mm) in rows.iter().zip(&rows_mm) {
        for (name, factor) in [
            ("midrib_length", 2.0),
            ("margin_length", 2.0),
            ("area", 4.0),
            ("contact_area", 4.0),
            ("mean_curvature_mean", 0.5),
            ("gaussian_curvature_median", 0.25),
            ("stretch_major_mean", 1.0),
        ] {
            let (a, b) = (number(row, column(name)), number(row_mm, column(name)));
            assert!(
                (b - factor * a).abs() <= 1e-12 * b.abs().max(1e-300) || (a.is_nan() && b.is_nan()),
                "{name}: {a} and {b}"
            );
        }
    }
    // In the bud nothing has stretched; later the organs have grown.
    for row in &rows {
        let major = number(row, column("stretch_major_mean"));
        let minor = number(row, column("stretch_minor_mean"));
        assert!(minor <= major + 1e-12);
        if row[0] == "0" {
            assert!(
                (major - 1.0).abs() < 1e-9 && (minor - 1.0).abs() < 1e-9,
                "{row:?}"
            );
        }
        assert!(number(row, column("midrib_length")) > 0.0);
        assert!(number(row, column("margin_length")) > number(row, column("midrib_length")));
    }
    let grown = |organ: &str, name: &str| {
        let at = |k: &str| {
            rows.iter()
                .find(|r| r[0] == k && r[1] == organ)
                .map(|r| number(r, column(name)))
                .expect("a row")
        };
        at("3") / at("0")
    };
    assert!(grown("petal-1", "area") > 1.0);
}

#[test]
fn measure_picks_organs_keyframes_and_the_contact_distance() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = whorl_with_unit(dir.path(), "whorl", None);
    let p = path.to_str().expect("utf-8");
    let (header, rows) = measure(
        dir.path(),
        &[p, "--organs", "petal-1,sepal-2", "--at", "0,2:3"],
    );
    let keys: Vec<(&str, &str)> = rows
        .iter()
        .map(|r| (r[0].as_str(), r[1].as_str()))
        .collect();
    assert_eq!(
        keys,
        [
            ("0", "petal-1"),
            ("0", "sepal-2"),
            ("2", "petal-1"),
            ("2", "sepal-2"),
            ("3", "petal-1"),
            ("3", "sepal-2")
        ]
    );
    let area = header
        .iter()
        .position(|h| h.starts_with("area ["))
        .expect("area");
    let contact = header
        .iter()
        .position(|h| h.starts_with("contact_area ["))
        .expect("contact_area");
    // Every vertex is within a distance larger than the flower of another
    // organ, and none within 0 of one (the organs never cross).
    let (_, all) = measure(dir.path(), &[p, "--contact-distance", "1000"]);
    for row in &all {
        assert!((number(row, contact) - number(row, area)).abs() < 1e-9 * number(row, area));
    }
    let (_, none) = measure(dir.path(), &[p, "--contact-distance", "0"]);
    assert!(none.iter().all(|row| number(row, contact) == 0.0));
    // An organ simulated alone touches only the parts: the receptacle it
    // sits on, within a distance larger than the flower, all over.
    let alone_at = |distance: &str| {
        measure(
            dir.path(),
            &[p, "--alone", "petal-1", "--contact-distance", distance],
        )
        .1
    };
    let alone = alone_at("1000");
    assert_eq!(alone.len(), 4);
    for row in &alone {
        assert_eq!(row[1], "petal-1");
        assert!((number(row, contact) - number(row, area)).abs() < 1e-9 * number(row, area));
    }
    assert!(alone_at("0").iter().all(|row| number(row, contact) == 0.0));
    // Mistakes are refused before the run, in one line naming them.
    for (args, says) in [
        (vec![p, "--at", "9"], "past the run's last keyframe, 3"),
        (vec![p, "--organs", "petal-9"], "no organ named `petal-9`"),
        (
            vec![p, "--contact-distance", "-1"],
            "--contact-distance must be 0 or more",
        ),
    ] {
        let mut all = vec!["measure"];
        all.extend(args);
        let run = anthesis(&all);
        assert!(!run.status.success());
        assert!(text(&run.stderr).contains(says), "{}", text(&run.stderr));
    }
}

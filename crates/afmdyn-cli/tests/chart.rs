//! `afmdyn chart` end to end: the JSON contract, the files (CSV, NetCDF, maps), resuming a
//! killed chart, refusing another request's store and a locked directory, bad axes.

use std::path::Path;
use std::process::{Command, Output};

fn afmdyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_afmdyn"))
        .args(args)
        .output()
        .expect("run afmdyn")
}

/// `out` succeeded (its stderr shown when not).
fn succeeded(out: &Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `files` of the directories `a` and `b` are byte for byte the same.
fn same_files(a: &Path, b: &Path, files: &[&str]) {
    for f in files {
        let (x, y) = (
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
        );
        assert!(
            x == y,
            "{f}: the resumed run's differs from the uninterrupted one's"
        );
    }
}

const SMALL: [&str; 12] = [
    "chart",
    "--x-steps",
    "4",
    "--y-steps",
    "2",
    "--starts",
    "2",
    "--tile",
    "2",
    "--lyapunov-periods",
    "50",
    "--json",
];

fn small(out: &Path, extra: &[&str]) -> Output {
    let mut a: Vec<&str> = SMALL.to_vec();
    a.extend(["--out", out.to_str().unwrap()]);
    a.extend(extra);
    afmdyn(&a)
}

#[test]
fn chart_json_lists_every_cell_and_its_attractors() {
    let dir = tempfile::tempdir().unwrap();
    let out = small(dir.path(), &[]);
    succeeded(&out);
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["x"]["name"], "omega");
    assert_eq!(doc["y"]["name"], "drive_amplitude");
    assert_eq!(doc["x"]["values"].as_array().unwrap().len(), 4);
    assert_eq!(doc["y"]["values"][1], 0.12);
    let cells = doc["cells"].as_array().unwrap();
    assert_eq!(cells.len(), 8);
    for (k, c) in cells.iter().enumerate() {
        assert_eq!(c["ix"], k % 4);
        assert_eq!(c["iy"], k / 4);
        let at = c["attractors"].as_array().unwrap();
        assert!(!at.is_empty(), "{c}");
        for a in at {
            for key in [
                "period",
                "lyapunov",
                "x_max",
                "contacts_per_period",
                "fraction",
            ] {
                assert!(a.get(key).is_some(), "{key} in {a}");
            }
            // λ₁ exactly for the nonperiodic ones
            assert_eq!(a["period"].is_null(), !a["lyapunov"].is_null(), "{a}");
        }
    }
    for f in [
        "chart.csv",
        "chart.nc",
        "chart-period.png",
        "chart-lyapunov.svg",
    ] {
        assert!(dir.path().join(f).metadata().unwrap().len() > 0, "{f}");
    }
    // NetCDF: the classic format's magic, version 2 (64-bit offsets)
    let nc = std::fs::read(dir.path().join("chart.nc")).unwrap();
    assert_eq!(&nc[..4], b"CDF\x02");
}

#[test]
fn a_killed_chart_resumes_to_the_uninterrupted_files() {
    let full = tempfile::tempdir().unwrap();
    let cut = tempfile::tempdir().unwrap();
    assert!(small(full.path(), &[]).status.success());
    let killed = small(cut.path(), &["--threads", "1", "--abort-after", "2"]);
    assert!(!killed.status.success(), "the run was killed");
    let tiles = cut.path().join(".chart.tiles.jsonl");
    let text = std::fs::read_to_string(&tiles).unwrap();
    assert_eq!(text.lines().count(), 2, "two tasks stored");
    // a line cut as a kill during a write would leave it
    std::fs::write(&tiles, text + "{\"task\": 3, \"cells\": [{\"ix\"").unwrap();
    let resumed = small(cut.path(), &["--resume"]);
    succeeded(&resumed);
    same_files(full.path(), cut.path(), &["chart.csv", "chart.nc"]);
    let stored = std::fs::read_to_string(&tiles).unwrap();
    assert_eq!(stored.lines().count(), 4, "no lost or duplicated task");
    // a finished store computes nothing on --resume; another request is refused
    let again = small(cut.path(), &["--resume"]);
    assert!(again.status.success());
    assert_eq!(std::fs::read_to_string(&tiles).unwrap(), stored);
    let other = small(cut.path(), &["--resume", "--seed", "2"]);
    // (the refusal names the first field that differs)
    assert_eq!(other.status.code(), Some(2));
    let err = String::from_utf8_lossy(&other.stderr);
    assert!(
        err.contains("seed = 1 in the interrupted run, 2 now"),
        "{err}"
    );
}

/// The impact oscillator N = 1, r = 0.8 near Ω = 2 (two coexisting period-1 orbits).
const IMPACT: [&str; 8] = [
    "--contact-law",
    "impact",
    "--restitution",
    "0.8",
    "--modes",
    "1",
    "--omega",
    "2.0",
];

/// `afmdyn COMMAND` on the impact oscillator with `args`, its outputs in `dir`, then `extra`.
fn on_impact(command: &[&str], dir: &Path, extra: &[&str]) -> Output {
    let out = ["--out", dir.to_str().unwrap()];
    afmdyn(&[command, &IMPACT[..], &out, extra].concat())
}

/// A basin map of two passes (the plane is the whole section: 50 × 50 at the automatic
/// stride 2) on `dir`, with `extra` flags.
fn two_pass_basins(dir: &Path, extra: &[&str]) -> Output {
    on_impact(
        &["basins", "--x-steps", "50", "--y-steps", "50"],
        dir,
        extra,
    )
}

/// A basin map killed in its first pass (or in its second) resumes, pass by pass from the
/// stored rows, to the files of the uninterrupted map (byte for byte); no row is lost or run
/// twice; a finished store computes nothing; another request is refused naming the field.
#[test]
fn a_killed_basin_map_resumes_to_the_uninterrupted_files() {
    let full = tempfile::tempdir().unwrap();
    let cut = tempfile::tempdir().unwrap();
    assert!(two_pass_basins(full.path(), &[]).status.success());
    let killed = two_pass_basins(cut.path(), &["--threads", "1", "--abort-after", "3"]);
    assert!(!killed.status.success(), "the run was killed");
    let rows = cut.path().join(".basins.rows.jsonl");
    let text = std::fs::read_to_string(&rows).unwrap();
    assert_eq!(text.lines().count(), 3, "three rows stored");
    // a line cut as a kill during a write would leave it
    std::fs::write(&rows, text + "{\"row\": {\"pass\": 0, \"iy\"").unwrap();
    let resumed = two_pass_basins(cut.path(), &["--resume"]);
    succeeded(&resumed);
    same_files(full.path(), cut.path(), &["basins.csv", "basins.nc"]);
    // the document too, but for the files' paths
    let doc = |d: &Path| {
        let mut v: serde_json::Value =
            serde_json::from_slice(&std::fs::read(d.join("basins.json")).unwrap()).unwrap();
        let m = v.as_object_mut().unwrap();
        m.remove("csv");
        m.remove("netcdf");
        v
    };
    assert!(doc(full.path()) == doc(cut.path()), "basins.json");
    let stored = std::fs::read_to_string(&rows).unwrap();
    let mut tasks: Vec<u64> = stored
        .lines()
        .map(|l| {
            serde_json::from_str::<serde_json::Value>(l).unwrap()["task"]
                .as_u64()
                .unwrap()
        })
        .collect();
    let n = tasks.len();
    tasks.sort_unstable();
    tasks.dedup();
    assert_eq!(tasks.len(), n, "no row stored twice");
    // both passes: the coarse grid's 26 rows, then every row's remaining cells
    assert_eq!(n, 26 + 50, "no row lost");
    // killed in the second pass: resumed from both passes' stored rows
    let late = tempfile::tempdir().unwrap();
    let killed = two_pass_basins(late.path(), &["--threads", "1", "--abort-after", "30"]);
    assert!(!killed.status.success(), "the run was killed");
    assert!(two_pass_basins(late.path(), &["--resume"]).status.success());
    same_files(full.path(), late.path(), &["basins.csv"]);
    let again = two_pass_basins(cut.path(), &["--resume"]);
    assert!(again.status.success());
    assert_eq!(std::fs::read_to_string(&rows).unwrap(), stored);
    let other = two_pass_basins(cut.path(), &["--resume", "--near-tol", "0.03"]);
    assert_eq!(other.status.code(), Some(2));
    let err = String::from_utf8_lossy(&other.stderr);
    assert!(
        err.contains("near-tol = 0.02 in the interrupted run, 0.03 now"),
        "{err}"
    );
}

/// A global continuation over Ω (the impact oscillator's two period-1 orbits) on `dir`.
fn continuation(dir: &Path, extra: &[&str]) -> Output {
    let sweep = [
        "attractors",
        "--samples",
        "12",
        "--sweep",
        "omega",
        "--from",
        "1.98",
        "--to",
        "2.06",
        "--steps",
        "9",
    ];
    on_impact(&sweep, dir, extra)
}

/// A global continuation killed after three values resumes from the last stored value's
/// attractors (its seeds and ids) to the files of the uninterrupted run; each value is stored
/// once; another request is refused naming the field.
#[test]
fn a_killed_global_continuation_resumes_to_the_uninterrupted_files() {
    let full = tempfile::tempdir().unwrap();
    let cut = tempfile::tempdir().unwrap();
    let run = continuation(full.path(), &[]);
    succeeded(&run);
    let killed = continuation(cut.path(), &["--abort-after", "3"]);
    assert!(!killed.status.success(), "the run was killed");
    let values = cut.path().join(".continuation.values.jsonl");
    assert_eq!(std::fs::read_to_string(&values).unwrap().lines().count(), 3);
    let resumed = continuation(cut.path(), &["--resume"]);
    succeeded(&resumed);
    same_files(
        full.path(),
        cut.path(),
        &["attractors-sweep.csv", "attractors-sweep.nc"],
    );
    assert_eq!(std::fs::read_to_string(&values).unwrap().lines().count(), 9);
    let other = continuation(cut.path(), &["--resume", "--match-tol", "0.2"]);
    assert_eq!(other.status.code(), Some(2));
    let err = String::from_utf8_lossy(&other.stderr);
    assert!(
        err.contains("match-tol = 0.1 in the interrupted run, 0.2 now"),
        "{err}"
    );
}

/// An approach curve on the point-mass DMT probe (SI) on `dir`.
fn approach_curve(dir: &Path, extra: &[&str]) -> Output {
    let probe = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/probe-point-mass-dmt.toml"
    );
    let out = ["--out", dir.to_str().unwrap()];
    afmdyn(&[&["approach", "--probe", probe][..], &out, extra].concat())
}

/// An approach curve killed during the approach resumes from its last stored point (the
/// predictor through the points before it, the monodromy trend) to the files of the
/// uninterrupted curve; `--files none` has no store to resume.
#[test]
fn a_killed_approach_curve_resumes_to_the_uninterrupted_files() {
    let full = tempfile::tempdir().unwrap();
    let cut = tempfile::tempdir().unwrap();
    let run = approach_curve(full.path(), &[]);
    succeeded(&run);
    let killed = approach_curve(cut.path(), &["--abort-after", "50"]);
    assert!(!killed.status.success(), "the run was killed");
    let points = cut.path().join(".curve.points.jsonl");
    assert_eq!(
        std::fs::read_to_string(&points).unwrap().lines().count(),
        50
    );
    let resumed = approach_curve(cut.path(), &["--resume"]);
    succeeded(&resumed);
    same_files(full.path(), cut.path(), &["approach.csv", "approach.npy"]);
    let none = approach_curve(cut.path(), &["--resume", "--files", "none"]);
    assert_eq!(none.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&none.stderr).contains("--files none keeps no store"));
}

#[test]
fn a_locked_directory_is_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let lock = afmdyn::request::DirLock::acquire(dir.path()).unwrap();
    if !lock.is_locked() {
        return; // a file system without advisory locks
    }
    let t = std::time::Instant::now();
    let out = small(dir.path(), &[]);
    // exit 2, as every command refuses a directory in use (docs/outputs.md)
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("in use by another afmdyn run"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(t.elapsed().as_secs() < 5);
}

#[test]
fn bad_axes_are_refused_in_one_line() {
    for (args, needle) in [
        (vec!["chart", "--x", "modes"], "x = modes"),
        (vec!["chart", "--y", "omega"], "y = omega"),
        (vec!["chart", "--x-steps", "0"], "x-steps = 0"),
        (vec!["chart", "--x", "z-c"], "probe"),
        (
            vec![
                "chart", "--x", "gap", "--x-from", "-5e-1", "--x-to", "-1e-1", "--starts", "0",
            ],
            "starts = 0",
        ),
    ] {
        let out = afmdyn(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}

#[test]
fn basins_json_has_the_labels_attractors_and_measures() {
    let dir = tempfile::tempdir().unwrap();
    let out = afmdyn(&[
        "basins",
        "--contact-law",
        "impact",
        "--restitution",
        "0.8",
        "--modes",
        "1",
        "--omega",
        "2.0",
        "--x-steps",
        "12",
        "--y-steps",
        "10",
        "--json",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    succeeded(&out);
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["x"]["name"], "a1");
    assert_eq!(doc["y"]["name"], "adot1");
    let labels = doc["labels"].as_array().unwrap();
    assert_eq!(labels.len(), 10);
    assert!(labels.iter().all(|r| r.as_array().unwrap().len() == 12));
    let n = doc["attractors"].as_array().unwrap().len();
    assert!(n >= 1);
    let sum: f64 = doc["basin_fractions"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .sum();
    let failed = doc["failed"].as_f64().unwrap() / 120.0;
    assert!((sum + failed - 1.0).abs() < 1e-12);
    for f in [
        "basins.csv",
        "basins.png",
        "basins.svg",
        "basins.nc",
        "basins.json",
    ] {
        assert!(dir.path().join(f).metadata().unwrap().len() > 0, "{f}");
    }
    for (args, needle) in [
        (vec!["basins", "--x", "b1"], "x = b1: must be a1…aN"),
        (
            vec!["basins", "--base", "0.1;0.2"],
            "--base: expected 3 displacements",
        ),
        (vec!["basins", "--x", "a4"], "x = a4"),
        (vec!["basins", "--near-tol", "0"], "near-tol = 0"),
    ] {
        let out = afmdyn(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}

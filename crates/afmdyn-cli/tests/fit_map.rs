//! `afmdyn fit-map` end to end: a small map of Hertz curves written as the long-format CSV,
//! its files and JSON contract, a killed map resumed to the uninterrupted files, another
//! request's store refused, and a malformed map refused with exit 2 and one line.

use std::fmt::Write as _;
use std::path::Path;
use std::process::{Command, Output};

fn afmdyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_afmdyn"))
        .args(args)
        .output()
        .expect("run afmdyn")
}

const PROBE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../examples/probe-fit-hertz.toml"
);

/// A 4 × 3 map of noise-free Hertz approaches (k = 0.05 N/m, R = 5 µm, ν = 0.5; Sneddon 1965,
/// F = (4/3) E/(1 − ν²) √R δ^{3/2}), E = 2 kPa × (1 + ix), written into `dir`.
fn map(dir: &Path) -> String {
    let mut text = String::from("x,y,height,force\n");
    for iy in 0..3 {
        for ix in 0..4 {
            let e = 2e3 * (1 + ix) as f64;
            for i in 0..300 {
                let x = 1e-6 - 2.5e-6 * i as f64 / 299.0;
                let f = 4.0 / 3.0 * e / 0.75 * 5e-6_f64.sqrt() * (-x).max(0.0).powf(1.5);
                writeln!(text, "{}e-6,{}e-6,{:e},{:e}", ix, iy, x - f / 0.05, f).unwrap();
            }
        }
    }
    let path = dir.join("map.csv");
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

fn fit_map(data: &str, out: &Path, extra: &[&str]) -> Output {
    let mut a = vec![
        "fit-map",
        "--probe",
        PROBE,
        "--data",
        data,
        "--json",
        "--threads",
        "1",
    ];
    a.extend(["--out", out.to_str().unwrap()]);
    a.extend(extra);
    afmdyn(&a)
}

#[test]
fn a_map_writes_its_grid_files_and_resumes_after_a_kill() {
    let dir = tempfile::tempdir().unwrap();
    let data = map(dir.path());
    let (full, cut) = (dir.path().join("full"), dir.path().join("cut"));
    let out = fit_map(&data, &full, &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["counts"]["fitted"], 12);
    assert_eq!(doc["grid"]["x"].as_array().unwrap().len(), 4);
    let c = &doc["curves"][5];
    let e = c["estimates"]["sample.youngs_modulus"]["value"]
        .as_f64()
        .unwrap();
    let truth = 2e3 * (1 + c["ix"].as_u64().unwrap()) as f64;
    assert!((e / truth - 1.0).abs() < 1e-3, "{e} vs {truth}");
    for f in [
        "fit_map.nc",
        "fit_map.csv",
        "fit_map.json",
        "modulus.png",
        "topography.svg",
    ] {
        assert!(full.join(f).exists(), "{f}");
    }
    // killed after one line, resumed: the same files
    let killed = fit_map(&data, &cut, &["--abort-after", "1"]);
    assert!(!killed.status.success(), "the run was killed");
    let lines = std::fs::read_to_string(cut.join(".fit_map.lines.jsonl")).unwrap();
    assert_eq!(lines.lines().count(), 1);
    let resumed = fit_map(&data, &cut, &["--resume"]);
    assert!(
        resumed.status.success(),
        "{}",
        String::from_utf8_lossy(&resumed.stderr)
    );
    for f in ["fit_map.nc", "fit_map.csv"] {
        assert_eq!(
            std::fs::read(full.join(f)).unwrap(),
            std::fs::read(cut.join(f)).unwrap(),
            "{f}"
        );
    }
    // another request on that store is refused, naming the field
    let other = fit_map(
        &data,
        &cut,
        &["--resume", "--fit", "sample.youngs_modulus,contact_point"],
    );
    assert_eq!(other.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&other.stderr).contains("fit"));
}

#[test]
fn a_malformed_map_exits_2_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, "x,y,height\n0,0,1\n").unwrap();
    let out = fit_map(bad.to_str().unwrap(), &dir.path().join("out"), &[]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("bad.csv") && err.contains("no column force"),
        "{err}"
    );
}

/// An instrument's binary map given to the command line (which reads CSV or the NetCDF of
/// `afmdyn.export_map`) is refused in one readable line that says which files it reads, not
/// the CSV reader's internal error.
#[test]
fn a_binary_map_is_refused_saying_what_the_command_reads() {
    let dir = tempfile::tempdir().unwrap();
    let jpk = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/fmt-jpk-fd_map2x2_extracted.jpk-force-map"
    );
    let out = fit_map(jpk, &dir.path().join("out"), &[]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("not a CSV map")
            && err.contains("afmdyn.export_map")
            && !err.contains("Utf8 {"),
        "{err}"
    );
}

//! `afmdyn approach` and `afmdyn resonance` end to end: the JSON contract of the issue, the
//! files (CSV, NPY with its column header, plots) and bad input. The numerical identities are
//! tested in `crates/afmdyn/tests/approach.rs`, the agreement with SciPy in
//! `crates/afmdyn-py/tests/test_approach_scipy.py`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn afmdyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_afmdyn"))
        .args(args)
        .current_dir(repo())
        .output()
        .expect("run afmdyn")
}

fn json(args: &[&str]) -> serde_json::Value {
    let out = afmdyn(args);
    assert!(
        out.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON document")
}

fn bad_input(args: &[&str], needle: &str) {
    let out = afmdyn(args);
    assert_eq!(out.status.code(), Some(2), "{args:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    assert!(
        err.contains(needle),
        "{args:?}: '{err}' should mention '{needle}'"
    );
    assert!(out.stdout.is_empty(), "no output presented as a result");
}

const KEYS: [&str; 12] = [
    "z_c",
    "amplitude",
    "phase_deg",
    "mean_deflection",
    "peak_force",
    "min_force",
    "indentation",
    "contact_fraction",
    "min_distance",
    "energy_dissipated",
    "virial",
    "stable",
];

#[test]
fn approach_json_has_equal_length_si_arrays_and_a_marked_bistable_range() {
    let doc = json(&[
        "approach",
        "--probe",
        "examples/probe-point-mass-dmt.toml",
        "--from",
        "12e-9",
        "--to",
        "4e-9",
        "--step",
        "0.25e-9",
        "--files",
        "none",
        "--json",
    ]);
    let n = 33; // 12 nm to 4 nm in steps of 0.25 nm
    for sweep in ["approach", "retract"] {
        for key in KEYS {
            let a = doc[sweep][key]
                .as_array()
                .unwrap_or_else(|| panic!("{sweep}.{key}"));
            assert_eq!(a.len(), n, "{sweep}.{key}");
        }
    }
    let zc = |sweep: &str, i: usize| doc[sweep]["z_c"][i].as_f64().unwrap();
    assert!((zc("approach", 0) - 12e-9).abs() < 1e-18 && (zc("retract", 0) - 4e-9).abs() < 1e-18);
    // SI: amplitudes of nanometres, the far-away amplitude the probe's A0 = 10 nm
    let a_far = doc["approach"]["amplitude"][0].as_f64().unwrap();
    assert!((a_far - 10e-9).abs() < 0.01e-9, "A(12 nm) = {a_far}");
    assert_eq!(doc["units"]["length"], "m");
    // two folds bound one bistable range; each sweep jumps once, at a fold within one step
    let folds: Vec<f64> = doc["folds"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(folds.len(), 2, "{folds:?}");
    let range = doc["bistable"][0].as_array().unwrap();
    assert_eq!(range[0].as_f64().unwrap(), folds[0]);
    assert_eq!(range[1].as_f64().unwrap(), folds[1]);
    let jumps = doc["jumps"].as_array().unwrap();
    assert_eq!(jumps.len(), 2, "{jumps:?}");
    for j in jumps {
        let fold = j["fold"].as_f64().expect("a fold at the jump");
        for end in ["from", "to"] {
            assert!((j[end].as_f64().unwrap() - fold).abs() <= 0.25e-9 * (1.0 + 1e-9));
        }
    }
    // the branch has an unstable stretch, and every sweep point is stable
    let br = &doc["branches"][0]["stable"];
    assert!(br.as_array().unwrap().iter().any(|s| s == false));
    for sweep in ["approach", "retract"] {
        assert!(doc[sweep]["stable"]
            .as_array()
            .unwrap()
            .iter()
            .all(|s| s == true));
    }
}

/// `approach` on the example probe over z_c = 11 … 6 nm (11 points, no branches), then
/// `extra`: the run the file tests share.
fn probe_approach<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    let mut a = vec![
        "approach",
        "--probe",
        "examples/probe-point-mass-dmt.toml",
        "--from",
        "11e-9",
        "--to",
        "6e-9",
        "--points",
        "11",
        "--no-branches",
    ];
    a.extend_from_slice(extra);
    a
}

#[test]
fn approach_writes_csv_npy_and_plots() {
    let dir = std::env::temp_dir().join(format!("afmdyn-approach-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = afmdyn(&probe_approach(&["--out", dir.to_str().unwrap()]));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.join("approach.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    // named as the JSON document (issue 28 item 8), the abscissa and its columns first
    assert_eq!(
        &header[..13],
        &[
            "z_c",
            "amplitude",
            "amplitude_ratio",
            "phase_deg",
            "mean_deflection",
            "peak_force",
            "min_force",
            "indentation",
            "contact_fraction",
            "min_distance",
            "energy_dissipated",
            "virial",
            "harmonic_distortion",
        ]
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 22, "11 approach + 11 retract rows");
    // the columns hold the JSON's values: the approach's rows are its sweep
    let doc = json(&probe_approach(&["--files", "none", "--json"]));
    for (k, name) in header[..13].iter().enumerate() {
        for (i, r) in rows[..11].iter().enumerate() {
            let want = doc["approach"][*name][i].as_f64().unwrap();
            assert!((r[k] - want).abs() <= 1e-9 * want.abs(), "{name} row {i}");
        }
    }
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("approach.npy.json")).unwrap())
            .unwrap();
    assert_eq!(meta["shape"][0], 22);
    assert_eq!(meta["shape"][1], header.len());
    assert_eq!(meta["columns"][3]["name"], "phase_deg");
    assert_eq!(meta["columns"][3]["unit"], "degree");
    for stem in ["amplitude", "phase", "dissipation", "virial", "peak-force"] {
        assert!(dir.join(format!("approach-{stem}.png")).exists(), "{stem}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn dforce_columns_keep_the_zcdom_header_and_values() {
    let dir = std::env::temp_dir().join(format!("afmdyn-dforce-cols-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let args = |dforce: bool, sub: &str| {
        let mut a = vec![
            "approach".to_string(),
            "--probe".into(),
            "examples/probe-point-mass-dmt.toml".into(),
            "--from".into(),
            "11e-9".into(),
            "--to".into(),
            "6e-9".into(),
            "--points".into(),
            "5".into(),
            "--no-branches".into(),
            "--files".into(),
            "data".into(),
            "--out".into(),
            dir.join(sub).to_str().unwrap().into(),
        ];
        if dforce {
            a.push("--dforce-columns".into());
        }
        a
    };
    let read = |sub: &str| -> (Vec<String>, Vec<Vec<f64>>) {
        let csv = std::fs::read_to_string(dir.join(sub).join("approach.csv")).unwrap();
        let mut lines = csv.lines();
        let header = lines.next().unwrap().split(',').map(String::from).collect();
        let rows = lines
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect();
        (header, rows)
    };
    for (dforce, sub) in [(true, "d"), (false, "j")] {
        let a = args(dforce, sub);
        let out = afmdyn(&a.iter().map(String::as_str).collect::<Vec<_>>());
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let (dh, drows) = read("d");
    let (jh, jrows) = read("j");
    // dForce 2.0's zcdom columns first, in its order (header of its zcdom*.csv)
    assert_eq!(
        &dh[..11],
        &[
            "zc",
            "Amplitude",
            "Phase",
            "Distance_min",
            "Force_max",
            "Energy_diss",
            "Virial1",
            "Deflection",
            "Contact_time",
            "Power_diss",
            "sweep"
        ]
    );
    assert_eq!(dh.len(), jh.len());
    // the same numbers under both names
    let pairs = [
        ("zc", "z_c"),
        ("Amplitude", "amplitude"),
        ("Phase", "phase_deg"),
        ("Virial1", "virial"),
        ("Energy_diss", "energy_dissipated"),
        ("Force_max", "max_abs_force"),
        ("Power_diss", "power_dissipated"),
    ];
    for (d, j) in pairs {
        let (kd, kj) = (
            dh.iter().position(|h| h == d).unwrap(),
            jh.iter().position(|h| h == j).unwrap(),
        );
        for (rd, rj) in drows.iter().zip(&jrows) {
            assert_eq!(rd[kd].to_bits(), rj[kj].to_bits(), "{d} = {j}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn resonance_json_has_up_and_down_sweeps() {
    let doc = json(&[
        "resonance",
        "--points",
        "7",
        "--no-branches",
        "--files",
        "none",
        "--json",
    ]);
    for sweep in ["up", "down"] {
        assert_eq!(doc[sweep]["omega"].as_array().unwrap().len(), 7);
        assert_eq!(doc[sweep]["amplitude"].as_array().unwrap().len(), 7);
    }
    let up = &doc["up"]["omega"];
    assert!(up[0].as_f64().unwrap() < up[6].as_f64().unwrap());
}

#[test]
fn bad_grids_exit_2_with_one_line() {
    bad_input(&["approach", "--points", "1", "--files", "none"], "points");
    bad_input(
        &["approach", "--points", "100001", "--files", "none"],
        "points",
    );
    bad_input(&["approach", "--step", "-0.1", "--files", "none"], "step");
    bad_input(&["approach", "--step", "1e-12", "--files", "none"], "step");
    bad_input(&["approach", "--from", "inf", "--files", "none"], "--from");
    bad_input(
        &["approach", "--tolerance", "0", "--files", "none"],
        "tolerance",
    );
    bad_input(&["approach", "--from", "2e6", "--files", "none"], "alpha5");
    bad_input(&["resonance", "--mode", "9", "--files", "none"], "mode");
    bad_input(
        &["resonance", "--from", "0", "--to", "1", "--files", "none"],
        "omega",
    );
}

/// Issue 28 item 1: `--units afm` (the default) prints SI quantities prefixed as AFM papers
/// write them, `--units si` in plain SI; the JSON is plain SI either way.
#[test]
fn display_units_choose_prefixed_or_plain_si() {
    let run = |units: &str| {
        let out = afmdyn(&[
            "--units",
            units,
            "approach",
            "--probe",
            "examples/probe-point-mass-dmt.toml",
            "--points",
            "30",
            "--files",
            "none",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    let (afm, si) = (run("afm"), run("si"));
    let fold = |text: &str| {
        text.lines()
            .find(|l| l.trim_start().starts_with("fold at z_c = "))
            .unwrap()
            .trim()
            .to_string()
    };
    assert!(fold(&afm).ends_with(" nm"), "{afm}");
    let plain = fold(&si);
    assert!(plain.ends_with("e-9 m"), "{si}");
    // the same fold in both spellings
    let nm: f64 = fold(&afm)["fold at z_c = ".len()..]
        .trim_end_matches(" nm")
        .parse()
        .unwrap();
    let m: f64 = plain["fold at z_c = ".len()..]
        .trim_end_matches(" m")
        .parse()
        .unwrap();
    assert!((nm * 1e-9 - m).abs() < 1e-5 * m, "{nm} nm vs {m} m");
    let bad = afmdyn(&["--units", "cgs", "approach"]);
    assert_eq!(bad.status.code(), Some(2));
}

/// Issue 42 §4: the setpoint summary printed one "peak force" (max F_c, which without
/// repulsion is the far field's) and a conservative law's E_dis as `5.5e-10 aJ` (round-off).
/// It now prints the repulsive maximum and the adhesion minimum, each as the JSON's value,
/// and energies below 1e-6 of the model's unit (kA₀² here) as 0.
#[test]
fn setpoint_summary_prints_repulsive_peak_adhesion_and_resolved_zeros() {
    let dir = std::env::temp_dir().join(format!("afmdyn-sp-sum-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let probe = repo().join("examples/probe-point-mass-dmt.toml");
    let args = [
        "approach",
        "--probe",
        probe.to_str().unwrap(),
        "--setpoint",
        "0.8",
        "--files",
        "none",
        "--out",
        dir.to_str().unwrap(),
    ];
    let out = afmdyn(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text
        .lines()
        .find(|l| l.contains("(repulsive): z_c"))
        .unwrap_or_else(|| panic!("{text}"));
    let _ = std::fs::remove_dir_all(&dir);
    let doc = json(&[&args[..], &["--json"]].concat());
    let p = &doc["setpoint"]["points"][0];
    let (peak, least) = (
        p["peak_force"].as_f64().unwrap(),
        p["min_force"].as_f64().unwrap(),
    );
    // DMT: repulsion at the deepest indentation, adhesion −H/a0² · R/6 at contact
    assert!(peak > 0.0 && least < 0.0, "{peak} {least}");
    assert!(
        line.contains(&format!("repulsive peak force {:.5} nN", peak * 1e9)),
        "{line}"
    );
    assert!(
        line.contains(&format!("adhesion (min force) {:.5} nN", least * 1e9)),
        "{line}"
    );
    // the probe's sample has no viscosity: E_dis is round-off of the energy unit kA0²
    let e = p["energy_dissipated"].as_f64().unwrap();
    let unit = 40.0 * 10e-9 * 10e-9;
    assert!(e.abs() < 1e-6 * unit, "E_dis {e:e}");
    assert!(line.ends_with("E_dis 0 J"), "{line}");
}

/// Every operating point at a setpoint is an orbit of the curve, listed once (issue 77): on
/// the RTESPA-300 over a 50 MPa DMT sample (A₀ 15 nm) the branch jumps between two of its
/// points, and the observables interpolated across that gap made an "attractive" point at
/// z_c = 5.98 nm with A = 12 nm where the stable orbits have 6.6–7.2 nm and 14.6 nm; a
/// stretch of the branch traced three times listed its repulsive point three times.
#[test]
fn setpoint_operating_points_are_orbits_of_the_curve() {
    let dir = tempfile::tempdir().unwrap();
    let probe = std::fs::read_to_string(repo().join("examples/probe-rtespa300-polystyrene.toml"))
        .unwrap()
        .replace("youngs_modulus = 2.5e9", "youngs_modulus = 50e6")
        .replace("viscosity = 10.0", "");
    let path = dir.path().join("rt50.toml");
    std::fs::write(&path, probe).unwrap();
    let doc = json(&[
        "approach",
        "--probe",
        path.to_str().unwrap(),
        "--setpoint",
        "0.8",
        "--json",
        "--files",
        "none",
    ]);
    let col = |block: &serde_json::Value, k: &str| -> Vec<f64> {
        block[k]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap_or(f64::NAN))
            .collect()
    };
    let z = col(&doc["approach"], "z_c");
    let step = (z[0] - z[1]).abs();
    // every stable (z_c, A) of the sweeps and the branches
    let mut stable: Vec<(f64, f64)> = Vec::new();
    let blocks = [&doc["approach"], &doc["retract"]];
    let branches = doc["branches"].as_array().unwrap();
    for b in blocks.into_iter().chain(branches) {
        let (zs, amps) = (col(b, "z_c"), col(b, "amplitude"));
        let st = b["stable"].as_array().unwrap();
        for i in 0..zs.len() {
            if st[i].as_bool() == Some(true) {
                stable.push((zs[i], amps[i]));
            }
        }
    }
    let points = doc["setpoint"]["points"].as_array().unwrap();
    assert!(!points.is_empty());
    let a_sp = doc["setpoint"]["amplitude"].as_f64().unwrap();
    for (i, p) in points.iter().enumerate() {
        let (zc, a) = (p["z_c"].as_f64().unwrap(), p["amplitude"].as_f64().unwrap());
        assert!((a - a_sp).abs() <= 1e-6 * a_sp, "{p}");
        let near = stable
            .iter()
            .any(|&(zs, amp)| (zs - zc).abs() <= 1.5 * step && (amp - a).abs() <= 0.05 * a);
        assert!(near, "no stable orbit of the curve near {p}");
        for q in &points[..i] {
            let dz = (q["z_c"].as_f64().unwrap() - zc).abs();
            assert!(
                dz > 1e-12 || q["regime"] != p["regime"],
                "listed twice: {p}"
            );
        }
    }
}

/// `approach --temperature`: σ_A in m at every point of both sweeps, the `"thermal"` block (the
/// lock-in's time constant and bandwidth), a warning for a temperature in °C, and the refusals
/// (no probe; a time constant alone) as one line with exit 2.
#[test]
fn approach_temperature_gives_the_lock_ins_noise() {
    let probe = "examples/probe-rtespa300-polystyrene.toml";
    let doc = json(&[
        "approach",
        "--probe",
        probe,
        "--points",
        "6",
        "--no-branches",
        "--temperature",
        "295",
        "--time-constant",
        "1e-3",
        "--json",
    ]);
    let t = &doc["thermal"];
    assert_eq!(t["temperature"], 295.0);
    assert_eq!(t["time_constant"], 1e-3);
    // (f_d/2) β/(2 − β) ≈ 1/(4τ_L) for τ_L ≫ T
    assert!((t["bandwidth"].as_f64().unwrap() / 250.0 - 1.0).abs() < 1e-3);
    for sweep in ["approach", "retract"] {
        let s = doc[sweep]["amplitude_noise"].as_array().unwrap();
        assert_eq!(s.len(), 6);
        // picometres: k_BT/k = (10 pm)² for 40 N/m
        assert!(s
            .iter()
            .all(|v| v.as_f64().is_some_and(|v| v > 1e-13 && v < 2e-11)));
    }
    let warm = json(&[
        "approach",
        "--probe",
        probe,
        "--points",
        "3",
        "--no-branches",
        "--temperature",
        "22",
        "--json",
    ]);
    let said = warm["warnings"].to_string();
    assert!(said.contains("written in °C?"), "{said}");
    bad_input(
        &["approach", "--temperature", "295", "--json"],
        "temperature",
    );
    bad_input(
        &[
            "approach",
            "--probe",
            probe,
            "--time-constant",
            "1e-3",
            "--json",
        ],
        "time-constant",
    );
}

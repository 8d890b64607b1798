//! `afmdyn bimodal` end to end on examples/probe-bimodal.toml (the eigenmode model, two
//! components each at its mode's resonance, f₂/f₁ = 25/4): far from the sample each
//! component's amplitude is its free amplitude (the probe's 10 nm and 1 nm, to 1e-4 at
//! 1.2 × their sum), near it both fall; the CSV carries the per-component columns in the
//! document's names; a single-frequency probe and a bad `[drive]` array exit 2 with one line,
//! as do `resonance` and `fm`, which move the drive frequency, on a multifrequency probe.
//! `--average` measures the same points by the time average, within its error estimates of
//! the orbits; an incommensurate ratio is averaged without being asked, and says so.

use crate::common;
use common::{column, run as afmdyn};

const PROBE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../examples/probe-bimodal.toml"
);
const SINGLE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../examples/probe-eigenmodes-dmt.toml"
);

#[test]
fn bimodal_curve_reports_each_component() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("bimodal");
    let out = afmdyn(&[
        "bimodal",
        "--probe",
        PROBE,
        "--points",
        "12",
        "--no-branches",
        "--files",
        "data",
        "--json",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let free = &doc["drive_components"]["free_amplitude"];
    assert!((free[0].as_f64().unwrap() / 10e-9 - 1.0).abs() < 1e-9);
    assert!((free[1].as_f64().unwrap() / 1e-9 - 1.0).abs() < 1e-9);
    let f = &doc["drive_components"]["frequency"];
    assert!((f[1].as_f64().unwrap() / 1.875e6 - 1.0).abs() < 1e-12);
    let (a1, a2) = (
        column(&doc, "approach", "amplitude_1"),
        column(&doc, "approach", "amplitude_2"),
    );
    let z = column(&doc, "approach", "z_c");
    assert!(
        (z[0] / 13.365e-9 - 1.0).abs() < 1e-9,
        "default start 1.2 × 11 nm + a0"
    );
    assert!((a1[0] / 10e-9 - 1.0).abs() < 1e-4, "A1 far {}", a1[0]);
    assert!((a2[0] / 1e-9 - 1.0).abs() < 1e-4, "A2 far {}", a2[0]);
    assert!(a1.last().unwrap() < &(0.5 * 10e-9));
    assert!(a2.last().unwrap() < &(0.5 * 1e-9));
    for k in [
        "phase_1_deg",
        "phase_2_deg",
        "virial_1",
        "virial_2",
        "energy_dissipated_2",
    ] {
        assert_eq!(column(&doc, "retract", k).len(), 12, "{k}");
    }
    // the primary's column is the curve's amplitude
    for (x, y) in a1.iter().zip(column(&doc, "approach", "amplitude")) {
        assert!((x / y - 1.0).abs() < 1e-9, "{x} vs {y}");
    }
    let csv = std::fs::read_to_string(out_dir.join("bimodal.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(
        header.ends_with(
            "amplitude_1,phase_1_deg,virial_1,energy_dissipated_1,amplitude_2,phase_2_deg,\
             virial_2,energy_dissipated_2"
        ),
        "{header}"
    );
    assert_eq!(csv.lines().count(), 1 + 24);
}

#[test]
fn bimodal_refuses_a_single_frequency_drive_and_bad_arrays() {
    let out = afmdyn(&["bimodal", "--probe", SINGLE, "--files", "none"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("[drive].free_amplitude"), "{err}");
    // analyses that move the drive frequency refuse a multifrequency drive
    let tmp = tempfile::tempdir().unwrap();
    let fm_out = tmp.path().join("fm");
    for args in [
        vec!["resonance", "--files", "none"],
        vec!["fm", "--out", fm_out.to_str().unwrap()],
    ] {
        let cmd = args[0];
        let out = afmdyn(&[&args[..], &["--probe", PROBE, "--points", "4"]].concat());
        assert_eq!(out.status.code(), Some(2), "{cmd}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains("[drive].frequency"), "{cmd}: {err}");
    }
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(PROBE).unwrap();
    for (bad, says) in [
        ("frequency = [300e3, 1.875e6]", "frequency = [300e3]"),
        (
            "frequency = [300e3, 1.875e6]",
            "frequency = [300e3, 1.875e6 ]\nfoo = 1",
        ),
        (
            "frequency = [300e3, 1.875e6]",
            "frequency = [300e3, -1.875e6]",
        ),
    ] {
        let p = dir.path().join("p.toml");
        std::fs::write(&p, text.replace(bad, says)).unwrap();
        let out = afmdyn(&["bimodal", "--probe", p.to_str().unwrap(), "--files", "none"]);
        assert_eq!(out.status.code(), Some(2), "{says}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains("[drive]"), "{says}: {err}");
    }
}

/// A bimodal curve over its budget is refused by its own name, not the approach's it wraps.
#[test]
fn a_bimodal_curve_over_budget_is_refused_as_bimodal() {
    let args = [
        "bimodal", "--probe", PROBE, "--points", "100000", "--traces", "20",
    ];
    let out = afmdyn(&[&args[..], &["--files", "none"]].concat());
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.starts_with("afmdyn: bimodal: a peak memory of"),
        "{err}"
    );
}

/// The doc's `time_average.<sweep>.<k>` as rows of numbers (one per point).
fn estimates(doc: &serde_json::Value, sweep: &str, k: &str) -> Vec<Vec<f64>> {
    doc["time_average"][sweep][k]
        .as_array()
        .unwrap_or_else(|| panic!("time_average.{sweep}.{k}"))
        .iter()
        .map(|r| {
            r.as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect()
        })
        .collect()
}

#[test]
fn average_agrees_with_the_orbits_within_its_estimates() {
    let range = ["--from", "12nm", "--to", "8nm", "--points", "4"];
    let common = [
        &[
            "bimodal",
            "--probe",
            PROBE,
            "--no-branches",
            "--files",
            "none",
            "--json",
        ][..],
        &range[..],
    ]
    .concat();
    let orbit = common::json(&common);
    let avg = common::json(&[&common[..], &["--average"]].concat());
    assert!(orbit.get("time_average").is_none());
    let ta = &avg["time_average"];
    assert!(ta["window_periods"].as_u64().unwrap() >= 16, "{ta}");
    for sweep in ["approach", "retract"] {
        let settled = ta[sweep]["settled"].as_array().unwrap();
        assert!(settled.iter().all(|s| s == true), "{sweep}: {ta}");
        let err = estimates(&avg, sweep, "amplitude_error");
        for (i, a0) in [(1, 10e-9), (2, 1e-9)] {
            let k = format!("amplitude_{i}");
            let (x, y) = (column(&orbit, sweep, &k), column(&avg, sweep, &k));
            for (j, (x, y)) in x.iter().zip(&y).enumerate() {
                // the estimate, or the settling tolerance 1e-5 A0 at the least
                let bound = err[j][i - 1].max(1e-5 * a0);
                assert!(
                    (x - y).abs() <= bound,
                    "{sweep} {k}[{j}]: orbit {x}, average {y}, bound {bound}"
                );
            }
        }
    }
}

#[test]
fn an_incommensurate_ratio_is_averaged_and_says_so() {
    // f2/f1 = 6.25 + √2·1e-2: no fraction with a common period of ≤ 1000 drive periods
    let dir = tempfile::tempdir().unwrap();
    let f2 = 300e3 * (6.25 + std::f64::consts::SQRT_2 * 1e-2);
    let text = std::fs::read_to_string(PROBE)
        .unwrap()
        .replace(
            "frequency = [300e3, 1.875e6]  ",
            &format!("frequency = [300e3, {f2}]"),
        )
        .replace("quality_factor = [400, 2500]", "quality_factor = [60, 300]");
    let p = dir.path().join("p.toml");
    std::fs::write(&p, text).unwrap();
    let doc = common::json(&[
        "bimodal",
        "--probe",
        p.to_str().unwrap(),
        "--from",
        "11nm",
        "--to",
        "9nm",
        "--points",
        "3",
        "--files",
        "none",
        "--json",
    ]);
    let warnings = doc["warnings"].to_string();
    assert!(warnings.contains("quasi-periodic"), "{warnings}");
    let r = doc["drive_components"]["ratio"][1].as_f64().unwrap();
    assert!((r / (f2 / 300e3) - 1.0).abs() < 1e-9, "ratio {r}");
    let settled = doc["time_average"]["approach"]["settled"]
        .as_array()
        .unwrap();
    assert_eq!(settled.len(), 3);
    let a2 = column(&doc, "approach", "amplitude_2");
    assert!(
        a2.iter().all(|a| a.is_finite() && *a > 0.0 && *a < 1.5e-9),
        "{a2:?}"
    );
}

/// A time-averaged curve killed after 3 points resumes from the last stored point's end state
/// (τ and z) to the files of the uninterrupted curve, byte for byte; resuming it without
/// `--average` is another request, refused naming it.
#[test]
fn a_killed_average_resumes_to_the_uninterrupted_files() {
    let (full, cut) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let curve = |dir: &std::path::Path, extra: &[&str]| {
        let base = [
            "bimodal", "--probe", PROBE, "--from", "12nm", "--to", "8nm", "--points", "4",
            "--files", "data", "--out",
        ];
        afmdyn(&[&base[..], &[dir.to_str().unwrap()], extra].concat())
    };
    assert!(curve(full.path(), &["--average"]).status.success());
    assert!(!curve(cut.path(), &["--average", "--abort-after", "3"])
        .status
        .success());
    let other = curve(cut.path(), &["--resume", "--no-branches"]);
    assert_eq!(other.status.code(), Some(2));
    let err = String::from_utf8_lossy(&other.stderr);
    assert!(err.contains("average"), "{err}");
    let resumed = curve(cut.path(), &["--average", "--resume"]);
    assert!(
        resumed.status.success(),
        "{}",
        String::from_utf8_lossy(&resumed.stderr)
    );
    for f in ["bimodal.csv", "bimodal.npy"] {
        assert!(
            std::fs::read(full.path().join(f)).unwrap()
                == std::fs::read(cut.path().join(f)).unwrap(),
            "{f}: the resumed curve differs"
        );
    }
}

/// Issue 60 item 15: `bimodal --setpoint` gives the operating point where the first
/// component's amplitude — the one the feedback holds — is the setpoint times its free
/// amplitude (a defining identity: A1 = 0.7 × 10 nm), with every component's amplitude, phase,
/// virial and E_dis there, each between its values at the two curve points around it.
#[test]
fn bimodal_setpoint_gives_every_component() {
    let out = afmdyn(&[
        "bimodal",
        "--probe",
        PROBE,
        "--points",
        "20",
        "--setpoint",
        "0.7",
        "--files",
        "none",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let a01 = doc["drive_components"]["free_amplitude"][0]
        .as_f64()
        .unwrap();
    let points = doc["setpoint"]["points"].as_array().unwrap();
    assert!(!points.is_empty());
    for p in points {
        let a1 = p["amplitude_1"].as_f64().unwrap();
        assert!((a1 - 0.7 * a01).abs() < 1e-9 * a01, "{a1} vs {}", 0.7 * a01);
        for key in [
            "amplitude_2",
            "phase_2_deg",
            "virial_2",
            "energy_dissipated_2",
        ] {
            assert!(p[key].as_f64().is_some_and(f64::is_finite), "{key}: {p}");
        }
        // the same row of the curve's own columns brackets each component's value
        let z = p["z_c"].as_f64().unwrap();
        let source = p["source"].as_str().unwrap();
        if let Some(j) = source.strip_prefix("branch ") {
            let b = &doc["branches"][j.parse::<usize>().unwrap()];
            let zs: Vec<f64> = b["z_c"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            let k = zs
                .windows(2)
                .position(|w| (w[0] - z) * (w[1] - z) <= 0.0)
                .expect("the setpoint lies on its branch");
            for key in ["amplitude_2", "phase_2_deg"] {
                let (lo, hi) = (b[key][k].as_f64().unwrap(), b[key][k + 1].as_f64().unwrap());
                let v = p[key].as_f64().unwrap();
                assert!(
                    v >= lo.min(hi) - 1e-12 && v <= lo.max(hi) + 1e-12,
                    "{key}: {v} not in [{lo}, {hi}]"
                );
            }
        }
    }
}

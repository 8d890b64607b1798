//! `afmdyn fm` end to end: the Sader–Jarvis round trip (J. E. Sader and S. P. Jarvis, Appl.
//! Phys. Lett. 84, 1801 (2004)) — the DMT probe's van der Waals force −HR/(6d²) → Δf(z_c) by
//! `afmdyn fm` → `afmdyn reconstruct --fm fm.json` → the force again within 2 % outside contact
//! (d from 3a₀ to A/2, where the inversion's own error is below 1 % on this grid); the files;
//! bad input exits 2 with one line naming the flag.

use crate::common;
use common::{column, run as afmdyn};
use std::process::Output;

const PROBE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../examples/probe-point-mass-dmt.toml"
);

/// The output of `afmdyn args`, which must succeed.
fn succeeded(args: &[&str]) -> Output {
    let out = afmdyn(args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

#[test]
fn fm_then_reconstruct_gives_back_the_van_der_waals_force() {
    let dir = tempfile::tempdir().unwrap();
    let fm_dir = dir.path().join("fm");
    let out = succeeded(&[
        "fm",
        "--probe",
        PROBE,
        "--from",
        "60nm",
        "--to",
        "10.5nm",
        "--step",
        "0.02nm",
        "--json",
        "--out",
        fm_dir.to_str().unwrap(),
    ]);
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["units"]["frequency_shift"], "Hz");
    assert_eq!(doc["spring_constant"], 40.0);
    assert_eq!(
        doc["warnings"].as_array().unwrap().len(),
        0,
        "{}",
        doc["warnings"]
    );
    let shift = column(&doc, "curve", "frequency_shift");
    assert_eq!(shift.len(), 2476);
    // attractive: the shift is negative and grows towards the sample
    assert!(shift.windows(2).all(|w| w[1] < w[0] && w[1] < 0.0));
    for file in ["fm.csv", "fm.json", "fm-frequency-shift.png"] {
        assert!(fm_dir.join(file).metadata().unwrap().len() > 0, "{file}");
    }
    let rec = dir.path().join("rec");
    let out = succeeded(&[
        "reconstruct",
        "--fm",
        fm_dir.join("fm.json").to_str().unwrap(),
        "--json",
        "--out",
        rec.to_str().unwrap(),
    ]);
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let (d, force) = (
        column(&doc, "force", "distance"),
        column(&doc, "force", "force"),
    );
    let hr = 6.6e-20 * 10e-9;
    let a0 = 0.165e-9;
    let mut checked = 0;
    for (d, f) in d
        .iter()
        .zip(&force)
        .filter(|(d, _)| **d >= 3.0 * a0 && **d <= 5e-9)
    {
        let want = -hr / (6.0 * d * d);
        assert!((f / want - 1.0).abs() < 0.02, "d = {d}: {f} vs {want}");
        checked += 1;
    }
    assert!(checked > 200, "{checked}");
    // the model's force beside it: the law's van der Waals force outside contact, exactly
    let law = column(&doc, "force", "law");
    assert_eq!(law.len(), d.len());
    for (d, l) in d.iter().zip(&law).filter(|(d, _)| **d > a0) {
        let want = -hr / (6.0 * d * d);
        assert!((l / want - 1.0).abs() < 1e-12, "d = {d}: {l} vs {want}");
    }
}

#[test]
fn bad_fm_requests_exit_2_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    for (extra, needle) in [
        (&["--amplitude", "-1nm"][..], "amplitude"),
        (&["--mode", "2"][..], "mode"),
        (&["--tolerance", "0"][..], "tolerance"),
        (&["--from", "1"][..], "from = 1 m"),
        (&["--points", "1"][..], "points"),
    ] {
        let mut args = vec!["fm", "--probe", PROBE, "--out", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        let o = afmdyn(&args);
        assert_eq!(o.status.code(), Some(2), "{extra:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains(needle), "{needle}: {err}");
    }
    // a document in the model's units cannot be inverted
    let plain = dir.path().join("plain");
    let o = afmdyn(&["fm", "--points", "3", "--out", plain.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = afmdyn(&[
        "reconstruct",
        "--fm",
        plain.join("fm.json").to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("fm") && err.contains("SI"), "{err}");
}

/// `reconstruct --am`: the point-mass approach curve's attractive run (the van der Waals
/// force, A₀ = 10 nm, Q = 400), inverted at each point's amplitude, gives −HR/(6d²) back within
/// 1 % from 0.5 to 5 nm (measured 0.45 % and 0.79 %); another model's document is refused.
#[test]
fn am_approach_reconstructs_the_van_der_waals_force() {
    let dir = tempfile::tempdir().unwrap();
    let probe = dir.path().join("p.toml");
    let text = std::fs::read_to_string(PROBE).unwrap();
    let text: String = text
        .lines()
        .filter(|l| !l.starts_with("z_c"))
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(&probe, text).unwrap();
    let out = succeeded(&[
        "approach",
        "--probe",
        probe.to_str().unwrap(),
        "--from",
        "60nm",
        "--to",
        "3nm",
        "--step",
        "0.02nm",
        "--no-branches",
        "--files",
        "none",
        "--json",
    ]);
    let doc_path = dir.path().join("approach.json");
    std::fs::write(&doc_path, &out.stdout).unwrap();
    let rec = dir.path().join("rec");
    let out = succeeded(&[
        "reconstruct",
        "--am",
        doc_path.to_str().unwrap(),
        "--json",
        "--out",
        rec.to_str().unwrap(),
    ]);
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(doc["points"].as_u64().unwrap() > 2000);
    let (d, force) = (
        column(&doc, "force", "distance"),
        column(&doc, "force", "force"),
    );
    let hr = 6.6e-20 * 10e-9;
    let mut checked = 0;
    for (d, f) in d
        .iter()
        .zip(&force)
        .filter(|(d, _)| **d >= 0.5e-9 && **d <= 5e-9)
    {
        let want = -hr / (6.0 * d * d);
        assert!((f / want - 1.0).abs() < 0.01, "d = {d}: {f} vs {want}");
        checked += 1;
    }
    assert!(checked > 200, "{checked}");
    // the beam's base-driven balance is not the point mass's: refused, naming --am
    let beam = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/probe-beam-dmt.toml"
    );
    let out = afmdyn(&[
        "approach",
        "--probe",
        beam,
        "--points",
        "4",
        "--no-branches",
        "--files",
        "none",
        "--json",
    ]);
    std::fs::write(&doc_path, &out.stdout).unwrap();
    let o = afmdyn(&[
        "reconstruct",
        "--am",
        doc_path.to_str().unwrap(),
        "--out",
        rec.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("am") && err.contains("point-mass"), "{err}");
}

/// The refusal of `args`: exit 2 and one line on stderr.
fn refused(args: &[&str]) -> String {
    let out = afmdyn(args);
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    err
}

/// Issue 60: an SI amplitude is held against the amplitude's range of the library
/// (`probe::ranges`, `[drive] free_amplitude`: 1 pm to 10 µm), not a rest distance's ±1e-4 m
/// nor any range of the front end: 0.5 mm and 5e-324 m are refused naming `amplitude` and
/// the amplitude's bound, a negative one as not > 0.
#[test]
fn an_si_amplitude_is_refused_by_the_amplitudes_range() {
    let err = refused(&[
        "fm",
        "--probe",
        PROBE,
        "--amplitude",
        "5e-4",
        "--files",
        "none",
    ]);
    assert!(
        err.contains("amplitude = 0.0005 m: must be ≤ 1e-5 m"),
        "{err}"
    );
    let err = refused(&[
        "fm",
        "--probe",
        PROBE,
        "--amplitude",
        "0.5mm",
        "--files",
        "none",
    ]);
    assert!(
        err.contains("amplitude = 0.0005 m: must be ≤ 1e-5 m"),
        "{err}"
    );
    let err = refused(&[
        "fm",
        "--probe",
        PROBE,
        "--amplitude",
        "5e-324",
        "--files",
        "none",
    ]);
    assert!(err.contains("amplitude = 5e-324 m: below 1 pm"), "{err}");
    let err = refused(&[
        "fm",
        "--probe",
        PROBE,
        "--amplitude",
        "-10nm",
        "--files",
        "none",
    ]);
    assert!(
        err.contains("amplitude") && err.contains("must be > 0"),
        "{err}"
    );
}

/// Issue 60: the summary's numbers have at most 6 significant digits in their unit (a model
/// run printed `2e0 g0`, `0e0 Ω`).
#[test]
fn the_model_summary_prints_plain_numbers() {
    let out = succeeded(&["fm", "--points", "12", "--files", "none"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.starts_with("12 z_c values from 2 g0 to 1 g0: Δf from "),
        "{text}"
    );
    assert!(!text.contains("e0 "), "{text}");
}

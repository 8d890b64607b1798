//! `afmdyn calibrate` end to end: the thermal spectrum `afmdyn thermal` writes for the soft
//! silicon lever in water (examples/probe-water-beam.toml: Q₁ ≈ 2.4, three modes), read back
//! from a CSV, gives the probe's static spring constant by the thermal method within 0.5 % and
//! by Sader's method (the lever's plan in water) within 1 %, the first two modes' effective
//! ones by the thermal method within 1 % (the third, Q ≈ 7 on its neighbours' broad tails,
//! within 5 %: the oscillator on a white floor is the fit's model, not the overlapping peaks of
//! a lever in liquid); its files; in V²/Hz with an InvOLS, the same k; bad options
//! refused with exit 2 and one line naming them.

use crate::common::{json, run as afmdyn};
use std::fmt::Write;

/// The probe (the tests run in the repository's root).
const PROBE: &str = "examples/probe-water-beam.toml";

/// The probe's thermal document and its apparent deflection's spectrum as a CSV in `dir`,
/// scaled by `scale` (1/InvOLS² for volts).
fn spectrum(dir: &std::path::Path, scale: f64) -> (serde_json::Value, String) {
    let out = dir.join("thermal").display().to_string();
    let doc = json(&[
        "thermal", "--probe", PROBE, "--to", "150kHz", "--points", "20000", "--json", "--out", &out,
    ]);
    let mut csv = String::from("frequency,psd\n");
    let psd = &doc["psd"];
    for (f, s) in psd["frequency"]
        .as_array()
        .unwrap()
        .iter()
        .zip(psd["apparent_deflection"].as_array().unwrap())
    {
        writeln!(csv, "{},{}", f, s.as_f64().unwrap() * scale).unwrap();
    }
    let path = dir.join(format!("psd-{scale}.csv"));
    std::fs::write(&path, csv).unwrap();
    (doc, path.display().to_string())
}

#[test]
fn a_lever_in_water_gives_its_spring_constant_back() {
    let dir = tempfile::tempdir().unwrap();
    let (thermal, psd) = spectrum(dir.path(), 1.0);
    let ks = thermal["spring_constant"].as_f64().unwrap();
    let out = dir.path().join("cal").display().to_string();
    let doc = json(&[
        "calibrate",
        "--probe",
        PROBE,
        "--psd",
        &psd,
        "--json",
        "--out",
        &out,
    ]);
    let k = &doc["spring_constant"];
    let rel = |v: &serde_json::Value, want: f64| (v.as_f64().unwrap() / want - 1.0).abs();
    assert!(rel(&k["thermal"], ks) < 5e-3, "{k} vs {ks}");
    assert!(rel(&k["sader"], ks) < 1e-2, "{k} vs {ks}");
    assert!(k["agreement"]["sader_over_thermal"].as_f64().is_some());
    let modes = doc["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 3);
    for (m, want) in modes.iter().zip(thermal["modes"].as_array().unwrap()) {
        let keff = want["effective_spring_constant"].as_f64().unwrap();
        let tol = [5e-3, 1e-2, 5e-2][m["mode"].as_u64().unwrap() as usize - 1];
        assert!(rel(&m["spring_constant_thermal"], keff) < tol, "{m}");
        assert!(
            m["spring_constant_thermal_standard_error"]
                .as_f64()
                .unwrap()
                > 0.0
        );
    }
    for file in [
        "spectrum.nc",
        "modes.nc",
        "calibration.json",
        "calibration.svg",
    ] {
        assert!(dir.path().join("cal").join(file).exists(), "{file}");
    }
    // the detector's V²/Hz with its InvOLS (50 nm/V): the same k
    let (_, volts) = spectrum(dir.path(), 1.0 / (50e-9f64 * 50e-9));
    let doc = json(&[
        "calibrate",
        "--probe",
        PROBE,
        "--psd",
        &volts,
        "--volts",
        "--invols",
        "50e-9",
        "--json",
        "--out",
        &out,
    ]);
    assert!(
        rel(&doc["spring_constant"]["thermal"], ks) < 5e-3,
        "{}",
        doc["spring_constant"]
    );
}

#[test]
fn bad_options_are_refused_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out").display().to_string();
    let bad_csv = dir.path().join("bad.csv");
    std::fs::write(&bad_csv, "frequency,amplitude\n1,2\n").unwrap();
    let bad_csv = bad_csv.display().to_string();
    let (_, psd) = spectrum(dir.path(), 1.0);
    for (args, word) in [
        (vec!["calibrate", "--psd", &psd, "--out", &out], "probe"),
        (
            vec![
                "calibrate",
                "--probe",
                PROBE,
                "--psd",
                &bad_csv,
                "--out",
                &out,
            ],
            "psd",
        ),
        (
            vec![
                "calibrate",
                "--probe",
                PROBE,
                "--psd",
                &psd,
                "--volts",
                "--out",
                &out,
            ],
            "volts",
        ),
        (
            vec![
                "calibrate",
                "--probe",
                PROBE,
                "--psd",
                &psd,
                "--invols",
                "5e-8",
                "--out",
                &out,
            ],
            "invols",
        ),
        (
            vec![
                "calibrate",
                "--probe",
                PROBE,
                "--psd",
                &psd,
                "--peaks",
                "4",
                "--out",
                &out,
            ],
            "peaks",
        ),
        (
            vec![
                "calibrate",
                "--probe",
                PROBE,
                "--psd",
                &psd,
                "--bands",
                "3kHz",
                "--out",
                &out,
            ],
            "bands",
        ),
    ] {
        let o = afmdyn(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(
            e.contains(word) && e.trim().lines().count() == 1,
            "{args:?}: {e}"
        );
    }
}

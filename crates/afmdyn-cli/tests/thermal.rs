//! `afmdyn thermal` end to end: a point-mass probe's one mode carries k_B T/k at the file's k and
//! f₀ (equipartition) and its PSD peaks at f₀ with the harmonic oscillator's 2k_BTQ/(πkf₀);
//! its files; a missing probe, a spot off the lever and a temperature at absolute zero refused
//! with exit 2 and one line naming the option; a temperature in °C warned of.

use crate::common::{json, run as afmdyn};

/// The probe (the tests run in the repository's root).
const PROBE: &str = "examples/probe-point-mass-dmt.toml";

#[test]
fn a_point_mass_lever_carries_kt_over_k() {
    let dir = std::env::temp_dir().join(format!("afmdyn-thermal-{}", std::process::id()));
    let out = dir.display().to_string();
    // 2 frequencies: f₀ and 2 f₀
    let doc = json(&[
        "thermal", "--probe", PROBE, "--to", "600kHz", "--points", "2", "--json", "--out", &out,
    ]);
    let kt = 1.380_649e-23 * 295.0;
    let (k, f0, q) = (40.0, 300e3, 400.0);
    let mode = &doc["modes"][0];
    let close = |v: &serde_json::Value, want: f64| (v.as_f64().unwrap() / want - 1.0).abs() < 1e-9;
    assert!(close(&mode["effective_spring_constant"], k), "{mode}");
    assert!(close(&mode["frequency"], f0), "{mode}");
    assert!(close(&mode["mean_square_deflection"], kt / k), "{mode}");
    assert!(close(&doc["psd"]["frequency"][0], f0));
    let peak = 2.0 * kt * q / (std::f64::consts::PI * k * f0);
    assert!(close(&doc["psd"]["deflection"][0], peak), "{}", doc["psd"]);
    for file in ["thermal.nc", "modes.nc", "thermal.json", "thermal.svg"] {
        assert!(dir.join(file).exists(), "{file}");
    }
    // in °C: warned, on stderr
    let o = afmdyn(&[
        "thermal",
        "--probe",
        PROBE,
        "--temperature",
        "22",
        "--points",
        "4",
        "--out",
        &out,
    ]);
    assert!(o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("written in °C?"));
}

#[test]
fn bad_options_are_refused_naming_them() {
    let dir = std::env::temp_dir().join(format!("afmdyn-thermal-bad-{}", std::process::id()));
    let out = dir.display().to_string();
    for (args, word) in [
        (vec!["thermal", "--out", &out], "probe"),
        (
            vec!["thermal", "--probe", PROBE, "--spot", "1.5", "--out", &out],
            "spot",
        ),
        (
            vec![
                "thermal",
                "--probe",
                PROBE,
                "--temperature",
                "0",
                "--out",
                &out,
            ],
            "temperature",
        ),
        (
            vec!["thermal", "--probe", PROBE, "--points", "0", "--out", &out],
            "points",
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

//! Issue 60, part A: answers that were wrong without a word, each now refused, reduced or
//! warned about on the command line (stderr as well as the JSON document).

use std::path::PathBuf;

use crate::common;
use common::{json, refused, run};

/// A probe file written into a fresh temporary directory.
fn probe_file(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("afmdyn-silent-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// A fresh output directory for one test's command.
fn out_dir(name: &str) -> String {
    let dir = std::env::temp_dir().join(format!("afmdyn-silent-{}-out-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir.to_str().unwrap().to_string()
}

/// A point-mass lever (40 N/m, 300 kHz, Q 400, A₀ 10 nm) over the JKR sample of the issue (R
/// 10 nm, E 100 MPa, W 0.05 J/m²).
const JKR: &str = r#"
model = "point-mass"
[cantilever]
spring_constant = 40.0
resonance_frequency = 300e3
quality_factor = 400
[tip]
radius = 10e-9
youngs_modulus = 130e9
poisson_ratio = 0.27
[sample]
law = "jkr"
youngs_modulus = 100e6
poisson_ratio = 0.4
adhesion_energy = 0.05
z_c = 5e-9
[drive]
free_amplitude = 10e-9
"#;

/// Item 1: `--modes N` means one thing on every model. On a lumped probe it must equal the
/// probe's modes (the eigenmode model's arrays, the point mass's one): a larger N padded the
/// eigenmode model with copies of mode 1 (300 kHz listed twice). The probe's own modes stay
/// those of its file: 300 kHz and 1.88 MHz (examples/probe-eigenmodes-dmt.toml).
#[test]
fn modes_on_a_lumped_probe_are_the_probes() {
    let probe = "examples/probe-eigenmodes-dmt.toml";
    refused(
        &["modes", "--probe", probe, "--modes", "3", "--json"],
        &["modes = 3", "eigenmodes model has 2 mode(s)"],
    );
    refused(
        &["orbit", "--probe", probe, "--modes", "3", "--json"],
        &["modes = 3"],
    );
    refused(
        &[
            "modes",
            "--probe",
            "examples/probe-point-mass-dmt.toml",
            "--modes",
            "2",
        ],
        &["modes = 2", "point-mass model has 1 mode(s)"],
    );
    let same = json(&["modes", "--probe", probe, "--modes", "2", "--json"]);
    let plain = json(&["modes", "--probe", probe, "--json"]);
    assert_eq!(same, plain);
    let f = same["si"]["free_frequencies_hz"].as_array().unwrap();
    assert_eq!(f.len(), 2, "{f:?}");
    for (got, want) in f.iter().zip([300e3, 1.88e6]) {
        let got = got.as_f64().unwrap();
        assert!((got - want).abs() <= 1e-9 * want, "{got} against {want}");
    }
}

/// Item 4: the reported period is the minimal one. A period-1 orbit is a fixed point of P¹³
/// too: shot as period 13 it was labelled "period 13" with the multipliers of P¹³ (μ¹³). It is
/// now the period-1 orbit itself: the same state and multipliers as the orbit shot at
/// period 1. A true period-2 orbit of the paper's model (Ω = 2.8) stays period 2: its two
/// section points differ.
#[test]
fn an_orbit_reports_its_minimal_period() {
    let probe = probe_file("jkr", JKR);
    let p = probe.to_str().unwrap();
    let shot = |n: &str| json(&["orbit", "--probe", p, "--period", n, "--json"]);
    let (one, thirteen) = (shot("1"), shot("13"));
    assert_eq!(one["period"], 1);
    assert_eq!(thirteen["period"], 1, "{}", thirteen["period"]);
    let state = |d: &serde_json::Value| -> Vec<f64> {
        d["state"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    for (a, b) in state(&one).iter().zip(state(&thirteen)) {
        assert!((a - b).abs() <= 1e-8 * (1.0 + a.abs()), "{a} against {b}");
    }
    let modulus = |d: &serde_json::Value| {
        let m = &d["multipliers"][0];
        m[0].as_f64().unwrap().hypot(m[1].as_f64().unwrap())
    };
    let (m1, m13) = (modulus(&one), modulus(&thirteen));
    assert!((m1 - m13).abs() <= 1e-8, "{m1} against {m13}");
    assert!(m1 < 1.0);

    let two = json(&["orbit", "--omega", "2.8", "--period", "2", "--json"]);
    assert_eq!(two["period"], 2);
    let v_t = common::column(&two, "poincare", "v_t");
    assert_eq!(v_t.len(), 2);
    assert!((v_t[0] - v_t[1]).abs() > 1e-3, "period-2 points {v_t:?}");
}

/// Item 3: two drive components at one frequency are one lock-in channel; each was reported
/// with their total amplitude. They are refused, naming the component.
#[test]
fn two_components_at_one_frequency_are_refused() {
    let text = std::fs::read_to_string(common::repo().join("examples/probe-bimodal.toml"))
        .unwrap()
        .replace(
            "\nfrequency = [300e3, 1.875e6]",
            "\nfrequency = [300e3, 300e3]",
        );
    assert!(text.contains("\nfrequency = [300e3, 300e3]"));
    let probe = probe_file("same-frequency", &text);
    refused(
        &["bimodal", "--probe", probe.to_str().unwrap(), "--json"],
        &["[drive].frequency[1] = 300000 Hz", "one frequency"],
    );
}

/// Item 2: unit slips in a probe file. Beyond any liquid's surface tension (mercury's
/// 0.485 N/m) or any solid's work of adhesion, a value is refused with the unit it was likely
/// meant in; inside the physical range but outside the typical one it runs with a warning on
/// stderr and in the document.
#[test]
fn unit_slips_in_a_probe_are_refused_or_warned() {
    let capillary =
        std::fs::read_to_string(common::repo().join("examples/probe-capillary-humid.toml"))
            .unwrap();
    let with_gamma = |g: &str| {
        let t = capillary.replace("surface_tension = 0.072", &format!("surface_tension = {g}"));
        assert!(t.contains(&format!("surface_tension = {g}")));
        t
    };
    let slip = probe_file("gamma72", &with_gamma("72.0"));
    refused(
        &["orbit", "--probe", slip.to_str().unwrap(), "--json"],
        &["[sample].surface_tension = 72", "mN/m"],
    );
    let odd = probe_file("gamma08", &with_gamma("0.8"));
    let out = run(&[
        "approach",
        "--probe",
        odd.to_str().unwrap(),
        "--json",
        "--out",
        &out_dir("gamma"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(
            "afmdyn: warning: [sample].surface_tension = 0.8 (N/m) is outside the typical"
        ),
        "{err}"
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(doc["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .any(|w| w.as_str().unwrap().contains("surface_tension = 0.8")));

    let w50 = probe_file(
        "w50",
        &JKR.replace("adhesion_energy = 0.05", "adhesion_energy = 50.0"),
    );
    refused(
        &["orbit", "--probe", w50.to_str().unwrap()],
        &["[sample].adhesion_energy = 50", "mJ/m²"],
    );
    // the examples hold no value outside its typical range
    for p in [
        "examples/probe-capillary-humid.toml",
        "examples/probe-jkr-polymer.toml",
        "examples/probe-point-mass-dmt.toml",
        "examples/probe-bimodal.toml",
    ] {
        let probe = afmdyn::probe::Probe::load(&common::repo().join(p)).unwrap();
        assert!(
            probe.input_warnings.is_empty(),
            "{p}: {:?}",
            probe.input_warnings
        );
    }
}

/// Item 5: a Hertz contact indented beyond half the tip radius (20 nm into a 1 MPa sample
/// under an 8 nm tip) is outside the paraboloid's validity and says so, on stderr and in the
/// document; the stiff polystyrene of the examples (indentations below 1 nm) does not.
#[test]
fn an_indentation_beyond_the_tip_radius_warns() {
    let soft = probe_file(
        "hertz-soft",
        r#"
model = "point-mass"
[cantilever]
spring_constant = 40.0
resonance_frequency = 300e3
quality_factor = 400
[tip]
radius = 8e-9
[sample]
law = "hertz"
youngs_modulus = 1e6
poisson_ratio = 0.5
[drive]
free_amplitude = 20e-9
"#,
    );
    let args = |p: &str, out: &str| {
        run(&[
            "approach",
            "--probe",
            p,
            "--from",
            "20nm",
            "--to",
            "0nm",
            "--step",
            "2nm",
            "--json",
            "--out",
            &out_dir(out),
        ])
    };
    let out = args(soft.to_str().unwrap(), "soft");
    assert!(out.status.success());
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let deepest = common::column(&doc, "approach", "indentation")
        .into_iter()
        .fold(0.0, f64::max);
    assert!(deepest > 4e-9, "{deepest}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("afmdyn: warning: the largest indentation")
            && err.contains("exceeds half the tip radius R = 8e-9 m"),
        "{err}"
    );
    // the advice holds for AM's amplitude ratio and for PeakForce's force (issue 77: it said
    // "a larger setpoint", wrong for a peak-force setpoint)
    assert!(
        err.contains("a larger AM setpoint A/A₀, a smaller peak-force setpoint"),
        "{err}"
    );
    let stiff = args("examples/probe-point-mass-dmt.toml", "stiff");
    assert!(stiff.status.success());
    let err = String::from_utf8_lossy(&stiff.stderr);
    assert!(!err.contains("tip radius"), "{err}");
}

/// Item 5: an FM range given near-to-far runs from the far end, and says so.
#[test]
fn a_reversed_fm_range_says_how_it_runs() {
    let out = run(&[
        "fm",
        "--probe",
        "examples/probe-point-mass-dmt.toml",
        "--from",
        "5nm",
        "--to",
        "12nm",
        "--step",
        "1nm",
        "--json",
        "--out",
        &out_dir("fm"),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("afmdyn: warning: from = 5e-9 m is nearer the sample than to = 1.2e-8 m"),
        "{err}"
    );
}

/// Item 5: a probe's own warnings (here a DMT sample in JKR's regime: 50 MPa with a Hamaker
/// constant of 6.6e-20 J under a 10 nm tip has a Tabor parameter of ≈ 14, above 5; Johnson &
/// Greenwood 1997) reach the command line's stderr with `--json` too, as they reach the
/// document.
#[test]
fn a_probes_warnings_reach_stderr() {
    let text = std::fs::read_to_string(common::repo().join("examples/probe-bimodal.toml"))
        .unwrap()
        .replace("youngs_modulus = 4e9", "youngs_modulus = 50e6");
    assert!(text.contains("youngs_modulus = 50e6"));
    let probe = probe_file("tabor", &text);
    let out = run(&[
        "bimodal",
        "--probe",
        probe.to_str().unwrap(),
        "--from",
        "12nm",
        "--to",
        "10nm",
        "--step",
        "1nm",
        "--json",
        "--out",
        &out_dir("tabor"),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let tabor = |w: &str| w.contains("Tabor parameter");
    assert!(doc["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .any(|w| tabor(w.as_str().unwrap())));
    assert!(
        err.lines()
            .any(|l| l.starts_with("afmdyn: warning: ") && tabor(l)),
        "{err}"
    );
}

/// The probe's own warnings reach an AM image as they reach `approach` and a PeakForce image
/// (issue 77: the AM image lacked them): the point-mass example on a 50 MPa DMT sample
/// (Hamaker 6.6e-20 J, R = 10 nm: a Tabor parameter of ≈ 14, in JKR's regime), named by its
/// material, in the document and on stderr.
#[test]
fn an_am_image_carries_the_probes_warnings() {
    let text = std::fs::read_to_string(common::repo().join("examples/probe-point-mass-dmt.toml"))
        .unwrap()
        .replace("youngs_modulus = 4e9", "youngs_modulus = 50e6");
    assert!(text.contains("youngs_modulus = 50e6"));
    let probe = probe_file("am-image-tabor", &text);
    let sample = common::flat_sample(probe.parent().unwrap());
    let out = run(&[
        "image",
        "--probe",
        probe.to_str().unwrap(),
        "--sample",
        sample.to_str().unwrap(),
        "--setpoint",
        "0.7",
        "--pixels",
        "2",
        "--curve-points",
        "40",
        "--json",
        "--files",
        "none",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let tabor = |w: &str| w.starts_with("background: ") && w.contains("Tabor parameter");
    assert!(
        doc["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| tabor(w.as_str().unwrap())),
        "{doc}"
    );
    assert!(err.contains("Tabor parameter"), "{err}");
}

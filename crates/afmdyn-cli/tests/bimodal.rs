//! `afmdyn bimodal` end to end on examples/probe-bimodal.toml (the eigenmode model, two
//! components each at its mode's resonance, f₂/f₁ = 25/4): far from the sample each
//! component's amplitude is its free amplitude (the probe's 10 nm and 1 nm, to 1e-4 at
//! 1.2 × their sum), near it both fall; the CSV carries the per-component columns in the
//! document's names; a single-frequency probe and a bad `[drive]` array exit 2 with one line,
//! as do `resonance` and `fm`, which move the drive frequency, on a multifrequency probe.

mod common;
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
            "frequency = [300e3, 1876058.4]",
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

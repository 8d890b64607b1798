//! `afmdyn image` end to end: the 2D blend example (`examples/sample-blend.toml` over
//! `examples/probe-point-mass-dmt.toml`) writes its document and maps, with the terrace 5 nm
//! up at its true height and the rubber domain at its own operating point; bad input exits 2
//! with one line naming the field; `--feedback pi` writes the library's scan document and its
//! maps.

use std::process::{Command, Output};

fn afmdyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_afmdyn"))
        .args(args)
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .output()
        .expect("run afmdyn")
}

#[test]
fn the_blend_example_images_at_a_setpoint() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    let out = afmdyn(&[
        "image",
        "--probe",
        "examples/probe-point-mass-dmt.toml",
        "--sample",
        "examples/sample-blend.toml",
        "--setpoint",
        "0.7",
        "--pixels",
        "16",
        "--json",
        "--out",
        d,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let img = &doc["image"];
    assert_eq!(img["height"].as_array().unwrap().len(), 16);
    for j in 0..16 {
        for i in 0..16 {
            let h = img["height"][j][i].as_f64().unwrap();
            match img["domain"][j][i].as_str().unwrap() {
                "terrace" => assert!((h - 5e-9).abs() < 1e-18, "{h}"),
                "background" => assert_eq!(h, 0.0),
                "rubber" => {
                    let z = img["z_c"][j][i].as_f64().unwrap();
                    let r = doc["reference_z_c"].as_f64().unwrap();
                    assert!((h - (z - r)).abs() < 1e-18);
                }
                other => panic!("{other}"),
            }
        }
    }
    for f in [
        "image.json",
        "image-height.png",
        "image-phase.png",
        "image-dissipation.png",
        "image-profile.png",
    ] {
        assert!(dir.path().join(f).exists(), "{f}");
    }
}

#[test]
fn bad_input_exits_2_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    let bad_map = dir.path().join("bad.toml");
    std::fs::write(
        &bad_map,
        "size = [1e-6, 0]\n[[domain]]\nname = \"d\"\nx = [5e-7, 1e-7]\n",
    )
    .unwrap();
    for (extra, want) in [
        (vec!["--setpoint", "1.5"], "setpoint"),
        (vec!["--setpoint", "0.7", "--feedback", "pid"], "feedback"),
        (vec!["--setpoint", "0.7", "--scan-rate", "2"], "--scan-rate"),
        (
            vec!["--setpoint", "0.7", "--feedback", "pi", "--gains", "-1,10"],
            "gains",
        ),
        (
            vec!["--setpoint", "0.7", "--feedback", "pi", "--gains", "1"],
            "--gains",
        ),
        (
            vec![
                "--setpoint",
                "0.7",
                "--feedback",
                "pi",
                "--scan-rate",
                "1e9",
            ],
            "scan",
        ),
        (vec!["--setpoint", "0.7", "--lines", "4"], "lines"),
    ] {
        let mut args = vec![
            "image",
            "--probe",
            "examples/probe-point-mass-dmt.toml",
            "--sample",
            "examples/sample-stripe.toml",
            "--out",
            d,
        ];
        args.extend(extra);
        let out = afmdyn(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(
            err.contains(want) && err.trim().lines().count() == 1,
            "{err}"
        );
    }
    let out = afmdyn(&[
        "image",
        "--probe",
        "examples/probe-point-mass-dmt.toml",
        "--sample",
        bad_map.to_str().unwrap(),
        "--setpoint",
        "0.7",
        "--out",
        d,
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("domain 'd' x"), "{err}");
}

/// `--feedback pi --json` prints the library's document of the same scan (lines on 2 threads
/// here, 1 in the library) and writes the maps of the recorded height, the error image, the
/// phase and E_dis, and the profile.
#[test]
fn the_pi_scan_writes_the_libraries_document_and_maps() {
    use afmdyn::analysis::progress::Progress;
    use afmdyn::request::image::{ImageRequest, SampleMap};
    use afmdyn::request::image_scan::{pi_image, PiScan};
    let dir = tempfile::tempdir().unwrap();
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../");
    let text = std::fs::read_to_string(format!("{root}examples/probe-point-mass-dmt.toml"))
        .unwrap()
        .replace("quality_factor = 400", "quality_factor = 100");
    let probe = dir.path().join("probe.toml");
    std::fs::write(&probe, &text).unwrap();
    let out = afmdyn(&[
        "image",
        "--probe",
        probe.to_str().unwrap(),
        "--sample",
        "examples/sample-stripe.toml",
        "--setpoint",
        "0.5",
        "--feedback",
        "pi",
        "--pixels",
        "8",
        "--scan-rate",
        "40",
        "--gains",
        "0.1,2000",
        "--time-constant",
        "20e-6",
        "--threads",
        "2",
        "--json",
        "--out",
        dir.path().join("out").to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let table: toml::Table = text.parse().unwrap();
    let map = SampleMap::load(std::path::Path::new(&format!(
        "{root}examples/sample-stripe.toml"
    )))
    .unwrap();
    let req = ImageRequest {
        pixels: 8,
        ..ImageRequest::at(0.5)
    };
    let scan = PiScan {
        scan_rate: Some(40.0),
        gains: Some((0.1, 2000.0)),
        time_constant: Some(20e-6),
    };
    let lib = pi_image(&table, &map, &req, &scan, Some(1), &Progress::new())
        .unwrap()
        .document(0.5);
    assert_eq!(doc, lib);
    assert_eq!(doc["feedback"], "pi");
    assert_eq!(doc["scan"]["proportional_gain"], 0.1);
    for f in [
        "image.json",
        "image-height.png",
        "image-error.png",
        "image-phase.png",
        "image-dissipation.png",
        "image-profile.png",
    ] {
        assert!(dir.path().join("out").join(f).exists(), "{f}");
    }
}

//! `afmdyn image` end to end: the 2D blend example (`examples/sample-blend.toml` over
//! `examples/probe-point-mass-dmt.toml`) writes its document and maps, with the terrace 5 nm
//! up at its true height and the rubber domain at its own operating point; bad input exits 2
//! with one line naming the field.

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
        (vec!["--setpoint", "0.7", "--feedback", "pi"], "feedback"),
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

//! `afmdyn reconstruct` end to end: the example curve (`examples/fm-vdw.csv`: the frequency
//! shift of a van der Waals force by Giessibl's relation, computed in plain Python by
//! `scripts/fm-example.py`) is inverted back to −HR/(6d²) within 1 % where A ≥ 2d (the
//! Sader–Jarvis formula's large-amplitude limit, on the example's grid of 400 values); bad
//! input exits 2 with one line.

use std::process::{Command, Output};

fn afmdyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_afmdyn"))
        .args(args)
        .output()
        .expect("run afmdyn")
}

const FM: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/fm-vdw.csv");

#[test]
fn the_example_curve_gives_back_the_van_der_waals_force() {
    let dir = tempfile::tempdir().unwrap();
    let out = afmdyn(&[
        "reconstruct",
        "--fm",
        FM,
        "--spring-constant",
        "40",
        "--resonance-frequency",
        "300kHz",
        "--amplitude",
        "10nm",
        "--json",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let f = &doc["force"];
    let col = |k: &str| -> Vec<f64> {
        f[k].as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    let (d, force) = (col("distance"), col("force"));
    assert_eq!(d.len(), 400);
    let hr = 1e-19 * 1e-8;
    let mut checked = 0;
    for (d, f) in d.iter().zip(&force).filter(|(d, _)| **d <= 5e-9) {
        let want = -hr / (6.0 * d * d);
        assert!((f / want - 1.0).abs() < 0.01, "d = {d}: {f} vs {want}");
        checked += 1;
    }
    assert!(checked > 150, "{checked}");
    assert_eq!(doc["units"]["force"], "N");
    for file in [
        "reconstruct.csv",
        "reconstruct.json",
        "reconstruct-force.png",
    ] {
        assert!(
            dir.path().join(file).metadata().unwrap().len() > 0,
            "{file}"
        );
    }
}

#[test]
fn bad_curves_exit_2_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("c.csv");
    let out = dir.path().join("o");
    let run = |text: &str, extra: &[&str]| {
        std::fs::write(&csv, text).unwrap();
        let mut args = vec![
            "reconstruct",
            "--fm",
            csv.to_str().unwrap(),
            "--resonance-frequency",
            "300kHz",
            "--amplitude",
            "10nm",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        afmdyn(&args)
    };
    let good = "distance,frequency_shift\n1e-9,-3\n2e-9,-2\n3e-9,-1\n";
    for (text, extra, needle) in [
        (
            good,
            &["--spring-constant", "-1"][..],
            "spring-constant = -1",
        ),
        (
            "z,frequency_shift\n1,2\n2,3\n3,4\n",
            &["--spring-constant", "1"][..],
            "distance",
        ),
        (
            "distance,df\n1,2\n",
            &["--spring-constant", "1"][..],
            "no frequency_shift column",
        ),
        (
            "distance,frequency_shift\n1e-9,-3\n3e-9,-2\n2e-9,-1\n",
            &["--spring-constant", "1"][..],
            "must increase",
        ),
        (
            "distance,frequency_shift\n1e-9,x\n",
            &["--spring-constant", "1"][..],
            "line 2",
        ),
        (
            good,
            &["--spring-constant", "1", "--amplitude", "3kHz"][..],
            "--amplitude",
        ),
    ] {
        let o = run(text, extra);
        assert_eq!(o.status.code(), Some(2), "{text} {extra:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains(needle), "{needle}: {err}");
    }
}

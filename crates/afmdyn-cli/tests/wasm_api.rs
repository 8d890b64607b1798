//! The browser's front end (`crates/afmdyn-wasm`, issue 47) is a name mapping over the same
//! requests: its documents equal the command line's `--json` documents for the same model and
//! options (the paper's defaults, keywords spelled as the request types name them, a probe
//! file's text), and its errors are the command line's one-line messages.

use afmdyn_wasm::run_json;
use serde_json::{json, Value};
use std::process::Command;

fn cli(args: &[&str]) -> (Option<i32>, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_afmdyn"))
        .args(args)
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .output()
        .expect("run afmdyn");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn cli_json(args: &[&str]) -> Value {
    let (code, out, err) = cli(args);
    assert_eq!(code, Some(0), "{err}");
    serde_json::from_str(&out).unwrap()
}

fn wasm(analysis: &str, input: Value) -> Value {
    serde_json::from_str(&run_json(analysis, &input.to_string()).unwrap()).unwrap()
}

/// `modes` and `orbit` on the paper's model (Ω = 2.8, the Fig. 5 range), and `orbit` of the
/// Hertz law at another Ω, keywords as the requests name them.
#[test]
fn orbit_and_modes_are_the_command_lines_documents() {
    assert_eq!(wasm("modes", json!({})), cli_json(&["modes", "--json"]));
    assert_eq!(
        wasm("orbit", json!({"model": {"omega": 2.8}})),
        cli_json(&["orbit", "--omega", "2.8", "--json"])
    );
    assert_eq!(
        wasm(
            "orbit",
            json!({"model": {"omega": 2.6, "contact_law": "hertz"}, "request": {"period": 1}})
        ),
        cli_json(&[
            "orbit",
            "--omega",
            "2.6",
            "--contact-law",
            "hertz",
            "--period",
            "1",
            "--json"
        ])
    );
}

/// An approach curve from a probe file (SI), with a setpoint, as `afmdyn approach --probe`.
#[test]
fn an_approach_curve_from_a_probe_is_the_command_lines() {
    let path = "examples/probe-point-mass-dmt.toml";
    let text =
        std::fs::read_to_string(format!("{}/../../{path}", env!("CARGO_MANIFEST_DIR"))).unwrap();
    assert_eq!(
        wasm(
            "approach",
            json!({"probe": text, "request": {"points": 40, "setpoint": 0.7}})
        ),
        cli_json(&[
            "approach",
            "--probe",
            path,
            "--points",
            "40",
            "--setpoint",
            "0.7",
            "--json"
        ])
    );
}

/// Bad input: the command line's message (after its `afmdyn: ` prefix) for a model value out
/// of range; an unknown key and an unknown analysis are named.
#[test]
fn errors_are_the_command_lines_messages() {
    let e = run_json("orbit", &json!({"model": {"omega": -1.0}}).to_string()).unwrap_err();
    let (code, _, err) = cli(&["orbit", "--omega=-1", "--json"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("omega") && e.contains("omega"), "{e} | {err}");
    let e = run_json("orbit", &json!({"model": {"omegaa": 1.0}}).to_string()).unwrap_err();
    assert!(e.contains("omegaa"), "{e}");
    let e = run_json("orbitt", "{}").unwrap_err();
    assert!(e.contains("orbitt") && e.contains("modes"), "{e}");
}

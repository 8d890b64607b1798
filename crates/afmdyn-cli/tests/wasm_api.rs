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

/// The bifurcation diagram in chunks of 5 points (a page drawing as they come) is the command
/// line's uninterrupted sweep: every row of `bifurcation.csv` (value, branch, status, period,
/// W(1,τ) at each Poincaré point) in the same order, the chains continued across the chunks.
#[test]
fn a_bifurcation_in_chunks_is_the_command_lines_sweep() {
    use afmdyn_wasm::bifurcation::BifurcationSession;
    let dir = tempfile::tempdir().unwrap();
    let (code, _, err) = cli(&[
        "bifurcation",
        "--from",
        "2.4",
        "--to",
        "3.2",
        "--steps",
        "12",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{err}");
    let input = json!({"request": {"from": 2.4, "to": 3.2, "steps": 12}}).to_string();
    let mut s = BifurcationSession::new(&input).unwrap();
    assert_eq!(s.total(), 24);
    let mut rows: Vec<Value> = Vec::new();
    let mut chunks = 0;
    while !s.finished() {
        let chunk: Vec<Value> = serde_json::from_str(&s.next(5).unwrap()).unwrap();
        rows.extend(chunk);
        chunks += 1;
        assert!(chunks <= 24, "the sweep ends");
    }
    assert!(chunks >= 5, "{chunks} chunks");
    // the one order of the file: by value index, then forward, backward
    rows.sort_by_key(|r| {
        (
            r["index"].as_u64().unwrap(),
            r["branch"].as_str().unwrap() != "forward",
            r["point"].as_u64().unwrap(),
        )
    });
    let mut csv = csv::Reader::from_path(dir.path().join("bifurcation.csv")).unwrap();
    let header = csv.headers().unwrap().clone();
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let records: Vec<csv::StringRecord> = csv.records().map(|r| r.unwrap()).collect();
    assert_eq!(records.len(), rows.len());
    for (r, w) in records.iter().zip(&rows) {
        assert_eq!(&r[col("branch")], w["branch"].as_str().unwrap());
        assert_eq!(&r[col("status")], w["status"].as_str().unwrap());
        let num = |name: &str| r[col(name)].parse::<f64>().unwrap();
        assert_eq!(num("value"), w["value"].as_f64().unwrap());
        assert_eq!(num("w_tip"), w["w_tip"].as_f64().unwrap(), "{r:?}");
        assert_eq!(num("tau"), w["tau"].as_f64().unwrap());
    }
}

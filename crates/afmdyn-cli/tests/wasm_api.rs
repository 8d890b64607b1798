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
    // its own output directory: the command line locks it, and other tests run beside this one
    let out = tempfile::tempdir().unwrap();
    let out = out.path().to_str().unwrap();
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
            "--out",
            out,
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
    // the columns the page writes its CSV with: the file's header, in its order, and the keys
    // of every row
    let columns: Vec<String> = afmdyn_wasm::bifurcation::columns()
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(columns, header.iter().collect::<Vec<_>>());
    let mut sorted = columns.clone();
    sorted.sort();
    for w in &rows {
        let mut keys: Vec<&String> = w.as_object().unwrap().keys().collect();
        keys.sort();
        assert_eq!(keys, sorted.iter().collect::<Vec<_>>());
    }
    for (r, w) in records.iter().zip(&rows) {
        assert_eq!(&r[col("branch")], w["branch"].as_str().unwrap());
        assert_eq!(&r[col("status")], w["status"].as_str().unwrap());
        let num = |name: &str| r[col(name)].parse::<f64>().unwrap();
        assert_eq!(num("value"), w["value"].as_f64().unwrap());
        assert_eq!(num("w_tip"), w["w_tip"].as_f64().unwrap(), "{r:?}");
        assert_eq!(num("tau"), w["tau"].as_f64().unwrap());
    }
}

/// The repository's file `path` as text (a probe or sample map the page would send).
fn example(path: &str) -> String {
    std::fs::read_to_string(format!("{}/../../{path}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

/// `simulate` of `input` (its request `{"periods", "samples_per_period", …}`) and
/// `afmdyn simulate ARGS --files data --json` (the same run): the wasm output, after checking
/// that its summary is the command line's (but for `"files": "none"`, nothing being written),
/// and the shape and rows of the command line's `timeseries.npy` (columns t/τ, V_T, W, Ẇ,
/// contact, force, a, ȧ).
fn simulated(input: Value, args: &[&str]) -> (Value, Vec<u64>, Vec<f64>) {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().to_str().unwrap();
    let mut cli_args = vec!["simulate"];
    cli_args.extend(args);
    cli_args.extend(["--files", "data", "--out", out_dir, "--json"]);
    let mut cli_doc = cli_json(&cli_args);
    let out = wasm("simulate", input);
    assert_eq!(out["summary"]["files"], "none");
    cli_doc["files"] = json!("none");
    assert_eq!(out["summary"], cli_doc);
    let bytes = std::fs::read(dir.path().join("timeseries.npy")).unwrap();
    let npy = npyz::NpyFile::new(&bytes[..]).unwrap();
    let shape = npy.shape().to_vec();
    (out, shape, npy.into_vec().unwrap())
}

/// The numbers of a series variable (null as NaN).
fn values(series: &Value, name: &str) -> Vec<f64> {
    series[name]["values"]
        .as_array()
        .unwrap_or_else(|| panic!("{name}"))
        .iter()
        .map(|v| match v {
            Value::Bool(b) => f64::from(u8::from(*b)),
            v => v.as_f64().unwrap_or(f64::NAN),
        })
        .collect()
}

/// `simulate` from the period-2 orbit's state at Ω = 2.8 (the page's phase portrait of a
/// clicked orbit): its summary is `afmdyn simulate --json`'s with the same periods, samples and
/// initial state, and its series are the numbers of the command line's `timeseries.npy`
/// exactly, periods × samples_per_period + 1 of them, starting at the given state.
#[test]
fn simulate_is_the_command_lines_run_and_time_series() {
    let orbit = wasm("orbit", json!({"model": {"omega": 2.8}}));
    let z: Vec<f64> = serde_json::from_value(orbit["state"].clone()).unwrap();
    let n = z.len() / 2;
    let initial = afmdyn::report::initial_modal(Some(&nalgebra::DVector::from_vec(z.clone())));
    let (out, shape, rows) = simulated(
        json!({"model": {"omega": 2.8},
               "request": {"initial": z, "periods": 4, "samples_per_period": 50}}),
        &[
            "--omega",
            "2.8",
            "--periods",
            "4",
            "--samples-per-period",
            "50",
            &format!("--initial-modal={initial}"),
        ],
    );
    let series = &out["series"];
    assert_eq!(series["tau"]["dims"], json!(["tau"]));
    assert_eq!(series["a"]["dims"], json!(["tau", "mode"]));
    assert_eq!(series["a"]["shape"], json!([201, n]));
    assert_eq!(shape, [4 * 50 + 1, 6 + 2 * n as u64]);
    let width = shape[1] as usize;
    let column = |k: usize| -> Vec<f64> { rows.chunks(width).map(|r| r[k]).collect() };
    for (k, name) in [
        "tau",
        "v_t",
        "w_tip",
        "w_tip_dot",
        "in_contact",
        "contact_force",
    ]
    .iter()
    .enumerate()
    {
        assert_eq!(values(series, name), column(k), "{name}");
    }
    let (a, a_dot) = (values(series, "a"), values(series, "a_dot"));
    for j in 0..n {
        let of = |v: &[f64]| v.chunks(n).map(|r| r[j]).collect::<Vec<_>>();
        assert_eq!(of(&a), column(6 + j), "a_{}", j + 1);
        assert_eq!(of(&a_dot), column(6 + n + j), "a_dot_{}", j + 1);
    }
    // the first sample is the given state, at τ = 0
    assert_eq!(values(series, "tau")[0], 0.0);
    assert_eq!(&a[..n], &z[..n]);
    assert_eq!(&a_dot[..n], &z[n..]);
    assert_eq!(values(series, "v_t_dot").len(), 201);
    assert!(series["contact_force"]["attrs"]["sign_convention"].is_string());
}

/// `simulate` from a probe file is in SI, as `afmdyn simulate --probe`: the time is `t` (s),
/// lengths in m, the summary with its `si` block.
#[test]
fn simulate_from_a_probe_is_in_si_as_the_command_line() {
    let path = "examples/probe-point-mass-dmt.toml";
    let (out, shape, rows) = simulated(
        json!({"probe": example(path), "request": {"periods": 3, "samples_per_period": 40}}),
        &[
            "--probe",
            path,
            "--periods",
            "3",
            "--samples-per-period",
            "40",
        ],
    );
    let series = &out["series"];
    assert!(out["summary"]["si"].is_object());
    assert!(series.get("tau").is_none());
    assert_eq!(series["t"]["units"], "s");
    assert_eq!(series["w_tip"]["units"], "m");
    let width = shape[1] as usize;
    for (k, name) in ["t", "v_t", "w_tip", "w_tip_dot"].iter().enumerate() {
        let col: Vec<f64> = rows.chunks(width).map(|r| r[k]).collect();
        assert_eq!(values(series, name), col, "{name}");
    }
}

/// The cantilever library is `afmdyn cantilevers --json`.
#[test]
fn cantilevers_are_the_command_lines() {
    let doc: Value = serde_json::from_str(&afmdyn_wasm::cantilevers()).unwrap();
    assert_eq!(doc, cli_json(&["cantilevers", "--json"]));
}

/// The bimodal approach curve from examples/probe-bimodal.toml is `afmdyn bimodal --json`'s;
/// a single-frequency drive is refused as there.
#[test]
fn bimodal_is_the_command_lines_curve() {
    let path = "examples/probe-bimodal.toml";
    assert_eq!(
        wasm(
            "bimodal",
            json!({"probe": example(path), "request": {"points": 12, "branches": false}})
        ),
        cli_json(&[
            "bimodal",
            "--probe",
            path,
            "--points",
            "12",
            "--no-branches",
            "--files",
            "none",
            "--json"
        ])
    );
    let probe = example("examples/probe-point-mass-dmt.toml");
    let e = run_json("bimodal", &json!({"probe": probe}).to_string()).unwrap_err();
    assert!(e.contains("free_amplitude"), "{e}");
}

/// The ideal-feedback image of the stripe sample is `afmdyn image --json`'s, with its setpoint
/// study; the PI feedback, missing inputs and model keys are refused.
#[test]
fn image_is_the_command_lines_document() {
    let dir = tempfile::tempdir().unwrap();
    let (probe, sample) = (
        "examples/probe-point-mass-dmt.toml",
        "examples/sample-stripe.toml",
    );
    let input = |request: Value| json!({"probe": example(probe), "sample": example(sample), "request": request});
    // the browser's document holds every pixel (the explorer draws them); the command line's
    // their summary (the maps are image.nc's): the same image, materials and study
    let web = wasm(
        "image",
        input(json!({"setpoint": 0.7, "pixels": 16, "setpoint_study": "0.3:0.9:4"})),
    );
    let cli = cli_json(&[
        "image",
        "--probe",
        probe,
        "--sample",
        sample,
        "--setpoint",
        "0.7",
        "--pixels",
        "16",
        "--setpoint-study",
        "0.3:0.9:4",
        "--out",
        dir.path().to_str().unwrap(),
        "--json",
    ]);
    for key in [
        "feedback",
        "setpoint",
        "reference_z_c",
        "materials",
        "warnings",
        "setpoint_study",
    ] {
        assert_eq!(web[key], cli[key], "{key}");
    }
    for name in ["height", "z_c", "phase_deg", "true_height"] {
        let values: Vec<f64> = web["image"][name]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|row| row.as_array().unwrap().iter().filter_map(Value::as_f64))
            .collect();
        let m = &cli["image"]["maps"][name];
        assert_eq!(m["finite"], values.len(), "{name}");
        let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let min = values.iter().copied().fold(f64::INFINITY, f64::min);
        assert_eq!(m["max"].as_f64(), Some(max), "{name}");
        assert_eq!(m["min"].as_f64(), Some(min), "{name}");
    }
    let refused = |input: Value, words: &[&str]| {
        let e = run_json("image", &input.to_string()).unwrap_err();
        assert!(words.iter().all(|w| e.contains(w)), "{e}");
        assert!(!e.contains('\n'), "{e}");
    };
    refused(
        input(json!({"setpoint": 0.7, "feedback": "pi"})),
        &["feedback", "ideal"],
    );
    refused(input(json!({"pixels": 8})), &["setpoint", "(0, 1)"]);
    refused(input(json!({"setpoint": 1.5})), &["setpoint", "(0, 1)"]);
    refused(input(json!({"setpoint": 0.7, "pixel": 8})), &["pixel"]);
    refused(
        json!({"probe": example(probe), "sample": "size = [1.0e-6, 1.0e-6]",
               "request": {"setpoint": 0.7, "pixels": 600}}),
        &["pixels", "262144"],
    );
    refused(
        json!({"probe": example(probe), "request": {"setpoint": 0.7}}),
        &["sample"],
    );
    refused(
        json!({"model": {"omega": 2.0}, "probe": example(probe), "sample": example(sample),
               "request": {"setpoint": 0.7}}),
        &["model"],
    );
}

/// Refusals: a sample map given to another analysis; a series beyond the browser's samples; a
/// height map file (in wasm, without files: the library's message; natively the file is not
/// there); each one line naming the key.
#[test]
fn refusals_name_the_key() {
    let one_line = |e: String, words: &[&str]| {
        assert!(words.iter().all(|w| e.contains(w)), "{e}");
        assert!(!e.contains('\n'), "{e}");
    };
    let e = run_json("orbit", &json!({"sample": "size = [1e-6, 0]"}).to_string()).unwrap_err();
    one_line(e, &["sample", "image", "orbit"]);
    let e = run_json(
        "simulate",
        &json!({"request": {"periods": 20000, "samples_per_period": 200}}).to_string(),
    )
    .unwrap_err();
    one_line(e, &["periods", "samples_per_period", "2000000"]);
    let e = run_json(
        "simulate",
        &json!({"request": {"samples_per_period": 0}}).to_string(),
    )
    .unwrap_err();
    one_line(e, &["samples_per_period"]);
    let e = run_json(
        "simulate",
        &json!({"request": {"initial": [1.0, 2.0]}}).to_string(),
    )
    .unwrap_err();
    one_line(e, &["initial"]);
    let sample = "size = [1.0e-6, 0.0]\nheight_map = \"no-such-map.csv\"\n";
    let e = run_json(
        "image",
        &json!({"probe": example("examples/probe-point-mass-dmt.toml"), "sample": sample,
                "request": {"setpoint": 0.7}})
        .to_string(),
    )
    .unwrap_err();
    one_line(e, &["height_map", "no-such-map.csv"]);
}

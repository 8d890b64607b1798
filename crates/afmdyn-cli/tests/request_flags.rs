//! The request flags (written by `scripts/gen_cli.py` from the request schemas) held against
//! the library's requests themselves: for every command, each field of its request's
//! `Default` (serialised by serde, not read from the schema) has its flag — kebab-case of the
//! field, `--no-<field>` for a boolean on by default — and the default `--help` shows for it
//! is the request's, value for value.

use crate::common;

use afmdyn::request::image::ImageRequest;
use afmdyn::request::{
    ApproachRequest, AttractorsRequest, BasinsRequest, BifurcationRequest, ChartRequest,
    ContinuationRequest, ConvergeRequest, FitRequest, FmRequest, LyapunovRequest, OrbitRequest,
    PeakForceRequest, ReconstructRequest, ResonanceRequest, SimulateRequest,
};
use serde::Serialize;
use serde_json::Value;

/// Each flag of `afmdyn CMD --help` with its text (the flag's line and its help lines, joined).
fn flags(cmd: &str) -> Vec<(String, String)> {
    let help = common::text(&[cmd, "--help"]);
    let mut out: Vec<(String, String)> = Vec::new();
    for line in help.lines() {
        let indent = line.len() - line.trim_start().len();
        let t = line.trim();
        // an option's line starts with its flag, indented at most 6 (`  -s, --x` or `      --x`)
        let flag = (indent <= 6 && t.starts_with('-'))
            .then(|| t.split([' ', ',']).find(|w| w.starts_with("--")))
            .flatten();
        match flag {
            Some(f) => out.push((f.to_string(), t.to_string())),
            None => {
                if let Some(last) = out.last_mut() {
                    last.1.push(' ');
                    last.1.push_str(t);
                }
            }
        }
    }
    out
}

/// The `[default: …]` of a flag's help text.
fn shown_default(text: &str) -> Option<&str> {
    let at = text.rfind("[default: ")? + "[default: ".len();
    text[at..].split(']').next()
}

/// Every field of `request` (nested requests' fields too, by their own names) has its flag in
/// `afmdyn cmd --help`, showing the request's default; `skip`: fields the command takes in
/// another form (`initial` as `--initial-modal`) or not at all.
fn defaults_shown(cmd: &str, request: impl Serialize, skip: &[&str]) {
    let flags = flags(cmd);
    let find = |flag: &str| {
        flags
            .iter()
            .find(|(f, _)| f == flag)
            .map(|(_, t)| t.as_str())
            .unwrap_or_else(|| panic!("{cmd}: no {flag} in --help"))
    };
    let mut fields: Vec<(String, Value)> = Vec::new();
    let Value::Object(top) = serde_json::to_value(request).unwrap() else {
        panic!("{cmd}: a request serialises to an object")
    };
    for (key, value) in top {
        match value {
            Value::Object(nested) => fields.extend(nested),
            v => fields.push((key, v)),
        }
    }
    let mut checked = 0;
    for (key, value) in fields {
        if skip.contains(&key.as_str()) {
            continue;
        }
        let flag = format!("--{}", key.replace('_', "-"));
        match &value {
            Value::Bool(true) => drop(find(&format!("--no-{}", &flag[2..]))),
            Value::Bool(false) | Value::Null => drop(find(&flag)),
            Value::Number(n) => {
                let text = find(&flag);
                let shown = shown_default(text).unwrap_or_else(|| panic!("{cmd} {flag}: {text}"));
                let v: f64 = shown
                    .parse()
                    .unwrap_or_else(|_| panic!("{cmd} {flag}: default {shown}"));
                assert_eq!(Some(v), n.as_f64(), "{cmd} {flag}: {text}");
            }
            Value::String(s) => {
                let text = find(&flag);
                assert_eq!(
                    shown_default(text),
                    Some(s.as_str()),
                    "{cmd} {flag}: {text}"
                );
            }
            // a list of names (`fit`'s parameters): clap shows the defaults space-separated
            Value::Array(items) if items.iter().all(Value::is_string) => {
                let text = find(&flag);
                let shown = shown_default(text).unwrap_or_else(|| panic!("{cmd} {flag}: {text}"));
                let want: Vec<&str> = items.iter().filter_map(Value::as_str).collect();
                assert_eq!(
                    shown.split(' ').collect::<Vec<_>>(),
                    want,
                    "{cmd} {flag}: {text}"
                );
            }
            Value::Array(_) | Value::Object(_) => panic!("{cmd}: {key} has no flag: skip it"),
        }
        checked += 1;
    }
    assert!(checked > 0, "{cmd}: no field checked");
}

/// `afmdyn cmd --help` has each of `flags` without a default: a value the command requires
/// (`image --setpoint`) or takes from elsewhere when not given (`reconstruct`'s constants,
/// from an fm document), whose request default (0) is no default of the command line's.
fn without_default(cmd: &str, wanted: &[&str]) {
    let flags = flags(cmd);
    for flag in wanted {
        let (_, text) = flags
            .iter()
            .find(|(f, _)| f == flag)
            .unwrap_or_else(|| panic!("{cmd}: no {flag} in --help"));
        assert_eq!(shown_default(text), None, "{cmd} {flag}: {text}");
    }
}

#[test]
fn every_request_field_has_its_flag_and_the_request_default() {
    defaults_shown("approach", ApproachRequest::default(), &[]);
    defaults_shown("bimodal", ApproachRequest::default(), &[]);
    defaults_shown("resonance", ResonanceRequest::default(), &[]);
    defaults_shown("fm", FmRequest::default(), &[]);
    defaults_shown("simulate", SimulateRequest::default(), &["initial"]);
    defaults_shown("converge", ConvergeRequest::default(), &[]);
    defaults_shown("bifurcation", BifurcationRequest::default(), &["values"]);
    defaults_shown("attractors", AttractorsRequest::default(), &[]);
    defaults_shown("basins", BasinsRequest::default(), &[]);
    defaults_shown("chart", ChartRequest::default(), &[]);
    defaults_shown("orbit", OrbitRequest::default(), &["initial"]);
    defaults_shown("continue", ContinuationRequest::default(), &["initial"]);
    defaults_shown("lyapunov", LyapunovRequest::default(), &["initial"]);
    defaults_shown("peakforce", PeakForceRequest::default(), &["fit_band"]);
    // the setpoint is required (the default request's 0.5 only exemplifies it)
    defaults_shown("image", ImageRequest::default(), &["setpoint"]);
    without_default("image", &["--setpoint"]);
    defaults_shown("image", afmdyn::request::image_scan::PiScan::default(), &[]);
    defaults_shown(
        "image",
        afmdyn::request::image_options::ImageOptions::default(),
        &[],
    );
    // the curve's columns come from --fm FILE; k, f0 and A from it too unless given
    let constants = ["spring_constant", "resonance_frequency", "amplitude"];
    let columns = ["distance", "z_c", "frequency_shift"];
    defaults_shown(
        "reconstruct",
        ReconstructRequest::default(),
        &[&columns[..], &constants[..]].concat(),
    );
    without_default(
        "reconstruct",
        &["--spring-constant", "--resonance-frequency", "--amplitude"],
    );
    // the curve's columns come from --data FILE.csv
    defaults_shown(
        "fit",
        FitRequest::default(),
        &["height", "force", "sigma", "time"],
    );
    without_default("fit", &["--no-profiles"]);
}

#[test]
fn a_boolean_on_by_default_is_turned_off_by_its_no_flag() {
    // `--no-branches` is the request's `branches: false`: the default curve of the paper's
    // beam has branches, the same curve with the flag none
    let args = ["approach", "--points", "6", "--files", "none", "--json"];
    let branches = |doc: &serde_json::Value| doc["branches"].as_array().map_or(0, Vec::len);
    assert!(branches(&common::json(&args)) > 0);
    let off = common::json(&[&args[..], &["--no-branches"]].concat());
    assert_eq!(branches(&off), 0, "{}", off["branches"]);
}

/// `fit` of the example Hertz force curve, its document on stdout.
const FIT_HERTZ: [&str; 8] = [
    "fit",
    "--probe",
    "examples/probe-fit-hertz.toml",
    "--data",
    "examples/force-curve-hertz.csv",
    "--files",
    "none",
    "--json",
];

#[test]
fn an_optional_boolean_takes_on_off_or_the_default() {
    // `fit`'s `profiles: Option<bool>`: a force curve has profile-likelihood intervals by
    // default (`None`), Wald intervals with `--no-profiles` (`Some(false)`); the two flags
    // together are refused
    let args = FIT_HERTZ;
    let method = |extra: &[&str]| {
        let doc = common::json(&[&args[..], extra].concat());
        doc["method"].as_str().unwrap().to_string()
    };
    assert!(
        method(&[]).contains("profile likelihood"),
        "{}",
        method(&[])
    );
    assert!(method(&["--profiles"]).contains("profile likelihood"));
    let off = method(&["--no-profiles"]);
    assert!(
        off.contains("Wald") && !off.contains("profile likelihood"),
        "{off}"
    );
    let both = common::run(&[&args[..], &["--profiles", "--no-profiles"]].concat());
    assert!(!both.status.success(), "--profiles with --no-profiles");
}

#[test]
fn enum_names_unit_lists_and_a_mode_setpoint_read_as_the_library_does() {
    // `reconstruct --inversion exact`: the library's exact inversion, whose document records
    // its iterations under "exact"; the default (Sader–Jarvis) has none
    let fm = [
        "reconstruct",
        "--fm",
        "examples/fm-vdw.csv",
        "--spring-constant",
        "40",
        "--resonance-frequency",
        "300kHz",
        "--amplitude",
        "10nm",
        "--files",
        "none",
        "--json",
    ];
    assert!(common::json(&fm).get("exact").is_none());
    let exact = common::json(&[&fm[..], &["--inversion", "exact"]].concat());
    assert!(exact["exact"]["iterations"].as_u64().is_some(), "{exact}");
    common::refused(
        &[&fm[..], &["--inversion", "newton"]].concat(),
        &["--inversion"],
    );
    // `fit --range LO,HI` (x-dim length): 20 nm and 2e-8 are the same range
    let fit = |range: &str| common::json(&[&FIT_HERTZ[..], &[range]].concat());
    let (si, units) = (fit("--range=-2e-8,2e-7"), fit("--range=-20nm,200nm"));
    assert_eq!(si["range"], serde_json::json!([-2e-8, 2e-7]));
    assert_eq!(si["range"], units["range"]);
    assert_eq!(si["rows_fitted"], units["rows_fitted"]);
    // `image --setpoint` (x-dim mode): a plain ratio in AM, a unit refused by name
    common::refused(
        &[
            "image",
            "--probe",
            "examples/probe-point-mass-dmt.toml",
            "--sample",
            "examples/sample-stripe.toml",
            "--setpoint",
            "2nN",
            "--files",
            "none",
        ],
        &["--setpoint", "plain number"],
    );
}

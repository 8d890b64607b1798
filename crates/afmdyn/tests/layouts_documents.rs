//! The layouts of `fm`, `reconstruct` and the image's setpoint study against their JSON
//! documents, the other form of the same result (the `--json` output that the command line's
//! files and the former Python datasets were built from): each layout holds exactly the
//! document's arrays, value for value, each in the unit the document's `units` names for it —
//! the defining identity of a layout laid out from its result.
#![cfg(feature = "files")]

use afmdyn::analysis::progress::Progress;
use afmdyn::layout::{Layout, Values};
use afmdyn::probe::Probe;
use afmdyn::request::image_job::ImageKeywords;
use afmdyn::request::{named, Resolved};
use afmdyn::study::image_ideal::setpoint_study;
use afmdyn::study::named::Outcome;
use afmdyn::Params;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn probe_text() -> String {
    std::fs::read_to_string(root().join("examples/probe-point-mass-dmt.toml")).unwrap()
}

/// The model of the point-mass DMT probe (`with_probe`) or the paper's parameters.
fn model(with_probe: bool) -> Resolved {
    let probe = with_probe.then(|| Probe::parse(&probe_text(), "probe").unwrap());
    Resolved {
        params: probe.as_ref().map_or_else(Params::default, |p| p.params),
        probe,
    }
}

/// Analysis `name` of `request` run by the one door.
fn door(name: &str, request: Value, model: &Resolved) -> Outcome {
    let r = named::parse(name, request).unwrap().unwrap();
    r.validate(model).unwrap();
    r.run(model, &Progress::default()).unwrap()
}

/// The one layout of `outcome`, named `name`, checked (every variable fills its shape).
fn only<'a>(outcome: &'a Outcome, name: &str) -> &'a Layout {
    assert_eq!(outcome.datasets.len(), 1);
    let (n, layout) = &outcome.datasets[0];
    assert_eq!(n, name);
    layout.check().unwrap();
    layout
}

/// The values of `v` as JSON, as the document writes them (NaN as `null`).
fn as_json(v: &Values) -> Vec<Value> {
    let f = |x: &f64| if x.is_finite() { json!(x) } else { Value::Null };
    match v {
        Values::F64(x) => x.iter().map(f).collect(),
        Values::I32(x) => x.iter().map(|i| json!(i)).collect(),
        Values::Bool(x) => x.iter().map(|b| json!(b)).collect(),
        Values::Text(x) => x.iter().map(|s| json!(s)).collect(),
        Values::C64(_) => panic!("no complex values here"),
    }
}

/// The columns of the table `fm.csv`, in its order.
const FM_COLUMNS: [&str; 18] = [
    "z_c",
    "frequency_shift",
    "frequency",
    "excitation",
    "amplitude",
    "phase_deg",
    "energy_dissipated",
    "virial",
    "mean_deflection",
    "min_distance",
    "peak_force",
    "mean_force",
    "law_force",
    "indentation",
    "max_multiplier",
    "stable",
    "loop_residual",
    "iterations",
];

#[test]
fn the_fm_layout_is_the_documents_curve_in_its_units() {
    for with_probe in [false, true] {
        let out = door("fm", json!({"points": 4}), &model(with_probe));
        let layout = only(&out, "fm");
        let doc = &out.document;
        let units = &doc["units"];
        // the variables of the table fm.csv, in its order, each over z_c
        let names: Vec<&str> = layout.variables.iter().map(|v| v.name.as_str()).collect();
        assert_eq!(names, FM_COLUMNS);
        assert_eq!(layout.dim("z_c"), Some(4));
        for v in &layout.variables {
            assert_eq!(v.dims, ["z_c"], "{}", v.name);
            let column = doc["curve"][&v.name].as_array().unwrap();
            assert_eq!(&as_json(&v.values), column, "{}", v.name);
            if let Some(u) = units[&v.name].as_str() {
                assert_eq!(v.units, u, "{}", v.name);
            }
        }
        // the lengths and forces the document leaves without a unit are in its length's and
        // force's (z_c's, peak_force's)
        let unit = |n: &str| layout.variable(n).unwrap().units.as_str();
        for n in ["mean_deflection", "indentation"] {
            assert_eq!(unit(n), units["z_c"].as_str().unwrap(), "{n}");
        }
        for n in ["mean_force", "law_force"] {
            assert_eq!(unit(n), units["peak_force"].as_str().unwrap(), "{n}");
        }
        assert_eq!(unit("z_c"), if with_probe { "m" } else { "g0" });
    }
}

/// The layout of a reconstruction against its document's `force` arrays and `units`
/// (`law` in the force's unit), `law` present as in the document.
fn check_reconstruction(out: &Outcome) {
    let layout = only(out, "reconstruct");
    let doc = &out.document;
    let n = doc["force"]["distance"].as_array().unwrap().len();
    assert_eq!(layout.dim("distance"), Some(n));
    let mut want: Vec<&str> = vec!["distance"];
    if doc["force"].get("law").is_some() {
        want.push("law");
    }
    want.extend(["force", "potential"]);
    let names: Vec<&str> = layout.variables.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(names, want);
    for v in &layout.variables {
        assert_eq!(v.dims, ["distance"]);
        assert_eq!(
            &as_json(&v.values),
            doc["force"][&v.name].as_array().unwrap()
        );
        let key = if v.name == "law" { "force" } else { &v.name };
        assert_eq!(Some(v.units.as_str()), doc["units"][key].as_str());
    }
}

#[test]
fn the_reconstruct_layout_is_the_documents_force_and_potential() {
    // a curve as given: no model force
    let curve = json!({"distance": [5e-9, 4e-9, 3e-9, 2e-9, 1e-9],
                       "frequency_shift": [-0.16, -0.25, -0.45, -1.0, -4.0],
                       "spring_constant": 40.0, "resonance_frequency": 3e5, "amplitude": 1e-8});
    let plain = door("reconstruct", curve, &model(false));
    check_reconstruction(&plain);
    assert!(plain.document["force"].get("law").is_none());
    // an fm curve's document: the model's force beside the reconstruction
    let si = model(true);
    let fm = door("fm", json!({"points": 5}), &si);
    let text = fm.document.to_string();
    let from_fm = door("reconstruct_document", json!({ "fm": text }), &si);
    check_reconstruction(&from_fm);
    // the law is the fm curve's law_force, in increasing distance (the fm curve approaches)
    let mut law: Vec<Value> = fm.document["curve"]["law_force"]
        .as_array()
        .unwrap()
        .clone();
    law.reverse();
    assert_eq!(&law, from_fm.document["force"]["law"].as_array().unwrap());
}

#[test]
fn the_setpoint_study_layout_is_its_json() {
    let keywords = ImageKeywords {
        sample: root()
            .join("examples/sample-stripe.toml")
            .display()
            .to_string(),
        ..ImageKeywords::default()
    };
    let (table, map) = keywords.inputs(&probe_text()).unwrap();
    let ratios = [0.3, 0.6, 0.9];
    let out = setpoint_study(&table, &map, &ratios, 20).unwrap().outcome();
    let layout = only(&out, "setpoint_study");
    let doc = &out.document;
    let domains = doc["domains"].as_array().unwrap();
    assert_eq!(layout.dim("domain"), Some(map.domains.len() + 1));
    assert_eq!(layout.dim("setpoint"), Some(ratios.len()));
    let var = |n: &str| as_json(&layout.variable(n).unwrap().values);
    let names: Vec<Value> = domains.iter().map(|d| d["name"].clone()).collect();
    assert_eq!(var("domain"), names);
    assert_eq!(names[0], "background");
    assert_eq!(&var("setpoint"), doc["ratio"].as_array().unwrap());
    for key in [
        "apparent_height",
        "phase_deg",
        "energy_dissipated",
        "regime",
    ] {
        // row-major over (domain, setpoint): each domain's series in turn, a regime's
        // absence (null) an empty word
        let want: Vec<Value> = domains
            .iter()
            .flat_map(|d| d[key].as_array().unwrap().clone())
            .map(|v| {
                if key == "regime" && v.is_null() {
                    json!("")
                } else {
                    v
                }
            })
            .collect();
        assert_eq!(var(key), want, "{key}");
        let v = layout.variable(key).unwrap();
        assert_eq!(v.dims, ["domain", "setpoint"]);
    }
    // the background's apparent height is 0 at every setpoint by definition (h + z_c − z_c,ref
    // with its own z_c the reference)
    assert_eq!(var("apparent_height")[..3], vec![json!(0.0); 3]);
}

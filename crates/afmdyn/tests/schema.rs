//! The JSON Schemas of the requests (`docs/schema/requests/<name>.json`) are generated from the
//! types (`schemars`, feature `schema`) and must equal the committed files, so that the files
//! cannot drift from the code.
//! `AFMDYN_WRITE_SCHEMA=1 cargo test -p afmdyn --lib integration::schema::` (re)writes them. Each
//! schema carries the request's default, serialised, as its one `examples` entry
//! (crates/afmdyn-py/tests/test_schema.py validates it against the schema); here it must
//! deserialise back to the default.
#![cfg(feature = "schema")]

use afmdyn::request::image::ImageRequest;
use afmdyn::request::{
    ApproachRequest, BasinsRequest, ChartRequest, FmRequest, ModesRequest, ReconstructRequest,
    ResonanceRequest,
};
use afmdyn::request::{
    AttractorsRequest, BifurcationRequest, ContinuationRequest, ConvergeRequest, CurveRequest,
    GlobalContinuationRequest, IntegratorRequest, LyapunovRequest, ModelSpec, ObserveRequest,
    OrbitRequest, SimulateRequest, StartRequest, SteadyRequest,
};
use schemars::{schema_for, JsonSchema};
use serde::{de::DeserializeOwned, Serialize};
use serde_json::Value;
use std::fmt::Debug;
use std::path::{Path, PathBuf};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/schema/requests")
}

/// The schema of `T` as it is written to its file; `examples` holds the
/// default serialised.
fn schema<T>(name: &str) -> Value
where
    T: JsonSchema + Serialize + DeserializeOwned + Default + PartialEq + Debug,
{
    let default = serde_json::to_value(T::default()).unwrap();
    let back: T = serde_json::from_value(default.clone()).unwrap();
    assert_eq!(
        back,
        T::default(),
        "{name}: the default does not round-trip"
    );
    let mut s = schema_for!(T).to_value();
    let obj = s.as_object_mut().unwrap();
    obj.insert("examples".into(), Value::Array(vec![default]));
    s
}

/// Every request type by its file name.
fn schemas() -> Vec<(&'static str, Value)> {
    vec![
        ("model", schema::<ModelSpec>("model")),
        ("steady", schema::<SteadyRequest>("steady")),
        ("integrator", schema::<IntegratorRequest>("integrator")),
        ("start", schema::<StartRequest>("start")),
        ("orbit", schema::<OrbitRequest>("orbit")),
        (
            "continuation",
            schema::<ContinuationRequest>("continuation"),
        ),
        ("lyapunov", schema::<LyapunovRequest>("lyapunov")),
        ("attractors", schema::<AttractorsRequest>("attractors")),
        (
            "global_continuation",
            schema::<GlobalContinuationRequest>("global_continuation"),
        ),
        ("observe", schema::<ObserveRequest>("observe")),
        ("converge", schema::<ConvergeRequest>("converge")),
        ("simulate", schema::<SimulateRequest>("simulate")),
        ("bifurcation", schema::<BifurcationRequest>("bifurcation")),
        ("curve", schema::<CurveRequest>("curve")),
        ("modes", schema::<ModesRequest>("modes")),
        ("approach", schema::<ApproachRequest>("approach")),
        ("resonance", schema::<ResonanceRequest>("resonance")),
        ("chart", schema::<ChartRequest>("chart")),
        ("basins", schema::<BasinsRequest>("basins")),
        ("reconstruct", schema::<ReconstructRequest>("reconstruct")),
        ("fm", schema::<FmRequest>("fm")),
        (
            "peakforce",
            schema::<afmdyn::request::PeakForceRequest>("peakforce"),
        ),
        ("image", schema::<ImageRequest>("image")),
        (
            "image_scan",
            schema::<afmdyn::request::image_scan::PiScan>("image_scan"),
        ),
        (
            "image_options",
            schema::<afmdyn::request::image_options::ImageOptions>("image_options"),
        ),
        ("fit", schema::<afmdyn::request::FitRequest>("fit")),
    ]
}

#[test]
fn request_schemas_match_the_committed_files() {
    let write = std::env::var_os("AFMDYN_WRITE_SCHEMA").is_some_and(|v| v == "1");
    let dir = dir();
    let mut stale = Vec::new();
    for (name, schema) in schemas() {
        let text = serde_json::to_string_pretty(&schema).unwrap() + "\n";
        let path = dir.join(format!("{name}.json"));
        if write {
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::write(&path, &text).unwrap();
        } else if std::fs::read_to_string(&path).ok().as_deref() != Some(text.as_str()) {
            stale.push(path.display().to_string());
        }
    }
    assert!(
        stale.is_empty(),
        "request schemas differ from the code: {stale:?}; regenerate with \
         AFMDYN_WRITE_SCHEMA=1 cargo test -p afmdyn --lib integration::schema::"
    );
}

/// No file in docs/schema/requests without a request type behind it.
#[test]
fn no_stray_request_schema() {
    let names: Vec<String> = schemas()
        .into_iter()
        .map(|(n, _)| format!("{n}.json"))
        .collect();
    for entry in std::fs::read_dir(dir()).unwrap() {
        let file = entry.unwrap().file_name().into_string().unwrap();
        assert!(
            names.contains(&file),
            "docs/schema/requests/{file}: no request type"
        );
    }
}

/// The schemas describe what deserialisation takes: unknown keys refused (every request is
/// `deny_unknown_fields`), flattened groups' keys at the top level.
#[test]
fn request_schemas_refuse_unknown_keys_and_flatten_groups() {
    for (name, s) in schemas() {
        assert_eq!(
            s["additionalProperties"],
            Value::Bool(false),
            "{name}: additionalProperties"
        );
    }
    let all = schemas();
    let bif = &all.iter().find(|(n, _)| *n == "bifurcation").unwrap().1;
    for key in ["param", "tol", "max_periods", "integrator", "tolerance"] {
        assert!(bif["properties"].get(key).is_some(), "bifurcation: {key}");
    }
}

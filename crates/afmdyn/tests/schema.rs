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
        (
            "fit_map",
            schema::<afmdyn::request::FitMapRequest>("fit_map"),
        ),
        (
            "thermal",
            schema::<afmdyn::request::ThermalRequest>("thermal"),
        ),
        (
            "calibrate",
            schema::<afmdyn::request::CalibrateRequest>("calibrate"),
        ),
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

/// The sections of a probe file (tables at its root, not keys).
const PROBE_SECTIONS: [&str; 5] = ["cantilever", "tip", "sample", "drive", "medium"];

/// The keys of a probe file (`docs/schema/probe-keys.json`, read by `scripts/gen_reference.py`
/// for docs/reference/probe-keys.md): every key the reader knows, by its section, with its unit
/// and sign as the reader checks it, its physical and typical range (`probe::ranges::SI_RANGES`)
/// and the laws whose `[sample]` takes it and the groups it sets (the registry `contact::LAWS`).
/// The keys and their units are the reader's own: those a file with an unknown key is told to
/// use instead, and those a key set to NaN is refused with.
fn probe_keys() -> Value {
    use afmdyn::probe::{ranges::SI_RANGES, Probe};
    use serde_json::json;
    let problems = |text: &str| -> String {
        Probe::parse(text, "p.toml")
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    };
    // the contexts whose keys the reader lists: (section, what the file holds before them)
    let contexts = [
        ("", ""),
        ("tip", "[tip]\n"),
        ("cantilever", "model = \"beam\"\n[cantilever]\n"),
        ("cantilever", "model = \"eigenmodes\"\n[cantilever]\n"),
        ("drive", "[drive]\n"),
        ("drive", "[drive]\nmode = \"off-resonance\"\n"),
        ("medium", "[medium]\n"),
    ];
    let mut keys: Vec<(String, String, String)> = Vec::new(); // (section, key, header)
    for (section, head) in contexts {
        let text = problems(&format!("{head}zzz = 1\n"));
        let list = text
            .split("(expected one of: ")
            .nth(1)
            .unwrap()
            .split(')')
            .next()
            .unwrap();
        // (the root's sections are tables, listed under their own names)
        for k in list
            .split(", ")
            .filter(|k| !section.is_empty() || !PROBE_SECTIONS.contains(k))
        {
            keys.push((section.into(), k.into(), head.into()));
        }
    }
    for law in afmdyn::contact::LAWS {
        for k in law.sample_keys {
            keys.push((
                "sample".into(),
                (*k).into(),
                format!("[sample]\nlaw = \"{}\"\n", law.name),
            ));
        }
    }
    let mut out: Vec<Value> = Vec::new();
    for (section, key, head) in &keys {
        let name = if section.is_empty() {
            key.clone()
        } else {
            format!("{section}.{key}")
        };
        let at = if section.is_empty() {
            key.clone()
        } else {
            format!("[{section}].{key}")
        };
        let text = problems(&format!("{head}{key} = nan\n"));
        // `[section].key = NaN (unit): must be range`
        let checked = text.split(&format!("{at} = NaN (")).nth(1).map(|rest| {
            let (unit, rest) = rest.split_once("): must be ").unwrap();
            (
                unit.to_string(),
                rest.split("; ").next().unwrap().to_string(),
            )
        });
        // a name (not a number): what the reader expects instead of `zzz`
        let named = || {
            // (the context's own line of the key replaced: `law = "dmt"` in `[sample]`)
            let own = format!("{key} = ");
            let head: String = head
                .lines()
                .filter(|l| !l.starts_with(&own))
                .map(|l| format!("{l}\n"))
                .collect();
            let text = problems(&format!("{head}{key} = \"zzz\"\n"));
            let rest = text.split(&format!("{at} ")).nth(1)?.split_once("zzz")?.1;
            let words = rest.split_once(": ")?.1.split("; ").next()?;
            Some(words.to_string())
        };
        let must_be = checked.as_ref().map(|c| c.1.clone()).or_else(named);
        let laws: Vec<&str> = afmdyn::contact::LAWS
            .iter()
            .filter(|l| section == "sample" && l.sample_keys.contains(&key.as_str()))
            .map(|l| l.name)
            .collect();
        let groups: Vec<String> = afmdyn::contact::LAWS
            .iter()
            .flat_map(|l| l.params.iter().map(move |p| (l, p)))
            .filter(|(_, p)| section == "sample" && p.si_keys.contains(&key.as_str()))
            .map(|(l, p)| format!("{} ({})", p.name, l.name))
            .collect();
        let range = SI_RANGES
            .iter()
            .find(|r| r.sections.contains(&section.as_str()) && r.keys.contains(&key.as_str()));
        let entry = json!({
            "key": name,
            "unit": range.map(|r| r.unit.to_string()).or(checked.as_ref().map(|c| c.0.clone())),
            "must_be": must_be,
            "below": range.and_then(|r| r.below.map(|b| b.0)),
            "above": range.and_then(|r| r.above.map(|b| b.0)),
            "magnitude": range.is_some_and(|r| r.magnitude),
            "typical": range.and_then(|r| r.typical.map(|t| json!([t.0, t.1, t.2]))),
            "laws": laws,
            "groups": groups,
        });
        match out.iter_mut().find(|e| e["key"] == entry["key"]) {
            // a key of several contexts (a law's [sample]): the laws and groups of all
            Some(e) => {
                for f in ["laws", "groups"] {
                    let mut all = e[f].as_array().unwrap().clone();
                    for v in entry[f].as_array().unwrap() {
                        if !all.contains(v) {
                            all.push(v.clone());
                        }
                    }
                    e[f] = Value::Array(all);
                }
                for f in ["unit", "must_be"] {
                    if e[f].is_null() {
                        e[f] = entry[f].clone();
                    }
                }
            }
            None => out.push(entry),
        }
    }
    // the ranged keys of other files (the image's [feedback])
    for r in SI_RANGES {
        for s in r.sections {
            for k in r.keys {
                let name = format!("{s}.{k}");
                let read = |e: &Value| e["key"].as_str().unwrap().starts_with(&format!("{s}."));
                if !out.iter().any(read) {
                    out.push(json!({"key": name, "unit": r.unit, "must_be": null,
                        "below": r.below.map(|b| b.0), "above": r.above.map(|b| b.0),
                        "magnitude": r.magnitude, "typical": r.typical.map(|t| json!([t.0, t.1, t.2])),
                        "laws": [], "groups": []}));
                }
            }
        }
    }
    // each key's default (probe::defaults), one per key the reader knows
    use afmdyn::probe::defaults::KEY_DEFAULTS;
    for e in &mut out {
        let key = e["key"].as_str().unwrap().to_string();
        let d = KEY_DEFAULTS.iter().find(|d| d.0 == key);
        e["default"] = json!(
            d.unwrap_or_else(|| panic!("{key}: no KEY_DEFAULTS entry"))
                .2
        );
    }
    for d in KEY_DEFAULTS {
        assert!(
            out.iter().any(|e| e["key"] == d.0),
            "{}: not a probe key",
            d.0
        );
    }
    let laws: serde_json::Map<String, Value> = afmdyn::contact::LAWS
        .iter()
        .map(|l| (l.name.to_string(), json!(l.sample_keys)))
        .collect();
    json!({
        "description": "Every key of a probe file, written by crates/afmdyn/tests/schema.rs from \
            the probe reader (its keys and the unit and sign it checks), its range table \
            (probe::ranges::SI_RANGES: refused outside [below, above], warned outside the \
            typical range), the law registry (contact::LAWS: the laws whose [sample] takes a \
            key, the groups it sets) and its defaults (probe::defaults::KEY_DEFAULTS: the value \
            a file without the key reads as).",
        "keys": out,
        "laws": laws,
    })
}

/// Every numeric default of `probe::defaults::KEY_DEFAULTS` is the reader's: a file of
/// `examples/` that takes the key reads the same without it and with it set to the default.
#[test]
fn the_declared_defaults_are_the_readers() {
    use afmdyn::probe::{defaults::KEY_DEFAULTS, Probe};
    let examples = dir().join("../../../examples");
    let read = |file: &str| -> toml::Table {
        let text = std::fs::read_to_string(examples.join(file)).unwrap();
        toml::from_str(&text).unwrap()
    };
    // an electrostatic sample: the DMT one with a bias
    let mut electrostatic = read("probe-point-mass-dmt.toml");
    let s = electrostatic["sample"].as_table_mut().unwrap();
    s.insert("law".into(), "electrostatic".into());
    s.insert("bias_voltage".into(), 1.0.into());
    let mut checked = 0;
    for (key, value, _) in KEY_DEFAULTS {
        let Some(value) = value else { continue };
        let (section, name) = key.split_once('.').unwrap();
        let base = match *key {
            "cantilever.tip_mass_ratio" => read("probe-beam-dmt.toml"),
            "cantilever.tip_mass" | "sample.damping" => read("probe-geometry-hertz.toml"),
            "sample.surface_tension" | "sample.contact_angle" => read("probe-capillary-humid.toml"),
            "sample.contact_potential" => electrostatic.clone(),
            _ => read("probe-point-mass-dmt.toml"),
        };
        let probe = |v: Option<f64>| {
            let mut t = base.clone();
            let s = t[section].as_table_mut().unwrap();
            s.remove(name);
            if let Some(v) = v {
                s.insert(name.into(), v.into());
            }
            Probe::parse(&toml::to_string(&t).unwrap(), key).unwrap()
        };
        assert_eq!(
            probe(None),
            probe(Some(*value)),
            "{key}: its default is not {value}"
        );
        checked += 1;
    }
    assert!(checked >= 9);
}

#[test]
fn probe_keys_match_the_committed_file() {
    committed("probe-keys.json", &probe_keys());
}

/// The columns the library declares for a CSV file that has no `.npy.json` beside it
/// (`docs/schema/csv-columns.json`, which `scripts/gen_reference.py` shows in the book's CSV
/// files): `chart.csv`'s ([`afmdyn::request::chart::CSV_COLUMNS`]), `converge.csv`'s (`{N}` in
/// a name stands for a number), `bifurcation.csv`'s (the sweep's records) and the other
/// commands' (`afmdyn::report::csv_columns`).
#[test]
fn csv_columns_match_the_committed_file() {
    let columns = |c: &[(&str, &str, &str)]| -> Vec<Value> {
        c.iter()
            .map(|(name, unit, meaning)| serde_json::json!({"name": name, "unit": unit, "meaning": meaning}))
            .collect()
    };
    use afmdyn::report::csv_columns as c;
    let sweep: Vec<(&str, &str, &str)> = (afmdyn::report::sweep::COLUMNS.iter())
        .map(|r| (r.name, r.unit, r.meaning))
        .collect();
    committed(
        "csv-columns.json",
        &serde_json::json!({
            "chart.csv": columns(&afmdyn::request::chart::CSV_COLUMNS),
            "converge.csv": columns(&afmdyn::report::present::converge::COLUMNS),
            "bifurcation.csv": columns(&sweep),
            "events.csv": columns(&c::EVENTS),
            "energy.csv": columns(&c::ENERGY),
            "spectrum.csv": columns(&c::SPECTRUM),
            "basins.csv": columns(&c::BASINS),
            "attractors-sweep.csv": columns(&c::ATTRACTORS_SWEEP),
            "continuation.csv": columns(&c::CONTINUATION),
            "fig3.csv": columns(&c::FIG3),
            "fit_map.csv": columns(&c::FIT_MAP),
        }),
    );
}

/// `value` is the committed `docs/schema/<name>` (`AFMDYN_WRITE_SCHEMA=1` writes it).
fn committed(name: &str, value: &Value) {
    let path = dir().join("..").join(name);
    let text = serde_json::to_string_pretty(value).unwrap() + "\n";
    if std::env::var_os("AFMDYN_WRITE_SCHEMA").is_some_and(|v| v == "1") {
        std::fs::write(&path, &text).unwrap();
    }
    assert_eq!(
        std::fs::read_to_string(&path).ok().as_deref(),
        Some(text.as_str()),
        "docs/schema/{name} differs from the library; regenerate with \
         AFMDYN_WRITE_SCHEMA=1 cargo test -p afmdyn --lib integration::schema::"
    );
}

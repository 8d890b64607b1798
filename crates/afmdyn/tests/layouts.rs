//! The layouts of the analyses' results as data (`docs/schema/layouts/<analysis>.json`): each
//! analysis is run on a small example request through the route its front ends take (the one
//! door [`named::parse`], the stored studies [`stored::parse`], the chart's plan, the image's
//! job), and every [`afmdyn::layout::Layout`] of its outcome is written without its values
//! ([`afmdyn::layout::Layout::description`]: names, dims, units, long names, kinds and
//! attributes), with the example that produced it. The files must equal what the code lays
//! out, so that they cannot drift from it; `AFMDYN_WRITE_SCHEMA=1 cargo test -p afmdyn --test
//! layouts` (re)writes them. `scripts/gen_wrappers.py` builds the Python docstrings' "Returns"
//! from them.
#![cfg(feature = "files")]

use afmdyn::analysis::chart::ChartPlan;
use afmdyn::analysis::progress::Progress;
use afmdyn::probe::Probe;
use afmdyn::request::image_job::ImageKeywords;
use afmdyn::request::{named, ChartArrays, ChartRequest, ModelSpec, Resolved};
use afmdyn::study::image_ideal::setpoint_study;
use afmdyn::study::named::Outcome;
use afmdyn::study::stored;
use afmdyn::Params;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn dir() -> PathBuf {
    root().join("docs/schema/layouts")
}

/// How an example runs: the route of its front ends.
#[derive(Clone, Copy)]
enum Route {
    /// The one door by name ([`named::parse`]).
    Door,
    /// A study run into a store, here in memory ([`stored::parse`]).
    Stored,
    /// The chart's plan, every task, and its arrays ([`ChartArrays::layout`]).
    Chart,
    /// The image's job ([`ImageKeywords::job`]): `request` holds the keywords, `sample` the
    /// repository path of the sample map.
    Image,
    /// The image's setpoint study ([`setpoint_study`]): `request` holds `sample` (a repository
    /// path), `ratios` and `curve_points`.
    Study,
    /// A reconstruction from an `fm` curve's document (the one door's `reconstruct_document`):
    /// `request` holds `fm`, the request of the `fm` curve run first by the door.
    FmDocument,
}

/// One example: the analysis (the Python function's name), its variant (another layout of the
/// same analysis, file `<analysis>.<variant>.json`: `image`'s PI scan and PeakForce image,
/// `peakforce`'s sweep, `reconstruct`'s of an `fm` curve, `fit`'s of the `sls` law (with the
/// rows' times), and `si`, the same request under a probe), its route and request, and the
/// probe file (a repository path) it runs under (`None`: the paper's parameters).
struct Example {
    analysis: &'static str,
    variant: Option<&'static str>,
    route: Route,
    request: Value,
    probe: Option<&'static str>,
}

fn ex(
    analysis: &'static str,
    route: Route,
    request: Value,
    probe: Option<&'static str>,
) -> Example {
    Example {
        analysis,
        variant: None,
        route,
        request,
        probe,
    }
}

/// The analyses whose layouts are in SI under a probe, and the probe of their `si` variant
/// (the same request).
const SI: ([&str; 5], &str) = (
    ["simulate", "observe", "approach", "resonance", "fm"],
    "examples/probe-point-mass-dmt.toml",
);

/// The examples, one per analysis with arrays (small runs of each route), and the variants.
fn examples() -> Vec<Example> {
    let mut all = plain();
    let si: Vec<Example> = all
        .iter()
        .filter(|e| e.variant.is_none() && SI.0.contains(&e.analysis))
        .map(|e| Example {
            variant: Some("si"),
            ..ex(e.analysis, e.route, e.request.clone(), Some(SI.1))
        })
        .collect();
    all.extend(si);
    all
}

/// The examples without the `si` variants.
fn plain() -> Vec<Example> {
    use Route::*;
    vec![
        ex("modes", Door, json!({}), None),
        ex(
            "simulate",
            Door,
            json!({"periods": 4.0, "samples_per_period": 16}),
            None,
        ),
        ex(
            "converge",
            Door,
            json!({"max_modes": 2, "samples_per_period": 16}),
            None,
        ),
        ex("orbit", Door, json!({}), None),
        ex("lyapunov", Door, json!({"periods": 40, "blocks": 2}), None),
        ex("attractors", Door, json!({"samples": 4}), None),
        ex("continuation", Door, json!({"from": 4.0, "to": 3.9}), None),
        ex("observe", Door, json!({"harmonics": 3}), None),
        ex("approach", Stored, json!({"points": 4, "traces": 8}), None),
        ex(
            "bimodal",
            Stored,
            json!({"points": 3}),
            Some("examples/probe-bimodal.toml"),
        ),
        ex("resonance", Stored, json!({"points": 4}), None),
        ex("basins", Stored, json!({"x_steps": 3, "y_steps": 2}), None),
        ex(
            "global_continuation",
            Stored,
            json!({"steps": 2, "samples": 4}),
            None,
        ),
        ex(
            "bifurcation",
            Stored,
            json!({"steps": 2, "from": 3.0, "to": 3.2}),
            None,
        ),
        ex(
            "chart",
            Chart,
            json!({"x_steps": 2, "y_steps": 1, "starts": 1, "lyapunov_periods": 20}),
            None,
        ),
        ex(
            "peakforce",
            Door,
            json!({"samples": 2000}),
            Some("examples/probe-peakforce-air.toml"),
        ),
        ex(
            "fit",
            Door,
            json!({"data": "examples/force-curve-hertz.csv"}),
            Some("examples/probe-fit-hertz.toml"),
        ),
        Example {
            variant: Some("sls"),
            ..ex(
                "fit",
                Door,
                json!({"data": "examples/force-curve-sls-dwell.csv"}),
                Some("examples/probe-fit-sls.toml"),
            )
        },
        ex(
            "image",
            Image,
            json!({"sample": "examples/sample-stripe.toml", "setpoint": 0.7, "pixels": 4,
                   "curve_points": 20}),
            Some("examples/probe-point-mass-dmt.toml"),
        ),
        ex(
            "setpoint_study",
            Study,
            json!({"sample": "examples/sample-stripe.toml", "ratios": [0.4, 0.8],
                   "curve_points": 20}),
            Some("examples/probe-point-mass-dmt.toml"),
        ),
        ex("fm", Door, json!({"points": 4}), None),
        ex(
            "reconstruct",
            Door,
            json!({"distance": [1e-9, 2e-9, 3e-9, 4e-9, 5e-9],
                   "frequency_shift": [-4.0, -1.0, -0.45, -0.25, -0.16],
                   "spring_constant": 40.0, "resonance_frequency": 3e5, "amplitude": 1e-8}),
            None,
        ),
        Example {
            variant: Some("fm"),
            ..ex(
                "reconstruct",
                FmDocument,
                json!({"fm": {"points": 4}}),
                Some("examples/probe-point-mass-dmt.toml"),
            )
        },
        Example {
            variant: Some("sweep"),
            ..ex(
                "peakforce",
                Door,
                json!({"samples": 2000,
                       "sweep": {"quantity": "z_c", "values": [95e-9, 90e-9]}}),
                Some("examples/probe-peakforce-air.toml"),
            )
        },
        Example {
            variant: Some("pi"),
            ..ex(
                "image",
                Image,
                json!({"sample": "examples/sample-stripe.toml", "setpoint": 0.7, "pixels": 4,
                       "curve_points": 20, "feedback": {"scan_rate": 40.0}, "threads": 1}),
                Some("examples/probe-point-mass-dmt.toml"),
            )
        },
        Example {
            variant: Some("peakforce"),
            ..ex(
                "image",
                Image,
                json!({"sample": "examples/sample-peakforce-blend.toml", "setpoint": 2e-9,
                       "mode": "peakforce", "pixels": 2, "lines": 2, "threads": 1}),
                Some("examples/probe-peakforce-amo-garcia.toml"),
            )
        },
    ]
}

/// The file stem of `e`: its analysis, and its variant after a dot.
fn stem(e: &Example) -> String {
    match e.variant {
        Some(v) => format!("{}.{v}", e.analysis),
        None => e.analysis.to_string(),
    }
}

fn read(repo_path: &str) -> String {
    std::fs::read_to_string(root().join(repo_path)).unwrap()
}

/// `request` with its repository paths (`data`, `sample`) made absolute.
fn located(mut request: Value) -> Value {
    for key in ["data", "sample"] {
        if let Some(Value::String(p)) = request.get(key) {
            let full = root().join(p).display().to_string();
            request[key] = Value::String(full);
        }
    }
    request
}

/// The layouts of `e`'s outcome.
fn run(e: &Example) -> Outcome {
    let text = e.probe.map(read);
    let probe = text.as_deref().map(|t| Probe::parse(t, "probe").unwrap());
    let model = Resolved {
        params: probe.as_ref().map_or_else(Params::default, |p| p.params),
        probe,
    };
    let request = located(e.request.clone());
    let progress = Progress::default();
    let name = e.analysis;
    match e.route {
        Route::Door => {
            let r = named::parse(name, request).unwrap().unwrap();
            r.validate(&model).unwrap();
            r.run(&model, &progress).unwrap()
        }
        Route::Stored => {
            let s = stored::parse(name, request).unwrap().unwrap();
            let prepared = s.prepare(model).unwrap();
            prepared.run(None, false, &progress).unwrap()
        }
        Route::Chart => {
            let r: ChartRequest = serde_json::from_value(request).unwrap();
            let chart = r
                .chart(ModelSpec::default(), model.params, text.as_deref())
                .unwrap();
            let plan = ChartPlan::new(&chart.spec, &chart.model);
            let cancel = AtomicBool::new(false);
            let cells: Vec<_> = (0..plan.tasks())
                .flat_map(|t| plan.run_task(t, &cancel).unwrap())
                .collect();
            let layout = ChartArrays::new(&chart, &cells).layout(chart.model.x, chart.model.y);
            Outcome {
                datasets: vec![("chart".into(), layout)],
                ..Outcome::default()
            }
        }
        Route::Study => {
            let keywords = ImageKeywords {
                sample: request["sample"].as_str().unwrap().into(),
                ..ImageKeywords::default()
            };
            let (table, map) = keywords.inputs(text.as_deref().unwrap()).unwrap();
            let ratios: Vec<f64> = serde_json::from_value(request["ratios"].clone()).unwrap();
            let points = request["curve_points"].as_u64().unwrap() as usize;
            setpoint_study(&table, &map, &ratios, points)
                .unwrap()
                .outcome()
        }
        Route::FmDocument => {
            let fm = named::parse("fm", request["fm"].clone()).unwrap().unwrap();
            let doc = fm.run(&model, &progress).unwrap().document;
            let r = named::parse("reconstruct_document", json!({"fm": doc.to_string()}));
            r.unwrap().unwrap().run(&model, &progress).unwrap()
        }
        Route::Image => {
            let keywords: ImageKeywords = serde_json::from_value(request).unwrap();
            let setpoint = keywords.setpoint;
            let job = keywords.job(text.as_deref().unwrap()).unwrap();
            let model = job.model().unwrap();
            afmdyn::request::run(&job, &model, &progress)
                .unwrap()
                .output
                .outcome(setpoint)
        }
    }
}

/// The file of `e`: the example (its request as given, its probe file) and each dataset's
/// name with its layout's description.
fn file(e: &Example) -> Value {
    let outcome = run(e);
    let datasets: Vec<Value> = outcome
        .datasets
        .iter()
        .map(|(name, layout)| {
            layout.check().unwrap();
            let mut d = serde_json::to_value(layout.description()).unwrap();
            d.as_object_mut()
                .unwrap()
                .insert("name".into(), Value::String(name.clone()));
            d
        })
        .collect();
    json!({
        "analysis": e.analysis,
        "variant": e.variant,
        "example": {"request": e.request, "probe": e.probe},
        "datasets": datasets,
    })
}

#[test]
fn layouts_match_the_committed_files() {
    let write = std::env::var_os("AFMDYN_WRITE_SCHEMA").is_some_and(|v| v == "1");
    let dir = dir();
    let mut stale = Vec::new();
    for e in examples() {
        let text = serde_json::to_string_pretty(&file(&e)).unwrap() + "\n";
        let path = dir.join(format!("{}.json", stem(&e)));
        if write {
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::write(&path, &text).unwrap();
        } else if std::fs::read_to_string(&path).ok().as_deref() != Some(text.as_str()) {
            stale.push(path.display().to_string());
        }
    }
    assert!(
        stale.is_empty(),
        "result layouts differ from the code: {stale:?}; regenerate with \
         AFMDYN_WRITE_SCHEMA=1 cargo test --release -p afmdyn --lib integration::layouts::"
    );
}

/// No file in docs/schema/layouts without an example behind it.
#[test]
fn no_stray_layout_file() {
    let names: Vec<String> = examples()
        .iter()
        .map(|e| format!("{}.json", stem(e)))
        .collect();
    let Ok(entries) = std::fs::read_dir(dir()) else {
        return;
    };
    for entry in entries {
        let file = entry.unwrap().file_name().into_string().unwrap();
        assert!(
            names.contains(&file),
            "docs/schema/layouts/{file}: no example"
        );
    }
}

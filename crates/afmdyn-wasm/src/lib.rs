//! afmdyn in the browser (issue 47): the library's requests as JSON in, their documents out —
//! the same documents `afmdyn … --json` prints and Python's `to_dict()` returns — compiled to
//! `wasm32-unknown-unknown` without threads or files, for a page and its Web Worker.
//!
//! A front end of names only: [`run_json`] reads `{"model": {…}, "probe": "…", "request": {…}}`
//! — `model` the keys of a `--config` file (`omega`, `alpha4`, `contact_law`, …;
//! [`afmdyn::request::ModelSpec`]), `probe` the text of a probe file (SI), `request` the
//! analysis's keywords as the library's request types name them (their JSON Schemas in
//! `docs/schema/requests/`) — resolves the model as the command line does (the paper's
//! defaults, or the probe's), and runs [`afmdyn::request::run()`]. Errors are the command line's
//! one-line messages (the library's, naming the field and its range), so a page shows the same
//! text beside the field.
//!
//! The analyses: `modes`, `orbit`, `observe`, `lyapunov`, `continuation`, `attractors`,
//! `converge`, `approach`, `resonance` and `fm` ([`ANALYSES`]); the bifurcation diagram in
//! chunks ([`Bifurcation`], [`bifurcation::BifurcationSession`]).

#![warn(missing_docs)]

pub mod bifurcation;

use afmdyn::analysis::progress::Progress;
use afmdyn::probe::Probe;
use afmdyn::request::{self, Analysis, ModelSpec, Resolved};
use afmdyn::Params;
use serde::de::DeserializeOwned;
use serde::Deserialize;
use serde_json::Value;
use wasm_bindgen::prelude::*;

/// The analyses [`run_json`] runs, by the command line's names.
pub const ANALYSES: [&str; 10] = [
    "modes",
    "orbit",
    "observe",
    "lyapunov",
    "continuation",
    "attractors",
    "converge",
    "approach",
    "resonance",
    "fm",
];

/// What a page sends.
#[derive(Debug, Default, Deserialize)]
#[serde(default, deny_unknown_fields)]
struct Input {
    /// The model's values (a `--config` file's keys).
    model: ModelSpec,
    /// A probe file's text (SI).
    probe: Option<String>,
    /// The analysis's keywords.
    request: Option<Value>,
}

/// The model of `input` (the command line's defaults, or the probe's, then the `model` keys)
/// and its `request`.
pub(crate) fn resolve(input: &str) -> Result<(Resolved, Option<Value>), String> {
    let inp: Input = if input.trim().is_empty() {
        Input::default()
    } else {
        serde_json::from_str(input).map_err(|e| format!("input: {e}"))?
    };
    let probe = inp
        .probe
        .as_deref()
        .map(|t| Probe::parse(t, "probe"))
        .transpose()
        .map_err(|e| e.to_string())?;
    let params = inp
        .model
        .resolve(Params::default(), probe.as_ref())
        .map_err(|e| e.to_string())?;
    Ok((Resolved { params, probe }, inp.request))
}

/// Run `A` read from `request` on `model`: its JSON document as text.
fn document<A: Analysis + DeserializeOwned + Default>(
    request: Option<Value>,
    model: &Resolved,
) -> Result<String, String> {
    let a: A = match request {
        Some(v) => serde_json::from_value(v).map_err(|e| format!("request: {e}"))?,
        None => A::default(),
    };
    let doc = request::run(&a, model, &Progress::new()).map_err(|e| e.to_string())?;
    Ok(doc.json.to_string())
}

/// Run the analysis `analysis` (one of [`ANALYSES`]) on `input` (module docs): the document as
/// JSON text, or the error's one-line message.
///
/// # Errors
/// An unknown analysis; input that is not the JSON described (naming the key); a probe file
/// the probe format refuses; the model's and the request's validation errors (naming the field
/// and its range) and the analysis's.
pub fn run_json(analysis: &str, input: &str) -> Result<String, String> {
    let (model, r) = resolve(input)?;
    match analysis {
        "modes" => document::<request::ModesRequest>(r, &model),
        "orbit" => document::<request::OrbitRequest>(r, &model),
        "observe" => document::<request::ObserveRequest>(r, &model),
        "lyapunov" => document::<request::LyapunovRequest>(r, &model),
        "continuation" => document::<request::ContinuationRequest>(r, &model),
        "attractors" => document::<request::AttractorsRequest>(r, &model),
        "converge" => document::<request::ConvergeRequest>(r, &model),
        "approach" => document::<request::ApproachRequest>(r, &model),
        "resonance" => document::<request::ResonanceRequest>(r, &model),
        "fm" => document::<request::fm::FmRequest>(r, &model),
        other => Err(format!(
            "analysis = {other}: must be one of {}",
            ANALYSES.join(", ")
        )),
    }
}

/// Most drive periods [`advance_periods`] integrates.
pub const MAX_PERIODS: usize = 1_000_000;

/// Integrate the model of `input` (its `model` and `probe`; no `request`) from rest over
/// `periods` drive periods with the default (`auto`) integrator: the final state `z` (shape
/// `[2N]`, (a, ȧ)) as JSON — the engine's cost per forcing period, timed by the caller (the
/// browser against the native build, `scripts/perf-wasm.sh`).
///
/// # Errors
/// `periods` outside 1..=[`MAX_PERIODS`]; as [`run_json`]'s model; the integrator's.
pub fn advance_periods(input: &str, periods: usize) -> Result<String, String> {
    if !(1..=MAX_PERIODS).contains(&periods) {
        return Err(format!("periods = {periods}: must be in 1..=1000000"));
    }
    let (model, _) = resolve(input)?;
    let m = afmdyn::CantileverModel::new(&model.params).map_err(|e| e.to_string())?;
    let mut integ = afmdyn::integrate::build(
        &m,
        afmdyn::integrate::IntegratorOptions::default(),
        0.0,
        &m.rest(),
    )
    .map_err(|e| e.to_string())?;
    afmdyn::integrate::advance(integ.as_mut(), periods as f64 * m.period())
        .map_err(|e| e.to_string())?;
    Ok(serde_json::to_string(integ.state().as_slice()).expect("numbers serialise"))
}

/// [`advance_periods`] for JavaScript.
///
/// # Errors
/// As [`advance_periods`].
#[wasm_bindgen]
pub fn periods(input: &str, periods: usize) -> Result<String, JsError> {
    advance_periods(input, periods).map_err(|e| JsError::new(&e))
}

/// [`run_json`] for JavaScript: the document's JSON text, or a thrown `Error` with the
/// one-line message.
///
/// # Errors
/// As [`run_json`].
#[wasm_bindgen]
pub fn run(analysis: &str, input: &str) -> Result<String, JsError> {
    run_json(analysis, input).map_err(|e| JsError::new(&e))
}

/// The library's version (the page shows it).
#[wasm_bindgen]
pub fn version() -> String {
    env!("CARGO_PKG_VERSION").to_string()
}

/// A bifurcation diagram computed in chunks for JavaScript
/// ([`bifurcation::BifurcationSession`]): `new Bifurcation(input)`, then `next(points)` until
/// `finished()`, each call returning the new rows as JSON text.
#[wasm_bindgen]
pub struct Bifurcation {
    inner: bifurcation::BifurcationSession,
}

#[wasm_bindgen]
impl Bifurcation {
    /// The sweep of `input` (as [`run`]'s, the request `afmdyn bifurcation`'s keywords).
    ///
    /// # Errors
    /// As [`bifurcation::BifurcationSession::new`].
    #[wasm_bindgen(constructor)]
    pub fn new(input: &str) -> Result<Bifurcation, JsError> {
        bifurcation::BifurcationSession::new(input)
            .map(|inner| Bifurcation { inner })
            .map_err(|e| JsError::new(&e))
    }

    /// The sweep's points.
    pub fn total(&self) -> usize {
        self.inner.total()
    }

    /// Whether every point has been handed out.
    pub fn finished(&self) -> bool {
        self.inner.finished()
    }

    /// At least `points` further points: their rows, JSON text.
    ///
    /// # Errors
    /// As [`bifurcation::BifurcationSession::next`].
    pub fn next(&mut self, points: usize) -> Result<String, JsError> {
        self.inner.next(points).map_err(|e| JsError::new(&e))
    }
}

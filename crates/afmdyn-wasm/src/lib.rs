//! afmdyn in the browser (issue 47): the library's requests as JSON in, their documents out —
//! the same documents `afmdyn … --json` prints and Python's `to_dict()` returns — compiled to
//! `wasm32-unknown-unknown` without threads or files, for a page and its Web Worker.
//!
//! A front end of names only: [`run_json`] reads `{"model": {…}, "probe": "…", "request": {…}}`
//! — `model` the keys of a `--config` file (`omega`, `alpha4`, `contact_law`, …;
//! [`afmdyn::request::ModelSpec`]), `probe` the text of a probe file (SI), `request` the
//! analysis's keywords as the library's request types name them (their JSON Schemas in
//! `docs/schema/requests/`) — resolves the model as the command line does (the paper's
//! defaults, or the probe's), and runs [`afmdyn::request::run()`]. `image` also takes
//! `"sample"`, the text of a sample map; the other analyses refuse it. Errors are the command
//! line's one-line messages (the library's, naming the field and its range), so a page shows
//! the same text beside the field.
//!
//! The analyses ([`analyses()`]: every name of the library's door, [`request::named::NAMES`],
//! so an analysis added there is reachable here without an edit) and what each returns:
//!
//! * `modes`, `orbit`, `observe`, `lyapunov`, `continuation`, `attractors`,
//!   `global_continuation`, `converge`, `approach`, `resonance`, `basins`, `fm`,
//!   `reconstruct`, `peakforce`, `fit`: the document of `afmdyn <analysis> --json` (in one
//!   thread; `reconstruct` and `fit` take their curves as the request's columns);
//! * `bimodal`: the multifrequency approach curve of `afmdyn bimodal --json` (the request
//!   `approach`'s keys; the probe's `[drive]` must have two or more components);
//! * `simulate`: `{"summary": <afmdyn simulate --files none --json>, "series": {name: {"dims",
//!   "shape", "units", "long_name", "values"}, …}}`, the run's time series by the library's
//!   layout ([`simulate`]: `tau` or `t`, `v_t`, `w_tip`, `w_tip_dot`, `v_t_dot`, `in_contact`,
//!   `contact_force`, `a`, `a_dot`, …);
//! * `image`: the ideal-feedback image of `afmdyn image --json` ([`image`]).
//!
//! Besides: [`reconstruct_fm()`] (the force behind an `fm` document, `afmdyn reconstruct
//! --fm`), [`cantilevers()`] (the cantilever library, `afmdyn cantilevers --json`), the
//! bifurcation diagram in chunks ([`Bifurcation`], [`bifurcation::BifurcationSession`]),
//! [`periods()`] (the cost per drive period) and [`version()`].

#![warn(missing_docs)]

pub mod bifurcation;
pub mod image;
pub mod series;
pub mod simulate;

use afmdyn::probe::Probe;
use afmdyn::request::Params;
use afmdyn::request::Progress;
use afmdyn::request::{self, ModelSpec, Resolved};
use serde::de::DeserializeOwned;
use serde::Deserialize;
use serde_json::Value;
use wasm_bindgen::prelude::*;

/// The analyses [`run_json`] runs, by the command line's names: every analysis of the
/// library's one door ([`request::named::NAMES`]), and `image`.
pub fn analyses() -> impl Iterator<Item = &'static str> {
    request::named::NAMES.iter().copied().chain(["image"])
}

/// What a page sends.
#[derive(Debug, Default, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub(crate) struct Input {
    /// The model's values (a `--config` file's keys).
    pub(crate) model: ModelSpec,
    /// A probe file's text (SI).
    pub(crate) probe: Option<String>,
    /// A sample map's text (`image` only).
    pub(crate) sample: Option<String>,
    /// The analysis's keywords.
    pub(crate) request: Option<Value>,
}

impl Input {
    /// `input` read (empty: no keys).
    pub(crate) fn read(input: &str) -> Result<Input, String> {
        if input.trim().is_empty() {
            Ok(Input::default())
        } else {
            serde_json::from_str(input).map_err(|e| format!("input: {e}"))
        }
    }
}

/// The model of `input` (the command line's defaults, or the probe's, then the `model` keys)
/// and its `request`, for `analysis` (which takes no sample map).
pub(crate) fn resolve(input: &str, analysis: &str) -> Result<(Resolved, Option<Value>), String> {
    let inp = Input::read(input)?;
    if inp.sample.is_some() {
        return Err(format!(
            "sample: only image takes a sample map, not {analysis}"
        ));
    }
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

/// A request read from `request` (`None`: its defaults).
pub(crate) fn request<R: DeserializeOwned + Default>(request: Option<Value>) -> Result<R, String> {
    match request {
        Some(v) => serde_json::from_value(v).map_err(|e| format!("request: {e}")),
        None => Ok(R::default()),
    }
}

/// Run the analysis `analysis` (one of [`analyses()`]) on `input` (module docs): the document as
/// JSON text, or the error's one-line message.
///
/// # Errors
/// An unknown analysis; input that is not the JSON described (naming the key); a probe file
/// the probe format refuses; the model's and the request's validation errors (naming the field
/// and its range) and the analysis's.
pub fn run_json(analysis: &str, input: &str) -> Result<String, String> {
    if !analyses().any(|a| a == analysis) {
        return Err(format!(
            "analysis = {analysis}: must be one of {}",
            analyses().collect::<Vec<_>>().join(", ")
        ));
    }
    match analysis {
        "simulate" => return simulate::simulate(input),
        "image" => return image::image(input),
        _ => {}
    }
    let (model, r) = resolve(input, analysis)?;
    // the one door: the request parsed by name, run to its outcome (its document here)
    let r = r.unwrap_or_else(|| Value::Object(Default::default()));
    let named = request::named::parse(analysis, r)
        .map_err(|e| format!("request: {e}"))?
        .ok_or_else(|| format!("analysis = {analysis}: not a named analysis"))?;
    let outcome = named
        .run(&model, &Progress::new())
        .map_err(|e| e.to_string())?;
    Ok(outcome.document.to_string())
}

/// The force and potential behind an FM curve (Sader–Jarvis): `fm` the JSON document `fm`
/// returned with a probe (SI), its request read by the library
/// ([`afmdyn::request::ReconstructRequest::from_fm_document`]: the distances of closest
/// approach, the shifts, k, f₀ and A) and run through the named door — the document of
/// `afmdyn reconstruct --fm fm.json --json`.
///
/// # Errors
/// A text that is no JSON; a document that is no SI `fm` document; the request's validation
/// (naming the field and its range) and the inversion's.
pub fn reconstruct_fm_json(fm: &str) -> Result<String, String> {
    let doc: Value = serde_json::from_str(fm).map_err(|e| format!("fm: {e}"))?;
    let req = request::ReconstructRequest::from_fm_document(&doc, None, None, None)
        .map_err(|e| e.to_string())?;
    let value = serde_json::to_value(&req).map_err(|e| format!("request: {e}"))?;
    let named = request::named::parse("reconstruct", value)
        .map_err(|e| format!("request: {e}"))?
        .ok_or("analysis = reconstruct: not a named analysis")?;
    let model = Resolved::plain(Params::default());
    named.validate(&model).map_err(|e| e.to_string())?;
    let outcome = named
        .run(&model, &Progress::new())
        .map_err(|e| e.to_string())?;
    Ok(outcome.document.to_string())
}

/// [`reconstruct_fm_json`] for JavaScript.
///
/// # Errors
/// As [`reconstruct_fm_json`].
#[wasm_bindgen]
pub fn reconstruct_fm(fm: &str) -> Result<String, JsError> {
    reconstruct_fm_json(fm).map_err(|e| JsError::new(&e))
}

/// The model of `input` (its `model` and `probe`; no `request`) integrated from rest over
/// `periods` drive periods ([`afmdyn::study::advance_from_rest`]): the final state
/// `z` (shape `[2N]`, (a, ȧ)) as JSON, the engine's cost per forcing period timed by the
/// caller.
///
/// # Errors
/// `periods` outside 1..=1000000; as [`run_json`]'s model; the integrator's.
pub fn advance_periods(input: &str, periods: usize) -> Result<String, String> {
    let (model, _) = resolve(input, "periods")?;
    let z = afmdyn::study::advance_from_rest(&model.params, periods).map_err(|e| e.to_string())?;
    Ok(serde_json::to_string(&z).expect("numbers serialise"))
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

/// The cantilever library (nominal k, f₀, Q and tip radius of common cantilevers, SI): the
/// document of `afmdyn cantilevers --json` ([`afmdyn::cantilevers::document`]), JSON text.
#[wasm_bindgen]
pub fn cantilevers() -> String {
    afmdyn::cantilevers::document().to_string()
}

/// The registered contact laws ([`afmdyn::request::LAWS`]), in registry order: JSON text of
/// `[{"name", "aliases", "doc", "params", "sample_keys"}, …]`; the explorer's law lists are
/// filled from it, so a law added to the registry appears there without an edit.
#[wasm_bindgen]
pub fn laws() -> String {
    serde_json::to_string(afmdyn::request::LAWS).expect("the law descriptors serialise")
}

/// The columns of `bifurcation.csv`, in its order ([`bifurcation::columns`]): JSON text of
/// `[{"name", "unit", "meaning"}, …]`, the keys of [`Bifurcation::next`]'s rows.
#[wasm_bindgen]
pub fn bifurcation_columns() -> String {
    bifurcation::columns().to_string()
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

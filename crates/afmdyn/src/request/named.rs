//! Every analysis by its name, through one door: a front end that knows an analysis only by
//! its name (`"orbit"`) and its keywords — Python's one `run`, the WebAssembly engine — parses
//! the request by name ([`parse`], with the request's serde names, `deny_unknown_fields` and
//! defaults; [`default_request`] gives the defaults) into a [`NamedRequest`] and validates it
//! ([`NamedRequest::validate`]); running it to its outcome (the JSON document, the result's
//! arrays as layouts and the scalars a dataset carries as attributes) is the study layer's.
//!
//! The names are those of [`NAMES`]; `simulate` records its trajectory whole in memory
//! (its own budgets, [`SimulateRequest::validate_in_memory`]) and `bimodal` is the approach
//! curve of a multifrequency drive (`super::curves::check_bimodal`).

use super::reconstruct_document::FromDocument;
use super::run::{Bimodal, Request, Resolved};
use super::{
    ApproachRequest, AttractorsRequest, BasinsRequest, ContinuationRequest, ConvergeRequest,
    FitRequest, FmRequest, GlobalContinuationRequest, LyapunovRequest, ModesRequest,
    ObserveRequest, OrbitRequest, PeakForceRequest, ReconstructRequest, ResonanceRequest,
    SimulateRequest,
};
use crate::error::SimError;
use serde::de::{Deserialize, Deserializer};
use serde_json::Value;

/// The names of the analyses [`parse`] knows.
pub const NAMES: [&str; 20] = [
    "modes",
    "simulate",
    "converge",
    "attractors",
    "global_continuation",
    "orbit",
    "continuation",
    "lyapunov",
    "observe",
    "approach",
    "bimodal",
    "resonance",
    "basins",
    "fm",
    "reconstruct",
    "peakforce",
    "fit",
    "fit_map",
    "thermal",
    "calibrate",
];

/// An analysis request parsed by name ([`parse`]): the request of its name, as data. Its
/// checks are here ([`NamedRequest::validate`]); running it to its outcome is the study
/// layer's.
#[derive(Debug, Clone)]
pub struct NamedRequest(pub(crate) Parsed);

/// The request of each name.
#[derive(Debug, Clone)]
pub(crate) enum Parsed {
    /// `modes`.
    Modes(ModesRequest),
    /// `simulate`.
    Simulate(SimulateRequest),
    /// `converge`.
    Converge(ConvergeRequest),
    /// `attractors`.
    Attractors(AttractorsRequest),
    /// `global_continuation`.
    GlobalContinuation(GlobalContinuationRequest),
    /// `orbit`.
    Orbit(OrbitRequest),
    /// `continuation`.
    Continuation(ContinuationRequest),
    /// `lyapunov`.
    Lyapunov(LyapunovRequest),
    /// `observe`.
    Observe(ObserveRequest),
    /// `approach`.
    Approach(ApproachRequest),
    /// `bimodal`.
    Bimodal(Bimodal),
    /// `resonance`.
    Resonance(ResonanceRequest),
    /// `basins`.
    Basins(BasinsRequest),
    /// `fm`.
    Fm(FmRequest),
    /// `reconstruct`.
    Reconstruct(ReconstructRequest),
    /// `reconstruct_document`.
    ReconstructDocument(FromDocument),
    /// `peakforce`.
    PeakForce(PeakForceRequest),
    /// `fit`.
    Fit(FitRequest),
    /// `fit_map`.
    FitMap(super::FitMapRequest),
    /// `thermal`.
    Thermal(super::ThermalRequest),
    /// `calibrate`.
    Calibrate(super::CalibrateRequest),
}

/// `$body` on the request `$r` of every variant of a [`NamedRequest`]'s `Parsed` but `simulate` (its
/// trajectory recorded whole in memory) and `reconstruct_document` (a reconstruction from a
/// document), which take their own arms: each request is an analysis of its own.
macro_rules! each_request {
    ($named:expr, $r:ident => $body:expr, Simulate($s:ident) => $simulate:expr,
     ReconstructDocument($f:ident) => $document:expr $(,)?) => {
        match $named {
            $crate::request::named::Parsed::Modes($r) => $body,
            $crate::request::named::Parsed::Converge($r) => $body,
            $crate::request::named::Parsed::Attractors($r) => $body,
            $crate::request::named::Parsed::GlobalContinuation($r) => $body,
            $crate::request::named::Parsed::Orbit($r) => $body,
            $crate::request::named::Parsed::Continuation($r) => $body,
            $crate::request::named::Parsed::Lyapunov($r) => $body,
            $crate::request::named::Parsed::Observe($r) => $body,
            $crate::request::named::Parsed::Approach($r) => $body,
            $crate::request::named::Parsed::Bimodal($r) => $body,
            $crate::request::named::Parsed::Resonance($r) => $body,
            $crate::request::named::Parsed::Basins($r) => $body,
            $crate::request::named::Parsed::Fm($r) => $body,
            $crate::request::named::Parsed::Reconstruct($r) => $body,
            $crate::request::named::Parsed::PeakForce($r) => $body,
            $crate::request::named::Parsed::Fit($r) => $body,
            $crate::request::named::Parsed::FitMap($r) => $body,
            $crate::request::named::Parsed::Thermal($r) => $body,
            $crate::request::named::Parsed::Calibrate($r) => $body,
            $crate::request::named::Parsed::Simulate($s) => $simulate,
            $crate::request::named::Parsed::ReconstructDocument($f) => $document,
        }
    };
}
pub(crate) use each_request;

impl NamedRequest {
    /// Check every option on `model` without computing (before a front end's side effects):
    /// the probe held against what the request uses of it, then the request's checks.
    ///
    /// # Errors
    /// The request's validation errors, naming the parameter and its range.
    pub fn validate(&self, model: &Resolved) -> Result<(), SimError> {
        each_request!(&self.0, r => super::run::validate(r, model),
            Simulate(s) => s.validate_in_memory(&model.params).map(|_| ()),
            ReconstructDocument(f) => FromDocument::validate(f))
    }
    /// What the request costs on `model` ([`super::Request::cost`]; `simulate`'s is its
    /// recording's, [`SimulateRequest::in_memory_cost`]); `None` for `reconstruct_document`,
    /// whose cost is its reconstruction's, known once its document is read.
    ///
    /// # Errors
    /// The request's validation errors.
    pub fn cost(&self, model: &Resolved) -> Result<Option<super::limits::Cost>, SimError> {
        each_request!(&self.0, r => r.cost(model).map(Some),
            Simulate(s) => s.in_memory_cost(&model.params).map(Some),
            ReconstructDocument(_f) => Ok(None))
    }
    /// What the request uses of a probe ([`super::Request::probe_needs`]).
    pub fn probe_needs(&self) -> crate::probe::ProbeNeeds {
        each_request!(&self.0, r => r.probe_needs(),
            Simulate(_s) => crate::probe::ProbeNeeds::Oscillation,
            ReconstructDocument(_f) => crate::probe::ProbeNeeds::Oscillation)
    }
}

/// The request of analysis `name` ([`NAMES`], and `reconstruct_document`) from `d`; `None`
/// for another name.
///
/// # Errors
/// The deserialiser's: an unknown keyword (`deny_unknown_fields`), a value of the wrong type.
pub fn parse<'de, D: Deserializer<'de>>(
    name: &str,
    d: D,
) -> Result<Option<NamedRequest>, D::Error> {
    use Parsed as N;
    fn door<'de, A, D>(d: D, named: fn(A) -> Parsed) -> Result<Option<NamedRequest>, D::Error>
    where
        A: Deserialize<'de>,
        D: Deserializer<'de>,
    {
        Ok(Some(NamedRequest(named(A::deserialize(d)?))))
    }
    match name {
        "modes" => door(d, N::Modes),
        "simulate" => door(d, N::Simulate),
        "converge" => door(d, N::Converge),
        "attractors" => door(d, N::Attractors),
        "global_continuation" => door(d, N::GlobalContinuation),
        "orbit" => door(d, N::Orbit),
        "continuation" => door(d, N::Continuation),
        "lyapunov" => door(d, N::Lyapunov),
        "observe" => door(d, N::Observe),
        "approach" => door(d, N::Approach),
        "bimodal" => door(d, N::Bimodal),
        "resonance" => door(d, N::Resonance),
        "basins" => door(d, N::Basins),
        "fm" => door(d, N::Fm),
        "reconstruct" => door(d, N::Reconstruct),
        // the reconstruction of an fm or AM document (not in NAMES: no schema of its own)
        "reconstruct_document" => door(d, N::ReconstructDocument),
        "peakforce" => door(d, N::PeakForce),
        "fit" => door(d, N::Fit),
        "fit_map" => door(d, N::FitMap),
        "thermal" => door(d, N::Thermal),
        "calibrate" => door(d, N::Calibrate),
        _ => Ok(None),
    }
}

/// The default request of analysis `name` as JSON (what a front end's keywords default to);
/// `None` for a name without one. Besides [`NAMES`] (but `modes` and `bimodal`, which is
/// `approach`'s), `bifurcation` and `chart`.
pub fn default_request(name: &str) -> Option<Value> {
    use super::{BifurcationRequest, ChartRequest};
    fn v<T: serde::Serialize + Default>() -> Option<Value> {
        serde_json::to_value(T::default()).ok()
    }
    match name {
        "simulate" => v::<SimulateRequest>(),
        "converge" => v::<ConvergeRequest>(),
        "bifurcation" => v::<BifurcationRequest>(),
        "attractors" => v::<AttractorsRequest>(),
        "global_continuation" => v::<GlobalContinuationRequest>(),
        "orbit" => v::<OrbitRequest>(),
        "continuation" => v::<ContinuationRequest>(),
        "lyapunov" => v::<LyapunovRequest>(),
        "observe" => v::<ObserveRequest>(),
        "approach" => v::<ApproachRequest>(),
        "resonance" => v::<ResonanceRequest>(),
        "basins" => v::<BasinsRequest>(),
        "chart" => v::<ChartRequest>(),
        "reconstruct" => v::<ReconstructRequest>(),
        "fm" => v::<FmRequest>(),
        "peakforce" => v::<super::PeakForceRequest>(),
        "fit" => v::<super::FitRequest>(),
        "fit_map" => v::<super::FitMapRequest>(),
        "thermal" => v::<super::ThermalRequest>(),
        "calibrate" => v::<super::CalibrateRequest>(),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::Map;

    #[test]
    fn every_name_parses_its_default() {
        for name in NAMES {
            let r = parse(name, Value::Object(Map::new())).expect("parses");
            assert!(r.is_some(), "{name}");
        }
        assert!(parse("nope", Value::Null).expect("no error").is_none());
    }

    #[test]
    fn an_unknown_keyword_is_refused() {
        let r = parse("orbit", serde_json::json!({"nope": 1}));
        assert!(r.is_err());
    }
}

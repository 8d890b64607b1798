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

/// The analyses by name, each once (`"name" => Variant(Request)`, in the order of [`NAMES`]; `own`
/// where `each_request!` gives it its own arm): [`NAMES`], the variants of `Parsed` (and
/// `reconstruct_document`'s, which has no name of its own there), [`parse`]'s arms and
/// `each_request!`. Read entry by entry (`@read`, the variants of the common arm gathered), then
/// written (`@write`, given the `$` that the written `each_request!` needs as `$d`).
macro_rules! analyses {
    (@read [$($all:tt)*] [$($plain:ident)*]) => {
        analyses!(@write ($) [$($all)*] [$($plain)*]);
    };
    (@read [$($all:tt)*] [$($plain:ident)*] $name:literal => $v:ident($t:ty) own, $($rest:tt)*) => {
        analyses!(@read [$($all)* ($name $v $t)] [$($plain)*] $($rest)*);
    };
    (@read [$($all:tt)*] [$($plain:ident)*] $name:literal => $v:ident($t:ty), $($rest:tt)*) => {
        analyses!(@read [$($all)* ($name $v $t)] [$($plain)* $v] $($rest)*);
    };
    (@write ($d:tt) [$(($name:literal $v:ident $t:ty))*] [$($plain:ident)*]) => {
        /// The names of the analyses [`parse`] knows.
        pub const NAMES: [&str; [$($name),*].len()] = [$($name),*];

        /// The request of each name.
        #[derive(Debug, Clone)]
        pub(crate) enum Parsed {
            $(#[doc = concat!("`", $name, "`.")] $v($t),)*
            /// `reconstruct_document`.
            ReconstructDocument(FromDocument),
        }

        /// `$body` on the request `$r` of every variant of a [`NamedRequest`]'s `Parsed` but
        /// `simulate` (its trajectory recorded whole in memory) and `reconstruct_document` (a
        /// reconstruction from a document), which take their own arms: each request is an
        /// analysis of its own.
        macro_rules! each_request {
            ($d named:expr, $d r:ident => $d body:expr, Simulate($d s:ident) => $d simulate:expr,
             ReconstructDocument($d f:ident) => $d document:expr $d(,)?) => {
                match $d named {
                    $($crate::request::named::Parsed::$plain($d r) => $d body,)*
                    $crate::request::named::Parsed::Simulate($d s) => $d simulate,
                    $crate::request::named::Parsed::ReconstructDocument($d f) => $d document,
                }
            };
        }

        /// The request of analysis `name` ([`NAMES`], and `reconstruct_document`) from `d`;
        /// `None` for another name.
        ///
        /// # Errors
        /// The deserialiser's: an unknown keyword (`deny_unknown_fields`), a value of the wrong
        /// type.
        pub fn parse<'de, D: Deserializer<'de>>(
            name: &str,
            d: D,
        ) -> Result<Option<NamedRequest>, D::Error> {
            let named = match name {
                $($name => Parsed::$v(<$t>::deserialize(d)?),)*
                // the reconstruction of an fm or AM document (not in NAMES: no schema of its own)
                "reconstruct_document" => Parsed::ReconstructDocument(FromDocument::deserialize(d)?),
                _ => return Ok(None),
            };
            Ok(Some(NamedRequest(named)))
        }
    };
    ($($entries:tt)*) => {
        analyses!(@read [] [] $($entries)*);
    };
}

analyses! {
    "modes" => Modes(ModesRequest),
    "simulate" => Simulate(SimulateRequest) own,
    "converge" => Converge(ConvergeRequest),
    "attractors" => Attractors(AttractorsRequest),
    "global_continuation" => GlobalContinuation(GlobalContinuationRequest),
    "orbit" => Orbit(OrbitRequest),
    "continuation" => Continuation(ContinuationRequest),
    "lyapunov" => Lyapunov(LyapunovRequest),
    "observe" => Observe(ObserveRequest),
    "approach" => Approach(ApproachRequest),
    "bimodal" => Bimodal(Bimodal),
    "resonance" => Resonance(ResonanceRequest),
    "basins" => Basins(BasinsRequest),
    "fm" => Fm(FmRequest),
    "reconstruct" => Reconstruct(ReconstructRequest),
    "peakforce" => PeakForce(PeakForceRequest),
    "fit" => Fit(FitRequest),
    "fit_map" => FitMap(super::FitMapRequest),
    "thermal" => Thermal(super::ThermalRequest),
    "calibrate" => Calibrate(super::CalibrateRequest),
}

/// An analysis request parsed by name ([`parse`]): the request of its name, as data. Its
/// checks are here ([`NamedRequest::validate`]); running it to its outcome is the study
/// layer's.
#[derive(Debug, Clone)]
pub struct NamedRequest(pub(crate) Parsed);

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

/// The default request of analysis `name` as JSON (what a front end's keywords default to);
/// `None` for a name without one. Besides [`NAMES`] (but `modes` and `bimodal`, which is
/// `approach`'s), `bifurcation` and `chart`.
pub fn default_request(name: &str) -> Option<Value> {
    let named = match name {
        "modes" | "bimodal" => return None,
        "bifurcation" => return serde_json::to_value(super::BifurcationRequest::default()).ok(),
        "chart" => return serde_json::to_value(super::ChartRequest::default()).ok(),
        // every field of a request has its default (`#[serde(default)]`)
        _ => parse(name, Value::Object(serde_json::Map::new())).ok()??,
    };
    each_request!(&named.0, r => serde_json::to_value(r).ok(),
        Simulate(s) => serde_json::to_value(s).ok(),
        ReconstructDocument(_f) => None)
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

//! Every analysis by its name, through one door: a front end that knows an analysis only by
//! its name (`"orbit"`) and its keywords — Python's one `run`, the WebAssembly engine — parses
//! the request by name ([`parse`], with the request's serde names, `deny_unknown_fields` and
//! defaults; [`default_request`] gives the defaults), validates it ([`Named::validate`]) and
//! runs it ([`Named::run`]) to an [`Outcome`]: the JSON document, the result's arrays as
//! [`Layout`]s ([`Datasets`], declared beside the results in `super::datasets`) and the
//! scalars a dataset carries as attributes.
//!
//! The names are those of [`NAMES`]; `simulate` records its trajectory whole in memory
//! (its own budgets, [`SimulateRequest::validate_in_memory`]) and `bimodal` is the approach
//! curve of a multifrequency drive (`super::curves::check_bimodal`).

use super::reconstruct_document::FromDocument;
#[cfg(feature = "files")]
use super::run::document;
use super::run::{run, Analysis, Resolved};
use super::{
    ApproachRequest, AttractorsRequest, BasinsRequest, ContinuationRequest, ConvergeRequest,
    FmRequest, GlobalContinuationRequest, LyapunovRequest, ModesRequest, ObserveRequest,
    OrbitRequest, ReconstructRequest, ResonanceRequest, SimulateRequest,
};
use crate::analysis::progress::Progress;
use crate::error::SimError;
use crate::layout::Layout;
use crate::model::CantileverModel;
use crate::report;
use serde::de::{Deserialize, Deserializer};
use serde_json::{Map, Value};

/// The names of the analyses [`parse`] knows.
pub const NAMES: [&str; 17] = [
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
];

/// What a named analysis returns: its document, its arrays and its scalars.
#[derive(Debug, Clone, Default)]
pub struct Outcome {
    /// The JSON document (`--json`, Python's `to_dict()`), with `"si"` for a probe's model.
    pub document: Value,
    /// The result's arrays, each a named [`Layout`] (an `xarray.Dataset` in Python).
    pub datasets: Vec<(String, Layout)>,
    /// Scalars of the result that its document does not hold in the form a front end shows
    /// them (a dataset's attributes: a simulation's end time in its unit, a branch's
    /// parameter).
    pub facts: Map<String, Value>,
}

/// A result's layouts, each named, and its scalars ([`Outcome::facts`]).
pub(crate) type Arrays = (Vec<(String, Layout)>, Map<String, Value>);

/// The arrays of an analysis' result, beside its document: empty by default.
pub trait Datasets: Analysis {
    /// The result's layouts, each named, and its scalars ([`Outcome::facts`]).
    ///
    /// # Errors
    /// [`SimError`] where the layout needs the model built again (an invalid `params`).
    fn datasets(&self, _model: &Resolved, _output: &Self::Output) -> Result<Arrays, SimError> {
        Ok((Vec::new(), Map::new()))
    }
}

/// An analysis request parsed by name ([`parse`]), ready to run on a model.
pub trait Named: Send {
    /// Check every option on `model` without computing (before a front end's side effects).
    ///
    /// # Errors
    /// The request's validation errors, naming the parameter and its range.
    fn validate(&self, model: &Resolved) -> Result<(), SimError>;
    /// Run it on `model` ([`run`]: validated, its cost held against the budgets), counting in
    /// `progress`, to its [`Outcome`].
    ///
    /// # Errors
    /// As [`run`].
    fn run(&self, model: &Resolved, progress: &Progress) -> Result<Outcome, SimError>;
    /// Whether the run counts its work in its progress and stops at a cancel (`false` for
    /// one short computation, or a recording that cannot stop early).
    fn checks_cancel(&self) -> bool {
        true
    }
    /// What the request uses of a probe ([`super::Request::probe_needs`]).
    fn probe_needs(&self) -> crate::probe::ProbeNeeds {
        crate::probe::ProbeNeeds::Oscillation
    }
}

/// An [`Analysis`] with its [`Datasets`] as a [`Named`] one; `quick` for one that neither
/// counts nor checks its progress.
struct Door<A> {
    request: A,
    quick: bool,
}

impl<A> Named for Door<A>
where
    A: Datasets + Send,
{
    fn validate(&self, model: &Resolved) -> Result<(), SimError> {
        super::run::validate(&self.request, model)
    }
    fn run(&self, model: &Resolved, progress: &Progress) -> Result<Outcome, SimError> {
        let doc = run(&self.request, model, progress)?;
        let (datasets, facts) = self.request.datasets(model, &doc.output)?;
        Ok(Outcome {
            document: doc.json,
            datasets,
            facts,
        })
    }
    fn checks_cancel(&self) -> bool {
        !self.quick
    }
    fn probe_needs(&self) -> crate::probe::ProbeNeeds {
        self.request.probe_needs()
    }
}

/// `simulate`: one trajectory recorded whole in memory, laid out by
/// [`report::simulate_layout`] (in SI with a probe), with its end time, switchings, body
/// contact, integrator and transient as facts.
struct Simulate(SimulateRequest);

impl Named for Simulate {
    fn validate(&self, model: &Resolved) -> Result<(), SimError> {
        self.0.validate_in_memory(&model.params).map(|_| ())
    }
    fn run(&self, model: &Resolved, _: &Progress) -> Result<Outcome, SimError> {
        let p = &model.params;
        let span = self.0.validate_in_memory(p)?;
        let su = report::SeriesUnits::new(p, model.probe.as_ref());
        let m = CantileverModel::new(p)?;
        let (tr, integrator) = self.0.record_whole(&m, &span)?;
        let layout = report::simulate_layout(&m, &tr, &su, self.0.samples_per_period);
        let document = report::with_si(report::simulate(&m, &tr), model.probe.as_ref(), p);
        let facts = serde_json::json!({
            "time": su.names().time,
            "tau_end": su.t(tr.tau_end),
            "switchings": tr.events.len(),
            "body_contact": tr.body_contact,
            "integrator": integrator,
            "transient_tau": su.t(span.transient_tau),
        });
        Ok(Outcome {
            document,
            datasets: vec![("simulate".into(), layout)],
            facts: facts.as_object().cloned().unwrap_or_default(),
        })
    }
    fn checks_cancel(&self) -> bool {
        false
    }
}

/// `reconstruct_document`: a reconstruction from an `fm` or AM document.
impl Named for FromDocument {
    fn validate(&self, _model: &Resolved) -> Result<(), SimError> {
        FromDocument::validate(self)
    }
    fn run(&self, model: &Resolved, progress: &Progress) -> Result<Outcome, SimError> {
        let (document, layout) = FromDocument::run(self, model, progress)?;
        Ok(Outcome {
            document,
            datasets: vec![("reconstruct".into(), layout)],
            ..Outcome::default()
        })
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
) -> Result<Option<Box<dyn Named>>, D::Error> {
    fn door<'de, A, D>(d: D, quick: bool) -> Result<Option<Box<dyn Named>>, D::Error>
    where
        A: Datasets + Deserialize<'de> + Send + 'static,
        D: Deserializer<'de>,
    {
        let request = A::deserialize(d)?;
        Ok(Some(Box::new(Door { request, quick })))
    }
    match name {
        "modes" => door::<ModesRequest, D>(d, true),
        "simulate" => Ok(Some(Box::new(Simulate(SimulateRequest::deserialize(d)?)))),
        "converge" => door::<ConvergeRequest, D>(d, false),
        "attractors" => door::<AttractorsRequest, D>(d, false),
        "global_continuation" => door::<GlobalContinuationRequest, D>(d, false),
        "orbit" => door::<OrbitRequest, D>(d, true),
        "continuation" => door::<ContinuationRequest, D>(d, false),
        "lyapunov" => door::<LyapunovRequest, D>(d, false),
        "observe" => door::<ObserveRequest, D>(d, true),
        "approach" => door::<ApproachRequest, D>(d, false),
        "bimodal" => door::<super::run::Bimodal, D>(d, false),
        "resonance" => door::<ResonanceRequest, D>(d, false),
        "basins" => door::<BasinsRequest, D>(d, false),
        "fm" => door::<FmRequest, D>(d, false),
        "reconstruct" => door::<ReconstructRequest, D>(d, false),
        // the reconstruction of an fm or AM document (not in NAMES: no schema of its own)
        "reconstruct_document" => Ok(Some(Box::new(FromDocument::deserialize(d)?))),
        "peakforce" => door::<super::PeakForceRequest, D>(d, false),
        "fit" => door::<super::FitRequest, D>(d, true),
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
        _ => None,
    }
}

/// The document of a study's `output` that a front end ran into a store of its own, with its
/// datasets: as [`Named::run`]'s outcome for the same request.
///
/// # Errors
/// As [`document`] and [`Datasets::datasets`].
#[cfg(feature = "files")]
pub(crate) fn outcome<A: Datasets>(
    request: &A,
    model: &Resolved,
    output: &A::Output,
) -> Result<Outcome, SimError> {
    let (datasets, facts) = request.datasets(model, output)?;
    Ok(Outcome {
        document: document(request, model, output)?,
        datasets,
        facts,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_parses_its_default_and_runs_modes() {
        for name in NAMES {
            let r = parse(name, Value::Object(Map::new())).expect("parses");
            assert!(r.is_some(), "{name}");
        }
        assert!(parse("nope", Value::Null).expect("no error").is_none());
        let modes = parse("modes", Value::Object(Map::new())).unwrap().unwrap();
        let out = modes
            .run(&Resolved::plain(Default::default()), &Progress::default())
            .expect("runs");
        assert_eq!(out.datasets.len(), 2);
        assert!(out.document.get("free").is_some() || out.document.is_object());
    }

    #[test]
    fn an_unknown_keyword_is_refused() {
        let r = parse("orbit", serde_json::json!({"nope": 1}));
        assert!(r.is_err());
    }
}

//! Running a request parsed by name (`request::named`): [`NamedRequest::run`] to an
//! [`Outcome`] — the JSON document, the result's arrays as [`Layout`]s ([`Datasets`],
//! declared beside the results in `super::datasets`) and the scalars a dataset carries as
//! attributes — the one door of Python and WebAssembly.

use crate::analysis::progress::Progress;
use crate::error::SimError;
use crate::layout::Layout;
use crate::model::CantileverModel;
use crate::report;
use crate::request::named::{each_request, NamedRequest};
use crate::request::reconstruct_document::FromDocument;
#[cfg(feature = "files")]
use crate::request::run::document;
use crate::request::run::{run, Analysis, Resolved};
use crate::request::SimulateRequest;
use serde_json::{Map, Value};

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

impl NamedRequest {
    /// Run it on `model` (`crate::request::run()`: validated, its cost held against the
    /// budgets), counting in `progress`, to its [`Outcome`].
    ///
    /// # Errors
    /// As `crate::request::run()`.
    pub fn run(&self, model: &Resolved, progress: &Progress) -> Result<Outcome, SimError> {
        each_request!(&self.0, r => door(r, model, progress),
            Simulate(s) => progress.watch(|| simulate(s, model)),
            ReconstructDocument(f) => reconstruct_document(f, model, progress))
    }
}

/// An [`Analysis`] with its [`Datasets`] run to its [`Outcome`].
fn door<A: Datasets>(
    request: &A,
    model: &Resolved,
    progress: &Progress,
) -> Result<Outcome, SimError> {
    let doc = run(request, model, progress)?;
    let (datasets, facts) = request.datasets(model, &doc.output)?;
    Ok(Outcome {
        document: doc.json,
        datasets,
        facts,
    })
}

/// `simulate`: one trajectory recorded whole in memory, laid out by
/// [`report::simulate_layout`] (in SI with a probe), with its end time, switchings, body
/// contact, integrator and transient as facts.
fn simulate(request: &SimulateRequest, model: &Resolved) -> Result<Outcome, SimError> {
    let p = &model.params;
    let span = request.validate_in_memory(p)?;
    let su = report::SeriesUnits::new(p, model.probe.as_ref());
    let m = CantileverModel::new(p)?;
    let (tr, integrator) = request.record_whole(&m, model.probe.as_ref(), &span)?;
    let layout = report::simulate_layout(&m, &tr, &su, request.samples_per_period);
    let mut document = report::with_si(
        report::simulate(&m, &tr, request.energy_balance),
        model.probe.as_ref(),
        p,
    );
    request.thermal_into(&mut document, &p.contact_law);
    // a trajectory from its start, as the streamed run's (`SimulateStream`)
    report::Convergence::exact("trajectory").write_into(&mut document);
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

/// `reconstruct_document`: a reconstruction from an `fm` or AM document.
fn reconstruct_document(
    request: &FromDocument,
    model: &Resolved,
    progress: &Progress,
) -> Result<Outcome, SimError> {
    let (document, layout) = FromDocument::run(request, model, progress)?;
    Ok(Outcome {
        document,
        datasets: vec![("reconstruct".into(), layout)],
        ..Outcome::default()
    })
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
    use crate::request::named::parse;

    #[test]
    fn modes_runs_by_name() {
        let modes = parse("modes", Value::Object(Map::new())).unwrap().unwrap();
        let out = modes
            .run(&Resolved::plain(Default::default()), &Progress::default())
            .expect("runs");
        assert_eq!(out.datasets.len(), 2);
        assert!(out.document.get("free").is_some() || out.document.is_object());
    }
}

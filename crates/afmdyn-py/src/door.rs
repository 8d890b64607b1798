//! The one door of every analysis: `run(name, request, params, probe, progress)` parses the
//! request by name in the library ([`afmdyn::request::named::parse`]), validates it, runs it
//! without the GIL ([`crate::run`]; cancellable where it checks its progress) and returns its
//! outcome: `json` (the document), `datasets` (each result layout as
//! [`crate::convert::layout_dict`], which `afmdyn._layout` turns into a dataset) and `facts`
//! (the result's scalars, a dict). The studies run into the command line's resumable store go
//! through `run_stored` (the library's [`afmdyn::study::stored`]), to the same outcome.

use crate::convert::{json_to_py, layout_dict};
use crate::errors::{lock_store, study_error};
use crate::errors::{probe_error, sim_error, value_error};
use crate::params::PyParams;
use crate::run::{run as run_job, Job};
use afmdyn::error::SimError;
use afmdyn::probe::{Probe, ProbeNeeds};
use afmdyn::request::Params;
use afmdyn::request::Progress;
use afmdyn::request::Resolved;
use afmdyn::study::named::Outcome;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The model of a call: `params` (default: the paper's set) and the probe file's text, read
/// for what the request uses of it (the command line's `--probe`).
fn resolved(
    params: Option<PyRef<'_, PyParams>>,
    probe: Option<String>,
    needs: ProbeNeeds,
) -> PyResult<Resolved> {
    Ok(Resolved {
        params: params.map_or_else(Params::default, |p| p.inner),
        probe: probe
            .map(|text| Probe::parse_for(&text, "probe", needs))
            .transpose()
            .map_err(probe_error)?,
    })
}

/// Run analysis `name` (`"orbit"`, …: `afmdyn.request.named.NAMES`) with the keywords
/// `request` on `params` (default: the paper's set) and the probe file's text `probe`:
/// `{"json": str, "datasets": {name: layout}, "facts": dict}`. `progress(done, total)` is
/// called at every poll.
#[pyfunction]
#[pyo3(signature = (name, request=None, params=None, probe=None, progress=None))]
pub fn run<'py>(
    py: Python<'py>,
    name: &str,
    request: Option<&Bound<'py, PyDict>>,
    params: Option<PyRef<'_, PyParams>>,
    probe: Option<String>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let named = crate::convert::named(name, request)?;
    let model = resolved(params, probe, named.probe_needs())?;
    named.validate(&model).map_err(sim_error)?;
    run_outcome(py, progress, move |p| named.run(&model, p))
}

/// Run `work` without the GIL ([`crate::run`]: an interrupt cancels its progress and waits
/// for it to stop) to the dict of its outcome ([`outcome_dict`]).
pub fn run_outcome<'py>(
    py: Python<'py>,
    progress: Option<Bound<'py, PyAny>>,
    work: impl FnOnce(&Progress) -> Result<Outcome, SimError> + Send + 'static,
) -> PyResult<Bound<'py, PyDict>> {
    let job = Job::default();
    let worker = job.clone();
    let outcome = run_job(py, &job, None, progress.as_ref(), move || {
        work(&worker.progress)
    })?
    .map_err(sim_error)?;
    outcome_dict(py, outcome)
}

/// Run study `name` (`"bifurcation"`, `"basins"`, `"global_continuation"`, `"approach"`,
/// `"bimodal"`, `"resonance"`) as [`run`] does, into the store of the directory `store`
/// (locked, created if needed; `resume` continues an interrupted run of the same request; no
/// store: in memory): what `run` returns.
#[pyfunction]
#[pyo3(signature = (name, request=None, params=None, probe=None, progress=None, store=None, resume=false))]
pub fn run_stored(
    name: &str,
    request: Option<&Bound<'_, PyDict>>,
    params: Option<PyRef<'_, PyParams>>,
    probe: Option<String>,
    progress: Option<Bound<'_, PyAny>>,
    store: Option<std::path::PathBuf>,
    resume: bool,
) -> PyResult<Py<PyDict>> {
    let stored = crate::convert::stored(name, request)?;
    let model = resolved(params, probe, stored.probe_needs())?;
    let study = stored.prepare(model).map_err(sim_error)?;
    if resume && store.is_none() {
        let msg = "resume=True needs store= (the directory of the interrupted run)";
        return Err(value_error(msg));
    }
    // locked here, before any work: a second run on the store is refused at once
    let lock = store.map(|dir| lock_store(&dir)).transpose()?;
    let job = Job::default();
    let worker = job.clone();
    // the call is attached to the interpreter already: its token from there, not as an
    // eighth argument
    Python::attach(|py| {
        let outcome = run_job(py, &job, None, progress.as_ref(), move || {
            study.run(lock.as_ref(), resume, &worker.progress)
        })?
        .map_err(study_error)?;
        outcome_dict(py, outcome).map(Bound::unbind)
    })
}

/// An [`Outcome`] as `run` returns it.
pub fn outcome_dict(py: Python<'_>, outcome: Outcome) -> PyResult<Bound<'_, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("json", outcome.document.to_string())?;
    let datasets = PyDict::new(py);
    for (name, layout) in outcome.datasets {
        datasets.set_item(name, layout_dict(py, layout)?)?;
    }
    out.set_item("datasets", datasets)?;
    let facts = serde_json::Value::Object(outcome.facts).to_string();
    out.set_item("facts", json_to_py(py, &facts)?)?;
    Ok(out)
}

//! The studies that Python runs resumably in the command line's store (`store=`, `resume=`):
//! a basin map ([`BasinStudy`]), a global continuation ([`ContinuationStudy`]) and the
//! approach and resonance curves ([`CurveStudy`]: the stepped sweeps with branch continuation
//! of [`afmdyn::analysis::stepped`]), returning what the one door returns for the same request
//! ([`crate::door::outcome_dict`]); in memory (no `store`) they go through the door.

use crate::analyses::{checkpoint_error, lock_store, study_error};
use crate::errors::{sim_error, value_error};
use crate::params::PyParams;
use crate::run::{run, Job, Stop};
use afmdyn::analysis::progress::Progress;
use afmdyn::analysis::stepped::SteppedCurve;
use afmdyn::request::{
    ApproachRequest, BasinsRequest, Datasets, GlobalContinuationRequest, Resolved, ResonanceRequest,
};
use afmdyn::study::basins::{basin_store, BasinStudy};
use afmdyn::study::global_continuation::{continuation_store, ContinuationStudy};
use afmdyn::study::stepped::{curve_store, CurveStudy};
use afmdyn::study::task_store::{StoredTasks, TaskStore};
use afmdyn::study::{execute, Study};
use afmdyn::{Params, SimError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::path::PathBuf;

/// Where a study runs: the store of a directory.
struct Place<'py> {
    params: Params,
    store: PathBuf,
    resume: bool,
    progress: Option<Bound<'py, PyAny>>,
    probe: Option<String>,
}

impl<'py> Place<'py> {
    fn new(
        params: Params,
        store: Option<PathBuf>,
        resume: bool,
        progress: Option<Bound<'py, PyAny>>,
        probe: Option<String>,
    ) -> PyResult<Self> {
        let Some(store) = store else {
            return Err(value_error(
                "resume=True needs store= (the directory of the interrupted run)",
            ));
        };
        Ok(Place {
            params,
            store,
            resume,
            progress,
            probe,
        })
    }

    /// The outcome of `request` on the place's parameters: the study `of` the request and
    /// the model run into the store `open` makes of the directory's lock (resumed with
    /// `resume`) and its output `finish`ed from the stored records (on `threads`, counting in
    /// the run's progress), with its document and datasets as the door's.
    fn output<A, S, R>(
        self,
        py: Python<'py>,
        request: A,
        of: impl FnOnce(&A, &Resolved) -> Result<S, SimError>,
        threads: Option<usize>,
        open: fn(&afmdyn::request::DirLock) -> TaskStore<'_, R>,
        finish: impl FnOnce(&S, Vec<(usize, R)>, &Progress) -> Result<A::Output, SimError>
            + Send
            + 'static,
    ) -> PyResult<Bound<'py, PyDict>>
    where
        A: Datasets + Send + 'static,
        A::Output: Send + 'static,
        S: Study<Record = (usize, R)> + Send + 'static,
        S::Done: StoredTasks<R>,
        R: Serialize + DeserializeOwned + Clone + Send + 'static,
    {
        let model = Resolved {
            params: self.params,
            probe: crate::door::probe_of(self.probe)?,
        };
        let study = of(&request, &model).map_err(sim_error)?;
        let lock = lock_store(&self.store)?;
        let resume = self.resume;
        let job = Job::default();
        let worker = job.clone();
        let output = run(
            py,
            &job,
            None,
            self.progress.as_ref(),
            Stop::Cancellable,
            move || -> PyResult<A::Output> {
                let mut s = open(&lock);
                execute(&study, &mut s, resume, threads, &*worker.progress).map_err(study_error)?;
                let records = s.records().map_err(checkpoint_error)?;
                let progress = &*worker.progress;
                afmdyn::request::in_pool(threads, || finish(&study, records, progress))
                    .map_err(sim_error)
            },
        )??;
        let outcome = afmdyn::request::named::outcome(&request, &model, &output);
        crate::door::outcome_dict(py, outcome.map_err(sim_error)?)
    }
}

/// A basin map over two coordinates of the initial state (see `afmdyn.basins`); with `store`
/// (a directory) its rows are kept there as `afmdyn basins --out DIR` keeps them, and
/// `resume` continues an interrupted map of the same request.
#[pyfunction]
#[pyo3(signature = (params, request=None, progress=None, probe=None, store=None, resume=false))]
pub fn basins<'py>(
    py: Python<'py>,
    params: PyRef<'_, PyParams>,
    request: Option<&Bound<'py, PyDict>>,
    progress: Option<Bound<'py, PyAny>>,
    probe: Option<String>,
    store: Option<PathBuf>,
    resume: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let request: BasinsRequest = crate::convert::request("basins", request)?;
    let place = Place::new(params.inner, store, resume, progress, probe)?;
    let threads = request.threads;
    place.output(
        py,
        request,
        |r, m| BasinStudy::new(r, &m.params),
        threads,
        basin_store,
        |s: &BasinStudy, records, _| s.map(records.into_iter().map(|(_, r)| r)),
    )
}

/// Attractors continued over a parameter (global continuation): the JSON document of
/// `afmdyn attractors --sweep --json` and its layout (the Python layer builds the dataset from
/// it); with `store` (a directory) its values are kept there as `afmdyn attractors --sweep
/// --out DIR` keeps them, and `resume` continues an interrupted continuation of the same
/// request.
#[pyfunction]
#[pyo3(signature = (params, request=None, progress=None, probe=None, store=None, resume=false))]
pub fn global_continuation<'py>(
    py: Python<'py>,
    params: PyRef<'_, PyParams>,
    request: Option<&Bound<'py, PyDict>>,
    progress: Option<Bound<'py, PyAny>>,
    probe: Option<String>,
    store: Option<PathBuf>,
    resume: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let request: GlobalContinuationRequest =
        crate::convert::request("global_continuation", request)?;
    let place = Place::new(params.inner, store, resume, progress, probe)?;
    place.output(
        py,
        request,
        |r, m| ContinuationStudy::new(r, &m.params),
        None,
        continuation_store,
        |s: &ContinuationStudy, records, _| s.steps(records),
    )
}

/// A stepped curve's document: the request `R` named `name` on `params`, through
/// [`Place::output`] with the study `of` it.
fn curve<'py, R>(
    py: Python<'py>,
    name: &str,
    request: Option<&Bound<'py, PyDict>>,
    place: Place<'py>,
    of: fn(&R, &Resolved) -> Result<CurveStudy, SimError>,
) -> PyResult<Bound<'py, PyDict>>
where
    R: Datasets<Output = SteppedCurve> + DeserializeOwned + Send + 'static,
{
    let request: R = crate::convert::request(name, request)?;
    place.output(
        py,
        request,
        of,
        None,
        curve_store,
        |s: &CurveStudy, records, progress| s.curve(records, progress),
    )
}

/// The approach–retract curve over the rest distance z_c (`afmdyn approach`); with `store` (a
/// directory) its points are kept there as `afmdyn approach --out DIR` keeps them, and
/// `resume` continues an interrupted curve of the same request from its last stored point.
#[pyfunction]
#[pyo3(signature = (params, request=None, probe=None, progress=None, store=None, resume=false))]
pub fn approach<'py>(
    py: Python<'py>,
    params: PyRef<'_, PyParams>,
    request: Option<&Bound<'py, PyDict>>,
    probe: Option<String>,
    progress: Option<Bound<'py, PyAny>>,
    store: Option<PathBuf>,
    resume: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let place = Place::new(params.inner, store, resume, progress, probe)?;
    curve::<ApproachRequest>(py, "approach", request, place, CurveStudy::approach)
}

/// The bimodal (multifrequency) approach curve (`afmdyn bimodal`): the approach curve of a
/// drive with two or more components ([`afmdyn::request::curves::check_bimodal`]), its
/// document with the per-component columns; `store` and `resume` as [`approach`]'s.
#[pyfunction]
#[pyo3(signature = (params, request=None, probe=None, progress=None, store=None, resume=false))]
pub fn bimodal<'py>(
    py: Python<'py>,
    params: PyRef<'_, PyParams>,
    request: Option<&Bound<'py, PyDict>>,
    probe: Option<String>,
    progress: Option<Bound<'py, PyAny>>,
    store: Option<PathBuf>,
    resume: bool,
) -> PyResult<Bound<'py, PyDict>> {
    afmdyn::request::curves::check_bimodal(&params.inner).map_err(crate::errors::sim_error)?;
    let place = Place::new(params.inner, store, resume, progress, probe)?;
    curve::<ApproachRequest>(py, "approach", request, place, CurveStudy::approach)
}

/// The resonance curve near mode `mode` (`afmdyn resonance`); `store` and `resume` as
/// [`approach`]'s.
#[pyfunction]
#[pyo3(signature = (params, request=None, probe=None, progress=None, store=None, resume=false))]
pub fn resonance<'py>(
    py: Python<'py>,
    params: PyRef<'_, PyParams>,
    request: Option<&Bound<'py, PyDict>>,
    probe: Option<String>,
    progress: Option<Bound<'py, PyAny>>,
    store: Option<PathBuf>,
    resume: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let place = Place::new(params.inner, store, resume, progress, probe)?;
    curve::<ResonanceRequest>(py, "resonance", request, place, CurveStudy::resonance)
}

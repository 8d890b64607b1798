//! `afmdyn.basins`: the library's basin map request ([`afmdyn::request::BasinsRequest`]) run
//! as its study ([`BasinStudy`]) — in memory, or in the command line's resumable store
//! (`store=`, `resume=`) — with its document and arrays ([`BasinArrays`]), for the Python
//! layer's `xarray.Dataset`.

use crate::analyses::{analysis, checkpoint_error, lock_store, study_error};
use crate::convert::Out;
use crate::errors::{probe_error, sim_error, value_error};
use crate::params::PyParams;
use crate::run::{run, Job, Stop};
use afmdyn::probe::Probe;
use afmdyn::request::{BasinArrays, BasinsRequest, Resolved};
use afmdyn::study::basins::{basin_store, BasinStudy};
use afmdyn::study::execute;
use pyo3::prelude::*;
use pyo3::types::PyDict;

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
    store: Option<std::path::PathBuf>,
    resume: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let request: BasinsRequest = crate::convert::request("basins", request)?;
    if resume && store.is_none() {
        return Err(value_error(
            "resume=True needs store= (the directory of the interrupted map)",
        ));
    }
    let study = BasinStudy::new(&request, &params.inner).map_err(sim_error)?;
    let (map, json) = match store {
        None => {
            let doc = analysis(py, request, params.inner, probe, progress.as_ref(), true)?;
            (doc.output, doc.json)
        }
        Some(dir) => {
            let probe = probe
                .map(|text| Probe::parse(&text, "probe"))
                .transpose()
                .map_err(probe_error)?;
            let lock = lock_store(&dir)?;
            let threads = request.threads;
            let job = Job::default();
            let worker = job.clone();
            let ran = study.clone();
            let map = run(
                py,
                &job,
                None,
                progress.as_ref(),
                Stop::Cancellable,
                move || -> PyResult<_> {
                    let mut s = basin_store(&lock);
                    execute(&ran, &mut s, resume, threads, &*worker.progress)
                        .map_err(study_error)?;
                    let rows = s.records().map_err(checkpoint_error)?;
                    afmdyn::request::in_pool(threads, || ran.map(rows.into_iter().map(|(_, r)| r)))
                        .map_err(sim_error)
                },
            )??;
            let model = Resolved {
                params: params.inner,
                probe,
            };
            let json = afmdyn::request::run::document(&request, &model, &map).map_err(sim_error)?;
            (map, json)
        }
    };
    let out = Out::new(py);
    out.json(&json)?;
    out.set(
        "layout",
        crate::convert::layout_dict(py, BasinArrays::new(&map).layout(&study.spec))?,
    )?;
    Ok(out.finish())
}

//! `afmdyn.basins`: the library's basin map request ([`afmdyn::request::BasinsRequest`]) with
//! its document and arrays ([`BasinArrays`]), for the Python layer's `xarray.Dataset`.

use crate::analyses::{analysis, integrator_request};
use crate::convert::Out;
use crate::params::PyParams;
use afmdyn::request::{BasinArrays, BasinsRequest, SteadyRequest};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A basin map over two coordinates of the initial state (see `afmdyn.basins`).
#[pyfunction]
#[pyo3(signature = (params, x, x_from, x_to, x_steps, y, y_from, y_to, y_steps, near_tol, cell,
    basin_hits, discover_after, stride, cluster_tol, tol, max_periods, max_period, base=None,
    integrator=None, steps_per_period=None, tolerance=1e-12, threads=None, progress=None,
    probe=None))]
#[allow(clippy::too_many_arguments)]
pub fn basins<'py>(
    py: Python<'py>,
    params: PyRef<'_, PyParams>,
    x: &str,
    x_from: f64,
    x_to: f64,
    x_steps: usize,
    y: &str,
    y_from: f64,
    y_to: f64,
    y_steps: usize,
    near_tol: f64,
    cell: f64,
    basin_hits: usize,
    discover_after: usize,
    stride: usize,
    cluster_tol: f64,
    tol: f64,
    max_periods: Option<usize>,
    max_period: usize,
    base: Option<Vec<f64>>,
    integrator: Option<&str>,
    steps_per_period: Option<usize>,
    tolerance: f64,
    threads: Option<usize>,
    progress: Option<Bound<'py, PyAny>>,
    probe: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let request = BasinsRequest {
        x: x.into(),
        x_from,
        x_to,
        x_steps,
        y: y.into(),
        y_from,
        y_to,
        y_steps,
        base,
        near_tol,
        cell,
        basin_hits,
        discover_after,
        stride,
        cluster_tol,
        threads,
        steady: SteadyRequest {
            tol,
            max_periods,
            max_period,
        },
        integrator: integrator_request(integrator, steps_per_period, tolerance)?,
    };
    let spec = request
        .spec(&params.inner)
        .map_err(crate::errors::sim_error)?;
    let doc = analysis(py, request, params.inner, probe, progress.as_ref(), true)?;
    let out = Out::new(py);
    out.json(&doc.json)?;
    out.set(
        "layout",
        crate::convert::layout_dict(py, BasinArrays::new(&doc.output).layout(&spec))?,
    )?;
    Ok(out.finish())
}

//! `afmdyn.basins`: the library's basin map request ([`afmdyn::request::BasinsRequest`]) with
//! its document and arrays ([`BasinArrays`]), for the Python layer's `xarray.Dataset`.

use crate::analyses::analysis;
use crate::convert::Out;
use crate::params::PyParams;
use afmdyn::request::{BasinArrays, BasinsRequest};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A basin map over two coordinates of the initial state (see `afmdyn.basins`).
#[pyfunction]
#[pyo3(signature = (params, request=None, progress=None, probe=None))]
pub fn basins<'py>(
    py: Python<'py>,
    params: PyRef<'_, PyParams>,
    request: Option<&Bound<'py, PyDict>>,
    progress: Option<Bound<'py, PyAny>>,
    probe: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let request: BasinsRequest = crate::convert::request("basins", request)?;
    let doc = analysis(py, request, params.inner, probe, progress.as_ref(), true)?;
    let a = BasinArrays::new(&doc.output);
    let out = Out::new(py);
    out.json(&doc.json)?;
    let ints = |v: Vec<i32>| v.into_iter().map(i64::from).collect();
    out.i64s("label", ints(a.label))?;
    out.i64s("decided", ints(a.decided))?;
    out.i64s("periods", ints(a.periods))?;
    out.i64s("period", ints(a.period))?;
    out.f64s("x_max", a.x_max)?;
    out.f64s("v_t_min", a.v_t_min)?;
    out.f64s("basin_fraction", a.basin_fraction)?;
    out.f64s("stable", a.stable)?;
    out.f64s("lyapunov", a.lyapunov)?;
    Ok(out.finish())
}

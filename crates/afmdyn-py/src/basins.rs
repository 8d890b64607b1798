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

//! `afmdyn.approach()` and `afmdyn.resonance()`: the stepped sweeps with branch continuation
//! of [`afmdyn::analysis::stepped`], run by the library's request layer
//! ([`afmdyn::request::ApproachRequest`], [`afmdyn::request::ResonanceRequest`]) and returning
//! the command line's JSON documents (`afmdyn approach --json`, `afmdyn resonance --json`).

use crate::analyses::analysis;
use crate::convert::Out;
use crate::params::PyParams;
use afmdyn::request::{ApproachRequest, ResonanceRequest};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The approach–retract curve over the rest distance z_c (`afmdyn approach`).
#[pyfunction]
#[pyo3(signature = (params, request=None, probe=None, progress=None))]
pub fn approach<'py>(
    py: Python<'py>,
    params: PyRef<'_, PyParams>,
    request: Option<&Bound<'py, PyDict>>,
    probe: Option<String>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let request: ApproachRequest = crate::convert::request("approach", request)?;
    let doc = analysis(py, request, params.inner, probe, progress.as_ref(), true)?;
    let out = Out::new(py);
    out.json(&doc.json)?;
    Ok(out.finish())
}

/// The resonance curve near mode `mode` (`afmdyn resonance`).
#[pyfunction]
#[pyo3(signature = (params, request=None, probe=None, progress=None))]
pub fn resonance<'py>(
    py: Python<'py>,
    params: PyRef<'_, PyParams>,
    request: Option<&Bound<'py, PyDict>>,
    probe: Option<String>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let request: ResonanceRequest = crate::convert::request("resonance", request)?;
    let doc = analysis(py, request, params.inner, probe, progress.as_ref(), true)?;
    let out = Out::new(py);
    out.json(&doc.json)?;
    Ok(out.finish())
}

//! `afmdyn.approach()` and `afmdyn.resonance()`: the stepped sweeps with branch continuation
//! of [`afmdyn::analysis::stepped`], run by the library's request layer
//! ([`afmdyn::request::ApproachRequest`], [`afmdyn::request::ResonanceRequest`]) and returning
//! the command line's JSON documents (`afmdyn approach --json`, `afmdyn resonance --json`).

use crate::analyses::analysis;
use crate::convert::Out;
use crate::params::PyParams;
use afmdyn::request::{ApproachRequest, CurveRequest, ResonanceRequest};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The curve range and options of the keywords.
fn curve(
    from: Option<f64>,
    to: Option<f64>,
    step: Option<f64>,
    points: Option<usize>,
    branches: bool,
    tolerance: f64,
    traces: Option<usize>,
) -> CurveRequest {
    CurveRequest {
        from,
        to,
        step,
        points,
        branches,
        tolerance,
        traces,
    }
}

/// The approach–retract curve over the rest distance z_c (`afmdyn approach`).
#[pyfunction]
#[pyo3(signature = (params, from_=None, to=None, step=None, points=None, branches=true,
    tolerance=afmdyn::analysis::stepped::DEFAULT_TOLERANCE, setpoint=None, traces=None,
    probe=None, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn approach<'py>(
    py: Python<'py>,
    params: PyRef<'_, PyParams>,
    from_: Option<f64>,
    to: Option<f64>,
    step: Option<f64>,
    points: Option<usize>,
    branches: bool,
    tolerance: f64,
    setpoint: Option<f64>,
    traces: Option<usize>,
    probe: Option<String>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let request = ApproachRequest {
        curve: curve(from_, to, step, points, branches, tolerance, traces),
        setpoint,
    };
    let doc = analysis(py, request, params.inner, probe, progress.as_ref(), true)?;
    let out = Out::new(py);
    out.json(&doc.json)?;
    Ok(out.finish())
}

/// The resonance curve near mode `mode` (`afmdyn resonance`).
#[pyfunction]
#[pyo3(signature = (params, mode=1, from_=None, to=None, step=None, points=None, branches=true,
    tolerance=afmdyn::analysis::stepped::DEFAULT_TOLERANCE, traces=None, probe=None,
    progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn resonance<'py>(
    py: Python<'py>,
    params: PyRef<'_, PyParams>,
    mode: usize,
    from_: Option<f64>,
    to: Option<f64>,
    step: Option<f64>,
    points: Option<usize>,
    branches: bool,
    tolerance: f64,
    traces: Option<usize>,
    probe: Option<String>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let request = ResonanceRequest {
        mode,
        curve: curve(from_, to, step, points, branches, tolerance, traces),
    };
    let doc = analysis(py, request, params.inner, probe, progress.as_ref(), true)?;
    let out = Out::new(py);
    out.json(&doc.json)?;
    Ok(out.finish())
}

//! `afmdyn.approach()` and `afmdyn.resonance()`: the stepped sweeps with branch continuation
//! of [`afmdyn::analysis::stepped`], returning the command line's JSON documents
//! (`afmdyn approach --json`, `afmdyn resonance --json`; [`afmdyn::report::approach`]).

use crate::convert::Out;
use crate::errors::{probe_error, sim_error};
use crate::params::PyParams;
use crate::run::run_abandonable;
use afmdyn::analysis::approach::approach_retract;
use afmdyn::analysis::resonance::resonance_curve;
use afmdyn::analysis::stepped::{SteppedCurve, SteppedSpec};
use afmdyn::probe::Probe;
use afmdyn::report::{self, CurveUnits};
use afmdyn::request::{approach_request, resonance_request, CurveRequest};
use afmdyn::{Params, SimError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// The units of a probe file (SI), or the model's own, and the probe; `hz`: frequencies in Hz.
fn units(probe: Option<PathBuf>, hz: bool) -> PyResult<(CurveUnits, Option<Probe>)> {
    match probe {
        None => Ok((CurveUnits::dimensionless(), None)),
        Some(path) => {
            let p = Probe::load(&path).map_err(probe_error)?;
            Ok((CurveUnits::from_scales(&p.scales, hz), Some(p)))
        }
    }
}

/// Run `compute` on `spec` with the GIL released and return `{"json": document}`.
fn go<'py>(
    py: Python<'py>,
    spec: SteppedSpec,
    progress: Option<Bound<'py, PyAny>>,
    compute: fn(&SteppedSpec) -> Result<SteppedCurve, SimError>,
    doc: impl Fn(&SteppedCurve) -> serde_json::Value,
) -> PyResult<Bound<'py, PyDict>> {
    let c = run_abandonable(py, progress.as_ref(), move || -> PyResult<_> {
        compute(&spec).map_err(sim_error)
    })??;
    let out = Out::new(py);
    out.json(&doc(&c))?;
    Ok(out.finish())
}

/// The approach–retract curve over the rest distance z_c (`afmdyn approach`).
#[pyfunction]
#[pyo3(signature = (params, from_=None, to=None, step=None, points=None, branches=true,
    tolerance=afmdyn::analysis::stepped::DEFAULT_TOLERANCE, probe=None, progress=None))]
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
    probe: Option<PathBuf>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let base: Params = params.inner;
    let (u, probe) = units(probe, false)?;
    let request = CurveRequest {
        from: from_,
        to,
        step,
        points,
        branches,
        tolerance,
    };
    let spec = approach_request(base, &request, u.length).map_err(sim_error)?;
    go(py, spec, progress, approach_retract, |c| {
        report::with_si(report::approach(&base, c, &u), probe.as_ref(), &base)
    })
}

/// The resonance curve near mode `mode` (`afmdyn resonance`).
#[pyfunction]
#[pyo3(signature = (params, mode=1, from_=None, to=None, step=None, points=None, branches=true,
    tolerance=afmdyn::analysis::stepped::DEFAULT_TOLERANCE, probe=None, progress=None))]
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
    probe: Option<PathBuf>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let base: Params = params.inner;
    let (u, probe) = units(probe, true)?;
    let hz = u.hz_per_omega.unwrap_or(1.0);
    let request = CurveRequest {
        from: from_,
        to,
        step,
        points,
        branches,
        tolerance,
    };
    let spec = resonance_request(base, mode, &request, hz).map_err(sim_error)?;
    go(py, spec, progress, resonance_curve, |c| {
        report::with_si(report::resonance(&base, c, &u), probe.as_ref(), &base)
    })
}

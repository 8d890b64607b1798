//! `afmdyn.approach()` and `afmdyn.resonance()`: the stepped sweeps with branch continuation
//! of [`afmdyn::analysis::stepped`], returning the command line's JSON documents
//! (`afmdyn approach --json`, `afmdyn resonance --json`; [`afmdyn::report::approach`]).

use crate::convert::Out;
use crate::errors::{sim_error, value_error};
use crate::params::PyParams;
use crate::run::{run, Job, Stop};
use afmdyn::analysis::approach::{approach_retract, approach_spec, default_range};
use afmdyn::analysis::resonance::{mode_band, resonance_curve, resonance_spec};
use afmdyn::analysis::stepped::{Spacing, SteppedCurve, SteppedSpec};
use afmdyn::probe::Probe;
use afmdyn::report::{self, CurveUnits};
use afmdyn::{Params, SimError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// The units of a probe file (SI), or the model's own, and the probe; `hz`: frequencies in Hz.
fn units(probe: Option<PathBuf>, hz: bool) -> PyResult<(CurveUnits, Option<Probe>)> {
    match probe {
        None => Ok((CurveUnits::dimensionless(), None)),
        Some(path) => {
            let p = Probe::load(&path).map_err(|e| value_error(format!("probe {e}")))?;
            Ok((CurveUnits::from_scales(&p.scales, hz), Some(p)))
        }
    }
}

/// The grid spacing from `step` (in units of `unit`) or `points` (default 120), not both.
fn spacing(step: Option<f64>, points: Option<usize>, unit: f64) -> PyResult<Spacing> {
    match (step, points) {
        (Some(_), Some(_)) => Err(value_error("give step or points, not both")),
        (Some(h), None) => Ok(Spacing::Step(h / unit)),
        (None, n) => Ok(Spacing::Points(n.unwrap_or(120))),
    }
}

/// Set the options, check both grid ends, run `compute` with the GIL released and return
/// `{"json": document}`.
#[allow(clippy::too_many_arguments)]
fn go<'py>(
    py: Python<'py>,
    mut spec: SteppedSpec,
    branches: bool,
    tolerance: f64,
    progress: Option<Bound<'py, PyAny>>,
    compute: fn(&SteppedSpec) -> Result<SteppedCurve, SimError>,
    doc: impl Fn(&SteppedCurve) -> serde_json::Value,
) -> PyResult<Bound<'py, PyDict>> {
    if !(tolerance.is_finite() && tolerance > 0.0 && tolerance < 1e-3) {
        return Err(value_error(format!(
            "tolerance = {tolerance}: must be in (0, 1e-3)"
        )));
    }
    spec.integrator.tolerance = tolerance;
    spec.branches = branches;
    for v in [spec.values[0], spec.values[spec.values.len() - 1]] {
        spec.base
            .with(spec.param, v)
            .validate()
            .map_err(crate::errors::param_error)?;
    }
    let c = run(
        py,
        &Job::default(),
        None,
        progress.as_ref(),
        Stop::Abandon,
        move || -> PyResult<_> { compute(&spec).map_err(sim_error) },
    )??;
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
    let (far, near) = default_range(&base).map_err(sim_error)?;
    let from = from_.map_or(far, |v| v / u.length);
    let to = to.map_or(near, |v| v / u.length);
    let spec =
        approach_spec(base, from, to, spacing(step, points, u.length)?).map_err(sim_error)?;
    go(
        py,
        spec,
        branches,
        tolerance,
        progress,
        approach_retract,
        |c| report::with_si(report::approach(&base, c, &u), probe.as_ref(), &base),
    )
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
    let (lo, hi) = mode_band(&base, mode).map_err(sim_error)?;
    let from = from_.map_or(lo, |v| v / hz);
    let to = to.map_or(hi, |v| v / hz);
    let spec = resonance_spec(base, from, to, spacing(step, points, hz)?).map_err(sim_error)?;
    go(
        py,
        spec,
        branches,
        tolerance,
        progress,
        resonance_curve,
        |c| report::with_si(report::resonance(&base, c, &u), probe.as_ref(), &base),
    )
}

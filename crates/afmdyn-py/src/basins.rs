//! `afmdyn.basins`: the library's basin map ([`afmdyn::analysis::basins`]) with its measures,
//! as arrays for the Python layer's `xarray.Dataset`.

use crate::convert::Out;
use crate::errors::{sim_error, value_error};
use crate::params::PyParams;
use crate::run::run_abandonable;
use afmdyn::analysis::basin_entropy::{basin_entropy, uncertainty_exponent};
use afmdyn::analysis::basins::{basins as basin_map, BasinSpec, StateCoord};
use afmdyn::analysis::bifurcation::SweepSpec;
use afmdyn::analysis::steady::SteadyOptions;
use nalgebra::DVector;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A basin map over two coordinates of the initial state (see `afmdyn.basins`).
#[pyfunction]
#[pyo3(signature = (params, x, x_from, x_to, x_steps, y, y_from, y_to, y_steps, near_tol, cell,
    basin_hits, discover_after, cluster_tol, tol, max_periods, max_period, integrator=None,
    steps_per_period=None, tolerance=1e-12, threads=None, progress=None))]
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
    cluster_tol: f64,
    tol: f64,
    max_periods: usize,
    max_period: usize,
    integrator: Option<&str>,
    steps_per_period: Option<usize>,
    tolerance: f64,
    threads: Option<usize>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let coord = |name: &str, s: &str| -> PyResult<StateCoord> {
        s.parse()
            .map_err(|e: String| value_error(format!("{name}: {e}")))
    };
    let p = params.inner;
    let spec = BasinSpec {
        params: p,
        x: coord("x", x)?,
        xs: SweepSpec::linspace(x_from, x_to, x_steps).map_err(sim_error)?,
        y: coord("y", y)?,
        ys: SweepSpec::linspace(y_from, y_to, y_steps).map_err(sim_error)?,
        base: DVector::zeros(2 * p.modes),
        near_tol,
        cell,
        basin_hits,
        discover_after,
        steady: SteadyOptions {
            tol,
            max_periods,
            max_period,
            ..SteadyOptions::default()
        },
        cluster_tol,
        integrator: crate::analyses::integrator_request(integrator, steps_per_period, tolerance)?
            .options(1),
    };
    spec.validate().map_err(sim_error)?;
    if let Some(t) = threads {
        if !(1..=1024).contains(&t) {
            return Err(value_error(format!("threads = {t}: must be in 1..=1024")));
        }
    }
    let worker = spec.clone();
    let map = run_abandonable(py, progress.as_ref(), move || {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads.unwrap_or(0))
            .build()
            .map_err(|e| afmdyn::SimError::out_of_range("threads", e, "cannot start"))
            .and_then(|pool| pool.install(|| basin_map(&worker)))
    })?
    .map_err(sim_error)?;
    let labels = map.labels();
    let nx = spec.xs.len();
    let out = Out::new(py);
    out.f64s("x", spec.xs.clone())?;
    out.f64s("y", spec.ys.clone())?;
    out.set("x_name", spec.x.to_string())?;
    out.set("y_name", spec.y.to_string())?;
    out.i64s("label", labels.clone())?;
    out.set(
        "decided",
        map.cells
            .iter()
            .map(|c| c.decided.name())
            .collect::<Vec<_>>(),
    )?;
    out.i64s(
        "periods",
        map.cells.iter().map(|c| c.periods as i64).collect(),
    )?;
    out.i64s(
        "attractor_period",
        map.attractors
            .iter()
            .map(|s| s.period().map_or(-1, |n| n as i64))
            .collect(),
    )?;
    out.f64s("basin_fraction", map.basin_fractions())?;
    out.set(
        "attractor_stable",
        map.orbits
            .iter()
            .map(|o| o.as_ref().map(|o| o.stable))
            .collect::<Vec<_>>(),
    )?;
    out.f64s(
        "attractor_lyapunov",
        map.lyapunov.iter().map(|l| l.unwrap_or(f64::NAN)).collect(),
    )?;
    out.f64s(
        "attractor_x_max",
        map.attractors.iter().map(|s| s.stats.x_max).collect(),
    )?;
    let e = basin_entropy(&labels, nx, 5);
    out.set("basin_entropy", e.map(|e| e.basin_entropy))?;
    out.set(
        "boundary_basin_entropy",
        e.map(|e| e.boundary_basin_entropy),
    )?;
    out.set(
        "uncertainty_exponent",
        uncertainty_exponent(&labels, nx).map(|u| u.0),
    )?;
    Ok(out.finish())
}

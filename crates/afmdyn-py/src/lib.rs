//! `afmdyn._afmdyn`: the compiled part of the Python package `afmdyn`.
//!
//! The pure-Python layer (`python/afmdyn/`) is the public API. Every analysis enters through
//! one door, `door::run(name, request, params, probe, progress)`: the library parses the
//! request by name and runs it ([`afmdyn::request::named`]) with the GIL released, and the
//! document, the result's layouts (dicts of NumPy arrays owning the Rust buffers) and its
//! scalars come back for the Python layer to turn into xarray datasets and result objects.
//! The studies run into a store (`store=`, `resume=`: bifurcation, basins, global
//! continuation, the stepped curves) go through `door::run_stored`; the Dask tasks go through
//! one class, `plan::Plan` (the library's plans: sweep, basin map, PI scan), and the chart's.

mod analyses;
mod chart;
mod convert;
mod door;
mod errors;
mod params;
mod plan;
mod run;

use pyo3::prelude::*;

/// The cantilever library's JSON document ([`afmdyn::cantilevers::document`]).
#[pyfunction]
fn cantilevers() -> String {
    afmdyn::cantilevers::document().to_string()
}

/// The default request of analysis `name` (`"simulate"`, `"bifurcation"`, …) as a dict of its
/// keywords: the one source of the Python functions' defaults. `KeyError` for another name.
#[pyfunction]
fn request_defaults<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
    let d = afmdyn::request::named::default_request(name)
        .ok_or_else(|| pyo3::exceptions::PyKeyError::new_err(name.to_string()))?;
    convert::json_to_py(py, &d.to_string())
}

/// Compiled core of afmdyn (use the `afmdyn` package, not this module).
#[pymodule]
fn _afmdyn(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<params::PyParams>()?;
    m.add_class::<chart::ChartStudy>()?;
    m.add_class::<chart::StoreLock>()?;
    m.add_class::<plan::Plan>()?;
    m.add_class::<plan::PlanStore>()?;
    m.add(
        "SimulationError",
        m.py().get_type::<errors::SimulationError>(),
    )?;
    m.add("FORCE_SIGN", afmdyn::request::FORCE_SIGN)?;
    m.add_function(wrap_pyfunction!(door::run, m)?)?;
    m.add_function(wrap_pyfunction!(door::run_stored, m)?)?;
    m.add_function(wrap_pyfunction!(cantilevers, m)?)?;
    m.add_function(wrap_pyfunction!(request_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(analyses::image, m)?)?;
    m.add_function(wrap_pyfunction!(analyses::read_height_map, m)?)?;
    m.add_function(wrap_pyfunction!(analyses::setpoint_study, m)?)?;
    m.add_function(wrap_pyfunction!(analyses::probe, m)?)?;
    m.add_function(wrap_pyfunction!(params::probe_source, m)?)?;
    m.add("POLL_SECONDS", run::POLL.as_secs_f64())?;
    m.add_function(wrap_pyfunction!(run::cancel_running, m)?)?;
    m.add_function(wrap_pyfunction!(params::resolve, m)?)?;
    // the one table of model parameters: (name, alias or name, unit, range, help)
    m.add(
        "MODEL_PARAMETERS",
        afmdyn::request::MODEL_PARAMETERS
            .iter()
            .map(|p| (p.name, p.alias.unwrap_or(p.name), p.unit, p.range, p.help))
            .collect::<Vec<_>>(),
    )?;
    // the columns of a bifurcation sweep's records, and their numeric form (the .npy's):
    // (name, unit, meaning)
    let columns = |c: &[afmdyn::request::sweep::RecordColumn]| {
        c.iter()
            .map(|c| (c.name, c.unit, c.meaning))
            .collect::<Vec<_>>()
    };
    m.add("SWEEP_COLUMNS", columns(&afmdyn::request::sweep::COLUMNS))?;
    m.add(
        "SWEEP_NUMERIC_COLUMNS",
        columns(&afmdyn::request::sweep::NUMERIC_COLUMNS),
    )?;
    Ok(())
}

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

/// The value of keyword `name` written as text with an SI unit (`"95nm"`, `"0.5 nN"`): its value
/// in SI ([`afmdyn::request::quantity::Quantity::si`]); `want` is the keyword's dimension (its
/// schema's `x-dim`: `"length"`, `"frequency"` or `"force"`), `si` whether the call has a probe.
///
/// # Errors
/// `ValueError` naming the keyword for text that is no number with a unit, a unit of another
/// dimension or a unit without a probe; `TypeError` for a number written as text without a
/// unit (`"40"`: give the number).
#[pyfunction]
fn si_value(text: &str, name: &str, want: &str, si: bool) -> PyResult<f64> {
    use afmdyn::request::quantity::{Dim, Quantity};
    use pyo3::exceptions::{PyTypeError, PyValueError};
    let want = Dim::of_key(want)
        .ok_or_else(|| PyValueError::new_err(format!("{name}: takes no unit (got {text:?})")))?;
    let q: Quantity = text
        .parse()
        .map_err(|e: String| PyValueError::new_err(format!("{name} = {e}")))?;
    if q.dim.is_none() {
        return Err(PyTypeError::new_err(format!(
            "{name}: must be a number, or text with a unit of {} such as '95nm', got str {text:?}",
            want.name()
        )));
    }
    q.si(name, "probe=", want, si)
        .map_err(PyValueError::new_err)
}

/// Compiled core of afmdyn (use the `afmdyn` package, not this module).
#[pymodule]
fn _afmdyn(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // NumPy's C API is loaded here, at import, not at a run's first array: a Ctrl-C landing
    // while NumPy is imported then fails the import, not a run (rust-numpy panics when the
    // capsule's import is interrupted)
    numpy::PyArray1::<f64>::zeros(m.py(), 0, false);
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
    // the names of the one door's analyses (`door::run`), the library's registry
    m.add("REQUEST_NAMES", afmdyn::request::named::NAMES.to_vec())?;
    m.add_function(wrap_pyfunction!(door::run, m)?)?;
    m.add_function(wrap_pyfunction!(door::run_stored, m)?)?;
    m.add_function(wrap_pyfunction!(cantilevers, m)?)?;
    m.add_function(wrap_pyfunction!(request_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(si_value, m)?)?;
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

//! The library's typed errors as Python exceptions: bad input is a `ValueError` (the command
//! line's exit code 2), a failed computation an `afmdyn.SimulationError` (a `RuntimeError`).

use afmdyn::{ParamError, SimError};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(
    afmdyn,
    SimulationError,
    PyRuntimeError,
    "A computation failed: chattering, divergence, a Newton solver that did not converge, or an \
     integrator failure. Bad input raises ValueError instead."
);

/// A parameter out of range: `ValueError` with the library's message (field and range).
pub fn param_error(e: ParamError) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// Input errors ([`SimError::is_input_error`]: the command line's exit code 2) are
/// `ValueError`; everything else is `SimulationError` (exit code 1).
pub fn sim_error(e: SimError) -> PyErr {
    if e.is_input_error() {
        PyValueError::new_err(e.to_string())
    } else {
        SimulationError::new_err(e.to_string())
    }
}

/// `ValueError` for a probe file that cannot be read or resolved (the message names the file
/// and every problem).
pub fn probe_error(e: afmdyn::probe::ProbeError) -> PyErr {
    PyValueError::new_err(format!("probe {e}"))
}

/// `ValueError` with a message.
pub fn value_error(msg: impl Into<String>) -> PyErr {
    PyValueError::new_err(msg.into())
}

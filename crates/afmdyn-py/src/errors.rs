//! The library's typed errors as Python exceptions: bad input is a `ValueError` (the command
//! line's exit code 2), a failed computation an `afmdyn.SimulationError` (a `RuntimeError`).

use afmdyn::error::{ParamError, SimError};
use afmdyn::request::{DirLock, LockError};
use afmdyn::study::checkpoint::CheckpointError;
use afmdyn::study::StudyError;
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

/// Lock a store directory (created if needed) before any work: a second run on it is refused
/// at once (`ValueError`), a directory that cannot be created or locked is an `OSError`.
pub(crate) fn lock_store(dir: &std::path::Path) -> PyResult<DirLock> {
    DirLock::acquire(dir).map_err(|e| match e {
        LockError::InUse { .. } => value_error(format!(
            "store: {e}; wait for it to finish or choose another store="
        )),
        LockError::Io { .. } => pyo3::exceptions::PyOSError::new_err(e.to_string()),
    })
}

/// A checkpoint error as Python sees it: a store of another request (or of none) is a
/// `ValueError` naming the field, a file that cannot be read or written an `OSError`.
pub(crate) fn checkpoint_error(e: CheckpointError) -> PyErr {
    match e {
        CheckpointError::Io { .. } => pyo3::exceptions::PyOSError::new_err(e.to_string()),
        CheckpointError::Mismatch { .. } => value_error(format!(
            "resume: {e}; call with the same arguments, or with resume=False to start over"
        )),
        // the library's advice names the command line's flag
        _ => value_error(format!(
            "resume: {}",
            e.to_string()
                .replace("rerun without --resume", "call with resume=False")
        )),
    }
}

/// A study's error as Python raises it.
pub(crate) fn study_error(e: StudyError) -> PyErr {
    match e {
        StudyError::Store(e) => checkpoint_error(e),
        StudyError::Sim(e) => sim_error(e),
    }
}

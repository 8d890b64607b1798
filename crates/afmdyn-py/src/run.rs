//! Running a computation without the GIL: the work goes to a worker thread while the calling
//! thread waits with the GIL released, waking every [`POLL`] to run Python's signal handlers
//! (Ctrl-C raises `KeyboardInterrupt`) and to report progress.

use afmdyn::analysis::progress::Progress;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::mpsc::{channel, RecvTimeoutError};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// How often the waiting thread checks for signals and reports progress.
pub const POLL: Duration = Duration::from_millis(50);

/// Shared between the worker and the waiting thread: the library's [`Progress`] of the run,
/// the units of work done (sweep points, random starts, curve points, periods) and the cancel
/// flag, set when the caller was interrupted (a cancellable computation stops at its next
/// check).
#[derive(Clone, Default)]
pub struct Job {
    /// The run's progress and cancel flag.
    pub progress: Arc<Progress>,
}

/// How the computation reacts to an interrupt.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// It checks [`Job::cancel`]: wait for it to stop, then raise.
    Cancellable,
    /// It cannot stop early: raise at once and let the worker finish in the background (its
    /// result is dropped; it holds no Python objects).
    Abandon,
}

fn panic_message(p: Box<dyn std::any::Any + Send>) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic".into()
    }
}

/// Run `work` on a worker thread with the GIL released. `progress(done, total)` is called from
/// the calling thread (with the GIL) at every poll and once at the end; `total` is the given
/// one, else the one the run counts in [`Job::progress`].
///
/// # Errors
/// `KeyboardInterrupt` (or whatever a signal handler raises), an exception raised by
/// `progress`, or `RuntimeError` if the computation panicked (a bug: reported, not a crash).
pub fn run<T, F>(
    py: Python<'_>,
    job: &Job,
    total: Option<usize>,
    progress: Option<&Bound<'_, PyAny>>,
    stop: Stop,
    work: F,
) -> PyResult<T>
where
    T: Send + 'static,
    F: FnOnce() -> T + Send + 'static,
{
    let (tx, rx) = channel();
    // the receiver is used from inside `detach`, which needs a `Sync` borrow
    let rx = Mutex::new(rx);
    std::thread::Builder::new()
        .name("afmdyn-worker".into())
        .spawn(move || {
            let r = catch_unwind(AssertUnwindSafe(work)).map_err(panic_message);
            let _ = tx.send(r);
        })
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start a worker thread: {e}")))?;
    let report = |py: Python<'_>| -> PyResult<()> {
        if let Some(cb) = progress {
            let _ = py;
            cb.call1((job.progress.done(), total.or(job.progress.total())))?;
        }
        Ok(())
    };
    loop {
        match py.detach(|| rx.lock().expect("receiver").recv_timeout(POLL)) {
            Ok(Ok(value)) => {
                report(py)?;
                return Ok(value);
            }
            Ok(Err(msg)) => {
                return Err(PyRuntimeError::new_err(format!(
                    "internal error in afmdyn (please report): {msg}"
                )))
            }
            Err(RecvTimeoutError::Disconnected) => {
                return Err(PyRuntimeError::new_err(
                    "internal error in afmdyn: the worker thread ended without a result",
                ))
            }
            Err(RecvTimeoutError::Timeout) => {}
        }
        if let Err(e) = py.check_signals().and_then(|_| report(py)) {
            job.progress.cancel();
            if stop == Stop::Cancellable {
                // the points already running finish; no new one starts
                let _ = py.detach(|| rx.lock().expect("receiver").recv());
            }
            return Err(e);
        }
    }
}

/// [`run`] for a computation that cannot count its work or stop early: no progress count
/// (`progress(0, None)`), abandoned on an interrupt ([`Stop::Abandon`]).
///
/// # Errors
/// As [`run`].
pub fn run_abandonable<T, F>(
    py: Python<'_>,
    progress: Option<&Bound<'_, PyAny>>,
    work: F,
) -> PyResult<T>
where
    T: Send + 'static,
    F: FnOnce() -> T + Send + 'static,
{
    run(py, &Job::default(), None, progress, Stop::Abandon, work)
}

//! Running a computation without the GIL: the work goes to a worker thread while the calling
//! thread waits with the GIL released, waking every [`POLL`] to run Python's signal handlers
//! (Ctrl-C raises `KeyboardInterrupt`) and to report progress.
//!
//! Python runs signal handlers on the main thread only, so a computation called from another
//! thread (a `ThreadPoolExecutor`) never sees Ctrl-C through them. Every waiting thread
//! therefore also watches a process-wide count of interrupts, [`INTERRUPTS`]: the package's
//! SIGINT handler (`afmdyn/_interrupt.py`, wrapping the one it finds) bumps it through
//! [`cancel_running`] before it raises `KeyboardInterrupt` in the main thread, and so does a
//! `KeyboardInterrupt` raised in a wait on the main thread. A computation sees the count move
//! past the value it started with at its next poll: it is cancelled and its
//! caller gets `KeyboardInterrupt`, whatever thread it runs in.

use afmdyn::request::Progress;
use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError};
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{channel, RecvTimeoutError};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// How often the waiting thread checks for signals and reports progress.
pub const POLL: Duration = Duration::from_millis(50);

/// The interrupts so far (see the module): a computation running when it moves is cancelled.
pub static INTERRUPTS: AtomicU64 = AtomicU64::new(0);

/// Cancel every computation running now, in every thread: each raises `KeyboardInterrupt`
/// within a poll ([`POLL`]); those started afterwards run as usual. The package's SIGINT
/// handler calls it (`afmdyn.cancel_running()`).
#[pyfunction]
pub fn cancel_running() {
    INTERRUPTS.fetch_add(1, Ordering::SeqCst);
}

/// Shared between the worker and the waiting thread: the library's [`Progress`] of the run,
/// the units of work done (sweep points, random starts, curve points, periods) and the cancel
/// flag, set when the caller was interrupted (a cancellable computation stops at its next
/// check).
#[derive(Clone, Default)]
pub struct Job {
    /// The run's progress and cancel flag.
    pub progress: Arc<Progress>,
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
/// `KeyboardInterrupt` (or whatever a signal handler raises; also in a thread other than the
/// main one, once [`cancel_running`] was called), an exception raised by `progress`, or
/// `RuntimeError` if the computation panicked (a bug: reported, not a crash).
pub fn run<T, F>(
    py: Python<'_>,
    job: &Job,
    total: Option<usize>,
    progress: Option<&Bound<'_, PyAny>>,
    work: F,
) -> PyResult<T>
where
    T: Send + 'static,
    F: FnOnce() -> T + Send + 'static,
{
    // on the main thread: wrap the SIGINT handler again if other code replaced it
    if let Ok(m) = py.import("afmdyn._interrupt") {
        m.call_method0("install")?;
    }
    let generation = INTERRUPTS.load(Ordering::SeqCst);
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
        let interrupted = || {
            if INTERRUPTS.load(Ordering::SeqCst) == generation {
                Ok(())
            } else {
                Err(PyKeyboardInterrupt::new_err(
                    "afmdyn: cancelled by Ctrl-C (KeyboardInterrupt in the main thread)",
                ))
            }
        };
        let checked = py
            .check_signals()
            .and_then(|_| interrupted())
            .and_then(|_| report(py));
        if let Err(e) = checked {
            if e.is_instance_of::<PyKeyboardInterrupt>(py) {
                // Ctrl-C here (the main thread) cancels the runs of the other threads too
                cancel_running();
            }
            // every run of the library's door stops within a second of its cancel
            // (afmdyn's tests/door.rs): waited for, so that nothing runs on in the background
            job.progress.cancel();
            let _ = py.detach(|| rx.lock().expect("receiver").recv());
            return Err(e);
        }
    }
}

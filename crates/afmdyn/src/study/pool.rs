//! The one place where a request's thread count becomes a rayon pool (`None`: all cores). The
//! count itself is checked with the request (1..=[`crate::request::limits`]'s bound); results
//! never depend on it (seeds come from the request and the task).

use crate::error::SimError;

/// A pool of `threads` worker threads (`None`: one per core).
///
/// # Errors
/// [`SimError::OutOfRange`] naming `threads` when the pool cannot start.
#[cfg(feature = "parallel")]
pub(crate) fn thread_pool(threads: Option<usize>) -> Result<rayon::ThreadPool, SimError> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| SimError::out_of_range("threads", e, "cannot start the worker threads"))
}

/// Run `f` on a [`thread_pool`] of `threads`; `None` on the current pool (rayon's global pool
/// of one thread per core, or the pool the caller runs in), which saves starting threads for
/// a short run.
///
/// # Errors
/// As [`thread_pool`]; `f`'s errors.
#[cfg(feature = "parallel")]
pub(crate) fn in_pool<T: Send>(
    threads: Option<usize>,
    f: impl FnOnce() -> Result<T, SimError> + Send,
) -> Result<T, SimError> {
    match threads {
        None => f(),
        Some(_) => thread_pool(threads)?.install(f),
    }
}

/// Without the `parallel` feature: `f` on the calling thread.
///
/// # Errors
/// `f`'s errors.
#[cfg(not(feature = "parallel"))]
pub(crate) fn in_pool<T: Send>(
    _threads: Option<usize>,
    f: impl FnOnce() -> Result<T, SimError> + Send,
) -> Result<T, SimError> {
    f()
}

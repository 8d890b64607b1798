//! Independent tasks on the current rayon pool: the local executor of the studies whose tasks
//! depend only on their number (a chart's tiles, an image scan's lines).

#[cfg(not(feature = "parallel"))]
use super::sequential::*;
#[cfg(feature = "parallel")]
use rayon::prelude::*;
use std::collections::HashSet;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

/// Run every task `0..tasks` not in `done` (one task per work item; without the `parallel`
/// feature one after another), handing each result to `sink` with its number as it finishes
/// (no lock on that path); `Ok(None)` is a task cut short, not sent. Starts no task once `cancel`
/// is set. Each task depends only on its number, so the results do not depend on the thread
/// count.
///
/// # Errors
/// The error of the lowest-numbered task that failed (the others that finished are sent).
pub(crate) fn run_independent<R, E: Send>(
    tasks: usize,
    done: &HashSet<usize>,
    task: &(dyn Fn(usize) -> Result<Option<R>, E> + Sync),
    sink: &(dyn Fn(usize, R) + Sync),
    cancel: &AtomicBool,
) -> Result<(), E> {
    let failed = Mutex::new(None::<(usize, E)>);
    // each task watches the caller's cancel flag too (`crate::analysis::progress`)
    let watched = crate::error::watched();
    (0..tasks)
        .into_par_iter()
        .with_max_len(1)
        .filter(|t| !done.contains(t))
        .for_each(|t| {
            if cancel.load(Ordering::Relaxed) {
                return;
            }
            match crate::error::watching(watched.clone(), || task(t)) {
                Ok(Some(r)) => sink(t, r),
                Ok(None) => {}
                Err(e) => {
                    let mut f = failed.lock().unwrap_or_else(|p| p.into_inner());
                    if f.as_ref().is_none_or(|(k, _)| t < *k) {
                        *f = Some((t, e));
                    }
                }
            }
        });
    match failed.into_inner().unwrap_or_else(|p| p.into_inner()) {
        Some((_, e)) => Err(e),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_task_not_done_is_sent_once_and_the_lowest_failure_returned() {
        let done: HashSet<usize> = [1, 4].into_iter().collect();
        let sent = Mutex::new(Vec::new());
        let r = run_independent(
            8,
            &done,
            &|t| match t {
                6 | 3 => Err(t),
                5 => Ok(None),
                _ => Ok(Some(10 * t)),
            },
            &|t, v| sent.lock().unwrap().push((t, v)),
            &AtomicBool::new(false),
        );
        assert_eq!(r, Err(3));
        let mut sent = sent.into_inner().unwrap();
        sent.sort();
        assert_eq!(sent, vec![(0, 0), (2, 20), (7, 70)]);
        let cancelled = run_independent::<usize, ()>(
            8,
            &HashSet::new(),
            &|_| panic!("no task starts once cancelled"),
            &|_, _| {},
            &AtomicBool::new(true),
        );
        assert_eq!(cancelled, Ok(()));
    }
}

//! Studies: analyses made of many independent tasks (a bifurcation sweep's points, a chart's
//! tiles), run by one executor into one kind of store, whatever the front end.
//!
//! - [`Study`]: what a study is to the executor — its fingerprint (what a resumed run must
//!   match), its size in progress units, and `run`, which computes every task not yet done and
//!   hands each finished one to a sink. How a study cuts itself into tasks and orders them (a
//!   sweep's coarse pass before its chain segments, a chart's tiles) stays the study's own.
//! - [`Store`]: where finished tasks go — a fingerprinted ledger that says what is done,
//!   appends a finished task, and finishes atomically (the files in the one order); the file
//!   stores lock their directory for one run at a time. Two stores serve every study: the
//!   file store `task_store::TaskStore` (feature `files`), its records written by a codec —
//!   JSON lines for a study of numbered tasks whose records serialize (the chart's
//!   `chart_store`; a PI-scanned image's lines, `scan_store`), the checkpoint's CSV rows for
//!   a sweep (`sweep::SweepRows`); and [`MemoryStore`], which keeps the tasks in memory
//!   with the same ledger (a resume of the same request goes on, of another is refused). What
//!   a resume skips is gathered from the stored records (`Resumes`).
//! - [`execute`]: the one executor — opens the store (refusing a resume of another request),
//!   builds the worker pool (the request's thread count, checked once by
//!   `crate::request::limits::check_threads`), runs the study, appends each finished task
//!   under one lock, reports progress to an [`Observer`], and finishes the store.
//! - [`plan`] (feature `files`): the studies as stages of tasks for an executor outside the
//!   library (Dask), each rebuilt from its recipe, with its ledger.
//! - the studies: three kinds ([`Study`] implementations). `Tasks`: independent tasks
//!   `0..n` run in parallel — [`chart`] (a behaviour chart's tiles, its store [`chart_store`]),
//!   [`scan`] (a PI-scanned image's lines, its store `scan_store`) and `peakforce_image`
//!   (a PeakForce image's lines). `Chain`: tasks that start from the records before them —
//!   [`basins`] (a basin map's rows, pass by pass, its store `basins::basin_store`),
//!   [`global_continuation`] (a global continuation's values, its store
//!   `global_continuation::continuation_store`), [`stepped`] (an approach or resonance curve's
//!   points, one chain through both sweeps, its store `stepped::curve_store`) and
//!   `peakforce` (a PeakForce sweep's taps, run in memory). And [`sweep`] (a bifurcation
//!   sweep's points, its branches continued across them, stored in its checkpoint). A chain's resume reads its stored records back (its next task starts from
//!   them: `Done` is the records); a study of independent tasks reads only their numbers.
//! - the running of the requests that are one computation (their `Analysis`: execution,
//!   document, presentation, layouts), beside the requests in [`crate::request`]: `fit` and
//!   `fit_dynamic` (a force curve's and a dynamic curve's fit), `fm` (an FM curve) and
//!   `reconstruct` (the force behind an FM or AM curve, and `reconstruct_document`'s run).
//!
//! - the running of the requests (`crate::request` holds what they are): the one-value
//!   analyses' `Analysis` (`analyses`, `modes`), `simulate` recorded whole (`simulate`) or
//!   streamed to files (`simulate_stream`), a request run by its name to its outcome
//!   ([`named`], its arrays `datasets`), and what the stores share ([`checkpoint`], with the
//!   sweep's checkpoint file `checkpoint_file`) and the worker pool (`pool`).
//!
//! The results' variables are declared once in [`crate::layout`], from which the NetCDF file,
//! the Python `xarray.Dataset` and the Dask Zarr store are written.
//!
//! Results never depend on the thread count or on the order tasks finish in: every seed comes
//! from the request and the task, and a store puts its records in the one order when it
//! finishes. Dask (`afmdyn.dask`) is another executor of the same tasks: it ships them to
//! workers and writes through the same layout.

pub(crate) mod analyses;
pub mod basins;
pub(crate) mod calibrate;
pub mod chart;
#[cfg(feature = "files")]
pub mod chart_store;
pub mod checkpoint;
#[cfg(feature = "files")]
pub(crate) mod checkpoint_file;
mod datasets;
pub(crate) mod fit;
pub(crate) mod fit_dynamic;
pub mod fit_map;
pub(crate) mod fit_result;
pub(crate) mod fm;
pub mod global_continuation;
pub mod image;
pub mod image_ideal;
mod kinds;
mod memory;
pub(crate) mod modes;
pub mod named;
pub(crate) mod peakforce;
pub mod peakforce_image;
pub(crate) mod peakforce_sweep;
#[cfg(feature = "files")]
pub mod plan;
pub(crate) mod pool;
pub(crate) mod reconstruct;
pub mod scan;
#[cfg(feature = "files")]
pub(crate) mod scan_store;
pub(crate) mod simulate;
#[cfg(feature = "files")]
pub mod simulate_stream;
pub mod stepped;
#[cfg(feature = "files")]
pub mod stored;
pub mod sweep;
#[cfg(feature = "files")]
pub(crate) mod task_store;
pub(crate) mod thermal;

pub use analyses::advance_from_rest;
pub(crate) use kinds::{in_order, Chain, Tasks};
pub use memory::MemoryStore;
pub use peakforce::PeakForceResult;
pub(crate) use pool::in_pool;

use crate::analysis::progress::Progress;
use crate::analysis::thermal::ModelUnits;
use crate::error::SimError;
use crate::study::checkpoint::CheckpointError;
use serde_json::Value;
use std::collections::{BTreeMap, HashSet};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;
use thiserror::Error;

/// The stored records of tasks 0, 1, 2, … up to the first task missing, in order: what a chain
/// resumes from, whose every task starts from the one before it (a stepped curve). The tasks
/// after a gap (a store with a line removed) are run again rather than shifted into its place.
#[derive(Debug, Clone)]
pub(crate) struct Prefix<R>(pub Vec<R>);

impl<R> Default for Prefix<R> {
    fn default() -> Self {
        Prefix(Vec::new())
    }
}

/// What a resumed study skips, gathered from its stored records (in the order stored; a task
/// stored twice counts once, its first record): the tasks' numbers (`HashSet<usize>`: the
/// records stay in the store), the records in the order of the tasks (`Vec<R>`), the first
/// unbroken ones (`Prefix`), or a sweep's points with their chains' last states.
pub(crate) trait Resumes<Record>: Sized {
    /// What gathers the records.
    type Gathered: Default;
    /// Note one stored record.
    fn gather(gathered: &mut Self::Gathered, record: &Record);
    /// What is done, from every record gathered.
    fn done(gathered: Self::Gathered) -> Self;
}

impl<R> Resumes<(usize, R)> for HashSet<usize> {
    type Gathered = HashSet<usize>;
    fn gather(tasks: &mut HashSet<usize>, record: &(usize, R)) {
        tasks.insert(record.0);
    }
    fn done(tasks: HashSet<usize>) -> Self {
        tasks
    }
}

impl<R: Clone> Resumes<(usize, R)> for Vec<R> {
    type Gathered = BTreeMap<usize, R>;
    fn gather(records: &mut BTreeMap<usize, R>, (task, record): &(usize, R)) {
        records.entry(*task).or_insert_with(|| record.clone());
    }
    fn done(records: BTreeMap<usize, R>) -> Self {
        records.into_values().collect()
    }
}

impl<R: Clone> Resumes<(usize, R)> for Prefix<R> {
    type Gathered = BTreeMap<usize, R>;
    fn gather(records: &mut BTreeMap<usize, R>, record: &(usize, R)) {
        <Vec<R> as Resumes<(usize, R)>>::gather(records, record);
    }
    fn done(records: BTreeMap<usize, R>) -> Self {
        Prefix(
            records
                .into_iter()
                .enumerate()
                .take_while(|(k, (task, _))| k == task)
                .map(|(_, (_, r))| r)
                .collect(),
        )
    }
}

/// A study: independent tasks whose results a [`Store`] keeps (see the module doc).
pub trait Study: Sync {
    /// One finished task, as a store keeps it.
    type Record: Send;
    /// What a resumed run skips, as its store reads it back (`Default`: nothing done).
    type Done: Default + Send + Sync;

    /// The fingerprint of the request (its options, model and defaults): what a resumed run
    /// must match.
    fn fingerprint(&self) -> &Value;

    /// The study's size in progress units (points, cells).
    fn units(&self) -> u64;

    /// The units of what `done` holds.
    fn done_units(&self, done: &Self::Done) -> u64;

    /// The units of one finished task.
    fn record_units(&self, record: &Self::Record) -> u64;

    /// Put the finished tasks of a store in the one order (a sweep's points by value and
    /// branch); by default they stay in the order they finished.
    fn order(&self, _records: &mut [Self::Record]) {}

    /// Compute every task not in `done` (on the current rayon pool with the `parallel`
    /// feature), handing each finished task to `sink` from the worker threads; start no
    /// further task once `cancel` is set (a task cut short is not sent).
    ///
    /// # Errors
    /// The error that stopped the study (a task of a chain that failed: the tasks after it
    /// cannot run); [`SimError::Cancelled`] once `cancel` is set, or `Ok`.
    fn run(
        &self,
        done: &Self::Done,
        sink: &(dyn Fn(Self::Record) + Sync),
        cancel: &AtomicBool,
    ) -> Result<(), SimError>;
}

/// Where a store stands when a run opens it.
#[derive(Debug, Clone, PartialEq)]
pub enum Opened<D> {
    /// The run computes what `D` does not hold.
    Run(D),
    /// A resumed store whose study finished: nothing to compute.
    Finished,
}

/// A store of a study's finished tasks (see the module doc).
pub trait Store<S: Study + ?Sized>: Send {
    /// Open the store for `study`. Without `resume` a new run begins (stored tasks dropped).
    /// With `resume`: an empty store begins; a store of another request is refused
    /// ([`CheckpointError::Mismatch`] naming the first field that differs); an unfinished one
    /// goes on after its stored tasks; a finished one is [`Opened::Finished`].
    ///
    /// # Errors
    /// [`CheckpointError`]: a mismatch, records without a ledger, unreadable or corrupt files.
    fn open(&mut self, study: &S, resume: bool) -> Result<Opened<S::Done>, CheckpointError>;

    /// Keep one finished task (all of it, at once).
    ///
    /// # Errors
    /// [`CheckpointError::Io`].
    fn append(&mut self, record: S::Record) -> Result<(), CheckpointError>;

    /// Mark the study finished, its records in the one order.
    ///
    /// # Errors
    /// [`CheckpointError::Io`].
    fn finish(&mut self, study: &S) -> Result<(), CheckpointError>;
}

/// What a run reports as it goes (a progress bar, a Python callback, a test hook). Every
/// method is called from the worker threads.
pub trait Observer: Sync {
    /// The run starts: the study's size and the units its store already holds.
    fn start(&self, total: u64, done: u64);
    /// A finished task is stored: its units, and the number of tasks this run has stored.
    fn stored(&self, units: u64, count: usize);
    /// The flag the caller sets to stop the run (the study starts no further task).
    fn cancel_flag(&self) -> &AtomicBool;
}

impl Observer for Progress {
    fn start(&self, total: u64, done: u64) {
        self.add_total(usize::try_from(total).unwrap_or(usize::MAX));
        self.advance(usize::try_from(done).unwrap_or(usize::MAX));
    }

    fn stored(&self, units: u64, _count: usize) {
        self.advance(usize::try_from(units).unwrap_or(usize::MAX));
    }

    fn cancel_flag(&self) -> &AtomicBool {
        Progress::cancel_flag(self)
    }
}

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// Every task is stored and the store finished.
    Finished,
    /// The store held the finished study already (a resume): nothing was computed.
    AlreadyFinished,
    /// The caller cancelled the run: the tasks stored so far are kept, the store unfinished.
    Cancelled,
}

/// What can stop a study.
#[derive(Debug, Error)]
pub enum StudyError {
    /// The store refused the run or could not be written.
    #[error(transparent)]
    Store(#[from] CheckpointError),
    /// The worker pool could not start.
    #[error(transparent)]
    Sim(#[from] SimError),
}

/// Run `study` into `store` on `threads` worker threads (`None`: all cores; with the
/// `parallel` feature, else on the calling thread): open the store (`resume` as
/// [`Store::open`]), compute every task it does not hold, append each under one lock as it
/// finishes, report to `observer`, and finish the store unless cancelled. A store error
/// cancels the run (the tasks already stored are kept) and is returned.
///
/// # Errors
/// [`StudyError::Store`] from the store; [`StudyError::Sim`] when the pool cannot start or
/// the study failed (the tasks stored so far are kept, the store unfinished).
pub fn execute<S: Study + ?Sized, St: Store<S>>(
    study: &S,
    store: &mut St,
    resume: bool,
    threads: Option<usize>,
    observer: &dyn Observer,
) -> Result<Outcome, StudyError> {
    // the one executor checks the thread count of every study (before its store is opened)
    crate::request::limits::check_threads(threads).map_err(StudyError::Sim)?;
    let done = match store.open(study, resume)? {
        Opened::Finished => {
            observer.start(study.units(), study.units());
            return Ok(Outcome::AlreadyFinished);
        }
        Opened::Run(done) => done,
    };
    observer.start(study.units(), study.done_units(&done));
    let cancel = observer.cancel_flag();
    let count = AtomicUsize::new(0);
    let shared = Mutex::new((&mut *store, None::<CheckpointError>));
    let sink = |record: S::Record| {
        // nothing is stored after a cancel: a task it cut short may end as a failed record
        if cancel.load(Ordering::Relaxed) {
            return;
        }
        let units = study.record_units(&record);
        let mut guard = shared.lock().unwrap_or_else(|e| e.into_inner());
        let (s, failed) = &mut *guard;
        if failed.is_none() {
            if let Err(e) = s.append(record) {
                *failed = Some(e);
                cancel.store(true, Ordering::Relaxed);
                return;
            }
        } else {
            return;
        }
        drop(guard);
        observer.stored(units, count.fetch_add(1, Ordering::SeqCst) + 1);
    };
    let watched = crate::error::watched();
    let ran = crate::study::in_pool(threads, || {
        crate::error::watching(watched, || study.run(&done, &sink, cancel))
    });
    let (_, failed) = shared.into_inner().unwrap_or_else(|e| e.into_inner());
    if let Some(e) = failed {
        return Err(e.into());
    }
    if cancel.load(Ordering::Relaxed) {
        return Ok(Outcome::Cancelled);
    }
    // a study that failed keeps the tasks stored so far, unfinished
    ran?;
    store.finish(study)?;
    Ok(Outcome::Finished)
}

/// Run `study` into a [`MemoryStore`] (a run that writes no files, as [`execute`] on
/// `threads` workers reporting to `observer`): its records in the order they finished.
///
/// # Errors
/// [`SimError::Cancelled`] when the observer's flag stopped the run; the pool's errors and the
/// study's ([`Study::run`]).
pub(crate) fn execute_in_memory<S: Study + ?Sized>(
    study: &S,
    threads: Option<usize>,
    observer: &dyn Observer,
) -> Result<Vec<S::Record>, SimError>
where
    S::Done: Resumes<S::Record>,
{
    let mut store = MemoryStore::default();
    match execute(study, &mut store, false, threads, observer) {
        Ok(Outcome::Cancelled) => Err(SimError::Cancelled),
        Ok(Outcome::Finished | Outcome::AlreadyFinished) => Ok(store.records),
        Err(StudyError::Sim(e)) => Err(e),
        // a memory store opens, appends and finishes without fail
        Err(StudyError::Store(e)) => unreachable!("memory store: {e}"),
    }
}

/// The SI scales of a probe (metres, newtons, seconds per model unit) as the thermal analyses
/// take them.
pub(crate) fn model_units(s: &crate::probe::Scales) -> ModelUnits {
    ModelUnits {
        length_m: s.length_m,
        force_n: s.force_n,
        time_s: s.time_s,
    }
}

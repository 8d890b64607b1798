//! A request run resumably into the store of a locked directory ([`Resumable`]: its study made
//! on the model before any side effect, run into the store — continued with `resume`, watched
//! by the testing hook `abort_after` — and finished to the request's typed output): the one
//! path of the command line's door and of Python's `run_stored`. The studies a front end runs
//! by name ([`parse`]: `bifurcation`, `basins`, `global_continuation`, `approach`, `bimodal`,
//! `resonance`, `fit_map`) are prepared ([`Stored::prepare`]: validated, before any side effect) and run
//! ([`Prepared::run`]) to the outcome the one door gives for the same request
//! (`super::named::outcome`).

use super::basins::{basin_store, BasinStudy};
use super::chart::cells_of;
use super::chart_store::chart_store;
use super::global_continuation::{continuation_store, ContinuationStudy};
use super::image::ImageOutput;
use super::named::{self, Datasets, Outcome};
use super::scan::ScanStudy;
use super::scan_store::scan_store;
use super::stepped::{curve_store, CurveStudy};
use super::sweep::{sweep_checkpoint, SweepStudy};
use super::task_store::{Codec, Lines, TaskStore};
use super::{execute, MemoryStore, Observer, Resumes, Study, StudyError};
use crate::analysis::bifurcation::SweepSpec;
use crate::analysis::progress::Progress;
use crate::analysis::stepped::SteppedCurve;
use crate::error::SimError;
use crate::report::present::sweeps::{stored_bifurcation, SweepFiles, SweepRow, SweepTally};
use crate::report::Convergence;
use crate::request::chart::Chart;
use crate::request::image_job::ImageJob;
use crate::request::run::Bimodal;
use crate::request::sweep::{every_point_failed, SweepRecord};
use crate::request::GlobalContinuationRequest;
use crate::request::{
    Analysis, ApproachRequest, BasinsRequest, BifurcationRequest, DirLock, Request,
};
use crate::request::{Resolved, ResonanceRequest};
use crate::study::checkpoint::CheckpointError;
use crate::study::checkpoint_file::{each_row, final_csv, final_rows, write_npy};
use serde::de::{DeserializeOwned, Deserializer};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::sync::atomic::AtomicBool;

/// Where a study runs: the store of a locked directory (none: in memory), continued from an
/// interrupted run of the same request (`resume`), and the testing hook `abort_after` (abort
/// the process, as if killed, once that many tasks are stored).
#[derive(Debug, Clone, Copy, Default)]
pub struct Storage<'a> {
    /// The locked directory of the store; `None`: in memory.
    pub lock: Option<&'a DirLock>,
    /// Continue the interrupted run stored there.
    pub resume: bool,
    /// Testing: abort the process once this many tasks are stored.
    pub abort_after: Option<usize>,
}

/// What a study's run reports to: the progress it counts in, and the testing hook.
struct Watch<'a> {
    progress: &'a Progress,
    abort_after: Option<usize>,
}

impl Observer for Watch<'_> {
    fn start(&self, total: u64, done: u64) {
        Observer::start(self.progress, total, done);
    }

    fn stored(&self, units: u64, count: usize) {
        Observer::stored(self.progress, units, count);
        if self.abort_after == Some(count) {
            std::process::abort();
        }
    }

    fn cancel_flag(&self) -> &AtomicBool {
        self.progress.cancel_flag()
    }
}

/// Where a study ran: the finished file store of the directory, or its records in memory.
enum Ran<'a, C: Codec> {
    /// The directory's store.
    Stored(TaskStore<'a, C>),
    /// The records.
    Memory(Vec<C::Record>),
}

impl<'a> Storage<'a> {
    /// Run `study` (on `threads`, counting in `progress`) into the store `open` makes of the
    /// directory, or into memory.
    ///
    /// # Errors
    /// The store's and the study's.
    fn run<S, C>(
        &self,
        study: &S,
        open: impl FnOnce(&'a DirLock) -> TaskStore<'a, C>,
        threads: Option<usize>,
        progress: &Progress,
    ) -> Result<Ran<'a, C>, StudyError>
    where
        S: Study<Record = C::Record>,
        S::Done: Resumes<C::Record>,
        C: Codec + Send,
        C::Record: Send,
    {
        let watch = Watch {
            progress,
            abort_after: self.abort_after,
        };
        match self.lock {
            Some(lock) => {
                let mut store = open(lock);
                execute(study, &mut store, self.resume, threads, &watch)?;
                Ok(Ran::Stored(store))
            }
            None => {
                let mut store = MemoryStore::default();
                execute(study, &mut store, false, threads, &watch)?;
                Ok(Ran::Memory(store.records))
            }
        }
    }

    /// Run `study` as [`Storage::run`] into the JSON-lines store `open` makes: its records.
    ///
    /// # Errors
    /// The store's and the study's.
    pub(crate) fn records<S, R>(
        &self,
        study: &S,
        open: fn(&DirLock) -> TaskStore<'_, Lines<R>>,
        threads: Option<usize>,
        progress: &Progress,
    ) -> Result<Vec<(usize, R)>, StudyError>
    where
        S: Study<Record = (usize, R)>,
        S::Done: Resumes<(usize, R)>,
        R: Serialize + DeserializeOwned + Clone + Send,
    {
        Ok(match self.run(study, open, threads, progress)? {
            Ran::Stored(mut store) => store.records()?,
            Ran::Memory(records) => records,
        })
    }
}

/// A request whose study runs resumably into a store ([`Storage`]) to the request's typed
/// output, which its [`Analysis::present`] presents.
pub trait Resumable: Analysis {
    /// The study, made on the model before any side effect.
    type Study: Send + Sync;
    /// The study of the request on `model`.
    ///
    /// # Errors
    /// The request's validation errors.
    fn study(&self, model: &Resolved) -> Result<Self::Study, SimError>;
    /// Run `study` on `model` into `storage`, counting in `progress`: the request's output.
    ///
    /// # Errors
    /// The store's and the study's.
    fn resume(
        &self,
        study: &Self::Study,
        model: &Resolved,
        storage: Storage<'_>,
        progress: &Progress,
    ) -> Result<Self::Output, StudyError>;
    /// A result that is no answer (every chart cell, every sweep point failed): its files
    /// are still written, then it fails. `None` by default.
    fn failure(&self, _output: &Self::Output) -> Option<Failure> {
        None
    }
}

/// A stored result that is no answer ([`Resumable::failure`]).
#[derive(Debug)]
pub struct Failure {
    /// The error.
    pub error: SimError,
    /// Whether a front end prints the document (`--json`) before failing (a sweep's tally).
    pub with_document: bool,
}

/// A stepped curve's points run into the curve store, then its branches.
fn curve(
    study: &CurveStudy,
    storage: Storage<'_>,
    progress: &Progress,
) -> Result<SteppedCurve, StudyError> {
    let records = storage.records(&study.chain(), curve_store, None, progress)?;
    Ok(study.curve(records, progress)?)
}

/// `Resumable` for a stepped-curve request whose study `$study(request, model)` makes: its
/// points run into the curve store, then its branches ([`curve`]).
macro_rules! curve_resumable {
    ($request:ty, $study:expr) => {
        impl Resumable for $request {
            type Study = CurveStudy;
            fn study(&self, model: &Resolved) -> Result<CurveStudy, SimError> {
                $study(self, model)
            }
            fn resume(
                &self,
                study: &CurveStudy,
                _: &Resolved,
                storage: Storage<'_>,
                progress: &Progress,
            ) -> Result<Self::Output, StudyError> {
                curve(study, storage, progress)
            }
        }
    };
}

curve_resumable!(ApproachRequest, CurveStudy::approach);
curve_resumable!(ResonanceRequest, CurveStudy::resonance);
curve_resumable!(Bimodal, |r: &Bimodal, model: &Resolved| {
    crate::request::curves::check_bimodal(&model.params)?;
    CurveStudy::approach(&r.0, model)
});

impl Resumable for BasinsRequest {
    type Study = BasinStudy;
    fn study(&self, model: &Resolved) -> Result<BasinStudy, SimError> {
        BasinStudy::new(self, &model.params)
    }
    fn resume(
        &self,
        study: &BasinStudy,
        _: &Resolved,
        storage: Storage<'_>,
        progress: &Progress,
    ) -> Result<Self::Output, StudyError> {
        let rows = storage.records(&study.chain(), basin_store, self.threads, progress)?;
        let map = || study.map(rows.into_iter().map(|(_, r)| r));
        Ok(crate::study::in_pool(self.threads, map)?)
    }
}

impl Resumable for GlobalContinuationRequest {
    type Study = ContinuationStudy;
    fn study(&self, model: &Resolved) -> Result<ContinuationStudy, SimError> {
        ContinuationStudy::new(self, &model.params)
    }
    fn resume(
        &self,
        study: &ContinuationStudy,
        _: &Resolved,
        storage: Storage<'_>,
        progress: &Progress,
    ) -> Result<Self::Output, StudyError> {
        let records = storage.records(&study.chain(), continuation_store, None, progress)?;
        Ok(study.steps(records)?)
    }
}

/// A chart is its own study (validated and held to the budgets when it was built).
impl Resumable for Chart {
    type Study = ();
    fn study(&self, _: &Resolved) -> Result<(), SimError> {
        Ok(())
    }
    fn resume(
        &self,
        _: &(),
        _: &Resolved,
        storage: Storage<'_>,
        progress: &Progress,
    ) -> Result<Self::Output, StudyError> {
        Ok(cells_of(storage.records(
            &self.tasks(),
            chart_store,
            self.threads,
            progress,
        )?))
    }
    fn failure(&self, cells: &Self::Output) -> Option<Failure> {
        let error = super::chart::every_cell_failed(cells)?;
        Some(Failure {
            error,
            with_document: false,
        })
    }
}

/// An image: a PI scan's lines run into the store (its study computes the materials' curves);
/// an image of the ideal feedback, or a PeakForce image, in memory.
impl Resumable for ImageJob {
    type Study = Option<ScanStudy>;
    fn study(&self, _: &Resolved) -> Result<Option<ScanStudy>, SimError> {
        self.scan_study()
    }
    fn resume(
        &self,
        study: &Option<ScanStudy>,
        model: &Resolved,
        storage: Storage<'_>,
        progress: &Progress,
    ) -> Result<Self::Output, StudyError> {
        let Some(study) = study else {
            return Ok(self.execute(model, progress)?);
        };
        let records = storage.records(&study.tasks(), scan_store, self.threads, progress)?;
        Ok(ImageOutput::Pi(study.assemble(records)?))
    }
}

/// `bifurcation` into the files of its store (`afmdyn bifurcation --out DIR`): the sweep run
/// resumably into the directory's checkpoint, then tallied, its NPY written and its diagrams
/// streamed from the finished rows' CSV (`SweepFiles`), so that memory does not grow with
/// the sweep. It runs only into a directory.
#[derive(Debug, Clone)]
pub struct SweepInto(pub BifurcationRequest);

/// Why a sweep into files cannot run without a directory.
const NO_DIRECTORY: &str = "a sweep into its store's files needs the store's directory";

impl Request for SweepInto {
    fn validate(&self, model: &Resolved) -> Result<(), SimError> {
        self.0.validate(model)
    }
    fn name(&self) -> &'static str {
        self.0.name()
    }
    fn cost(&self, model: &Resolved) -> Result<crate::request::limits::Cost, SimError> {
        self.0.cost(model)
    }
}

impl Analysis for SweepInto {
    type Output = SweepFiles;
    fn convergence(&self, files: &SweepFiles) -> Convergence {
        let t = &files.tally;
        let settled = t.periodic + t.nonperiodic;
        Convergence::of("points", settled, settled + t.errors)
    }
    fn execute(&self, _: &Resolved, _: &Progress) -> Result<SweepFiles, SimError> {
        Err(SimError::File(NO_DIRECTORY.into()))
    }
    fn report(&self, model: &Resolved, files: &SweepFiles) -> Result<Value, SimError> {
        let values = files.spec.values.len();
        let mut doc = files.tally.document(&model.params, self.0.param, values);
        doc["csv"] = serde_json::json!(files.csv);
        doc["npy"] = serde_json::json!(files.npy);
        Ok(doc)
    }
    fn present(
        &self,
        files: &SweepFiles,
        _: crate::request::Presenting<'_>,
    ) -> Result<crate::report::Presentation, SimError> {
        Ok(stored_bifurcation(files, self.0.param))
    }
}

impl Resumable for SweepInto {
    type Study = SweepStudy;
    fn study(&self, model: &Resolved) -> Result<SweepStudy, SimError> {
        Ok(SweepStudy::new(&self.0, self.0.spec(&model.params)?))
    }
    fn resume(
        &self,
        study: &SweepStudy,
        _: &Resolved,
        storage: Storage<'_>,
        progress: &Progress,
    ) -> Result<SweepFiles, StudyError> {
        let sweep = storage.run(study, sweep_checkpoint, self.0.threads, progress)?;
        let Ran::Stored(store) = sweep else {
            return Err(SimError::File(NO_DIRECTORY.into()).into());
        };
        // derived from the finished rows, streamed
        let dir = store.dir();
        let csv = final_csv(dir);
        let mut tally = SweepTally::default();
        each_row(&csv, &mut |r| -> Result<(), CheckpointError> {
            tally.add_row(SweepRow::from_csv(r));
            Ok(())
        })?;
        let npy = write_npy(dir, self.0.param).map_err(SimError::from)?;
        Ok(SweepFiles {
            spec: study.spec.clone(),
            tally,
            csv,
            npy,
        })
    }
    fn failure(&self, files: &SweepFiles) -> Option<Failure> {
        Some(Failure {
            error: files.tally.failure()?,
            with_document: true,
        })
    }
}

/// A request of a study run into a store.
pub trait Stored: Send {
    /// Its study on `model` (validated), ready to run.
    ///
    /// # Errors
    /// The request's validation errors.
    fn prepare(self: Box<Self>, model: Resolved) -> Result<Box<dyn Prepared>, SimError>;
    /// What the request uses of its probe ([`crate::request::run::Request::probe_needs`]).
    fn probe_needs(&self) -> crate::probe::ProbeNeeds {
        crate::probe::ProbeNeeds::Oscillation
    }
}

/// A study ready to run into a store.
pub trait Prepared: Send {
    /// Run into the store of `lock` (continued with `resume`; `None`: in memory), counting
    /// in `progress`: the outcome.
    ///
    /// # Errors
    /// The store's and the study's.
    fn run(
        &self,
        lock: Option<&DirLock>,
        resume: bool,
        progress: &Progress,
    ) -> Result<Outcome, StudyError>;
}

/// A [`Resumable`] request, with its model and study once prepared.
struct Held<A: Resumable> {
    request: A,
    ready: Option<(Resolved, A::Study)>,
}

impl<A> Stored for Held<A>
where
    A: Resumable + Datasets + Send + 'static,
{
    fn prepare(mut self: Box<Self>, model: Resolved) -> Result<Box<dyn Prepared>, SimError> {
        let study = self.request.study(&model)?;
        self.ready = Some((model, study));
        Ok(self)
    }
    fn probe_needs(&self) -> crate::probe::ProbeNeeds {
        self.request.probe_needs()
    }
}

impl<A> Prepared for Held<A>
where
    A: Resumable + Datasets + Send,
{
    fn run(
        &self,
        lock: Option<&DirLock>,
        resume: bool,
        progress: &Progress,
    ) -> Result<Outcome, StudyError> {
        let Some((model, study)) = &self.ready else {
            return Err(SimError::Cancelled.into()); // unreachable: only `prepare` makes one
        };
        let storage = Storage {
            lock,
            resume,
            abort_after: None,
        };
        let output = self.request.resume(study, model, storage, progress)?;
        // a result that is no answer (every curve, every cell failed) is the front end's error
        if let Some(failed) = self.request.failure(&output) {
            return Err(failed.error.into());
        }
        Ok(named::outcome(&self.request, model, &output)?)
    }
}

/// `request` held until prepared.
fn held<A: Resumable + Datasets + Send + 'static>(request: A) -> Box<dyn Stored> {
    Box::new(Held {
        request,
        ready: None,
    })
}

/// The study run into a store of analysis `name` with the request `d` deserialises to
/// (`bimodal`: the approach curve's request, refused on a drive of one component); `None` for
/// a name without one.
///
/// # Errors
/// The deserialiser's (an unknown key, a bad value).
pub fn parse<'de, D: Deserializer<'de>>(
    name: &str,
    d: D,
) -> Result<Option<Box<dyn Stored>>, D::Error> {
    Ok(Some(match name {
        "basins" => held(BasinsRequest::deserialize(d)?),
        "global_continuation" => held(GlobalContinuationRequest::deserialize(d)?),
        "approach" => held(ApproachRequest::deserialize(d)?),
        "bimodal" => held(Bimodal(ApproachRequest::deserialize(d)?)),
        "bifurcation" => Box::new(Sweep {
            request: BifurcationRequest::deserialize(d)?,
            spec: None,
        }),
        "resonance" => held(ResonanceRequest::deserialize(d)?),
        "fit_map" => held(crate::request::FitMapRequest::deserialize(d)?),
        _ => return Ok(None),
    }))
}

/// A bifurcation sweep, run into its checkpoint (the store's `bifurcation.csv`, or memory).
struct Sweep {
    request: BifurcationRequest,
    spec: Option<SweepSpec>,
}

impl Stored for Sweep {
    fn prepare(mut self: Box<Self>, model: Resolved) -> Result<Box<dyn Prepared>, SimError> {
        self.spec = Some(self.request.spec(&model.params)?);
        Ok(self)
    }
}

impl Prepared for Sweep {
    fn run(
        &self,
        lock: Option<&DirLock>,
        resume: bool,
        progress: &Progress,
    ) -> Result<Outcome, StudyError> {
        let Some(spec) = &self.spec else {
            return Err(SimError::Cancelled.into()); // unreachable: only `prepare` makes one
        };
        let study = SweepStudy::new(&self.request, spec.clone());
        let storage = Storage {
            lock,
            resume,
            abort_after: None,
        };
        let records = match storage.run(&study, sweep_checkpoint, self.request.threads, progress)? {
            Ran::Stored(store) => final_rows(store.dir())?,
            Ran::Memory(points) => points.into_iter().flatten().collect(),
        };
        if let Some(e) = every_point_failed(&records) {
            return Err(e.into());
        }
        Ok(sweep_outcome(spec, &records))
    }
}

/// A sweep's records (in their order) as an outcome: no document but the swept parameter and
/// its values (also the facts), the records' layout ([`crate::request::sweep::layout`]) as
/// `bifurcation`.
pub(crate) fn sweep_outcome(spec: &SweepSpec, records: &[SweepRecord]) -> Outcome {
    let facts = serde_json::json!({ "param": spec.param.name(), "values": spec.values });
    let layout = crate::request::sweep::layout(spec, records);
    Outcome {
        document: facts.clone(),
        datasets: vec![("bifurcation".into(), layout)],
        facts: facts.as_object().cloned().unwrap_or_default(),
    }
}

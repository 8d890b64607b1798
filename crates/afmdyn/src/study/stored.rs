//! The studies a front end runs by name into the command line's resumable store ([`parse`]:
//! `bifurcation`, `basins`, `global_continuation`, `approach`, `bimodal`, `resonance`): the request parsed,
//! its study made on the model ([`Stored::prepare`]: validated, before any side effect) and
//! run into the store of a locked directory, continued with `resume` ([`Prepared::run`]), to the
//! outcome the one door gives for the same request ([`crate::request::named::outcome`]).

use super::basins::{basin_store, BasinStudy};
use super::global_continuation::{continuation_store, ContinuationStudy};
use super::stepped::{curve_store, CurveStudy};
use super::sweep::SweepStudy;
use super::task_store::{StoredTasks, TaskStore};
use super::{execute, MemoryStore, Study, StudyError};
use crate::analysis::bifurcation::SweepSpec;
use crate::analysis::progress::Progress;
use crate::error::SimError;
use crate::request::named::{self, Datasets, Outcome};
use crate::request::sweep::{every_point_failed, SweepRecord};
use crate::request::{ApproachRequest, BasinsRequest, BifurcationRequest, DirLock};
use crate::request::{FileCheckpoint, GlobalContinuationRequest, MemoryCheckpoint};
use crate::request::{Resolved, ResonanceRequest};
use serde::de::{DeserializeOwned, Deserializer};
use serde::{Deserialize, Serialize};

/// A request of a study run into a store.
pub trait Stored: Send {
    /// Its study on `model` (validated), ready to run.
    ///
    /// # Errors
    /// The request's validation errors.
    fn prepare(self: Box<Self>, model: Resolved) -> Result<Box<dyn Prepared>, SimError>;
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

/// A request with what makes its study (`of`), opens its store (`open`) and finishes its
/// output from the stored records (`finish`); `ready` once prepared.
struct Plan<A, S, R, Of, Fin> {
    request: A,
    threads: Option<usize>,
    of: Of,
    open: fn(&DirLock) -> TaskStore<'_, R>,
    finish: Fin,
    ready: Option<(Resolved, S)>,
}

impl<A, S, R, Of, Fin> Stored for Plan<A, S, R, Of, Fin>
where
    A: Datasets + Send + 'static,
    A::Output: Send,
    S: Study<Record = (usize, R)> + Send + 'static,
    S::Done: StoredTasks<R>,
    R: Serialize + DeserializeOwned + Clone + Send + 'static,
    Of: Fn(&A, &Resolved) -> Result<S, SimError> + Send + 'static,
    Fin: Fn(&S, Vec<(usize, R)>, &Progress) -> Result<A::Output, SimError> + Send + Sync + 'static,
{
    fn prepare(mut self: Box<Self>, model: Resolved) -> Result<Box<dyn Prepared>, SimError> {
        let study = (self.of)(&self.request, &model)?;
        self.ready = Some((model, study));
        Ok(self)
    }
}

impl<A, S, R, Of, Fin> Prepared for Plan<A, S, R, Of, Fin>
where
    A: Datasets + Send,
    A::Output: Send,
    S: Study<Record = (usize, R)> + Send,
    S::Done: StoredTasks<R>,
    R: Serialize + DeserializeOwned + Clone + Send,
    Of: Send,
    Fin: Fn(&S, Vec<(usize, R)>, &Progress) -> Result<A::Output, SimError> + Send + Sync,
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
        let records = match lock {
            Some(lock) => {
                let mut store = (self.open)(lock);
                execute(study, &mut store, resume, self.threads, progress)?;
                store.records()?
            }
            None => {
                let mut store = MemoryStore::default();
                execute(study, &mut store, false, self.threads, progress)?;
                store.records
            }
        };
        let finish = &self.finish;
        let finish = || finish(study, records, progress);
        let output = crate::request::in_pool(self.threads, finish)?;
        Ok(named::outcome(&self.request, model, &output)?)
    }
}

fn plan<A, S, R, Of, Fin>(
    request: A,
    threads: Option<usize>,
    of: Of,
    open: fn(&DirLock) -> TaskStore<'_, R>,
    finish: Fin,
) -> Box<dyn Stored>
where
    A: Datasets + Send + 'static,
    A::Output: Send,
    S: Study<Record = (usize, R)> + Send + 'static,
    S::Done: StoredTasks<R>,
    R: Serialize + DeserializeOwned + Clone + Send + 'static,
    Of: Fn(&A, &Resolved) -> Result<S, SimError> + Send + 'static,
    Fin: Fn(&S, Vec<(usize, R)>, &Progress) -> Result<A::Output, SimError> + Send + Sync + 'static,
{
    Box::new(Plan {
        request,
        threads,
        of,
        open,
        finish,
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
    let curve = |s: &CurveStudy, records: Vec<_>, progress: &Progress| s.curve(records, progress);
    Ok(Some(match name {
        "basins" => {
            let r = BasinsRequest::deserialize(d)?;
            let threads = r.threads;
            let of = |r: &BasinsRequest, m: &Resolved| BasinStudy::new(r, &m.params);
            let map = |s: &BasinStudy, records: Vec<_>, _: &Progress| {
                s.map(records.into_iter().map(|(_, r)| r))
            };
            plan(r, threads, of, basin_store, map)
        }
        "global_continuation" => {
            let r = GlobalContinuationRequest::deserialize(d)?;
            let of =
                |r: &GlobalContinuationRequest, m: &Resolved| ContinuationStudy::new(r, &m.params);
            let steps = |s: &ContinuationStudy, records, _: &Progress| s.steps(records);
            plan(r, None, of, continuation_store, steps)
        }
        "approach" => plan(
            ApproachRequest::deserialize(d)?,
            None,
            CurveStudy::approach,
            curve_store,
            curve,
        ),
        "bimodal" => {
            let of = |r: &ApproachRequest, m: &Resolved| {
                crate::request::curves::check_bimodal(&m.params)?;
                CurveStudy::approach(r, m)
            };
            plan(
                ApproachRequest::deserialize(d)?,
                None,
                of,
                curve_store,
                curve,
            )
        }
        "bifurcation" => Box::new(Sweep {
            request: BifurcationRequest::deserialize(d)?,
            spec: None,
        }),
        "resonance" => plan(
            ResonanceRequest::deserialize(d)?,
            None,
            CurveStudy::resonance,
            curve_store,
            curve,
        ),
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
        let threads = self.request.threads;
        let records = match lock {
            Some(lock) => {
                let mut s = FileCheckpoint::new(lock);
                execute(&study, &mut s, resume, threads, progress)?;
                s.records()?
            }
            None => {
                let mut s = MemoryCheckpoint::default();
                execute(&study, &mut s, false, threads, progress)?;
                s.into_records()
            }
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

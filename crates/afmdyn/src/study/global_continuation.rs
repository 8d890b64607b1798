//! A global continuation ([`crate::analysis::global_continuation`]) as a `Chain`
//! (`ContinuationStudy::chain`): a task is one value of the parameter, numbered by its place in the
//! values; its record the value's step (its attractors with their ids); the tasks form one
//! chain — each value's census is seeded from the previous value's attractors and its ids
//! matched to them — so what a resume skips is the stored steps themselves, and the chain goes
//! on after the last (`continue_values`), to the steps of an uninterrupted run. Stored by
//! `MemoryStore` for a run that writes no files, by the directory store
//! `continuation_store` (feature `files`) for `afmdyn attractors --sweep --out DIR`,
//! resumable.
//!
//! The request's [`Analysis`] (`request::run`, Python's `afmdyn.global_continuation`) runs
//! this study in memory.

use super::{execute_in_memory, Chain};
use crate::analysis::global_continuation::{
    continue_values, ContinuationStep, GlobalContinuationSpec,
};
use crate::analysis::progress::Progress;
use crate::error::SimError;
use crate::params::Params;
use crate::report::{self, Convergence};
use crate::request::costs::{census_cost, check_cost};
use crate::request::run::{Analysis, Resolved};
use crate::request::GlobalContinuationRequest;
use serde_json::{json, Value};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// A global continuation, its study a `Chain` (see the module doc): its validated spec and its
/// fingerprint.
#[derive(Debug, Clone)]
pub struct ContinuationStudy {
    /// The validated continuation.
    pub spec: GlobalContinuationSpec,
    /// What a resumed continuation must match (`fingerprint`).
    pub fingerprint: Value,
}

/// The fingerprint of a global continuation: everything that determines its steps (the
/// library's version, the model values, every option of the request).
pub(crate) fn fingerprint(request: &GlobalContinuationRequest, params: &Params) -> Value {
    json!({
        "afmdyn": env!("CARGO_PKG_VERSION"),
        "global_continuation": request,
        "params": params,
    })
}

impl ContinuationStudy {
    /// The study of `request` over `params`.
    ///
    /// # Errors
    /// As [`GlobalContinuationRequest::spec`]; [`SimError::Budget`] beyond the budgets of a request
    /// ([`check_cost`]).
    pub(crate) fn new(
        request: &GlobalContinuationRequest,
        params: &Params,
    ) -> Result<ContinuationStudy, SimError> {
        let spec = request.spec(params)?;
        // held to the budgets here too: a front end runs the study into its store without
        // `run`
        check_cost(
            "attractors --sweep",
            census_cost(&spec.census, spec.values.len())?,
        )?;
        Ok(ContinuationStudy {
            spec,
            fingerprint: fingerprint(request, params),
        })
    }

    /// The steps of a finished study's records (in any order), in the order of the values.
    ///
    /// # Errors
    /// [`SimError::Cancelled`] when a value is missing (a run that was cut short).
    pub fn steps(
        &self,
        records: impl IntoIterator<Item = (usize, ContinuationStep)>,
    ) -> Result<Vec<ContinuationStep>, SimError> {
        super::in_order(records.into_iter().collect(), self.spec.values.len())
    }

    /// The continuation as a `Chain`: its values (their random starts the units), continued
    /// after every stored step ([`continue_values`]; a store holds its first values: a step is
    /// stored once the one before it is).
    pub(crate) fn chain(&self) -> Chain<'_, ContinuationStep, Vec<ContinuationStep>> {
        let samples = self.spec.census.samples as u64;
        let units = self.spec.values.len() as u64 * samples;
        let run = |done: &[ContinuationStep],
                   sink: &(dyn Fn(usize, ContinuationStep) + Sync),
                   cancel: &AtomicBool| {
            let index = AtomicUsize::new(done.len());
            let store =
                |s: &ContinuationStep| sink(index.fetch_add(1, Ordering::SeqCst), s.clone());
            continue_values(&self.spec, done, cancel, &store).map(|_| ())
        };
        Chain::new(&self.fingerprint, self.spec.values.len(), run).weighted(units, move |_| samples)
    }
}

impl Analysis for GlobalContinuationRequest {
    type Output = Vec<ContinuationStep>;
    /// A value's census converged: it found an attractor, no run failed, none is unsettled and
    /// no caveat was raised (a start still settling at the transient cap, or undecided, λ₁ ≈ 0).
    fn convergence(&self, steps: &Self::Output) -> Convergence {
        Convergence::count("values", steps, |s| {
            let unsettled = s.attractors.iter().any(|(_, a)| a.unsettled());
            !s.attractors.is_empty() && s.failures.is_empty() && s.warnings.is_empty() && !unsettled
        })
    }
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<Self::Output, SimError> {
        let study = ContinuationStudy::new(self, &model.params)?;
        let records = execute_in_memory(&study.chain(), None, progress)?;
        study.steps(records)
    }
    fn report(&self, model: &Resolved, steps: &Self::Output) -> Result<Value, SimError> {
        Ok(report::global_continuation(
            &model.params,
            self.param,
            self.samples,
            steps,
        ))
    }
    #[cfg(feature = "files")]
    fn present(
        &self,
        steps: &Self::Output,
        at: crate::request::Presenting<'_>,
    ) -> Result<report::Presentation, SimError> {
        Ok(crate::report::present::census::global_continuation(
            (self.param, self.samples),
            steps,
            at.document,
        ))
    }
}

/// The resumable store of a global continuation (feature `files`): a
/// [`TaskStore`](crate::study::task_store::TaskStore) of steps in the directory
/// `afmdyn attractors --sweep --out DIR` names — `.continuation.run.json` (the ledger) and
/// `.continuation.values.jsonl` (one checksummed line per value, its step in CBOR under
/// `"step"`), as [`crate::study::task_store`] describes.
#[cfg(feature = "files")]
pub(crate) mod store {
    use super::super::task_store::{Encoding, Lines, TaskFiles, TaskStore};
    use crate::analysis::global_continuation::ContinuationStep;
    use crate::io::dir_lock::DirLock;

    /// The global continuation's files.
    pub(crate) const CONTINUATION_FILES: TaskFiles = TaskFiles {
        ledger: ".continuation.run.json",
        records: ".continuation.values.jsonl",
        key: "step",
        prefix: "global_continuation.",
        encoding: Encoding::Cbor,
    };

    /// A global continuation's store: its steps by value.
    pub(crate) type ContinuationStore<'a> = TaskStore<'a, Lines<ContinuationStep>>;

    /// The continuation store of the directory `lock` holds.
    pub(crate) fn continuation_store(lock: &DirLock) -> ContinuationStore<'_> {
        TaskStore::new(lock, Lines::of(CONTINUATION_FILES)).keeping()
    }
}

#[cfg(feature = "files")]
pub(crate) use store::continuation_store;

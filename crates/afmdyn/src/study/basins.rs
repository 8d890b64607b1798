//! A basin map ([`crate::analysis::basins`]) as a `Chain` (`BasinStudy::chain`): a task is one
//! row of one pass, numbered `pass × ny + iy`; its record the finished row ([`BasinRow`]: its
//! cells and the attractors found there); what a resume skips the stored rows themselves, since
//! each pass begins with the attractors and the coarse grid of the passes before it
//! (`run_passes` merges the stored rows in their place, so a resumed map is the
//! uninterrupted one). The map is assembled from the records by `basin_map`, whatever store
//! kept them: `MemoryStore` for a run that writes no files, the
//! directory store `basin_store` (feature `files`) for `afmdyn basins --out DIR`, resumable.
//!
//! The request's [`Analysis`] (`request::run`, Python's `afmdyn.basins`) runs this study in
//! memory.

use super::{execute_in_memory, Chain};
use crate::analysis::basins::{basin_map, run_passes, BasinMap, BasinRow, BasinSpec, Decided};
use crate::analysis::progress::Progress;
use crate::error::SimError;
use crate::model::CantileverModel;
use crate::params::Params;
use crate::report::basins::document;
use crate::report::Convergence;
use crate::request::costs::{basins_cost, check_cost};
use crate::request::run::{Analysis, Resolved};
use crate::request::BasinsRequest;
use serde_json::{json, Value};
use std::sync::atomic::AtomicBool;

/// A basin map, its study a `Chain` (see the module doc): its validated spec, its model and its
/// fingerprint.
#[derive(Debug, Clone)]
pub struct BasinStudy {
    /// The validated map.
    pub spec: BasinSpec,
    /// The cantilever of `spec.params`.
    pub model: CantileverModel,
    /// What a resumed map must match (`fingerprint`).
    pub fingerprint: Value,
}

/// The fingerprint of a basin map: everything that determines its cells (the library's
/// version, the model values, every option of the request but the threads).
pub(crate) fn fingerprint(request: &BasinsRequest, params: &Params) -> Value {
    let mut r = serde_json::to_value(request).unwrap_or(Value::Null);
    if let Some(map) = r.as_object_mut() {
        map.remove("threads");
    }
    json!({
        "afmdyn": env!("CARGO_PKG_VERSION"),
        "basins": r,
        "params": params,
    })
}

impl BasinStudy {
    /// The study of `request` over `params`.
    ///
    /// # Errors
    /// As [`BasinsRequest::spec`]; [`SimError::Budget`] beyond the budgets of a request
    /// ([`check_cost`]).
    pub(crate) fn new(request: &BasinsRequest, params: &Params) -> Result<BasinStudy, SimError> {
        let spec = request.spec(params)?;
        // held to the budgets here too: a front end runs the study into its store without
        // `run`
        check_cost("basins", basins_cost(&spec)?)?;
        let model = CantileverModel::new(params)?;
        Ok(BasinStudy {
            spec,
            model,
            fingerprint: fingerprint(request, params),
        })
    }

    /// The number of task `row` (its pass and row index).
    pub(crate) fn task(&self, row: &BasinRow) -> usize {
        row.pass * self.spec.ys.len() + row.iy
    }

    /// The map of a finished study's records (in any order), as `basin_map`.
    ///
    /// # Errors
    /// As `basin_map`: [`SimError::Cancelled`] when a row is missing.
    pub fn map(&self, records: impl IntoIterator<Item = BasinRow>) -> Result<BasinMap, SimError> {
        basin_map(&self.spec, records.into_iter().collect())
    }

    /// The map as a `Chain`: its rows pass by pass (their cells the units), each pass after
    /// every stored row ([`run_passes`]).
    pub(crate) fn chain(&self) -> Chain<'_, BasinRow, Vec<BasinRow>> {
        let units = (self.spec.xs.len() * self.spec.ys.len()) as u64;
        let run =
            |done: &[BasinRow], sink: &(dyn Fn(usize, BasinRow) + Sync), cancel: &AtomicBool| {
                let store = |row: &BasinRow| sink(self.task(row), row.clone());
                run_passes(&self.spec, &self.model, done, &store, cancel).map(|_| ())
            };
        Chain::new(&self.fingerprint, 0, run).weighted(units, |row| row.cells.len() as u64)
    }
}

impl Analysis for BasinsRequest {
    type Output = BasinMap;
    fn convergence(&self, map: &BasinMap) -> Convergence {
        Convergence::count("cells", &map.cells, |c| c.decided != Decided::Failed)
    }
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<BasinMap, SimError> {
        let study = BasinStudy::new(self, &model.params)?;
        let records = execute_in_memory(&study.chain(), self.threads, progress)?;
        crate::study::in_pool(self.threads, || {
            study.map(records.into_iter().map(|(_, r)| r))
        })
    }
    fn report(&self, model: &Resolved, map: &BasinMap) -> Result<Value, SimError> {
        let spec = self.spec(&model.params)?;
        Ok(document(&spec, map))
    }
    fn present(
        &self,
        map: &BasinMap,
        at: crate::request::Presenting<'_>,
    ) -> Result<crate::report::Presentation, SimError> {
        let spec = self.spec(&at.model.params)?;
        let Some(dir) = at.to.dir else {
            return crate::report::present::maps::basins(&spec, map, at.document);
        };
        // the document (basins.json too) names the files written
        let mut document = at.document.clone();
        document["csv"] = serde_json::json!(dir.join("basins.csv"));
        document["netcdf"] = serde_json::json!(dir.join("basins.nc"));
        let mut shown = crate::report::present::maps::basins(&spec, map, &document)?;
        shown.document = Some(document);
        shown.outputs_note = crate::report::OutputsNote::Tail;
        Ok(shown)
    }
}

/// The resumable store of a basin map (feature `files`): a [`TaskStore`](crate::study::task_store::TaskStore) of rows in the
/// directory `afmdyn basins --out DIR` names — `.basins.run.json` (the ledger) and
/// `.basins.rows.jsonl` (one checksummed line per finished row, under `"row"`), as
/// [`crate::study::task_store`] describes.
#[cfg(feature = "files")]
pub(crate) mod store {
    use super::super::task_store::{Encoding, Lines, TaskFiles, TaskStore};
    use crate::analysis::basins::BasinRow;
    use crate::io::dir_lock::DirLock;

    /// The basin map's files.
    pub(crate) const BASIN_FILES: TaskFiles = TaskFiles {
        ledger: ".basins.run.json",
        records: ".basins.rows.jsonl",
        key: "row",
        prefix: "basins.",
        encoding: Encoding::Cbor,
    };

    /// A basin map's store: its rows by task.
    pub(crate) type BasinStore<'a> = TaskStore<'a, Lines<BasinRow>>;

    /// The basin store of the directory `lock` holds.
    pub(crate) fn basin_store(lock: &DirLock) -> BasinStore<'_> {
        TaskStore::new(lock, Lines::of(BASIN_FILES)).keeping()
    }
}

#[cfg(feature = "files")]
pub(crate) use store::basin_store;

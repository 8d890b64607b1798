//! A behaviour chart ([`crate::request::chart::Chart`]) as a study of independent tasks
//! (`Chart::tasks`): its tasks are the tiles of [`ChartPlan`] (cells of one row, continued
//! along x), its record a tile's cells with the task's number, what a resume skips the stored
//! tasks ([`super::chart_store`]).

use super::{execute_in_memory, Tasks};
pub use crate::analysis::chart::{ChartCell, ChartPlan};
use crate::analysis::progress::Progress;
use crate::error::SimError;
use crate::request::chart::chart_cost;
use crate::request::chart::{document, Chart};
use crate::request::limits::Cost;
use crate::request::run::{Analysis, Request, Resolved};
use serde_json::Value;

impl Chart {
    /// The chart as a `Tasks` study: its tasks the tiles of [`ChartPlan`], each counting its
    /// cells (a cell that fails is a cell without attractors, with its message: no task fails).
    pub(crate) fn tasks(&self) -> Tasks<'_, Vec<ChartCell>> {
        let plan = ChartPlan::new(&self.spec, &self.model);
        let cells: Vec<u64> = (0..plan.tasks())
            .map(|t| plan.tile(t).1.len() as u64)
            .collect();
        Tasks::new(&self.fingerprint, plan.tasks(), move |t, cancel| {
            Ok(plan.run_task(t, cancel))
        })
        .weighted(move |t| cells[t])
    }
}

/// A validated chart runs as an analysis ([`crate::request::run()`], Python's `afmdyn.chart`):
/// its model is its own — [`ChartRequest::chart`](crate::request::ChartRequest::chart) built
/// it from the request's model values, defaults and probe, validated every option and held
/// its cost to the budgets — so the `model` given here is not read (pass
/// [`Resolved::plain`] of any parameters). Its study runs in memory on its threads.
impl Request for Chart {
    fn validate(&self, _: &Resolved) -> Result<(), SimError> {
        Ok(())
    }
    fn name(&self) -> &'static str {
        "chart"
    }
    fn cost(&self, _: &Resolved) -> Result<Cost, SimError> {
        chart_cost(self)
    }
}

impl Analysis for Chart {
    type Output = Vec<ChartCell>;
    fn execute(&self, _: &Resolved, progress: &Progress) -> Result<Vec<ChartCell>, SimError> {
        let cells = cells_of(execute_in_memory(&self.tasks(), self.threads, progress)?);
        match every_cell_failed(&cells) {
            Some(e) => Err(e),
            None => Ok(cells),
        }
    }
    fn report(&self, _: &Resolved, cells: &Vec<ChartCell>) -> Result<Value, SimError> {
        Ok(document(self, cells))
    }
    fn present(
        &self,
        cells: &Vec<ChartCell>,
        at: crate::request::Presenting<'_>,
    ) -> Result<crate::report::Presentation, SimError> {
        let mut shown = crate::report::present::maps::chart(&self.view(), cells);
        // the printed document names the files written
        if let Some(dir) = at.to.dir {
            let mut document = at.document.clone();
            document["files"] = serde_json::json!({
                "csv": dir.join("chart.csv"),
                "netcdf": dir.join("chart.nc"),
            });
            shown.document = Some(document);
            shown.outputs_note = crate::report::OutputsNote::Tail;
        }
        Ok(shown)
    }
}

/// The cells of the tasks `records` (a [`super::MemoryStore`]'s, in any order), row
/// by row, x increasing.
pub(crate) fn cells_of(records: Vec<(usize, Vec<ChartCell>)>) -> Vec<ChartCell> {
    let mut cells: Vec<ChartCell> = records.into_iter().flat_map(|(_, c)| c).collect();
    cells.sort_by_key(|c| (c.iy, c.ix));
    cells
}

/// The chart's failure when no cell found any attractor: the one rule of every front end
/// (with the first cell's message).
pub fn every_cell_failed(cells: &[ChartCell]) -> Option<SimError> {
    every_count_zero(
        cells.iter().map(|c| c.attractors.len()),
        cells.iter().find_map(|c| c.message.clone()),
    )
}

/// [`every_cell_failed`] from the cells' attractor counts and the first failure's message
/// (`None`: a store that keeps no messages, such as the Dask Zarr store).
pub fn every_count_zero(
    counts: impl IntoIterator<Item = usize>,
    first: Option<String>,
) -> Option<SimError> {
    let mut runs = 0;
    for n in counts {
        if n > 0 {
            return None;
        }
        runs += 1;
    }
    Some(SimError::EveryRunFailed {
        what: "chart cells",
        runs,
        first: first.unwrap_or_else(|| "no attractor found (the store keeps no messages)".into()),
    })
}

#[cfg(test)]
mod tests {
    use super::every_count_zero;

    /// One cell with an attractor is an answer; none is the failure naming the count.
    #[test]
    fn a_chart_fails_only_when_no_cell_found_an_attractor() {
        assert!(every_count_zero([0, 2, 0], None).is_none());
        let e = every_count_zero([0, 0, 0], Some("diverged".into())).unwrap();
        assert_eq!(
            e.to_string(),
            "every one of the 3 chart cells failed; the first: diverged"
        );
    }
}

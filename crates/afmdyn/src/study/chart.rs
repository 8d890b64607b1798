//! A behaviour chart ([`crate::request::chart::Chart`]) as a study of independent tasks
//! (`Chart::tasks`): its tasks are the tiles of [`ChartPlan`] (cells of one row, continued
//! along x), its record a tile's cells with the task's number, what a resume skips the stored
//! tasks ([`super::chart_store`]). Its answer: the `--json` [`document`] with its
//! `warnings`, the CSV rows ([`csv_lines`]) and arrays ([`ChartArrays::layout`])
//! over the chart's axes, and its presentation (`Chart::view`).

use super::{execute_in_memory, Tasks};
use crate::analysis::chart::CellParams;
pub use crate::analysis::chart::{ChartCell, ChartPlan};
use crate::analysis::progress::Progress;
use crate::error::SimError;
use crate::layout::Layout;
use crate::report::chart_layout::ChartAxis;
use crate::report::Convergence;
use crate::request::chart::{axis_unit, Chart, ChartArrays};
use crate::request::parameter;
use crate::request::run::Analysis;
use crate::request::run::Resolved;
use serde_json::{json, Value};

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

impl Analysis for Chart {
    type Output = Vec<ChartCell>;
    fn convergence(&self, cells: &Vec<ChartCell>) -> Convergence {
        convergence(cells)
    }
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

/// The axis `name` as the chart's files show it: its symbol in [`super::MODEL_PARAMETERS`]
/// and its unit ([`axis_unit`]).
pub(crate) fn axis(name: &str) -> ChartAxis<'_> {
    let symbol = parameter(name).map_or(name, |p| p.symbol);
    ChartAxis {
        name,
        symbol,
        unit: axis_unit(name),
    }
}

/// The rows of `cell` of `chart` as CSV lines of [`CSV_HEADER`](crate::request::chart::CSV_HEADER), lengths in g₀ or, with a
/// probe, in m (`ChartModel::length_m` of the cell).
pub fn csv_lines(chart: &Chart, cell: &ChartCell) -> Vec<String> {
    let length = chart.model.length_m(cell.x, cell.y).unwrap_or(1.0);
    crate::report::chart_layout::csv_lines(length, cell)
}

impl ChartArrays {
    /// The chart's layout over its axes named `x_name` and `y_name`: coordinates `x` and `y`
    /// in their axes' units, per cell (y, x) `attractors`, `failures`, `dominant_period`, and
    /// per attractor slot (y, x, attractor) `period`, `motion`, `lyapunov`, `lyapunov_error`,
    /// `x_max`, `v_t_min`, `contacts_per_period`, `contact_fraction`, `fraction`.
    pub fn layout(&self, x_name: &str, y_name: &str) -> Layout {
        self.layout_over(axis(x_name), axis(y_name))
    }

    /// The arrays of `cells` (any order; each cell once) of the whole chart.
    pub fn new(chart: &Chart, cells: &[ChartCell]) -> ChartArrays {
        let size = (chart.spec.x.len(), chart.spec.y.len());
        ChartArrays::region(chart, (0, 0), size, cells)
    }

    /// The arrays of the region of `size` = (columns, rows) from the cell `origin` = (ix, iy)
    /// of the chart: a task's tile is the region ((lo, iy), (hi − lo, 1)); cells outside it are
    /// left out.
    pub fn region(
        chart: &Chart,
        origin: (usize, usize),
        size: (usize, usize),
        cells: &[ChartCell],
    ) -> ChartArrays {
        ChartArrays::region_of((&chart.spec, chart.slots), origin, size, cells)
    }
}

impl Chart {
    /// The chart as its presentation reads it ([`crate::report::present::maps::ChartView`]).
    pub(crate) fn view(&self) -> crate::report::present::maps::ChartView<'_> {
        crate::report::present::maps::ChartView {
            spec: &self.spec,
            slots: self.slots,
            axes: (axis(self.model.x), axis(self.model.y)),
            length: Box::new(|x, y| self.model.length_m(x, y).unwrap_or(1.0)),
        }
    }
}

/// The caveats of a chart's answer (the `warnings` of its document): attractors that did not
/// settle within the transient cap, runs that failed.
pub(crate) fn warnings(chart: &Chart, cells: &[ChartCell]) -> Vec<String> {
    let mut w = Vec::new();
    use crate::analysis::chart::MotionKind;
    let settling = |c: &&ChartCell| {
        c.attractors.iter().any(|a| {
            matches!(
                a.motion(),
                MotionKind::Unsettled | MotionKind::Quasiperiodic
            )
        })
    };
    let unsettled: Vec<&ChartCell> = cells.iter().filter(settling).collect();
    if let Some(first) = unsettled.first() {
        w.push(warning!(
            "chart.nonperiodic",
            "Raise max_periods (a lever settles over ~Q periods): λ₁ then tells \
             quasi-periodic from still settling.",
            "{} of {} cells have a nonperiodic motion with λ₁ ≤ 0 (first at x = {}, y = {}): \
             quasi-periodic, or still settling after the transient cap ({}); raise \
             max_periods to tell (a cantilever of quality factor Q settles over ~Q periods)",
            unsettled.len(),
            cells.len(),
            first.x,
            first.y,
            match chart.spec.steady.max_periods {
                Some(m) => format!("max_periods = {m}"),
                None => "derived from each cell's decay rate".to_string(),
            },
        ));
    }
    let failed: u64 = cells.iter().map(|c| u64::from(c.failures)).sum();
    if failed > 0 {
        let first = cells
            .iter()
            .find_map(|c| c.message.as_deref())
            .unwrap_or("");
        w.push(warning!(
            "chart.failed-runs",
            "Read the first failure's message; the failed runs are missing from their \
             cells' census.",
            "{failed} runs failed in {} of {} cells; the first: {first}",
            cells.iter().filter(|c| c.failures > 0).count(),
            cells.len()
        ));
    }
    w
}

/// The cells that converged: no failed start, and no attractor still settling at the transient
/// cap (λ₁ < 0 without a period).
fn convergence(cells: &[ChartCell]) -> Convergence {
    use crate::analysis::chart::{ChartAttractor, MotionKind};
    Convergence::count("cells", cells, |c| {
        let unsettled = |a: &ChartAttractor| matches!(a.motion(), MotionKind::Unsettled);
        c.failures == 0 && c.message.is_none() && !c.attractors.iter().any(unsettled)
    })
}

/// The `--json` document of a chart: the parameters of its first cell (x₀, y₀; the other cells
/// differ in the two axes), axes with names, units and values; every cell with its attractors;
/// the counts and the cells that converged (`converged`); with a probe the `si` block of the
/// first cell.
pub fn document(chart: &Chart, cells: &[ChartCell]) -> Value {
    let axis = |name: &str, values: &[f64]| json!({"name": name, "unit": axis_unit(name), "values": values});
    let cells_json: Vec<Value> = cells
        .iter()
        .map(|c| {
            json!({
                "ix": c.ix,
                "iy": c.iy,
                "attractors": c.attractors.iter().map(|a| json!({
                    "period": a.period,
                    "motion": a.motion().name(),
                    "lyapunov": a.lyapunov,
                    "lyapunov_error": a.lyapunov_error,
                    "x_max": a.x_max,
                    "v_t_min": a.v_t_min,
                    "contacts_per_period": a.contacts_per_period,
                    "contact_fraction": a.contact_fraction,
                    "fraction": a.fraction,
                    "origin": a.origin,
                })).collect::<Vec<_>>(),
                "failures": c.failures,
                "message": c.message,
            })
        })
        .collect();
    let first = chart.model.params(chart.spec.x[0], chart.spec.y[0]);
    let doc = json!({
        "params": first.as_ref().ok(),
        "x": axis(chart.model.x, &chart.spec.x),
        "y": axis(chart.model.y, &chart.spec.y),
        "units": {"x_max": "g0", "v_t_min": "g0", "lyapunov": "1/τ"},
        "starts": chart.spec.starts,
        "cells": cells_json,
        "failures": cells.iter().map(|c| c.failures as u64).sum::<u64>(),
        "warnings": warnings(chart, cells),
    });
    let mut doc = match &first {
        Ok(p) => crate::report::with_si(doc, chart.model.probe.as_ref(), p),
        Err(_) => doc,
    };
    // its convergence here (Dask and Python build it outside the door, which leaves it)
    convergence(cells).write_into(&mut doc);
    doc
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

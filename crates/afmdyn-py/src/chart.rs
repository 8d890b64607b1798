//! `afmdyn.chart` and the tasks `afmdyn.dask.chart` maps over a cluster: [`ChartStudy`], a
//! validated chart that any process can rebuild from its recipe (a JSON text: the request,
//! the model values, the defaults and the probe file's text), so that it pickles to Dask
//! workers as a few hundred bytes.

use crate::errors::{lock_store, study_error};
use crate::errors::{probe_error, sim_error, value_error};
use crate::params::{model_spec, PyParams};
use crate::run::{run, Job};
use afmdyn::probe::Probe;
use afmdyn::request::chart::Chart;
use afmdyn::request::Params;
use afmdyn::request::{ChartArrays, ChartRequest, DirLock, ModelSpec, Resolved};
use afmdyn::study::chart::{ChartCell, ChartPlan};
use afmdyn::study::stored::{Resumable, Storage};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use serde::{Deserialize, Serialize};
use std::sync::atomic::AtomicBool;
use std::sync::Mutex;

/// What rebuilds a chart in any process.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Recipe {
    request: ChartRequest,
    model: ModelSpec,
    defaults: Params,
    probe: Option<String>,
}

fn build(recipe: &Recipe) -> PyResult<Chart> {
    recipe
        .request
        .chart(recipe.model, recipe.defaults, recipe.probe.as_deref())
        .map_err(sim_error)
}

/// A behaviour chart planned as independent tasks (tiles of cells).
#[pyclass(frozen, module = "afmdyn._afmdyn")]
pub struct ChartStudy {
    chart: Chart,
    recipe: String,
}

fn arrays_dict<'py>(
    py: Python<'py>,
    chart: &Chart,
    a: ChartArrays,
) -> PyResult<Bound<'py, PyDict>> {
    crate::convert::layout_dict(py, a.layout(chart.model.x, chart.model.y))
}

fn cells_of(lines: &[String]) -> PyResult<Vec<ChartCell>> {
    let mut cells = Vec::new();
    for l in lines {
        let mut c: Vec<ChartCell> = serde_json::from_str(l)
            .map_err(|e| value_error(format!("not the cells of a chart task: {e}")))?;
        cells.append(&mut c);
    }
    Ok(cells)
}

#[pymethods]
impl ChartStudy {
    /// The chart of a recipe (the text [`ChartStudy::recipe`] returns).
    #[new]
    fn new(recipe: &str) -> PyResult<Self> {
        let r: Recipe =
            serde_json::from_str(recipe).map_err(|e| value_error(format!("chart recipe: {e}")))?;
        Ok(ChartStudy {
            chart: build(&r)?,
            recipe: recipe.to_string(),
        })
    }

    /// The chart of `request` (the keywords of the library's `ChartRequest`, through serde:
    /// an unknown key is a `TypeError`, a bad value a `ValueError`) over `params` (or the
    /// probe's set, or the paper's) with the `model` keywords; `probe` is the probe file's text.
    #[staticmethod]
    #[pyo3(signature = (request=None, params=None, probe=None, model=None))]
    fn build(
        request: Option<&Bound<'_, PyDict>>,
        params: Option<PyRef<'_, PyParams>>,
        probe: Option<String>,
        model: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let request: ChartRequest = crate::convert::request("chart", request)?;
        let parsed = probe
            .as_deref()
            .map(|t| Probe::parse(t, "probe").map_err(probe_error))
            .transpose()?;
        let defaults = match (&params, &parsed) {
            (Some(p), _) => p.inner,
            (None, Some(pr)) => pr.params,
            (None, None) => Params::default(),
        };
        let recipe = Recipe {
            request,
            model: model_spec(model)?,
            defaults,
            probe,
        };
        let text = serde_json::to_string(&recipe).map_err(|e| value_error(e.to_string()))?;
        Ok(ChartStudy {
            chart: build(&recipe)?,
            recipe: text,
        })
    }

    /// The recipe: JSON text that rebuilds this chart in any process.
    #[getter]
    fn recipe(&self) -> String {
        self.recipe.clone()
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        crate::convert::rebuilt_from::<ChartStudy>(slf.py(), &slf.get().recipe)
    }

    /// The fingerprint (JSON text): what a stored chart must match to be resumed.
    fn fingerprint(&self) -> String {
        self.chart.fingerprint.to_string()
    }

    /// The first field in which the stored fingerprint `then` (JSON text) differs from this
    /// chart's: (field, value then, value now), or `None` when they agree.
    fn compare(&self, then: &str) -> PyResult<Option<(String, String, String)>> {
        let then: serde_json::Value = serde_json::from_str(then)
            .map_err(|e| value_error(format!("stored fingerprint: {e}")))?;
        let now: serde_json::Value =
            serde_json::from_str(&self.chart.fingerprint.to_string()).unwrap_or_default();
        Ok(afmdyn::request::sweep::first_difference(&then, &now)
            .map(|(f, a, b)| (f.strip_prefix("chart.").unwrap_or(&f).to_string(), a, b)))
    }

    /// The axes: ((x name, x unit), (y name, y unit)).
    fn axes(&self) -> ((String, String), (String, String)) {
        let unit = afmdyn::request::chart::axis_unit;
        let (x, y) = (self.chart.model.x, self.chart.model.y);
        ((x.into(), unit(x).into()), (y.into(), unit(y).into()))
    }

    /// The number of tasks.
    fn tasks(&self) -> usize {
        ChartPlan::new(&self.chart.spec, &self.chart.model).tasks()
    }

    /// The cells of task `t`: (row, first column, end column).
    fn tile(&self, t: usize) -> PyResult<(usize, usize, usize)> {
        let plan = ChartPlan::new(&self.chart.spec, &self.chart.model);
        if t >= plan.tasks() {
            return Err(value_error(format!(
                "task = {t}: must be in 0..{}",
                plan.tasks()
            )));
        }
        let (iy, cols) = plan.tile(t);
        Ok((iy, cols.start, cols.end))
    }

    /// Run task `t` (without the GIL): its cells as JSON text.
    fn run_task(&self, py: Python<'_>, t: usize) -> PyResult<String> {
        self.tile(t)?;
        let cells = py.detach(|| {
            ChartPlan::new(&self.chart.spec, &self.chart.model)
                .run_task(t, &AtomicBool::new(false))
                .unwrap_or_default()
        });
        serde_json::to_string(&cells).map_err(|e| value_error(e.to_string()))
    }

    /// The arrays of the cells in `tasks` (the JSON texts of [`ChartStudy::run_task`]) over
    /// the region `origin` = (ix, iy) of `size` = (columns, rows); the whole chart by default.
    #[pyo3(signature = (tasks, origin=None, size=None))]
    fn arrays<'py>(
        &self,
        py: Python<'py>,
        tasks: Vec<String>,
        origin: Option<(usize, usize)>,
        size: Option<(usize, usize)>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let cells = cells_of(&tasks)?;
        let origin = origin.unwrap_or((0, 0));
        let size = size.unwrap_or((self.chart.spec.x.len(), self.chart.spec.y.len()));
        arrays_dict(
            py,
            &self.chart,
            ChartArrays::region(&self.chart, origin, size, &cells),
        )
    }

    /// Raise `SimulationError` when no cell found any attractor (`attractors`: the cells'
    /// counts, from a store that keeps no messages): the library's rule
    /// ([`afmdyn::study::chart::every_count_zero`]).
    fn check(&self, attractors: Vec<usize>) -> PyResult<()> {
        match afmdyn::study::chart::every_count_zero(attractors, None) {
            Some(e) => Err(sim_error(e)),
            None => Ok(()),
        }
    }

    /// The `--json` document of the cells in `tasks`, as JSON text.
    fn document(&self, tasks: Vec<String>) -> PyResult<String> {
        let cells = cells_of(&tasks)?;
        Ok(afmdyn::study::chart::document(&self.chart, &cells).to_string())
    }

    /// Run every task on this machine (`threads` workers, default all cores), with the
    /// command line's store in `store` (resumed with `resume`): the arrays and the document.
    #[pyo3(signature = (threads=None, progress=None, store=None, resume=false))]
    fn run<'py>(
        slf: &Bound<'py, Self>,
        py: Python<'py>,
        threads: Option<usize>,
        progress: Option<Bound<'py, PyAny>>,
        store: Option<std::path::PathBuf>,
        resume: bool,
    ) -> PyResult<(Bound<'py, PyDict>, String)> {
        if resume && store.is_none() {
            return Err(value_error(
                "resume=True needs store= (the directory of the interrupted chart)",
            ));
        }
        let lock = store.map(|dir| lock_store(&dir)).transpose()?;
        let this = slf.get();
        let chart = Chart {
            threads,
            ..this.chart.clone()
        };
        let total = chart.spec.x.len() * chart.spec.y.len();
        let job = Job::default();
        let worker_job = job.clone();
        let cells = run(
            py,
            &job,
            Some(total),
            progress.as_ref(),
            move || -> PyResult<Vec<ChartCell>> {
                // the command line's run into its store (the library's one path)
                let storage = Storage {
                    lock: lock.as_ref(),
                    resume,
                    abort_after: None,
                };
                // a chart's model is its own: the one given is not read
                let model = Resolved::plain(Params::default());
                let progress = &*worker_job.progress;
                chart
                    .resume(&(), &model, storage, progress)
                    .map_err(study_error)
            },
        )??;
        let this = slf.get();
        if let Some(e) = afmdyn::study::chart::every_cell_failed(&cells) {
            return Err(sim_error(e));
        }
        let doc = afmdyn::study::chart::document(&this.chart, &cells).to_string();
        Ok((
            arrays_dict(py, &this.chart, ChartArrays::new(&this.chart, &cells))?,
            doc,
        ))
    }
}

/// The lock of a store directory (created if needed): one run writes a store at a time,
/// whatever front end started it; released when dropped or by [`StoreLock::release`].
#[pyclass(module = "afmdyn._afmdyn")]
pub struct StoreLock {
    lock: Mutex<Option<DirLock>>,
}

#[pymethods]
impl StoreLock {
    #[new]
    fn new(path: std::path::PathBuf) -> PyResult<Self> {
        let lock = lock_store(&path)?;
        Ok(StoreLock {
            lock: Mutex::new(Some(lock)),
        })
    }

    /// Release the lock.
    fn release(&self) {
        self.lock.lock().unwrap_or_else(|e| e.into_inner()).take();
    }
}

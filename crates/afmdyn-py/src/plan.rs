//! The tasks `afmdyn.dask` maps over a cluster: [`Plan`], a study the library plans as stages
//! of numbered tasks ([`afmdyn::study::plan`]: a bifurcation sweep, a basin map, a PI-scanned
//! or PeakForce image, a fitted force map), which any process rebuilds from its recipe (JSON text), so that it
//! pickles to Dask workers as a few hundred bytes. Starts and results travel as text; the ledger (which tasks
//! a store holds, how results merge) is the library's ([`PlanStore`]).

use crate::door::outcome_dict;
use crate::errors::{lock_store, sim_error, study_error, value_error};
use crate::params::PyParams;
use afmdyn::request::image_job::ImageKeywords;
use afmdyn::study::plan::{self, Recipe};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::sync::atomic::AtomicBool;
use std::sync::Mutex;

/// A study planned as stages of tasks.
#[pyclass(frozen, module = "afmdyn._afmdyn")]
pub struct Plan {
    plan: Box<dyn plan::Plan>,
}

#[pymethods]
impl Plan {
    /// The plan of a recipe (the text [`Plan::recipe`] returns).
    #[new]
    fn new(recipe: &str) -> PyResult<Self> {
        let plan = plan::rebuild(recipe).map_err(sim_error)?;
        Ok(Plan { plan })
    }

    /// The plan of study `name` (`"bifurcation"`, `"basins"`, `"image"`, `"fit_map"`) with the
    /// keywords `request` (the library's request through serde: an unknown key is a
    /// `TypeError`, a bad value a `ValueError`; for `"image"`, `ImageKeywords`) over `params`;
    /// `probe` is the probe file's text (the basin map's SI block; the image's and the force
    /// map's probe).
    #[staticmethod]
    #[pyo3(signature = (name, request=None, params=None, probe=None))]
    fn build(
        name: &str,
        request: Option<&Bound<'_, PyDict>>,
        params: Option<PyRef<'_, PyParams>>,
        probe: Option<String>,
    ) -> PyResult<Self> {
        use crate::convert::request as req;
        let params = params.map(|p| p.inner).unwrap_or_default();
        let recipe = match name {
            "bifurcation" => Recipe::Bifurcation {
                request: req(name, request)?,
                params,
            },
            "basins" => Recipe::Basins {
                request: req(name, request)?,
                params,
                probe,
            },
            "image" => {
                let keywords: ImageKeywords = req(name, request)?;
                let text = probe.ok_or_else(|| value_error("image: the probe is needed"))?;
                Recipe::image(keywords, &text).map_err(sim_error)?
            }
            "fit_map" => Recipe::FitMap {
                request: req(name, request)?,
                params,
                probe,
            },
            _ => return Err(pyo3::exceptions::PyKeyError::new_err(name.to_string())),
        };
        let plan = plan::plan(recipe).map_err(sim_error)?;
        Ok(Plan { plan })
    }

    /// The recipe: JSON text that rebuilds this plan in any process.
    #[getter]
    fn recipe(&self) -> String {
        self.plan.recipe().to_string()
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let args = PyTuple::new(py, [slf.get().plan.recipe()])?;
        PyTuple::new(py, [py.get_type::<Plan>().into_any(), args.into_any()])
    }

    /// The number of stages.
    fn stages(&self) -> usize {
        self.plan.stages()
    }

    /// Stage `stage` from the results of the stages before it: (its start, its tasks).
    fn stage(
        &self,
        py: Python<'_>,
        stage: usize,
        results: Vec<String>,
    ) -> PyResult<(String, Vec<usize>)> {
        let st = py
            .detach(|| self.plan.stage(stage, &results))
            .map_err(sim_error)?;
        Ok((st.start, st.tasks))
    }

    /// Run task `task` of the stage beginning at `start` (without the GIL): its result.
    fn run(&self, py: Python<'_>, start: &str, task: usize) -> PyResult<String> {
        py.detach(|| self.plan.run(start, task, &AtomicBool::new(false)))
            .map_err(sim_error)
    }

    /// The outcome of every result, as `afmdyn._afmdyn.run` returns it.
    fn outcome<'py>(&self, py: Python<'py>, results: Vec<String>) -> PyResult<Bound<'py, PyDict>> {
        let out = py
            .detach(|| self.plan.outcome(&results))
            .map_err(sim_error)?;
        outcome_dict(py, out)
    }

    /// The command line's resumable store of the plan in the directory `path` (locked,
    /// created if needed); `ValueError` for a plan without one.
    fn store(&self, path: std::path::PathBuf) -> PyResult<PlanStore> {
        let store = self
            .plan
            .store(lock_store(&path)?)
            .ok_or_else(|| value_error("store: this study has no store of its own"))?;
        Ok(PlanStore {
            store: Mutex::new(Some(store)),
        })
    }
}

/// A plan's store ([`afmdyn::study::plan::PlanStore`]), locked until released (or dropped).
#[pyclass(module = "afmdyn._afmdyn")]
pub struct PlanStore {
    store: Mutex<Option<Box<dyn plan::PlanStore>>>,
}

impl PlanStore {
    fn with<T>(
        &self,
        f: impl FnOnce(&mut dyn plan::PlanStore) -> Result<T, afmdyn::study::StudyError>,
    ) -> PyResult<T> {
        let mut guard = self.store.lock().unwrap_or_else(|e| e.into_inner());
        let s = guard
            .as_mut()
            .ok_or_else(|| value_error("the store was released"))?;
        f(s.as_mut()).map_err(study_error)
    }
}

#[pymethods]
impl PlanStore {
    /// Where the plan stands (a new run begins without `resume`): `None` when it finished,
    /// else the tasks of the last stage still to run.
    fn open(&self, resume: bool) -> PyResult<Option<Vec<usize>>> {
        self.with(|s| s.open(resume))
    }

    /// Keep a result of the last stage.
    fn append(&self, result: &str) -> PyResult<()> {
        self.with(|s| s.append(result))
    }

    /// Mark the plan finished, its results in the one order.
    fn finish(&self) -> PyResult<()> {
        self.with(|s| s.finish())
    }

    /// The outcome of the finished store, as `afmdyn._afmdyn.run` returns it.
    fn outcome<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let out = self.with(|s| s.outcome())?;
        outcome_dict(py, out)
    }

    /// Release the lock.
    fn release(&self) {
        self.store.lock().unwrap_or_else(|e| e.into_inner()).take();
    }
}

//! The tasks `afmdyn.dask.bifurcation` maps over a cluster: [`SweepStudy`], a validated
//! bifurcation sweep that any process rebuilds from its recipe (the request and the parameter
//! set as JSON), planned by the library ([`SweepPlan`]): stage 0, the two coarse passes;
//! stage 1, the chain segments and the random starts, each seeded by the passes' states.
//! Points travel as the rows of `bifurcation.csv` (numbers in shortest round-trip form), so a
//! sweep assembled from tasks equals `afmdyn.bifurcation` bit for bit.

use crate::errors::{checkpoint_error, lock_store};
use crate::errors::{sim_error, value_error};
use crate::params::PyParams;
use afmdyn::analysis::bifurcation::{Branch, Seeds, SweepPlan, SweepPoint, SweepSpec, SweepTask};
use afmdyn::request::checkpoint::{self, Checkpoint, CheckpointError};
use afmdyn::request::sweep::{fingerprint, order_key, records, SweepRecord};
use afmdyn::request::{BifurcationRequest, DirLock, FileCheckpoint};
use afmdyn::Params;
use nalgebra::DVector;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use serde::{Deserialize, Serialize};
use std::collections::HashSet;
use std::sync::atomic::AtomicBool;
use std::sync::Mutex;

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Recipe {
    request: BifurcationRequest,
    params: Params,
}

/// A bifurcation sweep planned as independent tasks.
#[pyclass(frozen, module = "afmdyn._afmdyn")]
pub struct SweepStudy {
    spec: SweepSpec,
    request: BifurcationRequest,
    recipe: String,
}

fn states(v: &[DVector<f64>]) -> Vec<Vec<f64>> {
    v.iter().map(|z| z.iter().copied().collect()).collect()
}

fn vectors(v: Vec<Vec<f64>>) -> Vec<DVector<f64>> {
    v.into_iter().map(DVector::from_vec).collect()
}

impl SweepStudy {
    fn of(recipe: Recipe) -> PyResult<Self> {
        let spec = recipe.request.spec(&recipe.params).map_err(sim_error)?;
        let text = serde_json::to_string(&recipe).map_err(|e| value_error(e.to_string()))?;
        Ok(SweepStudy {
            spec,
            request: recipe.request,
            recipe: text,
        })
    }
}

#[pymethods]
impl SweepStudy {
    /// The sweep of a recipe (the text [`SweepStudy::recipe`] returns).
    #[new]
    fn new(recipe: &str) -> PyResult<Self> {
        let r: Recipe =
            serde_json::from_str(recipe).map_err(|e| value_error(format!("sweep recipe: {e}")))?;
        SweepStudy::of(r)
    }

    /// The sweep of `request` (the keywords of `afmdyn.bifurcation`, through serde into the
    /// library's `BifurcationRequest`: an unknown key is a `TypeError`, a bad value a
    /// `ValueError`) over `params`.
    #[staticmethod]
    #[pyo3(signature = (request, params))]
    fn build(request: Option<&Bound<'_, PyDict>>, params: PyRef<'_, PyParams>) -> PyResult<Self> {
        let request: BifurcationRequest = crate::convert::request("bifurcation", request)?;
        SweepStudy::of(Recipe {
            request,
            params: params.inner,
        })
    }

    /// The recipe: JSON text that rebuilds this sweep in any process.
    #[getter]
    fn recipe(&self) -> String {
        self.recipe.clone()
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        crate::convert::rebuilt_from::<SweepStudy>(slf.py(), &slf.get().recipe)
    }

    /// The number of tasks of `stage` (0: the coarse passes, 1: segments and random starts).
    fn tasks(&self, stage: usize) -> usize {
        SweepPlan::new(&self.spec).tasks(stage).len()
    }

    /// Stage-0 task `k` (0 forward, 1 backward; without the GIL): the coarse pass's seeds,
    /// JSON text.
    fn coarse(&self, py: Python<'_>, k: usize) -> PyResult<String> {
        let branch = match k {
            0 => Branch::Forward,
            1 => Branch::Backward,
            _ => return Err(value_error(format!("coarse task = {k}: must be 0 or 1"))),
        };
        let seeds =
            py.detach(|| SweepPlan::new(&self.spec).coarse(branch, &AtomicBool::new(false)));
        serde_json::to_string(&states(&seeds)).map_err(|e| value_error(e.to_string()))
    }

    /// Stage-1 task `k` (without the GIL) from the two coarse passes' results (`None` for a
    /// sweep without stage 0): its points as lines of `bifurcation.csv`.
    #[pyo3(signature = (k, forward=None, backward=None))]
    fn run_task(
        &self,
        py: Python<'_>,
        k: usize,
        forward: Option<&str>,
        backward: Option<&str>,
    ) -> PyResult<Vec<String>> {
        let plan = SweepPlan::new(&self.spec);
        let tasks = plan.tasks(1);
        let task: SweepTask = *tasks
            .get(k)
            .ok_or_else(|| value_error(format!("task = {k}: must be in 0..{}", tasks.len())))?;
        let parse = |t: Option<&str>| -> PyResult<Vec<DVector<f64>>> {
            let n = plan.chunks();
            match t {
                Some(t) => serde_json::from_str::<Vec<Vec<f64>>>(t)
                    .map(vectors)
                    .map_err(|e| value_error(format!("coarse pass: {e}"))),
                None => Ok(vec![DVector::zeros(self.spec.base.state_dim()); n]),
            }
        };
        let seeds = Seeds::new(parse(forward)?, parse(backward)?);
        let param = self.spec.param;
        let lines = py.detach(|| {
            let out = Mutex::new(Vec::new());
            plan.run_task(
                task,
                &seeds,
                &Default::default(),
                &|p: SweepPoint| {
                    let rows = records(param, &p);
                    out.lock()
                        .unwrap_or_else(|e| e.into_inner())
                        .extend(rows.iter().map(SweepRecord::csv_line));
                },
                &AtomicBool::new(false),
            );
            out.into_inner().unwrap_or_else(|e| e.into_inner())
        });
        Ok(lines)
    }

    /// The columns of `afmdyn.bifurcation` from the rows of every task, in the one row order.
    fn records<'py>(&self, py: Python<'py>, rows: Vec<String>) -> PyResult<Bound<'py, PyDict>> {
        let mut recs = rows
            .iter()
            .map(|l| SweepRecord::parse_csv(l).map_err(value_error))
            .collect::<PyResult<Vec<_>>>()?;
        recs.sort_by_key(order_key);
        if let Some(e) = afmdyn::request::sweep::every_point_failed(&recs) {
            return Err(sim_error(e));
        }
        crate::analyses::sweep_dict(py, &self.spec, recs)
    }
}

/// The command line's store of a sweep (`afmdyn bifurcation --out DIR`, `afmdyn.bifurcation(
/// store=DIR)`), written by an executor that runs the sweep's tasks elsewhere: it stores the
/// points of each finished task that are not stored yet, so a task computed again after an
/// interruption (a chain segment runs whole from its seed, deterministically) adds nothing
/// twice. Locked while it exists (released by [`SweepStore::release`] or when dropped).
#[pyclass(module = "afmdyn._afmdyn")]
pub struct SweepStore {
    lock: Mutex<Option<DirLock>>,
    done: Mutex<HashSet<(usize, Branch)>>,
}

impl SweepStore {
    fn with<T>(
        &self,
        f: impl FnOnce(&mut FileCheckpoint<'_>) -> Result<T, CheckpointError>,
    ) -> PyResult<T> {
        let guard = self.lock.lock().unwrap_or_else(|e| e.into_inner());
        let lock = guard
            .as_ref()
            .ok_or_else(|| value_error("the store was released"))?;
        f(&mut FileCheckpoint::new(lock)).map_err(checkpoint_error)
    }
}

#[pymethods]
impl SweepStore {
    #[new]
    fn new(path: std::path::PathBuf) -> PyResult<Self> {
        Ok(SweepStore {
            lock: Mutex::new(Some(lock_store(&path)?)),
            done: Mutex::new(HashSet::new()),
        })
    }

    /// Where `study` stands in the store (a new sweep begins without `resume`): `None` when
    /// it finished, else the stage-1 tasks with points still to store.
    fn open(&self, study: PyRef<'_, SweepStudy>, resume: bool) -> PyResult<Option<Vec<usize>>> {
        let fp = fingerprint(&study.request, &study.spec);
        let Some(left) = self.with(|s| checkpoint::open(s, &fp, resume))? else {
            return Ok(None);
        };
        let plan = SweepPlan::new(&study.spec);
        let todo = plan
            .tasks(1)
            .iter()
            .enumerate()
            .filter(|(_, t)| match **t {
                SweepTask::Segment(b, k) => plan
                    .chunk_indices(b, k)
                    .iter()
                    .any(|&i| !left.done.contains(&(i, b))),
                SweepTask::Start(i, s) => !left.done.contains(&(i, Branch::Start(s))),
                SweepTask::Coarse(_) => false,
            })
            .map(|(k, _)| k)
            .collect();
        *self.done.lock().unwrap_or_else(|e| e.into_inner()) = left.done;
        Ok(Some(todo))
    }

    /// Store the points of `rows` (a task's rows, [`SweepStudy::run_task`]) not stored yet.
    fn append(&self, rows: Vec<String>) -> PyResult<()> {
        let recs = rows
            .iter()
            .map(|l| SweepRecord::parse_csv(l).map_err(value_error))
            .collect::<PyResult<Vec<_>>>()?;
        let mut done = self.done.lock().unwrap_or_else(|e| e.into_inner());
        self.with(|s| {
            for point in recs.chunk_by(|a, b| (a.index, a.branch) == (b.index, b.branch)) {
                let key = (point[0].index, point[0].branch);
                if done.insert(key) {
                    s.append(point)?;
                }
            }
            Ok(())
        })
    }

    /// Put the stored rows in the one order and mark the sweep finished.
    fn finish(&self, study: PyRef<'_, SweepStudy>) -> PyResult<()> {
        let fp = fingerprint(&study.request, &study.spec);
        self.with(|s| s.finish(&fp))
    }

    /// The columns of the finished sweep (as `afmdyn.bifurcation` returns them).
    fn records<'py>(
        &self,
        py: Python<'py>,
        study: PyRef<'_, SweepStudy>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let recs = self.with(|s| s.records())?;
        if let Some(e) = afmdyn::request::sweep::every_point_failed(&recs) {
            return Err(sim_error(e));
        }
        crate::analyses::sweep_dict(py, &study.spec, recs)
    }

    /// Release the lock.
    fn release(&self) {
        self.lock.lock().unwrap_or_else(|e| e.into_inner()).take();
    }
}

//! The tasks `afmdyn.dask.bifurcation` maps over a cluster: [`SweepStudy`], a validated
//! bifurcation sweep that any process rebuilds from its recipe (the request and the parameter
//! set as JSON), planned by the library ([`SweepPlan`]): stage 0, the two coarse passes;
//! stage 1, the chain segments and the random starts, each seeded by the passes' states.
//! Points travel as the rows of `bifurcation.csv` (numbers in shortest round-trip form), so a
//! sweep assembled from tasks equals `afmdyn.bifurcation` bit for bit.

use crate::errors::{sim_error, value_error};
use crate::params::PyParams;
use afmdyn::analysis::bifurcation::{Branch, Seeds, SweepPlan, SweepPoint, SweepSpec, SweepTask};
use afmdyn::request::sweep::{order_key, records, SweepRecord};
use afmdyn::request::BifurcationRequest;
use afmdyn::Params;
use nalgebra::DVector;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use serde::{Deserialize, Serialize};
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
        Ok(SweepStudy { spec, recipe: text })
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

    /// The sweep of `request` (the options of `afmdyn.bifurcation` as JSON text; unknown keys
    /// are refused) over `params`.
    #[staticmethod]
    fn build(request: &str, params: PyRef<'_, PyParams>) -> PyResult<Self> {
        let request: BifurcationRequest = serde_json::from_str(request).map_err(|e| {
            pyo3::exceptions::PyTypeError::new_err(format!("bifurcation options: {e}"))
        })?;
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
        let py = slf.py();
        PyTuple::new(
            py,
            [
                py.get_type::<SweepStudy>().into_any(),
                PyTuple::new(py, [slf.get().recipe.clone()])?.into_any(),
            ],
        )
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
                None => Ok(vec![DVector::zeros(2 * self.spec.base.modes); n]),
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

//! The tasks `afmdyn.dask.basins` maps over a cluster: [`BasinMapStudy`], a basin map that any
//! process rebuilds from its recipe (a JSON text: the request, the model values and the probe
//! file's text), so that it pickles to Dask workers as a few hundred bytes. A pass's start
//! ([`PassStart`]: the attractors and the coarse grid of the passes before it) and a finished
//! row travel as CBOR text ([`to_cbor_text`]: every float bit for bit), so a map made on a
//! cluster is the local map bit for bit.

use crate::errors::{probe_error, sim_error, value_error};
use crate::params::PyParams;
use afmdyn::analysis::basins::{pass_start, passes, run_pass_row, BasinRow, PassStart};
use afmdyn::probe::Probe;
use afmdyn::request::{BasinArrays, BasinsRequest, Resolved};
use afmdyn::study::basins::BasinStudy;
use afmdyn::study::task_store::{from_cbor_text, to_cbor_text};
use afmdyn::Params;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use serde::{Deserialize, Serialize};
use std::sync::atomic::AtomicBool;

/// What rebuilds a basin map in any process.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Recipe {
    request: BasinsRequest,
    params: Params,
    probe: Option<String>,
}

/// A basin map planned as passes of independent rows.
#[pyclass(frozen, module = "afmdyn._afmdyn")]
pub struct BasinMapStudy {
    study: BasinStudy,
    recipe: Recipe,
    text: String,
}

fn decode<T: serde::de::DeserializeOwned>(what: &str, text: &str) -> PyResult<T> {
    from_cbor_text(text).map_err(|e| value_error(format!("not {what}: {e}")))
}

fn encode<T: Serialize>(value: &T) -> PyResult<String> {
    to_cbor_text(value).map_err(value_error)
}

fn rows_of(texts: &[String]) -> PyResult<Vec<BasinRow>> {
    texts
        .iter()
        .map(|t| decode("a row of a basin map", t))
        .collect()
}

impl BasinMapStudy {
    fn of(recipe: Recipe, text: String) -> PyResult<Self> {
        let study = BasinStudy::new(&recipe.request, &recipe.params).map_err(sim_error)?;
        Ok(BasinMapStudy {
            study,
            recipe,
            text,
        })
    }
}

#[pymethods]
impl BasinMapStudy {
    /// The map of a recipe (the text [`BasinMapStudy::recipe`] returns).
    #[new]
    fn new(recipe: &str) -> PyResult<Self> {
        let r: Recipe = serde_json::from_str(recipe)
            .map_err(|e| value_error(format!("basin map recipe: {e}")))?;
        BasinMapStudy::of(r, recipe.to_string())
    }

    /// The map of `request` (the keywords of the library's `BasinsRequest`, through serde: an
    /// unknown key is a `TypeError`, a bad value a `ValueError`) over `params`; `probe` is
    /// the probe file's text (for the document's SI block).
    #[staticmethod]
    #[pyo3(signature = (params, request=None, probe=None))]
    fn build(
        params: PyRef<'_, PyParams>,
        request: Option<&Bound<'_, PyDict>>,
        probe: Option<String>,
    ) -> PyResult<Self> {
        let recipe = Recipe {
            request: crate::convert::request("basins", request)?,
            params: params.inner,
            probe,
        };
        let text = serde_json::to_string(&recipe).map_err(|e| value_error(e.to_string()))?;
        BasinMapStudy::of(recipe, text)
    }

    /// The recipe: JSON text that rebuilds this map in any process.
    #[getter]
    fn recipe(&self) -> String {
        self.text.clone()
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        crate::convert::rebuilt_from::<BasinMapStudy>(slf.py(), &slf.get().text)
    }

    /// The number of passes (one where the plane is not the whole section).
    fn passes(&self) -> usize {
        passes(&self.study.spec)
    }

    /// The start of pass `index` from the finished rows `rows` (texts of
    /// [`BasinMapStudy::run_row`]): CBOR text.
    fn start(&self, py: Python<'_>, index: usize, rows: Vec<String>) -> PyResult<String> {
        if index >= passes(&self.study.spec) {
            return Err(value_error(format!(
                "index = {index}: must be in 0..{} (the passes)",
                passes(&self.study.spec)
            )));
        }
        let rows = rows_of(&rows)?;
        let start = py.detach(|| pass_start(&self.study.spec, &rows, index));
        encode(&start)
    }

    /// The rows that the pass beginning at `start` runs (their indices iy).
    fn rows(&self, start: &str) -> PyResult<Vec<usize>> {
        let start: PassStart = decode("the start of a pass", start)?;
        Ok(start.rows.iter().map(|(iy, _)| *iy).collect())
    }

    /// Run row `iy` of the pass beginning at `start` (without the GIL): the row as CBOR text.
    fn run_row(&self, py: Python<'_>, start: &str, iy: usize) -> PyResult<String> {
        let start: PassStart = decode("the start of a pass", start)?;
        let Some((_, columns)) = start.rows.iter().find(|(i, _)| *i == iy) else {
            return Err(value_error(format!(
                "iy = {iy}: not a row of pass {}",
                start.pass
            )));
        };
        let s = &self.study;
        let row = py
            .detach(|| {
                run_pass_row(
                    &s.spec,
                    &s.model,
                    &start,
                    iy,
                    columns,
                    &AtomicBool::new(false),
                )
            })
            .map_err(sim_error)?;
        encode(&row)
    }

    /// The map of every finished row `rows`: (its arrays, the `--json` document as JSON
    /// text), as `afmdyn.basins` returns them.
    fn result<'py>(
        &self,
        py: Python<'py>,
        rows: Vec<String>,
    ) -> PyResult<(Bound<'py, PyDict>, String)> {
        let rows = rows_of(&rows)?;
        let map = py.detach(|| self.study.map(rows)).map_err(sim_error)?;
        let probe = self
            .recipe
            .probe
            .as_deref()
            .map(|t| Probe::parse(t, "probe"))
            .transpose()
            .map_err(probe_error)?;
        let model = Resolved {
            params: self.recipe.params,
            probe,
        };
        let doc = afmdyn::request::run::document(&self.recipe.request, &model, &map)
            .map_err(sim_error)?;
        let layout =
            crate::convert::layout_dict(py, BasinArrays::new(&map).layout(&self.study.spec))?;
        Ok((layout, doc.to_string()))
    }
}

//! Rust results to Python objects: NumPy arrays that take over the Rust buffers (no copy), and
//! JSON documents as Python dicts.

use numpy::ndarray::Array2;
use numpy::{Complex64, IntoPyArray};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// `json.loads(text)`.
pub fn json_to_py<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.getattr("loads")?.call1((text,))
}

/// Builder of the dict a compiled function returns to the Python layer.
pub struct Out<'py> {
    pub py: Python<'py>,
    pub dict: Bound<'py, PyDict>,
}

impl<'py> Out<'py> {
    pub fn new(py: Python<'py>) -> Self {
        Out {
            py,
            dict: PyDict::new(py),
        }
    }
    /// A 1-D float64 array owning `v`.
    pub fn f64s(&self, key: &str, v: Vec<f64>) -> PyResult<()> {
        self.dict.set_item(key, v.into_pyarray(self.py))
    }
    /// A 1-D int64 array.
    pub fn i64s(&self, key: &str, v: Vec<i64>) -> PyResult<()> {
        self.dict.set_item(key, v.into_pyarray(self.py))
    }
    /// A 1-D bool array.
    pub fn bools(&self, key: &str, v: Vec<bool>) -> PyResult<()> {
        self.dict.set_item(key, v.into_pyarray(self.py))
    }
    /// A 1-D complex128 array.
    pub fn complex(&self, key: &str, v: Vec<Complex64>) -> PyResult<()> {
        self.dict.set_item(key, v.into_pyarray(self.py))
    }
    /// A C-ordered (rows × cols) float64 array owning the row-major `v`.
    pub fn matrix(&self, key: &str, rows: usize, cols: usize, v: Vec<f64>) -> PyResult<()> {
        let a = Array2::from_shape_vec((rows, cols), v).expect("rows × cols values");
        self.dict.set_item(key, a.into_pyarray(self.py))
    }
    /// Any other value.
    pub fn set<V: IntoPyObject<'py>>(&self, key: &str, v: V) -> PyResult<()> {
        self.dict.set_item(key, v)
    }
    /// A JSON document, as text (the Python layer keeps it for `to_dict()`).
    pub fn json(&self, doc: &serde_json::Value) -> PyResult<()> {
        self.dict.set_item("json", doc.to_string())
    }
    pub fn finish(self) -> Bound<'py, PyDict> {
        self.dict
    }
}

/// A result's [`afmdyn::study::Layout`] for the Python layer (`afmdyn._layout.dataset`):
/// `{"title": str, "dims": [(name, length)], "variables": [(name, dims, units, long_name,
/// values, attrs)]}`, values as flat NumPy arrays (float64, or int64 for integer variables)
/// that the Python layer reshapes to the dims.
pub fn layout_dict<'py>(
    py: Python<'py>,
    layout: afmdyn::study::Layout,
) -> PyResult<Bound<'py, PyDict>> {
    use afmdyn::study::layout::{Attr, Values};
    let out = PyDict::new(py);
    out.set_item("title", layout.title)?;
    out.set_item("dims", layout.dims)?;
    let mut vars = Vec::with_capacity(layout.variables.len());
    for v in layout.variables {
        let values = match v.values {
            Values::F64(x) => x.into_pyarray(py).into_any(),
            Values::I32(x) => x
                .into_iter()
                .map(i64::from)
                .collect::<Vec<_>>()
                .into_pyarray(py)
                .into_any(),
        };
        let attrs = PyDict::new(py);
        for (k, a) in v.attrs {
            match a {
                Attr::I32(x) => attrs.set_item(k, x)?,
                Attr::Text(s) => attrs.set_item(k, s)?,
            }
        }
        vars.push((v.name, v.dims, v.units, v.long_name, values, attrs));
    }
    out.set_item("variables", vars)?;
    Ok(out)
}

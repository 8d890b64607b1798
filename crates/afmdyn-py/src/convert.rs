//! Python keywords to the library's requests ([`request`]: a dict deserialised by serde, so
//! the request is the one signature), and Rust results to Python objects: NumPy arrays that
//! take over the Rust buffers (no copy), and JSON documents as Python dicts.

use afmdyn::request::keywords::{canonical_name, Keyword as Val, KeywordError};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// `json.loads(text)`.
pub fn json_to_py<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.getattr("loads")?.call1((text,))
}

/// A result's [`afmdyn::layout::Layout`] for the Python layer (`afmdyn._layout.dataset`):
/// `{"title": str, "dims": [(name, length)], "variables": [(name, dims, units, long_name,
/// values, attrs)]}`, values as flat NumPy arrays (float64, or int64 for integer variables)
/// that the Python layer reshapes to the dims.
pub fn layout_dict<'py>(
    py: Python<'py>,
    layout: afmdyn::layout::Layout,
) -> PyResult<Bound<'py, PyDict>> {
    use afmdyn::layout::{Attr, Values};
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
            Values::Bool(x) => x.into_pyarray(py).into_any(),
            Values::Text(x) => pyo3::types::PyList::new(py, x)?.into_any(),
            Values::C64(x) => x
                .into_iter()
                .map(|(re, im)| numpy::Complex64::new(re, im))
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

/// A probe given as a dict of sections, as the TOML table the probe reader takes: numbers
/// (NaN and ±∞ kept, so that the reader's own checks name the key), strings, booleans, lists
/// and sub-dicts; `None` entries left out.
///
/// # Errors
/// `TypeError` naming the key of a value that is none of these.
pub fn toml_table(d: &Bound<'_, PyDict>) -> PyResult<toml::Table> {
    let mut table = toml::Table::new();
    for (k, v) in d.iter() {
        let key: String = k.extract()?;
        if let Some(v) = val(&key, &v)?.into_toml() {
            table.insert(key, v);
        }
    }
    Ok(table)
}

/// `v` as a [`Val`] (the library's [`Keyword`]); `key` names it in a `TypeError` for a type serde cannot take.
fn val(key: &str, v: &Bound<'_, PyAny>) -> PyResult<Val> {
    use pyo3::types::{PyBool, PyFloat, PyInt, PyList, PyString, PyTuple};
    if v.is_none() {
        Ok(Val::Null)
    } else if v.is_instance_of::<PyBool>() {
        Ok(Val::Bool(v.extract()?))
    } else if v.is_instance_of::<PyString>() {
        Ok(Val::Str(v.extract()?))
    } else if v.is_instance_of::<PyFloat>() {
        Ok(Val::Float(v.extract()?))
    } else if v.is_instance_of::<PyInt>() {
        if let Ok(i) = v.extract() {
            return Ok(Val::Int(i));
        }
        // beyond 64 bits: a value out of range (named with the model parameter's range), or
        // for a real model parameter the nearest double
        use afmdyn::request::model::ValueKind;
        let msg = match afmdyn::request::parameter(key) {
            Some(p) if matches!(p.kind, ValueKind::Real) => match v.extract::<f64>() {
                Ok(x) => return Ok(Val::Float(x)),
                Err(_) => format!(
                    "{key} = an integer of {} digits: must be a finite number",
                    v.str()?.to_string().trim_start_matches('-').len()
                ),
            },
            Some(p) => format!("{key} = {v}: must be in {}", p.range),
            None => format!("{key} = {v}: out of range (beyond 64 bits)"),
        };
        Err(crate::errors::value_error(msg))
    } else if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items: PyResult<Vec<Val>> = v.try_iter()?.map(|x| val(key, &x?)).collect();
        Ok(Val::Seq(items?))
    } else if let Ok(d) = v.cast::<PyDict>() {
        Ok(Val::Map(entries(d, false)?))
    } else if let Ok(i) = v.extract::<i64>() {
        Ok(Val::Int(i))
    } else if let Ok(x) = v.extract::<f64>() {
        Ok(Val::Float(x))
    } else {
        Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "{key}: a {} is not a request value",
            v.get_type().name()?
        )))
    }
}

/// The entries of a dict of keywords, `None` ones left out (they mean the request's default),
/// a keyword with the trailing `_` of a Python keyword (`from_`) under the request's name
/// (`from`), and the names of the integrator and the swept parameter in the request's
/// spelling (parsed as the command line parses them: a `ValueError` names a bad one). The
/// model's keywords (`model`) keep a `None` (a value of the wrong type).
fn entries(d: &Bound<'_, PyDict>, model: bool) -> PyResult<Vec<(String, Val)>> {
    let mut out = Vec::with_capacity(d.len());
    for (k, v) in d.iter() {
        let key: String = k.extract()?;
        let key = if key == "from_" {
            "from".to_string()
        } else {
            key
        };
        let value = match (key.as_str(), val(&key, &v)?) {
            (_, Val::Null) if model => Val::NoneGiven,
            (_, Val::Null) => continue,
            (_, Val::Str(s)) => {
                Val::Str(canonical_name(&key, s).map_err(crate::errors::value_error)?)
            }
            (_, other) => other,
        };
        out.push((key, value));
    }
    Ok(out)
}

/// The library's request `R` of an analysis' keywords (the request is the one signature:
/// its serde names, `deny_unknown_fields` and defaults).
///
/// # Errors
/// `TypeError` for a keyword the request does not have (serde's `unknown field`, the
/// request's names listed) or a Python object that is no number, string, list or dict;
/// `ValueError` for a value the request refuses (a bad integrator or parameter name, a
/// negative count, a wrong type; the Python layer checks the types first).
pub fn request<R: serde::de::DeserializeOwned>(
    what: &str,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<R> {
    deserialize(what, kwargs, |d| R::deserialize(d))
}

/// The request of analysis `name` ([`afmdyn::request::named::parse`]) of its keywords, as
/// [`request`]; `KeyError` for another name.
pub fn named(
    name: &str,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<afmdyn::request::named::NamedRequest> {
    // the curve of a multifrequency drive is the approach curve's request
    let what = if name == "bimodal" { "approach" } else { name };
    deserialize(what, kwargs, |d| afmdyn::request::named::parse(name, d))?
        .ok_or_else(|| pyo3::exceptions::PyKeyError::new_err(name.to_string()))
}

/// The study run into a store of analysis `name` ([`afmdyn::study::stored::parse`]) of its
/// keywords, as [`request`]; `KeyError` for another name.
pub fn stored(
    name: &str,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<Box<dyn afmdyn::study::stored::Stored>> {
    let what = if name == "bimodal" { "approach" } else { name };
    deserialize(what, kwargs, |d| afmdyn::study::stored::parse(name, d))?
        .ok_or_else(|| pyo3::exceptions::PyKeyError::new_err(name.to_string()))
}

/// `parse` of the keywords (`model`: the model's, see [`entries`]): the error and the
/// keyword's path (serde_path_to_error's).
fn parse<T>(
    kwargs: Option<&Bound<'_, PyDict>>,
    model: bool,
    parse: impl FnOnce(serde_path_to_error::Deserializer<'_, '_, Val>) -> Result<T, KeywordError>,
) -> PyResult<Result<T, (String, KeywordError)>> {
    let map = match kwargs {
        Some(d) => entries(d, model)?,
        None => Vec::new(),
    };
    let mut track = serde_path_to_error::Track::new();
    let parsed = parse(serde_path_to_error::Deserializer::new(
        Val::Map(map),
        &mut track,
    ));
    Ok(parsed.map_err(|e| (track.path().to_string(), e)))
}

/// `parse` of the keywords, its error naming the keyword (serde_path_to_error's path) and the
/// kind of number in words: `TypeError` for an unknown keyword, else `ValueError`.
fn deserialize<T>(
    what: &str,
    kwargs: Option<&Bound<'_, PyDict>>,
    de: impl FnOnce(serde_path_to_error::Deserializer<'_, '_, Val>) -> Result<T, KeywordError>,
) -> PyResult<T> {
    parse(kwargs, false, de)?.map_err(|(path, e)| raise(e.is_unknown(), e.message(what, &path)))
}

/// The model keywords in `kwargs` as the library's [`ModelSpec`](afmdyn::request::ModelSpec)
/// (its serde names and aliases; ranges are checked when it is resolved). The errors name the
/// keyword: `TypeError` for an unknown one (the closest name as a hint, every name listed) or
/// a value of the wrong type (what it takes, from the one table of model parameters),
/// `ValueError` for a value out of range or a parameter given under its name and its alias.
pub fn model_spec(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<afmdyn::request::ModelSpec> {
    parse(kwargs, true, |d| serde::Deserialize::deserialize(d))?.map_err(|(key, e)| {
        let (type_error, msg) = e.model_message(&key);
        raise(type_error, msg)
    })
}

/// A `TypeError` or a `ValueError`.
fn raise(type_error: bool, msg: String) -> PyErr {
    if type_error {
        pyo3::exceptions::PyTypeError::new_err(msg)
    } else {
        pyo3::exceptions::PyValueError::new_err(msg)
    }
}

/// The `__reduce__` of a study class that any process rebuilds from its recipe (a JSON text):
/// `(cls, (recipe,))`, so that it pickles to Dask workers as its recipe.
///
/// # Errors
/// Python's, building the tuples.
pub fn rebuilt_from<'py, T: pyo3::PyTypeInfo>(
    py: Python<'py>,
    recipe: &str,
) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
    use pyo3::types::PyTuple;
    PyTuple::new(
        py,
        [
            py.get_type::<T>().into_any(),
            PyTuple::new(py, [recipe])?.into_any(),
        ],
    )
}

//! Python keywords to the library's requests ([`request`]: a dict deserialised by serde, so
//! the request is the one signature), and Rust results to Python objects: NumPy arrays that
//! take over the Rust buffers (no copy), and JSON documents as Python dicts.

use numpy::IntoPyArray;
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

/// A Python value as serde sees it: the keywords of an analysis on their way into the
/// library's request (NaN and ±∞ kept, so that the request's own checks name them).
enum Val {
    Null,
    Bool(bool),
    Int(i64),
    Float(f64),
    Str(String),
    Seq(Vec<Val>),
    Map(Vec<(String, Val)>),
}

/// A serde error of [`request`]: an unknown key is a `TypeError`, every other a `ValueError`.
#[derive(Debug)]
struct DeError {
    msg: String,
    unknown: bool,
}

impl std::fmt::Display for DeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.msg)
    }
}

impl std::error::Error for DeError {}

impl serde::de::Error for DeError {
    fn custom<T: std::fmt::Display>(msg: T) -> Self {
        DeError {
            msg: msg.to_string(),
            unknown: false,
        }
    }
    fn unknown_field(field: &str, expected: &'static [&'static str]) -> Self {
        DeError {
            msg: format!(
                "unknown keyword '{field}': expected {}",
                expected.join(", ")
            ),
            unknown: true,
        }
    }
}

impl<'de> serde::de::IntoDeserializer<'de, DeError> for Val {
    type Deserializer = Val;
    fn into_deserializer(self) -> Val {
        self
    }
}

impl<'de> serde::Deserializer<'de> for Val {
    type Error = DeError;
    fn deserialize_any<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, DeError> {
        use serde::de::value::{MapDeserializer, SeqDeserializer};
        match self {
            Val::Null => v.visit_unit(),
            Val::Bool(b) => v.visit_bool(b),
            Val::Int(i) => v.visit_i64(i),
            Val::Float(x) => v.visit_f64(x),
            Val::Str(s) => v.visit_string(s),
            Val::Seq(items) => v.visit_seq(SeqDeserializer::new(items.into_iter())),
            Val::Map(entries) => v.visit_map(MapDeserializer::new(entries.into_iter())),
        }
    }
    fn deserialize_option<V: serde::de::Visitor<'de>>(self, v: V) -> Result<V::Value, DeError> {
        match self {
            Val::Null => v.visit_none(),
            other => v.visit_some(other),
        }
    }
    fn deserialize_enum<V: serde::de::Visitor<'de>>(
        self,
        _name: &'static str,
        _variants: &'static [&'static str],
        v: V,
    ) -> Result<V::Value, DeError> {
        match self {
            Val::Str(s) => v.visit_enum(serde::de::value::StringDeserializer::new(s)),
            other => other.deserialize_any(v),
        }
    }
    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf
        unit unit_struct newtype_struct seq tuple tuple_struct map struct identifier
        ignored_any
    }
}

/// A probe given as a dict of sections, as the TOML table the probe reader takes: numbers
/// (NaN and ±∞ kept, so that the reader's own checks name the key), strings, booleans, lists
/// and sub-dicts; `None` entries left out.
///
/// # Errors
/// `TypeError` naming the key of a value that is none of these.
pub fn toml_table(d: &Bound<'_, PyDict>) -> PyResult<toml::Table> {
    fn toml_of(v: Val) -> Option<toml::Value> {
        Some(match v {
            Val::Null => return None,
            Val::Bool(b) => toml::Value::Boolean(b),
            Val::Int(i) => toml::Value::Integer(i),
            Val::Float(x) => toml::Value::Float(x),
            Val::Str(s) => toml::Value::String(s),
            Val::Seq(items) => toml::Value::Array(items.into_iter().filter_map(toml_of).collect()),
            Val::Map(entries) => toml::Value::Table(
                entries
                    .into_iter()
                    .filter_map(|(k, v)| toml_of(v).map(|v| (k, v)))
                    .collect(),
            ),
        })
    }
    let mut table = toml::Table::new();
    for (k, v) in d.iter() {
        let key: String = k.extract()?;
        if let Some(v) = toml_of(val(&key, &v)?) {
            table.insert(key, v);
        }
    }
    Ok(table)
}

/// `v` as a [`Val`]; `key` names it in a `TypeError` for a type serde cannot take.
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
        v.extract().map(Val::Int).map_err(|_| {
            crate::errors::value_error(format!("{key} = {v}: out of range (beyond 64 bits)"))
        })
    } else if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items: PyResult<Vec<Val>> = v.try_iter()?.map(|x| val(key, &x?)).collect();
        Ok(Val::Seq(items?))
    } else if let Ok(d) = v.cast::<PyDict>() {
        Ok(Val::Map(entries(d)?))
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
/// spelling (parsed as the command line parses them: a `ValueError` names a bad one).
fn entries(d: &Bound<'_, PyDict>) -> PyResult<Vec<(String, Val)>> {
    let mut out = Vec::with_capacity(d.len());
    for (k, v) in d.iter() {
        let key: String = k.extract()?;
        let key = if key == "from_" {
            "from".to_string()
        } else {
            key
        };
        let value = match (key.as_str(), val(&key, &v)?) {
            (_, Val::Null) => continue,
            ("integrator", Val::Str(s)) => {
                Val::Str(canonical::<afmdyn::integrate::IntegratorKind>(&s)?)
            }
            ("param", Val::Str(s)) => Val::Str(canonical::<afmdyn::SweepParam>(&s)?),
            (_, other) => other,
        };
        out.push((key, value));
    }
    Ok(out)
}

/// `s` parsed by `T`'s `FromStr` (its message as the `ValueError`), in `T`'s serde spelling.
fn canonical<T>(s: &str) -> PyResult<String>
where
    T: std::str::FromStr + serde::Serialize,
    T::Err: std::fmt::Display,
{
    let t: T = s
        .parse()
        .map_err(|e: T::Err| crate::errors::value_error(e.to_string()))?;
    match serde_json::to_value(t) {
        Ok(serde_json::Value::String(name)) => Ok(name),
        _ => Ok(s.to_string()),
    }
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
) -> PyResult<Box<dyn afmdyn::request::Named>> {
    // the curve of a multifrequency drive is the approach curve's request
    let what = if name == "bimodal" { "approach" } else { name };
    deserialize(what, kwargs, |d| afmdyn::request::named::parse(name, d))?
        .ok_or_else(|| pyo3::exceptions::PyKeyError::new_err(name.to_string()))
}

/// `parse` of the keywords, its error naming the keyword (serde_path_to_error's path) and the
/// kind of number in words: `TypeError` for an unknown keyword, else `ValueError`.
fn deserialize<T>(
    what: &str,
    kwargs: Option<&Bound<'_, PyDict>>,
    parse: impl FnOnce(serde_path_to_error::Deserializer<'_, '_, Val>) -> Result<T, DeError>,
) -> PyResult<T> {
    let map = match kwargs {
        Some(d) => entries(d)?,
        None => Vec::new(),
    };
    let mut track = serde_path_to_error::Track::new();
    let parsed = parse(serde_path_to_error::Deserializer::new(
        Val::Map(map),
        &mut track,
    ));
    parsed.map_err(|e| {
        let path = track.path().to_string();
        let text = ["usize", "u64", "u32", "u16", "u8"]
            .iter()
            .fold(e.to_string(), |t, ty| {
                t.replace(&format!("expected {ty}"), "expected a non-negative integer")
            });
        let msg = if e.unknown || path == "." {
            format!("{what}: {text}")
        } else {
            format!("{what}: {path}: {text}")
        };
        if e.unknown {
            pyo3::exceptions::PyTypeError::new_err(msg)
        } else {
            pyo3::exceptions::PyValueError::new_err(msg)
        }
    })
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

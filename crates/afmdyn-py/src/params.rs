//! `afmdyn.Params` and the one place where Python keyword arguments become an
//! [`afmdyn::request::Params`]: [`params_from_kwargs`].

use crate::errors::param_error;
use afmdyn::request::ModelSpec;
use afmdyn::request::Params;
use pyo3::exceptions::{PyAttributeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

pub use crate::convert::model_spec;

/// `base` with the model keywords in `kwargs` applied, validated ([`ModelSpec::resolve`]).
/// Every Python entry point (the `Params` constructor, `Params.replace`, the `**model`
/// keywords of every analysis) goes through here.
///
/// # Errors
/// As [`model_spec`], and `ValueError` naming the field and its range.
pub fn params_from_kwargs(base: Params, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Params> {
    model_spec(kwargs)?
        .resolve(base, None)
        .map_err(crate::errors::sim_error)
}

/// The parameter set of an analysis call (the command line's `--probe`, `--config` and model
/// flags): `params` (an `afmdyn.Params`, like a config file), or the probe file's set, or
/// `default`, or the paper's set, with the keywords applied ([`ModelSpec::resolve`]: `z_c`
/// and `drive_frequency` need the probe). `params` and `probe` together must agree (the
/// pattern `f(Params.from_probe(path), probe=path)`): the probe sets every parameter, the SI
/// keywords and `modes`/`restitution` override it, the dimensionless ones it sets are refused
/// ([`afmdyn::request::model::PROBE_SETS`]).
#[pyfunction]
#[pyo3(signature = (params=None, default=None, probe=None, model=None, quasi_static=false))]
pub fn resolve(
    params: Option<PyRef<'_, PyParams>>,
    default: Option<PyRef<'_, PyParams>>,
    probe: Option<String>,
    model: Option<&Bound<'_, PyDict>>,
    quasi_static: bool,
) -> PyResult<PyParams> {
    let spec = model_spec(model)?;
    let needs = probe_needs(quasi_static);
    let probe = probe
        .map(|t| afmdyn::probe::Probe::parse_for(&t, "probe", needs))
        .transpose()
        .map_err(crate::errors::probe_error)?;
    let base = match (&params, &probe) {
        (Some(given), Some(pr)) if given.inner != pr.params => {
            return Err(PyValueError::new_err(
                "params and probe both given and they differ: pass probe= alone (it sets every \
                 parameter; keywords override single ones)",
            ))
        }
        (Some(given), _) => given.inner,
        (None, _) => default.map_or_else(Params::default, |d| d.inner),
    };
    Ok(PyParams {
        inner: spec
            .resolve(base, probe.as_ref())
            .map_err(crate::errors::sim_error)?,
    })
}

/// Dimensionless model parameters (paper eq. 7), validated on construction.
///
/// ``Params(**model)`` takes the keywords of every analysis: ``modes`` (N, 1..=20),
/// ``tip_mass_ratio``/``alpha1`` (α1 ≥ 0), ``drive_amplitude``/``alpha2`` (α2 ≥ 0),
/// ``beam_damping``/``alpha3`` (α3 ≥ 0), ``contact_stiffness``/``alpha4`` (α4 ≥ 0),
/// ``gap``/``alpha5`` (α5, finite), ``contact_damping``/``alpha6`` (α6 ≥ 0), ``omega``
/// (Ω > 0), ``contact_law`` (``"linear"``, ``"hertz"``, ``"dmt"``, ``"electrostatic"``,
/// ``"jkr"``, ``"capillary"``, ``"sls"``, ``"impact"``) with its groups ``restitution`` (0..=1, impact), ``hamaker``
/// (≥ 0) and ``intermolecular_distance`` (> 0, DMT and electrostatic), ``electrostatic``
/// (Ẽ ≥ 0) and ``tip_radius`` (R̃ > 0, electrostatic), ``adhesion`` (P̃ > 0, JKR),
/// ``capillary`` (F̃_cap > 0), ``meniscus`` (h̃) and ``rupture`` (D̃_r, capillary),
/// ``maxwell_stiffness`` (κ > 0, the SLS sample's Maxwell arm; its dashpot is α6),
/// ``excitation`` (``"base"``, ``"tip"``: where the
/// drive acts on the beam). Missing ones take the paper's Figs. 5–14 set (N = 3, α1 = α2 = α3 = 0.1, α4 = 20,
/// α5 = 0, α6 = 0.2, Ω = 2.6). The names, ranges and help are the library's one table
/// (``afmdyn._afmdyn.MODEL_PARAMETERS``).
///
/// Raises ``ValueError`` naming the field and its range, ``TypeError`` for an unknown keyword.
/// Instances are immutable; ``p.replace(omega=3.0)`` returns a modified copy.
#[pyclass(frozen, eq, name = "Params", module = "afmdyn")]
#[derive(Clone, PartialEq)]
pub struct PyParams {
    pub inner: Params,
}

#[pymethods]
impl PyParams {
    #[new]
    #[pyo3(signature = (**model))]
    fn new(model: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        Ok(PyParams {
            inner: params_from_kwargs(Params::default(), model)?,
        })
    }

    /// A copy with the given model keywords changed (validated).
    #[pyo3(signature = (**model))]
    fn replace(&self, model: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        Ok(PyParams {
            inner: params_from_kwargs(self.inner, model)?,
        })
    }

    /// Read a model config file (the command line's ``--config FILE.toml``: the same keywords,
    /// snake_case names or ``alpha1``…``alpha6``; unknown keys are rejected). Keys the file
    /// leaves out take the defaults; ``**model`` overrides the file.
    #[staticmethod]
    #[pyo3(signature = (path, **model))]
    fn from_toml(
        py: Python<'_>,
        path: &Bound<'_, PyAny>,
        model: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let toml = py
            .import("tomllib")
            .or_else(|_| py.import("tomli"))
            .map_err(|_| {
                PyTypeError::new_err("reading TOML needs Python >= 3.11 or the tomli package")
            })?;
        let file = py
            .import("builtins")?
            .getattr("open")?
            .call1((path, "rb"))?;
        let loaded = toml.getattr("load")?.call1((&file,));
        file.call_method0("close")?;
        let table = loaded?.cast_into::<PyDict>()?;
        let p = params_from_kwargs(Params::default(), Some(&table)).map_err(|e| {
            let msg = e.value(py).to_string();
            let ty = e.get_type(py);
            PyErr::from_type(ty, format!("{}: {msg}", path))
        })?;
        Ok(PyParams {
            inner: params_from_kwargs(p, model)?,
        })
    }

    /// The dimensionless set of a probe file in SI units (the command line's
    /// ``--probe FILE``: cantilever k, f₀, Q or geometry; tip; sample law; drive A₀, f; see
    /// ``docs/getting-started.md``), also given as TOML text or a dict of its sections; ``**model``
    /// takes what a probe leaves open, as every analysis' ``probe=`` does: ``modes``,
    /// ``restitution``, ``z_c`` (m) and ``drive_frequency`` (Hz); a dimensionless value the
    /// probe sets (``gap``, ``omega``, ``hamaker``, …) is refused naming the probe key or SI
    /// keyword to use. Raises ``ValueError`` listing every problem of the file.
    #[staticmethod]
    #[pyo3(signature = (path, **model))]
    fn from_probe(path: &Bound<'_, PyAny>, model: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let text = probe_source(path, None, None, false)?;
        let pr = afmdyn::probe::Probe::parse(&text, "probe").map_err(crate::errors::probe_error)?;
        Ok(PyParams {
            inner: model_spec(model)?
                .resolve(Params::default(), Some(&pr))
                .map_err(crate::errors::sim_error)?,
        })
    }

    /// The structural model: ``"beam"`` (the paper) or ``"point-mass"``.
    #[getter]
    fn structure(&self) -> &'static str {
        self.inner.structure.name()
    }

    /// A model keyword's value (``modes``, ``alpha1`` … ``alpha6`` and their names, ``omega``,
    /// ``contact_law``, ``excitation``, the law's groups: ``None`` for those of another law;
    /// the one table, ``MODEL_PARAMETERS``): the library's [`ModelSpec::of`] the set.
    fn __getattr__<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        let value = ModelSpec::of(&self.inner).value(name).ok_or_else(|| {
            PyAttributeError::new_err(format!("'Params' object has no attribute '{name}'"))
        })?;
        crate::convert::json_to_py(py, &value.to_string())
    }

    /// Drive period T = 2π/Ω (dimensionless τ).
    #[getter]
    fn period(&self) -> f64 {
        self.inner.period()
    }

    /// The ``"params"`` object of the command line's JSON documents.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        crate::convert::json_to_py(py, &serde_json::to_string(&self.inner).expect("params"))
    }

    fn __repr__(&self) -> String {
        // every serialised field, the known ones in the paper's order first, so a field added
        // to `afmdyn::request::Params` shows up here without a change
        let value = serde_json::to_value(self.inner).expect("params");
        let map = value.as_object().expect("a struct");
        let order = [
            "modes", "alpha1", "alpha2", "alpha3", "alpha4", "alpha5", "alpha6", "omega",
        ];
        let mut keys: Vec<&String> = map.keys().collect();
        keys.sort_by_key(|k| order.iter().position(|o| o == k).unwrap_or(order.len()));
        let fields: Vec<String> = keys.iter().map(|k| format!("{k}={}", map[*k])).collect();
        format!("Params({})", fields.join(", "))
    }

    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        let _ = py;
        let from_json = slf.get_type().getattr("_from_json")?;
        Ok((
            from_json,
            (serde_json::to_string(&slf.get().inner).expect("params"),),
        ))
    }

    #[staticmethod]
    fn _from_json(text: &str) -> PyResult<Self> {
        let inner: Params = serde_json::from_str(text)
            .map_err(|e| PyValueError::new_err(format!("Params: {e}")))?;
        inner.validate().map_err(param_error)?;
        Ok(PyParams { inner })
    }
}

/// The TOML text of a probe given as Python's `probe=` takes it — a file's path (`str` or
/// `os.PathLike`), TOML text (a `str` with a line break or `=`) or a `dict` of its sections —
/// with `[cantilever].name` set from `cantilever` (the command line's `--cantilever`), checked:
/// [`Probe::source_text`]. What the analyses then take as `probe`.
///
/// # Errors
/// `ValueError` naming the source and every problem; `TypeError` for another type.
#[pyfunction]
#[pyo3(signature = (probe, cantilever=None, medium=None, quasi_static=false))]
pub fn probe_source(
    probe: &Bound<'_, PyAny>,
    cantilever: Option<String>,
    medium: Option<String>,
    quasi_static: bool,
) -> PyResult<String> {
    use crate::errors::probe_error;
    use afmdyn::probe::{Probe, ProbeSource};
    use std::path::PathBuf;
    let names = (cantilever.as_deref(), medium.as_deref());
    let needs = probe_needs(quasi_static);
    let r = if let Ok(d) = probe.cast::<pyo3::types::PyDict>() {
        let table = crate::convert::toml_table(d)?;
        Probe::source_text(ProbeSource::Table(&table), names, needs)
    } else if let Ok(s) = probe.extract::<String>() {
        Probe::source_text(ProbeSource::of_str(&s), names, needs)
    } else if let Ok(p) = probe.extract::<PathBuf>() {
        Probe::source_text(ProbeSource::Path(&p), names, needs)
    } else {
        return Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "probe: expected a path, TOML text or a dict, got {}",
            probe.get_type().name()?
        )));
    };
    r.map(|(text, _)| text).map_err(probe_error)
}

/// What a call uses of its probe: a quasi-static force curve's spring constant, tip and
/// sample (`quasi_static`), or the oscillating lever.
fn probe_needs(quasi_static: bool) -> afmdyn::probe::ProbeNeeds {
    if quasi_static {
        afmdyn::probe::ProbeNeeds::Static
    } else {
        afmdyn::probe::ProbeNeeds::Oscillation
    }
}

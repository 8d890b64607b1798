//! The compiled functions beside the one door ([`crate::door`]): a probe's parameters and SI
//! block, a height map file's heights, the image (the library's `ImageJob`, whose inputs are a
//! probe's TOML table and a sample map rather than a model, run as the door runs a request, to
//! the same outcome dict) and the image's setpoint study.

use crate::errors::{probe_error, sim_error};
use crate::params::PyParams;
use afmdyn::probe::Probe;
use afmdyn::report;
use afmdyn::request::{self, Request};
use pyo3::prelude::*;
use pyo3::types::PyDict;

type Dict<'py> = Bound<'py, PyDict>;

/// A probe (SI units, `afmdyn … --probe FILE`; its TOML text from [`crate::params::probe_source`]): its
/// dimensionless parameters and the `"si"` block of the command line's JSON (scales,
/// calibration, drive, A₀, z_c).
#[pyfunction]
pub fn probe(text: &str) -> PyResult<(PyParams, String)> {
    let pr = Probe::parse(text, "probe").map_err(probe_error)?;
    let si = report::si(&pr, &pr.params, &serde_json::json!({}));
    Ok((PyParams { inner: pr.params }, si.to_string()))
}

/// The heights of a height map file (`.csv` or `.npy`, a relative path from the current
/// directory; [`afmdyn::io::height_map::read`]), `[row][column]` in m: Python's
/// `afmdyn.image(…, height_map="h.npy")`.
#[pyfunction]
pub fn read_height_map(path: &str) -> PyResult<Vec<Vec<f64>>> {
    afmdyn::io::height_map::read(path, None).map_err(sim_error)
}

/// The image of a sample map under a probe (`afmdyn image`: the library's
/// [`afmdyn::request::image_job::ImageJob`], validated and held against the budgets): what
/// `run` returns ([`afmdyn::request::image_job::ImageOutput::outcome`]: the per-pixel
/// document, the layout `image` and the fact `summary`). `probe` is the probe's TOML text
/// ([`crate::params::probe_source`]); `request` the keywords of
/// [`afmdyn::request::image_job::ImageKeywords`] (`sample` the map's TOML text or path,
/// `feedback` a PI scan's settings: its lines on `threads` workers, cancellable, with progress).
#[pyfunction]
#[pyo3(signature = (probe, request, progress=None))]
pub fn image<'py>(
    py: Python<'py>,
    probe: &str,
    request: &Bound<'py, PyDict>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Dict<'py>> {
    use afmdyn::request::image_job::ImageKeywords;
    let keywords: ImageKeywords = crate::convert::request("image", Some(request))?;
    let setpoint = keywords.setpoint;
    let job = keywords.job(probe).map_err(sim_error)?;
    let model = job.model().map_err(sim_error)?;
    job.validate(&model).map_err(sim_error)?;
    crate::door::run_outcome(py, progress, move |p| {
        request::run(&job, &model, p).map(|doc| doc.output.outcome(setpoint))
    })
}

/// The setpoint study of a sample map under a probe (`afmdyn image --setpoint-study`:
/// [`afmdyn::study::image_ideal::setpoint_study`]): its outcome as [`crate::door::run`]'s, the
/// JSON (`ratio`, `domains`) and the layout `setpoint_study`. Arguments as [`image`]'s.
#[pyfunction]
#[pyo3(signature = (probe, sample, ratios, curve_points=None))]
pub fn setpoint_study<'py>(
    py: Python<'py>,
    probe: &str,
    sample: &str,
    ratios: Vec<f64>,
    curve_points: Option<usize>,
) -> PyResult<Dict<'py>> {
    use afmdyn::request::image::ImageRequest;
    use afmdyn::request::image_job::ImageKeywords;
    use afmdyn::study::image_ideal::setpoint_study;
    let keywords = ImageKeywords {
        sample: sample.to_string(),
        ..ImageKeywords::default()
    };
    let (table, map) = keywords.inputs(probe).map_err(sim_error)?;
    let points = curve_points.unwrap_or(ImageRequest::at(0.5).curve_points);
    let study = py
        .detach(|| setpoint_study(&table, &map, &ratios, points))
        .map_err(sim_error)?;
    crate::door::outcome_dict(py, study.outcome())
}

//! The analyses, called by the pure-Python layer (`afmdyn/__init__.py`), which turns the dicts
//! returned here into xarray datasets and result objects. Each function validates its options
//! as the command line does, runs the library without the GIL (see [`crate::run`]) and returns
//! NumPy arrays that own the Rust buffers, plus the command line's JSON document where it has
//! one (`"json"`).

use crate::convert::Out;
use crate::errors::{probe_error, sim_error, study_error};
use crate::image_tasks::{image_inputs, scan_out};
use crate::params::PyParams;
use crate::run::{run, Job, Stop};
use afmdyn::analysis::bifurcation::SweepSpec;
use afmdyn::probe::Probe;
use afmdyn::request::SweepRecord;
use afmdyn::request::{self, Analysis, Document, Resolved};
use afmdyn::study::execute;
use afmdyn::{report, Params};
use pyo3::prelude::*;
use pyo3::types::PyDict;

type Dict<'py> = Bound<'py, PyDict>;

/// The library's [`request::run`] of `request` on `params` (with the probe file's SI block in
/// the document) on a worker thread without the GIL: validated first, here; a `counted`
/// analysis reports its progress and stops at its next check on an interrupt
/// ([`Stop::Cancellable`]), the others are abandoned ([`Stop::Abandon`]).
pub fn analysis<A>(
    py: Python<'_>,
    request: A,
    params: Params,
    probe: Option<String>,
    progress: Option<&Bound<'_, PyAny>>,
    counted: bool,
) -> PyResult<Document<A::Output>>
where
    A: Analysis + Send + 'static,
    A::Output: Send + 'static,
{
    let model = Resolved {
        params,
        probe: crate::door::probe_of(probe)?,
    };
    request.validate(&model).map_err(sim_error)?;
    let job = Job::default();
    let worker = job.clone();
    let stop = if counted {
        Stop::Cancellable
    } else {
        Stop::Abandon
    };
    run(py, &job, None, progress, stop, move || {
        request::run(&request, &model, &worker.progress)
    })?
    .map_err(sim_error)
}

/// A sweep's records, in their order, as the door returns them
/// ([`afmdyn::study::stored::sweep_outcome`]).
pub(crate) fn sweep_dict<'py>(
    py: Python<'py>,
    spec: &SweepSpec,
    records: Vec<SweepRecord>,
) -> PyResult<Dict<'py>> {
    crate::door::outcome_dict(py, afmdyn::study::stored::sweep_outcome(spec, &records))
}

/// The JSON document of a reconstruction request, run as every analysis is ([`analysis`]):
/// cancellable (the inversion checks the cancel flag between chunks of rows; Ctrl-C stops it).
fn reconstruction<'py>(
    py: Python<'py>,
    request: afmdyn::request::ReconstructRequest,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Dict<'py>> {
    let doc = analysis(
        py,
        request,
        Params::default(),
        None,
        progress.as_ref(),
        true,
    )?;
    let out = Out::new(py);
    out.json(&doc.json)?;
    Ok(out.finish())
}

/// A JSON document passed as text (`name` the keyword, for the error).
fn json_document(name: &str, text: &str) -> PyResult<serde_json::Value> {
    serde_json::from_str(text).map_err(|e| {
        pyo3::exceptions::PyValueError::new_err(format!("{name}: not a JSON document: {e}"))
    })
}

/// The force and potential behind an `fm` document (`afmdyn reconstruct --fm fm.json`): the
/// request from the document ([`afmdyn::request::ReconstructRequest::from_fm_document`], its
/// k, f0 and A replaced by those given, by the `inversion` named), and its JSON document.
#[pyfunction]
#[pyo3(signature = (document, spring_constant=None, resonance_frequency=None, amplitude=None, progress=None, inversion="sader-jarvis"))]
pub fn reconstruct_fm<'py>(
    py: Python<'py>,
    document: &str,
    spring_constant: Option<f64>,
    resonance_frequency: Option<f64>,
    amplitude: Option<f64>,
    progress: Option<Bound<'py, PyAny>>,
    inversion: &str,
) -> PyResult<Dict<'py>> {
    let mut request = afmdyn::request::ReconstructRequest::from_fm_document(
        &json_document("fm", document)?,
        spring_constant,
        resonance_frequency,
        amplitude,
    )
    .map_err(sim_error)?;
    // the request's own words ("sader-jarvis", "exact"), refused naming the keyword otherwise
    request.inversion =
        serde_json::from_value(serde_json::Value::from(inversion)).map_err(|_| {
            pyo3::exceptions::PyValueError::new_err(format!(
                "inversion: {inversion:?} is not an inversion (\"sader-jarvis\" or \"exact\")"
            ))
        })?;
    reconstruction(py, request, progress)
}

/// The conservative force behind an AM approach document of the point mass (`afmdyn
/// reconstruct --am approach.json`: [`afmdyn::request::reconstruct::am_reconstruction`]): its
/// JSON document; without the GIL and cancellable, as [`reconstruction`].
#[pyfunction]
#[pyo3(signature = (document, progress=None))]
pub fn reconstruct_am<'py>(
    py: Python<'py>,
    document: &str,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Dict<'py>> {
    let approach = json_document("am", document)?;
    let job = Job::default();
    let worker = job.clone();
    let doc = run(
        py,
        &job,
        None,
        progress.as_ref(),
        Stop::Cancellable,
        move || afmdyn::request::reconstruct::am_reconstruction(&approach, &worker.progress),
    )?
    .map_err(sim_error)?;
    let out = Out::new(py);
    out.json(&doc.json)?;
    Ok(out.finish())
}

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

/// The ideal-feedback image of a sample map under a probe (`afmdyn image`:
/// [`afmdyn::request::image::image`]): `json` (its document) and `layout` (its arrays,
/// [`afmdyn::request::image_layout::layout`], as `image.nc` holds them). `probe` is the probe's TOML text
/// ([`crate::params::probe_source`]), `sample` the map's TOML text or path
/// ([`afmdyn::request::image::SampleMap::read`]); `None` takes the request's defaults
/// ([`afmdyn::request::image::ImageRequest::at`]).
#[pyfunction]
#[pyo3(signature = (probe, sample, setpoint, pixels=None, lines=None, curve_points=None, height_map=None))]
#[allow(clippy::too_many_arguments)]
pub fn image<'py>(
    py: Python<'py>,
    probe: &str,
    sample: &str,
    setpoint: f64,
    pixels: Option<usize>,
    lines: Option<usize>,
    curve_points: Option<usize>,
    height_map: Option<Vec<Vec<f64>>>,
) -> PyResult<Dict<'py>> {
    use afmdyn::request::image::{image, ImageRequest};
    let (table, map) = image_inputs(probe, sample, height_map)?;
    let req = ImageRequest::with(setpoint, pixels, lines, curve_points);
    let img = py.detach(|| image(&table, &map, &req)).map_err(sim_error)?;
    let out = Out::new(py);
    out.json(&img.document(setpoint))?;
    // the command line's image.json: the summary the dataset's `summary` attribute holds
    let summary = afmdyn::request::present::image::ideal_summary(&img, setpoint, None);
    out.set("summary", summary.to_string())?;
    let layout = afmdyn::request::image_layout::layout(&img, setpoint);
    out.set("layout", crate::convert::layout_dict(py, layout)?)?;
    Ok(out.finish())
}

/// The PI-scanned image of a sample map under a probe (`afmdyn image --feedback pi`:
/// [`afmdyn::study::scan::pi_image`]): its JSON document and layout, the lines on `threads` worker
/// threads (`None`: all cores), with progress (lines) and Ctrl-C. Arguments as [`image`]'s;
/// `scan_rate` (Hz), `gains` (K_P, K_I in 1/s) and `time_constant` (s), `None` for the lever's
/// defaults.
#[pyfunction]
#[pyo3(signature = (probe, sample, setpoint, pixels=None, lines=None, curve_points=None, height_map=None, scan_rate=None, gains=None, time_constant=None, threads=None, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn pi_image<'py>(
    py: Python<'py>,
    probe: &str,
    sample: &str,
    setpoint: f64,
    pixels: Option<usize>,
    lines: Option<usize>,
    curve_points: Option<usize>,
    height_map: Option<Vec<Vec<f64>>>,
    scan_rate: Option<f64>,
    gains: Option<(f64, f64)>,
    time_constant: Option<f64>,
    threads: Option<usize>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    use afmdyn::request::image_scan::ScanStudy;
    let recipe = crate::image_tasks::recipe(
        probe,
        sample,
        setpoint,
        pixels,
        lines,
        curve_points,
        height_map,
        scan_rate,
        gains,
        time_constant,
    )?;
    afmdyn::request::limits::check_threads(threads).map_err(sim_error)?;
    let job = Job::default();
    let worker = job.clone();
    let img = run(
        py,
        &job,
        Some(recipe.request.lines(&recipe.map)),
        progress.as_ref(),
        Stop::Cancellable,
        move || -> PyResult<afmdyn::request::image_scan::PiImage> {
            let study = ScanStudy::from_recipe(&recipe).map_err(sim_error)?;
            let mut store = afmdyn::study::MemoryStore::default();
            execute(&study, &mut store, false, threads, &*worker.progress).map_err(study_error)?;
            study.assemble(store.records).map_err(sim_error)
        },
    )??;
    scan_out(py, &img, setpoint)
}

/// The setpoint study of a sample map under a probe (`afmdyn image --setpoint-study`:
/// [`afmdyn::request::image::setpoint_study`]): its JSON (`ratio`, `domains`). Arguments as
/// [`image`]'s.
#[pyfunction]
#[pyo3(signature = (probe, sample, ratios, curve_points=None))]
pub fn setpoint_study(
    py: Python<'_>,
    probe: &str,
    sample: &str,
    ratios: Vec<f64>,
    curve_points: Option<usize>,
) -> PyResult<String> {
    use afmdyn::request::image::{setpoint_study, ImageRequest};
    let (table, map) = image_inputs(probe, sample, None)?;
    let points = curve_points.unwrap_or(ImageRequest::at(0.5).curve_points);
    let study = py
        .detach(|| setpoint_study(&table, &map, &ratios, points))
        .map_err(sim_error)?;
    Ok(serde_json::to_string(&study).expect("a study serialises"))
}

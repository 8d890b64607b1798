//! The tasks `afmdyn.dask.image` maps over a cluster: [`ScanStudy`], a PI-scanned image that any
//! process rebuilds from its recipe (a JSON text: the probe's table, the sample map, the request
//! and the settings; [`afmdyn::request::image_scan::ScanRecipe`]), whose tasks are its lines. A
//! finished line travels as CBOR text (every float bit for bit), so an image scanned on a
//! cluster is the local image bit for bit.

use crate::convert::Out;
use crate::errors::{probe_error, sim_error, value_error};
use afmdyn::analysis::am_loop::ScanLine;
use afmdyn::probe::Probe;
use afmdyn::request::image::ImageRequest;
use afmdyn::request::image_scan::{PiScan, ScanRecipe, ScanStudy as Study};
use afmdyn::study::task_store::{from_cbor_text, to_cbor_text};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::atomic::AtomicBool;

/// A PI scan planned as lines.
#[pyclass(frozen, module = "afmdyn._afmdyn")]
pub struct ScanStudy {
    study: Study,
    text: String,
}

/// The recipe of a PI scan from the arguments of `afmdyn.image(feedback="pi")` (`None`: the
/// defaults): the probe's TOML text, the sample map's text or path, its height map.
///
/// # Errors
/// `ValueError` for a probe or sample map the library refuses.
#[allow(clippy::too_many_arguments)]
pub(crate) fn recipe(
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
) -> PyResult<ScanRecipe> {
    let (probe, map) = image_inputs(probe, sample, height_map)?;
    Ok(ScanRecipe {
        probe,
        map,
        request: ImageRequest::with(setpoint, pixels, lines, curve_points),
        scan: PiScan {
            scan_rate,
            gains,
            time_constant,
        },
    })
}

impl ScanStudy {
    fn of(recipe: &ScanRecipe) -> PyResult<Self> {
        let study = Study::from_recipe(recipe).map_err(sim_error)?;
        let text = serde_json::to_string(recipe).map_err(|e| value_error(e.to_string()))?;
        Ok(ScanStudy { study, text })
    }
}

#[pymethods]
impl ScanStudy {
    /// The scan of a recipe (the text [`ScanStudy::recipe`] returns).
    #[new]
    fn new(recipe: &str) -> PyResult<Self> {
        let r: ScanRecipe = serde_json::from_str(recipe)
            .map_err(|e| value_error(format!("image scan recipe: {e}")))?;
        ScanStudy::of(&r)
    }

    /// The scan of a probe (TOML text) over a sample map (TOML text or path), with the
    /// arguments of `afmdyn.image(feedback="pi")` (`None`: the defaults).
    #[staticmethod]
    #[pyo3(signature = (probe, sample, setpoint, pixels=None, lines=None, curve_points=None, height_map=None, scan_rate=None, gains=None, time_constant=None))]
    #[allow(clippy::too_many_arguments)]
    fn build(
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
    ) -> PyResult<Self> {
        ScanStudy::of(&recipe(
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
        )?)
    }

    /// The recipe: JSON text that rebuilds this scan in any process.
    #[getter]
    fn recipe(&self) -> String {
        self.text.clone()
    }

    /// The number of lines (the tasks).
    fn lines(&self) -> usize {
        self.study.lines()
    }

    /// Line `t`, trace and retrace, as CBOR text (with its number).
    fn run_line(&self, py: Python<'_>, t: usize) -> PyResult<String> {
        let line = py
            .detach(|| self.study.line(t, &AtomicBool::new(false)))
            .map_err(sim_error)?;
        to_cbor_text(&(t, line)).map_err(value_error)
    }

    /// The image's document and layout (`{"json": text, "layout": …}`) of the finished lines
    /// (their texts, any order).
    fn document<'py>(
        &self,
        py: Python<'py>,
        lines: Vec<String>,
    ) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        let records = lines
            .iter()
            .map(|t| {
                from_cbor_text::<(usize, ScanLine)>(t)
                    .map_err(|e| value_error(format!("not a line of an image scan: {e}")))
            })
            .collect::<PyResult<Vec<_>>>()?;
        let img = self.study.assemble(records).map_err(sim_error)?;
        scan_out(py, &img, self.study.recipe().request.setpoint)
    }
}

/// The probe's table (from its TOML text) and the sample map (TOML text or path) of an image.
/// With `height_map`, the map's height map replaced by it.
pub(crate) fn image_inputs(
    probe: &str,
    sample: &str,
    height_map: Option<Vec<Vec<f64>>>,
) -> PyResult<(toml::Table, afmdyn::request::image::SampleMap)> {
    let table = Probe::table(probe, "probe").map_err(probe_error)?;
    let mut map = afmdyn::request::image::SampleMap::read(sample).map_err(sim_error)?;
    if let Some(rows) = height_map {
        map = map.with_height_map(rows).map_err(sim_error)?;
    }
    Ok((table, map))
}

/// A PI scan's document, its summary (the command line's `image.json`) and layout
/// ([`afmdyn::request::image_layout::scan_layout`]) as Python takes them: `{"json": text,
/// "summary": text, "layout": …}`.
pub(crate) fn scan_out<'py>(
    py: Python<'py>,
    img: &afmdyn::request::image_scan::PiImage,
    setpoint: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let out = Out::new(py);
    out.json(&img.document(setpoint))?;
    let summary = afmdyn::request::present::image::pi_summary(img, setpoint);
    out.set("summary", summary.to_string())?;
    let layout = afmdyn::request::image_layout::scan_layout(img, setpoint);
    out.set("layout", crate::convert::layout_dict(py, layout)?)?;
    Ok(out.finish())
}

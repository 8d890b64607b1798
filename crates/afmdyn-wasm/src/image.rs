//! `run("image", input)`: the AM-AFM image of a heterogeneous sample under an ideal amplitude
//! feedback: its document with every pixel ([`afmdyn::request::image::Image::document`], which
//! the explorer draws), of which `afmdyn image --probe P --sample S --setpoint R --json` prints
//! the summary ([`afmdyn::report::present::image::ideal_summary`]; the maps in `image.nc`).
//!
//! The input: `probe` (a probe file's text: the lever, tip, drive and the background sample;
//! required), `sample` (a sample map's text, [`afmdyn::request::image::SampleMap::parse`]:
//! `size = [Lx, Ly]` and `[[domain]]` entries; required; a `height_map` must be inline rows,
//! a file being refused with its message), no `model` keys (the probe and the map are the
//! model), and `request`: `setpoint` (A_sp/A₀ in (0, 1), required), `pixels`, `lines`,
//! `curve_points` (as [`afmdyn::request::image::ImageRequest::with`] takes them),
//! `setpoint_study` (`"FROM:TO:N"`: the document gains `"setpoint_study"`, as with
//! `--setpoint-study`) and `feedback` (`"ideal"`; the PI scan, `"pi"`, is refused: its lines
//! take seconds each and run on worker threads).
//!
//! `mode = "peakforce"` (an off-resonance probe, `[drive] mode = "off-resonance"`): the
//! PeakForce image under an ideal peak-force feedback
//! ([`afmdyn::request::image_peakforce`], `afmdyn image --mode peakforce`), `setpoint` the
//! peak force (N); its document with every pixel
//! ([`afmdyn::study::peakforce_image::PeakForceImage::document`]: maps of height,
//! modulus_dmt, adhesion, deformation, dissipation, …), its lines computed one after the
//! other (no threads in wasm32; the image does not depend on the thread count). No
//! `curve_points`, `setpoint_study` or PI feedback with it.

use afmdyn::probe::Probe;
use afmdyn::request::image::study_ratios;
use afmdyn::request::image::{ImageRequest, SampleMap};
use afmdyn::request::ModelSpec;
use afmdyn::study::image_ideal::{image as ideal_image, setpoint_study};
use afmdyn::study::peakforce_image::PeakForceImageStudy;
use serde::Deserialize;

/// Most pixels (pixels × lines) of an image in wasm: the document holds a dozen values per
/// pixel, and wasm32 at most 4 GiB (the command line takes up to 4096 × 4096).
pub const MAX_IMAGE_PIXELS: usize = 512 * 512;

/// The request's keys (module docs); `ImageRequest` itself has no defaults to deserialise
/// with, so the keys are mapped as the command line maps its flags.
#[derive(Debug, Default, Deserialize)]
#[serde(default, deny_unknown_fields)]
struct ImageKeys {
    setpoint: Option<f64>,
    pixels: Option<usize>,
    lines: Option<usize>,
    curve_points: Option<usize>,
    setpoint_study: Option<String>,
    feedback: Option<String>,
    mode: Option<String>,
}

/// The image of `input` (module docs): its document as JSON text.
///
/// # Errors
/// A missing probe, sample or setpoint; model keys; `feedback` other than `ideal`; the probe's
/// TOML syntax, the sample map's and the request's refusals (naming the key and its range);
/// more than [`MAX_IMAGE_PIXELS`] pixels; the materials' approach curves'.
pub fn image(input: &str) -> Result<String, String> {
    let inp = crate::Input::read(input)?;
    if inp.model != ModelSpec::default() {
        return Err(
            "model: image takes no model keys (the probe file and the sample map are \
                    its model)"
                .into(),
        );
    }
    let probe = inp
        .probe
        .ok_or("probe: image needs a probe file's text (the lever, tip, drive and background)")?;
    let sample = inp.sample.ok_or(
        "sample: image needs a sample map's text (size = [Lx, Ly] and [[domain]] entries)",
    )?;
    let keys: ImageKeys = crate::request(inp.request)?;
    match keys.feedback.as_deref() {
        None | Some("ideal") => {}
        Some("pi") => {
            return Err(
                "feedback = pi: not in the browser (a PI scan's lines take seconds \
                        each on worker threads; afmdyn image --feedback pi); must be ideal"
                    .into(),
            )
        }
        Some(other) => return Err(format!("feedback = {other}: must be ideal or pi")),
    }
    let peakforce = match keys.mode.as_deref() {
        None | Some("am") => false,
        Some("peakforce") => true,
        Some(other) => return Err(format!("mode = {other}: must be am or peakforce")),
    };
    if peakforce {
        if keys.curve_points.is_some() || keys.setpoint_study.is_some() {
            return Err(
                "mode = peakforce: no curve_points or setpoint_study (its ideal \
                        peak-force feedback engages each material by its own setpoint search)"
                    .into(),
            );
        }
        if keys.feedback.as_deref() == Some("pi") {
            return Err("feedback = pi: a PeakForce image has the ideal feedback only".into());
        }
    }
    let setpoint = keys.setpoint.ok_or(if peakforce {
        "setpoint: missing; must be the peak force (N) the feedback holds, > 0"
    } else {
        "setpoint: missing; must be a ratio A_sp/A0 in (0, 1)"
    })?;
    let table = Probe::table(&probe, "probe").map_err(|e| e.to_string())?;
    let map = SampleMap::parse(&sample, "sample").map_err(|e| e.to_string())?;
    let req = ImageRequest::with(setpoint, keys.pixels, keys.lines, keys.curve_points);
    if peakforce {
        req.validate_grid(&map)
    } else {
        req.validate(&map)
    }
    .map_err(|e| e.to_string())?;
    let lines = req.lines(&map);
    if req.pixels * lines > MAX_IMAGE_PIXELS {
        return Err(format!(
            "pixels = {}, lines = {lines}: {} pixels; must be at most {MAX_IMAGE_PIXELS} (512 × \
             512) in the browser (wasm32 memory)",
            req.pixels,
            req.pixels * lines
        ));
    }
    if peakforce {
        // its engages, then its lines one after the other (the document with every pixel)
        let study = PeakForceImageStudy::new(&table, &map, &req).map_err(|e| e.to_string())?;
        let records = (0..study.lines())
            .map(|t| study.line(t).map(|l| (t, l)))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| e.to_string())?;
        let img = study.assemble(records).map_err(|e| e.to_string())?;
        return Ok(img.document().to_string());
    }
    let ratios = keys
        .setpoint_study
        .as_deref()
        .map(study_ratios)
        .transpose()
        .map_err(|e| e.to_string())?;
    let img = ideal_image(&table, &map, &req).map_err(|e| e.to_string())?;
    let mut doc = img.document(setpoint);
    if let Some(r) = ratios {
        let study =
            setpoint_study(&table, &map, &r, req.curve_points).map_err(|e| e.to_string())?;
        doc["setpoint_study"] =
            serde_json::to_value(study).map_err(|e| format!("setpoint_study: {e}"))?;
    }
    Ok(doc.to_string())
}

//! AM-AFM images of a heterogeneous sample (issue 46): a sample map ([`SampleMap`], the
//! `--sample S.toml` of `afmdyn image`) and the request of the image an **ideal** amplitude
//! feedback records over it ([`ImageRequest`]: its grid, checks and declared cost); the image
//! itself is computed in the study layer.
//!
//! **Sample map.** `size = [Lx, Ly]` (m; Ly = 0 for a line), then `[[domain]]` entries with a
//! `name`, `x = [x0, x1]` (m), optional `y = [y0, y1]` (m; the whole width when left out), an
//! optional true `height` (m, default 0) reached over an optional `width` (m, default 0: a sharp
//! step; the height rises inside the domain's edges as the smoothstep 3t² − 2t³, t the distance
//! to the nearest edge over `width`) and an optional `[domain.sample]` table with the keys of
//! a probe's `[sample]` (law, moduli, Hamaker constant, viscosity, …); the probe's own
//! `[sample]` is the background (height 0). Where domains overlap, the later one lies on top. A
//! top-level `height_map = [[…], …]` (m; rows from y = 0 to Ly, columns from x = 0 to Lx, each
//! row as long) adds a topography sampled bilinearly at each pixel (a measured or generated
//! height map, e.g. from a NumPy array); `height_map = "h.csv"` or `"h.npy"` reads it from a
//! file (feature `files`: [`crate::io::height_map`]), a relative path taken from the sample
//! file's directory ([`SampleMap::load`]) or else the current directory ([`SampleMap::parse`]).

use crate::error::{in_range, SimError};
use crate::params::Params;
use crate::probe::Probe;
use crate::report::CurveUnits;
use serde::{Deserialize, Serialize};
use std::ops::Bound::Excluded;

use super::costs::{image_curves_cost, MODEL_BYTES};
use super::limits::Cost;

mod ratios;
mod sample;
pub use ratios::{study_ratios, MAX_STUDY_RATIOS};

pub(crate) use crate::report::image::SetpointStudy;
pub use crate::report::image::{Image, Material, OperatingPoint, Pixel, Regime};

pub use crate::io::height_map::{MAX_HEIGHT, MAX_PIXELS};

/// The imaging mode: amplitude-modulation (AM) tapping or off-resonance (PeakForce) tapping.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(rename_all = "lowercase")]
pub enum ImageMode {
    /// AM-AFM: the amplitude feedback at the setpoint ratio A_sp/A₀ ([`super::image`],
    /// [`super::image_scan`]).
    #[default]
    Am,
    /// PeakForce: the ideal peak-force feedback at the setpoint force (N) with an off-resonance
    /// probe ([`super::image_peakforce`]).
    Peakforce,
}

/// Largest number of domains of a sample map.
pub(crate) const MAX_DOMAINS: usize = 1000;

/// One domain of a [`SampleMap`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Domain {
    /// Its name.
    pub name: String,
    /// [x0, x1] (m).
    pub x: (f64, f64),
    /// [y0, y1] (m); `None`: the map's whole width in y.
    pub y: Option<(f64, f64)>,
    /// True height (m).
    pub height: f64,
    /// Width (m) over which the height rises inside the domain's edges (0: a sharp step).
    pub width: f64,
    /// Its `[domain.sample]` table (a probe's `[sample]` keys); `None`: the background's
    /// material.
    pub sample: Option<toml::Table>,
}

/// A heterogeneous sample (module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SampleMap {
    /// [Lx, Ly] (m).
    pub size: (f64, f64),
    /// The domains, the later on top.
    pub domains: Vec<Domain>,
    /// A topography added everywhere (m), `[row][column]` over y then x (empty: none).
    pub height_map: Vec<Vec<f64>>,
}

/// An image request (`afmdyn image`, Python's `afmdyn.image`; module docs). Its default
/// ([`ImageRequest::at`] 0.5) only exemplifies it: every front end asks for the setpoint.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct ImageRequest {
    /// Setpoint ratio A_sp/A₀ in (0, 1).
    #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "mode")))]
    pub setpoint: f64,
    /// Pixels per line (default 64).
    #[serde(default = "default_pixels")]
    pub pixels: usize,
    /// Lines; `None`: as many as pixels, 1 for a line map (Ly = 0) ([`ImageRequest::lines`]).
    pub lines: Option<usize>,
    /// Points of each material's approach curve (its z_c grid, the probe's default range;
    /// default 120, the approach's default: [`crate::analysis::stepped::DEFAULT_CURVE_POINTS`]).
    #[serde(default = "default_curve_points")]
    pub curve_points: usize,
    /// A PeakForce image's temperature T (K, > 0 and ≤ 1500; outside 200–500 K it warns): every
    /// pixel's σ of the peak force and the deformation from cycle to cycle, its material's tap
    /// at the setpoint under the lever's thermal force
    /// ([`crate::analysis::peakforce::tap_noise`]); `None`: no noise. Front ends take the one
    /// `temperature` of an image ([`ImageRequest::with_temperature`]); an AM image's is its PI
    /// scan's ([`super::image_scan::PiScan`]) and refused here.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature: Option<f64>,
}

/// [`ImageRequest::pixels`]' default: 64.
fn default_pixels() -> usize {
    64
}

/// [`ImageRequest::curve_points`]' default: the approach's
/// ([`crate::analysis::stepped::DEFAULT_CURVE_POINTS`]).
fn default_curve_points() -> usize {
    crate::analysis::stepped::DEFAULT_CURVE_POINTS
}

impl Default for ImageRequest {
    fn default() -> Self {
        ImageRequest::at(0.5)
    }
}

impl ImageRequest {
    /// The request at `setpoint` with the defaults: 64 pixels, the default lines, the
    /// approach curve's default points.
    pub fn at(setpoint: f64) -> ImageRequest {
        ImageRequest {
            setpoint,
            pixels: default_pixels(),
            lines: None,
            curve_points: default_curve_points(),
            temperature: None,
        }
    }

    /// The request with the image's `temperature` as a front end takes it: a PeakForce
    /// image's ([`ImageRequest::temperature`]); an AM image's is its PI scan's, not the
    /// request's.
    pub fn with_temperature(mut self, mode: ImageMode, t: Option<f64>) -> Self {
        self.temperature = t.filter(|_| mode == ImageMode::Peakforce);
        self
    }

    /// The request at `setpoint` with the options a front end was given (`None`: the
    /// defaults of [`ImageRequest::at`]).
    pub fn with(
        setpoint: f64,
        pixels: Option<usize>,
        lines: Option<usize>,
        curve_points: Option<usize>,
    ) -> ImageRequest {
        let d = ImageRequest::at(setpoint);
        ImageRequest {
            pixels: pixels.unwrap_or(d.pixels),
            lines,
            curve_points: curve_points.unwrap_or(d.curve_points),
            ..d
        }
    }

    /// The memory of the image over `map` while it is held and written:
    /// [`IMAGE_BYTES_PER_PIXEL`] a pixel.
    pub(crate) fn pixel_bytes(&self, map: &SampleMap) -> f64 {
        (self.pixels * self.lines(map)) as f64 * IMAGE_BYTES_PER_PIXEL
    }

    /// The number of lines over `map`: as given, else as many as pixels (1 for a line map).
    pub fn lines(&self, map: &SampleMap) -> usize {
        self.lines
            .unwrap_or(if map.size.1 == 0.0 { 1 } else { self.pixels })
    }

    /// Check the request against the map.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `setpoint` (in (0, 1)), `temperature` (a PeakForce
    /// image's), `pixels`, `lines` (1..=4096; 1 for a line map) or `curve_points` (8..=2000).
    pub fn validate(&self, map: &SampleMap) -> Result<(), SimError> {
        let why = "must be a ratio A_sp/A0 in (0, 1)";
        let open = (Excluded(0.0), Excluded(1.0));
        crate::error::within("setpoint", self.setpoint, open, why)?;
        if let Some(t) = self.temperature {
            let why = "an AM image's thermal noise is its PI scan's (feedback = pi)";
            return Err(SimError::out_of_range("temperature", t, why));
        }
        self.validate_grid(map)
    }

    /// Check the request's grid against the map (every check of [`ImageRequest::validate`]
    /// but the setpoint's, which a PeakForce image reads as a force).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `pixels`, `lines` (1..=4096; 1 for a line map) or
    /// `curve_points` (8..=2000); [`SimError::Budget`] for an image over `MAX_IMAGE_BYTES`.
    pub fn validate_grid(&self, map: &SampleMap) -> Result<(), SimError> {
        in_range("pixels", self.pixels, 1..=MAX_PIXELS)?;
        let lines = self.lines(map);
        in_range("lines", lines, 1..=MAX_PIXELS)?;
        if map.size.1 == 0.0 && lines != 1 {
            return Err(SimError::out_of_range(
                "lines",
                lines,
                "must be 1 for a line map (size = [Lx, 0])",
            ));
        }
        in_range("curve_points", self.curve_points, 8..=2000)?;
        // the image held in memory with its document: measured 920 B a pixel (RSS of a
        // 512 × 512 blend image, 241 MB), checked before any work
        let bytes = self.pixel_bytes(map);
        if bytes > MAX_IMAGE_BYTES {
            return Err(SimError::Budget {
                what: "image",
                needed: format!(
                    "{} × {lines} pixels at about {IMAGE_BYTES_PER_PIXEL} B each: {:.1} GiB",
                    self.pixels,
                    bytes / super::limits::GIB
                ),
                budget: "1.1 GiB".into(),
                hint: "fewer pixels or lines (up to about 1024 × 1024), or image the area in \
                       parts",
            });
        }
        Ok(())
    }
}

/// Memory of one pixel of an image while it is held and written (its maps, operating point
/// and its share of the JSON document): 920 B measured at 512 × 512 (RSS 241 MB), rounded up.
pub(crate) const IMAGE_BYTES_PER_PIXEL: f64 = 1000.0;

/// The largest memory an image may take, estimated before the run: 1.1 GiB, about the traces'
/// budget of a curve ([`super::limits::MAX_TRACE_BYTES`]), so that 1024 × 1024 pixels fit and
/// 2048 × 2048 (which aborted on allocation) is refused naming the budget.
pub(crate) const MAX_IMAGE_BYTES: f64 = 1.1 * super::limits::GIB;

/// The background probe of an image under the probe file's table `probe_table`.
///
/// # Errors
/// [`SimError::Probe`] for a table the probe format refuses; [`SimError::OutOfRange`] naming
/// `probe` for a multifrequency drive (an image is recorded with one drive frequency).
pub(crate) fn background_probe(probe_table: &toml::Table) -> Result<Probe, SimError> {
    let background =
        Probe::from_table(probe_table, "probe").map_err(|e| SimError::Probe(e.to_string()))?;
    if !background.components.is_empty() {
        return Err(SimError::out_of_range(
            "probe",
            "a multifrequency drive",
            "an image is recorded with one drive frequency",
        ));
    }
    Ok(background)
}

/// What the materials' approach curves of `map` under `background` cost, with `extra` (the
/// pixels' memory, a scan's drive periods, × the modes) added: the cost [`material_curves`]
/// holds against the budgets before the first curve.
///
/// # Errors
/// As the approach curves' cost ([`image_curves_cost`]).
pub(crate) fn curves_cost(
    background: &Probe,
    map: &SampleMap,
    curve_points: usize,
    extra: Cost,
) -> Result<Cost, SimError> {
    let units = CurveUnits::from_scales(&background.scales, false);
    let materials = 1 + map.domains.iter().filter(|d| d.sample.is_some()).count();
    let curves = image_curves_cost(background.params, units.length, curve_points, materials)?;
    Ok(Cost {
        bytes: MODEL_BYTES + curves.bytes + extra.bytes,
        work: curves.work + extra.work * background.params.modes as f64,
    })
}

/// The materials' (name, model) of a sample map, the material of each of its domains, and each
/// material's own probe warnings ([`Probe::warnings`], named by the material: a domain's only
/// where the background's does not say it).
pub(crate) type MaterialModels = (Vec<(String, Params)>, Vec<usize>, Vec<Vec<String>>);

/// The models of `map`'s materials under the probe table `probe_table` (its background
/// `background`): the background, then one per domain with its own sample (name, model: the
/// same lever, drive and units, only the sample differs); the material of each domain.
///
/// # Errors
/// [`SimError::Probe`] for a domain's sample the probe format refuses (named by the domain).
pub(crate) fn material_models(
    probe_table: &toml::Table,
    map: &SampleMap,
    background: &Probe,
) -> Result<MaterialModels, SimError> {
    let mut models = vec![("background".to_string(), background.params)];
    let mut of_domain = Vec::with_capacity(map.domains.len());
    let own = background.warnings();
    let mut warnings = vec![own.iter().map(|w| format!("background: {w}")).collect()];
    for d in &map.domains {
        let Some(sample) = &d.sample else {
            of_domain.push(0);
            continue;
        };
        let mut root = probe_table.clone();
        root.insert("sample".into(), toml::Value::Table(sample.clone()));
        let origin = format!("domain '{}'", d.name);
        let probe =
            Probe::from_table(&root, &origin).map_err(|e| SimError::Probe(e.to_string()))?;
        of_domain.push(models.len());
        models.push((d.name.clone(), probe.params));
        let new = probe.warnings().into_iter().filter(|w| !own.contains(w));
        warnings.push(new.map(|w| format!("{}: {w}", d.name)).collect());
    }
    Ok((models, of_domain, warnings))
}

/// The pixel centres x (m, `[pixels]`) and line positions y (m, `[lines]`) of `req` over `map`:
/// the centres of equal cells of the map's size.
pub(crate) fn pixel_grid(map: &SampleMap, req: &ImageRequest) -> (Vec<f64>, Vec<f64>) {
    let (lx, ly) = map.size;
    let x: Vec<f64> = (0..req.pixels)
        .map(|i| (i as f64 + 0.5) * lx / req.pixels as f64)
        .collect();
    let n_lines = req.lines(map);
    let y: Vec<f64> = (0..n_lines)
        .map(|j| (j as f64 + 0.5) * ly / n_lines as f64)
        .collect();
    (x, y)
}

//! AM-AFM images of a heterogeneous sample (issue 46): a sample map ([`SampleMap`], the
//! `--sample S.toml` of `afmdyn image`) and the image an **ideal** amplitude feedback records
//! over it ([`image`]).
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
//!
//! **Ideal feedback.** A feedback loop infinitely faster than the scan holds the amplitude at
//! the setpoint A_sp = r A₀ at every pixel, so a pixel's operating point is a point of its
//! material's approach curve where A(z_c) = A_sp ([`crate::analysis::setpoint`]), and the z
//! piezo records the true height plus the rest distance z_c there. Which of the material's
//! operating points (in the bistable range one attractive, one repulsive: García & San Paulo,
//! *Phys. Rev. B* 61 (2000) R13381) is the history's: each line is engaged from far, as an
//! instrument engages, on the operating point the approach sweep meets first (its largest z_c);
//! along the line the regime (attractive or repulsive) is kept from pixel to pixel while the new
//! material has an operating point in it, and otherwise the nearest z_c of the other regime is
//! taken and the switch reported. The apparent height is h + z_c − z_c,ref, z_c,ref the engaged
//! rest distance on the background, so a soft domain of the background's true height shows its
//! difference in z_c (García & San Paulo 2000; the height artefacts of Kühle, Sørensen & Bohr,
//! *J. Appl. Phys.* 81 (1997) 6562). The operating points of each material are computed once
//! (an approach curve per material, [`crate::analysis::approach::approach_retract`]), so the
//! image costs one approach curve per material however many pixels it has, and the
//! [`setpoint_study`] (every domain's contrast against the setpoint) as many however many
//! setpoints.

use crate::analysis::approach::approach_retract;
use crate::analysis::setpoint::operating_points;
use crate::analysis::stepped::SteppedSpec;
use crate::error::SimError;
use crate::params::Params;
use crate::probe::Probe;
use crate::report::CurveUnits;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::costs::{check_cost, image_curves_cost, MODEL_BYTES};
use super::curves::{approach_request, CurveRequest};
use super::limits::Cost;

mod sample;
mod study;
pub use study::{setpoint_study, study_ratios, MAX_STUDY_RATIOS};

pub(crate) use crate::report::image::{DomainContrast, SetpointStudy};
pub use crate::report::image::{Image, Material, OperatingPoint, Pixel, Regime};

pub use crate::io::height_map::{MAX_HEIGHT, MAX_PIXELS};

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
        }
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
}

impl ImageRequest {
    /// Check the request against the map.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `setpoint` (in (0, 1)), `pixels`, `lines` (1..=4096;
    /// 1 for a line map) or `curve_points` (8..=2000).
    pub fn validate(&self, map: &SampleMap) -> Result<(), SimError> {
        if !(self.setpoint > 0.0 && self.setpoint < 1.0) {
            return Err(SimError::out_of_range(
                "setpoint",
                crate::error::number(self.setpoint),
                "must be a ratio A_sp/A0 in (0, 1)",
            ));
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
        if !(1..=MAX_PIXELS).contains(&self.pixels) {
            return Err(SimError::out_of_range(
                "pixels",
                self.pixels,
                "must be in 1..=4096",
            ));
        }
        let lines = self.lines(map);
        if !(1..=MAX_PIXELS).contains(&lines) {
            return Err(SimError::out_of_range(
                "lines",
                lines,
                "must be in 1..=4096",
            ));
        }
        if map.size.1 == 0.0 && lines != 1 {
            return Err(SimError::out_of_range(
                "lines",
                lines,
                "must be 1 for a line map (size = [Lx, 0])",
            ));
        }
        if !(8..=2000).contains(&self.curve_points) {
            return Err(SimError::out_of_range(
                "curve_points",
                self.curve_points,
                "must be in 8..=2000",
            ));
        }
        // the image held in memory with its document: measured 920 B a pixel (RSS of a
        // 512 × 512 blend image, 241 MB), checked before any work
        let bytes = self.pixel_bytes(map);
        if bytes > MAX_IMAGE_BYTES {
            return Err(SimError::Budget {
                what: "image",
                needed: format!(
                    "{} × {lines} pixels at about {IMAGE_BYTES_PER_PIXEL} B each: {:.1} GiB",
                    self.pixels,
                    bytes / (1024.0 * 1024.0 * 1024.0)
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
pub(crate) const MAX_IMAGE_BYTES: f64 = 1.1 * 1024.0 * 1024.0 * 1024.0;

/// One material's approach curve: the background or a domain's sample under the probe's lever
/// and drive.
pub(crate) struct MaterialCurve {
    pub(crate) name: String,
    pub(crate) params: Params,
    pub(crate) curve: crate::analysis::stepped::SteppedCurve,
    /// The curve's spec (its operating points are refined with it).
    pub(crate) spec: SteppedSpec,
    /// Its probe's own warnings ([`Probe::warnings`]: a sample outside its law's regime, a
    /// value outside its typical range), named by the material.
    pub(crate) probe_warnings: Vec<String>,
}

/// The approach curve of `params` (`curve_points` z_c values each way over the probe's default
/// range, no branches), and its spec.
fn approach_curve(
    params: Params,
    units: &CurveUnits,
    curve_points: usize,
) -> Result<(SteppedSpec, crate::analysis::stepped::SteppedCurve), SimError> {
    let curve_req = CurveRequest {
        points: Some(curve_points),
        branches: false,
        ..CurveRequest::default()
    };
    let spec = approach_request(params, &curve_req, units.length, false)?;
    let curve = approach_retract(&spec)?;
    Ok((spec, curve))
}

/// The background probe of an image under the probe file's table `probe_table`.
///
/// # Errors
/// [`SimError::Probe`] for a table the probe format refuses; [`SimError::OutOfRange`] naming
/// `probe` for a multifrequency drive (an image is recorded with one drive frequency).
pub(crate) fn background_probe(probe_table: &toml::Table) -> Result<Probe, SimError> {
    let background =
        Probe::from_table(probe_table, "probe").map_err(|e| SimError::Probe(e.to_string()))?;
    if background.components.len() > 1 {
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

/// The materials of `map` under the probe `probe_table`: the background, then one per domain
/// with its own sample, each with its approach curve; the material of each domain; the SI
/// units.
///
/// `extra` is what the caller adds to the curves' cost (the pixels' memory, a scan's drive
/// periods): the whole is held against the budgets of a request ([`check_cost`], named
/// `image`) before the first curve.
pub(crate) fn material_curves(
    probe_table: &toml::Table,
    map: &SampleMap,
    curve_points: usize,
    extra: Cost,
) -> Result<(Vec<MaterialCurve>, Vec<usize>, CurveUnits), SimError> {
    let background = background_probe(probe_table)?;
    let units = CurveUnits::from_scales(&background.scales, false);
    check_cost("image", curves_cost(&background, map, curve_points, extra)?)?;
    let (models, of_domain, warnings) = material_models(probe_table, map, &background)?;
    let materials = models
        .into_iter()
        .zip(warnings)
        .map(|((name, params), probe_warnings)| {
            let (spec, curve) = approach_curve(params, &units, curve_points)?;
            Ok(MaterialCurve {
                name,
                params,
                curve,
                spec,
                probe_warnings,
            })
        })
        .collect::<Result<Vec<_>, SimError>>()?;
    Ok((materials, of_domain, units))
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

/// The warnings of the materials' approach curves, each named by its material.
fn curve_warnings(curves: &[MaterialCurve]) -> Vec<String> {
    curves
        .iter()
        .flat_map(|m| {
            m.curve
                .warnings
                .iter()
                .map(move |w| format!("{} (its approach curve): {w}", m.name))
        })
        .collect()
}

/// The operating points of a material's curve at the setpoint `ratio`, in SI (`units`;
/// [`crate::report::setpoint`]).
fn points_at(
    m: &MaterialCurve,
    ratio: f64,
    units: &CurveUnits,
) -> Result<Vec<OperatingPoint>, SimError> {
    let (points, dropped) = operating_points(&m.spec, &m.curve, ratio)?;
    let doc = crate::report::setpoint(&m.params, &m.curve, (&points, &dropped), ratio, units);
    let num = |p: &Value, k: &str| p[k].as_f64().unwrap_or(f64::NAN);
    Ok(doc["points"]
        .as_array()
        .map(|a| {
            a.iter()
                .map(|p| OperatingPoint {
                    source: p["source"].as_str().unwrap_or("").to_string(),
                    z_c: num(p, "z_c"),
                    regime: if p["regime"] == "attractive" {
                        Regime::Attractive
                    } else {
                        Regime::Repulsive
                    },
                    amplitude: num(p, "amplitude"),
                    phase_deg: num(p, "phase_deg"),
                    energy_dissipated: num(p, "energy_dissipated"),
                    virial: num(p, "virial"),
                    peak_force: num(p, "peak_force"),
                    indentation: num(p, "indentation"),
                })
                .collect()
        })
        .unwrap_or_default())
}

/// The operating point a line engages on: the approach sweep's first (largest z_c), else the
/// largest z_c of any.
fn engage(points: &[OperatingPoint]) -> Option<usize> {
    let best = |approach_only: bool| {
        (0..points.len())
            .filter(|&i| !approach_only || points[i].source == "approach")
            .max_by(|&a, &b| points[a].z_c.total_cmp(&points[b].z_c))
    };
    best(true).or_else(|| best(false))
}

/// The operating point of a material continued from the previous pixel's (regime, z_c): the
/// same regime, nearest z_c; else the nearest z_c of the other regime (switched = true).
fn continue_from(points: &[OperatingPoint], regime: Regime, z_c: f64) -> Option<(usize, bool)> {
    let nearest = |same: bool| {
        (0..points.len())
            .filter(|&i| (points[i].regime == regime) == same)
            .min_by(|&a, &b| {
                (points[a].z_c - z_c)
                    .abs()
                    .total_cmp(&(points[b].z_c - z_c).abs())
            })
    };
    nearest(true)
        .map(|i| (i, false))
        .or_else(|| nearest(false).map(|i| (i, true)))
}

/// The ideal-feedback image of `map` under `probe` (module docs): the operating points of each
/// material, then the scan line by line.
///
/// # Errors
/// As [`ImageRequest::validate`]; [`SimError::Probe`] for a domain's sample the probe format
/// refuses (named by the domain); as the approach curves.
pub fn image(
    probe_table: &toml::Table,
    map: &SampleMap,
    req: &ImageRequest,
) -> Result<Image, SimError> {
    req.validate(map)?;
    let extra = Cost {
        bytes: req.pixel_bytes(map),
        work: 0.0,
    };
    let (curves, of_domain, units) = material_curves(probe_table, map, req.curve_points, extra)?;
    image_of(&curves, &of_domain, &units, map, req)
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

/// [`image`] from the materials' curves ([`material_curves`]).
pub(crate) fn image_of(
    curves: &[MaterialCurve],
    of_domain: &[usize],
    units: &CurveUnits,
    map: &SampleMap,
    req: &ImageRequest,
) -> Result<Image, SimError> {
    let materials: Vec<Material> = curves
        .iter()
        .map(|m| {
            Ok(Material {
                name: m.name.clone(),
                points: points_at(m, req.setpoint, units)?,
                warnings: m.curve.warnings.clone(),
            })
        })
        .collect::<Result<_, SimError>>()?;
    let (x, y) = pixel_grid(map, req);
    // the materials' probe warnings (issue 77: the AM image lacked them), then their approach
    // curves' own (an unsettled point, a failed one), named by material
    let mut warnings: Vec<String> = curves
        .iter()
        .flat_map(|m| m.probe_warnings.clone())
        .collect();
    warnings.extend(curve_warnings(curves));
    for m in &materials {
        if m.points.is_empty() {
            warnings.push(format!(
                "{}: the setpoint A/A0 = {} is not reached on its approach curve: its pixels \
                 are empty (NaN)",
                m.name, req.setpoint
            ));
        }
    }
    let reference = engage(&materials[0].points)
        .map(|i| materials[0].points[i].z_c)
        .unwrap_or(f64::NAN);
    let mut pixels = Vec::with_capacity(y.len());
    let mut switches = 0usize;
    for &yj in &y {
        let mut line = Vec::with_capacity(req.pixels);
        let mut prev: Option<(Regime, f64)> = None;
        for &xi in &x {
            let d = map.domain_at(xi, yj);
            let material = d.map_or(0, |k| of_domain[k]);
            let height = map.height_at(xi, yj);
            let pts = &materials[material].points;
            let (point, switched) = match prev {
                None => (engage(pts), false),
                Some((regime, z)) => match continue_from(pts, regime, z) {
                    Some((i, s)) => (Some(i), s),
                    None => (None, false),
                },
            };
            if let Some(i) = point {
                prev = Some((pts[i].regime, pts[i].z_c));
            }
            switches += usize::from(switched);
            line.push(Pixel {
                domain: d,
                material,
                height,
                point,
                switched,
            });
        }
        pixels.push(line);
    }
    if switches > 0 {
        warnings.push(format!(
            "{switches} pixel(s) switch regime (attractive ↔ repulsive) where a material has no \
             operating point in the previous one's: the image's contrast changes there"
        ));
    }
    Ok(Image {
        x,
        y,
        materials,
        pixels,
        reference,
        domain_names: map.domains.iter().map(|d| d.name.clone()).collect(),
        warnings,
    })
}

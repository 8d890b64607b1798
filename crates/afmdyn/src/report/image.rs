//! The results of the images ([`crate::request::image`]): the ideal-feedback image
//! ([`Image`]), the PI scan ([`PiImage`]), the PeakForce image ([`PeakForceImage`]) and the
//! setpoint study ([`SetpointStudy`]), with the maps each reports (`FIELDS`, `SCAN_FIELDS`,
//! `PF_FIELDS`) and their documents: what the presentations of the images read
//! ([`crate::report::present::image`] and the images' layouts).

use crate::analysis::am_loop::{ScanLine, ScanPixel};
use crate::layout::columns::{self, columns, Column};
use crate::report::CurveUnits;
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

/// The `[line][pixel]` array of `f(line, pixel)` over a grid of `shape` (lines, pixels).
fn grid(shape: (usize, usize), f: &dyn Fn(usize, usize) -> Value) -> Value {
    let line = |j| Value::Array((0..shape.1).map(|i| f(j, i)).collect());
    Value::Array((0..shape.0).map(line).collect())
}

/// `v` as a JSON number, `null` where it is not finite.
fn finite(v: f64) -> Value {
    if v.is_finite() {
        json!(v)
    } else {
        Value::Null
    }
}

/// Regime of an operating point (García & San Paulo 2000): the mean tip–sample force is
/// attractive (negative) or repulsive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Regime {
    /// Net attractive force.
    Attractive,
    /// Net repulsive force.
    Repulsive,
}

/// One operating point of a material at the setpoint, in SI: the rest distance and the
/// observables interpolated there (`crate::report::setpoint`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OperatingPoint {
    /// `approach` or `retract`: the sweep it lies on.
    pub source: String,
    /// Rest distance z_c (m).
    pub z_c: f64,
    /// Regime.
    pub regime: Regime,
    /// Amplitude (m).
    pub amplitude: f64,
    /// Phase lag (degrees).
    pub phase_deg: f64,
    /// Energy dissipated per drive period (J).
    pub energy_dissipated: f64,
    /// Virial (J).
    pub virial: f64,
    /// Peak force (N).
    pub peak_force: f64,
    /// Indentation (m).
    pub indentation: f64,
}

/// A material of the image: the background or a domain's sample, with its operating points.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Material {
    /// `background` or the domain's name.
    pub name: String,
    /// Its operating points at the setpoint (none: the setpoint is not reached on it).
    pub points: Vec<OperatingPoint>,
    /// The warnings of its approach curve.
    pub warnings: Vec<String>,
}

/// A pixel: its domain, material and operating point (`None`: the setpoint is not reached
/// there).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pixel {
    /// Index into the map's domains, `None` for the background.
    pub domain: Option<usize>,
    /// Index into [`Image::materials`].
    pub material: usize,
    /// True height (m).
    pub height: f64,
    /// Index into the material's points.
    pub point: Option<usize>,
    /// Whether the regime changed at this pixel because the material had no operating point
    /// in the previous one.
    pub switched: bool,
}

/// An ideal-feedback image (of a [`crate::request::image::SampleMap`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    /// Pixel centres x (m).
    pub x: Vec<f64>,
    /// Line positions y (m).
    pub y: Vec<f64>,
    /// The materials: 0 the background, then one per domain with its own sample.
    pub materials: Vec<Material>,
    /// The pixels, `[line][pixel]`.
    pub pixels: Vec<Vec<Pixel>>,
    /// z_c,ref (m): the engaged rest distance on the background, the zero of the apparent
    /// height.
    pub reference: f64,
    /// The map's domain names, in its order.
    pub domain_names: Vec<String>,
    /// What the image cannot show as asked.
    pub warnings: Vec<String>,
}

/// A pixel of an image: (line, pixel).
pub(crate) type Cell = (usize, usize);

/// The numeric maps of an image over (y, x), in SI (NaN, `null` in the document, where the
/// setpoint is not reached): the document's `image` block ([`Image::document`]) and the
/// variables of its layout (`image.nc`, Python's Dataset), in this order.
pub(crate) const FIELDS: [Column<Image, Cell>; 9] = columns! {
    "height", Length, false, "apparent height h + z_c − z_c,ref (ideal feedback)",
        F64(|g, &(j, i)| g.apparent_height(j, i));
    "true_height", Length, false, "true height of the sample map",
        F64(|g, &(j, i)| g.pixels[j][i].height);
    "z_c", Length, false, "rest distance z_c the feedback holds",
        Opt(|g, &(j, i)| Some(g.point(j, i)?.z_c));
    "amplitude", Length, false, "amplitude (the setpoint where reached)",
        Opt(|g, &(j, i)| Some(g.point(j, i)?.amplitude));
    "phase_deg", Fixed("degree"), false, "phase lag behind the drive",
        Opt(|g, &(j, i)| Some(g.point(j, i)?.phase_deg));
    "energy_dissipated", Energy, false, "energy dissipated per drive period",
        Opt(|g, &(j, i)| Some(g.point(j, i)?.energy_dissipated));
    "virial", Energy, false, "virial of the tip–sample force",
        Opt(|g, &(j, i)| Some(g.point(j, i)?.virial));
    "peak_force", Force, false, "largest tip–sample force",
        Opt(|g, &(j, i)| Some(g.point(j, i)?.peak_force));
    "indentation", Length, false, "largest indentation",
        Opt(|g, &(j, i)| Some(g.point(j, i)?.indentation));
};

impl Image {
    /// The operating point of pixel (line, pixel), `None` where the setpoint is not reached.
    pub fn point(&self, line: usize, pixel: usize) -> Option<&OperatingPoint> {
        let p = &self.pixels[line][pixel];
        p.point.map(|i| &self.materials[p.material].points[i])
    }

    /// Apparent height of a pixel (m): h + z_c − z_c,ref (NaN where not reached).
    pub(crate) fn apparent_height(&self, line: usize, pixel: usize) -> f64 {
        let p = &self.pixels[line][pixel];
        self.point(line, pixel)
            .map_or(f64::NAN, |o| p.height + o.z_c - self.reference)
    }

    /// The image document (`afmdyn image --json`): `image` with `x`, `y` (m) and per
    /// `[line][pixel]` the `FIELDS` (null where not reached), `regime`, `material` and
    /// `domain` (their names); `materials` with their operating points; `reference_z_c` (m),
    /// `setpoint`, `warnings`.
    pub fn document(&self, setpoint: f64) -> Value {
        let shape = (self.y.len(), self.x.len());
        let mut image = columns::grids(&FIELDS, self, &columns::cells(shape), shape);
        image.insert("x".into(), serde_json::json!(self.x));
        image.insert("y".into(), serde_json::json!(self.y));
        let regime = grid(shape, &|j, i| {
            self.point(j, i)
                .map_or(Value::Null, |o| serde_json::json!(o.regime))
        });
        image.insert("regime".into(), regime);
        let material = grid(shape, &|j, i| {
            serde_json::json!(self.materials[self.pixels[j][i].material].name)
        });
        image.insert("material".into(), material);
        let domain = grid(shape, &|j, i| {
            serde_json::json!(self.pixels[j][i]
                .domain
                .map_or("background", |k| { self.domain_names[k].as_str() }))
        });
        image.insert("domain".into(), domain);
        serde_json::json!({
            "image": image,
            "feedback": "ideal",
            "setpoint": setpoint,
            "reference_z_c": finite(self.reference),
            "materials": self.materials,
            "warnings": self.warnings,
        })
    }
}

/// The settings a scan ran with (SI), as its document reports them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ScanSettings {
    /// Scan rate (Hz).
    pub scan_rate: f64,
    /// K_P (dimensionless).
    pub proportional_gain: f64,
    /// K_I (1/s).
    pub integral_gain: f64,
    /// Lock-in time constant (s).
    pub time_constant: f64,
    /// Drive periods per pixel.
    pub periods_per_pixel: usize,
    /// Drive periods of each line's engage.
    pub engage_periods: usize,
    /// Lock-in samples per drive period.
    pub lock_in_samples: usize,
    /// Duration of a pixel (s).
    pub pixel_time: f64,
    /// τ_c = 2Q/ω₀ (s): the lever's amplitude time constant.
    pub amplitude_time: f64,
    /// The temperature of the thermal force (K); absent without one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature: Option<f64>,
    /// The seed of the thermal force; absent without a temperature.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
}

/// One direction's artefacts of a PI scan ([`crate::request::image_scan`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Artefacts {
    /// RMS of recorded − ideal height over the pixels where both exist (m).
    pub height_rms_error: f64,
    /// Largest |recorded − ideal height| (m).
    pub height_max_error: f64,
    /// Largest overshoot beyond the ideal heights of a pixel and its neighbours (m).
    pub overshoot: f64,
    /// RMS of the error image A_sp − A (m).
    pub tracking_error_rms: f64,
    /// Pixels that lost contact.
    pub lost_contact_pixels: usize,
    /// Drive periods at the controller's output limit.
    pub saturated_periods: usize,
    /// The largest per-mode energy-balance residual of a pixel's last period, relative to the
    /// drive's work ([`ScanPixel::energy_residual`]); NaN (null in JSON) under a thermal force.
    pub energy_residual_max: f64,
}

/// A scanned image: the ideal image of the same map, the lines, the settings.
#[derive(Debug, Clone, PartialEq)]
pub struct PiImage {
    /// The ideal-feedback image (its materials, reference and geometry).
    pub ideal: Image,
    /// The lines in order.
    pub lines: Vec<ScanLine>,
    /// The settings.
    pub settings: ScanSettings,
    /// SI factors.
    pub(crate) units: CurveUnits,
    /// [trace, retrace].
    pub artefacts: [Artefacts; 2],
    /// The ideal image's warnings and the scan's.
    pub warnings: Vec<String>,
}

/// A pixel of a PI scan: (direction: 0 the trace, 1 the retrace; line; pixel).
pub(crate) type ScanCell = (usize, usize, usize);

/// The recorded maps of a PI scan over (y, x) in SI, each direction's: the document's `image`
/// and `retrace` blocks ([`PiImage::document`]) and the variables of its layout (the
/// retrace's suffixed `_retrace`), in this order.
pub(crate) const SCAN_FIELDS: [Column<PiImage, ScanCell>; 9] = columns! {
    "height", Length, false,
        "recorded height: the mean piezo position less the ideal reference z_c,ref",
        F64(|g, &(d, j, i)| g.height(d, j, i));
    "amplitude", Length, false, "mean lock-in amplitude",
        F64(|g, &(d, j, i)| g.row(d, j)[i].amplitude * g.units.length);
    "phase_deg", Fixed("degree"), false, "mean lock-in phase lag behind the drive",
        F64(|g, &(d, j, i)| g.row(d, j)[i].phase.to_degrees());
    "tracking_error", Length, false, "mean amplitude error A_sp − A (the error image)",
        F64(|g, &(d, j, i)| g.row(d, j)[i].tracking_error * g.units.length);
    "energy_dissipated", Energy, false, "energy dissipated over the pixel's last drive period",
        F64(|g, &(d, j, i)| g.row(d, j)[i].energy_dissipated * g.units.energy);
    "virial", Energy, false, "virial over the pixel's last drive period",
        F64(|g, &(d, j, i)| g.row(d, j)[i].virial * g.units.energy);
    "peak_force", Force, false, "largest tip–sample force over the pixel's last drive period",
        F64(|g, &(d, j, i)| g.row(d, j)[i].peak_force * g.units.force);
    "indentation", Length, false, "largest indentation over the pixel's last drive period",
        F64(|g, &(d, j, i)| g.row(d, j)[i].indentation * g.units.length);
    "lost_contact", Fixed("1"), false,
        "the controller lost contact (parachuting) in the pixel's last drive period",
        Bool(|g, &(d, j, i)| g.row(d, j)[i].lost_contact);
};

/// The cells of direction `d` of a scan of `shape` (lines, pixels), line by line.
pub(crate) fn scan_cells(d: usize, shape: (usize, usize)) -> Vec<ScanCell> {
    let cells = crate::layout::columns::cells(shape).into_iter();
    cells.map(|(j, i)| (d, j, i)).collect()
}

impl PiImage {
    /// Metres per model length unit g₀ (the records' lengths).
    pub(crate) fn length(&self) -> f64 {
        self.units.length
    }

    /// Newtons per model force unit (the records' forces).
    pub fn force(&self) -> f64 {
        self.units.force
    }

    /// Joules per model energy unit (the records' energies).
    pub fn energy(&self) -> f64 {
        self.units.energy
    }

    /// The pixels of direction `d` (0 trace, 1 retrace) of line `j`.
    fn row(&self, d: usize, j: usize) -> &[ScanPixel] {
        if d == 0 {
            &self.lines[j].trace
        } else {
            &self.lines[j].retrace
        }
    }

    /// Recorded height (m) of pixel (j, i) in direction `d`: the mean piezo position less the
    /// ideal image's reference.
    pub(crate) fn height(&self, d: usize, j: usize, i: usize) -> f64 {
        self.row(d, j)[i].z * self.units.length - self.ideal.reference
    }

    /// The artefacts of direction `d` (0 trace, 1 retrace) against the ideal image.
    pub(crate) fn artefacts_of(&self, d: usize) -> Artefacts {
        let (mut sq, mut n, mut worst, mut over, mut err_sq, mut lost, mut sat) =
            (0.0, 0usize, 0.0f64, 0.0f64, 0.0, 0, 0);
        let mut residual = 0.0f64;
        let px = self.ideal.x.len();
        for j in 0..self.lines.len() {
            for i in 0..px {
                let p = &self.row(d, j)[i];
                let e = p.tracking_error * self.units.length;
                err_sq += e * e;
                lost += usize::from(p.lost_contact);
                sat += p.saturated;
                residual = residual.max(p.energy_residual);
                let h = self.height(d, j, i);
                let ideal = self.ideal.apparent_height(j, i);
                if !ideal.is_finite() {
                    continue;
                }
                sq += (h - ideal).powi(2);
                n += 1;
                worst = worst.max((h - ideal).abs());
                // the ideal heights around it (a neighbour without one: no overshoot measured)
                let around: Vec<f64> = (i.saturating_sub(1)..(i + 2).min(px))
                    .map(|k| self.ideal.apparent_height(j, k))
                    .collect();
                if around.iter().all(|v| v.is_finite()) {
                    let hi = around.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                    let lo = around.iter().copied().fold(f64::INFINITY, f64::min);
                    over = over.max(h - hi).max(lo - h);
                }
            }
        }
        let all = (self.lines.len() * px) as f64;
        Artefacts {
            height_rms_error: if n > 0 {
                (sq / n as f64).sqrt()
            } else {
                f64::NAN
            },
            height_max_error: if n > 0 { worst } else { f64::NAN },
            overshoot: if n > 0 { over } else { f64::NAN },
            tracking_error_rms: (err_sq / all).sqrt(),
            lost_contact_pixels: lost,
            saturated_periods: sat,
            energy_residual_max: match self.settings.temperature {
                Some(_) => f64::NAN,
                None => residual,
            },
        }
    }

    /// The image document of `afmdyn image --feedback pi --json` (SI): `image` with `x`, `y`
    /// (m) and per `[line][pixel]` the trace's `height` (m, recorded: the mean piezo position
    /// less the ideal reference), `ideal_height` (m, the ideal image's apparent height),
    /// `true_height` (m), `amplitude` (m), `phase_deg`, `tracking_error` (m, A_sp − A),
    /// `energy_dissipated` (J), `virial` (J), `peak_force` (N), `indentation` (m), `regime`,
    /// `lost_contact`, `material` and `domain`; `retrace` with the same recorded fields;
    /// `scan` (the [`ScanSettings`]), `artefacts` (`trace`, `retrace`: [`Artefacts`]),
    /// `materials`, `reference_z_c` (m), `setpoint`, `warnings`.
    pub fn document(&self, setpoint: f64) -> Value {
        let ideal = self.ideal.document(setpoint);
        let (ny, nx) = (self.lines.len(), self.ideal.x.len());
        let grid = |d: usize, f: &dyn Fn(&ScanPixel) -> Value| -> Value {
            let line = |j| Value::Array(self.row(d, j).iter().take(nx).map(f).collect());
            Value::Array((0..ny).map(line).collect())
        };
        let recorded = |d: usize| {
            let mut m = columns::grids(&SCAN_FIELDS, self, &scan_cells(d, (ny, nx)), (ny, nx));
            let regime = grid(d, &|p| json!(crate::report::regime(p.mean_deflection)));
            m.insert("regime".into(), regime);
            let material = grid(d, &|p| json!(self.ideal.materials[p.material].name));
            m.insert("material".into(), material);
            m
        };
        let mut image = recorded(0);
        let m = &mut image;
        m.insert("x".into(), json!(self.ideal.x));
        m.insert("y".into(), json!(self.ideal.y));
        m.insert("ideal_height".into(), ideal["image"]["height"].clone());
        m.insert("true_height".into(), ideal["image"]["true_height"].clone());
        m.insert("domain".into(), ideal["image"]["domain"].clone());
        m.insert("retrace".into(), Value::Object(recorded(1)));
        json!({
            "image": image,
            "feedback": "pi",
            "scan": self.settings,
            "artefacts": {"trace": self.artefacts[0], "retrace": self.artefacts[1]},
            "setpoint": setpoint,
            "reference_z_c": ideal["reference_z_c"],
            "materials": ideal["materials"],
            "warnings": self.warnings,
        })
    }
}

/// A pixel's operating point in SI: the steady tap at the setpoint and its channels.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PeakForceTap {
    /// Mean rest separation z_c the feedback holds (m).
    pub z_c: f64,
    /// Peak force (N): the setpoint to the feedback's tolerance.
    pub peak_force: f64,
    /// Adhesion, the most negative force (N, ≤ 0).
    pub adhesion: f64,
    /// Deformation, the largest indentation (m).
    pub deformation: f64,
    /// Tip–sample dissipation per modulation period (J).
    pub dissipation: f64,
    /// The DMT fit's reduced modulus E* (Pa; NaN where no fit or no tip radius).
    pub modulus_dmt: f64,
    /// Contacts per modulation period (1: a single tap; more: double taps).
    pub taps_per_cycle: f64,
    /// Modulation periods after which the orbit repeats (2: period-2 tapping).
    pub period: usize,
    /// Whether the orbit is stable (every Floquet multiplier inside the unit circle).
    pub stable: bool,
    /// With a temperature, the noise of its material's tap at the setpoint from cycle to cycle
    /// (σ in N and m; [`crate::analysis::peakforce::tap_noise`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise: Option<crate::analysis::peakforce::TapNoise>,
}

/// One pixel of a line as its task computes it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LinePixel {
    /// The operating point (`None`: the setpoint is not reached on the pixel's material).
    pub tap: Option<PeakForceTap>,
    /// Steady taps computed for this pixel (0 where the previous pixel's orbit is kept or the
    /// material's engage is taken).
    pub evaluations: usize,
    /// Whether the continuation failed here and the pixel was re-engaged from far.
    pub reengaged: bool,
}

/// A material of a [`PeakForceImage`] as its document reports it (SI).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PfMaterialReport {
    /// `background` or the domain's name.
    pub name: String,
    /// The sample's true reduced modulus E* (Pa; NaN without a tip radius).
    pub true_modulus: f64,
    /// The operating point a line engages on from far (`None`: the setpoint is not reached).
    pub engaged: Option<PeakForceTap>,
    /// Why the setpoint is not reached (`None` when it is).
    pub message: Option<String>,
    /// Steady taps of its engage's search.
    pub evaluations: usize,
}

/// A PeakForce image ([`crate::request::image_peakforce`]).
#[derive(Debug, Clone, PartialEq)]
pub struct PeakForceImage {
    /// Pixel centres x (m).
    pub x: Vec<f64>,
    /// Line positions y (m).
    pub y: Vec<f64>,
    /// The setpoint: the peak force the feedback holds (N).
    pub setpoint: f64,
    /// The temperature of the noise maps (K; `None`: no noise).
    pub temperature: Option<f64>,
    /// The materials: 0 the background, then one per domain with its own sample.
    pub materials: Vec<PfMaterialReport>,
    /// The pixels' material (index into `materials`), `[line][pixel]`.
    pub material: Vec<Vec<usize>>,
    /// The pixels' domain (`None` the background), `[line][pixel]`.
    pub domain: Vec<Vec<Option<usize>>>,
    /// The true height (m), `[line][pixel]`.
    pub true_height: Vec<Vec<f64>>,
    /// The pixels, `[line][pixel]`.
    pub pixels: Vec<Vec<LinePixel>>,
    /// z_c,ref (m): the background's engaged z_c, the zero of the apparent height (NaN where
    /// the background does not reach the setpoint).
    pub reference: f64,
    /// The map's domain names, in its order.
    pub domain_names: Vec<String>,
    /// What the image cannot show as asked.
    pub warnings: Vec<String>,
}

/// The numeric maps of a PeakForce image over (y, x), in SI (NaN, `null` in the document,
/// where the setpoint is not reached): its document's `image` block and the variables of
/// `image.nc`, in this order; the last two, the noise maps, with a temperature only
/// ([`PeakForceImage::fields`]).
pub(crate) const PF_FIELDS: [Column<PeakForceImage, Cell>; 11] = columns! {
    "height", Length, false, "apparent height h + z_c − z_c,ref (ideal peak-force feedback)",
        Opt(|g, &(j, i)| Some(g.true_height[j][i] + g.tap(j, i)?.z_c - g.reference));
    "true_height", Length, false, "true height of the sample map",
        F64(|g, &(j, i)| g.true_height[j][i]);
    "z_c", Length, false, "mean rest separation z_c the feedback holds",
        Opt(|g, &(j, i)| Some(g.tap(j, i)?.z_c));
    "peak_force", Force, false, "peak force (the setpoint where reached)",
        Opt(|g, &(j, i)| Some(g.tap(j, i)?.peak_force));
    "modulus_dmt", Fixed("Pa"), false, "reduced modulus E* of the DMT fit of the retract curve (PF-QNM)",
        Opt(|g, &(j, i)| Some(g.tap(j, i)?.modulus_dmt));
    "adhesion", Force, false, "adhesion: the most negative tip–sample force",
        Opt(|g, &(j, i)| Some(g.tap(j, i)?.adhesion));
    "deformation", Length, false, "deformation: the largest indentation",
        Opt(|g, &(j, i)| Some(g.tap(j, i)?.deformation));
    "dissipation", Energy, false, "tip–sample dissipation per modulation period",
        Opt(|g, &(j, i)| Some(g.tap(j, i)?.dissipation));
    "taps_per_cycle", Fixed("1"), false, "contacts per modulation period",
        Opt(|g, &(j, i)| Some(g.tap(j, i)?.taps_per_cycle));
    "peak_force_noise", Force, false, "peak force's thermal noise per cycle (σ)",
        Opt(|g, &(j, i)| Some(g.tap(j, i)?.noise?.peak_force));
    "deformation_noise", Length, false, "deformation's thermal noise per cycle (σ)",
        Opt(|g, &(j, i)| Some(g.tap(j, i)?.noise?.deformation));
};

impl PeakForceImage {
    /// The image's maps: [`PF_FIELDS`], the noise maps with a temperature only.
    pub(crate) fn fields(&self) -> &'static [Column<PeakForceImage, Cell>] {
        &PF_FIELDS[..if self.temperature.is_some() { 11 } else { 9 }]
    }

    /// The operating point of pixel (line, pixel), `None` where the setpoint is not reached.
    pub(crate) fn tap(&self, line: usize, pixel: usize) -> Option<&PeakForceTap> {
        self.pixels[line][pixel].tap.as_ref()
    }

    /// The value of the map `name` (`PF_FIELDS`) at (line, pixel) (NaN where not reached or
    /// an unknown name).
    pub fn value(&self, name: &str, line: usize, pixel: usize) -> f64 {
        let field = self.fields().iter().find(|c| c.name == name);
        field.map_or(f64::NAN, |c| c.number(self, &(line, pixel)))
    }

    /// The image document (`afmdyn image --mode peakforce --json`): `image` with `x`, `y` (m)
    /// and per `[line][pixel]` the `PF_FIELDS` (SI; null where not reached), `evaluations`,
    /// `material` and `domain` (names); `mode` `"peakforce"`, `feedback` `"ideal"`, `setpoint`
    /// (N), `reference_z_c` (m), `materials` (each with its true modulus and engaged operating
    /// point), `taps` (steady taps computed), `warnings`.
    pub fn document(&self) -> Value {
        use serde_json::json;
        let shape = (self.y.len(), self.x.len());
        let mut image = columns::grids(self.fields(), self, &columns::cells(shape), shape);
        image.insert("x".into(), json!(self.x));
        image.insert("y".into(), json!(self.y));
        image.insert(
            "evaluations".into(),
            grid(shape, &|j, i| json!(self.pixels[j][i].evaluations)),
        );
        image.insert(
            "material".into(),
            grid(shape, &|j, i| {
                json!(self.materials[self.material[j][i]].name)
            }),
        );
        image.insert(
            "domain".into(),
            grid(shape, &|j, i| {
                json!(self.domain[j][i].map_or("background", |k| self.domain_names[k].as_str()))
            }),
        );
        let mut doc = self.document_head();
        doc["image"] = Value::Object(image);
        doc
    }

    /// The document's keys other than `image` ([`PeakForceImage::document`]): `mode`,
    /// `feedback`, `setpoint` (N), `reference_z_c` (m), `materials` (name, true modulus, the
    /// engaged operating point or why not, the engage's taps `evaluations`), `taps`, `warnings`,
    /// `thermal` (with a temperature: it and the noise maps' method).
    pub(crate) fn document_head(&self) -> Value {
        use serde_json::json;
        let mut doc = json!({
            "mode": "peakforce",
            "feedback": "ideal",
            "setpoint": self.setpoint,
            "reference_z_c": finite(self.reference),
            "materials": self.materials.iter().map(|m| json!({
                "name": m.name,
                "true_modulus": finite(m.true_modulus),
                "engaged": m.engaged,
                "message": m.message,
                "evaluations": m.evaluations,
            })).collect::<Vec<_>>(),
            "taps": self.taps(),
            "warnings": self.warnings,
        });
        if let Some(t) = self.temperature {
            doc["thermal"] = json!({
                "temperature": t,
                "method": "each pixel's σ of the peak force and the deformation from cycle to cycle: its material's steady tap at the setpoint under the fluctuation–dissipation theorem's thermal force on the lever and its medium, by linear response about the tap, the pixels of a material sharing its operating point (crate::analysis::peakforce::tap_noise)",
            });
        }
        doc
    }

    /// Steady taps computed for the image: the materials' engages and the lines' continuations.
    pub(crate) fn taps(&self) -> usize {
        self.materials.iter().map(|m| m.evaluations).sum::<usize>()
            + self
                .pixels
                .iter()
                .flatten()
                .map(|p| p.evaluations)
                .sum::<usize>()
    }
}

/// The apparent height and phase of every domain against the setpoint (issue 46's setpoint
/// study: the contrast inversion of AM-AFM, García & San Paulo 2000): at each ratio a line
/// engaged on the background (the ideal-feedback image's rule) crosses onto each domain, whose operating point
/// is the one the regime rule takes there. The materials' approach curves are computed once
/// for all ratios.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SetpointStudy {
    /// The setpoint ratios A_sp/A₀.
    pub ratio: Vec<f64>,
    /// The background first, then every domain of the map.
    pub domains: Vec<DomainContrast>,
    /// The materials' approach curves' warnings, named by material.
    pub warnings: Vec<String>,
}

/// One domain's series of a [`SetpointStudy`]: per ratio its apparent height (m), phase lag
/// (degrees) and regime, `None`/NaN where its material has no operating point there.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DomainContrast {
    /// `background` or the domain's name.
    pub name: String,
    /// Apparent height h + z_c − z_c,ref (m).
    pub apparent_height: Vec<f64>,
    /// Phase lag (degrees).
    pub phase_deg: Vec<f64>,
    /// Energy dissipated per period (J).
    pub energy_dissipated: Vec<f64>,
    /// Regime.
    pub regime: Vec<Option<Regime>>,
}

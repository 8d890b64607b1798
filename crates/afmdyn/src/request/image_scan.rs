//! The time-domain scan of `afmdyn image --feedback pi` (issue 46): the lines of an image
//! scanned by the cantilever under a lock-in and a PI z controller
//! ([`crate::analysis::am_loop`]), trace and retrace, beside the ideal-feedback image of the same
//! map ([`super::image`]) so that the tracking error and the artefacts — lag behind a step,
//! overshoot, loss of contact ("parachuting") — are measured against the exact operating points.
//!
//! **An image is a study** ([`ScanStudy`], [`crate::study::Study`]): its tasks are its lines,
//! each engaged from far on its first pixel's material (the steady state of the approach curve's
//! farthest point; the controller brings the tip down to the setpoint for
//! `ENGAGE_LOOP_TIMES` loop time constants 1/K_I), then scanned from x = 0 to Lx (trace) and
//! back (retrace) at the scan rate. Every line depends only on the request and its number, so
//! the image does not depend on the thread count or on the executor (the rayon pool, Dask).
//!
//! **Units.** A request is in SI: the scan rate in Hz (lines per second, each a trace and a
//! retrace, as instruments count it), K_P dimensionless (m of z per m of amplitude error), K_I
//! in 1/s (m/s of z per m of error), the lock-in's time constant in s. The defaults derive from
//! the lever (`crate::analysis::am_loop::FeedbackGains::for_lever`): τ_c = 2Q/ω₀, the
//! lock-in's time constant τ_c/4, K_I = 1/(4(τ_c + τ_L)), K_P = 0, and a pixel lasting
//! [`PIXEL_LOOP_TIMES`] loop time constants 1/K_I (RTESPA-300, Q = 400 at 300 kHz, 64 pixels:
//! 0.74 Hz).
//!
//! **Records.** Per pixel and direction ([`crate::analysis::am_loop::ScanPixel`]): the mean piezo
//! position over the pixel's drive periods (the height image: the piezo position less the
//! ideal image's reference z_c,ref, so that a perfect controller records the ideal image's
//! apparent height), the mean lock-in amplitude and phase, the mean error A_sp − A (the error
//! image), and E_dis, virial, peak force and indentation over the pixel's last drive period
//! (`crate::analysis::observables::observe`).
//!
//! **Artefacts** ([`Artefacts`], per direction): the RMS and largest difference of the recorded
//! height from the ideal image's apparent height; the overshoot, how far a recorded height goes
//! beyond the ideal heights of its pixel and its two neighbours (a lag stays between them; an
//! overshoot does not; pixels beside one without an ideal height are left out); the pixels that
//! lost contact; the periods at the controller's output limit (an unstable loop); the largest
//! energy-balance residual of a pixel's last period.

use super::image::{image_of, material_curves, Image, ImageRequest, SampleMap};
use crate::analysis::am_loop::{
    engage_position, scan_line, Engage, FeedbackGains, LineSpec, ScanLine, ScanPixel,
    LOCK_IN_SAMPLES,
};
use crate::analysis::approach::rest_distance;
use crate::error::{number, SimError};
use crate::integrate::IntegratorOptions;
use crate::layout::columns::{self, columns, Column};
use crate::probe::Probe;
use crate::report::CurveUnits;
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use std::sync::atomic::AtomicBool;

/// Most drive periods a scan may integrate (lines × (engage + 2 × pixels × periods per pixel)).
pub(crate) const MAX_SCAN_PERIODS: u64 = 1_000_000_000;

/// Loop time constants 1/K_I of a line's engage.
pub(crate) const ENGAGE_LOOP_TIMES: f64 = 20.0;

/// Loop time constants 1/K_I a pixel lasts at the default scan rate.
pub const PIXEL_LOOP_TIMES: f64 = 5.0;

/// The PI scan's settings as a front end takes them (SI; `None`: the lever's default, module
/// docs).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(default, deny_unknown_fields)]
pub struct PiScan {
    /// Scan rate (Hz): lines (trace and retrace) per second; `None`: a pixel lasts
    /// [`PIXEL_LOOP_TIMES`] loop time constants 1/K_I.
    #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "frequency")))]
    #[cfg_attr(
        feature = "schema",
        schemars(extend("x-constants" = { "PIXEL_LOOP_TIMES": PIXEL_LOOP_TIMES }))
    )]
    pub scan_rate: Option<f64>,
    /// The gains (K_P, K_I): K_P ≥ 0 (m/m), K_I > 0 (1/s); `None`: K_P = 0,
    /// K_I = 1/(4(τ_c + τ_L)), τ_c = 2Q/ω₀ the lever's amplitude time constant and τ_L the
    /// lock-in's.
    pub gains: Option<(f64, f64)>,
    /// The lock-in's low-pass time constant (s), ≥ 0 and at most 1 000 s (its physical range,
    /// section `feedback`; [`crate::probe::ranges`]); outside 1 µs–0.1 s the image warns of a
    /// likely unit slip. `None`: τ_c/4.
    pub time_constant: Option<f64>,
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
}

/// One direction's artefacts ([module docs](self)).
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
    /// drive's work ([`ScanPixel::energy_residual`]).
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
    units: CurveUnits,
    /// [trace, retrace].
    pub artefacts: [Artefacts; 2],
    /// The ideal image's warnings and the scan's.
    pub warnings: Vec<String>,
}

/// What rebuilds a [`ScanStudy`] in any process (a Dask worker): the probe's table, the
/// sample map (height maps read already), the request and the settings as given.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScanRecipe {
    /// The probe file's table.
    pub probe: toml::Table,
    /// The sample map.
    pub map: SampleMap,
    /// The image request.
    pub request: ImageRequest,
    /// The PI settings as given (`None`: the lever's defaults).
    pub scan: PiScan,
}

/// The study of a PI scan: one task per line ([module docs](self)).
pub struct ScanStudy {
    pub(crate) fingerprint: Value,
    recipe: ScanRecipe,
    ideal: Image,
    /// What a line needs (the start of a distributed scan's stage, [`ScanStudy::line_job`]).
    job: LineJob,
    units: CurveUnits,
    settings: ScanSettings,
}

/// What scanning one line of a PI image needs ([`ScanStudy::line_job`]): the line's
/// settings, each material's engage, the sample map and the lines' y positions (model units
/// as [`LineSpec`]; `length` is g₀ in m). Its lines are those of the study it came from, bit
/// for bit, wherever it is sent (serde: every number as its bits).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct LineJob {
    spec: LineSpec,
    /// Per material: where a line starting on it engages.
    engage: Vec<Engage>,
    map: SampleMap,
    /// The material of each of the map's domains.
    of_domain: Vec<usize>,
    /// The lines' y positions (m), shape `[lines]`.
    y: Vec<f64>,
    /// g₀ (m).
    length: f64,
    pixels: usize,
}

impl LineJob {
    /// The number of lines.
    pub fn lines(&self) -> usize {
        self.y.len()
    }

    /// Scan line `t` (trace and retrace).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `line` beyond the image; as
    /// [`crate::analysis::am_loop::scan_line`].
    pub fn line(&self, t: usize, cancel: &AtomicBool) -> Result<ScanLine, SimError> {
        if t >= self.lines() {
            return Err(SimError::out_of_range(
                "line",
                format!("{t} (of {} lines)", self.lines()),
                "must be a line of the image",
            ));
        }
        let y = self.y[t];
        let map = &self.map;
        let (lx, g0) = (map.size.0, self.length);
        let dx = lx / self.pixels as f64;
        let under_tip = |s: f64| {
            // a position on an edge belongs to the pixel it begins
            let x = (s * dx).clamp(0.0, lx);
            let m = map.domain_at(x, y).map_or(0, |k| self.of_domain[k]);
            (m, map.height_at(x, y) / g0)
        };
        let first = under_tip(engage_position(&self.spec)).0;
        scan_line(&self.spec, &self.engage[first], &under_tip, cancel)
    }
}

/// A positive finite SI setting, or an error naming it.
fn positive(
    name: &'static str,
    v: f64,
    zero_ok: bool,
    allowed: &'static str,
) -> Result<f64, SimError> {
    if v.is_finite() && (v > 0.0 || (zero_ok && v == 0.0)) {
        Ok(v)
    } else {
        Err(SimError::out_of_range(
            name,
            crate::error::number(v),
            allowed,
        ))
    }
}

/// The settings of a PI scan of `req` over `map` under `probe` (the lever's defaults where
/// `scan` leaves them out), the loop's gains in the model's units and the drive periods of the
/// whole scan, checked before any work ([`ScanStudy::new`]'s, and the cost of
/// [`super::image_job::ImageJob`]).
///
/// # Errors
/// As [`ScanStudy::new`]'s settings.
pub(crate) fn resolve(
    probe: &Probe,
    map: &SampleMap,
    req: &ImageRequest,
    scan: &PiScan,
) -> Result<(ScanSettings, FeedbackGains, f64), SimError> {
    let t_s = probe.scales.time_s;
    let (q, f0) = (
        probe.calibration.quality_factor,
        probe.calibration.resonance_frequency,
    );
    let lever = FeedbackGains::for_lever(q, std::f64::consts::TAU * f0 * t_s);
    let (kp, ki) = match scan.gains {
        Some((p, i)) => (
            positive("gains", p, true, "K_P must be a finite number ≥ 0")?,
            positive("gains", i, false, "K_I must be a finite rate > 0 (1/s)")?,
        ),
        None => (lever.proportional, lever.integral / t_s),
    };
    let tc = match scan.time_constant {
        Some(v) => {
            let v = positive("time_constant", v, true, "must be a finite time ≥ 0 (s)")?;
            // the lock-in's physical range (probe::ranges, section `feedback`)
            if let Some(why) = crate::probe::ranges::refusal("feedback", "time_constant", v) {
                return Err(SimError::out_of_range("time_constant", number(v), why));
            }
            v
        }
        None => lever.time_constant * t_s,
    };
    let gains = FeedbackGains {
        proportional: kp,
        integral: ki * t_s,
        time_constant: tc / t_s,
    };
    let f_drive = probe.drive_frequency;
    let pixels = req.pixels;
    let fastest = f_drive / (2.0 * pixels as f64);
    let scan_rate = match scan.scan_rate {
        Some(r) => positive(
            "scan_rate",
            r,
            false,
            "must be a finite rate > 0 (Hz, lines per second)",
        )?,
        None => ki / (2.0 * pixels as f64 * PIXEL_LOOP_TIMES),
    };
    if scan_rate > fastest && scan.scan_rate.is_none() {
        // the rate was not given: it follows K_I, which is then what to change
        return Err(SimError::out_of_range(
            "gains",
            format!(
                "K_I = {ki:e} 1/s (at most {:.6e} here)",
                fastest * 2.0 * pixels as f64 * PIXEL_LOOP_TIMES
            ),
            "sets the default scan rate (a pixel lasts 5 loop times 1/K_I) above the drive \
                 frequency over 2 × pixels: give a smaller K_I, or scan_rate",
        ));
    }
    if scan_rate > fastest {
        return Err(SimError::out_of_range(
            "scan_rate",
            format!("{scan_rate:e} (the limit here: {fastest:.6e} Hz)"),
            "must be at most the drive frequency over 2 × pixels: each pixel needs at least \
                 one drive period",
        ));
    }
    let periods_per_pixel = (f_drive / (2.0 * scan_rate * pixels as f64))
        .round()
        .max(1.0);
    let period = probe.params.period();
    let engage_periods = (ENGAGE_LOOP_TIMES / (gains.integral * period)).ceil();
    let lines = req.lines(map) as f64;
    let total = lines * (engage_periods + 2.0 * pixels as f64 * periods_per_pixel);
    if total.is_nan() || total > MAX_SCAN_PERIODS as f64 {
        return Err(SimError::out_of_range(
            "scan_rate",
            format!("{scan_rate:e} ({total:.3e} drive periods)"),
            "must leave at most 1e9 drive periods in all (lines × (engage + 2 × pixels × \
                 periods per pixel)): scan faster, or with fewer pixels or lines",
        ));
    }
    let settings = ScanSettings {
        scan_rate,
        proportional_gain: kp,
        integral_gain: ki,
        time_constant: tc,
        periods_per_pixel: periods_per_pixel as usize,
        engage_periods: engage_periods as usize,
        lock_in_samples: LOCK_IN_SAMPLES,
        pixel_time: periods_per_pixel / f_drive,
        amplitude_time: 2.0 * q / (std::f64::consts::TAU * f0),
    };
    Ok((settings, gains, total))
}

impl ScanStudy {
    /// The study of `req` and `scan` over `map` under the probe `probe_table` (SI in): the
    /// materials' approach curves, the ideal image, the settings.
    ///
    /// # Errors
    /// As [`super::image::image`]; [`SimError::OutOfRange`] naming `scan_rate` (> 0, at most
    /// the drive frequency over 2 × pixels: a pixel needs a drive period; and at most
    /// [`MAX_SCAN_PERIODS`] periods in all), `gains` (K_P ≥ 0, K_I > 0, finite) or
    /// `time_constant` (≥ 0, finite, at most 1 000 s).
    pub(crate) fn new(
        probe_table: &toml::Table,
        map: &SampleMap,
        req: &ImageRequest,
        scan: &PiScan,
    ) -> Result<ScanStudy, SimError> {
        req.validate(map)?;
        let probe =
            Probe::from_table(probe_table, "probe").map_err(|e| SimError::Probe(e.to_string()))?;
        let (settings, gains, total) = resolve(&probe, map, req, scan)?;
        let pixels = req.pixels;
        // the lines' drive periods (× modes) and the pixels' memory, with the curves' cost
        let extra = crate::request::limits::Cost {
            bytes: req.pixel_bytes(map),
            work: total,
        };
        let (curves, of_domain, units) =
            material_curves(probe_table, map, req.curve_points, extra)?;
        let ideal = image_of(&curves, &of_domain, &units, map, req)?;
        let engage = curves
            .iter()
            .map(|m| {
                let far = &m.curve.first[0];
                Engage {
                    state: far.state.clone(),
                    z_c: rest_distance(&m.params, far.value),
                    amplitude: far.observables.amplitude,
                    phase: far.observables.phase,
                }
            })
            .collect::<Vec<_>>();
        // the controller's range above the local surface: the approach curves' z_c range
        let (lo, hi) = curves
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |r, m| {
                m.curve.first.iter().fold(r, |(lo, hi), p| {
                    let z = rest_distance(&m.params, p.value);
                    (lo.min(z), hi.max(z))
                })
            });
        let free_amplitude = probe.free_amplitude / units.length;
        let spec = LineSpec {
            materials: curves.iter().map(|m| m.params).collect(),
            setpoint: req.setpoint * free_amplitude,
            free_amplitude,
            gains,
            samples: LOCK_IN_SAMPLES,
            pixels,
            periods_per_pixel: settings.periods_per_pixel,
            engage_periods: settings.engage_periods,
            range: (lo, hi),
            integrator: IntegratorOptions::default(),
        };
        // what a resumed scan must match: everything its lines depend on (the settings as
        // given under "feedback", named first when a resume differs; then as resolved)
        let fingerprint = json!({
            "feedback": scan,
            "probe": probe_table,
            "map": map,
            "request": req,
            "scan": settings,
        });
        let job = LineJob {
            spec,
            engage,
            map: map.clone(),
            of_domain,
            y: ideal.y.clone(),
            length: units.length,
            pixels,
        };
        Ok(ScanStudy {
            fingerprint,
            recipe: ScanRecipe {
                probe: probe_table.clone(),
                map: map.clone(),
                request: *req,
                scan: *scan,
            },
            ideal,
            job,
            units,
            settings,
        })
    }

    /// The study of a recipe ([`ScanStudy::recipe`]).
    ///
    /// # Errors
    /// As [`ScanStudy::new`].
    #[cfg(feature = "files")]
    pub(crate) fn from_recipe(r: &ScanRecipe) -> Result<ScanStudy, SimError> {
        ScanStudy::new(&r.probe, &r.map, &r.request, &r.scan)
    }

    /// What rebuilds this study elsewhere.
    pub fn recipe(&self) -> &ScanRecipe {
        &self.recipe
    }

    /// The number of lines.
    pub fn lines(&self) -> usize {
        self.ideal.y.len()
    }

    /// Scan line `t` (trace and retrace): `LineJob::line` of `ScanStudy::line_job`.
    ///
    /// # Errors
    /// As `LineJob::line`.
    pub fn line(&self, t: usize, cancel: &AtomicBool) -> Result<ScanLine, SimError> {
        self.job.line(t, cancel)
    }

    /// What scanning a line needs, without the materials' approach curves that
    /// [`ScanStudy::new`] computes: a distributed scan sends it to its workers once (the
    /// stage's start, [`crate::study::plan`]), so that a worker does not build the study.
    #[cfg(feature = "files")]
    pub(crate) fn line_job(&self) -> &LineJob {
        &self.job
    }

    /// The image of the finished lines `records` (in any order, every line once).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `lines` when a line is missing or repeated.
    pub fn assemble(&self, records: Vec<(usize, ScanLine)>) -> Result<PiImage, SimError> {
        let n = self.lines();
        let mut slots: Vec<Option<ScanLine>> = vec![None; n];
        for (t, l) in records {
            match slots.get_mut(t) {
                Some(s @ None) => *s = Some(l),
                _ => {
                    return Err(SimError::out_of_range(
                        "lines",
                        t,
                        "each line of the image once",
                    ))
                }
            }
        }
        let lines: Vec<ScanLine> = slots
            .into_iter()
            .collect::<Option<_>>()
            .ok_or_else(|| SimError::out_of_range("lines", n, "every line of the image"))?;
        let mut img = PiImage {
            ideal: self.ideal.clone(),
            lines,
            settings: self.settings,
            units: self.units,
            artefacts: [empty_artefacts(); 2],
            warnings: self
                .ideal
                .warnings
                .iter()
                .map(|w| format!("the ideal image beside the scan: {w}"))
                .collect(),
        };
        // a lock-in time constant given outside the typical range: a likely unit slip, named
        // (the lever's default τ_c/4 is no slip, whatever its value)
        if let Some(tc) = self.recipe.scan.time_constant {
            if let Some(why) = crate::probe::ranges::warning("feedback", "time_constant", tc) {
                img.warnings
                    .push(format!("time_constant = {} s is {why}", number(tc)));
            }
        }
        img.artefacts = [0, 1].map(|d| img.artefacts_of(d));
        for (d, a) in ["trace", "retrace"].iter().zip(img.artefacts) {
            if a.lost_contact_pixels > 0 {
                img.warnings.push(format!(
                    "{d}: {} pixel(s) lost contact (the tip left the sample and the amplitude \
                     rose toward the free amplitude: parachuting; scan slower or raise the gains)",
                    a.lost_contact_pixels
                ));
            }
            if a.saturated_periods > 0 {
                img.warnings.push(format!(
                    "{d}: the controller's output sat at a limit of its range (the approach \
                     curves' z_c range above the local surface) for {} drive period(s): a step \
                     too steep for the scan rate pressed the tip to the lowest z_c, or the loop \
                     is unstable (scan slower, or lower the gains)",
                    a.saturated_periods
                ));
            }
        }
        Ok(img)
    }
}

fn empty_artefacts() -> Artefacts {
    Artefacts {
        height_rms_error: f64::NAN,
        height_max_error: f64::NAN,
        overshoot: f64::NAN,
        tracking_error_rms: f64::NAN,
        lost_contact_pixels: 0,
        saturated_periods: 0,
        energy_residual_max: f64::NAN,
    }
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

    fn artefacts_of(&self, d: usize) -> Artefacts {
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
            energy_residual_max: residual,
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

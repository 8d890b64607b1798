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
    engage_position, scan_line, Engage, FeedbackGains, LineSpec, ScanLine, LOCK_IN_SAMPLES,
};
use crate::analysis::approach::rest_distance;
use crate::error::{number, SimError};
use crate::integrate::IntegratorOptions;
use crate::probe::Probe;
use crate::report::CurveUnits;
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use std::sync::atomic::AtomicBool;

pub(crate) use crate::report::image::{Artefacts, PiImage, ScanSettings};

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

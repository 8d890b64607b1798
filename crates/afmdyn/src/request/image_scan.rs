//! The time-domain scan of `afmdyn image --feedback pi` (issue 46): the lines of an image
//! scanned by the cantilever under a lock-in and a PI z controller
//! ([`crate::analysis::am_loop`]), trace and retrace, beside the ideal-feedback image of the same
//! map ([`super::image`]) so that the tracking error and the artefacts — lag behind a step,
//! overshoot, loss of contact ("parachuting") — are measured against the exact operating points.
//!
//! This module holds the scan's request ([`PiScan`], [`ScanRecipe`]), its limits and the
//! settings it resolves to, checked before any work (`resolve`); the scan runs as a study of
//! lines in the study layer.
//!
//! **Units.** A request is in SI: the scan rate in Hz (lines per second, each a trace and a
//! retrace, as instruments count it), K_P dimensionless (m of z per m of amplitude error), K_I
//! in 1/s (m/s of z per m of error), the lock-in's time constant in s. The defaults derive from
//! the lever (`crate::analysis::am_loop::FeedbackGains::for_lever`): τ_c = 2Q/ω₀, the
//! lock-in's time constant τ_c/4, K_I = 1/(4(τ_c + τ_L)), K_P = 0, and a pixel lasting
//! [`PIXEL_LOOP_TIMES`] loop time constants 1/K_I (RTESPA-300, Q = 400 at 300 kHz, 64 pixels:
//! 0.74 Hz).

use super::image::{ImageRequest, SampleMap};
use super::limits::positive;
use crate::analysis::am_loop::{FeedbackGains, LOCK_IN_SAMPLES};
use crate::error::{within, SimError};
use crate::probe::Probe;
use serde::{Deserialize, Serialize};

pub(crate) use crate::report::image::ScanSettings;

/// Most drive periods a scan may integrate (lines × (engage + 2 × pixels × periods per pixel)).
pub(crate) const MAX_SCAN_PERIODS: u64 = 1_000_000_000;

/// Loop time constants 1/K_I of a line's engage.
pub(crate) const ENGAGE_LOOP_TIMES: f64 = 20.0;

/// Loop time constants 1/K_I a pixel lasts at the default scan rate.
pub const PIXEL_LOOP_TIMES: f64 = 5.0;

request! {
    /// The PI scan's settings as a front end takes them (SI; `None`: the lever's default, module
    /// docs).
    #[derive(Copy)]
    pub struct PiScan {
        /// Scan rate (Hz): lines (trace and retrace) per second; `None`: a pixel lasts
        /// [`PIXEL_LOOP_TIMES`] loop time constants 1/K_I.
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "frequency")))]
        constants(PIXEL_LOOP_TIMES)
        pub scan_rate: Option<f64>,
        /// The gains (K_P, K_I): K_P ≥ 0 (m/m), K_I > 0 (1/s); `None`: K_P = 0,
        /// K_I = 1/(4(τ_c + τ_L)), τ_c = 2Q/ω₀ the lever's amplitude time constant and τ_L the
        /// lock-in's.
        pub gains: Option<(f64, f64)>,
        /// The lock-in's low-pass time constant (s), ≥ 0 and at most 1 000 s (its physical range,
        /// section `feedback`; [`crate::probe::ranges`]); outside 1 µs–0.1 s the image warns of a
        /// likely unit slip. `None`: τ_c/4.
        pub time_constant: Option<f64>,
        /// The temperature T of the thermal force on the lever (K, > 0 and ≤ 1500; outside
        /// 200–500 K it warns, a value in °C?); `None` (the default): no thermal noise. With one
        /// the lines are integrated by the stochastic step (exact for the linear law, SLS and
        /// the impact law, exponential Euler for the other laws),
        /// and the lock-in's amplitude and phase, the height and the error
        /// images carry the noise the lever's thermal motion gives them at the lock-in's
        /// bandwidth (the pixels' energy residual is then not given: the balance leaves the
        /// thermal force's work out).
        pub temperature: Option<f64>,
        /// The seed of the thermal force (with `temperature`; default 0): each line draws from
        /// streams of its own, so that an image is a function of its seed whatever the threads
        /// or the executor.
        pub seed: u64,
    }
}

impl PiScan {
    /// The thermal force of the scan under `probe`: `None` without a temperature.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `temperature`.
    pub(crate) fn thermal(
        &self,
        probe: &Probe,
    ) -> Result<Option<crate::integrate::exact::ThermalForce>, SimError> {
        (self.temperature)
            .map(|t| super::limits::thermal_force(t, self.seed, Some(probe)))
            .transpose()
    }
}

/// What rebuilds a PI scan's study (`ScanStudy`) in any process (a Dask worker): the probe's table, the
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

/// The lock-in's time constant τ_L (s) under `probe`: `given`, a finite time ≥ 0 within the
/// lock-in's physical range (section `feedback` of [`crate::probe::ranges`]), or the lever's
/// default τ_c/4 ([`FeedbackGains::for_lever`]).
///
/// # Errors
/// [`SimError::OutOfRange`] naming `time_constant`.
pub(crate) fn lock_in_time_constant(probe: &Probe, given: Option<f64>) -> Result<f64, SimError> {
    let t_s = probe.scales.time_s;
    let Some(v) = given else {
        let (q, f0) = (
            probe.calibration.quality_factor,
            probe.calibration.resonance_frequency,
        );
        return Ok(
            FeedbackGains::for_lever(q, std::f64::consts::TAU * f0 * t_s).time_constant * t_s,
        );
    };
    within(
        "time_constant",
        v,
        0.0..f64::INFINITY,
        "must be a finite time ≥ 0 (s)",
    )?;
    crate::probe::ranges::refuse("time_constant", ("feedback", "time_constant"), v)?;
    Ok(v)
}

/// The settings of a PI scan of `req` over `map` under `probe` (the lever's defaults where
/// `scan` leaves them out), the loop's gains in the model's units and the drive periods of the
/// whole scan, checked before any work (`ScanStudy::new`'s, and the cost of
/// [`super::image_job::ImageJob`]).
///
/// # Errors
/// [`SimError::OutOfRange`] naming `scan_rate` (> 0, at most the drive frequency over
/// 2 × pixels, at most [`MAX_SCAN_PERIODS`] periods in all), `gains` or `time_constant`.
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
        Some((p, i)) => {
            within("gains", p, 0.0..f64::INFINITY, "K_P must be finite and ≥ 0")?;
            positive("gains", i, "K_I must be a finite rate > 0 (1/s)")?;
            (p, i)
        }
        None => (lever.proportional, lever.integral / t_s),
    };
    let tc = lock_in_time_constant(probe, scan.time_constant)?;
    let gains = FeedbackGains {
        proportional: kp,
        integral: ki * t_s,
        time_constant: tc / t_s,
    };
    let f_drive = probe.drive_frequency;
    let pixels = req.pixels;
    let fastest = f_drive / (2.0 * pixels as f64);
    let scan_rate = match scan.scan_rate {
        Some(r) => {
            positive(
                "scan_rate",
                r,
                "must be a finite rate > 0 (Hz, lines per second)",
            )?;
            r
        }
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
        temperature: scan.temperature,
        seed: scan.temperature.map(|_| scan.seed),
    };
    Ok((settings, gains, total))
}

//! The limits of a request beyond the model's ranges ([`crate::params`]), each with its reason.
//! One place: the command line, Python and any later front end refuse the same values with the
//! same message because they all validate through [`super`].

/// Longest run, transient included, in drive periods: beyond, τ (a double) no longer resolves
/// the integration grid (the grid step of a period is ~1e-3 of it, and τ at 1e8 periods has an
/// ulp of ~1e-8 of a period).
pub const MAX_RUN_PERIODS: f64 = 1e8;
/// Bytes in a GiB.
pub(crate) const GIB: f64 = 1024.0 * 1024.0 * 1024.0;
/// Largest time series streamed to files (`afmdyn simulate` writes timeseries.npy, and
/// timeseries.csv on request), in bytes.
pub(crate) const MAX_SERIES_BYTES: f64 = 16.0 * GIB;
/// Largest time series held in memory (a Python call returns its arrays whole), in bytes: a
/// quarter of this machine class's 24 GiB less room for the caller.
pub(crate) const MAX_SERIES_MEMORY_BYTES: f64 = 4.0 * GIB;
/// Largest memory the traces of a stepped curve (`approach`/`resonance --traces`) may take, in
/// bytes, estimated before the run for the worst case (every trace over
/// [`crate::analysis::traces::MAX_TRACE_PERIODS`] drive periods): 1 GiB, so that the traces and
/// the copies a front end makes of them (files, NumPy arrays) stay within a few GiB.
pub(crate) const MAX_TRACE_BYTES: f64 = GIB;
/// Bytes of one trace sample: deflection, distance and force, 8 bytes each.
pub(crate) const TRACE_BYTES_PER_SAMPLE: f64 = 24.0;
use crate::error::SimError;
pub use crate::io::input::{MAX_INPUT_CSV_BYTES, MAX_INPUT_TEXT_BYTES};
/// The range of every integrator tolerance (relative and absolute; the adaptive, split and
/// Taylor integrators use it, the exact propagator and RK4 ignore it but it is checked alike): below 1e-16 it is beneath the double's resolution, above 1e-3 no longer an accuracy.
pub const TOLERANCE_RANGE: (f64, f64) = crate::integrate::TOLERANCE_RANGE;
/// Largest number of samples per drive period of a time series.
pub const MAX_SAMPLES_PER_PERIOD: usize = 100_000;
pub(crate) use crate::analysis::attractors::ATTRACTOR_SAMPLES_PER_PERIOD;
pub use crate::analysis::attractors::MAX_ATTRACTOR_SAMPLES;
pub use crate::analysis::steady::MAX_STEADY_PERIODS;
/// Largest number of worker threads a sweep may ask for.
pub const MAX_THREADS: usize = 1024;

/// A request's thread count (`None`: all cores) checked against 1..=[`MAX_THREADS`]: the one
/// rule of every study's `threads`.
///
/// # Errors
/// [`crate::SimError::OutOfRange`] naming `threads`.
pub(crate) fn check_threads(threads: Option<usize>) -> Result<(), crate::SimError> {
    threads.map_or(Ok(()), |t| {
        crate::error::in_range("threads", t, 1..=MAX_THREADS)
    })
}

/// `value` finite and > 0, else [`crate::SimError::OutOfRange`] naming `name` and `allowed`.
pub(crate) fn positive(
    name: &'static str,
    value: f64,
    allowed: &'static str,
) -> Result<(), crate::SimError> {
    use std::ops::Bound::Excluded;
    let open = (Excluded(0.0), Excluded(f64::INFINITY));
    crate::error::within(name, value, open, allowed)
}
/// What a request costs ([`crate::request::Request::cost`]), estimated before it runs for the
/// worst case its options allow (`crate::request::costs`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cost {
    /// Peak memory, in bytes.
    pub bytes: f64,
    /// Work, in mode-periods: drive periods integrated × the model's modes.
    pub work: f64,
}

/// Largest peak memory of a request, estimated before it runs, in bytes: 1.1 GiB, the budget
/// of an image (`MAX_IMAGE_BYTES` of `crate::request::image`, where 2048 × 2048 pixels aborted
/// on allocation) and about that of a curve's traces (`MAX_TRACE_BYTES`): what a request and
/// the copies a front end makes of its result (files, NumPy arrays) hold within a few GiB.
pub(crate) const MAX_REQUEST_BYTES: f64 = 1.1 * GIB;

/// Largest work of a request, estimated before it runs, in mode-periods (drive periods
/// integrated × modes): 1e11, about four days on one core at N = 20 (59 µs a drive period,
/// 3 µs a mode-period, `docs/performance.md`) and one at N = 3 (2.3 µs a period; a nonlinear
/// law 6–37 µs). Above every request whose factors the options bound one by one
/// ([`MAX_RUN_PERIODS`] × 20 modes × the 41 columns of a Lyapunov spectrum is 8.2e10), below
/// their products (random starts × transient cap × cells, which reach 1e18).
pub(crate) const MAX_REQUEST_WORK: f64 = 1e11;

/// Depth of a period-doubling cascade followed by branch switching: periods n, 2n, 4n and 8n.
pub const CASCADE_FACTOR: usize = 8;
/// Largest number of drive periods compared by the mode-convergence study (Fig. 4), and the
/// largest number of samples it holds: `periods × samples_per_period`.
pub const MAX_CONVERGE_PERIODS: usize = 10_000;
/// See [`MAX_CONVERGE_PERIODS`].
pub const MAX_CONVERGE_SAMPLES: usize = 10_000_000;
/// Largest number of orbit periods integrated for the observables.
pub const MAX_OBSERVE_PERIODS: usize = crate::analysis::observables::MAX_PERIODS;
/// Largest modal state entry of an initial state: states of norm
/// [`crate::params::STATE_NORM_MAX`] count as diverged.
pub(crate) const MAX_INITIAL_ENTRY: f64 = crate::params::STATE_NORM_MAX / 10.0;

// the limit is the physical range of a rest distance, declared with the probe's ranges
pub(crate) use crate::probe::ranges::MAX_SI_DISTANCE;

/// Drive frequencies (Hz) are accepted within [1e-2, 1e4] × the probe's own drive frequency:
/// wider than the band of any of its 20 modes, narrow enough to catch a value meant in kHz or
/// MHz but written in Hz (1e3 or 1e6 too small).
pub(crate) const SI_FREQUENCY_RATIO: (f64, f64) = (1e-2, 1e4);

pub(crate) use crate::analysis::tolerance;

/// Check an SI distance `v` (m) against [`MAX_SI_DISTANCE`].
///
/// # Errors
/// [`crate::SimError::OutOfRange`] naming `name`, with the hint that lengths are in metres.
pub(crate) fn si_distance(name: &'static str, v: f64) -> Result<(), crate::SimError> {
    if v.is_finite() && v.abs() > MAX_SI_DISTANCE {
        return Err(crate::SimError::out_of_range(
            name,
            format!("{} m", crate::error::number(v)),
            "must lie within ±1e-4 m: lengths are in metres and tapping-mode distances are \
             nanometres (20 nm is 20e-9, or 20nm on the command line)",
        ));
    }
    Ok(())
}

#[cfg(feature = "files")]
pub use crate::io::input::read_input;
pub use crate::io::input::InputFileError;

/// The physical range of the temperature (K): above absolute zero, below where a silicon lever
/// stays a lever.
pub const TEMPERATURE_RANGE: (f64, f64) = (0.0, 1500.0);

/// The temperatures of a measurement in a laboratory (K): a cooled to a heated stage. Below
/// them a value is either a cryogenic AFM's or in °C (22 for 295.15 K): it warns.
pub const TYPICAL_TEMPERATURE: (f64, f64) = (200.0, 500.0);

/// The warning of a temperature `t` (K) outside [`TYPICAL_TEMPERATURE`], naming the likely slip
/// (`thermal`'s, `calibrate`'s and `simulate`'s).
pub fn temperature_warnings(t: f64) -> Vec<String> {
    let (lo, hi) = TYPICAL_TEMPERATURE;
    if (lo..=hi).contains(&t) {
        return Vec::new();
    }
    vec![warning!(
        "thermal.temperature-unit",
        "Give the temperature in kelvin (22 °C is 295.15 K); a cryogenic or heated stage's \
         value stands.",
        "temperature = {t} K is outside the {lo}..{hi} K of a laboratory's stage: written \
         in °C? ({t} °C is {} K; a cryogenic AFM's temperature is right as it is)",
        t + 273.15
    )]
}

/// Check a temperature `t` (K) against [`TEMPERATURE_RANGE`] (`thermal`'s, `calibrate`'s,
/// `fit`'s and `simulate`'s).
///
/// # Errors
/// [`SimError::OutOfRange`] naming `temperature`.
pub fn check_temperature(t: f64) -> Result<(), SimError> {
    let (lo, hi) = TEMPERATURE_RANGE;
    if t > lo && t <= hi {
        return Ok(());
    }
    Err(SimError::out_of_range(
        "temperature",
        crate::error::number(t),
        "the temperature must be above absolute zero and at most 1500 K (K)",
    ))
}

/// The thermal force of a simulated measurement at `t` (K) under `probe` with `seed`: the
/// temperature checked ([`check_temperature`]) and k_B T in the probe's energy unit
/// (`simulate`'s, `approach`'s and the PI scan's, [`crate::integrate::exact::noise`]).
///
/// # Errors
/// [`SimError::OutOfRange`] naming `temperature` (out of range, or without a probe: the
/// dimensionless model has no k_B T).
pub(crate) fn thermal_force(
    t: f64,
    seed: u64,
    probe: Option<&crate::probe::Probe>,
) -> Result<crate::integrate::exact::ThermalForce, SimError> {
    check_temperature(t)?;
    let Some(probe) = probe else {
        return Err(SimError::out_of_range(
            "temperature",
            crate::error::number(t),
            "thermal noise needs the probe's SI units (k_B T in the model's energy unit): give \
             the probe (--probe), or drop temperature",
        ));
    };
    let kt = crate::analysis::thermal::BOLTZMANN * t / probe.scales.energy_j();
    Ok(crate::integrate::exact::ThermalForce::new(kt, seed))
}

/// k_B T at `t` in the model's energy unit of `model`'s probe, for a linear-response noise
/// estimate ([`thermal_force`]'s checks; the orbit's chain holds every law and every drive
/// component, `crate::analysis::orbit_noise`, `crate::analysis::lock_in_noise`).
///
/// # Errors
/// As [`thermal_force`].
pub(crate) fn thermal_kt(t: f64, model: &super::Resolved) -> Result<f64, crate::SimError> {
    Ok(thermal_force(t, 0, model.probe.as_ref())?.kt)
}

/// Refuse the options of `needs` (name, value) that only a temperature `t` gives a meaning
/// where there is none.
///
/// # Errors
/// [`crate::SimError::OutOfRange`] naming the first option given without a temperature.
pub(crate) fn needs_temperature(
    t: Option<f64>,
    needs: &[(&'static str, Option<f64>)],
) -> Result<(), crate::SimError> {
    let (number, why) = (
        crate::error::number,
        "belongs to the thermal noise, which needs a temperature: give it too, or drop this",
    );
    match needs.iter().find(|(_, v)| t.is_none() && v.is_some()) {
        Some(&(name, Some(v))) => Err(crate::SimError::out_of_range(name, number(v), why)),
        _ => Ok(()),
    }
}

/// k_B T of a request's optional temperature `t` ([`thermal_kt`]; `None` without one), where
/// `needs` lists the options that only a temperature gives a meaning ([`needs_temperature`]).
///
/// # Errors
/// As [`thermal_kt`] and [`needs_temperature`].
pub(crate) fn optional_kt(
    t: Option<f64>,
    needs: &[(&'static str, Option<f64>)],
    model: &super::Resolved,
) -> Result<Option<f64>, crate::SimError> {
    needs_temperature(t, needs)?;
    t.map(|t| thermal_kt(t, model)).transpose()
}

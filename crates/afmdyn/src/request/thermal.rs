//! `thermal`: the free lever's thermal spectrum at a temperature — the request the command line
//! (`afmdyn thermal --probe P.toml`) and Python (`afmdyn.thermal`) share: its options, their
//! ranges and its declared cost ([`crate::analysis::thermal`] computes it).

use super::costs::{MODEL_BYTES, OPERATION_WORK};
use super::limits::check_temperature;
use super::limits::Cost;
use super::run::Resolved;
use crate::error::SimError;

/// The default temperature (K): a laboratory's 22 °C.
pub const DEFAULT_TEMPERATURE: f64 = 295.0;

/// The default and the largest number of frequencies of the spectrum.
pub const DEFAULT_POINTS: usize = 4096;
/// The largest number of frequencies (10⁷, 240 MB of spectrum).
pub const MAX_POINTS: usize = 10_000_000;

request! {
    /// `thermal`: the temperature, the laser spot of the optical lever and the frequencies of the
    /// one-sided power spectral density (SI). Needs a probe.
    pub struct ThermalRequest {
        /// The temperature T (K, > 0 and ≤ 1500; default 295 K). Outside 200–500 K it warns (a
        /// value in °C?).
        pub temperature: f64 = DEFAULT_TEMPERATURE,
        /// The optical lever's laser spot ξ_s, a fraction of the lever's length from its base
        /// (0 < ξ_s ≤ 1; default 1, at the tip): the apparent deflection reads the slope there.
        pub spot: f64 = 1.0,
        /// The highest frequency of the spectrum (Hz, > 0); default 1.25 times the highest mode's
        /// frequency, at least 3 f₀.
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "frequency")))]
        pub to: Option<f64>,
        /// The number of frequencies, evenly spaced from to/points to `to` (1 to 10⁷; default
        /// 4096). A mode's peak narrower than the spacing (f_k/Q_k) is not resolved in the
        /// spectrum; each mode's share is exact whatever the spacing.
        pub points: usize = DEFAULT_POINTS,
    }
}

/// The checks of a temperature `t` (K) and a laser spot `spot` shared by the thermal
/// requests: a probe, T in (0, 1500] K, 0 < spot ≤ 1.
///
/// # Errors
/// [`SimError::OutOfRange`] naming `probe`, `temperature` or `spot`.
pub(crate) fn check_thermal(model: &Resolved, t: f64, spot: f64) -> Result<(), SimError> {
    model.params.validate_fields()?;
    if model.probe.is_none() {
        return Err(SimError::out_of_range(
            "probe",
            "missing",
            "the thermal spectrum is in SI: give the probe (its k, f0 and Q)",
        ));
    }
    check_temperature(t)?;
    use std::ops::Bound::{Excluded, Included};
    let lever = "the laser spot is a fraction of the length from the base: 0 < spot ≤ 1";
    crate::error::within("spot", spot, (Excluded(0.0), Included(1.0)), lever)
}

impl_request! {
    ThermalRequest, "thermal", advice = "ask for fewer points";
    validate |r, model| {
        check_thermal(model, r.temperature, r.spot)?;
        if let Some(f) = r.to {
            super::limits::positive("to", f, "the highest frequency must be finite and > 0 (Hz)")?;
        }
        crate::error::within(
            "points",
            r.points,
            1..=MAX_POINTS,
            "the number of frequencies must be 1..=10000000",
        )
    };
    // An N × N complex factorisation per frequency; the spectrum's columns, their copies in
    // the layouts and the document's JSON values (256 bytes a frequency).
    cost |r, model| {
        let n = model.params.modes as f64;
        let points = r.points as f64;
        Ok(Cost {
            bytes: MODEL_BYTES + points * 256.0,
            work: points * OPERATION_WORK * (n * n * n + 4.0 * n * n),
        })
    }
}

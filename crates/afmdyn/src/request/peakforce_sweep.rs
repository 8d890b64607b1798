//! `peakforce` with a sweep: the steady tap's channels as curves over the mean rest separation
//! z_c or over the modulation frequency f_m ([`PeakForceSweep`]), run as a chain of tasks
//! (each tap continued from the previous tap's orbit): the sweep's quantity, its values and
//! their limits. Its block of the document and its layout are made where it runs.

use crate::error::SimError;
use serde::{Deserialize, Serialize};
use std::str::FromStr;

/// Most values of a sweep.
pub const MAX_SWEEP_POINTS: usize = 10_000;

/// The quantity a PeakForce sweep steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(rename_all = "snake_case")]
pub enum PeakForceSweepParam {
    /// The mean rest separation z_c (m with a probe, else g₀).
    ZC,
    /// The modulation frequency f_m (Hz with a probe, else Ω, the model's drive frequency).
    ModulationFrequency,
}

impl PeakForceSweepParam {
    /// Its name in the document and on the command line (`z_c`, `modulation_frequency`).
    pub fn name(self) -> &'static str {
        match self {
            PeakForceSweepParam::ZC => "z_c",
            PeakForceSweepParam::ModulationFrequency => "modulation_frequency",
        }
    }

    /// Its unit: m or Hz with a probe, g0 or Ω without.
    pub fn unit(self, si: bool) -> &'static str {
        match (self, si) {
            (PeakForceSweepParam::ZC, true) => "m",
            (PeakForceSweepParam::ZC, false) => "g0",
            (PeakForceSweepParam::ModulationFrequency, true) => "Hz",
            (PeakForceSweepParam::ModulationFrequency, false) => "Ω",
        }
    }
}

impl FromStr for PeakForceSweepParam {
    type Err = String;
    /// `z_c` (or `z-c`) and `modulation_frequency` (or `modulation-frequency`, `f_m`).
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().replace('-', "_").as_str() {
            "z_c" | "zc" => Ok(PeakForceSweepParam::ZC),
            "modulation_frequency" | "f_m" | "fm" => Ok(PeakForceSweepParam::ModulationFrequency),
            other => Err(format!(
                "unknown peakforce sweep `{other}`: z_c or modulation_frequency"
            )),
        }
    }
}

/// A sweep of the steady tap: the quantity and its values, in the request's units (m or Hz
/// with a probe; g₀ or Ω without).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct PeakForceSweep {
    /// The swept quantity (not `param`: that keyword names a model parameter,
    /// [`crate::SweepParam`]).
    pub quantity: PeakForceSweepParam,
    /// Its values, in the order the chain visits them (1..=10000 of them).
    pub values: Vec<f64>,
}

impl PeakForceSweep {
    /// The values from `from` to `to` (both included when the step divides the range) in steps
    /// of |`step`|, towards `to`.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `step` when it is not finite and > 0 or gives more than
    /// [`MAX_SWEEP_POINTS`] values; [`SimError::NotFinite`] for an end that is not finite.
    pub fn grid(from: f64, to: f64, step: f64) -> Result<Vec<f64>, SimError> {
        crate::error::finite("from", from)?;
        crate::error::finite("to", to)?;
        let step = step.abs();
        super::limits::positive("step", step, "must be finite and ≠ 0")?;
        // one part in 1e9 of a step forgiven: 0.1 steps of 1.0 give 11 values
        let n = ((to - from).abs() / step * (1.0 + 1e-9)).floor();
        if n + 1.0 > MAX_SWEEP_POINTS as f64 {
            return Err(SimError::out_of_range(
                "step",
                step,
                format!("gives more than {MAX_SWEEP_POINTS} values from `from` to `to`"),
            ));
        }
        let dir = if to >= from { step } else { -step };
        Ok((0..=n as usize).map(|k| from + dir * k as f64).collect())
    }
}

//! `peakforce` with a sweep: the steady tap's channels as curves over the mean rest separation
//! z_c or over the modulation frequency f_m ([`PeakForceSweep`]), run as a chain of tasks
//! (`study::peakforce`, each tap continued from the previous tap's
//! orbit), and its block of the document ([`sweep_document`]) and layout ([`sweep_layout`]).

use crate::analysis::peakforce::SteadyTap;
use crate::error::SimError;
use crate::layout::columns::{self, UnitNames};
use crate::layout::{Layout, Values, Variable};
pub(crate) use crate::report::present::peakforce::{Frame, SweepTap, COLUMNS};
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
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
        if !(step.is_finite() && step > 0.0) {
            return Err(SimError::out_of_range(
                "step",
                step,
                "must be finite and ≠ 0",
            ));
        }
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

/// The `sweep` block of the document: the swept quantity and its values, each channel of
/// [`COLUMNS`] (`z_c` the feedback's with a setpoint; `modulus_dmt` the frame's modulus scale ×
/// the fitted Hertz group) over them (`null` where a point failed) and their units, the orbit's
/// period and stability, and each point's message (`null` when computed).
pub(crate) fn sweep_document(sweep: &PeakForceSweep, frame: &Frame, taps: &[SweepTap]) -> Value {
    let si = frame.u.si;
    json!({
        "quantity": sweep.quantity.name(),
        "unit": sweep.quantity.unit(si),
        "values": sweep.values,
        "channels": columns::arrays(&COLUMNS, frame, taps),
        "units": columns::units(&COLUMNS, &UnitNames::si_or_model(si)),
        "period": taps.iter().map(|t| t.tap.as_ref().map(|t| t.period)).collect::<Vec<_>>(),
        "stable": taps.iter().map(|t| t.tap.as_ref().map(|t| t.stable)).collect::<Vec<_>>(),
        "transient_periods": taps.iter().map(|t| t.tap.as_ref().map(|t| t.transient_periods)).collect::<Vec<_>>(),
        "evaluations": taps.iter().map(|t| t.evaluations).collect::<Vec<_>>(),
        "message": taps.iter().map(|t| t.message.clone()).collect::<Vec<_>>(),
        "warnings": taps
            .iter()
            .map(|t| {
                t.tap.as_ref().map_or(Vec::new(), |tap| {
                    tap_warnings(tap)
                        .into_iter()
                        .map(|(_, w)| w)
                        .collect()
                })
            })
            .collect::<Vec<Vec<String>>>(),
    })
}

/// What may make a steady tap's channels misleading, each with its kind (`period`, `double-tap`,
/// `unstable`, `no-contact`) and its message: a period-n orbit (the cycle shows the first
/// period), more than one contact per modulation period (`modulus_dmt` is then not meaningful),
/// an unstable orbit, no repulsive contact. Every tap of a sweep is checked alike
/// ([`sweep_warnings`]), and a single tap's document has them ([`super::peakforce::document`]).
pub(crate) fn tap_warnings(tap: &SteadyTap) -> Vec<(&'static str, String)> {
    let c = &tap.channels;
    let mut warnings = Vec::new();
    if tap.period > 1 {
        warnings.push((
            "period",
            format!(
                "period-{} tapping: the orbit repeats after {} modulation periods; the cycle \
                 shows the first",
                tap.period, tap.period
            ),
        ));
    }
    if c.taps_per_cycle > 1.0 + 1e-9 {
        warnings.push((
            "double-tap",
            format!(
                "{} contacts per modulation period: double taps (the lever's ringing reaches the \
                 sample again); modulus_dmt, fitted as PF-QNM does on the retract of one tap, is \
                 not meaningful for such a cycle",
                c.taps_per_cycle
            ),
        ));
    }
    if !tap.stable {
        warnings.push((
            "unstable",
            "the steady tap is unstable (a Floquet multiplier outside the unit circle)".into(),
        ));
    }
    if c.peak_force <= 0.0 {
        // the sample may indent the tip and still pull: adhesion outweighs the elastic
        // repulsion at the deepest indentation (issue 77: this was said as "never reaches")
        let why = if c.deformation > 0.0 {
            "the tip indents the sample but adhesion outweighs the elastic repulsion at the \
             deepest indentation (the peak force is an attraction)"
        } else {
            "the sample never reaches the tip at this z_c"
        };
        warnings.push(("no-contact", format!("no repulsive contact: {why}")));
    }
    warnings
}

/// The sweep's warnings for the document: each kind of [`tap_warnings`]
/// once, with the number of values it holds at and the swept values where it does (the
/// first three and the last, in `block`'s units), its message the first such tap's; the
/// per-value messages are in `sweep.warnings`.
pub(crate) fn sweep_warnings(block: &Value, taps: &[SweepTap]) -> Vec<String> {
    let quantity = block["quantity"].as_str().unwrap_or("value");
    let unit = block["unit"].as_str().unwrap_or("");
    let values: Vec<f64> = block["values"].as_array().map_or(Vec::new(), |a| {
        a.iter().map(|v| v.as_f64().unwrap_or(f64::NAN)).collect()
    });
    // (kind, first message, indices), in the order the kinds first appear
    let mut kinds: Vec<(&'static str, String, Vec<usize>)> = Vec::new();
    for (i, t) in taps.iter().enumerate() {
        let Some(tap) = &t.tap else { continue };
        for (kind, message) in tap_warnings(tap) {
            match kinds.iter_mut().find(|k| k.0 == kind) {
                Some(k) => k.2.push(i),
                None => kinds.push((kind, message, vec![i])),
            }
        }
    }
    kinds
        .into_iter()
        .map(|(_, message, at)| {
            let show = |&i: &usize| {
                values
                    .get(i)
                    .map_or_else(|| format!("#{i}"), |&v| crate::error::number(v))
            };
            let mut list: Vec<String> = at.iter().take(3).map(show).collect();
            if at.len() > 4 {
                list.push("…".into());
            }
            if at.len() > 3 {
                list.push(show(at.last().expect("non-empty")));
            }
            format!(
                "at {} of the sweep's {} values ({quantity} = {} {unit}): {message} (each \
                 value's in sweep.warnings)",
                at.len(),
                taps.len(),
                list.join(", ")
            )
        })
        .collect()
}

/// The sweep's layout: the values as the coordinate of the dimension named after the swept
/// quantity, every channel of [`COLUMNS`] over it but the swept one (NaN where a point failed;
/// `modulus_dmt` last), and `period` (0 where a point failed).
pub(crate) fn sweep_layout(sweep: &PeakForceSweep, frame: &Frame, taps: &[SweepTap]) -> Layout {
    let (dim, si) = (sweep.quantity.name(), frame.u.si);
    let d = [dim];
    let unit = sweep.quantity.unit(si);
    let swept = format!("swept {dim}");
    let mut variables = vec![Variable::f64(dim, &d, unit, swept, &sweep.values)];
    let names = UnitNames::si_or_model(si);
    let mut channels = columns::variables(&COLUMNS, frame, taps, &d, &names);
    // the swept z_c is the coordinate itself
    channels.retain(|v| v.name != dim);
    // the layout lists the modulus last (the table after ringing_amplitude)
    let modulus = channels.iter().position(|v| v.name == "modulus_dmt");
    let modulus = channels.remove(modulus.expect("a column"));
    variables.extend(channels.into_iter().chain([modulus]));
    let period = taps
        .iter()
        .map(|t| t.tap.as_ref().map_or(0.0, |t| t.period as f64));
    variables.push(Variable::new(
        "period",
        &d,
        "modulation periods",
        "period of the orbit (0: the point failed)",
        Values::F64(period.collect()),
    ));
    Layout::new("peakforce sweep", &[(dim, sweep.values.len())], variables)
}

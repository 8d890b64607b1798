//! What the force-curve fit ([`super::fit`]) and the dynamic fit ([`super::fit_dynamic`])
//! share: the result of a `fit` request, the data of an AM or FM curve, the fewest rows and the
//! fitted quantities' physical ranges.

use crate::analysis::fit::force_curve::Preprocessed;
use crate::analysis::fit::FitOutcome;
use crate::contact::LawKind;
use crate::error::SimError;
use crate::probe::ranges::si_range;

/// How a fit's intervals were found, for its document's `method`: the profile likelihood's
/// where any parameter was profiled, else the Wald intervals.
pub(crate) fn intervals_method(o: &FitOutcome) -> &'static str {
    if o.estimates.iter().any(|e| e.profile.is_some()) {
        "intervals from the profile likelihood (Δχ² ≤ 3.84; up to 4 fitted parameters, the probe keys first, Wald ±1.96 SE beyond)"
    } else {
        "Wald intervals (±1.96 standard errors; no profiles)"
    }
}

/// The fewest rows fitted (more than the parameters, for the χ²'s degrees of freedom).
pub(crate) const MIN_FIT_ROWS: usize = 8;

/// The physical range [lo, hi] of a fitted quantity from the probe's ranges
/// (`crate::probe::ranges::SI_RANGES`; a positive quantity without a lower bound there is
/// bounded by 0); (−∞, ∞) for the contact point and the baseline.
pub(crate) fn bounds(name: &str) -> (f64, f64) {
    let (section, key) = match name.split_once('.') {
        Some(sk) => sk,
        None => return (f64::NEG_INFINITY, f64::INFINITY),
    };
    let range = si_range(section, key);
    let lo = range.and_then(|r| r.below).map_or(0.0, |b| b.0);
    let hi = range.and_then(|r| r.above).map_or(f64::INFINITY, |b| b.0);
    (lo, hi)
}

/// The probe's value `v` of `key`, which the fit needs.
///
/// # Errors
/// [`SimError::OutOfRange`] naming `probe` and `key` when the probe lacks it.
pub(crate) fn probe_value(v: Option<f64>, key: &str) -> Result<f64, SimError> {
    v.ok_or_else(|| {
        SimError::out_of_range("probe", key, format!("the fit needs the probe's {key}"))
    })
}

/// The result of a `fit` request.
#[derive(Debug, Clone)]
pub struct FitResult {
    /// The law fitted.
    pub law: LawKind,
    /// The lever's spring constant (N/m).
    pub spring_constant: f64,
    /// The preprocessed curve.
    pub curve: Preprocessed,
    /// The rows fitted.
    pub rows: Vec<usize>,
    /// Every model parameter's name, in the model's order.
    pub names: Vec<&'static str>,
    /// Which were fitted.
    pub fitted: Vec<bool>,
    /// The fit.
    pub outcome: FitOutcome,
    /// The dynamic fit's data and channels, when the data are an AM or FM curve
    /// ([`super::fit_dynamic`]; then `curve` and `rows` are empty).
    pub dynamic: Option<DynamicFit>,
}

/// A measured dynamic curve's columns: an AM curve (amplitude and/or phase) or an FM curve
/// (frequency shift).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AmData {
    /// The piezo positions z (m).
    pub z: Vec<f64>,
    /// The amplitudes (m).
    pub amplitude: Option<Vec<f64>>,
    /// The phases (deg).
    pub phase: Option<Vec<f64>>,
    /// The amplitudes' standard deviations (m).
    pub sigma_amplitude: Option<Vec<f64>>,
    /// The phases' standard deviations (deg).
    pub sigma_phase: Option<Vec<f64>>,
    /// The frequency shifts Δf (Hz) of an FM curve (then the curve is fitted as one, by
    /// [`crate::analysis::fit::fm_curve`]).
    pub frequency_shift: Option<Vec<f64>>,
    /// The frequency shifts' standard deviations (Hz).
    pub sigma_frequency_shift: Option<Vec<f64>>,
    /// The second drive component's amplitudes A₂ (m) of a bimodal curve (then it is fitted
    /// by [`crate::analysis::fit::bimodal_curve`]).
    pub amplitude_2: Option<Vec<f64>>,
    /// The second component's phases φ₂ (deg).
    pub phase_2: Option<Vec<f64>>,
    /// A₂'s standard deviations (m).
    pub sigma_amplitude_2: Option<Vec<f64>>,
    /// φ₂'s standard deviations (deg).
    pub sigma_phase_2: Option<Vec<f64>>,
}

/// The dynamic fit's part of a [`FitResult`].
#[derive(Debug, Clone)]
pub struct DynamicFit {
    /// The data.
    pub data: AmData,
    /// Whether the amplitude and the phase were fitted (an AM curve: the model's values the
    /// amplitudes, then the phases).
    pub channels: (bool, bool),
    /// Whether the frequency shift was fitted (an FM curve; then `channels` is (false, false)).
    pub frequency_shift: bool,
    /// Whether the second drive component's amplitude and phase were fitted (a bimodal curve:
    /// the model's values A₁, φ₁, A₂, φ₂ of the channels fitted, in that order).
    pub second: (bool, bool),
    /// The last evaluation's warnings of the model (folds, grazing).
    pub model_warnings: Vec<String>,
}

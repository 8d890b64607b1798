//! What both fits return ([`FitResult`]: the force-curve fit's, `super::fit`, and the dynamic
//! fit's, `super::fit_dynamic`, with its part [`DynamicFit`]) and share: how the intervals
//! were found and the physical range of a fitted quantity.

use crate::analysis::fit::force_curve::Preprocessed;
use crate::analysis::fit::FitOutcome;
use crate::contact::LawKind;
use crate::probe::ranges::si_range;
use crate::request::fit_result::AmData;

/// How a fit's intervals were found, for its document's `method`: the profile likelihood's
/// where any parameter was profiled, else the Wald intervals.
pub(crate) fn intervals_method(o: &FitOutcome) -> &'static str {
    if o.estimates.iter().any(|e| e.profile.is_some()) {
        "intervals from the profile likelihood (Δχ² ≤ 3.84; up to 4 fitted parameters, the probe keys first, Wald ±1.96 SE beyond)"
    } else {
        "Wald intervals (±1.96 standard errors; no profiles)"
    }
}

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
    /// The curve's columns held against the probe that look off (a unit slip, another
    /// lever's spring constant), also among `outcome`'s warnings.
    pub data_warnings: Vec<String>,
    /// The dynamic fit's data and channels, when the data are an AM or FM curve
    /// ([`super::fit_dynamic`]; then `curve` and `rows` are empty).
    pub dynamic: Option<DynamicFit>,
    /// The thermal σ_F (N) each force was given, where the request's `temperature` set it
    /// (the data carrying no σ).
    pub thermal_sigma: Option<f64>,
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

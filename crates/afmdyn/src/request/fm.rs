//! `fm`: the frequency-modulation (FM-AFM) curve at constant amplitude over the rest distance
//! z_c ([`crate::analysis::fm`]: ideal PLL and amplitude controller, exact periodic orbits) —
//! the request the command line (`afmdyn fm`) and Python (`afmdyn.fm`) share: its options,
//! their defaults, ranges and checks, and its declared cost. With a probe everything is SI (z_c and A in m, Δf in Hz, E_dis in J, forces in N);
//! without one the model's units (g₀, Ω, F̃).

use super::costs::{newton_work, state_bytes, MODEL_BYTES, NOISE_PERIODS};
use super::curves::CurveRequest;
use super::limits::Cost;
use super::run::Resolved;
use crate::analysis::approach::approach_spec;
use crate::analysis::fm::FmSpec;
use crate::analysis::fm::DEFAULT_LOOP_TOLERANCE;
use crate::analysis::fm::{MAX_HALVINGS, MAX_LOOP_ITERATIONS};
use crate::error::SimError;

request! {
    /// `fm`: an FM curve from `from` to `to` (z_c; m with a probe, else g₀) at the oscillation
    /// amplitude `amplitude`, tracking mode `mode`.
    pub struct FmRequest {
        /// The first-harmonic amplitude A the amplitude controller holds (m with a probe, else g₀),
        /// > 0; default the probe's free amplitude A₀ (1 g₀).
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "length")))]
        pub amplitude: Option<f64>,
        /// The mode K (1-based) the PLL tracks; default 1.
        pub mode: usize = 1,
        /// First z_c of the approach (default: where the frequency shift has decayed to 0.5 % of
        /// its value at `to` ([`crate::request::fm::default_from`]); 2A + a₀, the lower turning point at A, for the
        /// laws without a force before contact).
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "length")))]
        pub from: Option<f64>,
        /// Last z_c (default A + a₀: the lower turning point at the contact distance a₀, 0 for
        /// the laws without attraction).
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "length")))]
        pub to: Option<f64>,
        /// Step of z_c; excludes `points`.
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "length")))]
        pub step: Option<f64>,
        /// Number of z_c values, ends included, 2..=[`crate::analysis::stepped::MAX_CURVE_POINTS`]
        /// (default [`crate::analysis::stepped::DEFAULT_CURVE_POINTS`]).
        constants(MAX_CURVE_POINTS in crate::analysis::stepped,
                  DEFAULT_CURVE_POINTS in crate::analysis::stepped)
        pub points: Option<usize>,
        /// Tolerance of the loop conditions, |A₁/A − 1| and |φ₁ − φ_set| (rad), in (0, 1e-3).
        pub tolerance: f64 = DEFAULT_LOOP_TOLERANCE,
        /// The temperature T of the thermal force (K, > 0 and ≤ 1500; outside 200–500 K it warns,
        /// a value in °C?); `None` (the default): no noise. With one every point gains σ of the
        /// frequency shift and of the excitation that the loops read under the lever's thermal
        /// force, by linear response of the closed loop ([`crate::analysis::fm::noise`]), and the
        /// document a `"thermal"` block. Needs the probe's SI units; every law (the impact law's
        /// sticking holds the tip against the thermal force's part at it).
        #[serde(skip_serializing_if = "Option::is_none")]
        pub temperature: Option<f64>,
        /// The loops' equivalent noise bandwidth B (Hz; with `temperature`), > 0 and at most
        /// ≈ π f_K/(4Q_K) (a gain min(π/Q_K, 1) per cycle, where they would outrun the lever);
        /// `None`: gains π/(3Q_K) per cycle, B ≈ π f_K/(12 Q_K) ([`crate::analysis::fm::LoopSpec`]).
        #[serde(skip_serializing_if = "Option::is_none")]
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "frequency")))]
        pub bandwidth: Option<f64>,
    }
}

/// The FM amplitude's range in the model's length unit (g₀ = A₀ of a probe): outside it the
/// request is refused, naming `amplitude`.
pub(crate) const FM_AMPLITUDE_RANGE: (f64, f64) = (1e-8, 1e4);

/// The share of the frequency shift at the curve's end (`to`) below which the default FM curve
/// starts: the range runs from where |Δf| has decayed to it down to contact, which is also the
/// range a Sader–Jarvis reconstruction needs (its integrals run to where the shift vanishes).
/// Half of `reconstruct`'s truncation threshold ([`super::reconstruct::DECAYED`]): the
/// default range comes from an estimate of the shift (the cycle mean of [`default_from`]),
/// and the computed curve's first point sits a little above it (1.0033 % where the two were
/// equal), so a default `fm` curve handed to `reconstruct` must start with a margin below
/// the threshold, not on it.
pub(crate) const FM_DEFAULT_DECAY: f64 = super::reconstruct::DECAYED / 2.0;

/// The default first z_c of an FM curve at amplitude `a` ending at `to` (units of g₀): the
/// largest z_c whose estimated frequency shift is still `FM_DEFAULT_DECAY` of its value at
/// `to` (by bisection to round-off), from Giessibl's first-order shift, which is
/// proportional to the cosine-weighted mean force over a cycle,
/// Δf ∝ −⟨F(z_c + A cos θ) cos θ⟩_θ (Giessibl, *Phys. Rev. B* 56, 16010 (1997), eq. 11;
/// `crate::analysis::fm::law_force` the law's conservative force at distance d, the mean by
/// the midpoint rule over enough phases to resolve the closest approach, 40 across its
/// width √(2 d_min/A)). `None` when the law has no force before contact (the
/// shift at `to` is 0) or it does not decay within 10⁶ g₀.
pub fn default_from(base: &crate::Params, a: f64, to: f64) -> Option<f64> {
    // the integrand peaks at the closest distance d_min = to − A within |θ − π| ≈ √(2 d_min/A):
    // 40 phases across that width (at least 1024, at most 2²⁰ over the cycle)
    let d_min = (to - a)
        .max(base.contact_law.distance_offset())
        .max(1e-9 * a);
    let width = (2.0 * d_min / a).sqrt().min(1.0);
    let phases = ((40.0 * std::f64::consts::TAU / width).ceil() as usize).clamp(1024, 1 << 20);
    let shift = |z: f64| {
        (0..phases)
            .map(|k| {
                let theta = std::f64::consts::TAU * (k as f64 + 0.5) / phases as f64;
                crate::analysis::fm::law_force(base, z + a * theta.cos()) * theta.cos()
            })
            .sum::<f64>()
            / phases as f64
    };
    let target = FM_DEFAULT_DECAY * shift(to).abs();
    if !(target > 0.0 && target.is_finite()) {
        return None;
    }
    // out from `to` by doubling steps until the shift is below the target, then bisect
    let (mut lo, mut step) = (to, 1e-3 * a.max(1e-6));
    while shift(to + step).abs() > target {
        lo = to + step;
        step *= 2.0;
        if step > 1e6 {
            return None;
        }
    }
    let mut hi = to + step;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if shift(mid).abs() > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(hi)
}

impl FmRequest {
    /// The analysis' spec on `model`: the z_c grid (α5 values, from the far end), the amplitude
    /// in g₀, the mode and the tolerance.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `amplitude`, `mode`, `tolerance`, `from`, `to`, `step`
    /// or `points` (as an approach curve's); [`SimError::Params`] for a model invalid at an
    /// end of the grid.
    pub fn spec(&self, model: &Resolved) -> Result<FmSpec, SimError> {
        let length = model.units(true).length;
        let range = CurveRequest {
            from: self.from,
            to: self.to,
            step: self.step,
            points: self.points,
            ..CurveRequest::default()
        };
        range.check_finite()?;
        if let Some(a) = self.amplitude {
            let why = "must be > 0: the oscillation amplitude the controller holds";
            super::limits::positive("amplitude", a, why)?;
            if length != 1.0 {
                // an amplitude's range is the probe's amplitude's ([`crate::probe::ranges`]),
                // not a rest distance's
                crate::probe::ranges::refuse("amplitude", ("drive", "free_amplitude"), a)?;
            }
            // the model's lengths are in units of its A₀ (g₀): an amplitude 1e8 times smaller
            // or 1e4 times larger leaves nothing of the other length scales
            let (lo, hi) = (FM_AMPLITUDE_RANGE.0 * length, FM_AMPLITUDE_RANGE.1 * length);
            let why = "must be within [1e-8, 1e4] × the model's length unit (A₀ of a probe's \
                       [drive] free_amplitude): amplitudes are in m with a probe (100 pm is \
                       100e-12, or 100pm on the command line)";
            crate::error::within("amplitude", a, lo..=hi, why)?;
        }
        if length != 1.0 {
            range.check_si_distances()?;
        }
        let base = model.params;
        crate::error::within(
            "mode",
            self.mode,
            1..=base.modes,
            "must be in 1..=N, the number of modes of the model (1 for the point mass)",
        )?;
        super::limits::tolerance("tolerance", self.tolerance)?;
        let a = self.amplitude.map_or(1.0, |a| a / length);
        let offset = base.contact_law.distance_offset();
        let to = range.to.map_or(a + offset, |t| t / length);
        let from = match range.from {
            Some(f) => f / length,
            None => default_from(&base, a, to).unwrap_or(2.0 * a + offset),
        };
        let values = approach_spec(base, from, to, range.spacing(length)?)
            .map_err(|e| super::curves::in_units(e, length))?
            .values;
        for v in [values[0], values[values.len() - 1]] {
            base.with(crate::params::SweepParam::Alpha5, v).validate()?;
        }
        let needs = [("bandwidth", self.bandwidth)];
        super::limits::optional_kt(self.temperature, &needs, model)?;
        let positive = |b| super::limits::positive("bandwidth", b, "must be > 0 (Hz)");
        self.bandwidth.map(positive).transpose()?;
        let mut spec = FmSpec::new(base, values, a);
        spec.mode = self.mode;
        spec.tolerance = self.tolerance;
        Ok(spec)
    }
}

impl_request! {
    FmRequest, "fm", advice = "ask for fewer points", needs = Tapping;
    validate |r, model| {
        super::curves::check_single_frequency(&model.params, "fm")?;
        r.spec(model).map(|_| ())
    };
    // every z_c: up to MAX_LOOP_ITERATIONS × MAX_HALVINGS steps of the phase loop, each a
    // Newton solve of the period-1 orbit; a point's orbit and observables kept
    cost |r, model| {
        let spec = r.spec(model)?;
        let p = &spec.base;
        let points = spec.values.len() as f64;
        let steps = (MAX_LOOP_ITERATIONS * MAX_HALVINGS) as f64;
        // the loop's noise: the orbit's chain over a period in 1 024 parts (the lock-in's two
        // NOISE_PERIODS per 512) and five cycles of its differences
        let noise = r.temperature.map_or(0.0, |_| (4.0 * NOISE_PERIODS + 5.0) * p.modes as f64);
        Ok(Cost {
            bytes: MODEL_BYTES + points * (4.0 * state_bytes(p) + 512.0),
            work: points * (steps * newton_work(p, 1, &spec.newton) + noise),
        })
    }
}

//! The time average of a multifrequency drive's steady state: a point of a stepped sweep
//! measured as an instrument measures it, for a drive whose common period is too long to shoot
//! (a quasi-periodic drive, [`crate::params::Params::is_quasiperiodic`]) or when asked for
//! ([`SteppedSpec::average`]).
//!
//! At each value the motion is integrated on from the previous value's end state (τ and z: the
//! drive's components keep their phases, as in an instrument whose z_c moves), in windows of
//! [`AverageOptions::window_periods`] primary drive periods 2π/Ω, each component demodulated
//! over a Hann² window (`observe_tapered`), until two successive windows' phasors
//! A_i e^{iφ_i} differ by at most [`AverageOptions::tol`] of each free amplitude A₀ᵢ (or the
//! point's transient cap, `transient_cap`, is spent: the point is then reported unsettled).
//! The point's observables are then measured over one such window of
//! [`AverageOptions::windows`] such windows.
//!
//! **Convergence estimate.** A transient that decays by the factor ρ per window leaves, after
//! windows that differed by Δ, at most Δρ/(1 − ρ) in the next (the geometric series); the
//! part of Δ that does not decay — the window's finite resolution of the motion's
//! combination tones m Ω + n ω₂ — is at most Δ in a window as long, less in the longer measured
//! one. [`AverageEstimate`] reports |ΔZ_i| max(1, ρ/(1 − ρ)) per component, with ρ the
//! larger of exp(−λL) from the slowest free decay rate λ
//! ([`TipSampleSystem::free_decay_rate`]) over the window's length L and the ratio of the last
//! two windows' differences when that is below 1 (the observed contraction: near a fold the
//! transient decays more slowly than the free one): an estimate, not a bound.

use super::{transient_cap, CurvePoint, Reached, SteppedSpec};
use crate::analysis::observables::{observe_tapered, ObservableOptions, Observables};
use crate::error::{within, SimError};
use crate::integrate::build;
use crate::model::CantileverModel;
use crate::tip_sample::TipSampleSystem;
use nalgebra::Complex;
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// Fewest primary drive periods in a settling window ([`AverageOptions::for_model`]).
pub(crate) const MIN_WINDOW_PERIODS: usize = 16;
/// Frequency bins 2π/L between a drive frequency and the nearest harmonic of another in a
/// settling window of length L ([`AverageOptions::for_model`]): the Hann² window's main lobe
/// spans ±3 bins, and 8 bins away its transform is 3e-5 of its peak.
pub(crate) const RESOLUTION: f64 = 8.0;
/// Highest harmonic of each drive frequency kept [`RESOLUTION`] bins from the others.
pub(crate) const RESOLVED_HARMONIC: u32 = 10;
/// Largest denominator q of the fractions p/q whose combination tones [`slowest_beat`] follows.
pub(crate) const BEAT_DENOMINATOR: u32 = 32;
/// Beats of [`slowest_beat`] per settling window: 3 or more put the beat's sidebands on the
/// zeros of the Hann² window's transform (it vanishes at every whole bin from the third on).
pub(crate) const BEATS_PER_WINDOW: f64 = 4.0;
/// Longest settling window the defaults choose ([`AverageOptions::for_model`]): a slower beat
/// leaves the point unsettled, and the warning says why.
pub(crate) const MAX_DEFAULT_WINDOW: usize = 4096;

/// The slowest beat of a multifrequency drive's combination tones: for each component's ratio
/// r = f_i/f₁ its best rational approximation p/q with q ≤ `BEAT_DENOMINATOR`
/// (`crate::params::convergent_within`), whose tone q f_i − p f₁ = q f₁ (r − p/q) a tapping
/// tip's nonlinearity makes: the motion's averages over windows shorter than its period
/// 1/(q |r − p/q|) primary periods follow the beat instead of settling (at f₂ = 1761/281 f₁,
/// 94/15: the beat is the common period, 281 periods). The slowest over the components as
/// (p, q, r, its period in primary periods); `None` when every ratio is such a fraction.
pub(crate) fn slowest_beat(p: &crate::params::Params) -> Option<(u32, u32, f64, f64)> {
    p.components()
        .filter_map(|c| {
            let r = c.ratio();
            let (a, b) = crate::params::convergent_within(r, BEAT_DENOMINATOR)?;
            let off = (r - f64::from(a) / f64::from(b)).abs();
            (off > 0.0).then(|| (a, b, r, 1.0 / (f64::from(b) * off)))
        })
        .max_by(|x, y| x.3.total_cmp(&y.3))
}

/// How the time average settles and measures ([`SteppedSpec::average`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AverageOptions {
    /// Primary drive periods 2π/Ω per settling window, in 1..=100000.
    pub window_periods: usize,
    /// Settling windows in the measured window, in 1..=1000.
    pub windows: usize,
    /// Settled when two successive windows' phasors A_i e^{iφ_i} differ by at most this
    /// fraction of each component's free amplitude A₀ᵢ, in [1e-12, 1e-2].
    pub tol: f64,
}

impl AverageOptions {
    /// The defaults for `model`'s drive, from its frequencies and its decay time: settling
    /// windows of at least `MIN_WINDOW_PERIODS` periods, long enough that every drive
    /// frequency (Ω and p/q Ω of every component) lies `RESOLUTION` frequency bins from the
    /// harmonics up to the `RESOLVED_HARMONIC`th of the others — where a tapping tip's
    /// strongest combination tones lie, so that they do not beat in the demodulation (at
    /// f₂ = 6.27 f₁ the 6th harmonic of f₁ is 0.27 f₁ from f₂: 30 periods) — and at least
    /// half the slowest free mode's decay time 1/λ, so that the transient changes between
    /// windows by a sizeable factor (e^{−1/2}; at Q = 400, 64 periods), and at least four
    /// periods of the slowest beat of the combination tones (`slowest_beat`), up to
    /// `MAX_DEFAULT_WINDOW` periods in all; four of them measured;
    /// tolerance 1e-5 (in contact the windows of a 40 N/m lever tapping polystyrene at
    /// f₂ = 6.27 f₁ still differ by 1e-6 of A₀ after 20 000 periods: combination tones of high
    /// order).
    pub fn for_model(model: &CantileverModel) -> Self {
        let p = model.params();
        let freqs: Vec<f64> = std::iter::once(1.0)
            .chain(p.components().map(|c| c.ratio()))
            .collect();
        let mut gap = f64::INFINITY;
        for (i, &ri) in freqs.iter().enumerate() {
            for (j, &rj) in freqs.iter().enumerate() {
                if i == j {
                    continue;
                }
                for h in 1..=RESOLVED_HARMONIC {
                    let d = (f64::from(h) * rj - ri).abs();
                    // an exact coincidence is a commensurate frequency, not a beat
                    if d > 1e-9 * ri {
                        gap = gap.min(d);
                    }
                }
            }
        }
        // a frequency difference Δr (in units of Ω) spans Δr n bins over n periods
        let resolve = RESOLUTION / gap;
        // (in primary periods 2π/Ω: model.period() is the common period of a commensurate drive)
        let decay = model
            .free_decay_rate()
            .map_or(0.0, |l| 0.5 * model.omega() / (l * TAU));
        let beat = slowest_beat(p).map_or(0.0, |b| BEATS_PER_WINDOW * b.3);
        let n = resolve.max(decay).max(beat).ceil();
        AverageOptions {
            window_periods: if n.is_finite() {
                (n as usize).clamp(MIN_WINDOW_PERIODS, MAX_DEFAULT_WINDOW)
            } else {
                MIN_WINDOW_PERIODS
            },
            windows: 4,
            tol: 1e-5,
        }
    }

    /// Check the ranges of the fields.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming the field.
    pub fn check(&self) -> Result<(), SimError> {
        within(
            "average.window_periods",
            self.window_periods,
            1..=100_000,
            "must be in 1..=100000 (drive periods per settling window)",
        )?;
        within(
            "average.windows",
            self.windows,
            1..=1000,
            "must be in 1..=1000 (settling windows in the measured window)",
        )?;
        within(
            "average.tol",
            self.tol,
            1e-12..=1e-2,
            "must be in [1e-12, 1e-2] (relative to each free amplitude)",
        )?;
        Ok(())
    }
}

/// How far a time-averaged point may be from the steady state's average (module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AverageEstimate {
    /// Primary drive periods integrated at this point: its settling windows and the measured
    /// one.
    pub periods: usize,
    /// Whether two successive windows agreed to [`AverageOptions::tol`] within the point's
    /// transient cap; `false`: the estimate is that of the last two windows, and the point may
    /// still be on its transient.
    pub settled: bool,
    /// Per drive component (the primary first): the estimate of the error of A_i (model length
    /// units, g₀).
    pub amplitude_error: Vec<f64>,
    /// Per drive component: the estimate of the error of φ_i (rad), the amplitude's over A_i.
    pub phase_error: Vec<f64>,
}

/// Each component's phasor A_i e^{iφ_i} and free amplitude of a window.
fn phasors(o: &Observables) -> Vec<(Complex<f64>, f64)> {
    o.components
        .iter()
        .map(|c| (Complex::from_polar(c.amplitude, c.phase), c.free_amplitude))
        .collect()
}

/// The time-averaged point at `value` from the end (τ, z) of `prev` (from rest at τ = 0 for
/// the first point).
///
/// # Errors
/// [`SimError::Params`] for an invalid value; [`SimError`] from the integrator or the
/// observables.
pub(super) fn average_point(
    spec: &SteppedSpec,
    opts: &AverageOptions,
    value: f64,
    prev: Option<&CurvePoint>,
) -> Result<CurvePoint, SimError> {
    let model = CantileverModel::quasiperiodic(&spec.base.with(spec.param, value))?;
    let (tau0, z0) = prev.map_or_else(|| (0.0, model.rest()), |p| (p.tau, p.state.clone()));
    let mut integ = build(&model, spec.integrator.clone(), tau0, &z0)?;
    let cap = transient_cap(&model, spec);
    let w = opts.window_periods;
    let window = ObservableOptions {
        periods: w,
        harmonics: spec.observables.harmonics,
    };
    let mut periods = 0;
    let mut last: Option<Vec<(Complex<f64>, f64)>> = None;
    let mut diff: Vec<f64> = Vec::new();
    let mut before: Vec<f64> = Vec::new();
    let mut settled = false;
    while periods + w <= cap.max(2 * w) {
        let z = phasors(&observe_tapered(integ.as_mut(), &window)?);
        periods += w;
        if let Some(prev) = &last {
            before = std::mem::take(&mut diff);
            diff = z
                .iter()
                .zip(prev)
                .map(|(a, b)| (a.0 - b.0).norm())
                .collect();
            if diff.iter().zip(&z).all(|(d, (_, a0))| *d <= opts.tol * a0) {
                settled = true;
                break;
            }
        }
        last = Some(z);
    }
    let measured = ObservableOptions {
        periods: w * opts.windows,
        harmonics: spec.observables.harmonics,
    };
    let observables = observe_tapered(integ.as_mut(), &measured)?;
    periods += measured.periods;
    // the geometric tail of a transient decaying by ρ per window (module docs): ρ the free
    // decay's, or the observed ratio of the last two differences where that is slower (near a
    // fold the transient slows down)
    let free_rho = model
        .free_decay_rate()
        .map_or(1.0, |l| (-l * w as f64 * TAU / model.omega()).exp());
    let amplitude_error: Vec<f64> = diff
        .iter()
        .enumerate()
        .map(|(i, d)| {
            let seen = before
                .get(i)
                .map_or(0.0, |b| if *b > 0.0 { d / b } else { 0.0 });
            let rho = if seen < 1.0 {
                free_rho.max(seen)
            } else {
                free_rho
            };
            let factor = if rho < 1.0 {
                (rho / (1.0 - rho)).max(1.0)
            } else {
                f64::INFINITY
            };
            d * factor
        })
        .collect();
    let phase_error = amplitude_error
        .iter()
        .zip(&observables.components)
        .map(|(e, c)| e / c.amplitude)
        .collect();
    Ok(CurvePoint {
        value,
        period: None,
        state: integ.state().clone(),
        tau: integ.tau(),
        multipliers: Vec::new(),
        monodromy: None,
        stable: true,
        reached: if prev.is_some() {
            Reached::Settled
        } else {
            Reached::Start
        },
        observables,
        average: Some(AverageEstimate {
            periods,
            settled,
            amplitude_error,
            phase_error,
        }),
        circle: None,
        fallback: None,
        free_decay_wait: false,
    })
}

//! Off-resonance (PeakForce) tapping: the steady tap of a lever whose sample (or base) is
//! modulated sinusoidally far below the lever's resonance, and the instrument's channels.
//!
//! **Model.** The modulation is the drive of [`crate::params::Excitation::Sample`] (the sample
//! moves, the lever's frame is at rest) or, for the beam, the paper's base drive (eq. 14, the
//! base's inertial term included): V_T = W(1,τ) + α5 + α2 sin Ωτ (eq. 8) with Ω = ω_m/ω̃ the
//! modulation frequency and α2 the modulation amplitude. In the instrument's convention the
//! sample sits at z_c + A_m cos 2πf_m t with t = 0 at the largest separation, which is
//! Ωτ = π/2 here: every time this module reports (the [`Cycle`], the snap-off time) is
//! t = τ − T/4, the integrators' phase is not changed.
//!
//! **Steady state.** The periodic orbit of the modulation period T = 2π/Ω (20–1 000 lever
//! periods), found as every steady state of afmdyn is: the transient settled by
//! [`steady_state`] (with Newton from the transient on slowly decaying levers), then shooting
//! on the period-n stroboscopic map for the orbit and its Floquet multipliers
//! ([`ShootingStrategy::BroydenFromZero`] where Broyden's updates pay, `broyden_pays`, and the
//! law is not hysteretic, else Newton; unwatched for grazing,
//! [`ShootingOptions::watch_grazing`]). A period-2 tapping is
//! reported as period 2 ([`SteadyTap::period`]); double taps show as
//! [`TapChannels::taps_per_cycle`] > 1. The integrators' steps and switching search follow
//! the fastest mode of the lever, not the modulation period (their grids and tolerances are
//! per step; `tests/peakforce.rs` checks an orbit at f₀/f_m = 100 against an
//! independent RK4 integration).
//!
//! **Channels** (model units: g₀, τ, the force unit F̃; the request converts to SI):
//! peak force, adhesion (the most negative force), deformation (the largest indentation −V_T),
//! dissipation (E_dis = −∮F_c ḋ dτ per period, [`super::observables`]), contact time, the
//! snap-off time (the last exit from contact in the cycle, from t = 0), the ringing amplitude
//! (after snap-off, the largest |W − c F_c| with c = φ(1)ᵀK⁻¹φ(1) the lever's static
//! compliance at the tip: the deviation from the quasi-static deflection) and the DMT fit of
//! the retract curve (`fit_dmt`) on the force the instrument measures, W/c (k × deflection),
//! against the distance d (the instrument's separation, z-piezo plus deflection), and the
//! same fit on the true force F_c: the channels are the true tip–sample force's, the fit
//! shows the instrument method's bias.

mod filter;
mod fit;
pub(crate) mod noise;
#[cfg(test)]
pub(crate) use noise::batch_variance;
mod setpoint;

pub use filter::low_pass_periodic;
pub(crate) use fit::MIN_FIT_POINTS;
pub use fit::{fit_dmt, DmtFit, FIT_BAND};
pub use noise::{
    simulated_tap_noise, tap_noise, SimulatedTapNoise, TapNoise, MAX_PEAK_SHIFT, MIN_THERMAL_CYCLES,
};
pub use setpoint::{
    peak_force_setpoint, SetpointOptions, SetpointTap, BRACKET_STEPS, SETPOINT_ITERATIONS,
    SETPOINT_TOL,
};

use super::observables::{observe, ObservableOptions};
use super::shooting::{broyden_pays, shoot, ShootingOptions, ShootingStrategy};
use super::steady::{steady_state, Motion, SteadyOptions};
use crate::error::{within, SimError};
use crate::galerkin::Region;
use crate::integrate::dense::{sample_dense, SpanSampling, StartSample};
use crate::integrate::{Integrator, IntegratorOptions};
use crate::maps::StroboscopicMap;
use crate::model::CantileverModel;
use nalgebra::{Complex, DVector};
use serde::Serialize;

/// Fewest samples of the reported cycle (the issue's ≥ 2 000 points per period).
pub(crate) const MIN_CYCLE_SAMPLES: usize = 2_000;
/// Most samples of the reported cycle (a budget: 8 bytes × 4 channels each).
pub(crate) const MAX_CYCLE_SAMPLES: usize = 1_000_000;
/// Samples of the retract branch resampled for the DMT fit, between the peak force and the
/// pull-off: the contact point d₀ is the distance at the force minimum, and a coarse grid
/// would misplace it by a sample's travel (the fit's δ^{3/2} is sensitive to d₀).
pub(crate) const FIT_SAMPLES: usize = 20_000;

/// Options of `steady_tap`.
#[derive(Debug, Clone)]
pub struct PeakForceOptions {
    /// Samples of the reported cycle, in `MIN_CYCLE_SAMPLES`..=`MAX_CYCLE_SAMPLES`.
    pub samples: usize,
    /// The force fractions (lo, hi) of the retract curve's range [adhesion, peak] the DMT fit
    /// uses (`FIT_BAND`, 0 ≤ lo < hi ≤ 1).
    pub fit_band: (f64, f64),
    /// The transient's settling (the default: tolerance 1e-8, cap from the slowest decay).
    pub steady: SteadyOptions,
    /// Newton's tolerance and iteration cap for the orbit (its period, strategy and grazing
    /// watch are the tap's).
    pub shooting: ShootingOptions,
    /// The integrator.
    pub integrator: IntegratorOptions,
}

impl Default for PeakForceOptions {
    fn default() -> Self {
        PeakForceOptions {
            samples: 4_096,
            fit_band: FIT_BAND,
            steady: SteadyOptions::default(),
            shooting: ShootingOptions::default(),
            integrator: IntegratorOptions::default(),
        }
    }
}

impl PeakForceOptions {
    /// Check the sample count and the fit band.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming the field.
    pub fn validate(&self) -> Result<(), SimError> {
        within(
            "samples",
            self.samples,
            MIN_CYCLE_SAMPLES..=MAX_CYCLE_SAMPLES,
            "must be in 2000..=1000000 (points of the reported cycle)",
        )?;
        let (lo, hi) = self.fit_band;
        if !(lo.is_finite() && hi.is_finite() && 0.0 <= lo && lo < hi && hi <= 1.0) {
            return Err(SimError::out_of_range(
                "fit_band",
                format!("[{lo}, {hi}]"),
                "must be fractions 0 ≤ lo < hi ≤ 1 of the retract curve's force range",
            ));
        }
        self.steady.validate()
    }
}

/// One period of the steady tap, sampled uniformly from the largest separation (t = 0).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Cycle {
    /// t = τ − T/4 from the largest separation, τ units, shape `[samples]`.
    pub time: Vec<f64>,
    /// Tip deflection W(1,τ) (positive away from the sample), g₀.
    pub deflection: Vec<f64>,
    /// Tip–sample distance d = V_T + [`crate::ContactLaw::distance_offset`], g₀.
    pub distance: Vec<f64>,
    /// Tip–sample force F_c (repulsive positive), F̃.
    pub force: Vec<f64>,
}

/// The instrument's channels of one steady tap, in model units (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TapChannels {
    /// Largest F_c over the period, F̃.
    pub peak_force: f64,
    /// The most negative F_c (≤ 0; 0 without attraction), F̃.
    pub adhesion: f64,
    /// The largest indentation max(−V_T, 0), g₀.
    pub deformation: f64,
    /// E_dis = −∮F_c ḋ dτ per period (tip–sample work), F̃·g₀.
    pub dissipation: f64,
    /// Time in contact per period, τ.
    pub contact_time: f64,
    /// Time of the last exit from contact, from the largest separation (t = 0), τ; NaN without
    /// contact.
    pub snap_off_time: f64,
    /// Largest |W − c F_c| after snap-off (c the static compliance at the tip), g₀; 0 without
    /// contact.
    pub ringing_amplitude: f64,
    /// Entries into contact per period: 1 for a single tap, 2 for a double tap.
    pub taps_per_cycle: f64,
}

/// The energy balance of one period (F̃·g₀): the lever's energy is periodic, so the work the
/// modulation does equals the lever's damping plus the tip–sample dissipation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EnergyBalance {
    /// ∮ F^I·ȧ dτ: the work of the base's inertial and drag forcing on the modes (eq. 14; 0
    /// for a moving sample).
    pub base_forcing: f64,
    /// ∮ ȧᵀC^I ȧ dτ: the lever's damping (air or liquid, eq. 12).
    pub lever_damping: f64,
    /// E_dis: the tip–sample dissipation.
    pub tip_sample: f64,
    /// The work of the modulation, base_forcing + the work of the moving sample (or base) on
    /// the tip–sample force: lever_damping + tip_sample − (the energy the modes received from
    /// the tip, which the lever's balance closes).
    pub modulation_work: f64,
    /// The lever's own balance, |Σ_j (drive − damping − sample)_j| per period: round-off on a
    /// periodic orbit.
    pub residual: f64,
}

/// The steady tap of `steady_tap`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SteadyTap {
    /// n: the orbit repeats after n modulation periods (2 for period-2 tapping).
    pub period: usize,
    /// Floquet multipliers of the period-n orbit, by decreasing modulus.
    #[serde(skip)]
    pub multipliers: Vec<Complex<f64>>,
    /// All multipliers inside the unit circle.
    pub stable: bool,
    /// Modulation periods of transient before the orbit was shot.
    pub transient_periods: usize,
    /// The state at τ = 0 (Ωτ = 0, the sample at its mean position moving down), `[2N + m]`.
    #[serde(skip)]
    pub state: DVector<f64>,
    /// The channels over the n periods (per period where a rate).
    pub channels: TapChannels,
    /// The DMT fit of the retract curve as the instrument measures it: the force k × deflection
    /// (the deflection W over the static compliance c) against the distance (`None` without a
    /// retract branch in contact). At f₀/f_m ≲ 20 the lever's inertia and ringing make the
    /// measured force differ from the tip–sample force: the fit's bias.
    pub fit: Option<DmtFit>,
    /// The same fit on the true tip–sample force F_c (the law's own curve, for comparison).
    pub fit_tip_sample: Option<DmtFit>,
    /// The energy balance per period.
    pub balance: EnergyBalance,
    /// One period (the first of n) sampled from t = 0.
    pub cycle: Cycle,
}

/// The steady tap of `model` (a modulated drive, [`crate::params::Excitation::Sample`] or the
/// beam's base drive): the orbit from rest, its channels and cycle (module docs).
///
/// # Errors
/// [`SimError::OutOfRange`] for bad options; [`SimError::NoConvergence`] when the transient
/// does not settle to a periodic orbit within its cap (reported, not hidden); [`SimError`]
/// from the integrator.
pub(crate) fn steady_tap(
    model: &CantileverModel,
    opts: &PeakForceOptions,
) -> Result<SteadyTap, SimError> {
    let z0 = DVector::zeros(model.params().state_dim());
    steady_tap_from(model, opts, &z0)
}

/// [`steady_tap`] from the state `z0` at τ = 0 (the neighbouring orbit of a sweep).
///
/// # Errors
/// As [`steady_tap`].
pub(crate) fn steady_tap_from(
    model: &CantileverModel,
    opts: &PeakForceOptions,
    z0: &DVector<f64>,
) -> Result<SteadyTap, SimError> {
    opts.validate()?;
    let mut map = StroboscopicMap::build(model, opts.integrator.clone(), z0, 1)?;
    let steady = steady_state(map.integrator(), &opts.steady)?;
    let n = match steady.motion {
        Motion::Periodic { period } => period,
        Motion::Nonperiodic => {
            return Err(SimError::NoConvergence {
                what: "the steady tap (the motion did not repeat within the transient cap)",
                residual: f64::NAN,
                iterations: steady.transient_periods,
            })
        }
    };
    let guess = steady.poincare[0].state.clone();
    // Broyden's updates from M ≈ 0 where the monodromy matrix costs variational equations
    // step by step: the tap's ringing decays over the cycle, its multipliers are small (not
    // for a hysteretic law, whose orbits are sensitive to the flows' steps)
    let broyden =
        broyden_pays(opts.integrator.clone(), model) && !map.integrator().system().is_hysteretic();
    let shooting = ShootingOptions {
        period: n,
        strategy: if broyden {
            ShootingStrategy::BroydenFromZero
        } else {
            ShootingStrategy::Newton
        },
        watch_grazing: false,
        ..opts.shooting
    };
    let orbit = shoot(&mut map, &guess, &shooting)?;
    let integ = map.integrator();
    integ.set_variational(false);
    let n = orbit.period;
    integ.reset(0.0, &orbit.state)?;
    let obs = observe(
        integ,
        &ObservableOptions {
            periods: n,
            harmonics: 1,
        },
    )?;
    let balance = {
        let sum = |f: &dyn Fn(&super::observables::ModeBalance) -> f64| -> f64 {
            obs.mode_balance.iter().map(f).sum()
        };
        // the observables' balances and E_dis are per modulation period already
        let (drive, damping, sample) = (
            sum(&|b| b.drive),
            sum(&|b| b.beam_damping),
            sum(&|b| b.sample),
        );
        EnergyBalance {
            base_forcing: drive,
            lever_damping: damping,
            tip_sample: obs.energy_dissipated,
            // the tip–sample force takes `sample` from the modes and dissipates E_dis: the
            // rest, E_dis − sample, comes from the moving sample (or base) through V_T
            modulation_work: drive + obs.energy_dissipated - sample,
            residual: (drive - damping - sample).abs(),
        }
    };
    integ.reset(0.0, &orbit.state)?;
    let cycle = sample_cycle(model, integ, opts.samples)?;
    let (snap_off_time, ringing_amplitude) = after_snap_off(model, &cycle);
    let (fit, fit_tip_sample) =
        retract_fit(model, integ, &orbit.state, &cycle, opts.fit_band)?.unwrap_or((None, None));
    Ok(SteadyTap {
        period: n,
        multipliers: orbit.multipliers,
        stable: orbit.stable,
        transient_periods: steady.transient_periods,
        state: orbit.state,
        channels: TapChannels {
            peak_force: obs.peak_force,
            adhesion: obs.min_force.min(0.0),
            deformation: obs.indentation,
            dissipation: obs.energy_dissipated,
            contact_time: obs.contact_time,
            snap_off_time,
            ringing_amplitude,
            taps_per_cycle: obs.impacts_per_period,
        },
        fit,
        fit_tip_sample,
        balance,
        cycle,
    })
}

/// The lever's first natural frequency as modelled (in its medium), in the units of Ω: 1 in
/// the lumped models' units, ≈ 3.516 in the beam's.
pub(crate) fn first_natural_frequency(model: &CantileverModel) -> f64 {
    crate::eigen::natural_modes(model.galerkin().region(Region::Free)).omega[0]
}

/// τ of the largest separation, T/4 (Ωτ = π/2: the sinusoid α2 sin Ωτ at its top).
pub(crate) fn time_origin(model: &CantileverModel) -> f64 {
    0.25 * model.period()
}

/// The force, deflection and distance at (τ, z).
fn tip_sample(model: &CantileverModel, tau: f64, z: &DVector<f64>) -> (f64, f64, f64) {
    let region = model.region_at(tau, z);
    let f = model.contact_force(region, tau, z);
    let w = model.w_tip(z);
    let d = model.v_t(tau, z) + model.law().distance_offset();
    (w, d, f)
}

/// Sample one period from t = 0 (τ = T/4) at `samples` uniform points; `integ` starts at the
/// orbit's state at τ = 0. The samples after the first are read from the integrator's dense
/// output ([`sample_dense`] with its start, [`StartSample::Included`]), the integrator taking
/// its own steps (spans where it has them, [`SpanSampling::Dense`]) instead of ending one at
/// every sample: the cycle's 4 096 samples and the fit's 20 000 ([`retract_fit`]) would
/// otherwise cut the lever's natural steps (a few per lever period) into hundreds of short
/// ones.
fn sample_cycle(
    model: &CantileverModel,
    integ: &mut dyn Integrator,
    samples: usize,
) -> Result<Cycle, SimError> {
    let (t, t0) = (model.period(), time_origin(model));
    let mut c = Cycle {
        time: Vec::with_capacity(samples),
        deflection: Vec::with_capacity(samples),
        distance: Vec::with_capacity(samples),
        force: Vec::with_capacity(samples),
    };
    let dt = |k: usize| t * k as f64 / samples as f64;
    let mut z = DVector::zeros(integ.state().len());
    let (spans, start) = (SpanSampling::Dense, StartSample::Included);
    sample_dense(
        integ,
        samples - 1,
        &|k| t0 + dt(k),
        spans,
        start,
        &mut |k, tau, s| {
            z.copy_from_slice(s);
            let (w, d, f) = tip_sample(model, tau, &z);
            c.time.push(dt(k));
            c.deflection.push(w);
            c.distance.push(d);
            c.force.push(f);
            Ok(())
        },
    )?;
    Ok(c)
}

/// The lever's static compliance at the tip, c = φ(1)ᵀK⁻¹φ(1) (free region, eq. 13): the
/// quasi-static deflection is c F_c.
pub(crate) fn static_compliance(model: &CantileverModel) -> f64 {
    let k = &model.galerkin().region(Region::Free).stiffness;
    let tip = model.tip();
    k.clone().lu().solve(tip).map_or(f64::NAN, |x| x.dot(tip))
}

/// The snap-off time (the last sample in contact, linearly interpolated to the crossing of
/// V_T = 0) and the ringing amplitude after it (module docs). (NaN, 0) without contact.
fn after_snap_off(model: &CantileverModel, c: &Cycle) -> (f64, f64) {
    let off = model.law().distance_offset();
    let n = c.time.len();
    let Some(last) = (0..n).rev().find(|&k| c.distance[k] - off <= 0.0) else {
        return (f64::NAN, 0.0);
    };
    let snap = if last + 1 < n {
        let (v0, v1) = (c.distance[last] - off, c.distance[last + 1] - off);
        let s = v0 / (v0 - v1);
        c.time[last] + s * (c.time[last + 1] - c.time[last])
    } else {
        c.time[last]
    };
    let compliance = static_compliance(model);
    let ringing = (last + 1..n)
        .map(|k| (c.deflection[k] - compliance * c.force[k]).abs())
        .fold(0.0, f64::max);
    (snap, ringing)
}

/// The retract branch's DMT fits: the instrument's (k × deflection) and the true force's.
type RetractFits = (Option<DmtFit>, Option<DmtFit>);

/// The DMT fits on the retract branch, resampled at [`FIT_SAMPLES`] points between the peak
/// force's sample and the pull-off (the force minimum after it): (the instrument's, on the
/// force it measures, the deflection over the static compliance, k × deflection; the same on
/// the true tip–sample force); `None` without contact.
fn retract_fit(
    model: &CantileverModel,
    integ: &mut dyn Integrator,
    z0: &DVector<f64>,
    c: &Cycle,
    band: (f64, f64),
) -> Result<Option<RetractFits>, SimError> {
    let n = c.time.len();
    let (peak, _) = c
        .force
        .iter()
        .enumerate()
        .fold(
            (0, f64::NEG_INFINITY),
            |(i, m), (k, &f)| if f > m { (k, f) } else { (i, m) },
        );
    let off = model.law().distance_offset();
    if !c.distance.iter().any(|&d| d - off <= 0.0) {
        return Ok(None);
    }
    // the force minimum after the peak (the retract's pull-off), within the cycle
    let (pull, _) = (peak..n).fold((peak, f64::INFINITY), |(i, m), k| {
        if c.force[k] < m {
            (k, c.force[k])
        } else {
            (i, m)
        }
    });
    let (a, b) = (peak.saturating_sub(1), (pull + 2).min(n - 1));
    if b <= a {
        return Ok(None);
    }
    let (t0, t1) = (c.time[a], c.time[b]);
    let origin = time_origin(model);
    integ.reset(0.0, z0)?;
    let compliance = static_compliance(model);
    let mut d = Vec::with_capacity(FIT_SAMPLES + 1);
    let (mut measured, mut f) = (d.clone(), d.clone());
    let time = |k: usize| origin + (t0 + (t1 - t0) * k as f64 / FIT_SAMPLES as f64);
    let mut z = DVector::zeros(z0.len());
    let (spans, start) = (SpanSampling::Dense, StartSample::Included);
    sample_dense(integ, FIT_SAMPLES, &time, spans, start, &mut |_, tau, s| {
        z.copy_from_slice(s);
        let (w, dk, fk) = tip_sample(model, tau, &z);
        d.push(dk);
        measured.push(w / compliance);
        f.push(fk);
        Ok(())
    })?;
    Ok(Some((fit_dmt(&d, &measured, band), fit_dmt(&d, &f, band))))
}

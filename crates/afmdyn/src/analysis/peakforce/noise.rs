//! A PeakForce tap's thermal noise: the standard deviations, from cycle to cycle, of its force
//! and its deformation at their peaks' times under the lever's thermal force, by linear
//! response about the steady tap ([`crate::analysis::orbit_noise`]: the deviations' chain over the orbit's n
//! modulation periods, its stationary covariance, and the covariance Σ(t) at the time t of the
//! channel's extremum).
//!
//! At the peak force's time t_p, dF_c/dτ = 0 on the orbit, so the peak of the perturbed path is
//! F_c(z*(t_p) + δz(t_p)) to first order whatever the shift of its time (the envelope theorem):
//! σ_F² = gᵀΣ(t_p)g with g = ∂F_c/∂z = −(∂F_c/∂δ φ(1), ∂F_c/∂δ̇ φ(1)) on (a, ȧ). The same holds
//! for the deformation, the largest −V_T, with g = −(φ(1), 0). t_p is the walk's part end of the
//! largest F_c (of −V_T): the parts are ω_c ℓ ≤ [`crate::analysis::orbit_noise::ETA`] in contact,
//! so g is taken within ETA/2 of the contact's phase from the extremum.
//!
//! **Validity.** This is the channel's σ at the peak's time, which is the per-cycle maximum's
//! while the peak is sharp against the noise. Near a flat peak the noise's own slope ṅ moves
//! the maximum: M ≈ F(t_p) + n(t_p) + ṅ(t_p)²/(2|F''|), a mean shift E\[ṅ²\]/(2|F''|) (ṅ the
//! elastic part of the channel's rate, ∂F_c/∂δ δ̇; F'' the orbit's curvature at the peak, by
//! the three parts about it). Where that shift passes [`MAX_PEAK_SHIFT`] σ
//! ([`TapNoise::flat_peak`]) each cycle's peak is the largest of several fluctuations, higher
//! and narrower in spread: the point mass of `examples/probe-peakforce-amo-garcia.toml` at
//! f₀/f_m = 10 to 100 (shifts 0.05–0.35) and the tests' taps (0.2) give σ within 5 % of the
//! simulated maxima's ([`simulated_tap_noise`]); the water beam of
//! `examples/probe-peakforce-water.toml`, pressed quasi-statically for 30 relaxation times
//! (shift 42), gives the equipartition σ at the peak's time while the maxima spread half as
//! much. The linear response also holds only while the noise moves the tap smoothly. A tap that
//! jumps to contact (out of contact the attraction's stiffness −∂F_c/∂δ passes the lever's
//! static stiffness at the tip, 1/c: [`TapNoise::snap_in`]) does not: near the jump the noise
//! moves its timing and speed nonlinearly, and rare cycles tap much harder. On a point-mass
//! lever of 2 N/m, 70 kHz, Q = 20 over polystyrene (DMT, R = 10 nm, f₀/f_m = 10, 2 nm past the
//! tip's rest) the simulated peak force's variance over 6 000 cycles is 8× the linear
//! response's with H = 6.6·10⁻²⁰ J (a jump to contact; its 1–50 % quantiles still span the
//! linear response's σ within 15 %), and equal to it within its standard error with
//! H = 10⁻²¹ J (no jump; the test below).
//!
//! The thermal force is the lever's and the medium's, and SLS's dashpot's; a nonlinear
//! sample's own dissipation adds none (a force of the state), and the impact law is refused
//! ([`crate::analysis::orbit_noise`]; JKR's neck and the capillary meniscus are carried from
//! part to part). Under SLS the peak force's
//! gradient holds its rate on the dashpot's extension u, ∂F_c/∂u = −κ.

use crate::analysis::orbit_noise::{Chain, Walk, ETA};
use crate::error::SimError;
use crate::galerkin::Region;
use crate::integrate::exact::{ThermalExact, ThermalForce};
use crate::integrate::{advance, Integrator, IntegratorOptions};
use crate::model::CantileverModel;
use nalgebra::DVector;
use serde::Serialize;

/// The standard deviations of a tap's channels at their peaks' times under the thermal force,
/// from cycle to cycle (model units; NaN where the orbit has no stationary noise, an unstable
/// tap): the per-cycle maxima's where the peaks are sharp ([`TapNoise::flat_peak`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize)]
pub struct TapNoise {
    /// σ of the peak force, F̃ (0 where no force acts over the cycle).
    pub peak_force: f64,
    /// σ of the deformation, g₀ (0 without contact).
    pub deformation: f64,
    /// Whether the tap jumps to contact: somewhere out of contact the attraction's stiffness
    /// −∂F_c/∂δ passes the lever's static stiffness at the tip, 1/c (module docs). The noise
    /// then moves the jump nonlinearly and the linear response gives the peaks' Gaussian core,
    /// not their tail.
    pub snap_in: bool,
    /// Whether a channel's peak is flat against the noise (module docs): the per-cycle maximum
    /// is then an extreme over several fluctuations, narrower and higher than the linear
    /// response's σ at the peak's time.
    pub flat_peak: bool,
}

/// A channel's extremum along the walk: its value, the chain there, the channel's gradient g
/// and its rate's gradient g_v on the deviation (the rate's elastic part, module docs), and the
/// channel's values at the parts before and after it (τ, value) for its curvature.
#[derive(Default)]
struct Extremum {
    value: f64,
    at: Option<(Chain, DVector<f64>, DVector<f64>)>,
    before: (f64, f64),
    after: Option<(f64, f64)>,
    tau: f64,
}

impl Extremum {
    /// Follow the channel's value `v` at the walk's part end (τ, `chain`): a new extremum takes
    /// the gradients `grads` (g, g_v) there; the first part after the extremum is kept.
    fn follow(
        &mut self,
        (tau, v): (f64, f64),
        previous: (f64, f64),
        chain: &Chain,
        grads: impl FnOnce() -> (DVector<f64>, DVector<f64>),
    ) {
        if v > self.value || (self.at.is_none() && v != 0.0) {
            let (g, gv) = grads();
            *self = Extremum {
                value: v,
                at: Some((chain.clone(), g, gv)),
                before: previous,
                after: None,
                tau,
            };
        } else if self.after.is_none() && self.at.is_some() {
            self.after = Some((tau, v));
        }
    }

    /// σ of the channel at its extremum and whether the peak is flat against the noise
    /// (module docs), `y` the stationary covariance.
    fn sigma(&self, y: &nalgebra::DMatrix<f64>) -> (f64, bool) {
        let Some((chain, g, gv)) = &self.at else {
            return (0.0, false);
        };
        let sigma = chain.variance(y, g).sqrt();
        let Some((t1, v1)) = self.after else {
            return (sigma, false);
        };
        // the curvature by the three points about the extremum
        let ((t0, v0), (tp, vp)) = (self.before, (self.tau, self.value));
        let curvature = 2.0 * ((v1 - vp) / (t1 - tp) - (vp - v0) / (tp - t0)) / (t1 - t0);
        let rate = chain.variance(y, gv);
        let shift = rate / (2.0 * curvature.abs() * sigma);
        (
            sigma,
            shift > MAX_PEAK_SHIFT || !shift.is_finite() && sigma > 0.0,
        )
    }
}

/// Whether the tap's noise covers `law`: every law but the impact law, whose peak force while
/// it sticks is the constraint's force λ, which takes the thermal force's part at the tip
/// itself (M ä = f + ξ + φλ, φᵀä = 0): white, its peak has no finite σ but through a
/// detector's bandwidth, which the tap's linear response does not model.
///
/// # Errors
/// [`SimError::Unsupported`] naming the impact law.
pub(crate) fn admits(law: &crate::contact::ContactLaw) -> Result<(), SimError> {
    if law.restitution().is_none() {
        return Ok(());
    }
    Err(SimError::Unsupported {
        integrator: "linear response",
        law: law.name(),
        hint: "a PeakForce tap's thermal noise follows every law but the impact law, whose peak \
               force is the sticking constraint's, white with the thermal force: drop \
               temperature for it",
    })
}

/// The largest mean shift of a channel's per-cycle maximum by the noise's slope,
/// E\[ṅ²\]/(2|F''|), against its σ, for the linear response to be the maximum's (module docs):
/// measured up to 0.35 within 5 % of the simulated maxima's σ, at 42 twice it.
pub const MAX_PEAK_SHIFT: f64 = 1.0;

/// The tap's noise (module docs) on its orbit through (0, `z`) of `periods` modulation periods,
/// at k_B T = `kt` (model units), integrated with `integrator`.
///
/// # Errors
/// [`SimError::OutOfRange`] naming `kt` (negative or not finite); [`SimError::Unsupported`] for
/// the impact law; [`SimError::Cancelled`] when the run's watched flag is set
/// (`crate::analysis::progress::Progress::watch`); the integrator's and the flow's.
pub fn tap_noise(
    model: &CantileverModel,
    z: &DVector<f64>,
    periods: usize,
    kt: f64,
    integrator: IntegratorOptions,
) -> Result<TapNoise, SimError> {
    admits(&model.params().contact_law)?;
    let end = periods.max(1) as f64 * model.period();
    let h = ETA / super::first_natural_frequency(model);
    let mut walk = Walk::new(model, z, kt, 0, integrator)?;
    let (n, dim) = (model.modes(), z.len());
    let stiffness = 1.0 / super::static_compliance(model);
    let mut snap_in = false;
    let (mut peak, mut deep) = (Extremum::default(), Extremum::default());
    let mut previous = [(0.0, 0.0); 2];
    // a gradient on the deviation (a, ȧ): `da` on a, `dv` on ȧ, each times φ(1)
    let gradient = |da: f64, dv: f64| {
        let mut g = DVector::zeros(dim);
        for (j, &phi) in model.tip().iter().enumerate() {
            (g[j], g[n + j]) = (da * phi, dv * phi);
        }
        g
    };
    while walk.tau < end {
        crate::error::cancelled()?;
        walk.adaptive_part(end, h)?;
        let (tau, s, e) = (walk.tau, &walk.state, walk.force);
        snap_in |= walk.region == Region::Free && -e.d_delta > stiffness;
        // F_c's gradient −(∂F/∂δ φ, ∂F/∂δ̇ φ), its rate's elastic part −∂F/∂δ φ on ȧ
        let force_grads = || {
            let mut g = gradient(-e.d_delta, -e.d_rate);
            if dim > 2 * n {
                g[2 * n] = walk.force_u; // SLS's Maxwell arm on u
            }
            (g, gradient(0.0, -e.d_delta))
        };
        peak.follow((tau, e.force), previous[0], &walk.chain, force_grads);
        // the deformation −V_T: −φ on a, its rate −φ on ȧ
        let depth = -model.v_t(tau, s);
        let depth_grads = || (gradient(-1.0, 0.0), gradient(0.0, -1.0));
        deep.follow((tau, depth), previous[1], &walk.chain, depth_grads);
        previous = [(tau, e.force), (tau, depth)];
    }
    let Some(y) = walk.chain.stationary() else {
        return Ok(TapNoise {
            peak_force: f64::NAN,
            deformation: f64::NAN,
            snap_in,
            flat_peak: false,
        });
    };
    let ((f, flat_f), (d, flat_d)) = (peak.sigma(&y), deep.sigma(&y));
    Ok(TapNoise {
        peak_force: f,
        deformation: d,
        snap_in,
        flat_peak: flat_f || flat_d,
    })
}

/// Batches of the simulated run's per-cycle values whose mean squares give the standard
/// error of its variance ([`simulated_tap_noise`]).
const BATCHES: usize = 20;

/// Fewest modulation cycles of a simulated run: its `BATCHES` batches of at least 5.
pub const MIN_THERMAL_CYCLES: usize = 100;

/// The per-cycle peak force and deformation of a thermally driven run of the tap
/// ([`simulated_tap_noise`]; model units).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SimulatedTapNoise {
    /// Cycles measured (after the burn-in).
    pub cycles: usize,
    /// The seed of the thermal force's stream.
    pub seed: u64,
    /// σ of the peak force and its standard error (batch means), F̃.
    pub peak_force: [f64; 2],
    /// σ of the deformation and its standard error, g₀.
    pub deformation: [f64; 2],
    /// The peak force's 1 %, 50 % and 99 % quantiles over the cycles, F̃.
    pub peak_force_quantiles: [f64; 3],
    /// The deformation's 1 %, 50 % and 99 % quantiles, g₀.
    pub deformation_quantiles: [f64; 3],
}

/// The tap's noise measured on the thermally driven lever itself: the stochastic step of
/// [`crate::integrate::exact::noise`] (exact over the linear law, the exponential Euler step
/// over Hertz, DMT and the electrostatic law; the switchings the noise makes located on the
/// Gaussian bridge) from the orbit's state `z` at τ = 0, the thermal force of k_B T = `kt`
/// (model units) drawn from `seed`, over `cycles` modulation cycles after a burn-in of
/// `cycles`/10 (at least 20), each cycle's peak force and deformation the largest over
/// `samples` equally spaced points per modulation period (`periods` of them make the orbit's
/// cycle), points of the step's grid.
/// What the linear response ([`tap_noise`]) cannot give near a jump to contact: the tail.
/// σ's standard error is the spread of 20 batch means of the squared deviations
/// (batches much longer than the cycles' correlation).
///
/// # Errors
/// [`SimError::OutOfRange`] naming `cycles` (below [`MIN_THERMAL_CYCLES`]); the stochastic
/// step's ([`crate::integrate::exact::ThermalExact::new`]);
/// [`SimError::Cancelled`] when the run's watched flag is set.
pub fn simulated_tap_noise(
    model: &CantileverModel,
    z: &DVector<f64>,
    periods: usize,
    thermal: ThermalForce,
    cycles: usize,
    samples: usize,
) -> Result<SimulatedTapNoise, SimError> {
    crate::error::within(
        "thermal_cycles",
        cycles,
        MIN_THERMAL_CYCLES..=usize::MAX,
        "must be at least 100 modulation cycles",
    )?;
    // the orbit's cycle of n periods, `samples` points in each period, each on the grid
    let (cycle, points) = (
        periods.max(1) as f64 * model.period(),
        samples * periods.max(1),
    );
    let opts = IntegratorOptions {
        steps_per_period: samples,
        ..IntegratorOptions::default()
    };
    let mut it = ThermalExact::new(model, &opts, thermal)?;
    it.reset(0.0, z)?;
    let burn = (cycles / 10).max(20);
    let mut series = [Vec::with_capacity(cycles), Vec::with_capacity(cycles)];
    for c in 0..burn + cycles {
        crate::error::cancelled()?;
        let (mut force, mut depth) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
        for j in 1..=points {
            let tau = cycle * (c as f64 + j as f64 / points as f64);
            advance(&mut it, tau)?;
            let s = it.state();
            force = force.max(model.contact_force(model.region_at(tau, s), tau, s));
            depth = depth.max(-model.v_t(tau, s));
        }
        if c >= burn {
            series[0].push(force);
            series[1].push(depth.max(0.0));
        }
    }
    let [f, d] = series.map(|v| (sigma(&v), quantiles(v)));
    Ok(SimulatedTapNoise {
        cycles,
        seed: thermal.seed,
        peak_force: f.0,
        deformation: d.0,
        peak_force_quantiles: f.1,
        deformation_quantiles: d.1,
    })
}

/// σ of `v` and its standard error by batch means (the module's [`BATCHES`]).
fn sigma(v: &[f64]) -> [f64; 2] {
    let [var, se_var] = batch_variance(v, v.len() / BATCHES, BATCHES);
    let s = var.sqrt();
    // σ's standard error from the variance's, δσ = δ(σ²)/(2σ)
    [s, if s > 0.0 { se_var / (2.0 * s) } else { 0.0 }]
}

/// The variance of the series `v` about its mean and the variance's standard error, by the
/// mean squares of its first `batches` batches of `per` values (batches much longer than the
/// series' correlation: their spread is the standard error).
pub(crate) fn batch_variance(v: &[f64], per: usize, batches: usize) -> [f64; 2] {
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    let squares: Vec<f64> = (v.chunks_exact(per).take(batches))
        .map(|b| b.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / per as f64)
        .collect();
    let n = squares.len() as f64;
    let var = squares.iter().sum::<f64>() / n;
    let se = (squares.iter().map(|b| (b - var).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
    [var, se]
}

/// The 1 %, 50 % and 99 % quantiles of `v` (the nearest rank).
fn quantiles(mut v: Vec<f64>) -> [f64; 3] {
    v.sort_by(f64::total_cmp);
    [0.01, 0.5, 0.99].map(|q| v[((v.len() - 1) as f64 * q).round() as usize])
}

#[cfg(test)]
mod tests;

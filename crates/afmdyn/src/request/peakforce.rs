//! `peakforce`: off-resonance (PeakForce) tapping ([`crate::analysis::peakforce`]): the steady
//! tap at a mean rest separation z_c, or at the z_c an ideal peak-force feedback finds for a
//! setpoint, with the instrument's channels, one cycle and the force–distance curve — the
//! request the command line (`afmdyn peakforce`) and, by its name, Python and the browser
//! share (its document is made where it runs). With a probe everything is SI (m, N, J, s, Pa); without one the
//! model's units (g₀, F̃, F̃·g₀, τ).

use super::costs::{newton_work, state_bytes, steady_periods, MODEL_BYTES, NOISE_PERIODS};
use super::limits::Cost;
use super::run::Resolved;
use crate::analysis::peakforce;
use crate::analysis::peakforce::{
    PeakForceOptions, BRACKET_STEPS, FIT_BAND, MIN_THERMAL_CYCLES, SETPOINT_ITERATIONS,
};
use crate::error::SimError;
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};

pub use super::peakforce_sweep::{PeakForceSweep, PeakForceSweepParam, MAX_SWEEP_POINTS};

/// Largest modulation frequency relative to the lever's first resonance, f_m/f₀ (the model's Ω
/// over the lever's first natural frequency as modelled: Ω itself in the lumped models, Ω/3.516
/// on the beam): above it the drive is not off resonance (use `orbit` or `approach`).
pub(crate) const MAX_MODULATION_RATIO: f64 = 0.5;

/// The lever's first natural frequency as modelled, in the units of Ω (in its medium; 1 in the
/// lumped models' units, ≈ 3.516 in the beam's): f₀/f_m = this / Ω.
pub(crate) fn first_natural_frequency(p: &Params) -> f64 {
    CantileverModel::new(p).map_or(1.0, |m| peakforce::first_natural_frequency(&m))
}

/// The work of a thermally driven run per point of its cycles and mode, in mode-periods (0.8–3
/// µs): measured 0.22 µs on examples/probe-peakforce-amo-garcia.toml (one mode), 1.2 µs on
/// examples/probe-peakforce-air.toml and 2.7 µs on examples/probe-peakforce-water.toml (three
/// modes, a point each).
const SAMPLE_WORK: f64 = 1.0;

/// The thermal block's parts against the free lever's 512 per lever period (the contact's are
/// shorter): 1.7 measured on examples/probe-peakforce-air.toml at z_c = 97 nm (30 109 parts
/// for 17 920, 6.8 µs each), 1.04 on examples/probe-peakforce-amo-garcia.toml.
const NOISE_CONTACT: f64 = 2.0;

request! {
    /// `peakforce`: one steady off-resonance tap at `z_c` (m with a probe, else g₀) or at the z_c
    /// whose peak force is `setpoint` (N with a probe, else F̃).
    pub struct PeakForceRequest {
        /// The mean rest separation z_c (m with a probe, else g₀): the tip–sample distance with the
        /// lever at rest and the sample at the centre of its modulation; default the model's
        /// (the probe's `[sample] z_c`, default A_m). Excludes `setpoint`.
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "length")))]
        pub z_c: Option<f64>,
        /// The peak force the ideal feedback holds (N with a probe, else F̃), > 0: z_c is found so
        /// that the steady tap's peak force equals it. Excludes `z_c`.
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "force")))]
        pub setpoint: Option<f64>,
        /// Points of the reported cycle, in 2000..=1000000 (default 4096).
        pub samples: usize = 4_096,
        /// The DMT fit's band: fractions [lo, hi] of the retract curve's force range from the
        /// adhesion to the peak force (default [0.3, 0.9]).
        pub fit_band: [f64; 2] = [FIT_BAND.0, FIT_BAND.1],
        /// The instrument's low-pass filter on the measured force: the cut-off f_c (Hz with a
        /// probe, else cycles per τ) of a causal second-order Butterworth filter
        /// ([`crate::analysis::peakforce::low_pass_periodic`]) applied over the cycle to the force
        /// the instrument measures, k × deflection; the curve then carries it filtered beside the
        /// tip–sample force. `None` (default): no filter. f_c must lie below the Nyquist frequency
        /// of the cycle's samples, `samples`/(2 × the modulation period).
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "frequency")))]
        pub filter_cutoff: Option<f64>,
        /// A sweep in z_c or in the modulation frequency ([`PeakForceSweep`]): the channels as
        /// curves over its values (the document's `sweep` block), each tap continued from the
        /// previous tap's orbit; the single tap's blocks (`channels`, `cycle`, `curve`, …) are
        /// those of the first value computed. A sweep in z_c excludes `z_c` and `setpoint`; with
        /// `setpoint` a sweep in the modulation frequency holds the peak force at every value.
        /// `None` (default): one tap.
        pub sweep: Option<PeakForceSweep>,
        /// The temperature T of the thermal force (K, > 0 and ≤ 1500; outside 200–500 K it warns,
        /// a value in °C?); `None` (the default): no noise. With one the document gains a
        /// `"thermal"` block: the standard deviations, from cycle to cycle, of the tap's force
        /// and deformation at their peaks' times under the lever's thermal force, by linear
        /// response about the steady tap ([`crate::analysis::peakforce::tap_noise`]; the
        /// per-cycle maxima's where the peak is sharp); a sweep gains them as the channels
        /// `peak_force_noise` and `deformation_noise` of every value (the block is the
        /// single-tap blocks' tap's). Needs the probe's SI units; the impact law is refused (its
        /// peak force is the sticking constraint's, white with the thermal force; SLS's dashpot
        /// adds its own force).
        #[serde(skip_serializing_if = "Option::is_none")]
        pub temperature: Option<f64>,
        /// Modulation cycles of a thermally driven run of the tap (with `temperature`;
        /// 100..=1000000): the `"thermal"` block gains `simulated`, the per-cycle peak force's
        /// and deformation's σ (with standard errors) and quantiles measured on the lever itself
        /// ([`crate::analysis::peakforce::simulated_tap_noise`], each cycle sampled at
        /// `samples` points): what the linear response cannot give near a jump to contact.
        /// `None` (default): no run.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub thermal_cycles: Option<usize>,
        /// The seed of the thermal run's random stream (with `thermal_cycles`; default 0): the
        /// run is a function of its seed.
        #[cfg_attr(feature = "schema", schemars(extend("default" = 0)))]
        pub seed: u64 = 0,
    }
}

impl PeakForceRequest {
    /// The analysis' options.
    pub fn options(&self) -> PeakForceOptions {
        PeakForceOptions {
            samples: self.samples,
            fit_band: (self.fit_band[0], self.fit_band[1]),
            ..PeakForceOptions::default()
        }
    }

    /// Check the request on `model` and give the parameters of the tap (α5 from `z_c`).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `z_c`, `setpoint`, `samples`, `fit_band`, or the model's
    /// drive (`excitation`, `omega`) when it is no off-resonance modulation.
    pub fn params(&self, model: &Resolved) -> Result<Params, SimError> {
        let p = model.params;
        let off_resonance = match &model.probe {
            Some(pr) => pr.off_resonance,
            None => !p.is_force_driven() && !p.is_multifrequency(),
        };
        check_off_resonance(&p, off_resonance)?;
        self.options().validate()?;
        if let Some(fc) = self.filter_cutoff {
            // the cycle's sampling interval in the document's time unit (s with a probe), its
            // period's frequency (the modulation's) and the samples' Nyquist frequency; below
            // the modulation frequency the filter leaves little but the cycle's mean, and far
            // below it (1e-308) its periodic steady state is singular (issue 77 §3)
            let dt = self.sampling_interval(model, &p);
            let (modulation, nyquist) = (1.0 / (dt * self.samples as f64), 0.5 / dt);
            let why = format!(
                "must be a cut-off frequency from the modulation frequency, {modulation:.6e} \
                 (below it the filter leaves little but the cycle's mean), to below the Nyquist \
                 frequency of the cycle's samples, {nyquist:.6e} (raise samples to raise it)"
            );
            crate::error::within("filter_cutoff", fc, modulation..nyquist, why)?;
        }
        let length = model.units(true).length;
        let mut q = p;
        match (self.z_c, self.setpoint) {
            (Some(_), Some(_)) => {
                return Err(SimError::out_of_range(
                    "setpoint",
                    "given with z_c",
                    "give either z_c (the mean rest separation) or setpoint (the peak force \
                     the feedback holds), not both",
                ))
            }
            (Some(z), None) => {
                crate::error::finite("z_c", z)?;
                if model.probe.is_some() {
                    super::limits::si_distance("z_c", z)?;
                }
                q = p.with(SweepParam::Alpha5, p.alpha5_for_rest_distance(z / length));
            }
            (None, Some(f)) => super::limits::positive(
                "setpoint",
                f,
                "must be a finite peak force > 0 (N with a probe: 2 nN is 2e-9, or 2nN on the \
                 command line)",
            )?,
            (None, None) => {}
        }
        q.validate()?;
        self.thermal(model)?;
        self.check_steps(model, &q)?;
        if let Some(sweep) = &self.sweep {
            self.sweep_points(sweep, model, &q)?;
        }
        Ok(q)
    }

    /// k_B T of the `"thermal"` block (model units): `None` without a temperature.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `temperature` (out of range, without a probe);
    /// [`SimError::Unsupported`] for the impact law.
    pub(crate) fn thermal(&self, model: &Resolved) -> Result<Option<f64>, SimError> {
        let cycles = self.thermal_cycles.map(|n| n as f64);
        let kt =
            super::limits::optional_kt(self.temperature, &[("thermal_cycles", cycles)], model)?;
        let law = &model.params.contact_law;
        kt.map(|_| crate::analysis::peakforce::noise::admits(law))
            .transpose()?;
        if let Some(n) = self.thermal_cycles {
            let why = "must be at least 100 modulation cycles";
            crate::error::within("thermal_cycles", n, MIN_THERMAL_CYCLES.., why)?;
        }
        Ok(kt)
    }

    /// The integrator's steps per modulation period on `p` against its budget
    /// ([`crate::params::ADAPTIVE_STEPS_BUDGET`]), before any work (issue 77 §7): a refusal
    /// naming the modulation frequency (`modulation_frequency` in Hz with a probe, `omega`
    /// without) and the lowest one that fits (the steps scale as the period, 1/f_m), or the
    /// sample's stiffness where no modulation below the resonance fits.
    fn check_steps(&self, model: &Resolved, p: &Params) -> Result<(), SimError> {
        let m = crate::model::CantileverModel::new(p)?;
        let kind = self.options().integrator.kind.resolve(&m);
        let budget = crate::params::ADAPTIVE_STEPS_BUDGET;
        let Some(steps) = crate::integrate::steps_per_period(&m, kind) else {
            return Ok(());
        };
        if steps <= budget {
            return Ok(());
        }
        let (name, f, unit) = match &model.probe {
            Some(pr) => ("modulation_frequency", pr.drive_frequency, " Hz"),
            None => ("omega", p.omega, ""),
        };
        let f_min = f * steps / budget;
        // the highest modulation still off resonance, f_m/f₀ = MAX_MODULATION_RATIO
        let f_max = f * MAX_MODULATION_RATIO * first_natural_frequency(p) / p.omega;
        let advice = if f_min <= f_max {
            format!(
                "give {name} ≥ {}{unit}, or a softer sample",
                crate::error::number(f_min)
            )
        } else {
            "no modulation below the resonance fits: soften the sample (youngs_modulus) or \
             its contact"
                .into()
        };
        Err(SimError::out_of_range(
            name,
            format!("{}{unit}", crate::error::number(f)),
            format!(
                "on this lever and sample the integrator needs about {steps:.2e} steps per \
                 modulation period, beyond its budget of {budget:e} (the steps grow as f0/f_m \
                 and with the contact's stiffness): {advice}"
            ),
        ))
    }

    /// The cycle's sampling interval, the modulation period over `samples` (s with a probe,
    /// else τ).
    pub(crate) fn sampling_interval(&self, model: &Resolved, p: &Params) -> f64 {
        std::f64::consts::TAU / p.omega / self.samples as f64 * model.units(true).time
    }

    /// The model of every value of `sweep` (`p` the request's model with its checks done).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `sweep` (no values, too many, a value that is not
    /// finite, out of the probe's range of distances, or a frequency not off resonance), or
    /// `setpoint` with a sweep in z_c (the feedback sets z_c).
    pub(crate) fn sweep_points(
        &self,
        sweep: &PeakForceSweep,
        model: &Resolved,
        p: &Params,
    ) -> Result<Vec<Params>, SimError> {
        let n = sweep.values.len();
        let why = format!("must have 1..={MAX_SWEEP_POINTS} values");
        crate::error::within("sweep", n, 1..=MAX_SWEEP_POINTS, why)?;
        let units = model.units(true);
        let bad = |v: f64, why: &str| {
            SimError::out_of_range("sweep", v, format!("{}: {why}", sweep.quantity.name()))
        };
        let mut points = Vec::with_capacity(n);
        for &v in &sweep.values {
            if !v.is_finite() {
                return Err(bad(v, "every value must be finite"));
            }
            let q = match sweep.quantity {
                PeakForceSweepParam::ZC => {
                    if self.setpoint.is_some() || self.z_c.is_some() {
                        return Err(SimError::out_of_range(
                            "sweep",
                            "z_c with z_c or setpoint",
                            "a sweep in z_c excludes z_c and setpoint (the feedback sets z_c: \
                             sweep modulation_frequency with a setpoint)",
                        ));
                    }
                    if model.probe.is_some() {
                        super::limits::si_distance("sweep", v)?;
                    }
                    p.with(
                        SweepParam::Alpha5,
                        p.alpha5_for_rest_distance(v / units.length),
                    )
                }
                PeakForceSweepParam::ModulationFrequency => {
                    let omega = v / units.hz_per_omega.unwrap_or(1.0);
                    let q = p.with(SweepParam::Omega, omega);
                    if !(omega > 0.0 && omega / first_natural_frequency(&q) <= MAX_MODULATION_RATIO)
                    {
                        return Err(bad(
                            v,
                            "every modulation frequency must be > 0 and below half the \
                             lever's first resonance (f_m/f₀ ≤ 0.5)",
                        ));
                    }
                    q
                }
            };
            q.validate()?;
            points.push(q);
        }
        Ok(points)
    }
}

/// That `p`, whose drive is an off-resonance modulation where `off_resonance` (its probe's
/// drive mode, or a model's sample or base excitation at one frequency), is modulated below
/// half the lever's first resonance: a single tap's and a PeakForce image's check.
///
/// # Errors
/// [`SimError::OutOfRange`] naming `excitation` or `omega`.
pub(crate) fn check_off_resonance(p: &Params, off_resonance: bool) -> Result<(), SimError> {
    if !off_resonance {
        return Err(SimError::out_of_range(
            "excitation",
            p.excitation.name(),
            "peakforce needs a modulated sample or base: a probe with [drive] mode = \
             \"off-resonance\" (modulation_frequency, modulation_amplitude), or a model \
             with excitation = \"sample\" (or the beam's base drive) and one drive frequency",
        ));
    }
    if p.omega / first_natural_frequency(p) > MAX_MODULATION_RATIO {
        return Err(SimError::out_of_range(
            "omega",
            p.omega,
            "the modulation must lie below half the lever's first resonance (f_m/f₀ ≤ \
             0.5) to be off resonance",
        ));
    }
    Ok(())
}

/// The work of a tap's thermal noise ([`crate::analysis::peakforce::tap_noise`]) on `q`: its
/// walk over the tap, 512 parts per lever period, each like the lock-in's (NOISE_PERIODS per 512
/// parts), more in contact (NOISE_CONTACT).
pub(crate) fn noise_work(q: &Params) -> f64 {
    NOISE_CONTACT * NOISE_PERIODS * q.modes as f64 * first_natural_frequency(q) / q.omega
}

impl_request! {
    PeakForceRequest, "peakforce", advice = "ask for fewer samples or sweep values";
    validate |r, model| r.params(model).map(|_| ());
    // every tap: the transient (at most its cap) and Newton's variational flows, each drive
    // period spanning 1/Ω lever periods; the setpoint's bracket and iterations; the cycle and
    // the fit's resampling kept
    cost |r, model| {
        let p = r.params(model)?;
        let opts = r.options();
        let tap_work = |q: &Params| -> Result<f64, SimError> {
            let lever_periods = (1.0 / q.omega).max(1.0);
            Ok((steady_periods(&opts.steady, q)? * q.modes as f64
                + newton_work(q, 1, &opts.shooting))
                * lever_periods)
        };
        let points = match &r.sweep {
            Some(s) => r.sweep_points(s, model, &p)?,
            None => vec![p],
        };
        let tap = points.iter().map(tap_work).sum::<Result<f64, SimError>>()?;
        let taps = if r.setpoint.is_some() {
            (2 * BRACKET_STEPS + SETPOINT_ITERATIONS) as f64
        } else {
            1.0
        };
        let fit = crate::analysis::peakforce::FIT_SAMPLES as f64;
        let noise = r.temperature.map_or(0.0, |_| points.iter().map(noise_work).sum());
        // the thermally driven run: its cycles and burn-in (a tenth), `samples` points each,
        // a point SAMPLE_WORK per mode
        let per_cycle = 1.1 * r.samples as f64 * SAMPLE_WORK * p.modes as f64;
        let simulated = r.thermal_cycles.map_or(0.0, |n| n as f64 * per_cycle);
        // a sweep keeps every value's tap without its cycle (`study::peakforce`): the channels,
        // fits, multipliers and state, and the value's model
        let record = 2048.0 + 8.0 * state_bytes(&p) + std::mem::size_of::<Params>() as f64;
        // a sample of the cycle and its force curve, with the document's numbers and the
        // outcome's arrays: 640 bytes (measured 490 at 2048 and 8192 samples, `tests/door.rs`);
        // the fit's resampled curve, 4 columns of 8 bytes twice
        Ok(Cost {
            bytes: MODEL_BYTES
                + r.samples as f64 * 640.0
                + fit * 64.0
                + 64.0 * state_bytes(&p)
                + points.len() as f64 * record,
            // and the reported cycle's samples, each under a mode-period (1.3 µs measured)
            work: taps * tap + r.samples as f64 + noise + simulated,
        })
    };
    computed_at |r, model| r.params(model)
}

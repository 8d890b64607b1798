//! `peakforce`: off-resonance (PeakForce) tapping ([`crate::analysis::peakforce`]): the steady
//! tap at a mean rest separation z_c, or at the z_c an ideal peak-force feedback finds for a
//! setpoint, with the instrument's channels, one cycle and the force–distance curve — the
//! request the command line (`afmdyn peakforce`) and, by its name, Python and the browser
//! share, and its document. With a probe everything is SI (m, N, J, s, Pa); without one the
//! model's units (g₀, F̃, F̃·g₀, τ).

use super::peakforce_sweep::SweepTap;
use super::run::Resolved;
use crate::analysis::peakforce::{
    low_pass_periodic, static_compliance, Cycle, PeakForceOptions, SteadyTap, FIT_BAND,
    MAX_CYCLE_SAMPLES, MIN_CYCLE_SAMPLES,
};
use crate::error::SimError;
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use crate::report::CurveUnits;
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

pub use super::peakforce_sweep::{PeakForceSweep, PeakForceSweepParam, MAX_SWEEP_POINTS};

/// Largest modulation frequency relative to the lever's first resonance, f_m/f₀ (the model's Ω
/// over the lever's first natural frequency as modelled: Ω itself in the lumped models, Ω/3.516
/// on the beam): above it the drive is not off resonance (use `orbit` or `approach`).
pub(crate) const MAX_MODULATION_RATIO: f64 = 0.5;

/// The lever's first natural frequency as modelled, in the units of Ω (in its medium; 1 in the
/// lumped models' units, ≈ 3.516 in the beam's): f₀/f_m = this / Ω.
pub(crate) fn first_natural_frequency(p: &Params) -> f64 {
    CantileverModel::new(p).map_or(1.0, |m| {
        crate::eigen::natural_modes(m.galerkin().region(crate::galerkin::Region::Free)).omega[0]
    })
}

/// `peakforce`: one steady off-resonance tap at `z_c` (m with a probe, else g₀) or at the z_c
/// whose peak force is `setpoint` (N with a probe, else F̃).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(default, deny_unknown_fields)]
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
    pub samples: usize,
    /// The DMT fit's band: fractions [lo, hi] of the retract curve's force range from the
    /// adhesion to the peak force (default [0.3, 0.9]).
    pub fit_band: [f64; 2],
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
}

impl Default for PeakForceRequest {
    fn default() -> Self {
        PeakForceRequest {
            z_c: None,
            setpoint: None,
            samples: 4_096,
            fit_band: [FIT_BAND.0, FIT_BAND.1],
            filter_cutoff: None,
            sweep: None,
        }
    }
}

/// The result of a `peakforce` request: the tap and the α5 it was computed at.
#[derive(Debug, Clone)]
pub struct PeakForceResult {
    /// α5 of the tap (the request's z_c, or the setpoint's).
    pub alpha5: f64,
    /// The steady tap.
    pub tap: SteadyTap,
    /// Steady taps the setpoint's feedback computed (1 at a given z_c).
    pub evaluations: usize,
    /// The measured force k × deflection (F̃) over the cycle through the instrument's filter
    /// (with [`PeakForceRequest::filter_cutoff`]).
    pub filtered: Option<Vec<f64>>,
    /// Every value's tap of [`PeakForceRequest::sweep`], in its order.
    pub sweep: Option<Vec<SweepTap>>,
}

impl PeakForceRequest {
    /// The units of the document: SI with a probe, else the model's.
    pub(crate) fn units(model: &Resolved) -> CurveUnits {
        CurveUnits::of(model.probe.as_ref(), true)
    }

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
        if !off_resonance {
            return Err(SimError::out_of_range(
                "excitation",
                p.excitation.name(),
                "peakforce needs a modulated sample or base: a probe with [drive] mode = \
                 \"off-resonance\" (modulation_frequency, modulation_amplitude), or a model \
                 with excitation = \"sample\" (or the beam's base drive) and one drive frequency",
            ));
        }
        if p.omega / first_natural_frequency(&p) > MAX_MODULATION_RATIO {
            return Err(SimError::out_of_range(
                "omega",
                p.omega,
                "the modulation must lie below half the lever's first resonance (f_m/f₀ ≤ \
                 0.5) to be off resonance",
            ));
        }
        if !(MIN_CYCLE_SAMPLES..=MAX_CYCLE_SAMPLES).contains(&self.samples) {
            return Err(SimError::out_of_range(
                "samples",
                self.samples,
                "must be in 2000..=1000000 (points of the reported cycle)",
            ));
        }
        self.options().validate()?;
        if let Some(fc) = self.filter_cutoff {
            // the cycle's sampling interval in the document's time unit (s with a probe)
            let nyquist = 0.5 / self.sampling_interval(model, &p);
            if !(fc.is_finite() && fc > 0.0 && fc < nyquist) {
                return Err(SimError::out_of_range(
                    "filter_cutoff",
                    fc,
                    format!(
                        "must be a cut-off frequency > 0 below the Nyquist frequency of the \
                         cycle's samples, {nyquist:.6e} (raise samples to raise it)"
                    ),
                ));
            }
        }
        let length = Self::units(model).length;
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
            (None, Some(f)) => {
                if !(f.is_finite() && f > 0.0) {
                    return Err(SimError::out_of_range(
                        "setpoint",
                        f,
                        "must be a finite peak force > 0 (N with a probe: 2 nN is 2e-9, or \
                         2nN on the command line)",
                    ));
                }
            }
            (None, None) => {}
        }
        q.validate()?;
        self.check_steps(model, &q)?;
        if let Some(sweep) = &self.sweep {
            self.sweep_points(sweep, model, &q)?;
        }
        Ok(q)
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
}

impl PeakForceRequest {
    /// The cycle's sampling interval, the modulation period over `samples` (s with a probe,
    /// else τ).
    fn sampling_interval(&self, model: &Resolved, p: &Params) -> f64 {
        std::f64::consts::TAU / p.omega / self.samples as f64 * Self::units(model).time
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
        let request = self;
        let n = sweep.values.len();
        if n == 0 || n > MAX_SWEEP_POINTS {
            return Err(SimError::out_of_range(
                "sweep",
                n,
                format!("must have 1..={MAX_SWEEP_POINTS} values"),
            ));
        }
        let units = Self::units(model);
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
                    if request.setpoint.is_some() || request.z_c.is_some() {
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

    /// The measured force k × deflection (the deflection over the static compliance) of the
    /// tap's cycle through the filter of [`PeakForceRequest::filter_cutoff`], F̃.
    pub(crate) fn filtered(
        &self,
        model: &Resolved,
        p: &Params,
        tap: &SteadyTap,
    ) -> Result<Option<Vec<f64>>, SimError> {
        let Some(fc) = self.filter_cutoff else {
            return Ok(None);
        };
        let c = static_compliance(&CantileverModel::new(p)?);
        let measured: Vec<f64> = tap.cycle.deflection.iter().map(|w| w / c).collect();
        low_pass_periodic(&measured, fc * self.sampling_interval(model, p)).map(Some)
    }
}

/// The filter's words in the document (`filter.kind`).
pub(crate) const FILTER_KIND: &str =
    "second-order Butterworth low-pass (Butterworth 1930; bilinear \
     transform with the cut-off prewarped), causal as the instrument's real-time filter, in \
     its periodic steady state over the cycle, on the measured force k × deflection: \
     curve.approach_filtered_force and curve.retract_filtered_force";

/// The sample's true reduced modulus E* (Pa) of a Hertz-type law under a probe: from the
/// Hertz group α4 = (4/3)E*√R g₀^{3/2}/F_s (module docs of [`crate::probe`]).
fn true_modulus(model: &Resolved, alpha4: f64) -> Option<f64> {
    let pr = model.probe.as_ref()?;
    let r = pr.tip_radius?;
    let s = &pr.scales;
    Some(alpha4 * s.force_n / (4.0 / 3.0 * r.sqrt() * s.length_m.powf(1.5)))
}

/// A DMT fit whose root-mean-square residual passes this fraction of the fitted force range
/// is said not to be the DMT relation's shape.
pub(crate) const MAX_FIT_RESIDUAL: f64 = 0.1;
/// A modulus_dmt more than this fraction off the sample's own E* (which a simulation knows) is
/// said to be biased.
pub(crate) const MAX_MODULUS_BIAS: f64 = 0.1;

/// Why a single tap's `modulus_dmt` is missing, or where it is not the sample's modulus
/// (issue 77): no fit (too few retract points in the band), a fit residual above
/// [`MAX_FIT_RESIDUAL`], a reading more than [`MAX_MODULUS_BIAS`] off the sample's own E*
/// (Hertz group α4 of `p`). A double tap is said by its own warning.
fn modulus_warnings(tap: &SteadyTap, band: [f64; 2], p: &Params) -> Vec<String> {
    if tap.channels.taps_per_cycle > 1.0 + 1e-9 {
        return Vec::new();
    }
    let Some(fit) = tap.fit else {
        return vec![format!(
            "modulus_dmt is missing: the DMT fit needs at least {} retract points between {} and \
             {} of the force range from the adhesion to the peak force, and this tap's retract \
             has fewer there (a contact short against the cycle's samples: raise samples, or \
             widen fit_band)",
            crate::analysis::peakforce::MIN_FIT_POINTS,
            band[0],
            band[1]
        )];
    };
    let mut w = Vec::new();
    if fit.relative_residual > MAX_FIT_RESIDUAL {
        w.push(format!(
            "modulus_dmt: the DMT fit's relative residual is {:.3} (above {MAX_FIT_RESIDUAL}): \
             the retract curve in the fit band does not have the DMT relation's shape, so the \
             modulus is not meaningful",
            fit.relative_residual
        ));
    }
    let ratio = fit.hertz_group / p.alpha4;
    if (ratio - 1.0).abs() > MAX_MODULUS_BIAS {
        let law = p.contact_law.name();
        let other_law = match law {
            "hertz" | "dmt" => String::new(),
            _ => format!("a {law} sample read with the DMT relation, "),
        };
        w.push(format!(
            "modulus_dmt reads {ratio:.3} × the sample's own E* (more than {:.0} % off): the DMT \
             fit of this tap is biased ({other_law}the lever's inertia and ringing within the \
             tap, an indentation past the paraboloid's validity): compare it against a \
             calibration sample, not as the sample's modulus",
            MAX_MODULUS_BIAS * 100.0
        ));
    }
    w
}

/// The factor from the fitted Hertz group (model units) to the reduced modulus E* (Pa) of the
/// model `p` under the probe of `model`; `None` for a law without a tip radius (no modulus)
/// or without a probe (the Hertz group itself is reported).
pub(crate) fn modulus_scale(model: &Resolved, p: &Params) -> Option<f64> {
    let has_radius = p.contact_law.info().tip_radius;
    true_modulus(model, 1.0).filter(|_| has_radius)
}

/// The document of a steady tap (`afmdyn peakforce --json`, Python's `to_dict()`): `channels`
/// (the instrument's, SI with a probe), `modulus` (the DMT fit beside the true modulus),
/// `orbit` (period, Floquet multipliers, stability), `balance` (energy per cycle), `cycle`
/// (time, deflection, distance, force from the largest separation) and `curve` (the
/// force–distance curve, approach and retract), `z_c`, `units`, `method`, `warnings`.
pub(crate) fn document(request: &PeakForceRequest, model: &Resolved, r: &PeakForceResult) -> Value {
    let u = PeakForceRequest::units(model);
    let tap = &r.tap;
    let c = &tap.channels;
    // a sweep's single-tap blocks are its first computed value's (its Ω in a sweep of f_m)
    let p = r
        .sweep
        .iter()
        .flatten()
        .find(|t| t.tap.is_some())
        .map_or(model.params, |t| t.params)
        .with(SweepParam::Alpha5, r.alpha5);
    let has_radius = p.contact_law.info().tip_radius;
    // the fitted Hertz group to a modulus (SI with a probe), beside the true one
    let fitted = tap.fit.map(|f| f.hertz_group);
    let (modulus_fit, modulus_true) = match true_modulus(model, 1.0) {
        Some(scale) if has_radius => (fitted.map(|k| k * scale), Some(p.alpha4 * scale)),
        _ => (fitted, has_radius.then_some(p.alpha4)),
    };
    // a sweep's taps are each checked (the sweep's warnings, below); a single tap here
    let mut warnings: Vec<String> = if r.sweep.is_some() {
        Vec::new()
    } else {
        super::peakforce_sweep::tap_warnings(tap)
            .into_iter()
            .map(|(_, w)| w)
            .collect()
    };
    if r.sweep.is_none() && has_radius {
        warnings.extend(modulus_warnings(tap, request.fit_band, &p));
    }
    let t = &tap.cycle;
    let multipliers: Vec<[f64; 2]> = tap.multipliers.iter().map(|m| [m.re, m.im]).collect();
    let period = std::f64::consts::TAU / p.omega;
    let omega1 = first_natural_frequency(&p);
    let sweep = sweep_block(request, model, r, has_radius, &mut warnings);
    json!({
        "sweep": sweep,
        "channels": {
            "peak_force": c.peak_force * u.force,
            "adhesion": c.adhesion * u.force,
            "deformation": c.deformation * u.length,
            "dissipation": c.dissipation * u.energy,
            "contact_time": c.contact_time * u.time,
            "snap_off_time": c.snap_off_time * u.time,
            "ringing_amplitude": c.ringing_amplitude * u.length,
            "modulus_dmt": modulus_fit,
            "taps_per_cycle": c.taps_per_cycle,
        },
        "modulus": {
            "modulus_dmt": modulus_fit,
            "true": modulus_true,
            "ratio": match (fitted, has_radius) { (Some(k), true) => Some(k / p.alpha4), _ => None },
            "tip_sample_modulus": match true_modulus(model, 1.0) {
                Some(scale) if has_radius => tap.fit_tip_sample.map(|f| f.hertz_group * scale),
                _ => tap.fit_tip_sample.map(|f| f.hertz_group),
            },
            "force_measured_as": "k × deflection (the deflection over the lever's static compliance at the tip), as the instrument does; tip_sample_modulus is the same fit on the true tip–sample force",
            "fit_band": request.fit_band,
            "fit_points": tap.fit.map(|f| f.points),
            "fit_relative_residual": tap.fit.map(|f| f.relative_residual),
            "contact_distance": tap.fit.map(|f| f.contact_distance * u.length),
            "quantity": if u.si { "reduced modulus E* (Pa), 1/E* = (1 − ν_t²)/E_t + (1 − ν_s²)/E_s" } else { "Hertz group (4/3)E*√R in model units (α4)" },
        },
        "z_c": p.rest_distance() * u.length,
        "setpoint": request.setpoint,
        "feedback_evaluations": r.evaluations,
        "modulation": {
            "period": period * u.time,
            "f0_over_fm": omega1 / p.omega,
            "amplitude": p.alpha2 * u.length,
        },
        "orbit": {
            "period": tap.period,
            "stable": tap.stable,
            "multipliers": multipliers,
            "transient_periods": tap.transient_periods,
        },
        "balance": {
            "modulation_work": tap.balance.modulation_work * u.energy,
            "lever_damping": tap.balance.lever_damping * u.energy,
            "tip_sample": tap.balance.tip_sample * u.energy,
            "base_forcing": tap.balance.base_forcing * u.energy,
            "residual": tap.balance.residual * u.energy,
        },
        "cycle": {
            "time": scaled(&t.time, u.time),
            "deflection": scaled(&t.deflection, u.length),
            "distance": scaled(&t.distance, u.length),
            "force": scaled(&t.force, u.force),
        },
        "curve": curve_block(t, r.filtered.as_deref(), &u),
        "filter": request.filter_cutoff.map(|fc| json!({
            "cutoff": fc,
            "kind": FILTER_KIND,
        })),
        "units": units_block(u.si),
        "method": "the sample (or base) modulated as z_c + A_m cos 2πf_m t (t = 0 at the largest separation); the steady tap is the periodic orbit of the modulation period, settled from rest and Newton-shot with its Floquet multipliers; modulus_dmt from the DMT relation F − F_adh = (4/3)E*√R(d₀ − d)^{3/2} fitted on the retract curve between fit_band of its force range, d₀ at the force minimum (PF-QNM, Bruker AN128); adhesion is the most negative force (signed) (docs/afm-workflow.md)",
        "warnings": warnings,
    })
}

/// A column of the cycle in the document's units.
fn scaled(v: &[f64], scale: f64) -> Vec<f64> {
    v.iter().map(|x| x * scale).collect()
}

/// The document's `curve`: the cycle's force–distance curve, approach (its first half, from the
/// largest separation) and retract, with the filtered force when there is one.
fn curve_block(t: &Cycle, filtered: Option<&[f64]>, u: &CurveUnits) -> Value {
    let half = t.time.len() / 2;
    let mut curve = json!({
        "approach_distance": scaled(&t.distance[..half], u.length),
        "approach_force": scaled(&t.force[..half], u.force),
        "retract_distance": scaled(&t.distance[half..], u.length),
        "retract_force": scaled(&t.force[half..], u.force),
    });
    if let Some(fl) = filtered {
        curve["approach_filtered_force"] = json!(scaled(&fl[..half], u.force));
        curve["retract_filtered_force"] = json!(scaled(&fl[half..], u.force));
    }
    curve
}

/// The document's `sweep` block (`None` without a sweep), its warnings added to `warnings`.
fn sweep_block(
    request: &PeakForceRequest,
    model: &Resolved,
    r: &PeakForceResult,
    has_radius: bool,
    warnings: &mut Vec<String>,
) -> Option<Value> {
    let frame = sweep_frame(model, has_radius);
    let sweep = request.sweep.as_ref().zip(r.sweep.as_ref());
    let sweep = sweep.map(|(s, taps)| super::peakforce_sweep::sweep_document(s, &frame, taps));
    if let (Some(block), Some(taps)) = (&sweep, &r.sweep) {
        warnings.extend(super::peakforce_sweep::sweep_warnings(block, taps));
        let failed = block["message"]
            .as_array()
            .map_or(0, |m| m.iter().filter(|x| !x.is_null()).count());
        if failed > 0 {
            warnings.push(format!(
                "{failed} of the sweep's values failed (null in sweep.channels; their \
                 messages in sweep.message)"
            ));
        }
    }
    sweep
}

/// What a sweep's channels are read through: the document's units, and the modulus in Pa (with a
/// probe, for a law with a tip radius `has_radius`) or as the Hertz group.
fn sweep_frame(model: &Resolved, has_radius: bool) -> super::peakforce_sweep::Frame {
    super::peakforce_sweep::Frame {
        u: PeakForceRequest::units(model),
        modulus_scale: true_modulus(model, 1.0)
            .filter(|_| has_radius)
            .unwrap_or(1.0),
    }
}

/// The document's `units`: SI with a probe, else the model's.
fn units_block(si: bool) -> Value {
    if si {
        json!({"peak_force": "N", "adhesion": "N", "deformation": "m", "dissipation": "J", "contact_time": "s",
                   "snap_off_time": "s (from the largest separation)", "ringing_amplitude": "m", "modulus_dmt": "Pa", "z_c": "m",
                   "time": "s", "deflection": "m", "distance": "m", "force": "N"})
    } else {
        json!({"peak_force": "F", "adhesion": "F", "deformation": "g0", "dissipation": "F·g0", "contact_time": "τ",
                   "snap_off_time": "τ (from the largest separation)", "ringing_amplitude": "g0", "modulus_dmt": "α4 (Hertz group)", "z_c": "g0",
                   "time": "τ", "deflection": "g0", "distance": "g0", "force": "F"})
    }
}

impl crate::study::named::Datasets for PeakForceRequest {
    /// `cycle` (time, deflection, distance, force over one period from the largest
    /// separation) and `curve` (approach and retract, each over its own dimension), in the
    /// document's units; the channels as facts.
    fn datasets(
        &self,
        model: &Resolved,
        r: &PeakForceResult,
    ) -> Result<crate::study::named::Arrays, SimError> {
        use crate::layout::{Layout, Variable};
        let doc = document(self, model, r);
        let units = &doc["units"];
        let unit = |k: &str| units[k].as_str().unwrap_or("").to_string();
        let arr = |block: &str, k: &str| -> Vec<f64> {
            doc[block][k].as_array().map_or(Vec::new(), |a| {
                a.iter().map(|v| v.as_f64().unwrap_or(f64::NAN)).collect()
            })
        };
        let n = r.tap.cycle.time.len();
        let cycle = Layout::new(
            "peakforce cycle",
            &[("sample", n)],
            ["time", "deflection", "distance", "force"]
                .iter()
                .map(|k| Variable::f64(k, &["sample"], &unit(k), *k, &arr("cycle", k)))
                .collect(),
        );
        let (a, b) = (
            arr("curve", "approach_distance").len(),
            arr("curve", "retract_distance").len(),
        );
        let mut variables = vec![
            Variable::f64(
                "approach_distance",
                &["approach"],
                &unit("distance"),
                "distance, approach",
                &arr("curve", "approach_distance"),
            ),
            Variable::f64(
                "approach_force",
                &["approach"],
                &unit("force"),
                "force, approach",
                &arr("curve", "approach_force"),
            ),
            Variable::f64(
                "retract_distance",
                &["retract"],
                &unit("distance"),
                "distance, retract",
                &arr("curve", "retract_distance"),
            ),
            Variable::f64(
                "retract_force",
                &["retract"],
                &unit("force"),
                "force, retract",
                &arr("curve", "retract_force"),
            ),
        ];
        // the measured force through the instrument's filter, with filter_cutoff
        if r.filtered.is_some() {
            for (k, dim, what) in [
                (
                    "approach_filtered_force",
                    "approach",
                    "filtered k × deflection, approach",
                ),
                (
                    "retract_filtered_force",
                    "retract",
                    "filtered k × deflection, retract",
                ),
            ] {
                variables.push(Variable::f64(
                    k,
                    &[dim],
                    &unit("force"),
                    what,
                    &arr("curve", k),
                ));
            }
        }
        let curve = Layout::new(
            "peakforce force-distance curve",
            &[("approach", a), ("retract", b)],
            variables,
        );
        let facts = doc["channels"].as_object().cloned().unwrap_or_default();
        let mut layouts = vec![("cycle".into(), cycle), ("curve".into(), curve)];
        if let Some((s, taps)) = self.sweep.as_ref().zip(r.sweep.as_ref()) {
            // the contact law, and so its tip radius, is the same at every value of a sweep
            let frame = sweep_frame(model, model.params.contact_law.info().tip_radius);
            let layout = super::peakforce_sweep::sweep_layout(s, &frame, taps);
            layouts.push(("sweep".into(), layout));
        }
        Ok((layouts, facts))
    }
}

/// A refusal of the setpoint stated in newtons (`newtons`, the request's value): the search
/// works in F̃, which a user of a probe never wrote (issue 77); other errors unchanged.
pub(crate) fn setpoint_in_newtons(e: SimError, newtons: f64) -> SimError {
    match e {
        SimError::OutOfRange { name, allowed, .. } if name == "setpoint" => SimError::OutOfRange {
            name,
            value: format!("{} N", crate::error::number(newtons)),
            allowed,
        },
        e => e,
    }
}

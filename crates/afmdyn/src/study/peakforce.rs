//! A PeakForce sweep ([`crate::analysis::peakforce`]) as a `Chain` (`PeakForceStudy::chain`):
//! a task is one value of the swept quantity (the mean rest separation z_c, or the modulation
//! frequency), numbered by its place in the values; its record the steady tap there, or why it
//! failed. The tasks form one chain: each tap's transient starts from the previous tap's orbit
//! (its state at τ = 0), which near a smooth branch settles in no more modulation periods
//! than a start from rest (across a change of the tapping it may take more). A
//! point that fails is recorded with its message and the chain goes on from the last orbit
//! found. With a setpoint (a sweep in the modulation frequency under ideal peak-force
//! feedback) each value runs the feedback's own search
//! ([`crate::analysis::peakforce::peak_force_setpoint`], from rest).
//!
//! Run in memory ([`super::execute_in_memory`]) by the `peakforce` request with a sweep, whose
//! [`Analysis`] (running a request: a study's layer, above the request's data) is here, with
//! the request's document ([`document`]: channels, modulus, cycle, curve, the sweep's block)
//! and its arrays (`Datasets`).

use super::peakforce_sweep::{SweepTap, NOISE_COLUMNS};
use super::Chain;
use crate::analysis::peakforce::{
    low_pass_periodic, peak_force_setpoint, simulated_tap_noise, static_compliance, steady_tap,
    steady_tap_from, tap_noise, Cycle, PeakForceOptions, SetpointOptions, SimulatedTapNoise,
    SteadyTap, TapNoise, MAX_PEAK_SHIFT,
};
use crate::analysis::progress::Progress;
use crate::error::SimError;
use crate::integrate::exact::ThermalForce;
use crate::layout::columns::{self, UnitNames};
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use crate::report::{Convergence, CurveUnits};
use crate::request::{Analysis, PeakForceRequest, PeakForceSweep, Resolved};
use nalgebra::DVector;
use serde_json::{json, Value};
use std::sync::atomic::{AtomicBool, Ordering};

/// A PeakForce sweep, its study a `Chain` (see the module doc).
#[derive(Debug, Clone)]
pub(crate) struct PeakForceStudy {
    /// The model of every value, in the order of the sweep.
    pub points: Vec<Params>,
    /// The peak force the ideal feedback holds at every value (F̃), or `None` (the points' own
    /// α5).
    pub setpoint: Option<f64>,
    /// The steady taps' options.
    pub options: PeakForceOptions,
    /// What a resumed run must match.
    pub fingerprint: Value,
    /// k_B T of each tap's thermal noise (model units; with a temperature).
    pub kt: Option<f64>,
}

impl PeakForceStudy {
    /// The tap at value `i` from the state `start` at τ = 0, with its noise under
    /// [`PeakForceStudy::kt`].
    fn tap(&self, i: usize, start: &DVector<f64>) -> Result<SweepTap, SimError> {
        let (params, tap, evaluations) = self.steady(i, start)?;
        let noise = match self.kt {
            Some(kt) => {
                let (m, integrator) = (
                    CantileverModel::new(&params)?,
                    self.options.integrator.clone(),
                );
                Some(tap_noise(&m, &tap.state, tap.period, kt, integrator)?)
            }
            None => None,
        };
        Ok(SweepTap {
            index: i,
            params,
            tap: Some(tap),
            evaluations,
            message: None,
            noise,
        })
    }

    /// The steady tap at value `i` from the state `start` at τ = 0.
    fn steady(
        &self,
        i: usize,
        start: &DVector<f64>,
    ) -> Result<(Params, SteadyTap, usize), SimError> {
        let p = self.points[i];
        match self.setpoint {
            Some(f) => {
                let opts = SetpointOptions {
                    tap: self.options.clone(),
                    ..SetpointOptions::default()
                };
                let s = peak_force_setpoint(&p, f, &opts)?;
                let q = p.with(SweepParam::Alpha5, s.alpha5);
                Ok((q, s.tap, s.evaluations))
            }
            None => {
                let tap = steady_tap_from(&CantileverModel::new(&p)?, &self.options, start)?;
                Ok((p, tap, 1))
            }
        }
    }

    /// The sweep as a `Chain`: its values' taps, each from the orbit of the last tap found
    /// (from rest without one), after the stored taps up to the first one missing.
    pub(crate) fn chain(&self) -> Chain<'_, SweepTap> {
        Chain::new(
            &self.fingerprint,
            self.points.len(),
            |done, sink, cancel| self.taps_after(done, sink, cancel),
        )
    }

    /// The taps after `done`, each handed to `sink` (see `PeakForceStudy::chain`).
    fn taps_after(
        &self,
        done: &[SweepTap],
        sink: &(dyn Fn(usize, SweepTap) + Sync),
        cancel: &AtomicBool,
    ) -> Result<(), SimError> {
        let dim = self.points.first().map_or(0, Params::state_dim);
        // the chain starts from the last orbit stored (from rest without one)
        let mut start = done
            .iter()
            .rev()
            .find_map(|r| r.tap.as_ref().map(|t| t.state.clone()))
            .unwrap_or_else(|| DVector::zeros(dim));
        // only the first computed tap's cycle is shown: the others' are dropped as they come,
        // so that a sweep holds one cycle of `samples`, not one per value (issue 77 §1: 10⁴
        // values of 10⁶ samples grew past 24 GB)
        let mut shown = done.iter().any(|r| r.tap.is_some());
        for i in done.len()..self.points.len() {
            if cancel.load(Ordering::Relaxed) {
                return Err(SimError::Cancelled);
            }
            let record = match self.tap(i, &start) {
                Ok(mut record) => {
                    let tap = record.tap.as_mut().expect("a computed tap");
                    start.copy_from(&tap.state);
                    if shown {
                        tap.cycle = Cycle::default();
                    }
                    shown = true;
                    record
                }
                Err(SimError::Cancelled) => return Err(SimError::Cancelled),
                Err(e) => SweepTap {
                    index: i,
                    params: self.points[i],
                    tap: None,
                    evaluations: 0,
                    message: Some(e.to_string()),
                    noise: None,
                },
            };
            sink(i, record);
        }
        Ok(())
    }
}

impl Analysis for PeakForceRequest {
    type Output = PeakForceResult;
    fn convergence(&self, r: &PeakForceResult) -> Convergence {
        match &r.sweep {
            Some(taps) => Convergence::count("taps", taps, |t| t.tap.is_some()),
            None => Convergence::exact("tap"), // a tap that does not settle is an error
        }
    }
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<PeakForceResult, SimError> {
        let mut r = self.tap(model, progress)?;
        let Some(kt) = self.thermal(model)? else {
            return Ok(r);
        };
        let m = CantileverModel::new(&tap_params(model, &r))?;
        let (state, period) = (&r.tap.state, r.tap.period);
        // a sweep's taps carry their own (the first computed one's is the block's)
        if r.sweep.is_none() {
            let integrator = self.options().integrator;
            r.noise = Some(tap_noise(&m, state, period, kt, integrator)?);
        }
        if let Some(cycles) = self.thermal_cycles {
            let force = ThermalForce::new(kt, self.seed);
            let run = simulated_tap_noise(&m, state, period, force, cycles, self.samples)?;
            r.simulated = Some(run);
        }
        Ok(r)
    }
    fn found_at(&self, model: &Resolved, r: &PeakForceResult) -> Result<Params, SimError> {
        // a setpoint's z_c is the one found; a sweep keeps the probe's (its values are listed)
        let p = self.params(model)?;
        Ok(match r.sweep {
            None => p.with(SweepParam::Alpha5, r.alpha5),
            Some(_) => p,
        })
    }
    fn report(&self, model: &Resolved, r: &PeakForceResult) -> Result<Value, SimError> {
        Ok(document(self, model, r))
    }
    fn present(
        &self,
        _: &PeakForceResult,
        at: crate::request::Presenting<'_>,
    ) -> Result<crate::report::Presentation, SimError> {
        let mut document = at.document.clone();
        let p = crate::report::present::peakforce::peakforce;
        Ok(p(&mut document, at.units, at.to))
    }
    fn largest_indentation(&self, r: &PeakForceResult) -> Option<f64> {
        // a sweep's largest over its taps
        let taps = r.sweep.iter().flatten().filter_map(|t| t.tap.as_ref());
        Some(
            taps.map(|t| t.channels.deformation)
                .fold(r.tap.channels.deformation, f64::max),
        )
    }
}

/// The sweep's chain of taps ([`PeakForceStudy`], in memory), the first value computed
/// giving the single tap's blocks.
fn execute_sweep(
    request: &PeakForceRequest,
    sweep: &PeakForceSweep,
    model: &Resolved,
    p: &Params,
    progress: &Progress,
) -> Result<PeakForceResult, SimError> {
    let force = model.units(true).force;
    let study = PeakForceStudy {
        points: request.sweep_points(sweep, model, p)?,
        setpoint: request.setpoint.map(|f| f / force),
        options: request.options(),
        fingerprint: json!({"afmdyn": env!("CARGO_PKG_VERSION"), "peakforce": request, "params": p}),
        kt: request.thermal(model)?,
    };
    let records = super::execute_in_memory(&study.chain(), None, progress)?;
    let taps = super::in_order(records, study.points.len())?;
    let failed = taps.iter().filter(|t| t.tap.is_none()).count();
    let Some(first) = taps.iter().find(|t| t.tap.is_some()) else {
        return Err(SimError::EveryRunFailed {
            what: "peakforce sweep points",
            runs: failed,
            first: taps
                .first()
                .and_then(|t| t.message.clone())
                .unwrap_or_default(),
        });
    };
    let tap = first.tap.clone().ok_or(SimError::Cancelled)?;
    Ok(PeakForceResult {
        alpha5: first.params.alpha5,
        filtered: request.filtered(model, &first.params, &tap)?,
        evaluations: taps.iter().map(|t| t.evaluations).sum(),
        noise: first.noise,
        simulated: None,
        tap,
        sweep: Some(taps),
    })
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
    /// The tap's thermal noise (with [`PeakForceRequest::temperature`]).
    pub noise: Option<TapNoise>,
    /// The thermally driven run of the tap (with [`PeakForceRequest::thermal_cycles`]).
    pub simulated: Option<SimulatedTapNoise>,
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

/// Why a DMT fit reads off the sample's own E* (a single tap's warning and a PeakForce image
/// material's).
pub(crate) const BIAS_CAUSE: &str = "the lever's inertia and ringing within the tap, an \
                                      indentation past the paraboloid's validity";

/// Why a single tap's `modulus_dmt` is missing, or where it is not the sample's modulus
/// (issue 77): no fit (too few retract points in the band), a fit residual above
/// [`MAX_FIT_RESIDUAL`], a reading more than [`MAX_MODULUS_BIAS`] off the sample's own E*
/// (Hertz group α4 of `p`). A double tap is said by its own warning.
fn modulus_warnings(tap: &SteadyTap, band: [f64; 2], p: &Params) -> Vec<String> {
    if tap.channels.taps_per_cycle > 1.0 + 1e-9 {
        return Vec::new();
    }
    let Some(fit) = tap.fit else {
        return vec![warning!(
            "peakforce.no-fit",
            "Raise samples, or widen fit_band.",
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
        w.push(warning!(
            "peakforce.fit-residual",
            "Read modulus_dmt of this tap as not meaningful; check the contact law and \
             fit_band.",
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
        w.push(warning!(
            "peakforce.modulus-bias",
            "Calibrate the reading against a sample of known modulus; do not read it as \
             the sample's modulus.",
            "modulus_dmt reads {ratio:.3} × the sample's own E* (more than {:.0} % off): the DMT \
             fit of this tap is biased ({other_law}{BIAS_CAUSE}): compare it against a \
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

/// The model of the single-tap blocks' tap: a sweep's first computed value's (its Ω in a sweep
/// of f_m) at the tap's α5.
fn tap_params(model: &Resolved, r: &PeakForceResult) -> Params {
    r.sweep
        .iter()
        .flatten()
        .find(|t| t.tap.is_some())
        .map_or(model.params, |t| t.params)
        .with(SweepParam::Alpha5, r.alpha5)
}

/// The document of a steady tap (`afmdyn peakforce --json`, Python's `to_dict()`): `channels`
/// (the instrument's, SI with a probe), `modulus` (the DMT fit beside the true modulus),
/// `orbit` (period, Floquet multipliers, stability), `balance` (energy per cycle), `cycle`
/// (time, deflection, distance, force from the largest separation) and `curve` (the
/// force–distance curve, approach and retract), `z_c`, `units`, `method`, `warnings`.
pub(crate) fn document(request: &PeakForceRequest, model: &Resolved, r: &PeakForceResult) -> Value {
    let u = model.units(true);
    let tap = &r.tap;
    let c = &tap.channels;
    // a sweep's single-tap blocks are its first computed value's (its Ω in a sweep of f_m)
    let p = tap_params(model, r);
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
    let omega1 = crate::request::peakforce::first_natural_frequency(&p);
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
        "thermal": thermal_block(request, r, &u, &mut warnings),
        "method": "the sample (or base) modulated as z_c + A_m cos 2πf_m t (t = 0 at the largest separation); the steady tap is the periodic orbit of the modulation period, settled from rest and Newton-shot with its Floquet multipliers; modulus_dmt from the DMT relation F − F_adh = (4/3)E*√R(d₀ − d)^{3/2} fitted on the retract curve between fit_band of its force range, d₀ at the force minimum (PF-QNM, Bruker AN128); adhesion is the most negative force (signed) (docs/tutorials/peakforce.md)",
        "warnings": warnings,
    })
}

/// σ/channel above which the thermal block's linear response is said to be at its limit.
pub(crate) const MAX_LINEAR_NOISE: f64 = 0.1;

/// The document's `thermal` block (`None` without a temperature): the tap's noise per cycle
/// ([`crate::analysis::peakforce::tap_noise`]) in the document's units, the temperature's
/// warnings and the linear response's, where a tap (of a sweep: any value's) jumps to contact
/// or its σ passes [`MAX_LINEAR_NOISE`] of its channel.
fn thermal_block(
    request: &PeakForceRequest,
    r: &PeakForceResult,
    u: &CurveUnits,
    warnings: &mut Vec<String>,
) -> Option<Value> {
    let (n, t) = (r.noise?, request.temperature?);
    warnings.extend(crate::request::limits::temperature_warnings(t));
    // every tap's noise beside its channels: the single tap's, or each value's of a sweep
    let channels = |n: TapNoise, t: &SteadyTap| (n, t.channels.peak_force, t.channels.deformation);
    let taps: Vec<(TapNoise, f64, f64)> = match &r.sweep {
        Some(s) => (s.iter())
            .filter_map(|v| Some(channels(v.noise?, v.tap.as_ref()?)))
            .collect(),
        None => vec![channels(n, &r.tap)],
    };
    warnings.extend(linear_warnings(&taps, r.simulated.is_none()));
    // the thermally driven run against the linear response, beyond its standard errors and
    // MAX_LINEAR_NOISE of itself (wider only at a flat peak, whose narrower maxima are said)
    let off = |linear: f64, [sim, se]: [f64; 2]| {
        let beyond = (linear - sim).abs() > 4.0 * se + MAX_LINEAR_NOISE * sim;
        beyond && (!n.flat_peak || sim > linear)
    };
    let disagrees = (r.simulated.as_ref())
        .filter(|s| off(n.peak_force, s.peak_force) || off(n.deformation, s.deformation));
    if let Some(s) = disagrees {
        let (f, l) = if u.si { ("N", "m") } else { ("F", "g0") };
        let shown = |v: f64, k: f64, unit: &str| format!("{} {unit}", crate::error::number(v * k));
        warnings.push(warning!(
            "thermal.linear-disagrees",
            "Read the simulated block: it measures the taps the noise makes.",
            "the linear response's σ (peak force {}, deformation {}) differs from the thermally \
             driven run's ({} ± {}, {} ± {}) by more than 4 standard errors and 10 %: the noise \
             moves this tap beyond its linearisation (a jump to contact, a grazing)",
            shown(n.peak_force, u.force, f),
            shown(n.deformation, u.length, l),
            shown(s.peak_force[0], u.force, f),
            shown(s.peak_force[1], u.force, f),
            shown(s.deformation[0], u.length, l),
            shown(s.deformation[1], u.length, l),
        ));
    }
    let simulated = r.simulated.as_ref().map(|s| {
        let scaled = |v: &[f64], k: f64| v.iter().map(|x| x * k).collect::<Vec<_>>();
        json!({
            "cycles": s.cycles,
            "seed": s.seed,
            "peak_force_noise": s.peak_force[0] * u.force,
            "peak_force_noise_error": s.peak_force[1] * u.force,
            "deformation_noise": s.deformation[0] * u.length,
            "deformation_noise_error": s.deformation[1] * u.length,
            "peak_force_quantiles": scaled(&s.peak_force_quantiles, u.force),
            "deformation_quantiles": scaled(&s.deformation_quantiles, u.length),
        })
    });
    let mut units = columns::units(&NOISE_COLUMNS, &UnitNames::si_or_model(u.si));
    units.insert("temperature".into(), "K".into());
    Some(json!({
        "temperature": t,
        "peak_force_noise": n.peak_force * u.force,
        "deformation_noise": n.deformation * u.length,
        "simulated": simulated,
        "units": units,
        "method": "standard deviations from cycle to cycle of the force and the deformation at their peaks' times (the per-cycle maxima's where the peak is sharp: thermal.flat-peak) under the fluctuation–dissipation theorem's thermal force on the lever and its medium, by linear response about the steady tap: the deviations' chain over the orbit (flow Jacobians and saltation matrices, the noise of each part exact where the motion is linear, else by the trapezoid rule), its stationary covariance by doubling, read at each channel's extremum (crate::analysis::peakforce::tap_noise)",
    }))
}

/// The linear response's warnings over taps' noise beside their channels, `(σ, peak force,
/// deformation)` in one system of units: a σ past [`MAX_LINEAR_NOISE`] of its channel, a peak
/// flat against the noise and, with `snap_in`, a jump to contact (none where a thermally driven
/// run measures it).
pub(crate) fn linear_warnings(taps: &[(TapNoise, f64, f64)], snap_in: bool) -> Vec<String> {
    let mut warnings = Vec::new();
    // a channel whose σ passes MAX_LINEAR_NOISE of its value at some tap
    let over = |sigma: f64, value: f64| sigma > MAX_LINEAR_NOISE * value.abs();
    let mut large = Vec::new();
    if taps.iter().any(|(n, f, _)| over(n.peak_force, *f)) {
        large.push("peak force");
    }
    if taps.iter().any(|(n, _, d)| over(n.deformation, *d)) {
        large.push("deformation");
    }
    if !large.is_empty() {
        let (what, percent) = (large.join(" and "), MAX_LINEAR_NOISE * 100.0);
        warnings.push(warning!(
            "thermal.noise-large",
            "Read the thermal block as an estimate; the peaks' distribution is then skewed.",
            "the thermal noise of the {what} is more than {percent:.0} % of the channel \
             itself: its linear response about the steady tap is at its limit (the noise may \
             make or break contact, which no linearisation holds)"
        ));
    }
    if taps.iter().any(|(n, ..)| n.flat_peak) {
        warnings.push(warning!(
            "thermal.flat-peak",
            "Read peak_force_noise and deformation_noise as the channels' σ at the peak's time; \
             a thermally driven run of the tap (peakforce's thermal_cycles, --thermal-cycles) \
             measures the per-cycle maxima.",
            "the tap's peak is flat against the thermal noise (the noise's slope shifts the \
             per-cycle maximum by more than {MAX_PEAK_SHIFT} of its σ): each cycle's peak is \
             then the largest of several fluctuations, narrower in spread and higher than the \
             linear response's σ at the peak's time"
        ));
    }
    if snap_in && taps.iter().any(|(n, ..)| n.snap_in) {
        warnings.push(warning!(
            "thermal.snap-in",
            "Read the σ as the typical cycle's spread; a thermally driven run of the tap \
             (peakforce's thermal_cycles, --thermal-cycles) measures the rare hard taps.",
            "the tap jumps to contact (out of contact the attraction's stiffness passes the \
             lever's): the noise moves the jump nonlinearly, so the linear response gives the \
             Gaussian core of the peaks' spread, not its tail of rare hard taps (8× the variance \
             in a simulated tap on polystyrene, crate::analysis::peakforce::tap_noise)"
        ));
    }
    warnings
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
            warnings.push(warning!(
                "peakforce.failed-values",
                "Read sweep.message for each failed value.",
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
        u: model.units(true),
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
        let mut facts = doc["channels"].as_object().cloned().unwrap_or_default();
        // the thermal block's σ beside the channels they are the noise of
        if let Some(th) = doc["thermal"].as_object() {
            for k in ["peak_force_noise", "deformation_noise"] {
                facts.insert(k.into(), th[k].clone());
            }
        }
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

impl PeakForceRequest {
    /// The steady tap of the request: at its z_c, its setpoint, or a sweep's (the first value
    /// computed giving the single tap's blocks), without its noise.
    fn tap(&self, model: &Resolved, progress: &Progress) -> Result<PeakForceResult, SimError> {
        let p = self.params(model)?;
        if let Some(sweep) = &self.sweep {
            return execute_sweep(self, sweep, model, &p, progress);
        }
        match self.setpoint {
            Some(f) => {
                let force = model.units(true).force;
                let opts = SetpointOptions {
                    tap: self.options(),
                    ..SetpointOptions::default()
                };
                let s =
                    peak_force_setpoint(&p, f / force, &opts).map_err(|e| match model.probe {
                        Some(_) => setpoint_in_newtons(e, f),
                        None => e,
                    })?;
                Ok(PeakForceResult {
                    alpha5: s.alpha5,
                    filtered: self.filtered(model, &p, &s.tap)?,
                    tap: s.tap,
                    evaluations: s.evaluations,
                    sweep: None,
                    noise: None,
                    simulated: None,
                })
            }
            None => {
                let tap = steady_tap(&CantileverModel::new(&p)?, &self.options())?;
                Ok(PeakForceResult {
                    alpha5: p.alpha5,
                    filtered: self.filtered(model, &p, &tap)?,
                    tap,
                    evaluations: 1,
                    sweep: None,
                    noise: None,
                    simulated: None,
                })
            }
        }
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

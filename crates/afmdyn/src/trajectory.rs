//! Trajectories: sampled time series, switching events, the stroboscopic Poincaré section,
//! per-period energy bookkeeping and the body-contact check; [`chunked`]: a long run recorded in
//! chunks of whole periods.

pub mod chunked;

use crate::error::{finite, SimError};
use crate::galerkin::Region;
use crate::integrate::{advance, Integrator, SwitchEvent};
use crate::model::{BodyContactCheck, CantileverModel};
use crate::system::EventKind;
use gauss_quad::legendre::GaussLegendre;
use nalgebra::DVector;
use std::num::NonZeroUsize;

/// One sample of the time series.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// τ.
    pub tau: f64,
    /// V_T (eq. 8).
    pub v_t: f64,
    /// W(1,τ).
    pub w_tip: f64,
    /// ∂W(1,τ)/∂τ.
    pub w_tip_dot: f64,
    /// Region at the sample.
    pub region: Region,
    /// Tip–sample force F_c (repulsive positive; α4 δ + α6 δ̇ for the linear law in contact).
    pub contact_force: f64,
    /// State (a, ȧ), shape `[2N]`.
    pub state: DVector<f64>,
}

impl Sample {
    /// Sample of `model` at (τ, z) in region `r`.
    pub fn new(model: &CantileverModel, r: Region, tau: f64, z: &DVector<f64>) -> Self {
        Sample {
            tau,
            v_t: model.v_t(tau, z),
            w_tip: model.w_tip(z),
            w_tip_dot: model.w_tip_dot(z),
            region: r,
            contact_force: model.contact_force(r, tau, z),
            state: z.clone(),
        }
    }
}

/// Energy balance of one drive period: ΔE = W_base − D_beam − D_contact (+ residual).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyBalance {
    /// Start of the period.
    pub tau0: f64,
    /// Stored energy at the start.
    pub e_start: f64,
    /// Stored energy at the end.
    pub e_end: f64,
    /// ∫ P_base dτ.
    pub base_work: f64,
    /// ∫ α3 ẊᵀẊ dτ.
    pub beam_dissipation: f64,
    /// ∫ α6 V̇_T² dτ over contact.
    pub contact_dissipation: f64,
}

impl EnergyBalance {
    /// (e_end − e_start) − (base_work − beam_dissipation − contact_dissipation).
    pub fn residual(&self) -> f64 {
        (self.e_end - self.e_start)
            - (self.base_work - self.beam_dissipation - self.contact_dissipation)
    }
}

/// Largest per-period residual of an energy balance ([`EnergyBalance::residual`]):
/// (absolute, relative to the period's largest term). The relative residual is +∞ for a nonzero
/// (or NaN) residual of a period whose terms are all 0.
pub fn energy_residual(energy: &[EnergyBalance]) -> (f64, f64) {
    let (mut abs, mut rel) = (0.0f64, 0.0f64);
    for e in energy {
        let r = e.residual().abs();
        let scale = [
            e.e_start,
            e.e_end,
            e.base_work,
            e.beam_dissipation,
            e.contact_dissipation,
        ]
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()));
        abs = abs.max(r);
        if scale > 0.0 {
            rel = rel.max(r / scale);
        } else if r > 0.0 || r.is_nan() {
            rel = f64::INFINITY;
        }
    }
    (abs, rel)
}

/// What to record along a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RecordSpec {
    /// Periods to run and discard before recording (transient).
    pub transient_periods: f64,
    /// Length of the recorded part, in τ.
    pub record_tau: f64,
    /// Samples per drive period in the recorded part (0: none).
    pub samples_per_period: usize,
    /// Integrate the energy balance per period (Gauss–Legendre on the dense output).
    pub energy: bool,
    /// Check the body-contact condition (Fig. 2f) at every step of the recorded part.
    pub body_contact: bool,
}

/// A recorded run.
#[derive(Debug, Clone, Default)]
pub struct Trajectory {
    /// Samples of the recorded part.
    pub samples: Vec<Sample>,
    /// Switchings of the recorded part.
    pub events: Vec<SwitchEvent>,
    /// Stroboscopic section τ = 2πk/Ω (drive phase 0) in the recorded part: (τ, z).
    pub poincare: Vec<(f64, DVector<f64>)>,
    /// Energy balance per complete period of the recorded part.
    pub energy: Vec<EnergyBalance>,
    /// Whether any beam point other than the tip reached the substrate (Fig. 2f).
    pub body_contact: bool,
    /// Final time.
    pub tau_end: f64,
    /// Final state.
    pub final_state: DVector<f64>,
    /// Final region.
    pub final_region: Region,
}

/// Run `integ` from its current state: a transient, then the recorded part.
///
/// # Errors
/// [`SimError`] for negative or non-finite lengths, or a failure of the integrator.
pub fn record(integ: &mut dyn Integrator, spec: &RecordSpec) -> Result<Trajectory, SimError> {
    finite("transient_periods", spec.transient_periods)?;
    finite("record_tau", spec.record_tau)?;
    if spec.transient_periods < 0.0 {
        return Err(SimError::out_of_range(
            "transient_periods",
            spec.transient_periods,
            "must be >= 0",
        ));
    }
    if spec.record_tau < 0.0 {
        return Err(SimError::out_of_range(
            "record_tau",
            spec.record_tau,
            "must be >= 0",
        ));
    }
    let model =
        crate::tip_sample::require_cantilever(integ.system(), "the recorded trajectory")?.clone();
    let period = model.period();
    let start = integ.tau() + spec.transient_periods * period;
    advance(integ, start)?;
    let end = start + spec.record_tau;
    let mut out = Trajectory::default();
    let body = spec.body_contact.then(|| BodyContactCheck::new(&model, 64));
    let gl = GaussLegendre::new(NonZeroUsize::new(12).expect("nonzero"));
    let dt = if spec.samples_per_period > 0 {
        period / spec.samples_per_period as f64
    } else {
        f64::INFINITY
    };
    let mut k_sample = 0usize;
    let mut k_period = (start / period).ceil() as i64;
    if spec.samples_per_period > 0 {
        out.samples.push(Sample::new(
            &model,
            integ.region(),
            integ.tau(),
            integ.state(),
        ));
        k_sample = 1;
    }
    let record_section = |tau: f64, z: &DVector<f64>, out: &mut Trajectory, k_period: &mut i64| {
        let t_sec = *k_period as f64 * period;
        if tau == t_sec || (tau - t_sec).abs() <= 1e-12 * (1.0 + tau.abs()) {
            out.poincare.push((tau, z.clone()));
            *k_period += 1;
        }
    };
    record_section(integ.tau(), integ.state(), &mut out, &mut k_period);
    let mut acc = EnergyBalance {
        tau0: integ.tau(),
        e_start: model.energy(integ.region(), integ.tau(), integ.state()),
        e_end: 0.0,
        base_work: 0.0,
        beam_dissipation: 0.0,
        contact_dissipation: 0.0,
    };
    let mut next_energy_cut = (k_period as f64) * period;
    if next_energy_cut <= integ.tau() {
        next_energy_cut += period;
    }
    while integ.tau() < end {
        let next_sample = start + k_sample as f64 * dt;
        let next_section = k_period as f64 * period;
        let target = end.min(next_sample).min(next_section);
        let step = integ.step(target)?;
        let closed = if spec.energy && step.tau1 > step.tau0 {
            integ.last_step_rate_integrals()
        } else {
            None
        };
        if let Some([pb, db, dc]) = closed {
            acc.base_work += pb;
            acc.beam_dissipation += db;
            acc.contact_dissipation += dc;
        } else if spec.energy && step.tau1 > step.tau0 {
            let r = step.region;
            let (mut pb, mut db, mut dc) = (0.0, 0.0, 0.0);
            for (x, w) in gl.iter() {
                let tau = 0.5 * (step.tau1 - step.tau0) * (x + 1.0) + step.tau0;
                let z = integ.dense_state(tau);
                let p = model.power(r, tau, &z);
                pb += w * p.base;
                db += w * p.beam_dissipation;
                dc += w * p.contact_dissipation;
            }
            let half = 0.5 * (step.tau1 - step.tau0);
            acc.base_work += half * pb;
            acc.beam_dissipation += half * db;
            acc.contact_dissipation += half * dc;
        }
        let tau = integ.tau();
        let z = integ.state();
        if let Some(b) = &body {
            out.body_contact |= b.touches(tau, z);
        }
        if let Some(e) = step.event {
            // an impact's impulse: energy lost in the sample and work done on the clamped frame
            let r = match e.kind {
                EventKind::Impact => model.law().restitution(),
                EventKind::Stick => Some(0.0),
                _ => None,
            };
            if let (true, Some(r)) = (spec.energy, r) {
                let (loss, base) = model.impact_energy(e.tau, e.v_t_dot, r);
                acc.contact_dissipation += loss;
                acc.base_work += base;
            }
            out.events.push(e);
        }
        if spec.energy
            && (tau >= next_energy_cut
                || (tau - next_energy_cut).abs() <= 1e-12 * (1.0 + tau.abs()))
        {
            acc.e_end = model.energy(step.region, tau, z);
            out.energy.push(acc);
            acc = EnergyBalance {
                tau0: tau,
                e_start: model.energy(integ.region(), tau, z),
                e_end: 0.0,
                base_work: 0.0,
                beam_dissipation: 0.0,
                contact_dissipation: 0.0,
            };
            next_energy_cut += period;
        }
        if spec.samples_per_period > 0 && (tau - next_sample).abs() <= 1e-12 * (1.0 + tau.abs()) {
            out.samples
                .push(Sample::new(&model, integ.region(), tau, z));
            k_sample += 1;
        }
        record_section(tau, z, &mut out, &mut k_period);
    }
    out.tau_end = integ.tau();
    out.final_state = integ.state().clone();
    out.final_region = integ.region();
    Ok(out)
}

//! Per-point traces of a stepped curve (issue 28): for every point of the first sweep (each z_c
//! of an approach, each frequency of an up-sweep), one steady-state cycle recorded from the
//! point's state at τ = 0 — tip deflection W(1,τ), tip–sample distance V_T and contact force —
//! the time-domain record dForce 2.0 keeps per z_c (`tdom`; Gisbert & Garcia, Soft Matter 19,
//! 5857 (2023)). The force against V_T over a cycle is the force–distance loop whose enclosed
//! area is the energy dissipated per cycle (Cleveland et al., Appl. Phys. Lett. 72, 2613
//! (1998)).
//!
//! Every trace covers the same `periods` drive periods (the largest period of the recorded
//! points, at most `MAX_TRACE_PERIODS`), so the traces form arrays of shape
//! `[points, periods × samples_per_period]` on one time axis.

use crate::error::{within, SimError};
use crate::integrate::{build, IntegratorOptions};
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use crate::trajectory::{record, RecordSpec};
use nalgebra::DVector;

/// A point of a sweep to trace: the swept parameter's value, the state at τ = 0 (shape `[2N]`)
/// and the period n (`None`: not period-n, traced over one period).
pub(crate) type TracePoint<'a> = (f64, &'a DVector<f64>, Option<usize>);

/// Most drive periods of a trace (a period-n orbit with n larger is recorded over this many).
pub(crate) const MAX_TRACE_PERIODS: usize = 16;
/// Most samples per drive period of a trace.
pub(crate) const MAX_TRACE_SAMPLES: usize = 10_000;

/// The traces of a sweep, arrays row per point (dimensionless: τ, g₀, F̃).
#[derive(Debug, Clone, PartialEq)]
pub struct Traces {
    /// Drive periods per trace.
    pub periods: usize,
    /// Samples per drive period.
    pub samples_per_period: usize,
    /// The swept parameter's value of each trace.
    pub values: Vec<f64>,
    /// Time since the point's τ = 0 in drive periods, shape `[samples]` (samples = periods ×
    /// samples_per_period): one axis for every trace, whatever its drive period.
    pub time: Vec<f64>,
    /// W(1,τ), row-major `[points][samples]`.
    pub deflection: Vec<f64>,
    /// V_T (≤ 0 in contact), `[points][samples]`.
    pub distance: Vec<f64>,
    /// Tip–sample force, `[points][samples]`.
    pub force: Vec<f64>,
}

/// The traces of `points` of a sweep of `param` over `base`, integrated with `integrator`,
/// `samples_per_period` samples per drive period.
///
/// # Errors
/// [`SimError::OutOfRange`] naming `trace_samples` outside 2..=`MAX_TRACE_SAMPLES`; the
/// model's or integrator's errors for a point.
pub(crate) fn traces(
    base: &Params,
    param: SweepParam,
    integrator: IntegratorOptions,
    points: &[TracePoint<'_>],
    samples_per_period: usize,
) -> Result<Traces, SimError> {
    within(
        "trace_samples",
        samples_per_period,
        2..=MAX_TRACE_SAMPLES,
        "must be in 2..=10000 samples per drive period",
    )?;
    let periods = points
        .iter()
        .map(|p| p.2.unwrap_or(1))
        .max()
        .unwrap_or(1)
        .min(MAX_TRACE_PERIODS);
    let samples = periods * samples_per_period;
    let mut out = Traces {
        periods,
        samples_per_period,
        values: Vec::with_capacity(points.len()),
        time: Vec::new(),
        deflection: Vec::with_capacity(points.len() * samples),
        distance: Vec::with_capacity(points.len() * samples),
        force: Vec::with_capacity(points.len() * samples),
    };
    for &(value, state, _) in points {
        let model = CantileverModel::new(&base.with(param, value))?;
        let mut integ = build(&model, integrator.clone(), 0.0, state)?;
        let tr = record(
            integ.as_mut(),
            &RecordSpec {
                transient_periods: 0.0,
                record_tau: periods as f64 * model.period(),
                samples_per_period,
                energy: false,
                body_contact: false,
            },
        )?;
        // the record holds both ends (samples + 1 points): the last one is the first again
        let rows = tr.samples.iter().take(samples);
        if out.time.is_empty() {
            out.time = (0..samples)
                .map(|k| k as f64 / samples_per_period as f64)
                .collect();
        }
        let before = out.deflection.len();
        for s in rows {
            out.deflection.push(s.w_tip);
            out.distance.push(s.v_t);
            out.force.push(s.contact_force);
        }
        // a short record (never expected) is padded so that the rows stay aligned
        for v in [&mut out.deflection, &mut out.distance, &mut out.force] {
            v.resize(before + samples, f64::NAN);
        }
        out.values.push(value);
    }
    Ok(out)
}

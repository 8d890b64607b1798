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
//! [`Analysis`] (running a request: a study's layer, above the request's data) is here.

use super::Chain;
use crate::analysis::peakforce::{
    peak_force_setpoint, steady_tap, steady_tap_from, PeakForceOptions, SetpointOptions, SteadyTap,
    BRACKET_STEPS, SETPOINT_ITERATIONS,
};
use crate::analysis::progress::Progress;
use crate::error::SimError;
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use crate::request::costs::{newton_work, state_bytes, steady_periods, MODEL_BYTES};
use crate::request::limits::Cost;
use crate::request::peakforce::{document, setpoint_in_newtons, PeakForceResult};
use crate::request::peakforce_sweep::SweepTap;
use crate::request::{Analysis, PeakForceRequest, PeakForceSweep, Request, Resolved};
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
}

impl PeakForceStudy {
    /// The tap at value `i` from the state `start` at τ = 0.
    fn tap(&self, i: usize, start: &DVector<f64>) -> Result<(Params, SteadyTap, usize), SimError> {
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
        for i in done.len()..self.points.len() {
            if cancel.load(Ordering::Relaxed) {
                return Err(SimError::Cancelled);
            }
            let record = match self.tap(i, &start) {
                Ok((params, tap, evaluations)) => {
                    start.copy_from(&tap.state);
                    SweepTap {
                        index: i,
                        params,
                        tap: Some(tap),
                        evaluations,
                        message: None,
                    }
                }
                Err(SimError::Cancelled) => return Err(SimError::Cancelled),
                Err(e) => SweepTap {
                    index: i,
                    params: self.points[i],
                    tap: None,
                    evaluations: 0,
                    message: Some(e.to_string()),
                },
            };
            sink(i, record);
        }
        Ok(())
    }
}

impl Request for PeakForceRequest {
    fn validate(&self, model: &Resolved) -> Result<(), SimError> {
        self.params(model).map(|_| ())
    }
    fn name(&self) -> &'static str {
        "peakforce"
    }
    fn cost(&self, model: &Resolved) -> Result<Cost, SimError> {
        // every tap: the transient (at most its cap) and Newton's variational flows, each drive
        // period spanning 1/Ω lever periods; the setpoint's bracket and iterations; the cycle
        // and the fit's resampling kept
        let p = self.params(model)?;
        let opts = self.options();
        let tap_work = |q: &Params| -> Result<f64, SimError> {
            let lever_periods = (1.0 / q.omega).max(1.0);
            Ok((steady_periods(&opts.steady, q)? * q.modes as f64
                + newton_work(q, 1, &opts.shooting))
                * lever_periods)
        };
        let tap = match &self.sweep {
            Some(s) => self
                .sweep_points(s, model, &p)?
                .iter()
                .map(tap_work)
                .sum::<Result<f64, SimError>>()?,
            None => tap_work(&p)?,
        };
        let per_value = if self.setpoint.is_some() {
            (2 * BRACKET_STEPS + SETPOINT_ITERATIONS) as f64
        } else {
            1.0
        };
        let taps = per_value;
        let samples = (self.samples + crate::analysis::peakforce::FIT_SAMPLES) as f64;
        Ok(Cost {
            bytes: MODEL_BYTES + 2.0 * samples * 4.0 * 8.0 + 64.0 * state_bytes(&p),
            work: taps * tap,
        })
    }
    fn computed_at(&self, model: &Resolved) -> Result<Params, SimError> {
        self.params(model)
    }
}

impl Analysis for PeakForceRequest {
    type Output = PeakForceResult;
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<PeakForceResult, SimError> {
        let p = self.params(model)?;
        if let Some(sweep) = &self.sweep {
            return execute_sweep(self, sweep, model, &p, progress);
        }
        match self.setpoint {
            Some(f) => {
                let force = Self::units(model).force;
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
                })
            }
        }
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
    let force = PeakForceRequest::units(model).force;
    let study = PeakForceStudy {
        points: request.sweep_points(sweep, model, p)?,
        setpoint: request.setpoint.map(|f| f / force),
        options: request.options(),
        fingerprint: json!({"afmdyn": env!("CARGO_PKG_VERSION"), "peakforce": request, "params": p}),
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
        tap,
        sweep: Some(taps),
    })
}

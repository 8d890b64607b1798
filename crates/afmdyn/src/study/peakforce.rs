//! A PeakForce sweep ([`crate::analysis::peakforce`]) as a [`Study`] ([`PeakForceStudy`]): a
//! task is one value of the swept quantity (the mean rest separation z_c, or the modulation
//! frequency), numbered by its place in the values; its record the steady tap there, or why it
//! failed. The tasks form one chain: each tap's transient starts from the previous tap's orbit
//! (its state at τ = 0), which near a smooth branch settles in no more modulation periods
//! than a start from rest (across a change of the tapping it may take more). A
//! point that fails is recorded with its message and the chain goes on from the last orbit
//! found. With a setpoint (a sweep in the modulation frequency under ideal peak-force
//! feedback) each value runs the feedback's own search
//! ([`crate::analysis::peakforce::peak_force_setpoint`], from rest).
//!
//! Run in memory ([`super::execute_in_memory`]) by the `peakforce` request with a sweep.

use super::{Prefix, Study};
use crate::analysis::peakforce::{
    peak_force_setpoint, steady_tap_from, PeakForceOptions, SetpointOptions, SteadyTap,
};
use crate::error::SimError;
use crate::model::CantileverModel;
use crate::params::Params;
use nalgebra::DVector;
use serde_json::Value;
use std::sync::atomic::{AtomicBool, Ordering};

/// One value of a PeakForce sweep: its place, the model it was computed on (α5 is the tap's:
/// the feedback's with a setpoint), and the steady tap or why it failed.
#[derive(Debug, Clone)]
pub struct SweepTap {
    /// Place of the value in the sweep (0-based).
    pub index: usize,
    /// The model's parameters of this tap (α5 found by the feedback with a setpoint).
    pub params: Params,
    /// The steady tap (`None` when the point failed).
    pub tap: Option<SteadyTap>,
    /// Steady taps computed for this value (1 without a setpoint).
    pub evaluations: usize,
    /// Why the point failed (`None` when it was computed).
    pub message: Option<String>,
}

/// A PeakForce sweep as a [`Study`] (see the module doc).
#[derive(Debug, Clone)]
pub struct PeakForceStudy {
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
    /// The records of a finished study (in any order), in the order of the values.
    ///
    /// # Errors
    /// [`SimError::Cancelled`] when a value is missing (a run cut short).
    pub fn taps(&self, mut records: Vec<SweepTap>) -> Result<Vec<SweepTap>, SimError> {
        records.sort_by_key(|r| r.index);
        if records.len() != self.points.len()
            || records.iter().enumerate().any(|(i, r)| r.index != i)
        {
            return Err(SimError::Cancelled);
        }
        Ok(records)
    }

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
                let q = p.with(crate::params::SweepParam::Alpha5, s.alpha5);
                Ok((q, s.tap, s.evaluations))
            }
            None => {
                let tap = steady_tap_from(&CantileverModel::new(&p)?, &self.options, start)?;
                Ok((p, tap, 1))
            }
        }
    }
}

impl Study for PeakForceStudy {
    /// The value's tap.
    type Record = SweepTap;
    /// The stored taps of the first values (the chain goes on from the last orbit).
    type Done = Prefix<SweepTap>;

    fn fingerprint(&self) -> &Value {
        &self.fingerprint
    }

    fn units(&self) -> u64 {
        self.points.len() as u64
    }

    fn done_units(&self, done: &Prefix<SweepTap>) -> u64 {
        done.0.len() as u64
    }

    fn record_units(&self, _: &SweepTap) -> u64 {
        1
    }

    fn run(
        &self,
        done: &Prefix<SweepTap>,
        sink: &(dyn Fn(SweepTap) + Sync),
        cancel: &AtomicBool,
    ) -> Result<(), SimError> {
        let dim = self.points.first().map_or(0, Params::state_dim);
        // the chain starts from the last orbit stored (from rest without one)
        let mut start = done
            .0
            .iter()
            .rev()
            .find_map(|r| r.tap.as_ref().map(|t| t.state.clone()))
            .unwrap_or_else(|| DVector::zeros(dim));
        for i in done.0.len()..self.points.len() {
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
            sink(record);
        }
        Ok(())
    }
}

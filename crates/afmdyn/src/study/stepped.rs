//! A stepped approach–retract or resonance curve ([`crate::analysis::stepped`]) as a
//! `Chain` (`CurveStudy::chain`): a task is one point of the two sweeps, numbered 0..n along the
//! first sweep (approach, up-sweep) and n..2n along the sweep back; the points form one chain
//! — each is stepped from the orbit before it (its state, the secant or quadratic predictor
//! through the points before, the monodromy trend) — so what a resume skips is the stored
//! points themselves, and the chain goes on after the last (`sweep_points`), to the points
//! of an uninterrupted run. The branches, folds, jumps and traces are computed from the two
//! sweeps when the curve is assembled ([`CurveStudy::curve`], `finish_curve`): they are not
//! tasks. Stored by `MemoryStore` for a run that writes no files, by the
//! directory store `curve_store` (feature `files`) for `afmdyn approach|resonance --out
//! DIR`, resumable.
//!
//! The requests' [`Analysis`] (`request::run`, Python's `afmdyn.approach` and
//! `afmdyn.resonance`) run this study in memory.

use super::{execute_in_memory, Chain};
use crate::analysis::progress::Progress;
use crate::analysis::setpoint::operating_points;
use crate::analysis::stepped::{
    check_values, finish_curve, sweep_points, CurvePoint, SteppedCurve, SteppedSpec,
};
use crate::error::SimError;
use crate::report::present::curves::{stepped, CurveKind};
use crate::report::{self, Convergence};
use crate::request::costs::{check_cost, stepped_cost};
use crate::request::run::{
    Analysis, ApproachRequest, Bimodal, Request, Resolved, ResonanceRequest,
};
use serde::Serialize;
use serde_json::{json, Value};

/// A stepped curve, its study a `Chain` (see the module doc): its validated spec and its
/// fingerprint.
#[derive(Debug, Clone)]
pub struct CurveStudy {
    /// The validated sweep.
    pub spec: SteppedSpec,
    /// What a resumed curve must match (`fingerprint`).
    pub fingerprint: Value,
}

/// The fingerprint of a stepped curve: everything that determines its points (the library's
/// version, the kind of curve and its request, the model values and the probe).
pub(crate) fn fingerprint(kind: &str, request: &impl Serialize, model: &Resolved) -> Value {
    json!({
        "afmdyn": env!("CARGO_PKG_VERSION"),
        kind: request,
        "params": model.params,
        "probe": model.probe,
        "z_c_in_file": model.probe.as_ref().map(|p| p.z_c_in_file),
    })
}

impl CurveStudy {
    /// The study of the approach curve `request` on `model`.
    ///
    /// # Errors
    /// As [`ApproachRequest::spec`] and `check_values`; [`SimError::Budget`] beyond the
    /// budgets of a request (`check_cost`).
    pub(crate) fn approach(
        request: &ApproachRequest,
        model: &Resolved,
    ) -> Result<CurveStudy, SimError> {
        CurveStudy::new(
            "approach",
            request.spec(model)?,
            fingerprint("approach", request, model),
        )
    }

    /// The study of the resonance curve `request` on `model`.
    ///
    /// # Errors
    /// As [`ResonanceRequest::spec`] and `check_values`; [`SimError::Budget`] beyond the
    /// budgets of a request (`check_cost`).
    pub fn resonance(request: &ResonanceRequest, model: &Resolved) -> Result<CurveStudy, SimError> {
        CurveStudy::new(
            "resonance",
            request.spec(model)?,
            fingerprint("resonance", request, model),
        )
    }

    fn new(
        what: &'static str,
        spec: SteppedSpec,
        mut fingerprint: Value,
    ) -> Result<CurveStudy, SimError> {
        check_values(&spec)?;
        // points measured on invariant circles are not those of the exact orbits a store
        // written before them holds (its fingerprint has no such key): such a store is not
        // resumed by a run on circles, nor the other way round
        if let (Some(t), Some(fp)) = (&spec.torus, fingerprint.as_object_mut()) {
            fp.insert("invariant_circles".into(), json!({ "nodes": t.nodes }));
        }
        // held to the budgets here too: a front end runs the study into its store without
        // `run`
        check_cost(what, stepped_cost(&spec)?)?;
        Ok(CurveStudy { spec, fingerprint })
    }

    /// The curve of a finished study's records (in any order): the two sweeps, then the
    /// branches (their points counted in `progress`), folds, jumps and traces
    /// (`finish_curve`).
    ///
    /// # Errors
    /// [`SimError::Cancelled`] when a point is missing (a run that was cut short) or once
    /// `progress` is cancelled; as `finish_curve`.
    pub fn curve(
        &self,
        records: impl IntoIterator<Item = (usize, CurvePoint)>,
        progress: &Progress,
    ) -> Result<SteppedCurve, SimError> {
        let n = self.spec.values.len();
        let mut points = super::in_order(records.into_iter().collect(), 2 * n)?;
        let second = points.split_off(n);
        finish_curve(&self.spec, points, second, progress)
    }

    /// The curve as a `Chain`: its points (one unit each) of both sweeps, `0..2n`, stepped
    /// after the stored points up to the first one missing ([`Prefix`](super::Prefix),
    /// [`sweep_points`]).
    pub(crate) fn chain(&self) -> Chain<'_, CurvePoint> {
        let n = 2 * self.spec.values.len();
        Chain::new(&self.fingerprint, n, |done, sink, cancel| {
            let store = |k: usize, p: &CurvePoint| sink(k, p.clone());
            sweep_points(&self.spec, done, cancel, &store).map(|_| ())
        })
    }

    /// Run the study in memory and assemble its curve.
    fn run_in_memory(&self, progress: &Progress) -> Result<SteppedCurve, SimError> {
        let records = execute_in_memory(&self.chain(), None, progress)?;
        self.curve(records, progress)
    }
}

/// [`Analysis::present`] of a stepped curve of kind `$kind`: its presentation
/// ([`crate::report::present::curves::stepped`]) with every file, named as the request.
macro_rules! present_curve {
    ($kind:expr) => {
        fn present(
            &self,
            c: &Self::Output,
            at: crate::request::Presenting<'_>,
        ) -> Result<report::Presentation, SimError> {
            Ok(stepped(
                $kind,
                (&at.model.params, at.model.probe.as_ref()),
                c,
                at.document,
                at.units,
                &at.to.curve(self.name()),
            ))
        }
    };
}

/// A stepped curve's convergence: its points of both sweeps, a time-averaged point that did
/// not settle within its transient cap counted out.
fn curve_convergence(c: &SteppedCurve) -> Convergence {
    let points: Vec<_> = c.first.iter().chain(&c.second).collect();
    Convergence::count("points", &points, |p| !p.unsettled())
}

impl Analysis for ApproachRequest {
    type Output = SteppedCurve;
    fn convergence(&self, c: &SteppedCurve) -> Convergence {
        curve_convergence(c)
    }
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<Self::Output, SimError> {
        CurveStudy::approach(self, model)?.run_in_memory(progress)
    }
    fn report(&self, model: &Resolved, c: &Self::Output) -> Result<Value, SimError> {
        let u = model.units(false);
        let mut doc = report::approach(&model.params, c, &u);
        if let Some(s) = self.setpoint {
            let (points, dropped) = operating_points(&self.spec(model)?, c, s)?;
            doc["setpoint"] = report::setpoint(&model.params, c, (&points, &dropped), s, &u);
            // a crossing left out, in the document's warnings too (every front end shows them)
            let gaps = doc["setpoint"]["warnings"].as_array().cloned();
            if let (Some(gaps), Some(ws)) = (gaps, doc["warnings"].as_array_mut()) {
                ws.extend(gaps);
            }
        }
        if let (Some(t), Some(n)) = (self.temperature, self.spec(model)?.noise) {
            doc["thermal"] = report::thermal_noise(&model.params, t, n.time_constant, &u);
            let ws = crate::request::limits::temperature_warnings(t);
            if let Some(w) = doc["warnings"].as_array_mut() {
                w.extend(ws.into_iter().map(Value::from));
            }
        }
        // the default range ends at the soft sample's force bound (default_range): say so when
        // the amplitude has not come down to half the free one by then
        if self.curve.to.is_none() && self.curve.from.is_none() {
            if let Some(w) = soft_sample_warning(&model.params, c, &u) {
                if let Some(ws) = doc["warnings"].as_array_mut() {
                    ws.push(w.into());
                }
            }
        }
        Ok(doc)
    }
    fn largest_indentation(&self, c: &Self::Output) -> Option<f64> {
        Some(c.largest_indentation())
    }
    present_curve!(CurveKind::Approach);
}

impl Analysis for ResonanceRequest {
    type Output = SteppedCurve;
    fn convergence(&self, c: &SteppedCurve) -> Convergence {
        curve_convergence(c)
    }
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<Self::Output, SimError> {
        CurveStudy::resonance(self, model)?.run_in_memory(progress)
    }
    fn report(&self, model: &Resolved, c: &Self::Output) -> Result<Value, SimError> {
        Ok(report::resonance(
            &self.computed_at(model)?,
            c,
            &model.units(true),
        ))
    }
    fn largest_indentation(&self, c: &Self::Output) -> Option<f64> {
        Some(c.largest_indentation())
    }
    present_curve!(CurveKind::Resonance);
}

/// The resumable store of a stepped curve (feature `files`): a
/// [`TaskStore`](crate::study::task_store::TaskStore) of points in the directory
/// `afmdyn approach|resonance --out DIR` names — `.curve.run.json` (the ledger) and
/// `.curve.points.jsonl` (one checksummed line per point, in CBOR under `"point"`), as
/// [`crate::study::task_store`] describes.
#[cfg(feature = "files")]
pub(crate) mod store {
    use super::super::task_store::{Encoding, Lines, TaskFiles, TaskStore};
    use crate::analysis::stepped::CurvePoint;
    use crate::io::dir_lock::DirLock;

    /// A stepped curve's files.
    pub(crate) const CURVE_FILES: TaskFiles = TaskFiles {
        ledger: ".curve.run.json",
        records: ".curve.points.jsonl",
        key: "point",
        prefix: "",
        encoding: Encoding::Cbor,
    };

    /// A stepped curve's store: its points by place.
    pub(crate) type CurveStore<'a> = TaskStore<'a, Lines<CurvePoint>>;

    /// The curve store of the directory `lock` holds.
    pub(crate) fn curve_store(lock: &DirLock) -> CurveStore<'_> {
        TaskStore::new(lock, Lines::of(CURVE_FILES)).keeping()
    }
}

#[cfg(feature = "files")]
pub(crate) use store::curve_store;

/// A warning when an approach over the default range
/// ([`crate::analysis::approach::default_range`]) never brought the amplitude down to 0.5 A₀:
/// on a sample so soft that it pushes back with the peak force of tapping only deep inside it
/// ([`crate::analysis::approach::soft_indentation`]), the range ends there (a peak-force
/// bound) and the setpoints a user would image at are not on the curve.
fn soft_sample_warning(
    params: &crate::params::Params,
    c: &crate::analysis::stepped::SteppedCurve,
    u: &report::CurveUnits,
) -> Option<String> {
    let ratio = |p: &crate::analysis::stepped::CurvePoint| {
        p.observables.amplitude / p.observables.closed_form.free_amplitude
    };
    let lowest = c.first.iter().map(ratio).fold(f64::INFINITY, f64::min);
    let last = c.first.last()?;
    if lowest.is_nan() || lowest <= 0.5 {
        return None;
    }
    let z = crate::analysis::approach::rest_distance(params, last.value) * u.length;
    Some(warning!(
        "approach.soft-sample",
        "Take a softer lever or a smaller A0, or give a deeper `to` for the range.",
        "the amplitude stays above {} A0 down to the default range's end, z_c = {} {}, where \
         the sample already pushes back with the peak force of tapping at A/A0 = 0.5 (about \
         min(1, 3/Q) k A0): the sample is too compliant for this lever to reach the usual setpoints (A/A0 ≤ 0.5) \
         within its contact law's validity; a softer lever or a smaller A0 would (or a deeper \
         `to` for the range)",
        crate::error::number((lowest * 1e3).floor() / 1e3),
        crate::error::number(z),
        if u.si { "m" } else { "g0" },
    ))
}

impl Analysis for Bimodal {
    type Output = SteppedCurve;
    fn convergence(&self, c: &SteppedCurve) -> Convergence {
        curve_convergence(c)
    }
    fn execute(
        &self,
        model: &Resolved,
        progress: &crate::analysis::progress::Progress,
    ) -> Result<Self::Output, SimError> {
        crate::request::curves::check_bimodal(&model.params)?;
        self.0.execute(model, progress)
    }
    fn report(&self, model: &Resolved, c: &Self::Output) -> Result<serde_json::Value, SimError> {
        self.0.report(model, c)
    }
    fn largest_indentation(&self, c: &Self::Output) -> Option<f64> {
        self.0.largest_indentation(c)
    }
    fn present(
        &self,
        c: &Self::Output,
        at: crate::request::Presenting<'_>,
    ) -> Result<crate::report::Presentation, SimError> {
        let options = at.to.curve("bimodal");
        Ok(stepped(
            CurveKind::Approach,
            (&at.model.params, at.model.probe.as_ref()),
            c,
            at.document,
            at.units,
            &options,
        ))
    }
}

//! `fit-map`'s running ([`crate::request::fit_map`] is the request): every curve of a map
//! fitted as `fit` fits one (`FitRequest::fit_curve`, its intervals Wald's), as a study of
//! independent tasks — one task a line of the map, its curves read from the file one at a time
//! ([`crate::io::force_map`]), so memory holds the map's index, its records and one curve per
//! worker. Each curve's record ([`CurveFit`]) carries its estimates and a flag
//! ([`CurveFlag`]): a result at a bound of its physical range, or not constrained by the data,
//! is flagged, never clamped silently. The store (`fit_map_store`) resumes an interrupted map
//! of the same request, map file and probe.

use super::fit::Curve;
#[cfg(feature = "files")]
use super::task_store::{Encoding, Lines, TaskFiles, TaskStore};
use super::Tasks;
use crate::analysis::fit::force_curve::{Segment, BASELINE, CONTACT_POINT};
use crate::analysis::fit::map::SHOWN_POINTS;
pub use crate::analysis::fit::map::{CurveFit, CurveFlag, FitMap, ShownCurve};
use crate::analysis::progress::Progress;
use crate::contact::LawKind;
use crate::error::SimError;
#[cfg(feature = "files")]
use crate::io::dir_lock::DirLock;
use crate::io::force_map::{ForceMap, MapCurve};
use crate::probe::SampleInputs;
use crate::report::Convergence;
use crate::request::fit::FitRequest;
use crate::request::fit_map::FitMapRequest;
use crate::request::fit_result::MIN_FIT_ROWS;
use crate::request::run::{Analysis, Resolved};
use serde_json::{json, Value};
use std::sync::atomic::{AtomicBool, Ordering};

/// The map's files: `.fit_map.run.json` (the ledger) and `.fit_map.lines.jsonl` (one line of
/// curves per finished task).
#[cfg(feature = "files")]
pub(crate) const FIT_MAP_FILES: TaskFiles = TaskFiles {
    ledger: ".fit_map.run.json",
    records: ".fit_map.lines.jsonl",
    key: "curves",
    prefix: "fit_map.",
    encoding: Encoding::Json,
};

/// The fit-map store of the directory `lock` holds.
#[cfg(feature = "files")]
pub(crate) fn fit_map_store(lock: &DirLock) -> TaskStore<'_, Lines<Vec<CurveFit>>> {
    TaskStore::new(lock, Lines::of(FIT_MAP_FILES))
}

/// The refits of a curve whose thickness is its contact point's height above the substrate,
/// at most, and the relative move of the thickness they stop at.
const LAYER_STEPS: usize = 8;
const LAYER_TOLERANCE: f64 = 1e-4;

/// The curves shown with their fits: at most this many, spread over the map.
const SHOWN_CURVES: usize = 4;

/// A map ready to fit: the request, the map's index, the law, the probe's sample and spring
/// constant, and what a resumed run must match.
pub struct MapStudy {
    request: FitRequest,
    map: ForceMap,
    law: LawKind,
    sample: SampleInputs,
    spring_constant: f64,
    names: Vec<String>,
    /// The substrate's piezo height each curve's thickness is measured from (m).
    substrate_height: Option<f64>,
    /// How the thickness was given, for the document.
    layer: Option<String>,
    shown: Vec<usize>,
    fingerprint: Value,
}

impl MapStudy {
    /// The study of `request` on `model` (validated): the map indexed.
    ///
    /// # Errors
    /// The request's checks; the map file's refusals naming `data`.
    pub(crate) fn new(request: &FitMapRequest, model: &Resolved) -> Result<MapStudy, SimError> {
        let curve_request = request.curve_request();
        let law = curve_request.check(model)?;
        let map = request.index()?;
        let probe = model.probe.as_ref().expect("checked by FitRequest::check");
        let n = map.curves.len();
        let mut shown: Vec<usize> = (0..SHOWN_CURVES)
            .map(|i| i * (n - 1) / (SHOWN_CURVES - 1).max(1))
            .collect();
        shown.dedup();
        Ok(MapStudy {
            names: curve_request.fitted(law),
            request: curve_request,
            substrate_height: request.substrate_height,
            layer: layer_of(request),
            law,
            sample: probe.sample_inputs,
            spring_constant: probe.calibration.spring_constant,
            shown,
            fingerprint: json!({
                "afmdyn": env!("CARGO_PKG_VERSION"),
                "fit_map": request,
                "map": {"bytes": map.bytes, "curves": n, "x": map.xs.len(), "y": map.ys.len()},
                "probe": model.probe,
            }),
            map,
        })
    }

    /// The study's tasks: the map's lines, each counting its curves.
    pub(crate) fn tasks(&self) -> Tasks<'_, Vec<CurveFit>> {
        Tasks::new(&self.fingerprint, self.lines(), move |t, cancel| {
            self.line(t, cancel)
        })
        .weighted(move |t| self.map.lines[t].len() as u64)
    }

    /// The number of the map's lines (its tasks).
    pub(crate) fn lines(&self) -> usize {
        self.map.lines.len()
    }

    /// What a resumed run must match (the store's fingerprint).
    #[cfg(feature = "files")]
    pub(crate) fn fingerprint(&self) -> &Value {
        &self.fingerprint
    }

    /// The fits of line `t`'s curves; `None` when cancelled before its end.
    pub(crate) fn line(
        &self,
        t: usize,
        cancel: &AtomicBool,
    ) -> Result<Option<Vec<CurveFit>>, SimError> {
        let range = self.map.lines[t].clone();
        let mut reader = match self.map.reader() {
            Ok(r) => r,
            Err(e) => return Err(SimError::out_of_range("data", "the map", e.to_string())),
        };
        let mut fits = Vec::with_capacity(range.len());
        for i in range {
            if cancel.load(Ordering::Relaxed) {
                return Ok(None);
            }
            let curve = &self.map.curves[i];
            let fit = match reader.read(curve) {
                Ok(rows) => self.fit(curve, rows, self.shown.contains(&i)),
                Err(e) => failed(curve, self.names.len(), e.to_string()),
            };
            fits.push(fit);
        }
        Ok(Some(fits))
    }

    /// The fit of one curve's `rows`, flagged; its data and fit kept when `show`.
    fn fit(&self, c: &MapCurve, rows: crate::io::force_map::CurveRows, show: bool) -> CurveFit {
        let k = c.spring_constant.unwrap_or(self.spring_constant);
        let curve = Curve {
            height: &rows.height,
            force: &rows.force,
            sigma: None,
            time: rows.time,
            spring_constant: k,
            approach_rows: c.approach_rows,
        };
        let (r, thickness) = match self.fit_layer(curve) {
            Ok(r) => r,
            Err(e) => return failed(c, self.names.len(), e.to_string()),
        };
        let o = &r.outcome;
        let at = |name: &str| r.names.iter().position(|n| *n == name);
        let value = |name: &str| at(name).map_or(0.0, |i| o.values[i]);
        let cp = value(CONTACT_POINT);
        let x: Vec<f64> = r.rows.iter().map(|&i| r.curve.tip_position[i]).collect();
        let contact_rows = x.iter().filter(|&&x| x < cp).count();
        let contact_height = contact_height_of(&r, k);
        let finite = |v: f64| v.is_finite().then_some(v);
        let (flag, reason) = flag_of(&r, contact_rows, value(BASELINE));
        let shown = show.then(|| {
            let step = x.len().div_ceil(SHOWN_POINTS).max(1);
            let pick = |v: &[f64]| v.iter().step_by(step).copied().collect();
            let y: Vec<f64> = r.rows.iter().map(|&i| r.curve.force[i]).collect();
            ShownCurve {
                tip_position: pick(&x),
                force: pick(&y),
                fit: pick(&o.fitted),
            }
        });
        CurveFit {
            ix: c.ix,
            iy: c.iy,
            x: c.x,
            y: c.y,
            values: o.estimates.iter().map(|e| finite(e.value)).collect(),
            standard_errors: o
                .estimates
                .iter()
                .map(|e| finite(e.standard_error))
                .collect(),
            intervals: o.estimates.iter().map(|e| e.interval.map(finite)).collect(),
            chi2_dof: finite(o.chi2_dof),
            contact_rows,
            contact_height: finite(contact_height),
            spring_constant: Some(k),
            thickness,
            flag,
            reason,
            data_warning: r.data_warnings.first().cloned(),
            shown,
        }
    }

    /// The fit of `curve` and the sample's thickness it was fitted with: the request's, or,
    /// with a substrate height, the fitted contact point's height above it — fitted first
    /// with the thickness under the contact point by the deviation from the baseline (nanite's
    /// preprocessing), then again with the thickness under the contact point the last fit
    /// found, until the thickness moves by at most [`LAYER_TOLERANCE`] of itself (at most
    /// [`LAYER_STEPS`] refits: the contact moves by nm where the thickness is µm).
    ///
    /// # Errors
    /// `fit`'s, and [`SimError::OutOfRange`] naming `substrate_height` for a contact not
    /// above the substrate.
    fn fit_layer(
        &self,
        curve: Curve<'_>,
    ) -> Result<(super::fit_result::FitResult, Option<f64>), SimError> {
        let never = Progress::new();
        let (law, s) = (self.law, &self.sample);
        let Some(z) = self.substrate_height else {
            let r = self.request.fit_curve(law, s, curve, None, &never)?;
            return Ok((r, self.request.thickness));
        };
        let k = curve.spring_constant;
        let at = |h: f64| FitRequest {
            thickness: Some(h),
            ..self.request.clone()
        };
        let first = crate::analysis::fit::force_curve::preprocess(curve.height, curve.force, k);
        // the contact's piezo height: tip position 0 after correct_tip_offset, force 0
        let mut h = thickness_above(z, first.tip_offset - first.force_offset / k)?;
        let mut r = at(h).fit_curve(law, s, curve.clone(), None, &never)?;
        for _ in 0..LAYER_STEPS {
            let next = thickness_above(z, contact_height_of(&r, k))?;
            if (next - h).abs() <= LAYER_TOLERANCE * h {
                break;
            }
            h = next;
            r = at(h).fit_curve(law, s, curve.clone(), None, &never)?;
        }
        Ok((r, Some(h)))
    }

    /// The fitted map of the tasks' `records` (any order).
    ///
    /// # Errors
    /// [`SimError::Cancelled`] when a line is missing (a run cut short).
    pub(crate) fn assemble(
        &self,
        records: Vec<(usize, Vec<CurveFit>)>,
    ) -> Result<FitMap, SimError> {
        let lines = super::in_order(records, self.map.lines.len())?;
        Ok(FitMap {
            law: self.law,
            xs: self.map.xs.clone(),
            ys: self.map.ys.clone(),
            names: self.names.clone(),
            curves: lines.into_iter().flatten().collect(),
            segment: match self.request.segment_of(self.law) {
                Segment::Approach => "approach",
                Segment::Retract => "retract",
                Segment::Whole => "whole",
            },
            range: self.request.range,
            layer: self.layer.clone(),
        })
    }
}

/// How `request` gives the sample's thickness, for the document (`None`: infinitely thick).
fn layer_of(request: &FitMapRequest) -> Option<String> {
    let bonded = match request.bonded {
        Some(false) => "non-bonded",
        _ => "bonded",
    };
    let n = crate::error::number;
    match (request.thickness, request.substrate_height) {
        (Some(h), _) => Some(format!("{bonded}, {} m thick at every curve", n(h))),
        (None, Some(z)) => Some(format!(
            "{bonded}, each curve's thickness its fitted contact point's height above the \
             substrate's height {} m (fitted from deviation_from_baseline's, then refitted)",
            n(z)
        )),
        (None, None) => None,
    }
}

/// The fitted contact point's piezo height (m) of the fit `r` of a curve under the spring
/// constant `k`: the topography.
fn contact_height_of(r: &super::fit_result::FitResult, k: f64) -> f64 {
    let value = |name: &str| {
        let i = r.names.iter().position(|n| *n == name);
        i.map_or(0.0, |i| r.outcome.values[i])
    };
    value(CONTACT_POINT) + r.curve.tip_offset - (r.curve.force_offset + value(BASELINE)) / k
}

/// The sample's thickness under a contact at the piezo height `contact` above the substrate's
/// `z` (m).
///
/// # Errors
/// [`SimError::OutOfRange`] naming `substrate_height` when the contact is not above it.
fn thickness_above(z: f64, contact: f64) -> Result<f64, SimError> {
    let h = contact - z;
    if h > 0.0 && h.is_finite() {
        return Ok(h);
    }
    Err(SimError::out_of_range(
        "substrate_height",
        crate::error::number(z),
        format!(
            "the curve's contact point is at the piezo height {} m, not above the substrate: \
             no sample to correct for",
            crate::error::number(contact)
        ),
    ))
}

/// The map's failure when no curve was fitted at all (the first curve's reason): no answer.
pub fn every_curve_failed(m: &FitMap) -> Option<SimError> {
    if m.curves.iter().any(|c| c.flag != CurveFlag::Failed) {
        return None;
    }
    Some(SimError::EveryRunFailed {
        what: "map curves",
        runs: m.curves.len(),
        first: m
            .curves
            .iter()
            .find_map(|c| c.reason.clone())
            .unwrap_or_default(),
    })
}

/// The record of a curve without a fit, for `reason`.
fn failed(c: &MapCurve, n: usize, reason: String) -> CurveFit {
    CurveFit {
        ix: c.ix,
        iy: c.iy,
        x: c.x,
        y: c.y,
        values: vec![None; n],
        standard_errors: vec![None; n],
        intervals: vec![[None; 2]; n],
        chi2_dof: None,
        contact_rows: 0,
        contact_height: None,
        spring_constant: c.spring_constant,
        thickness: None,
        flag: CurveFlag::Failed,
        reason: Some(reason),
        data_warning: None,
        shown: None,
    }
}

/// The flag of the fit `r` with `contact_rows` rows indented and the fitted `baseline` (N),
/// and its reason: the first of too few contact rows; no contact (the fitted contact force
/// never rises 3 σ above the baseline, σ the noise the residuals give: a curve on the
/// substrate beside a cell, or one that stops short of the sample, whose E the fit drives to
/// anything); a minimiser that did not converge (`failed`, its values kept); an estimate at a bound of its physical range ([`super::fit_result::bounds`]);
/// an estimate not constrained (no finite standard error; for a probe key, a standard error as
/// large as the value).
fn flag_of(
    r: &super::fit_result::FitResult,
    contact_rows: usize,
    baseline: f64,
) -> (CurveFlag, Option<String>) {
    if contact_rows < MIN_FIT_ROWS {
        return (
            CurveFlag::TooFewContactRows,
            Some(format!(
                "{contact_rows} rows indented beyond the contact point (at least {MIN_FIT_ROWS})"
            )),
        );
    }
    let o = &r.outcome;
    let peak = o.fitted.iter().fold(0.0_f64, |m, f| m.max(f - baseline));
    let noise = if o.noise_estimated {
        o.chi2_dof.sqrt()
    } else {
        0.0
    };
    // (a NaN peak or noise is no contact either)
    if peak.partial_cmp(&(3.0 * noise)) != Some(std::cmp::Ordering::Greater) {
        return (
            CurveFlag::NotConstrained,
            Some(format!(
                "no contact: the fitted contact force peaks at {peak:.3e} N, within 3 σ of the \
                 noise (σ = {noise:.3e} N)"
            )),
        );
    }
    if !o.converged {
        return (
            CurveFlag::Failed,
            Some(format!(
                "the minimiser did not converge ({})",
                o.termination
            )),
        );
    }
    for e in &r.outcome.estimates {
        let (lo, hi) = super::fit_result::bounds(&e.name);
        let near = |b: f64| b.is_finite() && (e.value - b).abs() <= 1e-9 * b.abs().max(1e-300);
        if near(lo) || near(hi) {
            let which = if near(lo) { "lower" } else { "upper" };
            return (
                CurveFlag::AtBound,
                Some(format!("{} = {:.4e} at its {which} bound", e.name, e.value)),
            );
        }
    }
    for e in &r.outcome.estimates {
        let positive = e.name.contains('.');
        if !e.standard_error.is_finite() || (positive && e.standard_error >= e.value.abs()) {
            return (
                CurveFlag::NotConstrained,
                Some(format!(
                    "{} = {:.4e} ± {:.2e}: not constrained by the data",
                    e.name, e.value, e.standard_error
                )),
            );
        }
    }
    (CurveFlag::Fitted, None)
}

impl Analysis for FitMapRequest {
    type Output = FitMap;
    fn convergence(&self, m: &FitMap) -> Convergence {
        // a curve converged when its fit did (its flag says what the fit determines)
        Convergence::count("curves", &m.curves, |c| c.flag != CurveFlag::Failed)
    }
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<FitMap, SimError> {
        let study = MapStudy::new(self, model)?;
        let records = super::execute_in_memory(&study.tasks(), self.threads, progress)?;
        let map = study.assemble(records)?;
        match every_curve_failed(&map) {
            Some(e) => Err(e),
            None => Ok(map),
        }
    }
    fn report(&self, _: &Resolved, m: &FitMap) -> Result<Value, SimError> {
        Ok(crate::report::fit_map::document(m))
    }
    fn present(
        &self,
        m: &FitMap,
        at: crate::request::Presenting<'_>,
    ) -> Result<crate::report::Presentation, SimError> {
        Ok(crate::report::present::fit_map::fit_map(m, at.document))
    }
}

impl super::named::Datasets for FitMapRequest {
    /// `fit_map` ([`crate::report::fit_map::layout`]); the counts per flag as facts.
    fn datasets(&self, _: &Resolved, m: &FitMap) -> Result<super::named::Arrays, SimError> {
        let facts = m
            .counts()
            .into_iter()
            .map(|(name, n)| (format!("curves_{name}"), json!(n)))
            .collect();
        Ok((
            vec![("fit_map".into(), crate::report::fit_map::layout(m))],
            facts,
        ))
    }
}

/// A map runs resumably into its store: its lines, each a task.
#[cfg(feature = "files")]
impl super::stored::Resumable for FitMapRequest {
    type Study = MapStudy;
    fn study(&self, model: &Resolved) -> Result<MapStudy, SimError> {
        MapStudy::new(self, model)
    }
    fn resume(
        &self,
        study: &MapStudy,
        _: &Resolved,
        storage: super::stored::Storage<'_>,
        progress: &Progress,
    ) -> Result<FitMap, super::StudyError> {
        let records = storage.records(&study.tasks(), fit_map_store, self.threads, progress)?;
        Ok(study.assemble(records)?)
    }
    fn failure(&self, m: &FitMap) -> Option<super::stored::Failure> {
        Some(super::stored::Failure {
            error: every_curve_failed(m)?,
            with_document: false,
        })
    }
}

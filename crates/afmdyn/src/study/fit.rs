//! `fit`'s running ([`crate::request::fit`] is the request): a measured quasi-static force
//! curve fitted with a contact law of the registry ([`crate::analysis::fit::force_curve`]) —
//! its preprocessing, rows and start values, and its document: estimates with standard errors
//! and 95 % intervals, the correlation matrix, χ²/dof, the fitted curve beside the data, the
//! residuals and the identifiability warnings (the result, [`FitResult`], is
//! `super::fit_result`'s, shared with the dynamic fit, [`super::fit_dynamic`]). Everything is SI
//! (m, N, Pa, J/m²).

use crate::analysis::fit::contact_rows::ContactRows;
use crate::analysis::fit::force_curve::{
    self, preprocess, ForceCurveModel, Preprocessed, Segment, BASELINE, CONTACT_POINT, HAMAKER,
    RADIUS, YOUNGS_MODULUS,
};
use crate::analysis::fit::profile::ProfileWalk;
use crate::analysis::fit::sls_curve::{
    SlsCurveModel, MAXWELL_STIFFNESS, RELAXATION_TIME, STIFFNESS,
};
use crate::analysis::fit::start::coarse_start;
use crate::analysis::fit::{fit_cancellable, CurveModel, Observations, Parameter, ProfileEnd};
use crate::analysis::progress::Progress;
use crate::contact::LawKind;
use crate::error::SimError;
use crate::probe::SampleInputs;
use crate::report::Convergence;
use crate::request::fit::{bad, check_columns, FitRequest};
use crate::request::fit_result::{probe_value, MIN_FIT_ROWS};
use crate::request::run::{Analysis, Resolved};
use crate::study::named::{Arrays, Datasets};
use serde_json::{json, Value};

pub use super::fit_result::FitResult;
use super::fit_result::{bounds, intervals_method};

impl FitRequest {
    /// The thermal force noise σ_F = k √(⟨z*²⟩_B + n_d² B) (N) at `temperature` (the request's
    /// `temperature` docs): the probe's modes (`crate::analysis::thermal`) and its spring
    /// constant k, B the `bandwidth` or the Nyquist frequency of the rows' `time`.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `bandwidth` when neither is given; the thermal
    /// spectrum's errors.
    fn thermal_sigma(
        &self,
        model: &Resolved,
        temperature: f64,
        time: Option<&[f64]>,
        progress: &Progress,
    ) -> Result<f64, SimError> {
        use crate::analysis::thermal::{apparent_mean_square_in_band, thermal_spectrum};
        let probe = model.probe.as_ref().expect("checked");
        let nyquist = time
            .filter(|t| t.len() > 1)
            .map(|t| 0.5 * (t.len() - 1) as f64 / (t[t.len() - 1] - t[0]));
        let b = self.bandwidth.or(nyquist).ok_or_else(|| {
            bad(
                "bandwidth",
                "missing",
                "the thermal σ needs the detection bandwidth (Hz), or a time column",
            )
        })?;
        let units = super::model_units(&probe.scales);
        let s = thermal_spectrum(&model.params, units, temperature, 1.0, &[], progress)?;
        let floor = self.detector_noise.unwrap_or(0.0).powi(2) * b;
        let k = probe.calibration.spring_constant;
        Ok(k * (apparent_mean_square_in_band(&s.modes, b) + floor).sqrt())
    }

    /// The curve of `height` and `force` (and the sls law's `time`) preprocessed with the
    /// lever's spring constant `k`, its approach `approach_rows` long when given (the
    /// request's, or a map curve's segments).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `approach_rows` beyond the curve's rows, or `time` for
    /// the sls law without it.
    fn preprocessed(
        &self,
        law: LawKind,
        height: &[f64],
        force: &[f64],
        time: Option<Vec<f64>>,
        k: f64,
        approach_rows: Option<usize>,
    ) -> Result<Preprocessed, SimError> {
        let mut curve = preprocess(height, force, k);
        if let Some(n) = approach_rows {
            if !(1..=force.len()).contains(&n) {
                return Err(bad(
                    "approach_rows",
                    n,
                    format!("must be 1..={} (the curve's rows)", force.len()),
                ));
            }
            curve.approach_len = n;
        }
        if law == LawKind::Sls && time.is_none() {
            return Err(bad(
                "time",
                "missing",
                "the sls law's force depends on the indentation's history: give the rows' \
                 times (s), a time column",
            ));
        }
        curve.time = time;
        Ok(curve)
    }
}

/// The rows of `curve`'s `segment` in `range`, enough of them to fit `fitted` parameters.
///
/// # Errors
/// [`SimError::OutOfRange`] naming `range` when there are too few.
fn fit_rows(
    curve: &Preprocessed,
    segment: Segment,
    range: Option<[f64; 2]>,
    fitted: usize,
) -> Result<Vec<usize>, SimError> {
    let rows = curve.rows(segment, range);
    if rows.len() < MIN_FIT_ROWS.max(fitted + 1) {
        let part = match segment {
            Segment::Approach => "approach",
            Segment::Retract => "retract",
            Segment::Whole => "curve",
        };
        // the range named only where one was given (a constant-height curve has no approach)
        let (name, where_) = match range {
            Some(_) => ("range", " in the range"),
            None => ("segment", ""),
        };
        return Err(bad(
            name,
            format!("{} rows", rows.len()),
            format!("too few rows of the {part}{where_} to fit {fitted} parameters"),
        ));
    }
    Ok(rows)
}

/// Every parameter of the law (`names`) with its start (the probe's sample `s`; the contact
/// point and baseline at 0), scale (the tip positions `x` and forces `y` fitted for those
/// two) and range.
///
/// # Errors
/// [`SimError::OutOfRange`] naming `probe` and the first value the probe lacks.
fn start_values(
    names: &[&'static str],
    s: &SampleInputs,
    x: &[f64],
    y: &[f64],
) -> Result<Vec<Parameter>, SimError> {
    let span = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let fmax = y.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let mut params = Vec::new();
    for &name in names {
        let (start, scale) = match name {
            CONTACT_POINT => (0.0, (0.1 * span).max(1e-12)),
            BASELINE => (0.0, (0.01 * fmax).max(1e-15)),
            HAMAKER => {
                let h = probe_value(s.hamaker, HAMAKER)?;
                (h, h.max(1e-21))
            }
            YOUNGS_MODULUS | RADIUS | STIFFNESS | MAXWELL_STIFFNESS | RELAXATION_TIME => {
                let v = match name {
                    YOUNGS_MODULUS => s.youngs_modulus,
                    RADIUS => s.radius,
                    STIFFNESS => s.stiffness,
                    MAXWELL_STIFFNESS => s.maxwell_stiffness,
                    _ => s.relaxation_time,
                };
                let v = probe_value(v, name)?;
                (v, v)
            }
            _ => {
                let w = probe_value(s.adhesion_energy, "sample.adhesion_energy")?;
                (w, w.max(1e-3))
            }
        };
        let (lower, upper) = bounds(name);
        params.push(Parameter {
            name: name.into(),
            start,
            lower,
            upper,
            scale,
        });
    }
    Ok(params)
}

/// The warning of an sls fit (its values `p`) whose curve is in contact at its first row: the
/// model starts the sample at rest there.
fn sls_start_warning(model: &SlsCurveModel, p: &[f64]) -> Option<String> {
    let mut f = vec![0.0; model.height.len()];
    model.forces(p, &mut f, None);
    f.first().is_some_and(|f| *f > 0.0).then(|| {
        warning!(
            "fit.sls-start",
            "Record the approach from off the surface.",
            "the fitted curve is in contact at its first row ({:.3e} N): the sls model \
             starts the sample at rest there, so a curve that starts on the surface is \
             misfitted; record the approach from off the surface",
            f[0]
        )
    })
}

/// A force curve's columns held against the probe (issue 77 item 4): the heights' span
/// against a piezo's travel (1 nm to 100 µm), the forces' span against what the lever's
/// deflection over that span allows (k × the heights' span, from 10⁻⁴ of it on a soft sample
/// to 10 times it).
pub(crate) fn data_warnings(height: &[f64], force: &[f64], k: f64) -> Vec<String> {
    use crate::request::quantity::{span, unit_slip, Dim};
    let h = span(height);
    let slips = [
        unit_slip("height", "the span", h, Dim::Length, (1e-9, 1e-4)),
        unit_slip(
            "force",
            "the span",
            span(force),
            Dim::Force,
            (1e-4 * k * h, 10.0 * k * h),
        ),
    ];
    slips.into_iter().flatten().collect()
}

/// A contact point fitted more than the tip positions' span outside them (both after the
/// preprocessing's offset): the fit has not found the contact (issue 77 item 4: a curve in nm
/// and nN gave −1445 m).
fn contact_point_warning(tip: &[f64], contact: f64) -> Option<String> {
    let (lo, hi) = crate::request::quantity::extent(tip);
    let h = (hi - lo).max(0.0);
    (contact < lo - h || contact > hi + h).then(|| {
        warning!(
            "fit.contact-point",
            "Check the columns' units and the curve's segment.",
            "contact_point = {contact:.4e} m lies far outside the tip positions measured \
             ({lo:.4e} to {hi:.4e} m, after the preprocessing's offset): the fit has not found the contact; check the columns' units and the \
             curve's segment"
        )
    })
}

/// One measured force curve: its piezo heights (m), forces (N), their σ (N) and the rows'
/// times (s), the lever's spring constant (N/m) and, where the instrument records its
/// segments, the number of approach rows.
#[derive(Clone)]
pub(crate) struct Curve<'a> {
    /// The piezo heights (m).
    pub height: &'a [f64],
    /// The forces (N).
    pub force: &'a [f64],
    /// The forces' standard deviations (N).
    pub sigma: Option<&'a [f64]>,
    /// The rows' times (s).
    pub time: Option<Vec<f64>>,
    /// The lever's spring constant k (N/m).
    pub spring_constant: f64,
    /// The approach's rows (the instrument's segments); `None`: up to the lowest height.
    pub approach_rows: Option<usize>,
}

impl FitRequest {
    /// Fit `curve` with the request's options and the registry's `law` (checked,
    /// [`FitRequest::check`]), started from and holding the probe's sample `s`, its intervals
    /// walked as `walk` says (none: Wald's): one curve of `fit`, or of a map's `fit-map`.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming the column, `approach_rows`, `range` or `segment` that
    /// leaves too few rows, or the probe value missing; [`SimError::Cancelled`].
    pub(crate) fn fit_curve(
        &self,
        law: LawKind,
        s: &SampleInputs,
        c: Curve<'_>,
        walk: Option<ProfileWalk>,
        progress: &Progress,
    ) -> Result<FitResult, SimError> {
        // (the times matter, and are checked, for the sls law only)
        let time = c.time.filter(|_| law == LawKind::Sls);
        check_columns(c.height, c.force, c.sigma, time.as_deref())?;
        let k = c.spring_constant;
        let curve = self.preprocessed(law, c.height, c.force, time, k, c.approach_rows)?;
        let segment = self.segment_of(law);
        let fit = self.fitted(law);
        let rows = fit_rows(&curve, segment, self.range, fit.len())?;
        let x: Vec<f64> = rows.iter().map(|&i| curve.tip_position[i]).collect();
        let y: Vec<f64> = rows.iter().map(|&i| curve.force[i]).collect();
        let sig: Option<Vec<f64>> = c.sigma.map(|s| rows.iter().map(|&i| s[i]).collect());
        let names = force_curve::parameter_names_of(law, &s.tip_shape)
            .unwrap_or_default()
            .to_vec();
        let mut params = start_values(&names, s, &x, &y)?;
        let fitted: Vec<bool> = names.iter().map(|n| fit.iter().any(|f| f == n)).collect();
        let fixed: Vec<Option<f64>> = params
            .iter()
            .zip(&fitted)
            .map(|(p, f)| (!f).then_some(p.start))
            .collect();
        // the SLS's force depends on every row before (its history from the first row)
        let sls = match (law, &curve.time) {
            (LawKind::Sls, Some(t)) => Some(SlsCurveModel {
                // the piezo's height in the preprocessed frame, free of the force's noise
                height: (curve.tip_position.iter().zip(&curve.force))
                    .map(|(x, f)| x - f / k)
                    .collect(),
                t: t.clone(),
                spring_constant: k,
                rows: rows.clone(),
            }),
            _ => None,
        };
        let elastic = match sls {
            Some(_) => None,
            None => Some(ForceCurveModel {
                law,
                x,
                segment,
                poisson_ratio: probe_value(s.poisson_ratio, "sample.poisson_ratio")?,
                tip: (
                    probe_value(s.tip_youngs_modulus, "tip.youngs_modulus")?,
                    probe_value(s.tip_poisson_ratio, "tip.poisson_ratio")?,
                ),
                intermolecular_distance: s.intermolecular_distance.unwrap_or(0.0),
                indenter: self.indenter(s)?,
            }),
        };
        let m: &dyn CurveModel = match (&sls, &elastic) {
            (Some(model), _) => model,
            (None, Some(model)) => model,
            (None, None) => unreachable!("one of the two models is built"),
        };
        progress.check()?;
        let obs = Observations {
            y: &y,
            sigma: sig.as_deref(),
        };
        // a long curve's elastic fit starts from the same fit on every k-th row
        let coarse = |k: usize| -> Option<Box<dyn CurveModel>> {
            let e = elastic.as_ref()?;
            let x = e.x.iter().step_by(k).copied().collect();
            Some(Box::new(ForceCurveModel { x, ..e.clone() }))
        };
        // Hertz's force is nil off contact: its minimum is found on the contact rows
        let mut outcome = match elastic.as_ref().filter(|e| e.law == LawKind::Hertz) {
            Some(e) => {
                let over = |rows: &[usize]| -> Box<dyn CurveModel> {
                    let x = rows.iter().map(|&i| e.x[i]).collect();
                    Box::new(ForceCurveModel { x, ..e.clone() })
                };
                let at = |name| names.iter().position(|n| *n == name).unwrap_or(0);
                let rows = ContactRows {
                    x: &e.x,
                    over: &over,
                    contact_point: at(CONTACT_POINT),
                    baseline: at(BASELINE),
                };
                rows.fit(m, &obs, &params, &fixed, walk, progress)?
            }
            None => {
                coarse_start(&coarse, &obs, &mut params, &fixed, progress)?;
                fit_cancellable(m, &obs, &params, &fixed, walk, progress)?
            }
        };
        if let Some(model) = &sls {
            outcome
                .warnings
                .extend(sls_start_warning(model, &outcome.values));
        }
        let data = data_warnings(c.height, c.force, k);
        outcome.warnings.extend(data.iter().cloned());
        let contact = names.iter().position(|n| *n == CONTACT_POINT);
        // the contact point is a tip position after the preprocessing's offset: held against
        // those, not the file's piezo heights (an instrument's are absolute: 18–23 µm)
        let at = contact.map(|i| outcome.values[i]);
        let tip = at.and_then(|v| contact_point_warning(&curve.tip_position, v));
        outcome.warnings.extend(tip);
        Ok(FitResult {
            law,
            spring_constant: k,
            curve,
            rows,
            names,
            fitted,
            outcome,
            data_warnings: data,
            dynamic: None,
            thermal_sigma: None,
        })
    }
}

/// Where the fit's weights come from, in words: the thermal σ, the residuals or the σ column.
fn noise(request: &FitRequest, r: &FitResult) -> String {
    match (r.thermal_sigma, r.outcome.noise_estimated) {
        (Some(s), _) => format!(
            "the thermal σ_F = {} N at {} K (the probe's thermal spectrum below {}, detector \
             floor {} m/√Hz; χ² in units of σ)",
            crate::error::number(s),
            crate::error::number(request.temperature.unwrap_or(f64::NAN)),
            request
                .bandwidth
                .map_or("the time column's Nyquist frequency".into(), |b| {
                    format!("{} Hz", crate::error::number(b))
                }),
            crate::error::number(request.detector_noise.unwrap_or(0.0)),
        ),
        (None, true) => "noise estimated from residuals (no sigma column): χ²/dof is the force \
                         noise variance σ² (N²)"
            .into(),
        (None, false) => "the sigma column (χ² in units of σ)".into(),
    }
}

impl Analysis for FitRequest {
    type Output = FitResult;
    fn convergence(&self, r: &FitResult) -> Convergence {
        Convergence::of("minimiser", usize::from(r.outcome.converged), 1)
    }
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<FitResult, SimError> {
        if let Some(data) = crate::request::fit_dynamic::read_am_data(self.data.as_deref())? {
            // `range` of a dynamic curve: the piezo positions z fitted
            let data = match self.range {
                Some(range) => data.within(range),
                None => data,
            };
            return super::fit_dynamic::execute(
                &self.fit,
                self.fit == FitRequest::default().fit,
                self.profiles.unwrap_or(false),
                model,
                data,
                progress,
            );
        }
        let law = self.check(model)?;
        let (height, force, sigma, time) = self.columns()?;
        let probe = model.probe.as_ref().expect("checked");
        let thermal = match (&sigma, self.temperature) {
            (None, Some(t)) => Some(self.thermal_sigma(model, t, time.as_deref(), progress)?),
            _ => None,
        };
        let sigma = sigma.or(thermal.map(|s| vec![s; force.len()]));
        let curve = Curve {
            height: &height,
            force: &force,
            sigma: sigma.as_deref(),
            time,
            spring_constant: probe.calibration.spring_constant,
            approach_rows: self.approach_rows,
        };
        let walk = self.profiles.unwrap_or(true).then_some(ProfileWalk::Grid);
        let mut r = self.fit_curve(law, &probe.sample_inputs, curve, walk, progress)?;
        r.thermal_sigma = thermal;
        Ok(r)
    }
    fn report(&self, _: &Resolved, r: &FitResult) -> Result<Value, SimError> {
        Ok(document(self, r))
    }
    fn present(
        &self,
        _: &FitResult,
        at: crate::request::Presenting<'_>,
    ) -> Result<crate::report::Presentation, SimError> {
        let mut document = at.document.clone();
        Ok(crate::report::present::fit::fit(
            &mut document,
            at.units,
            at.to,
        ))
    }
}

/// The document of a fit (`afmdyn fit --json`, Python's `summary`): `estimates` (each fitted
/// parameter's `value`, `standard_error`, 95 % `interval` — the profile likelihood's —,
/// `wald_interval`, `interval_ends` — crossing, bound, flat or failed —, `profile` — the
/// points walked, `value` and `delta_chi2`), `parameters` (every parameter's value, fitted or held), `correlation`
/// (`names`, `matrix`), `chi2`, `dof`, `chi2_dof`, `noise`, `curve` (the fitted rows' tip
/// position, force, fit and residual), `preprocessing`, `law`, `segment`, `range`, `units`,
/// `method`, `warnings`; SI throughout.
pub(crate) fn document(request: &FitRequest, r: &FitResult) -> Value {
    let end = |e: ProfileEnd| match e {
        ProfileEnd::Crossing(_) => "crossing",
        ProfileEnd::Bound(_) => "bound",
        ProfileEnd::Flat(_) => "flat (the last point walked: open)",
        ProfileEnd::Failed(_) => "failed (a refit failed: the Wald end)",
    };
    let o = &r.outcome;
    let mut estimates = serde_json::Map::new();
    for e in &o.estimates {
        let finite = |x: f64| x.is_finite().then_some(x);
        estimates.insert(
            e.name.clone(),
            json!({
                "value": e.value,
                "standard_error": finite(e.standard_error),
                "interval": e.interval.map(finite),
                "interval_method": if e.profile.is_some() { "profile likelihood, Δχ² ≤ 3.84" } else { "Wald, ±1.96 SE" },
                "wald_interval": e.wald.map(finite),
                "interval_ends": e.profile.as_ref().map(|p| [end(p.lower), end(p.upper)]),
                "profile": e.profile.as_ref().map(|p| json!({
                    "value": p.points.iter().map(|q| q.0).collect::<Vec<f64>>(),
                    "delta_chi2": p.points.iter().map(|q| q.1).collect::<Vec<f64>>(),
                })),
            }),
        );
    }
    let mut parameters = serde_json::Map::new();
    for (i, n) in r.names.iter().enumerate() {
        parameters.insert(
            (*n).into(),
            json!({"value": o.values[i], "fitted": r.fitted[i]}),
        );
    }
    let names: Vec<&str> = o.estimates.iter().map(|e| e.name.as_str()).collect();
    let matrix: Vec<Vec<Option<f64>>> = o
        .correlation
        .iter()
        .map(|row| row.iter().map(|x| x.is_finite().then_some(*x)).collect())
        .collect();
    if let Some(d) = &r.dynamic {
        return super::fit_dynamic::document(
            r,
            d,
            Value::Object(estimates),
            json!({"names": names, "matrix": matrix}),
        );
    }
    let pick = |v: &[f64]| r.rows.iter().map(|&i| v[i]).collect::<Vec<f64>>();
    let segment = match request.segment_of(r.law) {
        Segment::Approach => "approach",
        Segment::Retract => "retract",
        Segment::Whole => "whole",
    };
    let model = if r.law == LawKind::Sls {
        "F = baseline + F_c: the standard linear solid (Zener) with surface memory in time \
         (k1 relaxed spring, Maxwell arm k2 with relaxation time τ; F_c = k1 δ + k2 (δ − u), \
         u' = (δ − u)/τ in contact, the free surface recovering with τ (k1 + k2)/k1; López-Guerra \
         & Solares 2014), driven through the lever in series from the piezo height (x − F/k, free \
         of the force noise; linear between rows), from rest at the first row"
    } else {
        "F = baseline + F_law(contact_point − x) with the registry's law in SI (Hertz: E* g(δ) of \
         the probe's [tip] shape, the paraboloid's (4/3)√R δ^{3/2} by default, Sneddon 1965; \
         contact::indenter)"
    };
    let model =
        match request.thickness {
            Some(h) => format!(
            "{model}, times the bottom-effect factor of a {} sample {} m thick (Dimitriadis et \
             al. 2002 for the paraboloid and sphere, Garcia & Garcia 2018 for the others)",
            if request.bonded == Some(false) { "non-bonded" } else { "bonded" },
            crate::error::number(h)
        ),
            None => model.to_string(),
        };
    let mut doc = json!({
        "estimates": estimates,
        "parameters": parameters,
        "correlation": {"names": names, "matrix": matrix},
        "chi2": o.chi2,
        "dof": o.dof,
        "chi2_dof": o.chi2_dof,
        "noise": noise(request, r),
        "sigma_thermal": r.thermal_sigma,
        "curve": {
            "tip_position": pick(&r.curve.tip_position),
            "force": pick(&r.curve.force),
            "fit": o.fitted,
            "residual": o.residuals,
        },
        "preprocessing": {
            "steps": ["compute_tip_position", "correct_force_offset", "correct_tip_offset", "segments at the lowest height"],
            "spring_constant": r.spring_constant,
            "force_offset": r.curve.force_offset,
            "tip_offset": r.curve.tip_offset,
            "contact_index": r.curve.contact_index,
            "approach_rows": r.curve.approach_len,
            "rows": r.curve.force.len(),
        },
        "law": r.law.name(),
        "segment": segment,
        "range": request.range,
        "rows_fitted": r.rows.len(),
        "evaluations": o.evaluations,
        "termination": o.termination,
        "units": {"sample.youngs_modulus": "Pa", "tip.radius": "m", "contact_point": "m", "baseline": "N",
                  "sample.hamaker": "J", "sample.adhesion_energy": "J/m^2", "sample.stiffness": "N/m",
                  "sample.maxwell_stiffness": "N/m", "sample.relaxation_time": "s", "time": "s",
                  "tip_position": "m", "force": "N",
                  "fit": "N", "residual": "N", "chi2_dof": if o.noise_estimated { "N^2" } else { "1" }},
        "method": "weighted least squares by Levenberg–Marquardt (MINPACK lmder, rust-cv levenberg-marquardt) on the preprocessed curve (nanite's steps: tip position x = height + F/k, force offset and tip offset at the deviation_from_baseline contact point); ".to_string() + &model + "; standard errors from (JᵀWJ)⁻¹ s²; " + intervals_method(o) + " (docs/tutorials/fitting-force-curves.md)",
        "warnings": o.warnings,
    });
    if let Some(t) = &r.curve.time {
        doc["curve"]["time"] = json!(pick(t));
    }
    doc
}

impl Datasets for FitRequest {
    /// `curve` (tip position, force, fit and residual over the fitted rows); the estimates
    /// and their standard errors as facts.
    fn datasets(&self, _: &Resolved, r: &FitResult) -> Result<Arrays, SimError> {
        use crate::layout::{Layout, Variable};
        let doc = document(self, r);
        let arr = |k: &str| -> Vec<f64> {
            doc["curve"][k].as_array().map_or(Vec::new(), |a| {
                a.iter().map(|v| v.as_f64().unwrap_or(f64::NAN)).collect()
            })
        };
        let n = r.rows.len();
        let columns: &[(&str, &str, &str)] = if r.dynamic.is_some() {
            &crate::report::present::fit::CURVE_VARIABLES
        } else {
            &[
                ("tip_position", "m", "tip position"),
                ("force", "N", "force, measured"),
                ("fit", "N", "force, fitted"),
                ("residual", "N", "measured − fitted"),
                ("time", "s", "time (the sls law's curve)"),
            ]
        };
        let n = r.dynamic.as_ref().map_or(n, |d| d.data.z.len());
        let curve = Layout::new(
            "fit curve",
            &[("row", n)],
            columns
                .iter()
                .filter(|(k, _, _)| doc["curve"][k].is_array())
                .map(|&(k, u, l)| Variable::f64(k, &["row"], u, l, &arr(k)))
                .collect(),
        );
        let mut facts = serde_json::Map::new();
        for e in &r.outcome.estimates {
            facts.insert(e.name.clone(), json!(e.value));
            facts.insert(
                format!("{}.standard_error", e.name),
                json!(e.standard_error),
            );
        }
        facts.insert("chi2_dof".into(), json!(r.outcome.chi2_dof));
        Ok((vec![("curve".into(), curve)], facts))
    }
}

//! `fit`: a measured quasi-static force curve fitted with a contact law of the registry
//! ([`crate::analysis::fit::force_curve`]) — the request the command line (`afmdyn fit`) and,
//! by its name, Python share, and its document: estimates with standard errors and 95 %
//! intervals, the correlation matrix, χ²/dof, the fitted curve beside the data, the residuals
//! and the identifiability warnings. Everything is SI (m, N, Pa, J/m²); a probe file is
//! needed (the lever's spring constant, the start values and the held parameters).

use super::fit_result::probe_value;
pub(crate) use super::fit_result::{bounds, intervals_method, FitResult, MIN_FIT_ROWS};
use super::limits::Cost;
use super::run::{Analysis, Request, Resolved};
use crate::analysis::fit::force_curve::{
    self, preprocess, ForceCurveModel, Preprocessed, Segment, BASELINE, CONTACT_POINT, HAMAKER,
    RADIUS, YOUNGS_MODULUS,
};
use crate::analysis::fit::profile::ProfileWalk;
use crate::analysis::fit::sls_curve::{
    self, SlsCurveModel, MAXWELL_STIFFNESS, RELAXATION_TIME, STIFFNESS,
};
use crate::analysis::fit::{fit_cancellable, CurveModel, Observations, Parameter, ProfileEnd};
use crate::analysis::progress::Progress;
use crate::contact::LawKind;
use crate::error::SimError;
use crate::probe::SampleInputs;
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

/// The most rows a force curve may have (a 1 MHz record of one second).
pub(crate) const MAX_FIT_ROWS: usize = 1_000_000;

/// The segment of the curve fitted.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(rename_all = "snake_case")]
pub enum FitSegment {
    /// The approach, up to the lowest piezo height.
    #[default]
    Approach,
    /// The retract, after it.
    Retract,
    /// Every row: approach, dwell and retract (the default of the `sls` law, whose dwell
    /// shows its relaxation or creep).
    Whole,
}

/// `fit`: the force curve (a CSV file `data`, or the columns `height`, `force` and optionally
/// `sigma` and `time`), the parameters fitted (`fit`, probe keys), the segment and the range of tip
/// positions fitted.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(default, deny_unknown_fields)]
pub struct FitRequest {
    /// A CSV file, read through the bounded reader (instead of the columns `height` and
    /// `force`). A force
    /// curve: the columns `height` (m, the piezo height, decreasing into the sample), `force`
    /// (N, repulsion positive) and optionally `sigma` (N, each force's standard deviation) and
    /// `time` (s, strictly increasing; needed by the `sls` law). A
    /// dynamic curve: `z` (m, the piezo position, in the order stepped) with `amplitude` (m)
    /// and/or `phase` (deg) (AM), or `frequency_shift` (Hz) (FM, at the probe's free
    /// amplitude), or `amplitude_2` (m) and/or `phase_2` (deg) (bimodal, a probe with a second
    /// drive component), each with an optional `sigma_<column>`.
    pub data: Option<String>,
    /// The piezo heights (m), when no `data` file is given.
    pub height: Vec<f64>,
    /// The forces (N), as many as `height`.
    pub force: Vec<f64>,
    /// The forces' standard deviations (N, > 0), as many as `force`; without them the noise is
    /// estimated from the residuals.
    pub sigma: Option<Vec<f64>>,
    /// The rows' times (s, strictly increasing), as many as `force`, when no `data` file is
    /// given; needed by the `sls` law (its relaxation and creep), ignored by the others.
    pub time: Vec<f64>,
    /// The parameters fitted, by their probe keys: `sample.youngs_modulus`, `tip.radius`,
    /// `contact_point`, `baseline`, and `sample.hamaker` (DMT) or `sample.adhesion_energy`
    /// (JKR); of the `sls` law `sample.stiffness`, `sample.maxwell_stiffness`,
    /// `sample.relaxation_time` (N/m, N/m, s), `contact_point` and `baseline`. The others are
    /// held at the probe's values (contact point and baseline at 0, after the preprocessing).
    /// Default `sample.youngs_modulus`, `contact_point` (for `sls`: its three, `contact_point`
    /// and `baseline`). Of an AM, FM or bimodal curve: `sample.youngs_modulus`,
    /// `sample.hamaker` (DMT), `sample.viscosity` (DMT and JKR; Kelvin–Voigt η, Pa s),
    /// `sample.damping` (Hertz's damper, N s/m), `sample.adhesion_energy` (JKR, J/m²),
    /// `tip.radius`, `drive.free_amplitude` (m),
    /// `cantilever.quality_factor` (AM and bimodal curves without `[medium]`;
    /// at resonance Q trades against the sample's E: fit it with E held) and `z_offset` (always
    /// fitted); default `sample.youngs_modulus`, `sample.hamaker` (DMT) or
    /// `sample.adhesion_energy` (JKR) and `z_offset`.
    pub fit: Vec<String>,
    /// The segment fitted: `approach`, `retract` or `whole`; default the approach, the whole
    /// curve for the `sls` law.
    pub segment: Option<FitSegment>,
    /// The range of tip positions fitted [lo, hi] (m, after the preprocessing's offset, as
    /// nanite's `range_x`); default the whole segment.
    #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "length")))]
    pub range: Option<[f64; 2]>,
    /// The number of rows of the approach (the rest is the retract), as an instrument records
    /// its segments (afmformats' `segment` column, which Python reads from an instrument
    /// file); default up to the lowest piezo height, inclusive. 1 to the number of rows.
    pub approach_rows: Option<usize>,
    /// Profile-likelihood intervals (Δχ² ≤ 3.84) for the fitted parameters, up to 4 of them,
    /// the probe keys (sample, tip) before the contact point, baseline and z_offset (beyond,
    /// and when off, the Wald intervals ±1.96 SE). Default on for a force curve; off
    /// for an AM curve, where every profile point is a refit of stepped approaches (on, each
    /// side is walked by secants on √Δχ² in units of the standard error, at most 6 refits, each
    /// started from its neighbour; a side that has not risen by then is reported flat).
    pub profiles: Option<bool>,
}

impl Default for FitRequest {
    fn default() -> Self {
        FitRequest {
            data: None,
            height: Vec::new(),
            force: Vec::new(),
            sigma: None,
            time: Vec::new(),
            fit: vec![YOUNGS_MODULUS.into(), CONTACT_POINT.into()],
            segment: None,
            range: None,
            approach_rows: None,
            profiles: None,
        }
    }
}

/// A force curve's columns: heights, forces, their σ and the rows' times.
type Columns = (Vec<f64>, Vec<f64>, Option<Vec<f64>>, Option<Vec<f64>>);

fn bad(name: &'static str, value: impl std::fmt::Display, allowed: String) -> SimError {
    SimError::out_of_range(name, value, allowed)
}

/// The columns `height`, `force` and optionally `sigma` and `time` of the CSV file `path`, read through
/// the bounded reader ([`crate::io::curve_file::read_curve_file`], a curve CSV's cap).
///
/// # Errors
/// [`SimError::OutOfRange`] naming `data` and the file: refused by the reader, unreadable, a
/// missing column or a field that is not a number.
#[cfg(feature = "files")]
pub(crate) fn read_force_curve(path: &std::path::Path) -> Result<Columns, SimError> {
    use crate::io::curve_file::{read_curve_file, CurveFile};
    let file = |m: String| bad("data", path.display(), m);
    match read_curve_file(path).map_err(|e| file(e.to_string()))? {
        CurveFile::Document(_) => Err(file(
            "a JSON document; fit reads a CSV with the columns height (m) and force (N)".into(),
        )),
        CurveFile::Columns(names, cols) => {
            let col = |n: &str| names.iter().position(|c| c == n).map(|i| cols[i].clone());
            let missing = |c: &str| file(format!("no column {c} among {}", names.join(", ")));
            let height = col("height").ok_or_else(|| missing("height (m)"))?;
            let force = col("force").ok_or_else(|| missing("force (N)"))?;
            Ok((height, force, col("sigma"), col("time")))
        }
    }
}

impl FitRequest {
    /// The data's columns: the file's or the request's.
    ///
    /// # Errors
    /// As `read_force_curve`; [`SimError::OutOfRange`] naming `data` where both or neither
    /// are given, or a file without the `files` feature.
    pub fn columns(&self) -> Result<Columns, SimError> {
        match (&self.data, self.height.is_empty() && self.force.is_empty()) {
            (Some(_), false) => Err(bad(
                "data",
                "given with height/force",
                "give either a data file or the columns height and force, not both".into(),
            )),
            #[cfg(feature = "files")]
            (Some(path), true) => read_force_curve(std::path::Path::new(path)),
            #[cfg(not(feature = "files"))]
            (Some(_), true) => Err(bad(
                "data",
                "a file",
                "this build reads no files: give the columns height and force".into(),
            )),
            (None, true) => Err(bad(
                "data",
                "missing",
                "a force curve is needed: a CSV file (columns height, force, optional sigma) \
                 or the columns height and force"
                    .into(),
            )),
            (None, false) => Ok((
                self.height.clone(),
                self.force.clone(),
                self.sigma.clone(),
                (!self.time.is_empty()).then(|| self.time.clone()),
            )),
        }
    }

    /// The law of the probe and every model parameter's name.
    fn law(model: &Resolved) -> Result<LawKind, SimError> {
        let p = model.probe.as_ref().ok_or_else(|| {
            bad(
                "probe",
                "missing",
                "fit needs a probe file (the lever's spring constant, the start values and the \
                 held parameters in SI)"
                    .into(),
            )
        })?;
        let name = p.params.contact_law.name();
        name.parse::<LawKind>()
            .ok()
            .filter(|&k| force_curve::parameter_names(k).is_some())
            .ok_or_else(|| {
                bad(
                    "law",
                    name,
                    "the force-curve fit takes the probe's [sample].law = hertz, dmt, jkr or sls"
                        .into(),
                )
            })
    }

    /// The parameters fitted: `fit`, or the `sls` law's default when `fit` is the request's.
    pub(crate) fn fitted(&self, law: LawKind) -> Vec<String> {
        if law == LawKind::Sls && self.fit == FitRequest::default().fit {
            return sls_curve::DEFAULT_FIT
                .iter()
                .map(|s| s.to_string())
                .collect();
        }
        self.fit.clone()
    }

    /// The segment fitted: `segment`, or the law's default (the whole curve for `sls`).
    pub(crate) fn segment_of(&self, law: LawKind) -> Segment {
        match self.segment {
            Some(FitSegment::Approach) => Segment::Approach,
            Some(FitSegment::Retract) => Segment::Retract,
            Some(FitSegment::Whole) => Segment::Whole,
            None if law == LawKind::Sls => Segment::Whole,
            None => Segment::Approach,
        }
    }

    /// Check the options against the probe's law (the data are checked when read).
    fn check(&self, model: &Resolved) -> Result<LawKind, SimError> {
        let law = Self::law(model)?;
        let names = force_curve::parameter_names(law).unwrap_or_default();
        if law == LawKind::Jkr && self.segment == Some(FitSegment::Whole) {
            return Err(bad(
                "segment",
                "whole",
                "the jkr law's contact differs on the approach and the retract: fit one of them"
                    .into(),
            ));
        }
        let fit = self.fitted(law);
        if fit.is_empty() {
            return Err(bad(
                "fit",
                "none",
                format!("name one or more of {}", names.join(", ")),
            ));
        }
        for (i, f) in fit.iter().enumerate() {
            if !names.contains(&f.as_str()) {
                return Err(bad(
                    "fit",
                    f,
                    format!(
                        "the {} law's parameters are {}",
                        law.name(),
                        names.join(", ")
                    ),
                ));
            }
            if fit[..i].contains(f) {
                return Err(bad("fit", f, "named twice".into()));
            }
        }
        if let Some([lo, hi]) = self.range {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(bad(
                    "range",
                    format!("[{lo}, {hi}]"),
                    "must be two finite tip positions lo < hi (m)".into(),
                ));
            }
        }
        if self.data.is_none() {
            // (the times matter, and are checked, for the sls law only)
            let time =
                (law == LawKind::Sls && !self.time.is_empty()).then_some(self.time.as_slice());
            check_columns(&self.height, &self.force, self.sigma.as_deref(), time)?;
        }
        Ok(law)
    }
}

/// The columns' lengths, sizes and values.
fn check_columns(
    height: &[f64],
    force: &[f64],
    sigma: Option<&[f64]>,
    time: Option<&[f64]>,
) -> Result<(), SimError> {
    let rows = force.len();
    if height.len() != rows
        || sigma.is_some_and(|s| s.len() != rows)
        || time.is_some_and(|t| t.len() != rows)
    {
        return Err(bad(
            "force",
            force.len(),
            format!(
                "height, force (and sigma, time) must have one value per row ({} heights)",
                height.len()
            ),
        ));
    }
    if !(MIN_FIT_ROWS..=MAX_FIT_ROWS).contains(&force.len()) {
        return Err(bad(
            "data",
            format!("{} rows", force.len()),
            format!("a force curve has {MIN_FIT_ROWS}..={MAX_FIT_ROWS} rows"),
        ));
    }
    if let Some(i) = height.iter().chain(force).position(|x| !x.is_finite()) {
        return Err(bad(
            "data",
            format!("row {}", i % force.len() + 1),
            "heights and forces must be finite".into(),
        ));
    }
    if let Some(i) = sigma.and_then(|s| s.iter().position(|x| !(x.is_finite() && *x > 0.0))) {
        return Err(bad(
            "sigma",
            format!("row {}", i + 1),
            "must be finite and > 0 (N)".into(),
        ));
    }
    if let Some(i) = time
        .and_then(|t| (0..t.len()).position(|i| !(t[i].is_finite() && (i == 0 || t[i] > t[i - 1]))))
    {
        return Err(bad(
            "time",
            format!("row {}", i + 1),
            "must be finite and strictly increasing (s)".into(),
        ));
    }
    Ok(())
}

impl FitRequest {
    /// The curve of `height` and `force` (and the sls law's `time`) preprocessed with the
    /// lever's spring constant `k`, its approach `approach_rows` long when given.
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
    ) -> Result<Preprocessed, SimError> {
        let mut curve = preprocess(height, force, k);
        if let Some(n) = self.approach_rows {
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
                 times (s), a time column"
                    .into(),
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
        return Err(bad(
            "range",
            format!("{} rows", rows.len()),
            format!(
                "too few rows of the {} in the range to fit {fitted} parameters",
                match segment {
                    Segment::Approach => "approach",
                    Segment::Retract => "retract",
                    Segment::Whole => "curve",
                },
            ),
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
        format!(
            "the fitted curve is in contact at its first row ({:.3e} N): the sls model \
             starts the sample at rest there, so a curve that starts on the surface is \
             misfitted; record the approach from off the surface",
            f[0]
        )
    })
}

impl Request for FitRequest {
    fn validate(&self, model: &Resolved) -> Result<(), SimError> {
        if super::fit_dynamic::read_am_data(self.data.as_deref())?.is_some() {
            // an AM curve: its names and columns are checked when it runs; a probe read
            // for a force curve (its stand-ins) is refused now
            if let Some(p) = model.probe.as_ref().filter(|p| !p.assumed.is_empty()) {
                super::fit_dynamic::am_probe(p)?;
            }
            return Ok(());
        }
        self.check(model).map(|_| ())
    }
    fn name(&self) -> &'static str {
        "fit"
    }
    /// A force curve uses the probe's spring constant, tip and sample only; an AM, FM or
    /// bimodal curve refuses the values a quasi-static read stood in for
    /// (`super::fit_dynamic::am_probe`).
    fn probe_needs(&self) -> crate::probe::ProbeNeeds {
        crate::probe::ProbeNeeds::Static
    }
    fn cost(&self, model: &Resolved) -> Result<Cost, SimError> {
        // an AM curve: its stepped approaches, the profiles' refits included
        if let Some(d) = super::fit_dynamic::read_am_data(self.data.as_deref())? {
            let law = model
                .probe
                .as_ref()
                .map_or("", |p| p.params.contact_law.name());
            let default_fit = self.fit == FitRequest::default().fit;
            let n = super::fit_dynamic::fitted_names(&self.fit, default_fit, law).len();
            let profiles = self.profiles.unwrap_or(false);
            return super::fit_dynamic::cost(d.z.len(), n, profiles, &model.params);
        }
        // no integration; the columns, the preprocessed curve and the Jacobian (≤ 5 columns)
        let rows = if self.data.is_some() {
            MAX_FIT_ROWS
        } else {
            self.force.len()
        } as f64;
        Ok(Cost {
            bytes: rows * 8.0 * 16.0,
            work: 0.0,
        })
    }
}

impl Analysis for FitRequest {
    type Output = FitResult;
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<FitResult, SimError> {
        if let Some(data) = super::fit_dynamic::read_am_data(self.data.as_deref())? {
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
        // (the times matter, and are checked, for the sls law only)
        let time = time.filter(|_| law == LawKind::Sls);
        check_columns(&height, &force, sigma.as_deref(), time.as_deref())?;
        let probe = model.probe.as_ref().expect("checked");
        let k = probe.calibration.spring_constant;
        let s = probe.sample_inputs;
        let curve = self.preprocessed(law, &height, &force, time, k)?;
        let segment = self.segment_of(law);
        let fit = self.fitted(law);
        let rows = fit_rows(&curve, segment, self.range, fit.len())?;
        let x: Vec<f64> = rows.iter().map(|&i| curve.tip_position[i]).collect();
        let y: Vec<f64> = rows.iter().map(|&i| curve.force[i]).collect();
        let sig: Option<Vec<f64>> = sigma.map(|s| rows.iter().map(|&i| s[i]).collect());
        let names = force_curve::parameter_names(law)
            .unwrap_or_default()
            .to_vec();
        let params = start_values(&names, &s, &x, &y)?;
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
        let elastic;
        let m: &dyn CurveModel = match &sls {
            Some(model) => model,
            None => {
                elastic = ForceCurveModel {
                    law,
                    x,
                    segment,
                    poisson_ratio: probe_value(s.poisson_ratio, "sample.poisson_ratio")?,
                    tip: (
                        probe_value(s.tip_youngs_modulus, "tip.youngs_modulus")?,
                        probe_value(s.tip_poisson_ratio, "tip.poisson_ratio")?,
                    ),
                    intermolecular_distance: s.intermolecular_distance.unwrap_or(0.0),
                };
                &elastic
            }
        };
        progress.check()?;
        let obs = Observations {
            y: &y,
            sigma: sig.as_deref(),
        };
        let walk = self.profiles.unwrap_or(true).then_some(ProfileWalk::Grid);
        let mut outcome = fit_cancellable(m, &obs, &params, &fixed, walk, progress)?;
        if let Some(model) = &sls {
            outcome
                .warnings
                .extend(sls_start_warning(model, &outcome.values));
        }
        Ok(FitResult {
            law,
            spring_constant: k,
            curve,
            rows,
            names,
            fitted,
            outcome,
            dynamic: None,
        })
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
        let to = crate::report::present::Destination::default();
        Ok(crate::report::present::fit::fit(
            &mut document,
            at.units,
            to,
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
        "F = baseline + F_law(contact_point − x) with the registry's law in SI (Hertz: (4/3)E*√R \
         δ^{3/2}, Sneddon 1965)"
    };
    let mut doc = json!({
        "estimates": estimates,
        "parameters": parameters,
        "correlation": {"names": names, "matrix": matrix},
        "chi2": o.chi2,
        "dof": o.dof,
        "chi2_dof": o.chi2_dof,
        "noise": if o.noise_estimated { "noise estimated from residuals (no sigma column): χ²/dof is the force noise variance σ² (N²)" } else { "the sigma column (χ² in units of σ)" },
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
        "method": "weighted least squares by Levenberg–Marquardt (MINPACK lmder, rust-cv levenberg-marquardt) on the preprocessed curve (nanite's steps: tip position x = height + F/k, force offset and tip offset at the deviation_from_baseline contact point); ".to_string() + model + "; standard errors from (JᵀWJ)⁻¹ s²; " + intervals_method(o) + " (docs/afm-workflow.md, From data to properties)",
        "warnings": o.warnings,
    });
    if let Some(t) = &r.curve.time {
        doc["curve"]["time"] = json!(pick(t));
    }
    doc
}

impl crate::study::named::Datasets for FitRequest {
    /// `curve` (tip position, force, fit and residual over the fitted rows); the estimates
    /// and their standard errors as facts.
    fn datasets(
        &self,
        _: &Resolved,
        r: &FitResult,
    ) -> Result<crate::study::named::Arrays, SimError> {
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

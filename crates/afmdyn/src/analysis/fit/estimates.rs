//! From a minimum of χ² to estimates with their uncertainties: the covariance
//! C = (JᵀWJ)⁻¹ s² at the minimum (J = ∂f/∂p, W = diag(1/σᵢ²); s² = χ²/(m − n) when the noise
//! is estimated from the residuals, 1 when σ is given), standard errors √Cⱼⱼ, Wald intervals
//! p̂ ± 1.96 SE, the correlation matrix, profile-likelihood intervals ([`super::profile`]) and
//! the identifiability warnings: |correlation| > 0.99, a flat profile, an estimate at its
//! bound, a parameter the data do not constrain (JᵀWJ singular in it or, for a quantity with a
//! physical lower bound, a standard error ≥ |estimate|) (Bates & Watts, *Nonlinear Regression
//! Analysis and Its Applications*, Wiley 1988, §2.3; Raue et al. 2009 for the profiles).

use super::least_squares::{
    evaluate_in, minimize_cancellable, CurveModel, Minimum, Observations, Parameter, PATIENCE,
    TOLERANCE,
};
use super::profile::{profile, Fitted, Profile, ProfileEnd, ProfileWalk, DELTA_CHI2_95};
use crate::analysis::progress::Progress;
use crate::error::SimError;
use nalgebra::DMatrix;

pub(crate) use super::profile::Z_95;

/// Above this |correlation| two parameters are called not separately identifiable.
pub(crate) const CORRELATION_WARNING: f64 = 0.99;

/// Profiles are computed for at most this many fitted parameters (Wald intervals beyond):
/// [`profiled`] chooses them.
pub(crate) const MAX_PROFILED: usize = 4;

/// Which of the fitted parameters `names` get profiles: all of them up to [`MAX_PROFILED`];
/// beyond, the sample's, tip's and lever's (a probe key, `section.key`) first and then the
/// curve's own (contact point, baseline, z_offset), in order, [`MAX_PROFILED`] in all — the
/// properties sought before the nuisance parameters.
pub(crate) fn profiled<S: AsRef<str>>(names: &[S]) -> Vec<bool> {
    let mut on = vec![false; names.len()];
    let order = (0..names.len())
        .filter(|&k| names[k].as_ref().contains('.'))
        .chain((0..names.len()).filter(|&k| !names[k].as_ref().contains('.')));
    for k in order.take(MAX_PROFILED) {
        on[k] = true;
    }
    on
}

/// Below this ratio of the smallest to the largest eigenvalue of the scaled JᵀWJ the matrix is
/// called singular (the data do not fix some combination of the parameters).
pub(crate) const SINGULAR_RATIO: f64 = 1e-14;

/// One fitted parameter's estimate.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// Its name.
    pub name: String,
    /// The estimate p̂.
    pub value: f64,
    /// The standard error √Cⱼⱼ (NaN where JᵀWJ is singular in this parameter).
    pub standard_error: f64,
    /// The Wald interval p̂ ± 1.96 SE.
    pub wald: [f64; 2],
    /// The 95 % interval: the profile's where computed (`MAX_PROFILED`), else the Wald one.
    pub interval: [f64; 2],
    /// The profile, when computed.
    pub profile: Option<Profile>,
}

/// Standard deviations of χ²/dof above 1 beyond which a fit with σ given warns that the model
/// does not describe the data (χ² of m − n degrees of freedom has mean m − n and variance
/// 2(m − n); at 4 of them a fit that does describe its data warns about once in 30 000).
pub(crate) const CHI2_SIGMAS: f64 = 4.0;

/// A fit's outcome: estimates, correlation, χ²/dof, the model beside the data, warnings.
#[derive(Debug, Clone, PartialEq)]
pub struct FitOutcome {
    /// The fitted parameters' estimates, in the fit's order.
    pub estimates: Vec<Estimate>,
    /// Every parameter's value at the minimum, fixed ones too.
    pub values: Vec<f64>,
    /// The correlation matrix of the fitted parameters (n × n, rows in the estimates' order).
    pub correlation: Vec<Vec<f64>>,
    /// χ² at the minimum.
    pub chi2: f64,
    /// Degrees of freedom m − n.
    pub dof: usize,
    /// χ²/dof (with σ: near 1 for a model that fits; without: the noise variance s²).
    pub chi2_dof: f64,
    /// Whether the noise was estimated from the residuals (no σ given).
    pub noise_estimated: bool,
    /// The model at the estimates, fᵢ(p̂).
    pub fitted: Vec<f64>,
    /// The residuals yᵢ − fᵢ(p̂).
    pub residuals: Vec<f64>,
    /// Model evaluations made, the profiles' refits included.
    pub evaluations: usize,
    /// Whether the minimiser reports convergence (else the estimates may not be at the
    /// minimum, and a warning says so).
    pub converged: bool,
    /// The minimiser's termination.
    pub termination: String,
    /// Identifiability and convergence warnings, in words.
    pub warnings: Vec<String>,
}

/// Fit `model` to `obs` over the parameters `params` whose `fixed` entry is `None` (the others
/// held at it), from their start values; with the profile-likelihood intervals of up to
/// `MAX_PROFILED` of them when `profiles` (walked on the grid, [`ProfileWalk::Grid`]; else
/// the Wald intervals, ±1.96 standard errors).
///
/// # Panics
/// Never for consistent lengths: `params` and `fixed` have the model's n entries and `obs`
/// its m points (the caller's [`crate::request`] checks the data).
pub fn fit_with(
    model: &dyn CurveModel,
    obs: &Observations,
    params: &[Parameter],
    fixed: &[Option<f64>],
    profiles: bool,
) -> FitOutcome {
    let walk = profiles.then_some(ProfileWalk::Grid);
    // a run of its own, never cancelled: the one error is the cancellation
    let progress = Progress::new();
    match fit_cancellable(model, obs, params, fixed, walk, &progress) {
        Ok(o) => o,
        Err(e) => unreachable!("a fit nobody can cancel was cancelled: {e}"),
    }
}

/// [`fit_with`] in a run: the profiles walked as `profiles` says (none: the Wald intervals), every
/// model evaluation — the minimiser's, the covariance's, the profiles' refits — counted in
/// `progress` and checking its cancel flag first.
///
/// # Errors
/// [`SimError::Cancelled`] when `progress` is cancelled before the fit ends (at the latest
/// after the evaluation under way).
pub fn fit_cancellable(
    model: &dyn CurveModel,
    obs: &Observations,
    params: &[Parameter],
    fixed: &[Option<f64>],
    profiles: Option<ProfileWalk>,
    progress: &Progress,
) -> Result<FitOutcome, SimError> {
    let start: Vec<f64> = params.iter().map(|p| p.start).collect();
    let best = minimize_cancellable(
        model,
        obs,
        params,
        &start,
        fixed,
        (TOLERANCE, PATIENCE),
        progress,
    )?;
    fit_at(model, obs, params, fixed, best, profiles, progress)
}

/// [`fit_cancellable`] from its minimum `best` (found by the minimiser on `model`, or on a
/// problem with the same minimum: `super::contact_rows`): the standard errors, intervals,
/// correlations, warnings and the fitted curve of `model` there.
///
/// # Errors
/// [`SimError::Cancelled`] when `progress` is cancelled before the fit ends.
pub(crate) fn fit_at(
    model: &dyn CurveModel,
    obs: &Observations,
    params: &[Parameter],
    fixed: &[Option<f64>],
    best: super::least_squares::Minimum,
    profiles: Option<ProfileWalk>,
    progress: &Progress,
) -> Result<FitOutcome, SimError> {
    let free: Vec<usize> = (0..params.len()).filter(|&j| fixed[j].is_none()).collect();
    let (m, n) = (model.points(), free.len());
    let dof = m.saturating_sub(n);
    let noise_estimated = obs.sigma.is_none();
    let chi2_dof = if dof > 0 {
        best.chi2 / dof as f64
    } else {
        f64::NAN
    };
    let s2 = if noise_estimated { chi2_dof } else { 1.0 };
    let mut warnings = goodness_warnings(&best, noise_estimated, dof, chi2_dof);
    let (cov, singular) = covariance(model, obs, &best.values, &free, s2, progress)?;
    if singular {
        warnings.push(warning!(
            "fit.singular",
            "Fix a parameter the data cannot tell from another (give its value \
                 instead of fitting it), or fit data that vary them separately.",
            "JᵀWJ is singular: the data do not constrain every combination of the fitted \
             parameters"
        ));
    }
    let (se, correlation) = standard_errors(&cov);
    let mut evaluations = best.evaluations + 1;
    let mut estimates = Vec::with_capacity(n);
    let chosen = profiled(&free.iter().map(|&j| &params[j].name).collect::<Vec<_>>());
    for (k, &j) in free.iter().enumerate() {
        let p = &params[j];
        let value = best.values[j];
        let wald = [value - Z_95 * se[k], value + Z_95 * se[k]];
        let step = if se[k].is_finite() && se[k] > 0.0 {
            se[k]
        } else {
            0.1 * p.scale
        };
        let prof = match profiles {
            Some(walk) if chosen[k] && dof > 0 && s2 > 0.0 => {
                let fit = Fitted {
                    model,
                    obs,
                    params,
                    best: &best,
                    fixed,
                    s2,
                };
                Some(profile(&fit, j, step, walk, progress)?)
            }
            _ => None,
        };
        let interval = prof
            .as_ref()
            .map_or(wald, |pr| [pr.lower.value(), pr.upper.value()]);
        if let Some(pr) = &prof {
            evaluations += pr.evaluations;
            profile_warnings(&p.name, value, pr, profiles, &mut warnings);
        }
        estimate_warnings(p, value, se[k], &mut warnings);
        estimates.push(Estimate {
            name: p.name.clone(),
            value,
            standard_error: se[k],
            wald,
            interval,
            profile: prof,
        });
    }
    for a in 0..n {
        for b in a + 1..n {
            let r = correlation[a][b];
            if r.abs() > CORRELATION_WARNING {
                warnings.push(warning!(
                    "fit.correlated",
                    "Fix one of the two, or add data that separate them (another range, \
                     setpoint or channel).",
                    "{} and {} are correlated at {r:.4} (|r| > {CORRELATION_WARNING}): the data \
                     fix a combination of them, not each",
                    params[free[a]].name,
                    params[free[b]].name
                ));
            }
        }
    }
    let mut fitted = vec![0.0; m];
    evaluate_in(model, &best.values, &mut fitted, None, progress)?;
    evaluations += 1;
    let residuals = obs.y.iter().zip(&fitted).map(|(y, f)| y - f).collect();
    Ok(FitOutcome {
        estimates,
        values: best.values,
        correlation,
        chi2: best.chi2,
        dof,
        chi2_dof,
        noise_estimated,
        fitted,
        residuals,
        evaluations,
        converged: best.converged,
        termination: best.termination,
        warnings,
    })
}

/// The warnings on the minimum `best` as a whole: no convergence reported, the noise estimated
/// from the residuals, or (σ given) a χ²/dof above [`CHI2_SIGMAS`] standard deviations of its
/// distribution for `dof` degrees of freedom.
fn goodness_warnings(
    best: &Minimum,
    noise_estimated: bool,
    dof: usize,
    chi2_dof: f64,
) -> Vec<String> {
    let mut warnings = Vec::new();
    if !best.converged {
        warnings.push(warning!(
            "fit.unconverged",
            "Fit again from other start values, nearer the minimum.",
            "the minimiser did not report convergence ({}): the estimates may not be at the \
             minimum",
            best.termination
        ));
    }
    if noise_estimated {
        warnings.push(warning!(
            "fit.noise-estimated",
            "Give a σ column with the data's measured noise for standard errors that do \
             not assume the model fits.",
            "noise estimated from residuals: no σ column, so σ² = χ²/dof = {:.4e} (the \
             standard errors and intervals assume the model fits)",
            chi2_dof
        ));
    }
    // with σ given, χ² of a model that fits is χ²(dof): mean dof, standard deviation √(2 dof)
    let bound = 1.0 + CHI2_SIGMAS * (2.0 / dof.max(1) as f64).sqrt();
    if !noise_estimated && dof > 0 && chi2_dof > bound {
        warnings.push(warning!(
            "fit.chi2",
            "Try other start values (a local minimum), another contact law or model, or \
             check that σ is not too small.",
            "χ²/dof = {} with the σ given, above {} ({CHI2_SIGMAS} standard deviations of χ²/dof \
             for {dof} degrees of freedom): the model does not describe the data within σ — a \
             local minimum (another start), another law or model, or σ too small; the standard \
             errors assume it does",
            crate::error::number(chi2_dof),
            crate::error::number(bound)
        ));
    }
    warnings
}

/// The standard errors √Cₖₖ of the covariance `cov` and its correlation matrix. A variance that
/// is not positive (a parameter whose Jacobian column is zero or at the rounding level: the
/// pseudo-inverse's diagonal then comes out 0 or negative) gives NaN: the parameter is not
/// constrained, not known exactly.
fn standard_errors(cov: &DMatrix<f64>) -> (Vec<f64>, Vec<Vec<f64>>) {
    let n = cov.nrows();
    let se: Vec<f64> = (0..n)
        .map(|k| {
            let v = cov[(k, k)];
            if v > 0.0 {
                v.sqrt()
            } else {
                f64::NAN
            }
        })
        .collect();
    let correlation: Vec<Vec<f64>> = (0..n)
        .map(|a| {
            (0..n)
                .map(|b| cov[(a, b)] / (se[a] * se[b]))
                .collect::<Vec<f64>>()
        })
        .collect();
    (se, correlation)
}

/// Into `warnings`, those of the profile `pr` of the parameter `name` (estimate `value`) walked
/// as `walk` says: a flat side, refits stopped before converging, a failed refit, a χ² lower
/// than the fit's.
fn profile_warnings(
    name: &str,
    value: f64,
    pr: &Profile,
    walk: Option<ProfileWalk>,
    warnings: &mut Vec<String>,
) {
    let sides = |f: fn(&ProfileEnd) -> bool| match (f(&pr.lower), f(&pr.upper)) {
        (true, true) => Some("either side"),
        (true, false) => Some("the lower side"),
        (false, true) => Some("the upper side"),
        (false, false) => None,
    };
    if let Some(side) = sides(|e| matches!(e, ProfileEnd::Flat(_))) {
        let walked = match walk {
            Some(ProfileWalk::Secant { max_steps }) => format!(
                " ({max_steps} refits a side, to {:.3e} from the estimate)",
                (pr.lower.value() - value)
                    .abs()
                    .max((pr.upper.value() - value).abs())
            ),
            _ => String::new(),
        };
        warnings.push(warning!(
            "fit.profile-flat",
            "Read that end of the interval as open: fix the parameter, or fit data that \
             bound it.",
            "{name}: flat profile — χ² rises by less than {DELTA_CHI2_95:.2} over the \
             range walked on {side}{walked}; the data do not bound it there (the \
             interval's end there is the last point walked: open)",
        ));
    }
    if pr.unconverged > 0 {
        warnings.push(warning!(
            "fit.profile-unconverged",
            "Read that interval as possibly too narrow; fit again from start values \
             nearer the minimum.",
            "{name}: {} of the profile's {} refits stopped at the minimiser's limit of \
             evaluations before converging (their Δχ² may be high, the interval narrow)",
            pr.unconverged,
            pr.refits
        ));
    }
    if let Some(side) = sides(|e| matches!(e, ProfileEnd::Failed(_))) {
        warnings.push(warning!(
            "fit.profile-failed",
            "Read that end of the interval as Wald's; narrower bounds keep the model \
             defined.",
            "{name}: a profile refit failed on {side} (the model could not be evaluated \
             there): the Wald end p̂ ± 1.96 SE stands in",
        ));
    }
    if pr.lowest < -1e-6 {
        warnings.push(warning!(
            "fit.profile-lower",
            "Fit again from the profile's better point as the start: the fit stopped \
             short of the minimum.",
            "{name}: the profile met a χ² lower than the fit's (by {:.3} in Δχ²): the fit \
             stopped short of the minimum",
            -pr.lowest
        ));
    }
}

/// Into `warnings`, those of the estimate `value` of `p` with the standard error `se`: at a
/// bound, or not constrained by the data.
fn estimate_warnings(p: &Parameter, value: f64, se: f64, warnings: &mut Vec<String>) {
    let width = (p.upper - p.lower).abs().min(p.scale.max(value.abs()));
    for (bound, which) in [(p.lower, "lower"), (p.upper, "upper")] {
        if bound.is_finite() && (value - bound).abs() <= 1e-6 * width {
            warnings.push(warning!(
                "fit.at-bound",
                "Widen that parameter's bounds, or check the data and the model: the best \
                 value may lie beyond them.",
                "{}: the estimate {value:.6e} is at its {which} bound {bound:.6e}",
                p.name
            ));
        }
    }
    // (an offset without a natural zero — contact point, baseline — is not held to it)
    if !se.is_finite() || (p.lower.is_finite() && se >= value.abs()) {
        warnings.push(warning!(
            "fit.unconstrained",
            "Fix the parameter at a known value, or fit data that depend on it more \
             strongly.",
            "{}: not constrained by the data (standard error {:.3e} ≥ |estimate| {:.3e})",
            p.name,
            se,
            value.abs()
        ));
    }
}

/// The covariance (JᵀWJ)⁻¹ s² of the free parameters at `p`, and whether JᵀWJ is singular
/// (then its pseudo-inverse on the eigenvalues above [`SINGULAR_RATIO`] of the largest, and NaN
/// variances for parameters in its null space). JᵀWJ is scaled to unit diagonal before the
/// eigen-decomposition, so parameters of any units compare. One evaluation of the run.
fn covariance(
    model: &dyn CurveModel,
    obs: &Observations,
    p: &[f64],
    free: &[usize],
    s2: f64,
    progress: &Progress,
) -> Result<(DMatrix<f64>, bool), SimError> {
    let (m, n_all, n) = (model.points(), p.len(), free.len());
    let mut f = vec![0.0; m];
    let mut jac = vec![0.0; m * n_all];
    evaluate_in(model, p, &mut f, Some(&mut jac), progress)?;
    let mut a = DMatrix::<f64>::zeros(n, n);
    for i in 0..m {
        let w2 = obs.weight(i).powi(2);
        let row = &jac[i * n_all..(i + 1) * n_all];
        for (ka, &ja) in free.iter().enumerate() {
            for (kb, &jb) in free.iter().enumerate().skip(ka) {
                a[(ka, kb)] += row[ja] * row[jb] * w2;
            }
        }
    }
    for ka in 0..n {
        for kb in 0..ka {
            a[(ka, kb)] = a[(kb, ka)];
        }
    }
    let d: Vec<f64> = (0..n)
        .map(|k| {
            let x = a[(k, k)];
            if x > 0.0 {
                1.0 / x.sqrt()
            } else {
                0.0
            }
        })
        .collect();
    let b = DMatrix::from_fn(n, n, |i, j| a[(i, j)] * d[i] * d[j]);
    let eig = b.symmetric_eigen();
    let largest = eig.eigenvalues.iter().cloned().fold(0.0_f64, f64::max);
    let mut singular = d.contains(&0.0) || largest <= 0.0;
    let mut inv = DMatrix::<f64>::zeros(n, n);
    let mut null = vec![false; n];
    for (k, &lambda) in eig.eigenvalues.iter().enumerate() {
        let v = eig.eigenvectors.column(k);
        if lambda > SINGULAR_RATIO * largest {
            inv += v * v.transpose() / lambda;
        } else {
            singular = true;
            for (ni, vi) in null.iter_mut().zip(v.iter()) {
                *ni |= vi.abs() > 1e-6;
            }
        }
    }
    let cov = DMatrix::from_fn(n, n, |i, j| {
        if null[i] || null[j] || d[i] == 0.0 || d[j] == 0.0 {
            f64::NAN
        } else {
            inv[(i, j)] * d[i] * d[j] * s2
        }
    });
    Ok((cov, singular))
}

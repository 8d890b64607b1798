//! Weighted least squares by Levenberg–Marquardt: the minimiser of
//! χ²(p) = Σᵢ ((yᵢ − fᵢ(p))/σᵢ)² over the free parameters, within their bounds.
//!
//! The minimiser is rust-cv's `levenberg-marquardt` crate, a port of MINPACK's `lmder`
//! (Moré, *The Levenberg–Marquardt algorithm: implementation and theory*, Lecture Notes in
//! Mathematics 630 (1978) 105), with its scaled trust region. Bounds enter as MINUIT's
//! transformations to unbounded internal variables u (James & Roos, *Comput. Phys. Commun.* 10
//! (1975) 343; as lmfit does): p = lo + (hi − lo)(sin u + 1)/2 between two bounds,
//! p = lo + s(√(u² + 1) − 1) above a lower one (below an upper one alike), p = s u without;
//! s is the parameter's scale, so every u is of order one. The model's Jacobian ∂f/∂p is
//! chained with dp/du; the covariance is formed in p (`super::estimates`).
//!
//! Every evaluation is counted in the run's [`Progress`] and checks its cancel flag first
//! (`minimize_cancellable`): a cancelled run stops the minimiser at its next evaluation (the
//! model's residuals refused, the crate's `User` termination) and returns
//! [`SimError::Cancelled`]; a model whose evaluation is long also stops inside it
//! ([`CurveModel::evaluate_cancellable`]).

use crate::analysis::progress::Progress;
use crate::error::SimError;
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra_lm::{storage::Owned, DMatrix, DVector, Dyn};
use std::sync::atomic::AtomicBool;

/// The minimiser's relative tolerances (MINPACK's ftol, xtol, gtol): χ² to 1e-10 relative is
/// Δχ² to 1e-6 at 10⁴ points, far inside the profiles' 3.84, and the estimates to ~1e-10 of
/// their standard errors' scale.
pub(crate) const TOLERANCE: f64 = 1e-10;

/// The minimiser's patience: it stops after `PATIENCE × (n + 1)` evaluations of the residuals
/// (n free parameters; MINPACK's `maxfev`, the crate's `with_patience`).
pub(crate) const PATIENCE: usize = 200;

/// The most model evaluations of one minimisation over `n` free parameters with `patience`
/// ([`PATIENCE`] for a fit): the minimiser's `patience` × (n + 1) residual evaluations, at
/// most as many Jacobians (one per outer iteration, each of which evaluates the residuals at
/// least once) and the final χ²; 1 with nothing free.
pub(crate) fn max_evaluations(n: usize, patience: usize) -> usize {
    match n {
        0 => 1,
        n => 2 * patience * (n + 1) + 1,
    }
}

/// A model of a measured curve: values fᵢ(p) at the data's points and their derivatives.
pub trait CurveModel {
    /// The number of data points m.
    fn points(&self) -> usize;
    /// The model's values fᵢ(p) into `values` (length m) and, when given, its Jacobian
    /// ∂fᵢ/∂p_j into `jacobian`, row-major m × n (n = `p.len()`, every parameter of the model,
    /// fixed or not, in the order of the fit's [`Parameter`]s).
    fn evaluate(&self, p: &[f64], values: &mut [f64], jacobian: Option<&mut [f64]>);
    /// [`CurveModel::evaluate`], which may stop early once `cancel` is set: then `values` are
    /// unspecified (NaN for the library's models) and the caller, which checks the flag after
    /// the evaluation, discards them. The default ignores the flag (a model whose evaluation is
    /// short); the dynamic fit's stepped approach checks it between its rows.
    fn evaluate_cancellable(
        &self,
        p: &[f64],
        values: &mut [f64],
        jacobian: Option<&mut [f64]>,
        cancel: &AtomicBool,
    ) {
        let _ = cancel;
        self.evaluate(p, values, jacobian);
    }
}

/// One evaluation of `model` at `p` in a run: the cancel flag of `progress` checked before and
/// after it ([`CurveModel::evaluate_cancellable`] in between), one unit counted.
///
/// # Errors
/// [`SimError::Cancelled`] when `progress` is cancelled before the evaluation ends.
pub(crate) fn evaluate_in(
    model: &dyn CurveModel,
    p: &[f64],
    values: &mut [f64],
    jacobian: Option<&mut [f64]>,
    progress: &Progress,
) -> Result<(), SimError> {
    progress.check()?;
    model.evaluate_cancellable(p, values, jacobian, progress.cancel_flag());
    progress.tick();
    progress.check()
}

/// A parameter of a fit: its name (a probe key, `sample.youngs_modulus`), start value, bounds
/// (±∞ for none) and scale (its typical magnitude, > 0: the internal variable's unit).
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// The name.
    pub name: String,
    /// The start value (inside the bounds).
    pub start: f64,
    /// The lower bound (−∞ for none).
    pub lower: f64,
    /// The upper bound (+∞ for none).
    pub upper: f64,
    /// The typical magnitude, > 0.
    pub scale: f64,
}

impl Parameter {
    /// p(u) and dp/du of the module's transformation.
    fn external(&self, u: f64) -> (f64, f64) {
        let (lo, hi, s) = (self.lower, self.upper, self.scale);
        match (lo.is_finite(), hi.is_finite()) {
            (true, true) => (
                lo + 0.5 * (hi - lo) * (u.sin() + 1.0),
                0.5 * (hi - lo) * u.cos(),
            ),
            (true, false) => {
                let r = (u * u + 1.0).sqrt();
                (lo + s * (r - 1.0), s * u / r)
            }
            (false, true) => {
                let r = (u * u + 1.0).sqrt();
                (hi - s * (r - 1.0), -s * u / r)
            }
            (false, false) => (s * u, s),
        }
    }

    /// u(p), the inverse of [`Parameter::external`] (p clamped into the bounds); a start on a
    /// one-sided bound moves a hair inside, where dp/du ≠ 0.
    fn internal(&self, p: f64) -> f64 {
        let (lo, hi, s) = (self.lower, self.upper, self.scale);
        let p = p.clamp(lo, hi);
        match (lo.is_finite(), hi.is_finite()) {
            (true, true) => (2.0 * (p - lo) / (hi - lo) - 1.0).clamp(-1.0, 1.0).asin(),
            (true, false) => (((p - lo) / s + 1.0).powi(2) - 1.0).sqrt().max(1e-3),
            (false, true) => (((hi - p) / s + 1.0).powi(2) - 1.0).sqrt().max(1e-3),
            (false, false) => p / s,
        }
    }
}

/// The data a model is fitted to: yᵢ and, when known, their standard deviations σᵢ > 0
/// (without them every σᵢ = 1 and the noise is estimated from the residuals).
#[derive(Debug, Clone, Copy)]
pub struct Observations<'a> {
    /// The measured values yᵢ.
    pub y: &'a [f64],
    /// Their standard deviations σᵢ > 0, or `None`.
    pub sigma: Option<&'a [f64]>,
}

impl Observations<'_> {
    /// The weight 1/σᵢ of point i.
    pub(crate) fn weight(&self, i: usize) -> f64 {
        self.sigma.map_or(1.0, |s| 1.0 / s[i])
    }
}

/// A minimum of χ²: every parameter's value (the fixed ones too), χ², the evaluations made and
/// the minimiser's termination.
#[derive(Debug, Clone, PartialEq)]
pub struct Minimum {
    /// The parameters at the minimum, in the fit's order.
    pub values: Vec<f64>,
    /// χ² = Σ((yᵢ − fᵢ)/σᵢ)² there (the sum of squared residuals without σ).
    pub chi2: f64,
    /// Model evaluations made (values and Jacobians).
    pub evaluations: usize,
    /// Whether the minimiser reports convergence.
    pub converged: bool,
    /// The minimiser's termination, in words.
    pub termination: String,
}

/// The problem the crate minimises: the free parameters' internal variables.
struct Problem<'a> {
    model: &'a dyn CurveModel,
    obs: Observations<'a>,
    params: &'a [Parameter],
    /// Every parameter's value; the free ones overwritten from `u`.
    full: Vec<f64>,
    /// The indices of the free parameters.
    free: Vec<usize>,
    u: DVector<f64>,
    evaluations: std::cell::Cell<usize>,
    /// The run's progress: every evaluation counted, its cancel flag checked.
    progress: &'a Progress,
    /// Set when an evaluation met the cancel flag (the minimiser then stops).
    cancelled: std::cell::Cell<bool>,
}

impl Problem<'_> {
    fn set(&mut self, u: &DVector<f64>) {
        self.u.copy_from(u);
        for (k, &j) in self.free.iter().enumerate() {
            self.full[j] = self.params[j].external(u[k]).0;
        }
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, u: &DVector<f64>) {
        self.set(u);
    }
    fn params(&self) -> DVector<f64> {
        self.u.clone()
    }
    fn residuals(&self) -> Option<DVector<f64>> {
        let m = self.model.points();
        let mut f = vec![0.0; m];
        self.evaluations.set(self.evaluations.get() + 1);
        if evaluate_in(self.model, &self.full, &mut f, None, self.progress).is_err() {
            self.cancelled.set(true);
            return None;
        }
        let r = DVector::from_fn(m, |i, _| (f[i] - self.obs.y[i]) * self.obs.weight(i));
        r.iter().all(|x| x.is_finite()).then_some(r)
    }
    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let (m, n) = (self.model.points(), self.params.len());
        let mut f = vec![0.0; m];
        let mut jac = vec![0.0; m * n];
        self.evaluations.set(self.evaluations.get() + 1);
        if evaluate_in(
            self.model,
            &self.full,
            &mut f,
            Some(&mut jac),
            self.progress,
        )
        .is_err()
        {
            self.cancelled.set(true);
            return None;
        }
        let chain: Vec<f64> = self
            .free
            .iter()
            .enumerate()
            .map(|(k, &j)| self.params[j].external(self.u[k]).1)
            .collect();
        let j = DMatrix::from_fn(m, self.free.len(), |i, k| {
            jac[i * n + self.free[k]] * chain[k] * self.obs.weight(i)
        });
        j.iter().all(|x| x.is_finite()).then_some(j)
    }
}

/// [`chi2`] as one evaluation of a run ([`evaluate_in`]).
///
/// # Errors
/// [`SimError::Cancelled`] when `progress` is cancelled.
pub(crate) fn chi2_in(
    model: &dyn CurveModel,
    obs: &Observations,
    p: &[f64],
    progress: &Progress,
) -> Result<f64, SimError> {
    let mut f = vec![0.0; model.points()];
    evaluate_in(model, p, &mut f, None, progress)?;
    Ok(sum_squares(obs, &f))
}

/// Σ((yᵢ − fᵢ)/σᵢ)² of the model values `f`.
fn sum_squares(obs: &Observations, f: &[f64]) -> f64 {
    f.iter()
        .enumerate()
        .map(|(i, fi)| ((fi - obs.y[i]) * obs.weight(i)).powi(2))
        .sum()
}

/// The minimum of χ² over the parameters whose `fixed` entry is `None`, from `start` (every
/// parameter's value; the fixed ones held at theirs), within the bounds.
///
/// `params`, `start` and `fixed` have the model's n entries; `obs` its m points.
#[cfg(test)]
pub(crate) fn minimize(
    model: &dyn CurveModel,
    obs: &Observations,
    params: &[Parameter],
    start: &[f64],
    fixed: &[Option<f64>],
) -> Minimum {
    // a run of its own, never cancelled
    let progress = Progress::new();
    run(
        model,
        obs,
        params,
        start,
        fixed,
        (TOLERANCE, PATIENCE),
        &progress,
    )
    .0
}

/// [`minimize`] in a run, to the relative `tolerance` (MINPACK's ftol, xtol and gtol;
/// [`TOLERANCE`] for a fit) with `patience` ([`PATIENCE`] for a fit): every evaluation counted
/// in `progress` and checking its cancel flag (the module docs).
///
/// # Errors
/// [`SimError::Cancelled`] when `progress` is cancelled before the minimum is found.
pub(crate) fn minimize_cancellable(
    model: &dyn CurveModel,
    obs: &Observations,
    params: &[Parameter],
    start: &[f64],
    fixed: &[Option<f64>],
    (tolerance, patience): (f64, usize),
    progress: &Progress,
) -> Result<Minimum, SimError> {
    match run(
        model,
        obs,
        params,
        start,
        fixed,
        (tolerance, patience),
        progress,
    ) {
        (_, true) => Err(SimError::Cancelled),
        (m, false) => Ok(m),
    }
}

/// The minimiser's run, and whether it was cancelled (then the minimum is where it stopped).
fn run(
    model: &dyn CurveModel,
    obs: &Observations,
    params: &[Parameter],
    start: &[f64],
    fixed: &[Option<f64>],
    (tolerance, patience): (f64, usize),
    progress: &Progress,
) -> (Minimum, bool) {
    let full: Vec<f64> = start
        .iter()
        .zip(fixed)
        .map(|(s, f)| f.unwrap_or(*s))
        .collect();
    let free: Vec<usize> = (0..params.len()).filter(|&j| fixed[j].is_none()).collect();
    let u = DVector::from_iterator(
        free.len(),
        free.iter().map(|&j| params[j].internal(full[j])),
    );
    let mut problem = Problem {
        model,
        obs: *obs,
        params,
        full,
        free,
        u: u.clone(),
        evaluations: std::cell::Cell::new(0),
        progress,
        cancelled: std::cell::Cell::new(false),
    };
    problem.set(&u);
    let cancelled = |full: Vec<f64>, evaluations: usize| {
        let m = Minimum {
            values: full,
            chi2: f64::NAN,
            evaluations,
            converged: false,
            termination: "cancelled".into(),
        };
        (m, true)
    };
    if problem.free.is_empty() {
        return match chi2_in(model, obs, &problem.full, progress) {
            Ok(chi2) => (
                Minimum {
                    values: problem.full,
                    chi2,
                    evaluations: 1,
                    converged: true,
                    termination: "nothing to fit".into(),
                },
                false,
            ),
            Err(_) => cancelled(problem.full, 1),
        };
    }
    let (problem, report) = LevenbergMarquardt::new()
        .with_ftol(tolerance)
        .with_xtol(tolerance)
        .with_gtol(tolerance)
        .with_patience(patience)
        .minimize(problem);
    let evaluations = problem.evaluations.get() + 1;
    let values = problem.full;
    if problem.cancelled.get() {
        return cancelled(values, evaluations - 1);
    }
    match chi2_in(model, obs, &values, progress) {
        Ok(chi2) => (
            Minimum {
                chi2,
                values,
                evaluations,
                converged: report.termination.was_successful(),
                termination: format!("{:?}", report.termination),
            },
            false,
        ),
        Err(_) => cancelled(values, evaluations),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f = a exp(−b x) + c.
    struct Exp(Vec<f64>);
    impl CurveModel for Exp {
        fn points(&self) -> usize {
            self.0.len()
        }
        fn evaluate(&self, p: &[f64], v: &mut [f64], jac: Option<&mut [f64]>) {
            let (a, b, c) = (p[0], p[1], p[2]);
            for (i, x) in self.0.iter().enumerate() {
                v[i] = a * (-b * x).exp() + c;
            }
            if let Some(j) = jac {
                for (i, x) in self.0.iter().enumerate() {
                    let e = (-b * x).exp();
                    j[3 * i..3 * i + 3].copy_from_slice(&[e, -a * x * e, 1.0]);
                }
            }
        }
    }

    fn param(name: &str, start: f64, lower: f64, upper: f64) -> Parameter {
        Parameter {
            name: name.into(),
            start,
            lower,
            upper,
            scale: start.abs().max(1e-3),
        }
    }

    #[test]
    fn the_transformations_invert() {
        for p in [
            param("a", 2.0, 0.0, f64::INFINITY),
            param("b", 2.0, f64::NEG_INFINITY, 5.0),
            param("c", 2.0, 1.0, 5.0),
            param("d", 2.0, f64::NEG_INFINITY, f64::INFINITY),
        ] {
            let u = p.internal(3.0);
            let (x, d) = p.external(u);
            assert!((x - 3.0).abs() < 1e-12, "{}: {x}", p.name);
            let h = 1e-6;
            let fd = (p.external(u + h).0 - p.external(u - h).0) / (2.0 * h);
            assert!((fd - d).abs() < 1e-6 * d.abs().max(1.0), "{}", p.name);
        }
    }

    #[test]
    fn an_exact_curve_is_recovered_within_bounds() {
        let x: Vec<f64> = (0..50).map(|i| i as f64 * 0.1).collect();
        let model = Exp(x.clone());
        let truth = [2.0, 0.7, 0.3];
        let mut y = vec![0.0; x.len()];
        model.evaluate(&truth, &mut y, None);
        let params = [
            param("a", 1.0, 0.0, f64::INFINITY),
            param("b", 0.2, 0.0, 10.0),
            param("c", 0.0, f64::NEG_INFINITY, f64::INFINITY),
        ];
        let obs = Observations { y: &y, sigma: None };
        let start: Vec<f64> = params.iter().map(|p| p.start).collect();
        let m = minimize(&model, &obs, &params, &start, &[None; 3]);
        assert!(m.converged, "{}", m.termination);
        for (v, t) in m.values.iter().zip(truth) {
            assert!((v - t).abs() < 1e-8, "{:?}", m.values);
        }
        // c held: a and b move alone
        let m = minimize(&model, &obs, &params, &start, &[None, None, Some(0.3)]);
        assert_eq!(m.values[2], 0.3);
        assert!((m.values[1] - 0.7).abs() < 1e-8);
    }
}

//! The fit of a purely repulsive law (Hertz's: no force while δ ≤ 0) on its contact rows: a
//! row whose tip position x lies above every contact point the fit visits is the baseline
//! alone there, so the rows above a bound c_hi enter χ² only through their count W (Σ 1/σ²),
//! weighted mean ȳ and spread:
//!
//! Σ_{x_i ≥ c_hi} ((y_i − b)/σ_i)² = W (ȳ − b)² + Σ_{x_i ≥ c_hi} ((y_i − ȳ)/σ_i)²,
//!
//! one residual √W (ȳ − b) plus a constant. The minimiser then works on the rows below c_hi
//! and that one row (a measured curve of 10⁴ rows has ~10² in contact), and χ²'s minimum is
//! the full curve's wherever the contact point stays below c_hi, which the fit checks (it
//! raises c_hi and fits again otherwise). The estimates' errors, intervals and warnings are then
//! the full curve's, from one evaluation of every row at that minimum
//! ([`super::estimates::fit_at`]). This is variable elimination of rows, not an approximation:
//! the minimum is the same point.

use super::estimates::{fit_at, FitOutcome};
use super::least_squares::{
    chi2_in, minimize_cancellable, CurveModel, Minimum, Observations, Parameter, PATIENCE,
    TOLERANCE,
};
use super::profile::ProfileWalk;
use crate::analysis::progress::Progress;
use crate::error::SimError;

/// The fewest rows for which the reduction is worth it: shorter curves are fitted whole.
const MIN_ROWS: usize = 200;

/// The times c_hi is raised before the curve is fitted whole.
const RAISES: usize = 4;

/// A repulsive law's model on its rows below c_hi, and the one row standing for those above:
/// `inner` over the rows kept, then √W·b (b the parameter `baseline`).
struct Reduced<'a> {
    inner: &'a dyn CurveModel,
    baseline: usize,
    weight: f64,
}

impl CurveModel for Reduced<'_> {
    fn points(&self) -> usize {
        self.inner.points() + 1
    }
    fn evaluate(&self, p: &[f64], values: &mut [f64], jacobian: Option<&mut [f64]>) {
        let (m, n) = (self.inner.points(), p.len());
        match jacobian {
            Some(j) => {
                self.inner
                    .evaluate(p, &mut values[..m], Some(&mut j[..m * n]));
                let row = &mut j[m * n..];
                row.fill(0.0);
                row[self.baseline] = self.weight;
            }
            None => self.inner.evaluate(p, &mut values[..m], None),
        }
        values[m] = self.weight * p[self.baseline];
    }
}

/// The rows of a repulsive law's fit, and how to build its model over some of them.
pub(crate) struct ContactRows<'a> {
    /// The tip positions x (m) of the rows fitted.
    pub x: &'a [f64],
    /// The model over the rows given (indices into `x`).
    pub over: &'a dyn Fn(&[usize]) -> Box<dyn CurveModel>,
    /// The index of the contact point among the parameters.
    pub contact_point: usize,
    /// The index of the baseline among the parameters.
    pub baseline: usize,
}

impl ContactRows<'_> {
    /// Fit `model` (the law over every row of `x`) to `obs` as [`super::fit_cancellable`]
    /// does, its minimum found on the contact rows (the module docs); a curve of fewer than
    /// 200 rows, or one whose contact point keeps rising past c_hi, is minimised whole.
    ///
    /// # Errors
    /// [`SimError::Cancelled`] when `progress` is cancelled.
    pub(crate) fn fit(
        &self,
        model: &dyn CurveModel,
        obs: &Observations,
        params: &[Parameter],
        fixed: &[Option<f64>],
        profiles: Option<ProfileWalk>,
        progress: &Progress,
    ) -> Result<FitOutcome, SimError> {
        let start: Vec<f64> = params.iter().map(|p| p.start).collect();
        let cp = self.contact_point;
        // the contact point's bound: its start plus a margin (its scale), raised as needed
        let (mut c_hi, margin) = match fixed[cp] {
            Some(c) => (c, 0.0),
            None => (
                params[cp].start + 0.25 * params[cp].scale,
                0.25 * params[cp].scale,
            ),
        };
        let mut found = None;
        for _ in 0..RAISES {
            if self.x.len() < MIN_ROWS {
                break;
            }
            let Some(best) = self.reduced_minimum(c_hi, obs, params, &start, fixed, progress)?
            else {
                break;
            };
            if fixed[cp].is_some() || best.values[cp] <= c_hi - 0.5 * margin {
                found = Some(best);
                break;
            }
            c_hi = best.values[cp] + 2.0 * margin;
        }
        let best = match found {
            Some(mut best) => {
                // χ² of every row at that minimum (the constant of the rows above c_hi)
                best.chi2 = chi2_in(model, obs, &best.values, progress)?;
                best.evaluations += 1;
                best
            }
            None => {
                let tol = (TOLERANCE, PATIENCE);
                minimize_cancellable(model, obs, params, &start, fixed, tol, progress)?
            }
        };
        fit_at(model, obs, params, fixed, best, profiles, progress)
    }

    /// The minimum of χ² on the rows below `c_hi` and the one row standing for the rest;
    /// `None` when no row lies above `c_hi` (nothing to reduce).
    fn reduced_minimum(
        &self,
        c_hi: f64,
        obs: &Observations,
        params: &[Parameter],
        start: &[f64],
        fixed: &[Option<f64>],
        progress: &Progress,
    ) -> Result<Option<Minimum>, SimError> {
        let (below, above): (Vec<usize>, Vec<usize>) =
            (0..self.x.len()).partition(|&i| self.x[i] < c_hi);
        if above.is_empty() {
            return Ok(None);
        }
        // W = Σ 1/σ², ȳ the weighted mean of the rows above
        let w: f64 = above.iter().map(|&i| obs.weight(i).powi(2)).sum();
        let mean = above
            .iter()
            .map(|&i| obs.y[i] * obs.weight(i).powi(2))
            .sum::<f64>()
            / w;
        let inner = (self.over)(&below);
        let reduced = Reduced {
            inner: inner.as_ref(),
            baseline: self.baseline,
            weight: w.sqrt(),
        };
        let mut y: Vec<f64> = below.iter().map(|&i| obs.y[i]).collect();
        y.push(w.sqrt() * mean);
        let sigma = obs.sigma.map(|s| {
            let mut v: Vec<f64> = below.iter().map(|&i| s[i]).collect();
            v.push(1.0);
            v
        });
        let sub = Observations {
            y: &y,
            sigma: sigma.as_deref(),
        };
        let tol = (TOLERANCE, PATIENCE);
        minimize_cancellable(&reduced, &sub, params, start, fixed, tol, progress).map(Some)
    }
}

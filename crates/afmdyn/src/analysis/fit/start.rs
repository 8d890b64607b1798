//! Start values for the minimiser (`super::least_squares::minimize`): a parameter started at
//! the least χ² of a grid, the others at their starts. Levenberg–Marquardt descends to the
//! nearest minimum; where χ² has several (the dynamic fit's stepped approach, whose first rows
//! follow another branch than the data's when the contact point is off), a coarse scan of the
//! parameter that moves between them picks the basin first.

use super::least_squares::{chi2_in, CurveModel, Observations, Parameter};
use crate::analysis::progress::Progress;
use crate::error::SimError;

/// Half the number of steps of z_offset's start grid: the starts −6 … 6 steps.
pub(crate) const Z_OFFSET_GRID: i32 = 6;

/// The step of z_offset's start grid, in g₀ = A₀ (the grid spans ±0.3 A₀, within which the
/// free amplitude's far rows and the curve's onset place the contact point).
pub(crate) const Z_OFFSET_STEP: f64 = 0.05;

/// z_offset's start grid (m): −[`Z_OFFSET_GRID`] … [`Z_OFFSET_GRID`] steps of
/// [`Z_OFFSET_STEP`] `g0` (`g0` = A₀ in m), 13 values from −0.3 A₀ to 0.3 A₀, ascending.
pub(crate) fn z_offset_grid(g0: f64) -> impl Iterator<Item = f64> {
    (-Z_OFFSET_GRID..=Z_OFFSET_GRID).map(move |i| i as f64 * Z_OFFSET_STEP * g0)
}

/// The value of parameter `k` among `grid` with the least χ² of `model` on `obs`, every other
/// parameter at its [`Parameter::start`]; the first of equal χ², and `params[k].start` where
/// no grid value gives a χ² below +∞ (each a model evaluation without the Jacobian).
///
/// # Errors
/// [`SimError::Cancelled`] when `progress` is cancelled (each evaluation counted in it and
/// checking it, [`super::least_squares::evaluate_in`]).
///
/// # Panics
/// When `k` is not an index of `params`.
pub(crate) fn grid_start(
    model: &dyn CurveModel,
    obs: &Observations,
    params: &[Parameter],
    k: usize,
    grid: impl IntoIterator<Item = f64>,
    progress: &Progress,
) -> Result<f64, SimError> {
    let mut trial: Vec<f64> = params.iter().map(|p| p.start).collect();
    let mut best = (f64::INFINITY, params[k].start);
    for x in grid {
        trial[k] = x;
        let c = chi2_in(model, obs, &trial, progress)?;
        if c < best.0 {
            best = (c, trial[k]);
        }
    }
    Ok(best.1)
}

/// The rows a curve keeps for its coarse start ([`coarse_start`]): curves longer than this are
/// fitted first on every k-th row, k = rows / `COARSE_ROWS` rounded up.
pub(crate) const COARSE_ROWS: usize = 1000;

/// Start values from the same fit on every k-th row of a long curve (the module docs' other
/// start): `coarse(k)` builds the model over rows 0, k, 2k, … (`None` where the model has no
/// such subset); the minimum found there, in the bounds, starts the fit of every row, which
/// then descends in a few evaluations instead of walking the contact point from the
/// preprocessing's estimate over the whole curve. Curves of at most [`COARSE_ROWS`] rows, and
/// models without a subset, keep `params`' starts.
///
/// # Errors
/// [`SimError::Cancelled`] when `progress` is cancelled.
pub(crate) fn coarse_start(
    coarse: &dyn Fn(usize) -> Option<Box<dyn CurveModel>>,
    obs: &Observations,
    params: &mut [Parameter],
    fixed: &[Option<f64>],
    progress: &Progress,
) -> Result<(), SimError> {
    use super::least_squares::{minimize_cancellable, PATIENCE, TOLERANCE};
    let k = obs.y.len().div_ceil(COARSE_ROWS);
    let Some(model) = (k > 1).then(|| coarse(k)).flatten() else {
        return Ok(());
    };
    let pick = |v: &[f64]| -> Vec<f64> { v.iter().step_by(k).copied().collect() };
    let (y, sigma) = (pick(obs.y), obs.sigma.map(pick));
    let sub = Observations {
        y: &y,
        sigma: sigma.as_deref(),
    };
    let start: Vec<f64> = params.iter().map(|p| p.start).collect();
    let best = minimize_cancellable(
        model.as_ref(),
        &sub,
        params,
        &start,
        fixed,
        (TOLERANCE, PATIENCE),
        progress,
    )?;
    for (p, v) in params.iter_mut().zip(&best.values) {
        if v.is_finite() {
            p.start = v.clamp(p.lower, p.upper);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f = (x − p)² at x = 0 … 4: χ² of y = 0 has its least at p = x's mean, 2.
    struct Bowl;
    impl CurveModel for Bowl {
        fn points(&self) -> usize {
            5
        }
        fn evaluate(&self, p: &[f64], v: &mut [f64], _: Option<&mut [f64]>) {
            for (i, vi) in v.iter_mut().enumerate() {
                *vi = i as f64 - p[0];
            }
        }
    }

    #[test]
    fn the_grid_start_is_the_least_chi2_of_the_grid() {
        let params = [Parameter {
            name: "p".into(),
            start: -7.0,
            lower: f64::NEG_INFINITY,
            upper: f64::INFINITY,
            scale: 1.0,
        }];
        let y = [0.0; 5];
        let obs = Observations { y: &y, sigma: None };
        let p = Progress::default();
        let grid = (0..9).map(|i| 0.5 * i as f64);
        assert_eq!(grid_start(&Bowl, &obs, &params, 0, grid, &p).unwrap(), 2.0);
        assert_eq!(
            grid_start(&Bowl, &obs, &params, 0, [f64::NAN], &p).unwrap(),
            -7.0
        );
        let g: Vec<f64> = z_offset_grid(2.0).collect();
        assert_eq!(g.len(), 13);
        assert_eq!(
            (g[0], g[6], g[12]),
            (-0.6000000000000001, 0.0, 0.6000000000000001)
        );
    }
}

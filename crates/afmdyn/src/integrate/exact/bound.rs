//! The displacement bound of [`crate::integrate::Spans::displacement_bound`] in modal
//! regions: weighted column sums per region and a bound kept over a stint; the body-contact
//! guard of a span's steps ([`StepGuard`]).

use super::forcing::Forced;
use super::modal::{ModalExp, Modes};
use super::ExactPropagator;
use crate::model::BodyContactCheck;

/// Most grid steps over which the stint's bound of [`Spans::displacement_bound`] is kept
/// (see there).
///
/// [`Spans::displacement_bound`]: crate::integrate::Spans::displacement_bound
const STINT_BOUND_STEPS: f64 = 1e5;

/// The tables of [`Spans::displacement_bound`] for weights c (per region, formed on
/// first use), and the bound of the current stint's homogeneous part.
///
/// [`Spans::displacement_bound`]: crate::integrate::Spans::displacement_bound
#[derive(Debug, Clone, Default)]
pub(super) struct BoundCols {
    weights: Vec<f64>,
    /// Σ_j c_j |b_jk| over the first N rows of T⁻¹V, per modal representative k.
    cols: [Vec<f64>; 2],
    /// Σ_j c_j |a_p,j(τ_k)| at the grid points k = 0..=m (the particular part, from the grid
    /// table of z_p).
    grid: [Vec<f64>; 2],
    /// Whether Re λ_k ≤ 0 for every representative (|q_k| never grows).
    holds: [bool; 2],
    /// The thresholds of [`StepGuard`] at the grid points k = 0..=m, per region, and the bits
    /// of the base drive's amplitude they were formed for.
    thr: [Vec<f64>; 2],
    thr_amp: Option<u64>,
    /// (τ, bound) of the homogeneous part formed in the current stint.
    pub(super) stint: Option<(f64, f64)>,
}

impl BoundCols {
    /// Make the tables those of `weights` in region `ri`.
    fn prepare(&mut self, weights: &[f64], ri: usize, me: &ModalExp, fr: &Forced, n: usize) {
        // the same bits (without an early exit, so that the comparison vectorizes)
        let same = self.weights.len() == weights.len()
            && self
                .weights
                .iter()
                .zip(weights)
                .fold(0, |d, (a, b)| d | (a.to_bits() ^ b.to_bits()))
                == 0;
        if !same {
            self.weights.clear();
            self.weights.extend_from_slice(weights);
            self.cols.iter_mut().for_each(Vec::clear);
            self.grid.iter_mut().for_each(Vec::clear);
            self.thr.iter_mut().for_each(Vec::clear);
            self.stint = None;
        }
        if self.cols[ri].is_empty() {
            let nw = n.min(weights.len());
            self.cols[ri].extend((0..me.len()).map(|k| {
                (0..nw)
                    .map(|j| weights[j] * me.tv.re[(j, k)].hypot(me.tv.im[(j, k)]))
                    .sum::<f64>()
            }));
            let dim = fr.zp_grid.nrows();
            let zp = fr.zp_grid.as_slice().chunks_exact(dim.max(1));
            self.grid[ri].extend(zp.map(|z| crate::model::weighted_displacement(weights, z)));
            self.holds[ri] = me.lambda.iter().all(|l| l.re <= 0.0);
        }
    }

    /// Σ_k cols_k |q_k| in region `ri` (after [`Self::prepare`]).
    fn hom(&self, ri: usize, q: &Modes) -> f64 {
        weighted_modes(&self.cols[ri], q)
    }

    /// The guard of a span in region `ri` with the stint's bound `stint` (after
    /// [`Self::prepare_thresholds`]).
    pub(super) fn guard(&self, ri: usize, stint: f64) -> StepGuard<'_> {
        StepGuard {
            thr: &self.thr[ri],
            cols: &self.cols[ri],
            stint,
        }
    }

    /// The thresholds of [`StepGuard`] in region `ri` for a base amp · sin Ωτ + 1 (after
    /// [`Self::prepare`]; `trig`: sin/cos Ωτ_k on the grid, k = 0..=m).
    fn prepare_thresholds(&mut self, amp: f64, ri: usize, trig: &[(f64, f64)]) {
        if self.thr_amp != Some(amp.to_bits()) {
            self.thr.iter_mut().for_each(Vec::clear);
            self.thr_amp = Some(amp.to_bits());
        }
        if self.thr[ri].is_empty() {
            let base = |s: f64| (amp * s + 1.0 - 4.0 * f64::EPSILON) / (1.0 + 1e-9);
            let thr = trig
                .iter()
                .zip(&self.grid[ri])
                .map(|(&(s, _), p)| base(s) - p);
            self.thr[ri].extend(thr);
        }
    }
}

/// Σ_k c_k |q_k| over the first `c.len()` representatives.
#[inline(always)]
fn weighted_modes(c: &[f64], q: &Modes) -> f64 {
    c.iter()
        .zip(q.re.iter().zip(&q.im))
        .map(|(c, (x, y))| c * (x * x + y * y).sqrt())
        .sum()
}

/// The body-contact guard of the steps of a span (`span.rs`), as its grid steps see it: at
/// grid point k the displacement bound Σ_j c_j |a_p,j(τ_k)| + B (B ≥ Σ_k (Σ_j c_j |b_jk|) |q_k|,
/// the homogeneous part's bound of [`ExactPropagator::displacement_bound_impl`], with the
/// weights c = reach_j of a [`BodyContactCheck`](crate::model::BodyContactCheck)) spares every
/// station — [`BodyContactCheck::spared`](crate::model::BodyContactCheck) against the base
/// amp · sin Ωτ_k + 1 less 4 ulp, as `touches_observed` holds it — when B is below
/// thr_k = (amp sin Ωτ_k + 1 − 4ε)/(1 + 1e-9) − Σ_j c_j |a_p,j(τ_k)| (one table per region).
/// B is first the stint's bound at the span's start (no work per step), then the sum at the
/// current q.
#[derive(Debug, Clone, Copy)]
pub(super) struct StepGuard<'a> {
    thr: &'a [f64],
    cols: &'a [f64],
    stint: f64,
}

impl StepGuard<'_> {
    /// Whether every station is spared at grid point `k` (0..m) with modal coordinates `q`.
    #[inline(always)]
    pub(super) fn spared(&self, k: usize, q: &Modes) -> bool {
        let t = self.thr[if k == 0 { self.thr.len() - 1 } else { k }];
        self.stint < t || weighted_modes(self.cols, q) < t
    }
}

impl ExactPropagator {
    /// The time over which a bound of the homogeneous part formed in a stint is kept: a
    /// period, at most [`STINT_BOUND_STEPS`] grid steps (see [`Self::displacement_bound_impl`]).
    fn stint_bound_window(&self) -> f64 {
        self.grid.h * (self.grid.m as f64).min(STINT_BOUND_STEPS)
    }

    /// Prepare the body-contact guard of a span's steps in the current region for `body`
    /// ([`StepGuard`]): returns the homogeneous part's bound at the current q, widened by
    /// 1e-10 as the stint's bound of [`Self::displacement_bound_impl`], and the window over
    /// which it holds; `None` outside a modal region, where some Re λ_k > 0, or for a check
    /// whose drive is not the model's.
    pub(super) fn prepare_guard(&mut self, body: &BodyContactCheck) -> Option<(f64, f64)> {
        let ri = self.region.index();
        let me = self.spec[ri].modal.as_ref()?;
        let (amp, omega) = body.drive();
        if omega != self.model.omega() {
            return None;
        }
        let cache = &mut self.bound_cols;
        cache.prepare(&body.reach, ri, me, &self.forced[ri], self.model.modes());
        if !cache.holds[ri] {
            return None;
        }
        cache.prepare_thresholds(amp, ri, &self.trig);
        let stint = cache.hom(ri, &self.q) * (1.0 + 1e-10);
        Some((stint, self.stint_bound_window()))
    }

    /// The guard of the current span in the current region ([`StepGuard`]), after
    /// [`Self::prepare_guard`]: whether its step ending at grid point `k` is spared.
    pub(super) fn guard_spares(&self, stint: f64, k: usize) -> bool {
        let ri = self.region.index();
        self.bound_cols.guard(ri, stint).spared(k, &self.q)
    }

    /// While the plain state lags behind the modal coordinates: a = a_p(τ) + Σ_k Re(b_k q_k)
    /// (the first N rows b_k of T⁻¹V, `ModalExp::expand`), and |Re(b q)| ≤ |b| |q|, so
    /// Σ_j c_j |a_j| ≤ Σ_j c_j |a_p,j| + Σ_k (Σ_j c_j |b_jk|) |q_k| (|q_k| as √(Re² + Im²):
    /// within a few ulp, which the 1e-9 widening of the body-contact test covers; the states
    /// are below 1e12, far from overflow). Where Re λ_k ≤ 0 for every k, |q_k| does not grow
    /// along a stint (q_k(τ) = e^{λ_k (τ − τ_0)} q_k(τ_0)), so the homogeneous part's sum
    /// formed once in a stint bounds it at every later point of the stint: with the
    /// particular part from a table on the grid that is O(1) per step, returned when below
    /// `enough`. It is widened by 1e-10 and formed again after a period or 10⁵ grid steps,
    /// whichever is shorter: the rounding of one step's complex product can grow a computed
    /// |q_k| by a few ulp, at most about 6e-11 over 10⁵ steps. Otherwise the sum at the
    /// current q. Without modal coordinates, the sum itself.
    pub(super) fn displacement_bound_impl(&mut self, weights: &[f64], enough: f64) -> f64 {
        let ri = self.region.index();
        let (Some(me), true) = (&self.spec[ri].modal, self.stale) else {
            return crate::model::weighted_displacement(weights, self.z.as_slice());
        };
        let cache = &mut self.bound_cols;
        cache.prepare(weights, ri, me, &self.forced[ri], self.model.modes());
        let part = match self.on_grid {
            Some((_, k)) => cache.grid[ri][self.grid.table_column(k)],
            None => {
                // z_p in the scratch vector (free between steps)
                let mut zp = std::mem::take(&mut self.zb);
                self.zp_now(zp.as_mut_slice());
                let part = crate::model::weighted_displacement(weights, zp.as_slice());
                self.zb = zp;
                part
            }
        };
        let window = self.stint_bound_window();
        let cache = &mut self.bound_cols;
        if cache.holds[ri] {
            let stint = match cache.stint {
                Some((tau, h)) if self.tau - tau <= window => h,
                _ => {
                    let h = cache.hom(ri, &self.q) * (1.0 + 1e-10);
                    cache.stint = Some((self.tau, h));
                    h
                }
            };
            if part + stint < enough {
                return part + stint;
            }
        }
        part + cache.hom(ri, &self.q)
    }
}

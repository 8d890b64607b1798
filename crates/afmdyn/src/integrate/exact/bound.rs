//! The displacement bound of [`crate::integrate::Integrator::displacement_bound`] in modal
//! regions: weighted column sums per region and a bound kept over a stint.

use super::forcing::Forced;
use super::modal::{ModalExp, Modes};
use super::ExactPropagator;

/// Most grid steps over which the stint's bound of [`Integrator::displacement_bound`] is kept
/// (see there).
///
/// [`Integrator::displacement_bound`]: crate::integrate::Integrator::displacement_bound
const STINT_BOUND_STEPS: f64 = 1e5;

/// The tables of [`Integrator::displacement_bound`] for weights c (per region, formed on
/// first use), and the bound of the current stint's homogeneous part.
///
/// [`Integrator::displacement_bound`]: crate::integrate::Integrator::displacement_bound
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
        self.cols[ri]
            .iter()
            .zip(q.re.iter().zip(&q.im))
            .map(|(c, (x, y))| c * (x * x + y * y).sqrt())
            .sum()
    }
}

impl ExactPropagator {
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
        // the stint's bound is kept over a period, at most STINT_BOUND_STEPS grid steps
        let window = self.grid.h * (self.grid.m as f64).min(STINT_BOUND_STEPS);
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

//! The sub-step grid of the drive period shared by the fixed-grid integrators (exact, RK4):
//! m points per period T, τ_j = (j div m) T + (j mod m) h with h = T/m, so every period starts
//! exactly on a multiple of T (no accumulated rounding) and stroboscopic sections land on it.

/// m sub-steps per drive period T.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PeriodGrid {
    /// Drive period T.
    pub period: f64,
    /// Sub-steps per period m (≥ 1).
    pub m: usize,
    /// Sub-step h = T/m.
    pub h: f64,
}

impl PeriodGrid {
    /// The grid of `m` sub-steps per period `period`.
    pub(crate) fn new(period: f64, m: usize) -> Self {
        let m = m.max(1);
        PeriodGrid {
            period,
            m,
            h: period / m as f64,
        }
    }

    /// Time of grid point j.
    pub fn tau(&self, j: i64) -> f64 {
        let m = self.m as i64;
        j.div_euclid(m) as f64 * self.period + j.rem_euclid(m) as f64 * self.h
    }

    /// Index of the first grid point strictly after τ.
    pub(crate) fn next_index(&self, tau: f64) -> i64 {
        let p = (tau / self.period).floor();
        let rem = tau - p * self.period;
        let mut j = p as i64 * self.m as i64 + (rem / self.h).floor() as i64 + 1;
        while self.tau(j - 1) > tau {
            j -= 1;
        }
        while self.tau(j) <= tau {
            j += 1;
        }
        j
    }

    /// The column of a one-period table over the grid points k = 0..=m (sin/cos Ωτ_k, z_p at
    /// τ_k) for grid point k of some period reached by a step: m at a period end (k = 0), so
    /// that the values are those at the end of the period the step ran in.
    pub(crate) fn table_column(&self, k: usize) -> usize {
        if k == 0 {
            self.m
        } else {
            k
        }
    }

    /// The first grid time strictly after τ.
    pub fn next(&self, tau: f64) -> f64 {
        self.tau(self.next_index(tau))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Grid points are strictly increasing, periods start exactly on multiples of T, and the
    /// next point after any τ (on or between points, negative or large) is the right one.
    #[test]
    fn next_point_is_the_first_strictly_after() {
        let g = PeriodGrid::new(2.0 * std::f64::consts::PI / 2.6, 7);
        assert_eq!(g.tau(7 * 3), 3.0 * g.period);
        for j in -30i64..200 {
            let t = g.tau(j);
            assert!(g.tau(j + 1) > t);
            assert_eq!(g.next_index(t), j + 1);
            assert_eq!(g.next_index(0.5 * (t + g.tau(j + 1))), j + 1);
        }
    }
}

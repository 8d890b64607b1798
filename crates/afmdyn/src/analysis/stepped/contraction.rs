//! The measured contraction of a settling point's stroboscopic returns ([`super::settle`]):
//! whether the returns' period test could still succeed before the free decay's wait ends, or
//! the motion shows no approach to a period of at most `max_period` and its time average may
//! be taken as soon as its windows agree.
//!
//! **The rule.** Over each run of returns z_0, z_1, … (one per drive period) the spread of lag
//! m (1 ≤ m ≤ `max_period`) is s_m = max_k ‖z_k − z_{k−m}‖ / (1 + ‖z_k‖), the quantity the
//! period test compares with its tolerance `tol` ([`crate::analysis::period::close`]). A
//! motion going to a period-m orbit has returns whose lag-m differences contract
//! geometrically, by a ratio r = s_m(now)/s_m(before) over the D drive periods between two
//! runs' starts; at that ratio they fall below `tol` after
//!
//!   P_m = D ln(s_m/tol) / ln(1/r)
//!
//! more periods (the geometric series of the differences still ahead: their sum, the
//! transient left, is at most s_m/(1 − r^{m/D}), and each is r^{P/D} of the last after P
//! periods). When no lag's P_m falls within what is left of the free decay's wait (ln(1/tol)
//! Q/π periods at resonance, [`crate::analysis::steady::decay_periods`]) in [`STALLED_RUNS`]
//! successive runs, the period test cannot succeed before that wait ends, and the wait is
//! over: the returns' differences have
//! stopped contracting (the irregular taps and missed taps of a grazing JKR contact, whose
//! returns stay ~1e-4 apart however long the motion runs) or contract too slowly. A lag whose
//! spread is within `tol`, or whose contraction cannot be measured (a spread of zero, a
//! first run), keeps the wait: it ends at the free decay as before. On the issue 60 image line
//! (RTESPA-300, Q = 500, over E_s = 100 MPa, W = 0.05 J/m²) the transient reaches the floor
//! of ~1e-4 within the Newton attempts' 1 000 periods, and the wait ends with the windows'
//! agreement instead of at the free decay's 2 930 periods: the line's averaged points take
//! about half the periods (3 080 before) and the line 2.6 s of CPU instead of 5.8 s, 1.8× the
//! line with a DMT stripe (docs/contact-laws.md).

use nalgebra::DVector;
use std::collections::VecDeque;

/// Successive runs of returns whose contraction must end the wait (module docs) before a
/// motion is settled by its time average early: two, so that one run whose spreads happen to
/// stall while the taps lock into a period does not (on the issue 60 line, a period-7 orbit
/// found 27 periods after one stalled run).
pub const STALLED_RUNS: usize = 2;

/// How long [`super::settle`] waits before a motion may be settled by its time average.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SettleWait {
    /// Until the slowest free mode has decayed by the period test's tolerance, or earlier
    /// when the returns' measured contraction shows the period test cannot succeed before
    /// then (module docs).
    #[default]
    Contraction,
    /// Until the slowest free mode has decayed by the period test's tolerance
    /// ([`crate::analysis::steady::decay_periods`]) whatever the returns do.
    FreeDecay,
}

/// The spreads s_m of one run of returns (module docs), m = 1..=`max_period`.
#[derive(Debug, Clone)]
pub(crate) struct Spread {
    recent: VecDeque<DVector<f64>>,
    max_period: usize,
    spreads: Vec<f64>,
}

impl Spread {
    /// A run starting at the return `first`.
    pub(crate) fn new(max_period: usize, first: &DVector<f64>) -> Self {
        let mut recent = VecDeque::with_capacity(max_period + 1);
        recent.push_back(first.clone());
        Spread {
            recent,
            max_period,
            spreads: vec![0.0; max_period],
        }
    }

    /// Account for the next return.
    pub(crate) fn push(&mut self, z: &DVector<f64>) {
        let scale = 1.0 + z.norm();
        for (j, past) in self.recent.iter().rev().enumerate() {
            let d = (z - past).norm() / scale;
            // NaN keeps the spread unmeasurable (it is not > the spread)
            if d > self.spreads[j] || d.is_nan() {
                self.spreads[j] = d;
            }
        }
        if self.recent.len() == self.max_period {
            self.recent.pop_front();
        }
        self.recent.push_back(z.clone());
    }

    /// s_m for m = 1..=`max_period` (0 for a lag longer than the run).
    pub(crate) fn spreads(&self) -> &[f64] {
        &self.spreads
    }
}

/// Whether the wait for the period test is over (module docs): no lag m whose spread went
/// from `before[m−1]` to `now[m−1]` over `distance` drive periods reaches `tol` within `left`
/// more periods at that ratio. `false` when some lag is within `tol`, reaches it in time, or
/// cannot be measured (a spread of zero or not finite).
pub(crate) fn wait_over(before: &[f64], now: &[f64], distance: f64, tol: f64, left: f64) -> bool {
    before.iter().zip(now).all(|(&a, &b)| {
        if !(a.is_finite() && b.is_finite() && a > 0.0 && b > tol) {
            return false;
        }
        let ratio = b / a;
        // a lag that does not contract never reaches tol
        ratio >= 1.0 || distance * (b / tol).ln() / (1.0 / ratio).ln() > left
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn z(x: f64, y: f64) -> DVector<f64> {
        DVector::from_vec(vec![x, y])
    }

    /// The spread of lag m is the largest relative difference of returns m apart: on a
    /// period-2 sequence lag 2 is 0 and lag 1 its jump.
    #[test]
    fn spreads_of_a_period_two_sequence() {
        let mut s = Spread::new(3, &z(1.0, 0.0));
        for k in 1..10 {
            s.push(&z(if k % 2 == 0 { 1.0 } else { -1.0 }, 0.0));
        }
        assert_eq!(s.spreads()[1], 0.0);
        assert_eq!(s.spreads()[0], 1.0);
        assert_eq!(s.spreads()[2], 1.0);
    }

    /// A geometric contraction that reaches the tolerance within what is left keeps the wait;
    /// one that would take longer, a stalled spread and a growing one end it; a lag within
    /// the tolerance or unmeasured keeps it.
    #[test]
    fn the_wait_ends_only_when_no_lag_can_reach_the_tolerance() {
        // 1e-3 → 3.7e-4 over 160 periods (free decay at Q = 500): 1e-8 after ~1 840 more
        let (a, b) = (1e-3, 1e-3 * (-1.0f64).exp());
        assert!(!wait_over(&[a], &[b], 160.0, 1e-8, 2000.0));
        assert!(wait_over(&[a], &[b], 160.0, 1e-8, 1500.0));
        assert!(wait_over(&[1e-4, 2e-4], &[1e-4, 3e-4], 160.0, 1e-8, 1e6));
        assert!(!wait_over(&[1e-4, 1e-4], &[1e-4, 1e-9], 160.0, 1e-8, 0.0));
        assert!(!wait_over(&[1e-4, 0.0], &[1e-4, 1e-4], 160.0, 1e-8, 0.0));
        assert!(!wait_over(
            &[1e-4, f64::NAN],
            &[1e-4, 1e-4],
            160.0,
            1e-8,
            0.0
        ));
    }
}

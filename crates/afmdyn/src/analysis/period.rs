//! Period-n detection on a sequence of stroboscopic returns P_k = z(2πk/Ω).

use nalgebra::DVector;

/// Largest period searched (the paper reports period-11, -21 and -28 orbits).
pub const MAX_PERIOD: usize = 64;

/// Whether two returns coincide: ‖a − b‖ ≤ tol (1 + ‖a‖).
pub(crate) fn close(a: &DVector<f64>, b: &DVector<f64>, tol: f64) -> bool {
    within(a.as_slice(), b.as_slice(), tol * (1.0 + a.norm()))
}

/// ‖a − b‖ ≤ `bound` (the test of [`close`], with its bound tol (1 + ‖a‖) given: the same
/// sum in the same order, on slices).
fn within(a: &[f64], b: &[f64], bound: f64) -> bool {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt()
        <= bound
}

/// The smallest n ≤ `max_period` such that the last n returns each repeat the return n
/// earlier: P_{k−j} ≈ P_{k−j−n} for j = 0..n (so a whole period-n cycle has converged).
/// `history` is ordered oldest first. None when no such n exists in the history.
///
/// Called on every return of a transient, where the first test (the last return against
/// the one n earlier) fails for every n: its bound tol (1 + ‖P_k‖) is formed once.
pub(crate) fn detect_period(
    history: &[DVector<f64>],
    tol: f64,
    max_period: usize,
) -> Option<usize> {
    let len = history.len();
    let last = len.checked_sub(1)?;
    let newest = history[last].as_slice();
    let bound = tol * (1.0 + history[last].norm());
    (1..=max_period.min(len / 2)).find(|&n| {
        within(newest, history[last - n].as_slice(), bound)
            && (1..n).all(|j| close(&history[last - j], &history[last - j - n], tol))
    })
}

/// Factor by which the tolerance is widened when a detected period n is reduced to a divisor.
pub(crate) const MERGE_FACTOR: f64 = 1e3;

/// The smallest divisor d of `n` such that the last `n` returns repeat with shift d within
/// `tol`. A stable focus whose returns rotate by ≈ 2π/n per period matches its n-th iterate
/// long before its consecutive iterates agree; reducing with a wider tolerance
/// (`MERGE_FACTOR` × the detection tolerance) reports it as the fixed point it converges to.
pub(crate) fn minimal_divisor(history: &[DVector<f64>], n: usize, tol: f64) -> usize {
    let last = history.len() - 1;
    (1..n)
        .filter(|&d| n.is_multiple_of(d) && history.len() > n + d)
        .find(|&d| (0..n).all(|j| close(&history[last - j], &history[last - j - d], tol)))
        .unwrap_or(n)
}

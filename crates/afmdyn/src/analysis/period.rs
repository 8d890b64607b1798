//! Period-n detection on a sequence of stroboscopic returns P_k = z(2πk/Ω).

use nalgebra::DVector;

/// Largest period searched (the paper reports period-11, -21 and -28 orbits).
pub const MAX_PERIOD: usize = 64;

/// Whether two returns coincide: ‖a − b‖ ≤ tol (1 + ‖a‖).
pub fn close(a: &DVector<f64>, b: &DVector<f64>, tol: f64) -> bool {
    let scale = 1.0 + a.norm();
    a.iter()
        .zip(b.iter())
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt()
        <= tol * scale
}

/// The smallest n ≤ `max_period` such that the last n returns each repeat the return n
/// earlier: P_{k−j} ≈ P_{k−j−n} for j = 0..n (so a whole period-n cycle has converged).
/// `history` is ordered oldest first. None when no such n exists in the history.
pub fn detect_period(history: &[DVector<f64>], tol: f64, max_period: usize) -> Option<usize> {
    let len = history.len();
    let last = len.checked_sub(1)?;
    (1..=max_period.min(len / 2)).find(|&n| {
        close(&history[last], &history[last - n], tol)
            && (1..n).all(|j| close(&history[last - j], &history[last - j - n], tol))
    })
}

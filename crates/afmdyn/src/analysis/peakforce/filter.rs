//! The instrument's low-pass filter on the measured force: a second-order Butterworth filter,
//! causal, in its periodic steady state.
//!
//! **Which filter.** The deflection signal of an instrument passes through the photodetector's
//! and the controller's low-pass stages before the force curve is formed; a second-order
//! Butterworth response (maximally flat, H(s) = 1/(s² + √2 s + 1) at s = iω/ω_c: S. Butterworth,
//! *Wireless Engineer* 7, 536 (1930)) at a stated cut-off f_c stands for them. It is applied
//! **causally**, as the instrument's real-time filter is: it delays the measured force (a group
//! delay of √2/(2π f_c) at low frequency) and so shifts and rounds the peak and the pull-off,
//! which is the distortion to be seen. (A zero-phase, forward–backward filter would hide the
//! delay; it is what an offline analysis of stored curves could do, not the instrument.)
//!
//! **Discretisation.** The bilinear transform with the cut-off prewarped, K = tan(π f_c Δt):
//! b₀ = b₂ = K²/D, b₁ = 2K²/D, a₁ = 2(K² − 1)/D, a₂ = (1 − √2K + K²)/D, D = 1 + √2K + K²
//! (A. V. Oppenheim & R. W. Schafer, *Discrete-Time Signal Processing*, 3rd ed. 2010, §7.2),
//! in transposed direct form II. The cycle is periodic, so the output is the filter's periodic
//! steady state: the two filter states at the start of the period are solved for exactly,
//! s₀ = (I − M)⁻¹ r, with M the states' map over one period without input and r the states a
//! period of input leaves from rest — no transient, whatever f_c. `tests/peakforce.rs` checks
//! the gain and phase at the cut-off (1/√2, −π/2), the unit DC gain and the roll-off.

use crate::error::SimError;

/// The biquad's coefficients (b₀, b₁, b₂, a₁, a₂) at the cut-off `fc_dt` = f_c Δt (cycles per
/// sample).
fn coefficients(fc_dt: f64) -> [f64; 5] {
    let k = (std::f64::consts::PI * fc_dt).tan();
    let r2 = std::f64::consts::SQRT_2;
    let d = 1.0 + r2 * k + k * k;
    let b0 = k * k / d;
    [
        b0,
        2.0 * b0,
        b0,
        2.0 * (k * k - 1.0) / d,
        (1.0 - r2 * k + k * k) / d,
    ]
}

/// One pass of the transposed direct form II over `x` from the states `s`; the output (when
/// `out`) and the final states.
fn pass(
    c: &[f64; 5],
    x: impl Iterator<Item = f64>,
    mut s: [f64; 2],
    out: Option<&mut Vec<f64>>,
) -> [f64; 2] {
    let [b0, b1, b2, a1, a2] = *c;
    let mut out = out;
    for xi in x {
        let y = b0 * xi + s[0];
        s[0] = b1 * xi - a1 * y + s[1];
        s[1] = b2 * xi - a2 * y;
        if let Some(o) = out.as_deref_mut() {
            o.push(y);
        }
    }
    s
}

/// The periodic steady state of the second-order Butterworth low-pass (module docs) of the
/// periodic signal `x` (one period, uniformly sampled, the next period starting after its last
/// sample), with the cut-off `fc_dt` = f_c Δt in cycles per sample; same length as `x`.
///
/// # Errors
/// [`SimError::OutOfRange`] naming `filter_cutoff` unless 0 < f_c Δt < 0.5 (below the Nyquist
/// frequency of the samples).
pub fn low_pass_periodic(x: &[f64], fc_dt: f64) -> Result<Vec<f64>, SimError> {
    if !(fc_dt > 0.0 && fc_dt < 0.5) {
        return Err(SimError::out_of_range(
            "filter_cutoff",
            fc_dt,
            "the cut-off times the sampling interval must lie in (0, 0.5): below the Nyquist \
             frequency of the cycle's samples (raise --samples or lower the cut-off)",
        ));
    }
    let c = coefficients(fc_dt);
    let zero = || std::iter::repeat_n(0.0, x.len());
    // r: the states a period of input leaves from rest; M's columns: the free response
    let r = pass(&c, x.iter().copied(), [0.0; 2], None);
    let m0 = pass(&c, zero(), [1.0, 0.0], None);
    let m1 = pass(&c, zero(), [0.0, 1.0], None);
    // (I − M) s₀ = r, 2 × 2 by Cramer's rule
    let (a, b, cc, d) = (1.0 - m0[0], -m1[0], -m0[1], 1.0 - m1[1]);
    let det = a * d - b * cc;
    let s0 = [(r[0] * d - b * r[1]) / det, (a * r[1] - cc * r[0]) / det];
    let mut y = Vec::with_capacity(x.len());
    pass(&c, x.iter().copied(), s0, Some(&mut y));
    Ok(y)
}

//! The step's polynomials: the step-size rule of a Taylor method and the search for the
//! leftmost zero of a guard given by its Taylor polynomial.

use crate::roots::{extremum, safeguarded_newton};

/// Order p of the series for a tolerance ε: ⌈¾ ln(1/ε) + 1⌉ (22 at 1e-12), with the step of
/// [`step_size`] the truncation error is about ε.
///
/// Jorba & Zou (*Exp. Math.* 14 (2005) 99, eq. 3.6) take ½ ln(1/ε) + 1 and the step ρ/e², the
/// optimum when a step costs O(p²); here most of a step's cost is linear in p and latency-bound
/// (the recurrence of order k waits for order k − 1), so fewer, larger steps of higher order
/// pay: measured on the point-mass DMT probe (steps per drive period, CPU time) ½: 36.2 steps,
/// ¾: 23.5 steps and 6 % less time, 1: 19.5 steps and 11 % more; on the beam (N = 3, DMT) ½: 105,
/// ¾: 54, 1: 37 steps at the time of ¾. Accuracy against DOP853 at 1e-14 is the same
/// (`tests/taylor.rs`).
pub(crate) fn order_for(tol: f64) -> usize {
    ((-0.75 * tol.ln() + 1.0).ceil() as usize).clamp(8, super::jet::MAX_ORDER)
}

/// The step of a Taylor method of order p for the tolerance ε from the ∞-norms of the state
/// (`x0`) and of the coefficients of orders p − 1 and p: h = ρ ε^{1/p} e^{−0.7/(p−1)} with
/// ρ = min_{m ∈ {p−1, p}} (max(1, ‖x₀‖)/‖x_m‖)^{1/m}, the radius of convergence estimated from
/// the last two orders, so that the last term ‖x_p‖hᵖ ≈ ε max(1, ‖x₀‖) (Jorba & Zou 2005,
/// §3.2–3.3, absolute and relative tolerance alike; the safety factor of heyoka, Biscani & Izzo,
/// *MNRAS* 504 (2021) 2614). `f64::INFINITY` when both norms vanish.
pub(crate) fn step_size(x0: f64, norm_pm1: f64, norm_p: f64, p: usize, tol: f64) -> f64 {
    // in logarithms: two logarithms and one exponential instead of two powers
    let scale = x0.max(1.0).ln();
    let l1 = (scale - norm_pm1.ln()) / (p - 1) as f64;
    let l2 = (scale - norm_p.ln()) / p as f64;
    (l1.min(l2) + tol.ln() / p as f64 - 0.7 / (p - 1) as f64).exp()
}

/// [P(s), P′(s), P″(s)] of the polynomial with coefficients `c` (c₀ + c₁s + …), by Horner.
pub(crate) fn eval3(c: &[f64], s: f64) -> [f64; 3] {
    let mut p = 0.0;
    let mut dp = 0.0;
    let mut ddp = 0.0;
    for &ck in c.iter().rev() {
        ddp = ddp * s + 2.0 * dp;
        dp = dp * s + p;
        p = p * s + ck;
    }
    [p, dp, ddp]
}

/// P(s).
pub(crate) fn eval(c: &[f64], s: f64) -> f64 {
    c.iter().rev().fold(0.0, |p, &ck| p * s + ck)
}

/// Nodes of the scan of [`leftmost_crossing`] beyond the certified bounds.
const NODES: usize = 16;

/// The leftmost s in (0, h] where the guard P (positive inside the region, coefficients `c`)
/// goes below −`dead`: a crossing of zero located by safeguarded Newton ([`safeguarded_newton`])
/// from the last point before it where P > 0, or 0 when P is never positive before it (the
/// trajectory does not enter the region). `None` when P stays above −`dead`.
///
/// Certified bounds decide most steps without a search: P(s) ≥ c₀ − Σ_{k≥1} |c_k| hᵏ and
/// P(s) ≥ c₀ + min(c₁, 0) h − Σ_{k≥2} |c_k| hᵏ (no zero for c₀ > 0 off the surface), and
/// |c₁| > Σ_{k≥2} k |c_k| h^{k−1} (P′ keeps the sign of c₁ on [0, h]: P is monotone, so it
/// crosses zero at most once, where P(h) < 0, and that zero is located at once). Otherwise P
/// and P′ are scanned at 16 equal sub-intervals: a zero where P falls below −`dead` at a node,
/// a dip below it between nodes at a minimum of P (a sign change of P′ from − to +; the step of
/// a Taylor method is a small fraction of the fastest oscillation, so P′ has at most a few
/// zeros in a step and two of them within one sub-interval do not occur). `on_surface`: the
/// step starts on the guard's zero (just after an event), so the zero at s = 0 does not count:
/// the bracket starts at the first maximum of P.
pub(crate) fn leftmost_crossing(c: &[f64], h: f64, dead: f64, on_surface: bool) -> Option<f64> {
    let c0 = c[0];
    let first = c[1] * h;
    // Σ_{k≥2} |c_k| hᵏ and h Σ_{k≥2} k |c_k| h^{k−1}
    let (mut tail, mut slope_tail) = (0.0, 0.0);
    let mut hk = h;
    for (k, &ck) in c.iter().enumerate().skip(2) {
        hk *= h;
        let term = ck.abs() * hk;
        tail += term;
        slope_tail += k as f64 * term;
    }
    if !on_surface
        && c0 > 0.0
        && (c0 - first.abs() - tail > -dead || c0 + first.min(0.0) - tail > -dead)
    {
        return None;
    }
    if first.abs() > slope_tail {
        // monotone on [0, h]
        if first > 0.0 {
            return (c0 <= -dead).then_some(0.0);
        }
        let end = eval(c, h);
        if end > -dead {
            return None;
        }
        if c0 <= 0.0 {
            return Some(0.0);
        }
        return Some(safeguarded_newton(
            0.0,
            c0,
            h,
            end.min(0.0),
            0.0,
            &mut |s| {
                let [p, dp, _] = eval3(c, s);
                (p, dp)
            },
        ));
    }
    let at = |s: f64| eval3(c, s);
    let mut f = |s: f64| {
        let [p, dp, ddp] = at(s);
        [p, dp, ddp]
    };
    // the last point with P > 0 before the current node (the bracket's left end)
    let mut pos: Option<(f64, f64)> = (c0 > 0.0 && !on_surface).then_some((0.0, c0));
    let mut prev_s = 0.0;
    let mut prev = at(0.0);
    if on_surface && prev[0] > 0.0 && prev[1] <= 0.0 {
        // on the surface but above it by round-off, moving outwards: no positive point yet
        prev[0] = 0.0;
    }
    for i in 1..=NODES {
        let s = h * i as f64 / NODES as f64;
        let cur = at(s);
        // a maximum of P inside (prev, s): the left end of a bracket when P > 0 there
        if prev[1] > 0.0 && cur[1] < 0.0 {
            let sm = extremum(prev_s, s, prev[1], &mut f);
            let pm = at(sm)[0];
            if pm > 0.0 {
                pos = Some((sm, pm));
            }
        }
        let mut bottom = None;
        if cur[0] < -dead {
            bottom = Some((s, cur[0]));
        } else if prev[1] < 0.0 && cur[1] > 0.0 {
            let sm = extremum(prev_s, s, prev[1], &mut f);
            let pm = at(sm)[0];
            if pm < -dead {
                bottom = Some((sm, pm));
            }
        }
        if let Some((sb, pb)) = bottom {
            let Some((sa, pa)) = pos else {
                // never clearly inside the region: the event is at the start of the step
                return Some(0.0);
            };
            return Some(safeguarded_newton(sa, pa, sb, pb.min(0.0), 0.0, &mut |s| {
                let [p, dp, _] = at(s);
                (p, dp)
            }));
        }
        if cur[0] > 0.0 {
            pos = Some((s, cur[0]));
        }
        prev_s = s;
        prev = cur;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Horner's value and derivatives of (s − 1)(s − 2)(s + 3) = s³ − 7s + 6.
    #[test]
    fn evaluates_value_and_derivatives() {
        let c = [6.0, -7.0, 0.0, 1.0];
        for s in [-1.5, 0.0, 0.3, 2.5] {
            let [p, dp, ddp] = eval3(&c, s);
            assert!((p - (s * s * s - 7.0 * s + 6.0)).abs() < 1e-12);
            assert!((dp - (3.0 * s * s - 7.0)).abs() < 1e-12);
            assert!((ddp - 6.0 * s).abs() < 1e-12);
            assert_eq!(eval(&c, s), p);
        }
    }

    /// The leftmost root of polynomials with known roots; a dip between nodes; no root; a start
    /// on the surface moving inwards (the root at 0 does not count) and outwards (event at 0).
    #[test]
    fn finds_the_leftmost_crossing() {
        // (s − 0.3)(s − 0.7) = s² − s + 0.21: falls through 0.3 first
        let c = [0.21, -1.0, 1.0];
        let s = leftmost_crossing(&c, 1.0, 1e-14, false).unwrap();
        assert!((s - 0.3).abs() < 1e-15);
        // a narrow dip: (s − 0.51)(s − 0.52) + tiny: between the nodes 8/16 and 9/16
        let c = [0.51 * 0.52, -1.03, 1.0];
        let s = leftmost_crossing(&c, 1.0, 1e-14, false).unwrap();
        assert!((s - 0.51).abs() < 1e-14, "{s}");
        // stays positive: (s − 0.5)² + 0.01
        assert!(leftmost_crossing(&[0.26, -1.0, 1.0], 1.0, 1e-14, false).is_none());
        // on the surface, rising then falling through 0 at s = 0.8: s (0.8 − s)
        let c = [0.0, 0.8, -1.0];
        let s = leftmost_crossing(&c, 1.0, 1e-14, true).unwrap();
        assert!((s - 0.8).abs() < 1e-15, "{s}");
        // on the surface and falling at once: the event is at the start
        assert_eq!(
            leftmost_crossing(&[0.0, -0.5, 0.0], 1.0, 1e-14, true),
            Some(0.0)
        );
        // the crossing past the step's end is not reported
        assert!(leftmost_crossing(&[0.21, -1.0, 1.0], 0.25, 1e-14, false).is_none());
    }

    /// The step-size rule: for eˢ (all coefficients 1/k!) ρ = ((p − 1)!)^{1/(p−1)}; a
    /// vanishing series gives an unbounded step.
    #[test]
    fn step_size_follows_the_last_two_orders() {
        let p = 15;
        let fact = |k: usize| (1..=k).map(|i| i as f64).product::<f64>();
        let h = step_size(1.0, 1.0 / fact(p - 1), 1.0 / fact(p), p, 1e-12);
        let rho = fact(p - 1).powf(1.0 / (p - 1) as f64);
        let expected = rho * (1e-12f64.ln() / p as f64 - 0.7 / (p - 1) as f64).exp();
        assert!((h - expected).abs() < 1e-12 * expected);
        assert!(step_size(1.0, 0.0, 0.0, p, 1e-12).is_infinite());
        assert_eq!(order_for(1e-12), 22);
    }
}

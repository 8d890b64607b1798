//! Safeguarded Newton iteration on a bracket: the one root finder behind event location (exact
//! and adaptive integrators) and the search for extrema of dense quantities (grazing distance,
//! X_max, min V_T).
//!
//! Newton's step is taken when it stays inside the current bracket, bisection otherwise, so the
//! iteration converges quadratically near a simple root and never leaves the bracket (Press et
//! al., *Numerical Recipes*, 3rd ed., CUP 2007, §9.4, `rtsafe`).

/// Zero of g on [lo, hi] given g(lo) > 0 ≥ g(hi); `g(t)` returns (g, g′). `offset` is added to
/// t for the relative stopping test (pass the step's start time when t is local), so the result
/// is exact to a few ulps of the absolute time.
pub(crate) fn safeguarded_newton(
    mut lo: f64,
    glo: f64,
    mut hi: f64,
    ghi: f64,
    offset: f64,
    g: &mut dyn FnMut(f64) -> (f64, f64),
) -> f64 {
    // regula falsi start inside a true bracket, else the midpoint (the iterates never leave
    // [lo, hi], so a caller's wrong bracket gives a point of it, never a panic)
    let mut t = if glo > 0.0 && ghi <= 0.0 {
        lo + (hi - lo) * glo / (glo - ghi)
    } else {
        0.5 * (lo + hi)
    };
    if !(t >= lo && t <= hi) {
        t = 0.5 * (lo + hi);
    }
    // the last Newton correction taken (None after a bisection)
    let mut prev_step: Option<f64> = None;
    for _ in 0..100 {
        let (v, d) = g(t);
        if v > 0.0 {
            lo = t;
        } else {
            hi = t;
        }
        let scale = 1.0 + (offset + t).abs();
        let tol = 2.0 * f64::EPSILON * scale;
        let newton = if d != 0.0 { t - v / d } else { f64::NAN };
        // a Newton correction at round-off ends the iteration wherever it lands: converging
        // from one side, it can land on (or just past) the end of the bracket that the
        // iterates themselves moved, and a bisection from there would start over from the
        // far end
        let step = (newton - t).abs();
        if step <= tol {
            t = newton;
            break;
        }
        let inside = newton > lo && newton < hi;
        // quadratic convergence: δ_{k+1} ≈ C δ_k² with C ≈ δ_k/δ_{k−1}², so the correction
        // after this one is about δ_k³/δ_{k−1}²; when that is below round-off, this Newton
        // step is the last one and needs no evaluation to confirm it
        if inside && prev_step.is_some_and(|p| step < p && step * step * step <= 0.25 * tol * p * p)
        {
            t = newton;
            break;
        }
        prev_step = inside.then_some(step);
        let next = if inside { newton } else { 0.5 * (lo + hi) };
        let done = (next - t).abs() <= tol || hi - lo <= 2.0 * tol;
        t = next;
        if done {
            break;
        }
    }
    t.clamp(lo.min(hi), hi.max(lo))
}

/// Zero of the derivative f′ of a dense quantity on [a, b], given f′(a) = `fa_d` and f′(b) of
/// opposite signs (a local extremum of f); `f(τ)` returns (f, f′, f″).
pub(crate) fn extremum(a: f64, b: f64, fa_d: f64, f: &mut dyn FnMut(f64) -> [f64; 3]) -> f64 {
    let sign = if fa_d > 0.0 { 1.0 } else { -1.0 };
    let [_, db, _] = f(b);
    safeguarded_newton(a, sign * fa_d, b, sign * db, 0.0, &mut |t| {
        let [_, d, dd] = f(t);
        (sign * d, sign * dd)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Roots of polynomials with known zeros, and the maximum of sin at π/2.
    #[test]
    fn finds_known_roots_and_extrema() {
        let t = safeguarded_newton(0.0, 2.0, 3.0, -7.0, 0.0, &mut |t| (2.0 - t * t, -2.0 * t));
        assert!((t - 2f64.sqrt()).abs() <= 4.0 * f64::EPSILON);
        // a flat bracket end (g′ = 0) falls back to bisection
        let t = safeguarded_newton(0.0, 1.0, 2.0, -1.0, 0.0, &mut |t| {
            ((1.0 - t).powi(3), -3.0 * (1.0 - t).powi(2))
        });
        assert!((t - 1.0).abs() < 1e-5);
        let t = extremum(1.0, 2.0, 1f64.cos(), &mut |t| [t.sin(), t.cos(), -t.sin()]);
        assert!((t - std::f64::consts::FRAC_PI_2).abs() <= 4.0 * f64::EPSILON);
        // no sign change: a point of the interval, no panic
        let t = safeguarded_newton(0.0, 1.0, 1.0, 2.0, 0.0, &mut |t| (1.0 + t, 1.0));
        assert!((0.0..=1.0).contains(&t));
    }

    /// Simple roots with a known value (√2, ln 2, π, and a root at τ ≈ 1e3 where the tolerance
    /// is relative to the absolute time) are found to a few ulps in a handful of evaluations,
    /// also when the iterates converge from one side: the correction at round-off ends the
    /// iteration instead of a bisection restarting from the bracket's far end (about 50
    /// evaluations before).
    #[test]
    fn converges_in_a_few_evaluations_to_a_few_ulps() {
        // (bracket, offset, root, g)
        type Case = (f64, f64, f64, f64, fn(f64) -> (f64, f64));
        let cases: [Case; 4] = [
            (0.0, 3.0, 0.0, 2f64.sqrt(), |t| (2.0 - t * t, -2.0 * t)),
            (0.0, 3.0, 0.0, 2f64.ln(), |t| {
                ((-t).exp() - 0.5, -(-t).exp())
            }),
            (3.0, 3.5, 0.0, std::f64::consts::PI, |t| (t.sin(), t.cos())),
            (0.0, 0.4, 1000.0, 0.25, |t| {
                (
                    (0.25 - t) * (1.0 + t * t),
                    -(1.0 + t * t) + (0.25 - t) * 2.0 * t,
                )
            }),
        ];
        for (lo, hi, offset, root, f) in cases {
            let mut evals = 0;
            let t = safeguarded_newton(lo, f(lo).0, hi, f(hi).0, offset, &mut |t| {
                evals += 1;
                f(t)
            });
            let ulps = 4.0 * f64::EPSILON * (1.0 + (offset + root).abs());
            assert!((t - root).abs() <= ulps, "root {root}: {t}");
            assert!(evals <= 7, "root {root}: {evals} evaluations");
        }
    }
}

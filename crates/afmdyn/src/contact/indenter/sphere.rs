//! Sneddon's exact sphere of radius R, not limited to δ ≪ R (Sneddon, *Int. J. Eng. Sci.* 3
//! (1965) 47, eqs. 6.13 and 6.15; nanite's `sneddon_spher`): parametric in the contact radius
//! a < R,
//!
//! δ = (a/2) ln((R + a)/(R − a)),  F = (E*/2) [(a² + R²) ln((R + a)/(R − a)) − 2aR].
//!
//! With u = a/R: δ/R = u artanh u and F/E* = R² [(1 + u²) artanh u − u]; u is found by the
//! crate's safeguarded Newton iteration ([`crate::roots::safeguarded_newton`]) on ln u, so its
//! relative error is a few ulps at any depth. Near u = 0 the bracket cancels (it is
//! (4/3)u³ + (8/15)u⁵ + …), so it is summed as its series Σ_{k≥1} 4k u^{2k+1}/(4k² − 1) below
//! u = 1/2. The contact stiffness is ∂F/∂δ = 2E*a (Sneddon's, for any axisymmetric punch), and
//! ∂F/∂R at fixed δ = 2E*R (artanh u − u).

use super::Elastic;

/// Below this u = a/R the bracket and artanh u − u are summed as their series.
const SERIES_BELOW: f64 = 0.5;

/// The contact radius over R, u = a/R, of the indentation δ/R = `d` > 0: the root of
/// u artanh u = d (saturating below 1 where d is beyond what a double resolves, d ≳ 18).
pub(crate) fn contact_ratio(d: f64) -> f64 {
    let top = 1.0 - f64::EPSILON;
    // u artanh u ≥ u², so u ≤ √d; and at √d e⁻² the left side is below d
    let hi = d.sqrt().min(top);
    let lo = hi * (-2.0_f64).exp();
    let g = |u: f64| d.ln() - (u * u.atanh()).ln();
    let (glo, ghi) = (g(lo), g(hi));
    if ghi > 0.0 {
        return hi;
    }
    let w = crate::roots::safeguarded_newton(lo.ln(), glo, hi.ln(), ghi, 0.0, &mut |w| {
        let u = w.exp();
        let at = u.atanh();
        (g(u), -(1.0 + u / ((1.0 - u * u) * at)))
    });
    w.exp()
}

/// (1 + u²) artanh u − u, the force's bracket.
fn bracket(u: f64) -> f64 {
    if u >= SERIES_BELOW {
        return (1.0 + u * u) * u.atanh() - u;
    }
    let (u2, mut p, mut sum) = (u * u, u, 0.0);
    for k in 1..200 {
        p *= u2;
        let k = f64::from(k);
        let term = 4.0 * k * p / (4.0 * k * k - 1.0);
        sum += term;
        if term <= 1e-17 * sum {
            break;
        }
    }
    sum
}

/// artanh u − u = Σ_{k≥1} u^{2k+1}/(2k + 1).
fn atanh_less_u(u: f64) -> f64 {
    if u >= SERIES_BELOW {
        return u.atanh() - u;
    }
    let (u2, mut p, mut sum) = (u * u, u, 0.0);
    for k in 1..200 {
        p *= u2;
        let term = p / f64::from(2 * k + 1);
        sum += term;
        if term <= 1e-17 * sum {
            break;
        }
    }
    sum
}

/// g = F/E* and its derivatives at δ > 0 (m) and R = `radius` (m) (module docs).
pub(crate) fn elastic(radius: f64, delta: f64) -> Elastic {
    let u = contact_ratio(delta / radius);
    Elastic {
        force: radius * radius * bracket(u),
        d_delta: 2.0 * radius * u,
        d_radius: 2.0 * radius * atanh_less_u(u),
    }
}

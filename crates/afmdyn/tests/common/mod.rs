//! Test helpers shared by the integration tests: the closed-form forced response of a region
//! and the events of a run.

use afmdyn::galerkin::Region;
use afmdyn::integrate::{advance_dyn, Integrator, SwitchEvent};
use afmdyn::CantileverModel;
use nalgebra::{Complex, DMatrix, DVector};

/// Closed-form periodic forced response of region `r` from the second-order equations
/// M Ẍ + C Ẋ + K X = F(τ) (eq. 10): K X₀ = F_const and (K − Ω²M + iΩC) X̂ = F_cos − i F_sin.
/// Independent of the first-order solve inside the propagator. Returns z_p(τ) = (X, Ẋ).
pub fn harmonic_response(model: &CantileverModel, r: Region, tau: f64) -> DVector<f64> {
    let g = model.galerkin().region(r);
    let w = model.omega();
    let c = |m: &DMatrix<f64>| m.map(|v| Complex::new(v, 0.0));
    let dyn_stiff = c(&g.stiffness) - c(&g.mass) * Complex::new(w * w, 0.0)
        + c(&g.damping) * Complex::new(0.0, w);
    let rhs =
        g.forcing.cos.map(|v| Complex::new(v, 0.0)) - g.forcing.sin.map(|v| Complex::new(0.0, v));
    let xh = dyn_stiff.lu().solve(&rhs).unwrap();
    let x0 = g.stiffness.clone().lu().solve(&g.forcing.constant).unwrap();
    let e = Complex::new((w * tau).cos(), (w * tau).sin());
    let n = model.modes();
    let mut z = DVector::zeros(2 * n);
    for j in 0..n {
        z[j] = x0[j] + (xh[j] * e).re;
        z[n + j] = (xh[j] * e * Complex::new(0.0, w)).re;
    }
    z
}

/// The events of `integ` up to `tau_end`.
pub fn events_until(integ: &mut dyn Integrator, tau_end: f64) -> Vec<SwitchEvent> {
    let mut ev = Vec::new();
    advance_dyn(integ, tau_end, &mut |_, s, _| {
        if let Some(e) = &s.event {
            ev.push(e.clone());
        }
        Ok(())
    })
    .unwrap();
    ev
}

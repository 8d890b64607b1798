//! The exact orbit sensitivities' check (`fit_dynamic.rs`, `fit_lever.rs`): the sensitivities
//! at an orbit against the fourth-order central differences of Newton-converged orbits, at the
//! first stable period-1 point of an AM approach in a regime (attractive, repulsive, light
//! touch) away from folds and grazing.

use super::orbit_params::{newton, value_of, with};
use afmdyn::analysis::approach::{approach_retract, approach_spec};
use afmdyn::analysis::fit::sensitivity::{orbit_sensitivity, OrbitParam, OrbitSensitivity};
use afmdyn::analysis::observables::observe_orbit;
use afmdyn::analysis::shooting::shoot;
use afmdyn::analysis::stepped::{CurvePoint, Spacing};
use afmdyn::integrate::{build, IntegratorKind, IntegratorOptions};
use afmdyn::maps::StroboscopicMap;
use afmdyn::model::CantileverModel;
use afmdyn::Params;
use nalgebra::DVector;
use std::f64::consts::FRAC_PI_2;

/// The adaptive integrator's tolerance of the sensitivities and of the finite differences.
pub const TOL: f64 = 1e-12;
/// The relative step of the central differences.
pub const STEP: f64 = 1e-3;
/// The agreement asked for (issue 62: ≤ 1e-6 relative).
pub const AGREE: f64 = 1e-6;

/// The orbit at `params` near `guess`, without sensitivities, integrated to `tol`.
pub fn orbit(params: &Params, guess: &DVector<f64>, tol: f64) -> OrbitSensitivity {
    let model = CantileverModel::new(params).expect("model");
    orbit_sensitivity(&model, tol, guess, &[], Some(&newton()), None).expect("orbit")
}

/// Check the exact sensitivities at the orbit near `guess` against central differences;
/// `false` (nothing checked) where the orbit is near a fold or grazing.
#[allow(dead_code)] // no test calls it at present (fit_bimodal.rs has its own)
pub fn check_point(base: &Params, guess: &DVector<f64>, params: &[OrbitParam], what: &str) -> bool {
    check_point_at(base, guess, params, what, TOL)
}

/// [`check_point`] with the orbits and their sensitivities integrated to `tol`.
pub fn check_point_at(
    base: &Params,
    guess: &DVector<f64>,
    params: &[OrbitParam],
    what: &str,
    tol: f64,
) -> bool {
    let model = CantileverModel::new(base).expect("model");
    let exact =
        orbit_sensitivity(&model, tol, guess, params, Some(&newton()), None).expect("sensitivity");
    if !exact.warnings.is_empty() {
        eprintln!("{what}: skipped, {:?}", exact.warnings);
        return false;
    }
    // the amplitude of the Fourier integrals is the library's observable
    let mut it = build(&model, IntegratorOptions::default(), 0.0, &model.rest()).expect("build");
    let map = &mut StroboscopicMap::new(it.as_mut(), 1);
    let shot = shoot(map, &exact.state, &newton()).expect("orbit");
    let opts = IntegratorOptions {
        kind: IntegratorKind::Adaptive,
        tolerance: tol,
        ..IntegratorOptions::default()
    };
    let obs = observe_orbit(&model, opts, &shot, 1).expect("observables");
    assert!(
        (obs.amplitude - exact.amplitude).abs() <= 1e-8 * obs.amplitude,
        "{what}: A = {} against the observables' {}",
        exact.amplitude,
        obs.amplitude
    );
    assert!(
        (obs.phase - exact.phase).abs() <= 1e-8,
        "{what}: φ = {} against the observables' {}",
        exact.phase,
        obs.phase
    );
    for (j, &p) in params.iter().enumerate() {
        let v = value_of(base, p);
        // Ω within a small share of the resonance's half linewidth Ω/(2Q) (Q = 400 here),
        // across which the phase turns by a radian
        let h = if p == OrbitParam::DriveFrequency {
            1e-6 * v.abs()
        } else {
            STEP * v.abs()
        };
        // the fourth-order central difference (its truncation error O(h⁴) far below the
        // integration error's ~TOL/h)
        let at = |k: f64| orbit(&with(base, p, v + k * h), &exact.state, tol);
        let (p1, m1, p2, m2) = (at(1.0), at(-1.0), at(2.0), at(-2.0));
        let diff = |f: &dyn Fn(&OrbitSensitivity) -> f64| {
            (8.0 * (f(&p1) - f(&m1)) - (f(&p2) - f(&m2))) / (12.0 * h)
        };
        let fd_a = diff(&|o| o.amplitude);
        let fd_phi = diff(&|o| o.phase);
        let fd_z = ((&p1.state - &m1.state) * 8.0 - (&p2.state - &m2.state)) / (12.0 * h);
        // relative to the derivative; a parameter the orbit does not feel (α4 or H̃ of an
        // orbit out of contact) has both exactly 0
        let rel = |e: f64, f: f64| {
            if e == 0.0 && f == 0.0 {
                0.0
            } else {
                (e - f).abs() / e.abs().max(f64::MIN_POSITIVE)
            }
        };
        let (ea, ep) = (exact.d_amplitude[j], exact.d_phase[j]);
        let ez = exact.d_state.column(j).into_owned();
        let rz = if ez.norm() == 0.0 && fd_z.norm() == 0.0 {
            0.0
        } else {
            (&ez - &fd_z).norm() / ez.norm()
        };
        eprintln!(
            "{what} {p:?}: dA/dp {ea:.9e} (fd {fd_a:.9e}, rel {:.1e}), dφ/dp {ep:.9e} (fd \
             {fd_phi:.9e}, rel {:.1e}), dz*/dp rel {rz:.1e}",
            rel(ea, fd_a),
            rel(ep, fd_phi)
        );
        assert!(rel(ea, fd_a) <= AGREE, "{what} {p:?}: dA/dp");
        assert!(rel(ep, fd_phi) <= AGREE, "{what} {p:?}: dφ/dp");
        assert!(rz <= AGREE, "{what} {p:?}: dz*/dp");
    }
    true
}

/// Check the first of `points` (approach points of `base`) that is neither near a fold nor
/// grazing.
pub fn check_first(base: &Params, points: &[&CurvePoint], params: &[OrbitParam], what: &str) {
    check_first_at(base, points, params, what, TOL);
}

/// [`check_first`] with the orbits and their sensitivities integrated to `tol`.
pub fn check_first_at(
    base: &Params,
    points: &[&CurvePoint],
    params: &[OrbitParam],
    what: &str,
    tol: f64,
) {
    let checked = points.iter().any(|p| {
        let b = with(base, OrbitParam::Gap, p.value);
        check_point_at(&b, &p.state, params, what, tol)
    });
    assert!(checked, "{what}: no point away from folds and grazing");
}

/// An approach from z_c = 1.2 A₀ to 0.2 A₀ in `points` points.
pub fn approach(base: Params, points: usize) -> Vec<CurvePoint> {
    let spec = approach_spec(base, 1.2, 0.2, Spacing::Points(points)).expect("spec");
    approach_retract(&spec).expect("approach").first
}

/// Which stable period-1 points of an approach a case checks (the first of them away from
/// folds and grazing, [`check_first`]).
#[derive(Debug, Clone, Copy)]
pub enum Regime {
    /// φ > 90°, A < 0.98 A_far.
    Attractive,
    /// φ < 90°, A < 0.7 A_far.
    Repulsive,
    /// A lighter touch: 0.7 A_far ≤ A < 0.99 A_far.
    LightTouch,
    /// φ < 90°, A < 0.98 A_far, in contact for a share of the period strictly between 0 and 1
    /// (a tapping orbit: it forms and breaks contact each period).
    Tapping,
}

impl Regime {
    pub fn name(self) -> &'static str {
        match self {
            Regime::Attractive => "attractive",
            Regime::Repulsive => "repulsive",
            Regime::LightTouch => "light touch",
            Regime::Tapping => "tapping",
        }
    }

    /// The stable period-1 points of `curve` in this regime, in the curve's order.
    pub fn points(self, curve: &[CurvePoint]) -> Vec<&CurvePoint> {
        let a_far = curve[0].observables.amplitude;
        curve
            .iter()
            .filter(|p| p.period == Some(1) && p.stable)
            .filter(|p| {
                let (a, phi) = (p.observables.amplitude, p.observables.phase);
                match self {
                    Regime::Attractive => phi > FRAC_PI_2 && a < 0.98 * a_far,
                    Regime::Repulsive => phi < FRAC_PI_2 && a < 0.7 * a_far,
                    Regime::LightTouch => (0.7 * a_far..0.99 * a_far).contains(&a),
                    Regime::Tapping => {
                        let c = p.observables.contact_fraction;
                        phi < FRAC_PI_2 && a < 0.98 * a_far && c > 0.0 && c < 1.0
                    }
                }
            })
            .collect()
    }
}

//! Fitting dynamic AM curves (issue 62 §1): the exact parametric sensitivities of the periodic
//! orbits and of their first harmonic (`analysis::fit::sensitivity`) against central finite
//! differences of the shooting solution, on the point mass and the N = 3 beam, Hertz and DMT,
//! attractive and repulsive points of an AM approach (the example probes
//! `examples/probe-point-mass-dmt.toml` and `examples/probe-beam-dmt.toml`).

use afmdyn::analysis::approach::{approach_retract, approach_spec};
use afmdyn::analysis::fit::sensitivity::{orbit_sensitivity, OrbitParam, OrbitSensitivity};
use afmdyn::analysis::observables::observe_orbit;
use afmdyn::analysis::shooting::{shoot, ShootingOptions};
use afmdyn::analysis::stepped::{CurvePoint, Spacing};
use afmdyn::contact::ContactLaw;
use afmdyn::integrate::{IntegratorKind, IntegratorOptions};
use afmdyn::model::CantileverModel;
use afmdyn::probe::Probe;
use afmdyn::Params;
use nalgebra::DVector;
use std::f64::consts::FRAC_PI_2;
use std::path::Path;

/// The adaptive integrator's tolerance of the sensitivities and of the finite differences.
const TOL: f64 = 1e-12;
/// The relative step of the central differences.
const STEP: f64 = 1e-3;
/// The agreement asked for (issue 62: ≤ 1e-6 relative).
const AGREE: f64 = 1e-6;

fn probe(name: &str) -> Params {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name);
    Probe::load(&path).expect("example probe").params
}

fn newton() -> ShootingOptions {
    ShootingOptions {
        tol: 1e-12,
        max_iter: 40,
    }
}

/// The model's parameters with p moved to `value`.
fn with(base: &Params, p: OrbitParam, value: f64) -> Params {
    let mut q = *base;
    match p {
        OrbitParam::Gap => q.alpha5 = value,
        OrbitParam::ContactStiffness => q.alpha4 = value,
        OrbitParam::Hamaker => match &mut q.contact_law {
            ContactLaw::Dmt { hamaker, .. } => *hamaker = value,
            _ => panic!("H̃ of a law without it"),
        },
    }
    q
}

fn value_of(base: &Params, p: OrbitParam) -> f64 {
    match p {
        OrbitParam::Gap => base.alpha5,
        OrbitParam::ContactStiffness => base.alpha4,
        OrbitParam::Hamaker => match base.contact_law {
            ContactLaw::Dmt { hamaker, .. } => hamaker,
            _ => panic!("H̃ of a law without it"),
        },
    }
}

/// The orbit at `params` near `guess`, without sensitivities.
fn orbit(params: &Params, guess: &DVector<f64>) -> OrbitSensitivity {
    let model = CantileverModel::new(params).expect("model");
    orbit_sensitivity(&model, TOL, guess, &[], &newton()).expect("orbit")
}

/// Check the exact sensitivities at the orbit near `guess` against central differences;
/// `false` (nothing checked) where the orbit is near a fold or grazing.
fn check_point(base: &Params, guess: &DVector<f64>, params: &[OrbitParam], what: &str) -> bool {
    let model = CantileverModel::new(base).expect("model");
    let exact = orbit_sensitivity(&model, TOL, guess, params, &newton()).expect("sensitivity");
    if !exact.warnings.is_empty() {
        eprintln!("{what}: skipped, {:?}", exact.warnings);
        return false;
    }
    // the amplitude of the Fourier integrals is the library's observable
    let shot = shoot(&model, &exact.state, 1, &newton()).expect("orbit");
    let opts = IntegratorOptions {
        kind: IntegratorKind::Adaptive,
        tolerance: TOL,
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
        let h = STEP * v.abs();
        // the fourth-order central difference (its truncation error O(h⁴) far below the
        // integration error's ~TOL/h)
        let at = |k: f64| orbit(&with(base, p, v + k * h), &exact.state);
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
fn check_first(base: &Params, points: &[&CurvePoint], params: &[OrbitParam], what: &str) {
    let checked = points.iter().any(|p| {
        let b = with(base, OrbitParam::Gap, p.value);
        check_point(&b, &p.state, params, what)
    });
    assert!(checked, "{what}: no point away from folds and grazing");
}

/// An approach from z_c = 1.2 A₀ to 0.2 A₀ in `points` points.
fn approach(base: Params, points: usize) -> Vec<CurvePoint> {
    let spec = approach_spec(base, 1.2, 0.2, Spacing::Points(points)).expect("spec");
    approach_retract(&spec).expect("approach").first
}

/// The attractive (φ > 90°, A < 0.98 A_far) and the repulsive (φ < 90°, A < 0.7 A_far)
/// stable period-1 points of the approach.
fn regimes(curve: &[CurvePoint]) -> (Vec<&CurvePoint>, Vec<&CurvePoint>) {
    let a_far = curve[0].observables.amplitude;
    let ok = |p: &&CurvePoint| p.period == Some(1) && p.stable;
    let attractive = curve
        .iter()
        .filter(ok)
        .filter(|p| p.observables.phase > FRAC_PI_2 && p.observables.amplitude < 0.98 * a_far)
        .collect();
    let repulsive = curve
        .iter()
        .filter(ok)
        .filter(|p| p.observables.phase < FRAC_PI_2 && p.observables.amplitude < 0.7 * a_far)
        .collect();
    (attractive, repulsive)
}

#[test]
fn point_mass_dmt_sensitivities_are_the_finite_differences() {
    let base = probe("probe-point-mass-dmt.toml");
    let curve = approach(base, 41);
    let (att, rep) = regimes(&curve);
    let ps = [
        OrbitParam::Gap,
        OrbitParam::ContactStiffness,
        OrbitParam::Hamaker,
    ];
    for (p, what) in [(att, "attractive"), (rep, "repulsive")] {
        check_first(&base, &p, &ps, &format!("point mass DMT, {what}"));
    }
}

#[test]
fn point_mass_hertz_sensitivities_are_the_finite_differences() {
    let base = Params {
        contact_law: ContactLaw::Hertz,
        ..probe("probe-point-mass-dmt.toml")
    };
    let curve = approach(base, 41);
    let (_, rep) = regimes(&curve);
    let ps = [OrbitParam::Gap, OrbitParam::ContactStiffness];
    check_first(&base, &rep, &ps, "point mass Hertz, repulsive");
    // a lighter touch: the stable points of A_far > A > 0.7 A_far
    let a_far = curve[0].observables.amplitude;
    let light: Vec<&CurvePoint> = curve
        .iter()
        .filter(|p| p.period == Some(1) && p.stable)
        .filter(|p| (0.7 * a_far..0.99 * a_far).contains(&p.observables.amplitude))
        .collect();
    check_first(&base, &light, &ps, "point mass Hertz, light touch");
}

#[test]
fn beam_dmt_sensitivities_are_the_finite_differences() {
    let base = probe("probe-beam-dmt.toml");
    let curve = approach(base, 21);
    let (att, rep) = regimes(&curve);
    let ps = [
        OrbitParam::Gap,
        OrbitParam::ContactStiffness,
        OrbitParam::Hamaker,
    ];
    for (p, what) in [(att, "attractive"), (rep, "repulsive")] {
        check_first(&base, &p, &ps, &format!("N = 3 beam DMT, {what}"));
    }
}

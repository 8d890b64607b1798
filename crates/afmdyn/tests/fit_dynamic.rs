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
const STEP: f64 = 1e-4;
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

/// Check the exact sensitivities at the orbit near `guess` against central differences.
fn check_point(base: &Params, guess: &DVector<f64>, params: &[OrbitParam], what: &str) {
    let model = CantileverModel::new(base).expect("model");
    let exact = orbit_sensitivity(&model, TOL, guess, params, &newton()).expect("sensitivity");
    assert!(
        exact.warnings.is_empty(),
        "{what}: {:?} (pick another point)",
        exact.warnings
    );
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
        let plus = orbit(&with(base, p, v + h), &exact.state);
        let minus = orbit(&with(base, p, v - h), &exact.state);
        let fd_a = (plus.amplitude - minus.amplitude) / (2.0 * h);
        let fd_phi = (plus.phase - minus.phase) / (2.0 * h);
        let fd_z = (&plus.state - &minus.state) / (2.0 * h);
        let rel = |e: f64, f: f64| (e - f).abs() / e.abs().max(f64::MIN_POSITIVE);
        let (ea, ep) = (exact.d_amplitude[j], exact.d_phase[j]);
        let ez = exact.d_state.column(j).into_owned();
        let rz = (&ez - &fd_z).norm() / ez.norm();
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
}

/// An approach from z_c = 1.2 A₀ to 0.2 A₀ in `points` points.
fn approach(base: Params, points: usize) -> Vec<CurvePoint> {
    let spec = approach_spec(base, 1.2, 0.2, Spacing::Points(points)).expect("spec");
    approach_retract(&spec).expect("approach").first
}

/// An attractive (φ > 90°, A < 0.95 A_far) and a repulsive (φ < 90°, A near 0.6 of the first
/// point's) stable period-1 point of the approach.
fn regimes(curve: &[CurvePoint]) -> (Option<&CurvePoint>, Option<&CurvePoint>) {
    let a_far = curve[0].observables.amplitude;
    let ok = |p: &&CurvePoint| p.period == Some(1) && p.stable;
    let attractive = curve
        .iter()
        .filter(ok)
        .find(|p| p.observables.phase > FRAC_PI_2 && p.observables.amplitude < 0.95 * a_far);
    let repulsive = curve.iter().filter(ok).find(|p| {
        p.observables.phase < FRAC_PI_2 && p.observables.amplitude < 0.7 * a_far
    });
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
        let p = p.unwrap_or_else(|| panic!("no {what} point"));
        let b = with(&base, OrbitParam::Gap, p.value);
        check_point(&b, &p.state, &ps, &format!("point mass DMT, {what}"));
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
    let p = rep.expect("a repulsive point");
    let ps = [OrbitParam::Gap, OrbitParam::ContactStiffness];
    let b = with(&base, OrbitParam::Gap, p.value);
    check_point(&b, &p.state, &ps, "point mass Hertz, repulsive");
    // a lighter touch: the first point in contact
    let light = curve
        .iter()
        .find(|q| q.period == Some(1) && q.stable && q.observables.amplitude < 0.98 * curve[0].observables.amplitude)
        .expect("a touching point");
    let b = with(&base, OrbitParam::Gap, light.value);
    check_point(&b, &light.state, &ps, "point mass Hertz, light touch");
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
        let p = p.unwrap_or_else(|| panic!("no {what} point"));
        let b = with(&base, OrbitParam::Gap, p.value);
        check_point(&b, &p.state, &ps, &format!("N = 3 beam DMT, {what}"));
    }
}

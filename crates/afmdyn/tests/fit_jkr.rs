//! Fitting dynamic AM curves under the JKR law (issue 62): the exact parametric sensitivities
//! of the tapping orbits to the gap α5, the Hertz group α4 and the adhesion group P̃
//! (`analysis::fit::sensitivity`, `analysis::fit::sensitivity_jkr`) against fourth-order
//! central differences of Newton-converged orbits, on the point mass
//! (`examples/probe-jkr-polymer.toml`) and the N = 3 beam (`examples/probe-beam-dmt.toml` with
//! a JKR sample); the contact forms and breaks every period there, so the force jumps at both
//! switchings and the contact guard |δ_b| − V_T moves with α4 and P̃.

use afmdyn::analysis::approach::{approach_retract, approach_spec};
use afmdyn::analysis::fit::sensitivity::{orbit_sensitivity, OrbitParam, OrbitSensitivity};
use afmdyn::analysis::observables::observe_orbit;
use afmdyn::analysis::shooting::shoot;
use afmdyn::analysis::stepped::{CurvePoint, Spacing};
use afmdyn::contact::ContactLaw;
use afmdyn::integrate::{IntegratorKind, IntegratorOptions};
use afmdyn::model::CantileverModel;
use afmdyn::probe::Probe;
use afmdyn::Params;
use nalgebra::DVector;
use std::f64::consts::FRAC_PI_2;
use std::path::Path;

mod common;
use common::orbit_params::{newton, probe, value_of, with};

/// The adaptive integrator's tolerance of the sensitivities and of the finite differences.
const TOL: f64 = 1e-12;
/// The relative step of the central differences.
const STEP: f64 = 1e-3;
/// The agreement asked for (issue 62: ≤ 1e-6 relative).
const AGREE: f64 = 1e-6;
/// The JKR parameters differentiated.
const JKR_PARAMS: &[OrbitParam] = &[
    OrbitParam::Gap,
    OrbitParam::ContactStiffness,
    OrbitParam::Adhesion,
];

/// The text of an example probe.
fn example_text(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name);
    std::fs::read_to_string(path).expect("example probe")
}

/// The example probe `name` (a DMT one) with its sample made JKR, W = 0.05 J/m² (the van der
/// Waals keys, which JKR does not read, dropped).
fn jkr_probe(name: &str) -> Probe {
    let text: String = example_text(name)
        .lines()
        .filter(|l| !l.starts_with("hamaker") && !l.starts_with("intermolecular_distance"))
        .map(|l| {
            if l.starts_with("law = ") {
                "law = \"jkr\"\nadhesion_energy = 0.05\n".to_string()
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    Probe::parse(&text, name).expect("jkr probe")
}

/// The orbit at `params` near `guess`, without sensitivities.
fn orbit(params: &Params, guess: &DVector<f64>) -> OrbitSensitivity {
    let model = CantileverModel::new(params).expect("model");
    orbit_sensitivity(&model, TOL, guess, &[], Some(&newton())).expect("orbit")
}

/// Relative difference of an exact derivative `e` and its finite difference `f` (0 when both
/// are exactly 0).
fn rel(e: f64, f: f64) -> f64 {
    if e == 0.0 && f == 0.0 {
        0.0
    } else {
        (e - f).abs() / e.abs().max(f64::MIN_POSITIVE)
    }
}

/// Check the exact sensitivities at the orbit near `guess` against fourth-order central
/// differences; `false` (nothing checked) where the orbit is near a fold, grazing, or does not
/// tap (contact for a share of the period strictly between 0 and 1).
fn check_point(base: &Params, guess: &DVector<f64>, params: &[OrbitParam], what: &str) -> bool {
    let model = CantileverModel::new(base).expect("model");
    let exact =
        orbit_sensitivity(&model, TOL, guess, params, Some(&newton())).expect("sensitivity");
    if !exact.warnings.is_empty() {
        eprintln!("{what}: skipped, {:?}", exact.warnings);
        return false;
    }
    let shot = shoot(&model, &exact.state, 1, &newton()).expect("orbit");
    let opts = IntegratorOptions {
        kind: IntegratorKind::Adaptive,
        tolerance: TOL,
        ..IntegratorOptions::default()
    };
    let obs = observe_orbit(&model, opts, &shot, 1).expect("observables");
    if !(obs.contact_fraction > 0.0 && obs.contact_fraction < 1.0) {
        eprintln!("{what}: skipped, contact fraction {}", obs.contact_fraction);
        return false;
    }
    // the Fourier integrals' harmonic is the library's observable
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
        let at = |k: f64| orbit(&with(base, p, v + k * h), &exact.state);
        let (p1, m1, p2, m2) = (at(1.0), at(-1.0), at(2.0), at(-2.0));
        let diff = |f: &dyn Fn(&OrbitSensitivity) -> f64| {
            (8.0 * (f(&p1) - f(&m1)) - (f(&p2) - f(&m2))) / (12.0 * h)
        };
        let fd_a = diff(&|o| o.amplitude);
        let fd_phi = diff(&|o| o.phase);
        let fd_z = ((&p1.state - &m1.state) * 8.0 - (&p2.state - &m2.state)) / (12.0 * h);
        let (ea, ep) = (exact.d_amplitude[j], exact.d_phase[j]);
        let ez = exact.d_state.column(j).into_owned();
        let rz = (&ez - &fd_z).norm() / ez.norm();
        eprintln!(
            "{what} {p:?} (contact fraction {:.3}): dA/dp {ea:.9e} (fd {fd_a:.9e}, rel {:.1e}), \
             dφ/dp {ep:.9e} (fd {fd_phi:.9e}, rel {:.1e}), dz*/dp rel {rz:.1e}",
            obs.contact_fraction,
            rel(ea, fd_a),
            rel(ep, fd_phi)
        );
        assert!(
            ea != 0.0 && ep != 0.0,
            "{what} {p:?}: a tapping orbit feels p"
        );
        assert!(rel(ea, fd_a) <= AGREE, "{what} {p:?}: dA/dp");
        assert!(rel(ep, fd_phi) <= AGREE, "{what} {p:?}: dφ/dp");
        assert!(rz <= AGREE, "{what} {p:?}: dz*/dp");
    }
    true
}

/// An approach from z_c = 1.2 A₀ to 0.2 A₀ in `points` points.
fn approach(base: Params, points: usize) -> Vec<CurvePoint> {
    let spec = approach_spec(base, 1.2, 0.2, Spacing::Points(points)).expect("spec");
    approach_retract(&spec).expect("approach").first
}

/// Check the first stable period-1 point of the approach of `base` whose amplitude is below
/// 0.98 of the far one and whose phase is above (`attractive`) or below 90°, that taps and is
/// away from folds and grazing.
fn check_first(base: &Params, points: usize, attractive: bool, what: &str) {
    let curve = approach(*base, points);
    let a_far = curve[0].observables.amplitude;
    let checked = curve
        .iter()
        .filter(|p| p.period == Some(1) && p.stable)
        .filter(|p| p.observables.amplitude < 0.98 * a_far)
        .filter(|p| (p.observables.phase > FRAC_PI_2) == attractive)
        .any(|p| {
            let b = with(base, OrbitParam::Gap, p.value);
            check_point(&b, &p.state, JKR_PARAMS, what)
        });
    assert!(
        checked,
        "{what}: no tapping point away from folds and grazing"
    );
}

/// ∂(A, φ, z*)/∂(α5, α4, P̃) under JKR against the fourth-order central differences
/// ([`check_point`], [`AGREE`]) on the point mass (`examples/probe-jkr-polymer.toml`) and the
/// N = 3 beam ([`jkr_probe`]), at a tapping point of each one's approach.
#[test]
fn jkr_sensitivities_are_the_finite_differences() {
    let point_mass = jkr_probe("probe-point-mass-dmt.toml").params;
    assert!(matches!(point_mass.contact_law, ContactLaw::Jkr { .. }));
    check_first(&point_mass, 41, false, "point mass JKR, repulsive");
    let beam = jkr_probe("probe-beam-dmt.toml").params;
    check_first(&beam, 21, false, "N = 3 beam JKR, repulsive");
}

/// The refusals: JKR with a Kelvin–Voigt damper (α6 > 0), H̃ of JKR, and P̃ of another law.
#[test]
fn jkr_refusals_name_the_reason() {
    let base = probe("probe-jkr-polymer.toml");
    let guess = DVector::zeros(2);
    let mut damped = base;
    damped.alpha6 = 0.01;
    let model = CantileverModel::new(&damped).expect("model");
    let e = orbit_sensitivity(&model, TOL, &guess, &[OrbitParam::Gap], None).expect_err("α6");
    assert!(e.to_string().contains("α6 = 0"), "{e}");
    let model = CantileverModel::new(&base).expect("model");
    let e = orbit_sensitivity(&model, TOL, &guess, &[OrbitParam::Hamaker], None).expect_err("H̃");
    assert!(e.to_string().contains("Hamaker"), "{e}");
    let dmt = probe("probe-point-mass-dmt.toml");
    let model = CantileverModel::new(&dmt).expect("model");
    let e = orbit_sensitivity(&model, TOL, &guess, &[OrbitParam::Adhesion], None).expect_err("P̃");
    assert!(e.to_string().contains("jkr"), "{e}");
}

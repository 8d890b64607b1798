//! Fitting dynamic AM curves under the JKR law (issue 62): the exact parametric sensitivities
//! of the tapping orbits to the gap α5, the Hertz group α4 and the adhesion group P̃
//! (`analysis::fit::sensitivity`, `analysis::fit::sensitivity_jkr`) against fourth-order
//! central differences of Newton-converged orbits, on the point mass
//! (`examples/probe-jkr-polymer.toml`) and the N = 3 beam (`examples/probe-beam-dmt.toml` with
//! a JKR sample); the contact forms and breaks every period there, so the force jumps at both
//! switchings and the contact guard |δ_b| − V_T moves with α4 and P̃.

use afmdyn::analysis::fit::am_curve::{scaled, AmCurveModel, AmParam, AmProbe};
use afmdyn::analysis::fit::sensitivity::{orbit_sensitivity, OrbitParam};
use afmdyn::contact::ContactLaw;
use afmdyn::model::CantileverModel;
use afmdyn::probe::Probe;
use afmdyn::request::fit_dynamic::am_probe;
use afmdyn::Params;
use nalgebra::DVector;
use std::path::Path;

use super::common;
use common::am_synthetic::{
    assert_recovered, door, interval, jacobian_gaps, run_fit, synthetic_of, truth,
};
use common::fm_check::check_fm_jacobian;
use common::orbit_check::{approach, check_first, Regime, AGREE, TOL};
use common::orbit_params::probe;

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
    jkr_probe_with(name, W)
}

/// [`jkr_probe`] with the work of adhesion `w` (J/m²).
fn jkr_probe_with(name: &str, w: f64) -> Probe {
    let text: String = example_text(name)
        .lines()
        .filter(|l| !l.starts_with("hamaker") && !l.starts_with("intermolecular_distance"))
        .map(|l| {
            if l.starts_with("law = ") {
                format!("law = \"jkr\"\nadhesion_energy = {w:?}\n")
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    Probe::parse(&text, name).expect("jkr probe")
}

/// Check the sensitivities to `params` at the first tapping point ([`Regime::Tapping`]) of
/// the approach of `base` in `points` points away from folds and grazing.
fn check_tapping(base: &Params, points: usize, params: &[OrbitParam], what: &str) {
    let curve = approach(*base, points);
    check_first(base, &Regime::Tapping.points(&curve), params, what);
}

/// ∂(A, φ, z*)/∂(α5, α4, P̃) under JKR against the fourth-order central differences
/// ([`check_point`], [`AGREE`]) on the point mass (`examples/probe-jkr-polymer.toml`) and the
/// N = 3 beam ([`jkr_probe`]), at a tapping point of each one's approach.
#[test]
fn jkr_sensitivities_are_the_finite_differences() {
    let point_mass = jkr_probe("probe-point-mass-dmt.toml").params;
    assert!(matches!(point_mass.contact_law, ContactLaw::Jkr { .. }));
    check_tapping(&point_mass, 41, JKR_PARAMS, "point mass JKR, tapping");
    let beam = jkr_probe("probe-beam-dmt.toml").params;
    check_tapping(&beam, 21, JKR_PARAMS, "N = 3 beam JKR, tapping");
}

/// The drive's α2 and Ω (the FM loop's unknowns; the N = 3 beam's base drive also moves V_T and
/// so the guards) under JKR, at the same points, against the same differences.
#[test]
fn jkr_drive_sensitivities_are_the_finite_differences() {
    const DRIVE: &[OrbitParam] = &[OrbitParam::DriveAmplitude, OrbitParam::DriveFrequency];
    let point_mass = jkr_probe("probe-point-mass-dmt.toml").params;
    check_tapping(&point_mass, 41, DRIVE, "point mass JKR, drive");
    let beam = jkr_probe("probe-beam-dmt.toml").params;
    check_tapping(&beam, 21, DRIVE, "N = 3 beam JKR, drive");
}

/// JKR's Kelvin–Voigt damper α6 q² δ̇ (α6 = 0.01, four times the point mass's own damping
/// 1/Q): ∂(A, φ, z*)/∂(α6, α4, P̃, α2, α5) against the fourth-order central differences at a
/// tapping point of the point mass and of the N = 3 beam (the damper's ∂F/∂q = 2α6 q δ̇ moves
/// α4's and P̃'s columns through the root q(δ); the force jumps by α6 q_c² δ̇ more where the
/// contact forms). (At α6 = 0.05 the first tapping point's amplitude is so curved in α5 that
/// the differences' step of 1e-3 is off by 6e-6 — at 1e-4 they agree within 2e-9.)
#[test]
fn damped_jkr_sensitivities_are_the_finite_differences() {
    const DAMPED: &[OrbitParam] = &[
        OrbitParam::Damping,
        OrbitParam::ContactStiffness,
        OrbitParam::Adhesion,
        OrbitParam::DriveAmplitude,
        OrbitParam::Gap,
    ];
    for (name, file, points) in [
        ("point mass JKR, damped", "probe-point-mass-dmt.toml", 41),
        ("N = 3 beam JKR, damped", "probe-beam-dmt.toml", 21),
    ] {
        let mut base = jkr_probe(file).params;
        base.alpha6 = 0.01;
        check_tapping(&base, points, DAMPED, name);
    }
}

/// The refusals: H̃ of JKR, and P̃ of another law.
#[test]
fn jkr_refusals_name_the_reason() {
    let base = probe("probe-jkr-polymer.toml");
    let guess = DVector::zeros(2);
    let model = CantileverModel::new(&base).expect("model");
    let e =
        orbit_sensitivity(&model, TOL, &guess, &[OrbitParam::Hamaker], None, None).expect_err("H̃");
    assert!(e.to_string().contains("Hamaker"), "{e}");
    let dmt = probe("probe-point-mass-dmt.toml");
    let model = CantileverModel::new(&dmt).expect("model");
    let e =
        orbit_sensitivity(&model, TOL, &guess, &[OrbitParam::Adhesion], None, None).expect_err("P̃");
    assert!(e.to_string().contains("jkr"), "{e}");
}

// ---- the dynamic fit of E, W and z_offset under JKR (`analysis::fit::am_curve`) ----

/// A probe as the dynamic fit's probe.
fn am_probe_of(p: &Probe) -> AmProbe {
    am_probe(p).expect("the fit's probe")
}

/// The work of adhesion of the JKR probes (J/m²), [`jkr_probe`]'s.
const W: f64 = 0.05;

/// The probe's W recovered from its groups ([`AmProbe::adhesion_energy`]) is the file's
/// `adhesion_energy`, and `scaled` makes P̃ = πWR/F_s: twice W, or W and R each 1.5 times,
/// give the probe's P̃ doubled and 2.25 times (the law's own `Jkr` group of a probe file with
/// those inputs, parsed independently).
#[test]
fn the_probes_work_of_adhesion_and_its_scaling() {
    for name in ["probe-point-mass-dmt.toml", "probe-beam-dmt.toml"] {
        let p = jkr_probe(name);
        assert_eq!(p.sample_inputs.adhesion_energy, Some(W));
        let probe = am_probe_of(&p);
        let w = probe.adhesion_energy();
        assert!((w - W).abs() <= 1e-12 * W, "{name}: W = {w}");
        let group = |q: &Params| match q.contact_law {
            ContactLaw::Jkr { adhesion } => adhesion,
            _ => panic!("not JKR"),
        };
        let p0 = group(&p.params);
        let (q, _, chain) = scaled(
            &probe,
            &[AmParam::AdhesionEnergy, AmParam::TipRadius],
            &[1.5 * W, 1.5 * probe.radius],
        );
        assert!(
            (group(&q) - 2.25 * p0).abs() <= 1e-12 * p0,
            "{name}: P̃ ∝ W R"
        );
        // the chain's ∂P̃/∂W = P̃/W and ∂P̃/∂R = P̃/R (P̃ linear in each)
        let term = |a: AmParam| {
            chain
                .terms
                .iter()
                .find(|(p, o, _)| *p == a && *o == OrbitParam::Adhesion)
                .map(|t| t.2)
                .expect("term")
        };
        let pq = group(&q);
        assert!((term(AmParam::AdhesionEnergy) - pq / (1.5 * W)).abs() <= 1e-12 * pq / W);
        let r = 1.5 * probe.radius;
        assert!((term(AmParam::TipRadius) - pq / r).abs() <= 1e-12 * pq / r);
        // a probe file with W doubled, parsed: its P̃ is the scaled one
        let doubled = jkr_probe_with(name, 2.0 * W);
        let (q2, _, _) = scaled(&probe, &[AmParam::AdhesionEnergy], &[2.0 * W]);
        let (a, b) = (group(&q2), group(&doubled.params));
        assert!(
            (a - b).abs() <= 1e-12 * b,
            "{name}: P̃ {a} against the file's {b}"
        );
    }
}

/// A synthetic AM approach ([`synthetic_of`]: the library's stepped approach, amplitude σ
/// 0.02 nm and phase σ 0.1°) of `rows` rows from z_c = `from` to `to` (units of A₀) under the
/// point-mass JKR probe with the truth (E, W = 0.05 J/m², z_offset = 1 nm).
fn synthetic(
    rows: usize,
    range: (f64, f64),
    params: Vec<AmParam>,
    seed: u64,
) -> (AmCurveModel, Vec<f64>, Vec<f64>, Vec<f64>) {
    let probe = am_probe_of(&jkr_probe("probe-point-mass-dmt.toml"));
    synthetic_of(probe, rows, range, params, (true, true), seed)
}

/// The AM model's Jacobian columns of E, W, z_offset and R (R's chain moves α4 ∝ √R and
/// P̃ ∝ R), and of the damped sample's η (`sample.viscosity`, α6 ∝ η √R; α6 = 0.01), against
/// central differences of its values (the stepped sweep's observables), on 12 rows of the
/// repulsive branch of the JKR approach, amplitude and phase: 1e-4 relative (the values'
/// integration error over the step 1e-4, with the values integrated at 1e-12).
#[test]
fn the_jkr_am_models_jacobian_is_its_finite_differences() {
    for alpha6 in [0.0, 0.01] {
        let mut ps = vec![
            AmParam::YoungsModulus,
            AmParam::AdhesionEnergy,
            AmParam::ZOffset,
            AmParam::TipRadius,
        ];
        let mut probe = am_probe_of(&jkr_probe("probe-point-mass-dmt.toml"));
        if alpha6 > 0.0 {
            probe.params.alpha6 = alpha6;
            ps.push(AmParam::Viscosity);
        }
        let (mut model, _, _, truth) = synthetic_of(probe, 12, (0.75, 0.3), ps, (true, true), 1);
        // the values' own integration and Newton tolerances tightened to the sensitivities':
        // at the sweep's defaults the phase rows' central differences scatter by ~1e-3
        // relative (JKR's force jumps at both switchings, located to the integrator's
        // tolerance)
        model.spec.integrator.tolerance = 1e-12;
        model.spec.newton.tol = 1e-12;
        model.tolerance = 1e-12;
        for (name, worst, phase_max) in jacobian_gaps(&model, &truth) {
            assert!(phase_max > 0.0, "α6 = {alpha6}, {name}: a zero column");
            assert!(worst < 1e-4, "α6 = {alpha6}, {name}: worst gap {worst:.2e}");
        }
    }
}

/// E, W and z_offset from a noisy synthetic JKR AM curve (100 rows of amplitude and phase on
/// the repulsive branch, z_c = 7.5 → 3 nm, made by the library's stepped approach at the
/// truth): each truth inside its 95 % interval, χ²/dof near 1.
#[test]
fn a_noisy_jkr_am_curve_gives_back_e_w_and_the_offset() {
    let ps = vec![
        AmParam::YoungsModulus,
        AmParam::AdhesionEnergy,
        AmParam::ZOffset,
    ];
    let (model, y, sigma, truth) = synthetic(100, (0.75, 0.3), ps, 62);
    // from E × 0.6, W × 1.3, z_offset 0.8 nm ([`parameters`])
    let out = run_fit(&model, &y, &sigma);
    assert_recovered(
        &out,
        &truth,
        "fit of E, W, z_offset to 100 rows",
        None,
        0.5..2.0,
    );
}

// ---- through the door (`afmdyn fit`'s request) ----

/// Through the door with the default parameters of a JKR probe (E, W and z_offset,
/// `fitted_names`), started from the probe's values (z_offset from its grid): each truth of the
/// synthetic curve inside its 95 % interval, χ²/dof near 1, W in J/m^2.
#[test]
fn the_door_fits_e_w_and_the_offset_of_a_jkr_sample_by_default() {
    let ps = vec![
        AmParam::YoungsModulus,
        AmParam::AdhesionEnergy,
        AmParam::ZOffset,
    ];
    let (model, y, sigma, truth) = synthetic(100, (0.75, 0.3), ps, 62);
    let p = jkr_probe("probe-point-mass-dmt.toml");
    let doc = door(p, &model, &y, &sigma, &[], "fit-jkr").expect("fit");
    assert_eq!(doc["law"], "jkr");
    assert_eq!(doc["units"]["sample.adhesion_energy"], "J/m^2");
    let chi2_dof = doc["chi2_dof"].as_f64().unwrap();
    assert!(chi2_dof < 1.5, "χ²/dof = {chi2_dof}: {}", doc["warnings"]);
    let names = [
        "sample.youngs_modulus",
        "sample.adhesion_energy",
        "z_offset",
    ];
    assert_eq!(
        doc["estimates"].as_object().map(|o| o.len()),
        Some(names.len()),
        "{}",
        doc["estimates"]
    );
    for (name, t) in names.iter().zip(&truth) {
        let [lo, hi] = interval(&doc, name);
        eprintln!("{name}: [{lo:.6e}, {hi:.6e}] (truth {t:.6e})");
        assert!(
            lo <= *t && *t <= hi,
            "{name}: truth {t} outside [{lo}, {hi}]"
        );
    }
}

/// The door's refusals: `sample.adhesion_energy` under DMT, a name it does not know (the
/// error lists `sample.adhesion_energy (jkr)`) and `sample.hamaker` under JKR.
#[test]
fn the_door_refuses_what_jkr_does_not_take() {
    let (model, y, sigma, _) = synthetic(8, (0.75, 0.3), vec![AmParam::ZOffset], 5);
    let dmt = Probe::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/probe-point-mass-dmt.toml"),
    )
    .expect("probe");
    let err = |p: Probe, fit: &[&str], tag: &str| {
        door(p, &model, &y, &sigma, fit, tag)
            .expect_err("refused")
            .to_string()
    };
    let e = err(dmt, &["sample.adhesion_energy"], "jkr-dmt");
    assert!(e.contains("jkr law's work of adhesion"), "{e}");
    let jkr = || jkr_probe("probe-point-mass-dmt.toml");
    let e = err(jkr(), &["sample.surface_energy"], "jkr-name");
    assert!(e.contains("sample.adhesion_energy (jkr)"), "{e}");
    let e = err(jkr(), &["sample.hamaker"], "jkr-hamaker");
    assert!(e.contains("DMT's"), "{e}");
}

// ---- the FM model under JKR (`analysis::fit::fm_curve`) ----

/// The Δf model's Jacobian columns of E, W and z_offset under JKR (the point mass), 4 rows
/// with z_c from 0.95 to 0.75 A₀ (the loop holding A₀: tapping), against fourth-order central
/// differences of its values (each the library's FM loop, to 1e-12): the FM model maps the
/// orbit's sensitivities to P̃ through the same chain ([`scaled`]).
#[test]
fn the_jkr_fm_models_jacobian_is_its_finite_differences() {
    use afmdyn::analysis::fit::fm_curve::FmCurveModel;
    let p = jkr_probe("probe-point-mass-dmt.toml");
    let hz = p.scales.frequency_hz(1.0);
    let probe = am_probe_of(&p);
    let params = vec![
        AmParam::YoungsModulus,
        AmParam::AdhesionEnergy,
        AmParam::ZOffset,
    ];
    let g0 = probe.length_m;
    let z: Vec<f64> = (0..4)
        .map(|i| g0 * (0.95 - 0.2 * i as f64 / 3.0) - 1e-9)
        .collect();
    let mut model = FmCurveModel::new(probe, z, params.clone(), hz);
    model.loop_tolerance = 1e-12;
    let truth = truth(&probe, &params, 1e-9);
    check_fm_jacobian(&model, &truth, "point mass JKR", AGREE, &[]);
}

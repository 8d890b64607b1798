//! DMT's Kelvin–Voigt viscosity η (`sample.viscosity`, Pa s) in the dynamic fit (issue 62 §1):
//! the orbit's column of α6 (∂F_c/∂α6 = √δ δ̇ in contact) and the other columns of a damped DMT
//! sample, whose ∂F_c/∂δ = (3/2)α4√δ + α6 δ̇/(2√δ) is unbounded at contact onset (an integrable
//! singularity), against fourth-order central differences of Newton-converged orbits on the
//! point mass and the N = 3 beam; the AM and FM models' Jacobian columns against central
//! differences of their values; noisy synthetic curves fitted back, on the library's
//! RTESPA-300 over polystyrene (η = 10 Pa s) through the door too; the refusals.

use afmdyn::analysis::fit::am_curve::{AmParam, AmProbe};
use afmdyn::analysis::fit::fm_curve::FmCurveModel;
use afmdyn::analysis::fit::sensitivity::OrbitParam;
use afmdyn::probe::Probe;
use afmdyn::request::fit_dynamic::am_probe;
use std::path::Path;

use super::common;
use common::am_synthetic::{
    assert_recovered, door, interval, jacobian_gaps, run_fit, synthetic_of, truth,
};
use common::fm_check::check_fm_jacobian;
use common::orbit_check::{approach, check_first_at, Regime};
use common::orbit_params::probe;

/// The Kelvin–Voigt group of the damped cases: α6 = 0.05, twenty times the point mass's own
/// damping 1/Q = 0.0025 (at δ ~ 0.01 and δ̇ ~ 1 a dissipative force of 5e-3, a tenth of the
/// Hertz force there).
const KV_ALPHA6: f64 = 0.05;

/// The integration tolerance of these checks: the variational equations converge at a reduced
/// order through the onset's singularity (α6's column within 2e-7 at 1e-11, 6e-6 at 1e-9), and
/// the adaptive integrator cannot pass the onset at 1e-12.
const KV_TOL: f64 = 1e-11;

/// The α6 column with the gap's, α4's and H̃'s.
const KV_PARAMS: &[OrbitParam] = &[
    OrbitParam::Damping,
    OrbitParam::Gap,
    OrbitParam::ContactStiffness,
    OrbitParam::Hamaker,
];

/// ∂(A, φ, z*)/∂(α6, α5, α4, H̃) of a damped DMT sample (α6 = 0.05) against the fourth-order
/// central differences (≤ 1e-6 relative), at the first repulsive point of the point mass's and
/// the N = 3 beam's approach away from folds and grazing, both at [`KV_TOL`].
#[test]
fn kelvin_voigt_sensitivities_are_the_finite_differences() {
    for (name, file, points) in [
        ("point mass DMT, η > 0", "probe-point-mass-dmt.toml", 41),
        ("N = 3 beam DMT, η > 0", "probe-beam-dmt.toml", 21),
    ] {
        let mut base = probe(file);
        base.alpha6 = KV_ALPHA6;
        let curve = approach(base, points);
        let points = Regime::Repulsive.points(&curve);
        check_first_at(&base, &points, KV_PARAMS, name, KV_TOL);
    }
}

/// The library's RTESPA-300 over polystyrene (`examples/probe-rtespa300-polystyrene.toml`:
/// k = 40 N/m, 300 kHz, Q = 500, A₀ = 15 nm, DMT with E = 2.5 GPa, H = 6.6e-20 J and
/// η = 10 Pa s) as the fit's probe, with the probe itself.
fn rtespa() -> (AmProbe, Probe) {
    let p = Probe::load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples/probe-rtespa300-polystyrene.toml"),
    )
    .expect("probe");
    (am_probe(&p).expect("fit probe"), p)
}

/// The probe's η (Pa s) read back from its α6 is the file's 10 Pa s, and the AM model's
/// Jacobian columns of η, E, z_offset and R (R's chain moves α4 ∝ √R, H̃ ∝ R and α6 ∝ √R)
/// against central differences of its values, 12 rows of the RTESPA-300's repulsive approach
/// (z_c = 0.75 → 0.3 A₀), amplitude and phase: 1e-3 relative (the sensitivities at the fit's
/// tolerance 1e-9).
#[test]
fn the_am_models_viscosity_column_is_its_finite_differences() {
    let (probe, _) = rtespa();
    assert!(
        (probe.viscosity() / 10.0 - 1.0).abs() < 1e-12,
        "η = {}",
        probe.viscosity()
    );
    let ps = vec![
        AmParam::Viscosity,
        AmParam::YoungsModulus,
        AmParam::ZOffset,
        AmParam::TipRadius,
    ];
    let (model, _, _, truth) = synthetic_of(probe, 12, (0.75, 0.3), ps, (true, true), 1);
    for (name, worst, phase_max) in jacobian_gaps(&model, &truth) {
        assert!(phase_max > 0.0, "{name}: no phase sensitivity");
        assert!(worst < 1e-3, "{name}: worst relative gap {worst:.2e}");
    }
}

/// The FM model's Jacobian column of η (with E and z_offset) against fourth-order central
/// differences of its Δf (each the library's FM loop, to 1e-12), on 4 rows of the point mass as
/// a damped DMT sample (α6 = 0.05) from the attractive regime into contact (z_c = 1.0 → 0.85
/// A₀): 1e-4 relative (the loop's noise over the steps), or 1e-3 of the column's largest where
/// an entry is smaller.
#[test]
fn the_fm_models_viscosity_column_is_its_finite_differences() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/probe-point-mass-dmt.toml");
    let p = Probe::load(&path).expect("probe");
    let mut probe = am_probe(&p).expect("fit probe");
    probe.params.alpha6 = KV_ALPHA6;
    let hz = p.scales.frequency_hz(1.0);
    let g0 = probe.length_m;
    let z: Vec<f64> = (0..4)
        .map(|i| g0 * (1.0 - 0.05 * i as f64) - 1e-9)
        .collect();
    let params = vec![AmParam::Viscosity, AmParam::YoungsModulus, AmParam::ZOffset];
    let mut model = FmCurveModel::new(probe, z, params.clone(), hz);
    model.loop_tolerance = 1e-12;
    model.tolerance = KV_TOL;
    let t = truth(&probe, &params, 1e-9);
    // E's step 2e-3 (at E ± 2 % the deepest row's loop does not converge)
    check_fm_jacobian(
        &model,
        &t,
        "point mass DMT, η > 0",
        1e-4,
        &[(AmParam::YoungsModulus, 2e-3)],
    );
}

/// A noisy synthetic AM curve of the RTESPA-300 over polystyrene (100 rows z_c = 0.75 → 0.3 A₀,
/// amplitude σ 0.02 nm and phase σ 0.1°, made by the library's stepped approach at the probe's
/// η = 10 Pa s, E = 2.5 GPa and z_offset = 1 nm) fitted for η, E and z_offset from η × 0.7 and
/// E × 0.6: each comes back inside its 95 % interval at χ²/dof near 1.
#[test]
fn a_noisy_am_curve_gives_back_the_viscosity() {
    let ps = vec![AmParam::Viscosity, AmParam::YoungsModulus, AmParam::ZOffset];
    let (probe, _) = rtespa();
    let (model, y, sigma, truth) = synthetic_of(probe, 100, (0.75, 0.3), ps, (true, true), 7);
    let out = run_fit(&model, &y, &sigma);
    assert_recovered(&out, &truth, "η", None, 0.5..2.0);
}

/// Through the door (`afmdyn fit`'s request) on the RTESPA-300 over polystyrene: η, E and
/// z_offset by their probe names come back inside their intervals from the probe's starts
/// (z_offset from its grid), η in Pa s; `sample.viscosity` is refused on a Hertz probe naming
/// `sample.damping`, and `sample.damping` on the DMT probe naming `sample.viscosity`.
#[test]
fn the_door_fits_the_viscosity_of_a_dmt_sample() {
    let ps = vec![AmParam::Viscosity, AmParam::YoungsModulus, AmParam::ZOffset];
    let (probe, p) = rtespa();
    let (model, y, sigma, truth) = synthetic_of(probe, 60, (0.75, 0.3), ps, (true, true), 3);
    let names = ["sample.viscosity", "sample.youngs_modulus", "z_offset"];
    let doc = door(p.clone(), &model, &y, &sigma, &names, "fit-viscosity").expect("fit");
    let chi2_dof = doc["chi2_dof"].as_f64().unwrap();
    assert!(chi2_dof < 1.5, "χ²/dof = {chi2_dof}: {}", doc["warnings"]);
    for (name, t) in names.iter().zip(&truth) {
        let [lo, hi] = interval(&doc, name);
        eprintln!("{name}: [{lo:.6e}, {hi:.6e}] (truth {t:.6e})");
        assert!(lo <= *t && *t <= hi, "{name}: {t} outside [{lo}, {hi}]");
    }
    assert_eq!(doc["units"]["sample.viscosity"], "Pa s");
    let e = door(
        p,
        &model,
        &y,
        &sigma,
        &["sample.damping"],
        "fit-visc-refused",
    )
    .expect_err("refused")
    .to_string();
    assert!(e.contains("sample.viscosity"), "{e}");
    let hertz = Probe::parse(
        "model = \"point-mass\"\n[cantilever]\nname = \"RTESPA-300\"\n[tip]\nradius = 8e-9\n\
         [sample]\nlaw = \"hertz\"\nyoungs_modulus = 2.5e9\npoisson_ratio = 0.33\n[drive]\n\
         free_amplitude = 15e-9\n",
        "rtespa-hertz",
    )
    .expect("probe");
    let e = door(
        hertz,
        &model,
        &y,
        &sigma,
        &["sample.viscosity"],
        "fit-visc-hertz",
    )
    .expect_err("refused")
    .to_string();
    assert!(e.contains("sample.damping"), "{e}");
}

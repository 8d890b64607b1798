//! The lever's quality factor Q₁ (`cantilever.quality_factor`) and the free amplitude A₀
//! (`drive.free_amplitude`) in the dynamic fit (issue 62 §1): the orbit's column of the
//! lever's damping α3 against central differences of Newton-converged orbits on the point
//! mass and the N = 3 beam; the free response's dH/dα3 against its differences and the
//! probe's defining identity α2 |H| = A₀/g₀; the drive following Q₁ so that the free
//! amplitude stays the one the instrument set; the AM and FM models' Jacobian columns against
//! central differences of their values; noisy synthetic curves fitted back; the refusals.

use afmdyn::analysis::fit::am_curve::{AmCurveModel, AmParam};
use afmdyn::analysis::fit::fm_curve::FmCurveModel;
use afmdyn::analysis::fit::sensitivity::OrbitParam;
use afmdyn::analysis::fit::CurveModel;
use afmdyn::contact::ContactLaw;
use afmdyn::model::CantileverModel;
use afmdyn::probe::Probe;
use std::path::Path;

use super::common;
use common::am_synthetic::{
    am_probe, assert_recovered, door, interval, jacobian_gaps, run_fit, synthetic, synthetic_of,
};
use common::orbit_check::{approach, check_first, Regime};
use common::orbit_params::probe;

/// The lever's damping with the drive and the gap: α3's column, α2's beside it (Q₁'s chain
/// goes through both) and α5's as a reference.
const LEVER: &[OrbitParam] = &[
    OrbitParam::LeverDamping,
    OrbitParam::DriveAmplitude,
    OrbitParam::Gap,
];

/// ∂(A, φ, z*)/∂α3 against the fourth-order central differences (≤ 1e-6 relative,
/// [`check_first`]) on the point mass (DMT attractive and repulsive, and Hertz with the damper
/// α6 = 0.05, whose force jumps at each switching) and the N = 3 beam (DMT repulsive, its
/// base drive carrying α3 in the forcing's base-velocity term, eq. 14).
#[test]
fn lever_damping_sensitivities_are_the_finite_differences() {
    // (name, probe, the Hertz damper α6 if any, approach points, regimes)
    type Case = (
        &'static str,
        &'static str,
        Option<f64>,
        usize,
        &'static [Regime],
    );
    let cases: [Case; 3] = [
        (
            "point mass DMT",
            "probe-point-mass-dmt.toml",
            None,
            41,
            &[Regime::Attractive, Regime::Repulsive],
        ),
        (
            "point mass Hertz, damped",
            "probe-point-mass-dmt.toml",
            Some(0.05),
            41,
            &[Regime::Repulsive],
        ),
        (
            "N = 3 beam DMT",
            "probe-beam-dmt.toml",
            None,
            21,
            &[Regime::Repulsive],
        ),
    ];
    for (name, file, damper, points, regimes) in cases {
        let mut base = probe(file);
        if let Some(a6) = damper {
            base.contact_law = ContactLaw::Hertz;
            base.alpha6 = a6;
        }
        let curve = approach(base, points);
        for &r in regimes {
            let what = format!("{name}, {}", r.name());
            check_first(&base, &r.points(&curve), LEVER, &what);
        }
    }
}

/// On a bimodal drive: the primary drive's α2 (its further component's force does not move
/// with α2), the further component's force F̃₁ (its column M⁻¹φ cos(ω₁τ + θ₁)) and α3:
/// ∂(A₁, φ₁)/∂p against the differences, which Q₁'s and A₀'s chains use on bimodal curves.
#[test]
fn the_bimodal_drives_sensitivities_are_the_finite_differences() {
    let base = probe("probe-bimodal.toml");
    let curve = approach(base, 21);
    let points = Regime::Repulsive.points(&curve);
    check_first(
        &base,
        &points,
        &[
            OrbitParam::DriveAmplitude,
            OrbitParam::ComponentForce,
            OrbitParam::LeverDamping,
            OrbitParam::Gap,
        ],
        "bimodal DMT, repulsive",
    );
}

/// The free response's dH/dα3 (`free_tip_response_damping_derivative`) against the
/// fourth-order central differences of H (≤ 1e-8 relative), and the probe's defining
/// identity: |H| = 1 at the probe's α2 (the free amplitude A₀ is the length unit g₀), on the
/// point mass, the
/// N = 3 beam and the bimodal eigenmode model.
#[test]
fn the_free_responses_damping_derivative_is_its_finite_difference() {
    for file in [
        "probe-point-mass-dmt.toml",
        "probe-beam-dmt.toml",
        "probe-bimodal.toml",
    ] {
        let base = probe(file);
        let model = CantileverModel::new(&base).expect("model");
        let (h, dh) = model
            .free_tip_response_damping_derivative()
            .expect("response");
        assert_eq!(h, model.free_tip_response().expect("response"), "{file}");
        assert!((h.norm() - 1.0).abs() < 1e-12, "{file}: |H| = {}", h.norm());
        let step = 1e-3 * base.alpha3;
        let at = |k: f64| {
            let mut q = base;
            q.alpha3 += k * step;
            CantileverModel::new(&q)
                .expect("model")
                .free_tip_response()
                .expect("response")
        };
        let fd = ((at(1.0) - at(-1.0)) * 8.0 - (at(2.0) - at(-2.0))) / (12.0 * step);
        let rel = (dh - fd).norm() / dh.norm();
        eprintln!("{file}: dH/dα3 = {dh:.9e} (fd {fd:.9e}, rel {rel:.1e})");
        assert!(rel < 1e-8, "{file}: rel {rel:e}");
    }
}

/// The AM model's rows far from the sample (z_c = 3 → 2.5 A₀, no contact) are the free
/// amplitude the instrument set, whatever Q₁: the drive α2 follows Q₁ (α2 = (A₀/g₀)/|H₁|). At
/// Q₁ × 1.3 and Q₁ × 0.7 the amplitude stays A₀ to the integration's 1e-6, and A₀ × 1.1 gives
/// 1.1 A₀; the drive of the unchanged probe is not touched (bit for bit).
#[test]
fn the_free_amplitude_is_held_whatever_the_quality_factor() {
    let probe = am_probe("probe-point-mass-dmt.toml");
    let g0 = probe.length_m;
    let z: Vec<f64> = (0..4).map(|i| g0 * (3.0 - 0.15 * i as f64)).collect();
    let params = vec![AmParam::QualityFactor, AmParam::FreeAmplitude];
    let model = AmCurveModel::new(probe, z, (true, false), params);
    let q = probe.quality_factor;
    for (q1, a0) in [(q, g0), (1.3 * q, g0), (0.7 * q, g0), (q, 1.1 * g0)] {
        let mut v = vec![0.0; model.points()];
        model.evaluate(&[q1, a0], &mut v, None);
        for a in &v {
            assert!(
                (a / a0 - 1.0).abs() < 1e-6,
                "Q = {q1}, A₀ = {a0:e}: a free row's amplitude {a:e}"
            );
        }
    }
    let (same, _, _) = afmdyn::analysis::fit::am_curve::scaled(&probe, &[AmParam::ZOffset], &[0.0]);
    assert_eq!(same.alpha2, probe.params.alpha2);
}

/// The AM model's Jacobian columns of Q₁ and A₀, with E and z_offset, against central
/// differences of its values (the stepped sweep's observables), 12 rows of amplitude and
/// phase on the point mass's repulsive branch and on the N = 3 beam's: 1e-3 relative, as the
/// other parameters' (`fit_dynamic.rs`).
#[test]
fn the_am_models_q_and_a0_columns_are_its_finite_differences() {
    let ps = vec![
        AmParam::QualityFactor,
        AmParam::FreeAmplitude,
        AmParam::YoungsModulus,
        AmParam::ZOffset,
    ];
    for file in ["probe-point-mass-dmt.toml", "probe-beam-dmt.toml"] {
        let (model, _, _, truth) = synthetic(file, 12, (0.75, 0.3), ps.clone(), (true, true), 1);
        for (name, worst, phase_max) in jacobian_gaps(&model, &truth) {
            assert!(phase_max > 0.0, "{file} {name}: no phase sensitivity");
            assert!(
                worst < 1e-3,
                "{file} {name}: worst relative gap {worst:.2e}"
            );
        }
    }
}

/// Q₁ on an FM curve is refused with the reason (the FM model's A₀ column is checked in
/// `fit_fm.rs`).
#[test]
fn the_fm_model_refuses_the_quality_factor() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/probe-point-mass-dmt.toml");
    let p = Probe::load(&path).expect("probe");
    let probe = afmdyn::request::fit_dynamic::am_probe(&p).expect("fit probe");
    let z = vec![probe.length_m; 4];
    let hz = p.scales.frequency_hz(1.0);
    let refused = FmCurveModel::new(probe, z, vec![AmParam::QualityFactor], hz);
    let mut out = vec![0.0; refused.points()];
    refused.evaluate(&[probe.quality_factor], &mut out, None);
    assert!(out.iter().all(|x| x.is_nan()));
    let w = refused.warnings().join("; ");
    assert!(w.contains("does not constrain Q"), "{w}");
}

/// The point-mass example as a Hertz sample (no Hamaker attraction): one branch from the free
/// lever to the repulsive contact, without the bistable range where a start off the truth
/// makes the model's rows jump at another row than the data's (a local minimum).
fn hertz_probe() -> afmdyn::analysis::fit::am_curve::AmProbe {
    let mut probe = am_probe("probe-point-mass-dmt.toml");
    probe.params.contact_law = ContactLaw::Hertz;
    probe.hamaker = 0.0;
    probe
}

/// Q₁ and E from one AM curve at resonance are not identifiable: the first harmonic's balance
/// at ω = ω₀ gives the virial V_ts = −(k A A₀/(2Q₁)) cos φ and the dissipated energy
/// E_dis = (πkA/Q₁)(A₀ sin φ − A) (Lozano & García, *Phys. Rev. Lett.* 100 (2008) 076102), so
/// amplitude and phase fix Q₁ V_ts and Q₁ E_dis; at a fixed indentation V_ts ∝ E*, so E × λ
/// with Q₁/λ makes the same curve. Fitting Q₁, E and z_offset on a noisy Hertz curve (100
/// rows z_c = 1.1 → 0.5 A₀) warns that they are correlated beyond 0.99.
#[test]
fn q_and_e_from_an_am_curve_at_resonance_are_not_identifiable() {
    let ps = vec![
        AmParam::QualityFactor,
        AmParam::YoungsModulus,
        AmParam::ZOffset,
    ];
    let (model, y, sigma, _) = synthetic_of(hertz_probe(), 100, (1.1, 0.5), ps, (true, true), 11);
    let out = run_fit(&model, &y, &sigma);
    let warnings = out.warnings.join("; ");
    eprintln!("χ²/dof {:.3}: {warnings}", out.chi2_dof);
    assert!(
        warnings.contains("cantilever.quality_factor and sample.youngs_modulus are correlated"),
        "{warnings}"
    );
}

/// On a sample of known E (held), Q₁ is identified: a noisy synthetic AM curve of a Hertz
/// sample ([`hertz_probe`]; 100 rows from z_c = 1.1 A₀, where the lever is free, to 0.5 A₀;
/// amplitude σ 0.02 nm and phase σ 0.1°; made by the library's stepped approach at the probe's
/// Q₁ = 400 and z_offset = 1 nm) fitted for Q₁ and z_offset from Q₁ × 0.8: both come back
/// inside their 95 % intervals at χ²/dof near 1, Q₁ to a few per cent.
#[test]
fn a_noisy_am_curve_on_a_known_sample_gives_back_the_quality_factor() {
    let ps = vec![AmParam::QualityFactor, AmParam::ZOffset];
    let (model, y, sigma, truth) =
        synthetic_of(hertz_probe(), 100, (1.1, 0.5), ps, (true, true), 11);
    let out = run_fit(&model, &y, &sigma);
    assert_recovered(&out, &truth, "Q", Some(0.1), 0.5..2.0);
}

/// A noisy synthetic AM curve of a Hertz sample fitted for A₀, E and z_offset from A₀ × 0.95: the free rows pin
/// A₀, which comes back inside its interval.
#[test]
fn a_noisy_am_curve_gives_back_the_free_amplitude() {
    let ps = vec![
        AmParam::FreeAmplitude,
        AmParam::YoungsModulus,
        AmParam::ZOffset,
    ];
    let (model, y, sigma, truth) = synthetic_of(hertz_probe(), 60, (1.1, 0.5), ps, (true, true), 5);
    let out = run_fit(&model, &y, &sigma);
    for (e, t) in out.estimates.iter().zip(&truth) {
        eprintln!(
            "{}: {:.6e} ± {:.3e} (truth {t:.6e})",
            e.name, e.value, e.standard_error
        );
        assert!(
            (e.interval[0]..=e.interval[1]).contains(t),
            "{}: the interval misses the truth",
            e.name
        );
    }
    assert!(
        (0.5..2.0).contains(&out.chi2_dof),
        "χ²/dof {}",
        out.chi2_dof
    );
}

/// Through the door (`afmdyn fit`'s request): `cantilever.quality_factor` and
/// `drive.free_amplitude` by their probe names come back inside their intervals from the
/// probe's starts, with their units in the document; Q₁ is refused on a probe in a medium,
/// naming why.
#[test]
fn the_door_fits_q_and_a0_and_refuses_q_where_it_does_not_hold() {
    let ps = vec![AmParam::QualityFactor, AmParam::ZOffset];
    let (model, y, sigma, truth) = synthetic(
        "probe-point-mass-dmt.toml",
        60,
        (1.1, 0.5),
        ps,
        (true, true),
        11,
    );
    let load = |name: &str| {
        Probe::load(
            &Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../examples")
                .join(name),
        )
        .expect("probe")
    };
    let names = ["cantilever.quality_factor", "z_offset"];
    let doc = door(
        load("probe-point-mass-dmt.toml"),
        &model,
        &y,
        &sigma,
        &names,
        "fit-q",
    )
    .expect("fit");
    for (name, t) in names.iter().zip(&truth) {
        let [lo, hi] = interval(&doc, name);
        assert!(lo <= *t && *t <= hi, "{name}: {t} outside [{lo}, {hi}]");
    }
    assert_eq!(doc["units"]["cantilever.quality_factor"], "1");
    assert_eq!(doc["units"]["drive.free_amplitude"], "m");
    // the water probe (its Kelvin–Voigt DMT sample fitted as any other)
    let e = door(
        load("probe-water-beam.toml"),
        &model,
        &y,
        &sigma,
        &["cantilever.quality_factor"],
        "fit-q-refused",
    )
    .expect_err("refused")
    .to_string();
    assert!(e.contains("[medium]"), "{e}");
}

/// The library's RTESPA-300 (k = 40 N/m, 300 kHz, A₀ = 15 nm) on a Hertz polystyrene
/// (E = 2.5 GPa) with the quality factor `q`, as the fit's probe.
fn rtespa(q: f64) -> afmdyn::analysis::fit::am_curve::AmProbe {
    let text = format!(
        "model = \"point-mass\"\n[cantilever]\nname = \"RTESPA-300\"\nquality_factor = {q:?}\n\
         [tip]\nradius = 8e-9\n[sample]\nlaw = \"hertz\"\nyoungs_modulus = 2.5e9\n\
         poisson_ratio = 0.33\n[drive]\nfree_amplitude = 15e-9\n"
    );
    let p = Probe::parse(&text, "rtespa-300").expect("probe");
    afmdyn::request::fit_dynamic::am_probe(&p).expect("fit probe")
}

/// A lever driven at its resonance has multipliers within ~π/Q of +1 without a fold: the fold
/// threshold is a fifth of the free lever's min |1 − e^{λT}| when that is below `FOLD_TOL`
/// (1e-3). In vacuum (the RTESPA-300 at Q = 20 000) it is 0.2 (1 − e^{−π/Q}) to 1e-3, at
/// Q = 500 `FOLD_TOL` itself; and the AM model of 12 rows from the free lever into contact
/// (z_c = 1.1 → 0.6 A₀) evaluates without a near-fold warning, its Q₁ and z_offset columns
/// its central differences.
#[test]
fn a_vacuum_levers_free_rows_are_not_folds() {
    use afmdyn::analysis::fit::sensitivity::{fold_threshold, FOLD_TOL};
    for q in [500.0, 20_000.0] {
        let probe = rtespa(q);
        let model = CantileverModel::new(&probe.params).expect("model");
        let t = afmdyn::system::HybridSystem::period(&model);
        let got = fold_threshold(&model, t);
        let expected = FOLD_TOL.min(0.2 * (1.0 - (-std::f64::consts::PI / q).exp()));
        eprintln!("Q = {q}: fold threshold {got:.4e} (expected {expected:.4e})");
        assert!((got / expected - 1.0).abs() < 1e-3, "Q = {q}: {got:e}");
    }
    let ps = vec![AmParam::QualityFactor, AmParam::ZOffset];
    let (model, _, _, truth) = synthetic_of(rtespa(20_000.0), 12, (1.1, 0.6), ps, (true, true), 2);
    // 1e-2: the free rows feel Q₁ not at all, and their differences are the values'
    // integration noise (2e-20 m per unit Q₁ over the step of 2, 5e-12 of A₀) against the
    // contact rows' 3e-15 m; those agree within 2e-4
    for (name, worst, _) in jacobian_gaps(&model, &truth) {
        assert!(worst < 1e-2, "{name}: worst relative gap {worst:.2e}");
    }
    assert!(model.warnings().is_empty(), "{:?}", model.warnings());
}

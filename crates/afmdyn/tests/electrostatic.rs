//! The electrostatic law (`--contact-law electrostatic`, probe `law = "electrostatic"`): DMT
//! plus the force of a biased spherical tip over a conducting plane, F_es = −πε₀V²R²/(d(d + R))
//! (Hudlet, Saint Jean, Guthmann & Berger, *Eur. Phys. J. B* 2 (1998) 5), checked through the
//! probe's SI mapping and the FM-AFM analysis:
//!
//! * the probe's groups give back the SI force at any distance;
//! * the frequency shift of a small oscillation is −f₀F′(d)/(2k) with the SI force gradient of
//!   van der Waals plus the biased sphere (Giessibl, *Rev. Mod. Phys.* 75 (2003) 949, eq. 15);
//! * at fixed distance the shift is a parabola in the bias with its vertex at the contact
//!   potential difference, as Kelvin probe force microscopy uses it (Nonnenmacher, O'Boyle &
//!   Wickramasinghe, *Appl. Phys. Lett.* 58 (1991) 2921): symmetric about V_cpd, equal to the
//!   unbiased DMT shift there.

use afmdyn::analysis::fm::{fm_curve, FmSpec};
use afmdyn::analysis::progress::Progress;
use afmdyn::contact::TipSample;
use afmdyn::probe::{Probe, VACUUM_PERMITTIVITY};
use afmdyn::ContactLaw;
use std::f64::consts::PI;

/// k (N/m), f₀ (Hz), the tip radius R (m) and the Hamaker constant H (J).
const K: f64 = 40.0;
const F0: f64 = 300e3;
const R: f64 = 10e-9;
const H: f64 = 6.6e-20;

/// A stiff lever (k = 40 N/m, f₀ = 300 kHz, Q = 10⁴) with a 10 nm tip over polystyrene, at the
/// bias `bias` (V) against a contact potential difference of 0.5 V; A₀ = 10 nm.
fn probe(bias: f64) -> Probe {
    let text = format!(
        "model = \"point-mass\"\n[cantilever]\nspring_constant = {K}\nresonance_frequency = {F0}\n\
         quality_factor = 1e4\n[tip]\nradius = {R}\n[sample]\nlaw = \"electrostatic\"\n\
         youngs_modulus = 4e9\npoisson_ratio = 0.33\nhamaker = {H}\nbias_voltage = {bias}\n\
         contact_potential = 0.5\nz_c = 20e-9\n[drive]\nfree_amplitude = 10e-9\n"
    );
    Probe::parse(&text, "<test>").unwrap_or_else(|e| panic!("{e}"))
}

/// The SI force (N) at tip–sample distance d (m): −HR/(6d²) − πε₀V²R²/(d(d + R)).
fn force_si(d: f64, v: f64) -> f64 {
    -H * R / (6.0 * d * d) - PI * VACUUM_PERMITTIVITY * v * v * R * R / (d * (d + R))
}

/// The probe's dimensionless groups reproduce the SI force from 0.5 nm to 100 nm.
#[test]
fn the_probe_groups_give_back_the_si_force() {
    let p = probe(3.0);
    let law = TipSample {
        law: p.params.contact_law,
        stiffness: p.params.alpha4,
        damping: p.params.alpha6,
    };
    assert!(matches!(
        p.params.contact_law,
        ContactLaw::Electrostatic { .. }
    ));
    let (g0, f_unit) = (p.scales.length_m, p.scales.force_n);
    for d in [0.5e-9, 2e-9, 10e-9, 100e-9] {
        let got = law.long_range(d / g0)[0] * f_unit;
        let want = force_si(d, 2.5);
        assert!((got / want - 1.0).abs() < 1e-12, "d = {d}: {got} vs {want}");
    }
}

/// The frequency shift (Hz) of a 0.05 nm oscillation at the rest distances `z_c` (m).
fn shifts(bias: f64, z_c: &[f64]) -> Vec<(f64, f64)> {
    let p = probe(bias);
    let g0 = p.scales.length_m;
    let gaps: Vec<f64> = z_c
        .iter()
        .map(|z| p.params.alpha5_for_rest_distance(z / g0))
        .collect();
    let curve = fm_curve(&FmSpec::new(p.params, gaps, 0.05e-9 / g0), &Progress::new()).unwrap();
    curve
        .points
        .iter()
        .map(|pt| {
            let df = p.scales.frequency_hz(pt.omega - curve.reference.omega);
            // the centre of the oscillation: the rest distance plus the static deflection
            (df, pt.observables.mean_deflection * g0)
        })
        .collect()
}

/// Small amplitude: the force gradient adds the spring −F′(d), so f = f₀√(1 − F′/k)
/// (→ −f₀F′/(2k), Giessibl's limit, when |F′| ≪ k; kept whole here, as F′/k ≈ 1e-3), with F′
/// of van der Waals plus the biased sphere, to the O((A/d)²) of the limit.
#[test]
fn small_amplitude_shift_is_the_si_force_gradient() {
    let z_c = [6e-9, 4e-9, 3e-9];
    for (&zc, (df, mean)) in z_c.iter().zip(shifts(3.0, &z_c)) {
        let d = zc + mean;
        let h = 1e-4 * d;
        let gradient = (force_si(d + h, 2.5) - force_si(d - h, 2.5)) / (2.0 * h);
        let expected = F0 * ((1.0 - gradient / K).sqrt() - 1.0);
        let rel = (df - expected).abs() / expected.abs();
        assert!(
            rel < 2.0 * (0.05e-9 / d).powi(2) + 1e-5,
            "z_c {zc}: {df} vs {expected}"
        );
    }
}

/// The Kelvin parabola at z_c = 5 nm: Δf(V_cpd ± 1 V) equal, Δf(V_cpd) the unbiased van der
/// Waals shift, and the force gradient k(1 − (1 + Δf/f₀)²) (the inverse of the spring formula
/// above) grows by four times as much at V_cpd + 2 V as at V_cpd + 1 V: F′ is linear in V² —
/// to 1e-2, as the static attraction (0.15 nN at 2 V, 3.7 pm of deflection at k = 40 N/m)
/// brings the centre of the oscillation 1e-3 of d closer.
#[test]
fn the_shift_is_a_parabola_in_the_bias_about_the_contact_potential() {
    let at = |bias: f64| shifts(bias, &[5e-9])[0];
    let (minus, (zero, mean), plus, plus2) = (at(-0.5).0, at(0.5), at(1.5).0, at(2.5).0);
    assert!(
        (minus - plus).abs() < 1e-6 * plus.abs(),
        "{minus} vs {plus}"
    );
    let d = 5e-9 + mean;
    let vdw = F0 * ((1.0 - H * R / (3.0 * d * d * d) / K).sqrt() - 1.0);
    assert!((zero / vdw - 1.0).abs() < 1e-3, "{zero} vs {vdw}");
    let gradient = |df: f64| K * (1.0 - (1.0 + df / F0).powi(2));
    let ratio = (gradient(plus2) - gradient(zero)) / (gradient(plus) - gradient(zero));
    assert!((ratio - 4.0).abs() < 1e-2, "{ratio}");
    assert!(plus < zero, "a bias pulls the tip: the frequency drops");
}

/// A probe's electrostatic sample needs its bias; the voltages are keys of that law only.
#[test]
fn probe_keys_of_the_electrostatic_law() {
    let text = |law: &str, bias: &str| {
        format!(
            "model = \"point-mass\"\n[cantilever]\nspring_constant = {K}\n\
             resonance_frequency = {F0}\nquality_factor = 400\n[tip]\nradius = {R}\n[sample]\n\
             law = \"{law}\"\nyoungs_modulus = 4e9\npoisson_ratio = 0.33\nhamaker = {H}\n{bias}\
             [drive]\nfree_amplitude = 10e-9\n"
        )
    };
    let e = Probe::parse(&text("electrostatic", ""), "p")
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing key [sample].bias_voltage (V)"), "{e}");
    let e = Probe::parse(&text("dmt", "bias_voltage = 1.0\n"), "p")
        .unwrap_err()
        .to_string();
    assert!(e.contains("unknown key [sample].bias_voltage"), "{e}");
    // zero volts across the gap: DMT's force exactly
    let p = Probe::parse(&text("electrostatic", "bias_voltage = 0.0\n"), "p").unwrap();
    assert!(matches!(
        p.params.contact_law,
        ContactLaw::Electrostatic { electrostatic, .. } if electrostatic == 0.0
    ));
}

/// The Tabor parameter μ = (R W²/(E*² z₀³))^{1/3}, W = H/(12πz₀²) (Tabor 1977; Johnson &
/// Greenwood 1997; Israelachvili 2011 §13.6), in `si` and as a warning in JKR's regime (μ > 5):
/// the case — a 2 N/m lever over a 50 MPa adhesive polymer (H = 6.6e-20 J, R = 10 nm)
/// — gets it; polystyrene (4 GPa) does not.
#[test]
fn the_tabor_parameter_warns_where_dmt_does_not_apply() {
    let text = |e: f64| {
        format!(
            "model = \"point-mass\"\n[cantilever]\nspring_constant = 2.0\n\
             resonance_frequency = 70e3\nquality_factor = 150\n[tip]\nradius = 10e-9\n\
             youngs_modulus = 130e9\npoisson_ratio = 0.28\n[sample]\nlaw = \"dmt\"\n\
             youngs_modulus = {e}\npoisson_ratio = 0.4\nhamaker = 6.6e-20\n\
             intermolecular_distance = 0.165e-9\n[drive]\nfree_amplitude = 10e-9\n"
        )
    };
    for (e, jkr) in [(50e6, true), (4e9, false)] {
        let p = Probe::parse(&text(e), "p").unwrap();
        // by hand: E* from 1/E* = (1 − ν_t²)/E_t + (1 − ν_s²)/E_s
        let e_star = 1.0 / ((1.0 - 0.28 * 0.28) / 130e9 + (1.0 - 0.4 * 0.4) / e);
        let z0: f64 = 0.165e-9;
        let w = 6.6e-20 / (12.0 * PI * z0 * z0);
        let mu = (10e-9 * w * w / (e_star * e_star * z0.powi(3))).cbrt();
        let got = p.tabor_parameter.unwrap();
        assert!((got / mu - 1.0).abs() < 1e-12, "{got} vs {mu}");
        assert_eq!(got > 5.0, jkr, "μ = {got}");
        let doc = afmdyn::report::with_si(serde_json::json!({"warnings": []}), Some(&p), &p.params);
        assert_eq!(doc["si"]["tabor_parameter"], serde_json::json!(got));
        let warned = doc["warnings"][0]
            .as_str()
            .is_some_and(|w| w.contains("JKR's regime"));
        assert_eq!(warned, jkr, "{doc}");
    }
}

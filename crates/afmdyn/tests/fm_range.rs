//! The default range of an FM curve (issue 60 item 13): from where the frequency shift has
//! decayed to [`FM_DEFAULT_DECAY`] (0.5 %) of its value at contact, down to contact — checked
//! against the two closed forms of Giessibl's shift for the van der Waals force F = −H/d² of a
//! sphere (Giessibl, Phys. Rev. B 56, 16010 (1997)): for A ≪ d, Δf ∝ F′(d) ∝ d⁻³, so the
//! 0.5 % point sits at 200^{1/3} times the contact distance; for A ≫ d, Δf ∝ d_min^{-3/2}, so
//! it sits at a closest distance 200^{2/3} times the contact distance. A default curve is
//! reconstructed without `reconstruct`'s truncation warning (its threshold
//! [`afmdyn::request::reconstruct::DECAYED`] is twice the default's decay).

use afmdyn::request::fm::{default_from, FM_DEFAULT_DECAY};
use afmdyn::{ContactLaw, Params};

/// The DMT law with a0 = 0.01 g₀ and H̃ = 1e-5 on the paper's lever.
fn dmt() -> Params {
    Params {
        contact_law: ContactLaw::Dmt {
            hamaker: 1e-5,
            intermolecular_distance: 0.01,
        },
        ..Params::default()
    }
}

#[test]
fn small_amplitude_limit_is_the_force_gradient() {
    let p = dmt();
    let (a, a0) = (1e-7, 0.01);
    let to = a + a0;
    let from = default_from(&p, a, to).unwrap();
    // rest distances d = z_c: F'(d) ∝ d⁻³ falls to 0.5 % of its value at `to` at
    // d = 200^{1/3} to (corrections O((A/d)²) = 1e-10)
    let want = to * (1.0 / FM_DEFAULT_DECAY).powf(1.0 / 3.0);
    assert!((from - want).abs() < 1e-6 * want, "{from} vs {want}");
}

#[test]
fn large_amplitude_limit_is_giessibls_normalised_shift() {
    let p = dmt();
    let (a, a0) = (1e3, 0.01);
    let to = a + a0;
    let from = default_from(&p, a, to).unwrap();
    // the closest distance d_min = z_c − A: the shift ∝ d_min^{-3/2} falls to 0.5 % at
    // d_min = 200^{2/3} a0 (corrections O(d_min/A) ≈ 2e-4)
    let want = a0 * (1.0 / FM_DEFAULT_DECAY).powf(2.0 / 3.0);
    let got = from - a;
    assert!((got - want).abs() < 2e-3 * want, "{got} vs {want}");
}

#[test]
fn laws_without_a_force_before_contact_keep_the_turning_point_default() {
    for law in [ContactLaw::Linear, ContactLaw::Hertz] {
        let p = Params {
            contact_law: law,
            ..Params::default()
        };
        assert_eq!(default_from(&p, 1.0, 1.0), None, "{law}");
    }
}

/// A qPlus sensor (k = 1 800 N/m, f0 = 30 kHz, Q = 2 000, A = 100 pm) over a van der Waals
/// sample: the `fm` curve on its default range, handed to `reconstruct` as its document
/// (`reconstruct --fm fm.json`), starts where |Δf| is below `reconstruct`'s truncation
/// threshold [`DECAYED`]: no truncation warning (issue 60 item 13).
#[test]
fn a_default_fm_curve_reconstructs_without_the_truncation_warning() {
    use afmdyn::analysis::progress::Progress;
    use afmdyn::probe::Probe;
    use afmdyn::request::fm::FmRequest;
    use afmdyn::request::reconstruct::{ReconstructRequest, DECAYED};
    use afmdyn::request::{run, Resolved};
    // the example probe (a DMT polystyrene sample) with the qPlus lever and amplitude
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/probe-point-mass-dmt.toml"
    ))
    .unwrap();
    let qplus = [
        ("spring_constant = 40.0", "spring_constant = 1800.0"),
        ("resonance_frequency = 300e3", "resonance_frequency = 30e3"),
        ("quality_factor = 400", "quality_factor = 2000"),
        ("z_c = 8e-9", "z_c = 1e-9"),
        ("free_amplitude = 10e-9", "free_amplitude = 100e-12"),
        ("frequency = 300e3", "frequency = 30e3"),
    ]
    .iter()
    .fold(text, |t, (from, to)| {
        assert!(t.contains(from), "{from}");
        t.replacen(from, to, 1)
    });
    let probe = Probe::parse(&qplus, "qplus").unwrap();
    let model = Resolved {
        params: probe.params,
        probe: Some(probe),
    };
    let doc = run::run(&FmRequest::default(), &model, &Progress::new()).unwrap();
    let shift: Vec<f64> = doc.json["curve"]["frequency_shift"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let extreme = shift.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    // the first point (the far end) below the threshold, with the margin of the default
    assert!(
        shift[0].abs() < DECAYED * extreme,
        "{} of the extreme",
        shift[0].abs() / extreme
    );
    let request = ReconstructRequest::from_fm_document(&doc.json, None, None, None).unwrap();
    let warnings = request.warnings();
    assert!(
        !warnings.iter().any(|w| w.contains("largest distance")),
        "{warnings:?}"
    );
}

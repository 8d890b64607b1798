//! The default range of an FM curve (issue 60 item 13): from where the frequency shift has
//! decayed to 1 % of its value at contact, down to contact — checked against the two closed
//! forms of Giessibl's shift for the van der Waals force F = −H/d² of a sphere (Giessibl,
//! Phys. Rev. B 56, 16010 (1997)): for A ≪ d, Δf ∝ F′(d) ∝ d⁻³, so the 1 % point sits at
//! 100^{1/3} times the contact distance; for A ≫ d, Δf ∝ d_min^{-3/2}, so it sits at a
//! closest distance 100^{2/3} times the contact distance.

use afmdyn::request::fm::default_from;
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
    // rest distances d = z_c: F'(d) ∝ d⁻³ falls to 1 % of its value at `to` at
    // d = 100^{1/3} to (corrections O((A/d)²) = 1e-10)
    let want = to * 100f64.powf(1.0 / 3.0);
    assert!((from - want).abs() < 1e-6 * want, "{from} vs {want}");
}

#[test]
fn large_amplitude_limit_is_giessibls_normalised_shift() {
    let p = dmt();
    let (a, a0) = (1e3, 0.01);
    let to = a + a0;
    let from = default_from(&p, a, to).unwrap();
    // the closest distance d_min = z_c − A: the shift ∝ d_min^{-3/2} falls to 1 % at
    // d_min = 100^{2/3} a0 (corrections O(d_min/A) ≈ 2e-4)
    let want = a0 * 100f64.powf(2.0 / 3.0);
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

//! Sader's method against the beam it is derived for.

use super::*;

/// Sader's constant for the first mode, 3/β₁⁴ · π/4, is his 0.1906 (Sader, Chon & Mulvaney
/// 1999, eq. 4); and a silicon beam in air (450 × 50 × 2 µm) whose wet mode and Q are the
/// hydrodynamic function's alone (`crate::hydro::wet_mode`) gives back its 3EI/L³ from each of
/// its first three modes (1e-9: the identity Sader's method rests on), the effective ones
/// k_s β_k⁴/12; 1 % standard errors in f₀ and Q give 1.5–2.5 % in k.
#[test]
fn saders_method_gives_the_beam_it_is_derived_for() {
    let c1 = 3.0 / crate::beam::beta_root(1).powi(4) * PI / 4.0;
    assert!((c1 - 0.1906).abs() < 5e-5, "{c1}");
    let (l, b, h, e, rho) = (450e-6, 50e-6, 2e-6, 169e9, 2330.0);
    let beam = crate::units::Cantilever {
        length: l,
        width: b,
        thickness: h,
        youngs_modulus: e,
        density: rho,
    };
    let ei = e * b * h.powi(3) / 12.0;
    let ks = 3.0 * ei / l.powi(3);
    for k in 1..=3 {
        let beta = crate::beam::beta_root(k);
        let f_vac = beta * beta / (2.0 * PI * l * l) * (ei / (rho * b * h)).sqrt();
        let wet = wet_mode(f_vac, &beam, &Medium::AIR).unwrap();
        let at = |v: f64| (v, 0.01 * v);
        let f0_q = (at(wet.frequency_hz), at(wet.quality_factor));
        let [s, eff] = sader((l, b), &Medium::AIR, k, f0_q, 0.0).unwrap();
        assert!((s.0 / ks - 1.0).abs() < 1e-9, "mode {k}: {} vs {ks}", s.0);
        assert!((eff.0 / (ks * beta.powi(4) / 12.0) - 1.0).abs() < 1e-9);
        // 1 % in Q and in f₀, uncorrelated: √(1 + (2 + d ln Γ_i/d ln ω)²) %, Γ_i falling as ω^−0.6
        assert!(s.1 / s.0 > 0.015 && s.1 / s.0 < 0.025, "{s:?}");
    }
}

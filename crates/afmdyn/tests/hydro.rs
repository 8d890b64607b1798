//! Sader's hydrodynamic function and the wet modes (`afmdyn::hydro`): Γ_circ against K₀ and
//! K₁ from an independent quadrature of their integral representation, its large-Re
//! asymptote, the signs and trend of Γ_rect, and the wet mode's defining equation, its
//! small-density limit and a lever in air and in water.

use afmdyn::hydro::{gamma_circular, gamma_rectangular, wet_mode, Medium};
use afmdyn::units::Cantilever;
use nalgebra::Complex;
use std::f64::consts::PI;

/// K_ν(z) = ∫₀^∞ exp(−z cosh t) cosh(νt) dt for Re z > 0 (Abramowitz & Stegun 9.6.24), by
/// the trapezoidal rule on [0, T], exponentially accurate for this analytic, doubly
/// exponentially decaying integrand; T where |exp(−z cosh t)| < 1e-300.
fn bessel_k_quadrature(nu: f64, z: Complex<f64>) -> Complex<f64> {
    let t_end = (2.0 * 700.0 / z.re).acosh();
    let n = 40_000;
    let h = t_end / n as f64;
    let f = |t: f64| (-z * t.cosh()).exp() * (nu * t).cosh();
    let mut sum = 0.5 * (f(0.0) + f(t_end));
    for i in 1..n {
        sum += f(i as f64 * h);
    }
    sum * h
}

#[test]
fn gamma_circular_matches_an_independent_quadrature() {
    for re in [1e-3, 0.1, 1.0, 10.0, 300.0] {
        let i = Complex::<f64>::i();
        let z = -i * (i * re).sqrt();
        let (k0, k1) = (bessel_k_quadrature(0.0, z), bessel_k_quadrature(1.0, z));
        let want = Complex::new(1.0, 0.0) + 4.0 * k1 / (z * k0);
        let got = gamma_circular(re).unwrap();
        assert!(
            (got - want).norm() < 1e-10 * want.norm(),
            "Re {re}: {got} vs {want}"
        );
    }
}

/// K₁/K₀ ~ 1 + 1/(2z) for large z (A&S 9.7.2), so Γ_circ = 1 + 4/z + 2/z² + O(z⁻³) with
/// z = e^{−iπ/4}√Re: 1 + 2√2(1 + i)/√Re + 2i/Re.
#[test]
fn gamma_circular_large_reynolds_asymptote() {
    let re = 1e4;
    let got = gamma_circular(re).unwrap();
    let first = Complex::new(1.0, 0.0) + 2.0 * 2f64.sqrt() * Complex::new(1.0, 1.0) / re.sqrt();
    let second = first + Complex::new(0.0, 2.0 / re);
    assert!((got - second).norm() < 2e-5, "{got} vs {second}");
    // the second-order term is resolved: without it the error is ten times larger
    assert!((got - first).norm() > 10.0 * (got - second).norm());
}

/// Γ_rect: added mass and damping positive over Sader's range, both falling with Re (a
/// thinner boundary layer), and Re outside [1e-6, 1e4] refused naming it.
#[test]
fn gamma_rectangular_is_positive_and_falls_with_reynolds() {
    let mut last = Complex::new(f64::INFINITY, f64::INFINITY);
    for k in -12..=8 {
        let re = 10f64.powf(0.5 * f64::from(k));
        let g = gamma_rectangular(re).unwrap();
        assert!(g.re > 0.0 && g.im > 0.0, "Re {re}: {g}");
        assert!(
            g.re < last.re && g.im < last.im,
            "Re {re}: {g} after {last}"
        );
        last = g;
    }
    for bad in [1e-7, 2e4, f64::NAN] {
        let e = gamma_rectangular(bad).unwrap_err().to_string();
        assert!(e.contains("reynolds"), "{e}");
    }
}

/// A silicon lever 125 µm × 30 µm × 4 µm (a common tapping-mode geometry) with its first
/// flexural mode at 300 kHz in vacuum.
fn lever() -> Cantilever {
    Cantilever {
        length: 125e-6,
        width: 30e-6,
        thickness: 4e-6,
        youngs_modulus: 169e9,
        density: 2330.0,
    }
}

#[test]
fn wet_mode_solves_its_equation_and_has_the_thin_fluid_limit() {
    let beam = lever();
    for medium in [Medium::WATER, Medium::AIR] {
        let m = wet_mode(300e3, &beam, &medium).unwrap();
        // ω_f² (1 + TΓ_r(ω_f)) = ω_vac²
        let t = PI * medium.density * beam.width / (4.0 * beam.density * beam.thickness);
        let g = gamma_rectangular(medium.reynolds(2.0 * PI * m.frequency_hz, beam.width)).unwrap();
        let lhs = m.frequency_hz.powi(2) * (1.0 + t * g.re);
        assert!((lhs / 300e3f64.powi(2) - 1.0).abs() < 1e-12, "{m:?}");
        assert!((m.quality_factor - (1.0 / t + g.re) / g.im).abs() < 1e-9 * m.quality_factor);
    }
    // a fluid a million times thinner than air: f_f = f_vac (1 − TΓ_r/2) to first order
    let thin = Medium {
        density: 1.184e-6,
        viscosity: 1.849e-5,
    };
    let m = wet_mode(300e3, &beam, &thin).unwrap();
    let shift = 1.0 - m.frequency_hz / 300e3;
    assert!(
        (shift / (0.5 * m.added_mass_ratio) - 1.0).abs() < 1e-5,
        "{m:?}"
    );
}

/// In air the added mass moves the resonance by well under 1 % and the fluid's Q is in the
/// hundreds; in water the resonance drops to a fraction of its vacuum value and Q to a few —
/// the regimes of Sader 1998 (Figs. 6–8) and of the tapping-mode levers of Basak & Raman,
/// Appl. Phys. Lett. 91, 064107 (2007).
#[test]
fn lever_in_air_and_in_water() {
    let beam = lever();
    let air = wet_mode(300e3, &beam, &Medium::AIR).unwrap();
    assert!(air.frequency_hz / 300e3 > 0.99, "{air:?}");
    assert!((100.0..5000.0).contains(&air.quality_factor), "{air:?}");
    let water = wet_mode(300e3, &beam, &Medium::WATER).unwrap();
    let ratio = water.frequency_hz / 300e3;
    assert!((0.3..0.9).contains(&ratio), "{water:?}");
    assert!((1.0..30.0).contains(&water.quality_factor), "{water:?}");
    // a thinner, more compliant lever loses more in water
    let thin = Cantilever {
        thickness: 1e-6,
        ..beam
    };
    let soft = wet_mode(20e3, &thin, &Medium::WATER).unwrap();
    assert!(soft.frequency_hz / 20e3 < ratio, "{soft:?}");
    assert!(soft.quality_factor < water.quality_factor, "{soft:?}");
}

#[test]
fn bad_media_are_refused_naming_the_field() {
    // the probe reader's lookup of `[medium] name`
    let e = afmdyn::units::preset(&afmdyn::hydro::MEDIA, "oil", "name", "medium")
        .unwrap_err()
        .to_string();
    assert!(e.contains("medium") && e.contains("water"), "{e}");
    let bad = Medium {
        density: -1.0,
        viscosity: 1e-3,
    };
    let e = wet_mode(300e3, &lever(), &bad).unwrap_err().to_string();
    assert!(e.contains("medium.density"), "{e}");
    let e = wet_mode(f64::NAN, &lever(), &Medium::WATER)
        .unwrap_err()
        .to_string();
    assert!(e.contains("vacuum_frequency_hz"), "{e}");
}

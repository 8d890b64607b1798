//! Mode shapes (eq. 9), Galerkin matrices (eqs. 10–18) and eigen-analysis (eqs. 19–25).

use afmdyn::beam::{beta_root, BeamMode, ModeShapes};
use afmdyn::eigen::{damped_eigenvalues, fig3_sweep, natural_modes, spectrum};
use afmdyn::galerkin::{Galerkin, Region};
use afmdyn::Params;
use gauss_quad::legendre::GaussLegendre;
use nalgebra::{Complex, DMatrix};
use std::num::NonZeroUsize;

/// Composite Gauss–Legendre on [0, 1]: 64 panels × 16 nodes (exact to round-off for φ_20).
fn integrate(f: impl Fn(f64) -> f64) -> f64 {
    let gl = GaussLegendre::new(NonZeroUsize::new(16).unwrap());
    let panels = 64;
    (0..panels)
        .map(|k| {
            let a = k as f64 / panels as f64;
            gl.integrate(a, a + 1.0 / panels as f64, &f)
        })
        .sum()
}

#[test]
fn beta_squared_matches_paper_eq23() {
    // paper eq. 23 prints 3.52, 22.03, 61.7; the issue asks for 3.516, 22.034, 61.697
    for (i, want) in [(1, 3.516), (2, 22.034), (3, 61.697)] {
        let b2 = beta_root(i).powi(2);
        assert!((b2 - want).abs() < 5e-4, "beta_{i}^2 = {b2}");
    }
    // the defining equation 1 + cos β cosh β = 0, scaled by cosh β, holds to round-off
    for i in 1..=20 {
        let b = beta_root(i);
        assert!(
            (b.cos() + 1.0 / b.cosh()).abs() < 4.0 * f64::EPSILON * b,
            "mode {i}"
        );
        // asymptote (2i − 1)π/2 for i ≥ 2 (Chang & Craig)
        assert!(i == 1 || (b - (2.0 * i as f64 - 1.0) * std::f64::consts::FRAC_PI_2).abs() < 0.02);
    }
}

#[test]
fn modes_are_orthonormal_to_1e12_for_n20() {
    let s = ModeShapes::new(20);
    for i in 0..20 {
        for j in 0..=i {
            let (a, b) = (s.modes()[i], s.modes()[j]);
            let g = integrate(|x| a.value(x) * b.value(x));
            let want = if i == j { 1.0 } else { 0.0 };
            assert!(
                (g - want).abs() < 1e-12,
                "<phi_{}, phi_{}> = {g}",
                i + 1,
                j + 1
            );
        }
    }
}

#[test]
fn clamped_free_boundary_conditions_and_tip_value() {
    for i in 1..=20 {
        let m = BeamMode::new(i);
        let b4 = m.beta.powi(4);
        assert!(m.derivative(0, 0.0).abs() < 1e-12, "phi(0), mode {i}");
        assert!(
            m.derivative(1, 0.0).abs() < 1e-12 * m.beta,
            "phi'(0), mode {i}"
        );
        assert!(
            m.derivative(2, 1.0).abs() < 1e-12 * m.beta.powi(2),
            "phi''(1), mode {i}"
        );
        assert!(
            m.derivative(3, 1.0).abs() < 1e-12 * m.beta.powi(3),
            "phi'''(1), mode {i}"
        );
        let sign = if i % 2 == 1 { 2.0 } else { -2.0 };
        assert!(
            (m.value(1.0) - sign).abs() < 1e-12,
            "phi(1) = {}",
            m.value(1.0)
        );
        // φ'''' = β⁴ φ
        for x in [0.1, 0.5, 0.93] {
            assert!((m.derivative(4, x) - b4 * m.value(x)).abs() < 1e-12 * b4);
        }
    }
}

#[test]
fn derivatives_match_finite_differences() {
    let m = BeamMode::new(7);
    let h = 1e-5;
    for k in 0..4 {
        for x in [0.2, 0.6] {
            let fd = (m.derivative(k, x + h) - m.derivative(k, x - h)) / (2.0 * h);
            let exact = m.derivative(k + 1, x);
            assert!(
                (fd - exact).abs() < 1e-6 * m.beta.powi(k as i32 + 1),
                "k = {k}"
            );
        }
    }
}

#[test]
fn closed_form_integral_matches_quadrature() {
    for m in ModeShapes::new(20).modes() {
        let q = integrate(|x| m.value(x));
        assert!((m.integral() - q).abs() < 1e-13, "{} vs {q}", m.integral());
    }
}

#[test]
fn galerkin_matrices_match_quadrature_of_eqs_11_to_18() {
    let p = Params {
        modes: 4,
        alpha1: 0.3,
        alpha3: 0.07,
        alpha4: 11.0,
        alpha5: 0.2,
        alpha6: 0.4,
        ..Params::default()
    };
    let g = Galerkin::new(&p).unwrap();
    let s = g.shapes().modes().to_vec();
    let n = p.modes;
    for i in 0..n {
        for j in 0..n {
            let (a, b) = (s[i], s[j]);
            let tip = a.value(1.0) * b.value(1.0);
            let mm = integrate(|x| a.value(x) * b.value(x));
            let kk = integrate(|x| a.value(x) * b.derivative(4, x));
            let free = g.region(Region::Free);
            let contact = g.region(Region::Contact);
            assert!(
                (free.mass[(i, j)] - (p.alpha1 * tip + mm)).abs() < 1e-11,
                "eq. 11"
            );
            assert!(
                (free.damping[(i, j)] - p.alpha3 * mm).abs() < 1e-11,
                "eq. 12"
            );
            assert!(
                (free.stiffness[(i, j)] - kk).abs() < 1e-9 * kk.abs().max(1.0),
                "eq. 13"
            );
            assert_eq!(contact.mass, free.mass, "eq. 15");
            assert!(
                (contact.damping[(i, j)] - (p.alpha3 * mm + p.alpha6 * tip)).abs() < 1e-11,
                "eq. 16"
            );
            assert!(
                (contact.stiffness[(i, j)] - (kk + p.alpha4 * tip)).abs()
                    < 1e-9 * kk.abs().max(1.0),
                "eq. 17"
            );
        }
        let (a, iphi) = (s[i], integrate(|x| s[i].value(x)));
        let free = &g.region(Region::Free).forcing;
        let contact = &g.region(Region::Contact).forcing;
        let w2 = p.omega * p.omega;
        assert!(
            (free.sin[i] - p.alpha2 * w2 * (p.alpha1 * a.value(1.0) + iphi)).abs() < 1e-12,
            "eq. 14"
        );
        assert!(
            (free.cos[i] + p.alpha2 * p.alpha3 * iphi).abs() < 1e-12,
            "eq. 14"
        );
        assert!(
            (contact.sin[i] - (free.sin[i] - p.alpha2 * p.alpha4 * a.value(1.0))).abs() < 1e-12,
            "eq. 18"
        );
        assert!(
            (contact.constant[i] + p.alpha4 * p.alpha5 * a.value(1.0)).abs() < 1e-12,
            "eq. 18"
        );
        assert!(
            (contact.cos[i] - (free.cos[i] - p.alpha2 * p.alpha6 * p.omega * a.value(1.0))).abs()
                < 1e-12,
            "eq. 18"
        );
    }
}

#[test]
fn eq25_contact_frequencies_are_reproduced_with_five_modes() {
    // paper eq. 24–25: α1 = 0.1, α4 = 20, α3 = α6 = 0 → 7.79, 20.33, 55.81. The paper does not
    // state N; N = 5 is the smallest that reproduces all printed digits (N = 4 gives 7.80).
    let printed = [7.79, 20.33, 55.81];
    let round2 = |x: f64| (x * 100.0).round() / 100.0;
    let contact = |n| {
        spectrum(&Params {
            modes: n,
            ..Params::paper_eq24()
        })
        .unwrap()
        .1
        .omega
    };
    let w5 = contact(5);
    for k in 0..3 {
        assert_eq!(round2(w5[k]), printed[k], "N = 5, mode {}", k + 1);
    }
    let w4 = contact(4);
    assert!(
        (0..3).any(|k| round2(w4[k]) != printed[k]),
        "N = 4 already matches: {w4:?}"
    );
}

#[test]
fn natural_modes_satisfy_k_x_equals_omega2_m_x() {
    let p = Params {
        modes: 6,
        alpha1: 0.25,
        alpha4: 37.0,
        ..Params::default()
    };
    let g = Galerkin::new(&p).unwrap();
    for r in [Region::Free, Region::Contact] {
        let m = g.region(r);
        let nm = natural_modes(m);
        for (k, w) in nm.omega.iter().enumerate() {
            let x = nm.vectors.column(k);
            let res = &m.stiffness * x - &m.mass * x * (w * w);
            assert!(res.norm() < 1e-10 * w * w, "residual {}", res.norm());
            assert!(
                ((x.transpose() * &m.mass * x)[(0, 0)] - 1.0).abs() < 1e-12,
                "mass-normalised"
            );
        }
        assert!(nm.omega.windows(2).all(|w| w[0] <= w[1]), "ascending");
    }
}

#[test]
fn damped_eigenvalues_solve_the_quadratic_eigenproblem() {
    let p = Params {
        modes: 4,
        ..Params::default()
    };
    let g = Galerkin::new(&p).unwrap();
    for r in [Region::Free, Region::Contact] {
        let m = g.region(r);
        let ev = damped_eigenvalues(m);
        assert_eq!(ev.len(), 4, "one per underdamped mode");
        for e in &ev {
            // (λ²M + λC + K) is singular: its smallest singular value vanishes
            let l = Complex::new(e.re, e.im);
            let q: DMatrix<Complex<f64>> = m.mass.map(|v| Complex::new(v, 0.0)) * (l * l)
                + m.damping.map(|v| Complex::new(v, 0.0)) * l
                + m.stiffness.map(|v| Complex::new(v, 0.0));
            let smin = q.clone().svd(false, false).singular_values.min();
            let smax = q.svd(false, false).singular_values.max();
            assert!(
                smin < 1e-10 * smax,
                "sigma_min / sigma_max = {}",
                smin / smax
            );
            assert!(e.re < 0.0 && e.im > 0.0);
            assert!((e.zeta - (-e.re / e.re.hypot(e.im))).abs() < 1e-15);
        }
        assert!(ev.windows(2).all(|w| w[0].im <= w[1].im), "sorted by Im");
    }
}

#[test]
fn fig3_trends() {
    let a1 = [0.0, 0.1, 0.3, 0.6];
    let a4 = [0.0, 5.0, 20.0, 100.0];
    let pts = fig3_sweep(3, &a1, &a4).unwrap();
    let at = |i: usize, j: usize| pts[i * a4.len() + j];
    // α1 = α4 = 0: the uniform cantilever, ω_i = β_i² (eq. 22–23), ratios 1
    assert!((at(0, 0).ratio1 - 1.0).abs() < 1e-12 && (at(0, 0).ratio2 - 1.0).abs() < 1e-12);
    for i in 0..a1.len() {
        for j in 1..a4.len() {
            assert!(at(i, j).ratio1 > at(i, j - 1).ratio1, "ω1 rises with α4");
        }
    }
    for j in 0..a4.len() {
        for i in 1..a1.len() {
            assert!(at(i, j).ratio1 < at(i - 1, j).ratio1, "ω1 falls with α1");
        }
    }
}

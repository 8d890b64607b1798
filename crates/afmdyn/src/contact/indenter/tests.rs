//! Each shape against its closed form (computed here, independently of the shape's file), the
//! exact sphere against the paraboloid and nanite's truncated series, the derivatives against
//! central differences, and the bottom-effect factors against their sources.

use super::bottom_effect::{dimitriadis_series, BottomEffect, GARCIA_CONE, GARCIA_PUNCH};
use super::*;
use std::f64::consts::PI;

const R: f64 = 5e-6;

fn all_shapes() -> [TipShape; 6] {
    [
        TipShape::Paraboloid,
        TipShape::Sphere,
        TipShape::Cone { half_angle: 25.0 },
        TipShape::Pyramid3 { face_angle: 15.0 },
        TipShape::Pyramid4 { half_angle: 35.0 },
        TipShape::FlatPunch,
    ]
}

/// The forces per unit E* at δ = 300 nm against Hertz, Sneddon (cone, punch), nanite's
/// `hertz_pyr3s` (0.8887 tan α δ²) and Bilodeau's four-sided tan α δ²/√2.
#[test]
fn each_shape_gives_its_closed_form() {
    let d: f64 = 300e-9;
    let tan = |deg: f64| (deg * PI / 180.0).tan();
    let expected = [
        4.0 / 3.0 * R.sqrt() * d.powf(1.5),
        f64::NAN, // the sphere: below, parametric
        2.0 / PI * tan(25.0) * d * d,
        0.8887 * tan(15.0) * d * d,
        tan(35.0) / 2f64.sqrt() * d * d,
        2.0 * R * d,
    ];
    for (shape, want) in all_shapes().iter().zip(expected) {
        if want.is_nan() {
            continue;
        }
        let got = shape.elastic(R, d).force;
        assert!(
            (got / want - 1.0).abs() < 1e-14,
            "{}: {got} {want}",
            shape.name()
        );
        assert_eq!(shape.elastic(R, -d).force, 0.0);
        assert_eq!(shape.elastic(R, 0.0).force, 0.0);
    }
}

/// Sneddon's sphere from its parametric form: at contact radii a = 0.01 R … 0.99 R,
/// δ = (a/2) ln((R + a)/(R − a)) and F/E* = ½[(a² + R²) ln((R + a)/(R − a)) − 2aR].
#[test]
fn the_sphere_is_sneddons_parametric_form() {
    for u in [0.01, 0.1, 0.3, 0.5, 0.7, 0.9, 0.99] {
        let a = u * R;
        // ln((R + a)/(R − a)) = ln(1 + 2u/(1 − u)), to a few ulps
        let l = (2.0 * u / (1.0 - u)).ln_1p();
        let delta = a / 2.0 * l;
        let want = 0.5 * ((a * a + R * R) * l - 2.0 * a * R);
        let e = TipShape::Sphere.elastic(R, delta);
        // the bracket cancels to ~ε/u² relative in the closed form itself
        let tol = 1e-13 + 4.0 * f64::EPSILON / (u * u);
        assert!(
            (e.force / want - 1.0).abs() < tol,
            "u = {u}: {} {want}",
            e.force
        );
        // Sneddon's contact stiffness 2E*a
        assert!((e.d_delta / (2.0 * a) - 1.0).abs() < 1e-12, "u = {u}");
    }
}

/// The exact sphere tends to the paraboloid as δ/R → 0, with the relative difference
/// −δ/(10R) + O((δ/R)²) of Sneddon's series (the first term of nanite's
/// `sneddon_spher_approx`); and it equals that truncated series (to δ⁴/R⁴) to within the
/// neglected terms, O((δ/R)⁵): below 1e-4 (δ/R)⁴ at δ/R = 0.1.
#[test]
fn the_sphere_tends_to_the_paraboloid() {
    for d in [1e-6, 1e-4, 1e-2] {
        let delta = d * R;
        let s = TipShape::Sphere.elastic(R, delta).force;
        let p = TipShape::Paraboloid.elastic(R, delta).force;
        let rel = s / p - 1.0;
        assert!((rel + d / 10.0).abs() < d * d, "δ/R = {d}: {rel}");
    }
    let d: f64 = 0.1;
    let series = 1.0 - d / 10.0 - d * d / 840.0
        + 11.0 * d.powi(3) / 15120.0
        + 1357.0 * d.powi(4) / 6652800.0;
    let s = TipShape::Sphere.elastic(R, d * R).force;
    let p = TipShape::Paraboloid.elastic(R, d * R).force;
    assert!(
        (s / (p * series) - 1.0).abs() < 1e-4 * d.powi(4),
        "{}",
        s / (p * series)
    );
}

/// ∂g/∂δ and ∂g/∂R of every shape, bare and on a 2 µm layer (bonded; non-bonded where the
/// source has it), against central differences.
#[test]
fn derivatives_are_central_differences() {
    for shape in all_shapes() {
        let mut indenters = vec![Indenter {
            shape,
            bottom: None,
        }];
        for bonded in [true, false] {
            if let Ok(b) = BottomEffect::new(shape, 2e-6, bonded, 0.5) {
                indenters.push(Indenter {
                    shape,
                    bottom: Some(b),
                });
            }
        }
        assert!(indenters.len() >= 2, "{}", shape.name());
        for ind in indenters {
            for delta in [2e-9, 50e-9, 400e-9, 1.5e-6] {
                let e = ind.elastic(R, delta);
                let hd = 1e-6 * delta;
                let fd = (ind.elastic(R, delta + hd).force - ind.elastic(R, delta - hd).force)
                    / (2.0 * hd);
                let hr = 1e-6 * R;
                let fr = (ind.elastic(R + hr, delta).force - ind.elastic(R - hr, delta).force)
                    / (2.0 * hr);
                let close = |a: f64, b: f64| (a - b).abs() <= 1e-7 * a.abs().max(b.abs()) + 1e-30;
                assert!(
                    close(e.d_delta, fd),
                    "{} δ {delta}: {} {fd}",
                    shape.name(),
                    e.d_delta
                );
                assert!(
                    close(e.d_radius, fr),
                    "{} δ {delta}: {} {fr}",
                    shape.name(),
                    e.d_radius
                );
            }
        }
    }
}

/// No shape panics or returns a non-finite force on extreme inputs.
#[test]
fn extreme_inputs_stay_finite() {
    for shape in all_shapes() {
        for delta in [1e-300, 1e-20, 1.0, 1e3, f64::MAX] {
            let e = shape.elastic(R, delta);
            assert!(
                e.force.is_finite() || delta > 1.0,
                "{} {delta}",
                shape.name()
            );
        }
        assert_eq!(shape.elastic(R, f64::NAN).force, 0.0);
    }
    // beyond what a double resolves the contact radius saturates below R
    let u = sphere::contact_ratio(1e3);
    assert!(u < 1.0 && u > 0.999_999);
}

/// The bottom-effect factors: 1 on an infinitely thick sample (χ → 0), above 1 on a thin one;
/// Dimitriadis et al.'s bonded, incompressible first two coefficients are Garcia & Garcia's
/// (1.133 of the paraboloid and the punch, 1.283 of the punch) and the cone's first is (2/π)
/// times the first (its contact radius is (2/π) δ tan θ): the two sources agree.
#[test]
fn bottom_effect_factors_match_their_sources() {
    for shape in all_shapes() {
        let thick = BottomEffect::new(shape, 1.0, true, 0.5).unwrap();
        let c = thick.factor(R, 1e-9).value;
        let punch = shape == TipShape::FlatPunch;
        // (the punch's factor is 1 + 1.133 R/h)
        assert!(
            (c - 1.0).abs() < if punch { 1e-5 } else { 1e-6 },
            "{}: {c}",
            shape.name()
        );
        // (a layer thicker than the punch: its series runs in a/h)
        let thin = BottomEffect::new(shape, 10e-6, true, 0.5).unwrap();
        assert!(thin.factor(R, 2e-6).value > 1.05, "{}", shape.name());
    }
    // Dimitriadis et al.'s printed series at ν = 0.5 (eqs. 12 and 13, to their 3–4 digits):
    // non-bonded in all four, bonded in the first three and the fourth's size (its sign is
    // eq. 11's, module docs)
    let close = |got: [f64; 4], want: [f64; 4]| {
        got.iter()
            .zip(want)
            .all(|(g, w)| (g - w).abs() <= 6e-4 * w.abs().max(1.0))
    };
    let free = dimitriadis_series(0.5, false);
    assert!(close(free, [0.884, 0.781, 0.386, 0.0048]), "{free:?}");
    let glued = dimitriadis_series(0.5, true);
    assert!(close(glued, [1.133, 1.283, 0.769, -0.0975]), "{glued:?}");
    assert!((free[3] - 0.0048).abs() < 1e-4, "{free:?}");
    let [c1, c2, _, _] = glued;
    assert!((c1 - 1.133).abs() < 5e-4, "{c1}");
    assert!((c1 - GARCIA_PUNCH[0]).abs() < 5e-4);
    assert!((c2 - GARCIA_PUNCH[1]).abs() < 5e-4, "{c2}");
    assert!((2.0 / PI * c1 - GARCIA_CONE[0]).abs() < 5e-4);
    // the factor is the series: at χ = 0.5 on the paraboloid (√(Rδ) = h/2)
    let h = 2e-6;
    let delta = (h / 2.0) * (h / 2.0) / R;
    let s = dimitriadis_series(0.3, false);
    let want = 1.0 + s[0] * 0.5 + s[1] * 0.25 + s[2] * 0.125 + s[3] * 0.0625;
    let got = BottomEffect::new(TipShape::Paraboloid, h, false, 0.3)
        .unwrap()
        .factor(R, delta)
        .value;
    assert!((got / want - 1.0).abs() < 1e-14);
}

/// The refusals name their field: a thickness ≤ 0, a non-bonded cone or pyramid, a cone on a
/// compressible sample; the adhesive laws refuse another shape.
#[test]
fn refusals_name_the_field() {
    let name = |e: SimError| match e {
        SimError::OutOfRange { name, .. } => name,
        e => panic!("{e}"),
    };
    let cone = TipShape::Cone { half_angle: 25.0 };
    assert_eq!(
        name(BottomEffect::new(cone, 0.0, true, 0.5).unwrap_err()),
        "thickness"
    );
    assert_eq!(
        name(BottomEffect::new(cone, f64::NAN, true, 0.5).unwrap_err()),
        "thickness"
    );
    assert_eq!(
        name(BottomEffect::new(cone, 1e-6, false, 0.5).unwrap_err()),
        "bonded"
    );
    assert_eq!(
        name(BottomEffect::new(cone, 1e-6, true, 0.3).unwrap_err()),
        "sample.poisson_ratio"
    );
    assert!(BottomEffect::new(TipShape::Sphere, 1e-6, false, 0.3).is_ok());
    assert_eq!(name(cone.check_law(LawKind::Dmt).unwrap_err()), "tip.shape");
    assert!(cone.check_law(LawKind::Hertz).is_ok());
    assert!(TipShape::Paraboloid.check_law(LawKind::Jkr).is_ok());
}

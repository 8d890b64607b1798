//! Parameter validation (a test per field) and the physical-unit front (eqs. 5, 7, Hertz).

use afmdyn::units::{
    beam_damping_from_q, contact_stiffness, hertz_stiffness, material, Cantilever,
    ContactStiffness, Material, PhysicalModel, SILICON_TIP,
};
use afmdyn::{ParamError, Params, UnitsError};

fn bad(p: Params) -> ParamError {
    p.validate().expect_err("must be rejected")
}

#[test]
fn defaults_are_the_paper_figs_5_to_14_set() {
    let p = Params::default();
    assert_eq!(
        (p.modes, p.alpha1, p.alpha2, p.alpha3, p.alpha4, p.alpha5, p.alpha6, p.omega),
        (3, 0.1, 0.1, 0.1, 20.0, 0.0, 0.2, 2.6)
    );
    assert!(p.validate().is_ok());
}

#[test]
fn modes_out_of_range() {
    assert_eq!(
        bad(Params {
            modes: 0,
            ..Params::default()
        }),
        ParamError::Modes(0)
    );
    assert_eq!(
        bad(Params {
            modes: 21,
            ..Params::default()
        }),
        ParamError::Modes(21)
    );
    assert!(ParamError::Modes(0).to_string().contains("1..=20"));
}

#[test]
fn each_nonnegative_alpha_is_checked() {
    let d = Params::default();
    let cases: [(Params, &str); 5] = [
        (Params { alpha1: -0.1, ..d }, "alpha1"),
        (
            Params {
                alpha2: f64::NAN,
                ..d
            },
            "alpha2",
        ),
        (Params { alpha3: -1.0, ..d }, "alpha3"),
        (
            Params {
                alpha4: f64::INFINITY,
                ..d
            },
            "alpha4",
        ),
        (Params { alpha6: -0.2, ..d }, "alpha6"),
    ];
    for (p, field) in cases {
        match bad(p) {
            ParamError::NonNegative { name, .. } => {
                assert!(name.starts_with(field), "{name} for {field}")
            }
            e => panic!("{field}: unexpected {e}"),
        }
    }
}

#[test]
fn gap_may_be_negative_but_finite() {
    assert!(Params {
        alpha5: -0.3,
        ..Params::default()
    }
    .validate()
    .is_ok());
    assert!(matches!(
        bad(Params {
            alpha5: f64::NAN,
            ..Params::default()
        }),
        ParamError::Gap(_)
    ));
}

#[test]
fn omega_must_be_positive() {
    assert!(matches!(
        bad(Params {
            omega: 0.0,
            ..Params::default()
        }),
        ParamError::Omega(_)
    ));
    assert!(matches!(
        bad(Params {
            omega: f64::NAN,
            ..Params::default()
        }),
        ParamError::Omega(_)
    ));
    assert!(bad(Params {
        omega: -1.0,
        ..Params::default()
    })
    .to_string()
    .contains("> 0"));
}

fn probe() -> Cantilever {
    // the real probe: silicon, L = 125 µm, b = 40 µm, h = 3.7 µm, E = 169 GPa, ρ = 2330
    Cantilever {
        length: 125e-6,
        width: 40e-6,
        thickness: 3.7e-6,
        youngs_modulus: 169e9,
        density: 2330.0,
    }
}

#[test]
fn real_probe_frequency_and_spring_constant() {
    let c = probe();
    let i = c.width * c.thickness.powi(3) / 12.0;
    let ei = c.youngs_modulus * i;
    let a = c.width * c.thickness;
    let f1 = 1.875_104_068_711_961_f64.powi(2) * (ei / (c.density * a * c.length.powi(4))).sqrt()
        / std::f64::consts::TAU;
    assert!((c.first_frequency_hz() - f1).abs() < 1e-9 * f1);
    let k = 3.0 * ei / c.length.powi(3);
    assert!((c.spring_constant() - k).abs() < 1e-12 * k);
    assert!((k - 44.0).abs() < 0.5, "k = {k} N/m, expected ≈ 44");
}

#[test]
fn alphas_to_physical_and_back() {
    let p = Params {
        modes: 4,
        alpha1: 0.07,
        alpha2: 0.13,
        alpha3: 0.02,
        alpha4: 17.0,
        alpha5: -0.05,
        alpha6: 0.3,
        omega: 3.3,
        ..Params::default()
    };
    let phys = PhysicalModel::from_params(probe(), &p, 20e-9).unwrap();
    let q = phys.to_params().unwrap();
    for (a, b) in [
        (p.alpha1, q.alpha1),
        (p.alpha2, q.alpha2),
        (p.alpha3, q.alpha3),
        (p.alpha4, q.alpha4),
        (p.alpha5, q.alpha5),
        (p.alpha6, q.alpha6),
        (p.omega, q.omega),
    ] {
        assert!((a - b).abs() <= 1e-13 * a.abs().max(1e-300), "{a} vs {b}");
    }
    // α4 = K1 L³/EI = 3 K1 / K_c (paper §4)
    assert!(
        (q.alpha4 - 3.0 * phys.contact_stiffness / probe().spring_constant()).abs()
            < 1e-12 * q.alpha4
    );
}

#[test]
fn quality_factor_gives_that_q() {
    let mut phys = PhysicalModel::from_params(probe(), &Params::default(), 20e-9).unwrap();
    phys.beam_damping = beam_damping_from_q(&phys, 250.0).unwrap();
    let p = phys.to_params().unwrap();
    let (free, _) = afmdyn::eigen::spectrum(&Params { alpha6: 0.0, ..p }).unwrap();
    // Q = 1/(2ζ) of the first damped mode
    let q = 1.0 / (2.0 * free.eigenvalues[0].zeta);
    assert!((q - 250.0).abs() < 0.01, "Q = {q}");
}

#[test]
fn hertz_contact_stiffness() {
    // K1 = 2E*√(RΔ), 1/E* = (1 − ν1²)/E1 + (1 − ν2²)/E2 (paper §4), by hand for PS
    let ps = material("Polystyrene").unwrap();
    let (r, d) = (10e-9, 10e-9 / 9.0);
    let estar = 1.0 / ((1.0 - 0.27f64.powi(2)) / 130e9 + (1.0 - 0.34f64.powi(2)) / 4e9);
    let k = hertz_stiffness(SILICON_TIP, ps, r, d);
    assert!((k - 2.0 * estar * (r * d).sqrt()).abs() < 1e-9 * k);
    let via = contact_stiffness(ContactStiffness::Hertz {
        tip: SILICON_TIP,
        sample: ps,
        radius: r,
        indentation: d,
    })
    .unwrap();
    assert_eq!(k, via);
    // stiffer sample, stiffer contact
    assert!(hertz_stiffness(SILICON_TIP, material("mica").unwrap(), r, d) > k);
    for name in ["polystyrene", "hopg", "pdms", "mica", "silicon"] {
        assert!(material(name).is_ok(), "{name}");
    }
}

#[test]
fn unit_errors_name_the_field() {
    assert!(matches!(material("cheese"), Err(UnitsError::Choice(_))));
    let bad_c = Cantilever {
        thickness: -1.0,
        ..probe()
    };
    assert!(matches!(
        bad_c.validate(),
        Err(UnitsError::Positive {
            name: "thickness",
            ..
        })
    ));
    let h = ContactStiffness::Hertz {
        tip: SILICON_TIP,
        sample: Material {
            youngs_modulus: 1e9,
            poisson_ratio: 0.7,
        },
        radius: 1e-8,
        indentation: 1e-9,
    };
    assert!(matches!(
        contact_stiffness(h),
        Err(UnitsError::Poisson {
            name: "sample_poisson_ratio",
            ..
        })
    ));
    let mut phys = PhysicalModel::from_params(probe(), &Params::default(), 20e-9).unwrap();
    phys.drive_frequency_hz = 0.0;
    assert!(matches!(
        phys.to_params(),
        Err(UnitsError::Positive {
            name: "drive_frequency_hz",
            ..
        })
    ));
    phys.drive_frequency_hz = 1e5;
    phys.tip_gap = f64::NAN;
    assert!(matches!(
        phys.to_params(),
        Err(UnitsError::Finite {
            name: "tip_gap",
            ..
        })
    ));
}

#[test]
fn magnitudes_beyond_the_numerics_are_rejected_naming_the_field() {
    // issue 9: α1 = 1e300 panicked ("M is SPD"), α4 = 1e300 panicked ("K is SPD"), α2, α3, α5 and
    // α4 = 1e308 (modes) looped forever, Ω = 1e-9 aborted allocating 4 TB, Ω = 1e9 was silently
    // wrong. Each limit is accepted exactly and refused just beyond, with a message naming the
    // field and the allowed range.
    let d = Params::default();
    let cases: [(Params, Params, &str, &str); 10] = [
        (
            Params { alpha1: 1e4, ..d },
            Params {
                alpha1: 1.01e4,
                ..d
            },
            "alpha1",
            "[0, 1e4]",
        ),
        (
            Params { alpha2: 1e6, ..d },
            Params { alpha2: 1e300, ..d },
            "alpha2",
            "[0, 1e6]",
        ),
        (
            Params { alpha3: 1e4, ..d },
            Params { alpha3: 1e300, ..d },
            "alpha3",
            "[0, 1e4]",
        ),
        (
            Params { alpha4: 1e8, ..d },
            Params { alpha4: 1e308, ..d },
            "alpha4",
            "[0, 1e8]",
        ),
        (
            Params { alpha5: -1e6, ..d },
            Params {
                alpha5: -1e300,
                ..d
            },
            "alpha5",
            "[-1e6, 1e6]",
        ),
        (
            Params { alpha6: 1e4, ..d },
            Params { alpha6: 2e4, ..d },
            "alpha6",
            "[0, 1e4]",
        ),
        (
            Params { omega: 1e-3, ..d },
            Params { omega: 1e-9, ..d },
            "omega",
            "[1e-3, 1e5]",
        ),
        (
            Params { omega: 1e5, ..d },
            Params { omega: 1e9, ..d },
            "omega",
            "[1e-3, 1e5]",
        ),
        // a modulated sample (off-resonance tapping) reaches f₀/f_m = 1e5; the resonant
        // drives keep 1e-3 (the case above is the default base drive)
        (
            Params {
                omega: 1e-5,
                excitation: afmdyn::params::Excitation::Sample,
                ..d
            },
            Params {
                omega: 9e-6,
                excitation: afmdyn::params::Excitation::Sample,
                ..d
            },
            "omega",
            "[1e-5, 1e5] (a modulated sample)",
        ),
        (
            Params { omega: 1e-3, ..d },
            Params { omega: 1e-4, ..d },
            "omega",
            "[1e-3, 1e5]",
        ),
    ];
    for (at, beyond, field, range) in cases {
        assert!(at.validate().is_ok(), "{field} at its limit");
        let e = bad(beyond);
        assert!(matches!(e, ParamError::Magnitude { .. }), "{field}: {e}");
        let msg = e.to_string();
        assert!(msg.starts_with(field) && msg.contains(range), "{msg}");
    }
    // the sign checks keep their own error
    assert!(matches!(
        bad(Params { alpha4: -1.0, ..d }),
        ParamError::NonNegative { .. }
    ));
}

use super::*;

fn laws() -> Vec<TipSample> {
    [
        ContactLaw::Linear,
        ContactLaw::Hertz,
        ContactLaw::Dmt {
            hamaker: 0.3,
            intermolecular_distance: 0.02,
        },
        ContactLaw::Electrostatic {
            hamaker: 0.3,
            intermolecular_distance: 0.02,
            electrostatic: 0.05,
            tip_radius: 0.7,
        },
        ContactLaw::Jkr { adhesion: 0.05 },
        ContactLaw::Capillary {
            capillary: 0.1,
            meniscus: 0.02,
            rupture: 0.06,
        },
    ]
    .into_iter()
    .map(|law| TipSample {
        law,
        stiffness: 20.0,
        damping: 0.2,
    })
    .collect()
}

/// The partial derivatives are those of the force (central differences), and the
/// conservative part is −dU/dV_T = dU/dδ (definition of the potential).
#[test]
fn partials_and_potential_are_consistent() {
    for ts in laws() {
        // and a hysteretic law's contact region beyond V_T = 0: JKR's neck (δ_b = −0.0167
        // here), the capillary meniscus (D̃_r = 0.06)
        let band: &[(bool, f64, f64)] = match ts.law {
            ContactLaw::Jkr { .. } => &[(true, -0.01, 0.3), (true, -0.002, -0.5)],
            // and next to the kink at D = 0, on both sides
            ContactLaw::Capillary { .. } => &[
                (true, -0.03, 0.3),
                (true, -0.055, -0.5),
                (true, -1e-5, 0.0),
                (true, 1.2e-5, 0.0),
            ],
            _ => &[],
        };
        for &(contact, delta, rate) in [
            (true, 0.07, 0.3),
            (true, 0.5, -1.2),
            (false, -0.05, 0.4),
            (false, -0.8, -2.0),
        ]
        .iter()
        .chain(band)
        {
            let f = ts.force(contact, delta, rate);
            // a step that stays on the kink's side where δ is that small
            let h = 1e-6f64.min(1e-3 * delta.abs());
            let fd = (ts.force(contact, delta + h, rate).force
                - ts.force(contact, delta - h, rate).force)
                / (2.0 * h);
            let fr = (ts.force(contact, delta, rate + h).force
                - ts.force(contact, delta, rate - h).force)
                / (2.0 * h);
            assert!((f.d_delta - fd).abs() < 1e-6 * (1.0 + fd.abs()), "{ts:?}");
            assert!((f.d_rate - fr).abs() < 1e-6 * (1.0 + fr.abs()), "{ts:?}");
            let du =
                (ts.potential(contact, delta + h) - ts.potential(contact, delta - h)) / (2.0 * h);
            let cons = f.force - ts.dissipative(contact, delta, rate);
            assert!((du - cons).abs() < 1e-6 * (1.0 + du.abs()), "{ts:?}");
        }
    }
}

/// DMT is continuous at the contact threshold (force and potential), the DMT adhesion
/// force is H̃/ã₀² there; the electrostatic law too, with the sphere–plane force
/// ẼR̃²/(ã₀(ã₀ + R̃)) added.
#[test]
fn dmt_is_continuous_at_contact() {
    for (ts, adhesion) in [
        (laws()[2], 0.3 / (0.02 * 0.02)),
        (
            laws()[3],
            0.3 / (0.02 * 0.02) + 0.05 * 0.7 * 0.7 / (0.02 * 0.72),
        ),
    ] {
        let (inside, outside) = (ts.force(true, 0.0, 0.0), ts.force(false, 0.0, 0.0));
        assert!((inside.force - outside.force).abs() < 1e-12);
        assert!((inside.force + adhesion).abs() < 1e-9 * adhesion);
        assert!((ts.potential(true, 0.0) - ts.potential(false, 0.0)).abs() < 1e-12);
    }
}

/// The electrostatic force is Hudlet's sphere term: −πε₀V²R/d for d ≪ R (the parallel
/// plate limit of the sphere, Hudlet et al. 1998) and −πε₀V²R²/d² for d ≫ R (a point
/// charge's image force), in the law's units Ẽ = πε₀V², R̃.
#[test]
fn electrostatic_force_has_its_limits() {
    let ts = TipSample {
        law: ContactLaw::Electrostatic {
            hamaker: 0.0,
            intermolecular_distance: 1e-3,
            electrostatic: 2.0,
            tip_radius: 5.0,
        },
        stiffness: 0.0,
        damping: 0.0,
    };
    let near = ts.long_range(1e-4)[0];
    assert!((near / (-2.0 * 5.0 / 1e-4) - 1.0).abs() < 1e-4, "{near}");
    let far = ts.long_range(1e5)[0];
    assert!((far / (-2.0 * 25.0 / 1e10) - 1.0).abs() < 1e-4, "{far}");
}

/// The registry agrees with itself: names, serde tags and the parser; each law's defaults
/// validate and are its descriptors' defaults; each group is one of [`GROUPS`] and a
/// request key; [`LawKind::EXPECTED`] lists the names.
#[test]
fn the_registry_is_consistent() {
    assert_eq!(LawKind::ALL.len(), LAWS.len());
    for (&kind, info) in LawKind::ALL.iter().zip(LAWS) {
        assert_eq!(kind.name(), info.name);
        assert_eq!(kind.info(), info);
        let law = kind.with_groups(LawGroups::default());
        assert_eq!(law.kind(), kind);
        let json = serde_json::to_value(law).unwrap();
        assert_eq!(json["law"], info.name);
        assert_eq!(serde_json::from_value::<ContactLaw>(json).unwrap(), law);
        assert_eq!(serde_json::to_value(kind).unwrap(), info.name);
        assert_eq!(info.name.to_uppercase().parse::<LawKind>().unwrap(), kind);
        for a in info.aliases {
            assert_eq!(a.parse::<LawKind>().unwrap(), kind);
        }
        law.validate().unwrap();
        let groups = law.groups();
        for p in info.params {
            assert!(
                GROUPS.iter().any(|g| g.name == p.name),
                "a group: {}",
                p.name
            );
            assert_eq!(
                groups.get(p.name),
                Some(p.default),
                "{}.{}",
                info.name,
                p.name
            );
            assert!(crate::request::parameter(p.name).is_some(), "{}", p.name);
        }
        let given = groups.entries().filter(|(_, v)| v.is_some()).count();
        assert_eq!(given, info.params.len(), "{}", info.name);
        assert!(LawKind::EXPECTED.contains(info.name));
    }
    assert!(LawKind::EXPECTED.starts_with("linear, hertz, dmt"));
    #[cfg(not(feature = "toy-law"))]
    assert_eq!(
        LawKind::EXPECTED,
        "linear, hertz, dmt, electrostatic, jkr, capillary, sls or impact"
    );
}

/// The prepared law ([`PreparedLaw`]: each law's prepare step, JKR's constants and DMT's
/// adhesion computed once) evaluates every law's
/// force, partials, potential and dissipative part bit for bit as the law evaluated from its
/// groups at each call, over δ from beyond JKR's break to deep indentation (the break itself,
/// δ = 0 and NaN included), both regions and three rates; and JKR's force is, bit for bit, the
/// expression of the law before the constants were kept (q(δ), F(q), dq/dδ from [`Jkr::new`]
/// at each call), DMT's force and potential the expressions with −H̃/ã₀² and −H̃/ã₀ formed at
/// each call.
#[test]
fn the_prepared_law_is_the_law_bit_for_bit() {
    let mut cases = laws();
    for (stiffness, adhesion) in [(0.5, 1e-3), (20.0, 2.0), (3000.0, 0.05)] {
        cases.push(TipSample {
            law: ContactLaw::Jkr { adhesion },
            stiffness,
            damping: 0.3,
        });
    }
    let bits = |e: ForceEval| [e.force, e.d_delta, e.d_rate].map(f64::to_bits);
    let mut checked = 0;
    let mut dmt_checked = 0;
    for ts in cases {
        let prepared = PreparedLaw::new(ts);
        assert_eq!(prepared.tip_sample(), &ts);
        let jkr = match ts.law {
            ContactLaw::Jkr { adhesion } => Some(Jkr::new(ts.stiffness, adhesion)),
            _ => None,
        };
        let mut deltas: Vec<f64> = (-400..=400).map(|i| f64::from(i) * 2.5e-4).collect();
        deltas.extend([0.0, -0.0, f64::NAN, 0.3, 1.7]);
        if let Some(j) = &jkr {
            deltas.extend([
                j.release(),
                j.release() * (1.0 + 1e-9),
                j.indentation(j.q_end),
            ]);
        }
        for &delta in &deltas {
            for rate in [-0.8, 0.0, 0.45] {
                for contact in [false, true] {
                    let at = format!("{} δ = {delta}, δ̇ = {rate}, {contact}", ts.law);
                    let want = ts.force(contact, delta, rate);
                    assert_eq!(
                        bits(prepared.force(contact, delta, rate)),
                        bits(want),
                        "{at}"
                    );
                    let (u, v) = (
                        prepared.potential(contact, delta),
                        ts.potential(contact, delta),
                    );
                    assert_eq!(u.to_bits(), v.to_bits(), "{at}");
                    let (u, v) = (
                        prepared.dissipative(contact, delta, rate),
                        ts.dissipative(contact, delta, rate),
                    );
                    assert_eq!(u.to_bits(), v.to_bits(), "{at}");
                    if let (Some(_), true) = (&jkr, contact) {
                        // the law's expression as it was, with the constants of every call
                        let j = Jkr::new(ts.stiffness, ts.law.groups().get("adhesion").unwrap());
                        let q = j.radius_variable(delta);
                        let (f, df_dq) = j.elastic(q);
                        let q2 = q * q;
                        let dq = if delta > j.release() {
                            1.0 / (4.0 * q2 * q - j.c)
                        } else {
                            0.0
                        };
                        let old = ForceEval {
                            force: f + ts.damping * q2 * rate,
                            d_delta: (df_dq + 2.0 * ts.damping * q * rate) * dq,
                            d_rate: ts.damping * q2,
                        };
                        assert_eq!(bits(prepared.force(true, delta, rate)), bits(old), "{at}");
                        checked += 1;
                    }
                    if let ContactLaw::Dmt {
                        hamaker: h,
                        intermolecular_distance: a0,
                    } = ts.law
                    {
                        // DMT's expression before the adhesion −H̃/ã₀² was prepared
                        let (k, c) = (ts.stiffness, ts.damping);
                        let (old, u) = if contact {
                            let d = delta.max(0.0);
                            let s = d.sqrt();
                            let visc_d = if s > 0.0 { 0.5 * c * rate / s } else { 0.0 };
                            let [f0, _, u0] = dmt::van_der_waals(h, a0);
                            let old = ForceEval {
                                force: f0 + k * d * s + c * s * rate,
                                d_delta: 1.5 * k * s + visc_d,
                                d_rate: c * s,
                            };
                            (old, u0 + f0 * delta + 0.4 * k * d.powf(2.5))
                        } else {
                            let [force, d_d, u] = dmt::van_der_waals(h, a0 - delta);
                            let old = ForceEval {
                                force,
                                d_delta: -d_d,
                                d_rate: 0.0,
                            };
                            (old, u)
                        };
                        assert_eq!(
                            bits(prepared.force(contact, delta, rate)),
                            bits(old),
                            "{at}"
                        );
                        let got = prepared.potential(contact, delta);
                        assert_eq!(got.to_bits(), u.to_bits(), "{at}");
                        dmt_checked += 1;
                    }
                }
            }
        }
    }
    assert!(checked > 4 * 800, "{checked} JKR evaluations compared");
    assert!(
        dmt_checked > 6 * 800,
        "{dmt_checked} DMT evaluations compared"
    );
}
